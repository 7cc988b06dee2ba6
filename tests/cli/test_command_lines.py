"""The command lines behave for their users: bad numbers are argparse's one-line error
(exit 2), a user's mistake is one line ``error: ...`` (never ``<frozen runpy>``), every
``--help`` shows an example, progress bars only on a terminal, Ctrl-C is one line and
status 130, a closed pipe ends quietly. The commands run as real subprocesses; the
quick ones all at once (one fixture), so the module stays within a few seconds."""
from __future__ import annotations

import argparse
import contextlib
import fcntl
import os
import pathlib
import pty
import select
import signal
import struct
import subprocess
import sys
import termios
import time

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
PY = sys.executable
ROUTINES = ("remez", "specials", "accuracy", "bench", "zoo", "chart", "report", "docs", "search",
            "fingerprint", "dump", "ladder")
#: bad value -> the one line argparse prints
BAD_NUMBERS = {
    "accuracy --samples -5": (["routines", "accuracy", "exp2", "--samples", "-5"],
                              "argument --samples: must be a positive integer, not -5"),
    "bench --size 0": (["routines", "bench", "--size", "0"], "argument --size: must be a positive integer, not 0"),
    "bench --rounds x": (["routines", "bench", "--rounds", "x"], "argument --rounds: invalid int value: 'x'"),
    "accuracy --workers 0": (["routines", "accuracy", "exp2", "--exhaustive", "--workers", "0"],
                             "argument --workers: must be a positive integer, not 0"),
    "report --rounds 0": (["routines", "report", "--rounds", "0"], "argument --rounds: must be a positive integer"),
    "report --samples -1": (["routines", "report", "--samples", "-1"], "argument --samples: must be a positive"),
    "report --functions sine": (["routines", "report", "--functions", "sin", "sine"],
                                "argument --functions: invalid choice: 'sine'"),
    "bench --functions arctan": (["routines", "bench", "--functions", "arctan"],
                                 "argument --functions: invalid choice: 'arctan'"),
    "zoo --workers 0": (["routines", "zoo", "--workers", "0"], "argument --workers: must be a positive integer"),
    "search --workers -2": (["routines", "search", "exp2", "--workers", "-2"], "argument --workers: must be a"),
    "remez --degree 0": (["routines", "remez", "-d", "0", "x"], "argument -d/--degree: invalid degree 0"),
    "remez --dps 3": (["routines", "remez", "--dps", "3", "x"], "argument --dps: invalid precision --dps 3"),
    "fingerprint --widths 3": (["routines", "fingerprint", "--widths", "3"], "argument --widths: invalid choice: 3"),
    "dump --width 3": (["routines", "dump", "exp2", "--width", "3"], "argument --width: invalid choice: 3"),
    "reactor dump --opt 9": (["reactor", "dump", "x.py:f", "--opt", "9"], "argument --opt: invalid choice: 9"),
    "fuzz --budget 0": (["fuzz", "--budget", "0"], "argument --budget: must be a positive integer, not 0"),
}
#: a user's mistake -> the one line ``error: ...``
USER_ERRORS = {
    "reactor dump missing file": (["reactor", "dump", "/no/such/file.py:x"], "error: no such file: /no/such/file.py"),
    "reactor dump missing module": (["reactor", "dump", "no_such_module:x"], "error: no module named"),
    "reactor dump missing name": (["reactor", "dump", "reactor:no_such_name"], "error: reactor has no attribute"),
    "fingerprint --compare missing": (["routines", "fingerprint", "--compare", "/no/such/fp.json"],
                                      "error: No such file or directory: /no/such/fp.json"),
    "chart --from missing": (["routines", "chart", "--from", "/no/such/report.json"], "error: no such file"),
    "unknown command": (["routines", "nonsense"], "error: unknown command 'nonsense'"),
}
HELPS = {**{f"routines {c}": ["routines", c, "--help"] for c in ROUTINES},
         "routines": ["routines", "--help"], "reactor dump": ["reactor", "dump", "--help"],
         "fuzz": ["fuzz", "--help"]}
BAR = ("\r", "%|", "\u2588", "it/s]")  # what a tqdm bar leaves in a stream


def _env():
    return dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p]))


@pytest.fixture(scope="module")
def quick_runs():
    """Every quick command of this module, run concurrently: key -> CompletedProcess."""
    jobs = {}
    for table in (BAD_NUMBERS, USER_ERRORS):
        for key, (argv, _) in table.items():
            jobs[key] = argv
    for key, argv in HELPS.items():
        jobs["help " + key] = argv
    procs = {k: subprocess.Popen([PY, "-m", *argv], cwd=ROOT, env=_env(), stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True) for k, argv in jobs.items()}
    out = {}
    for k, p in procs.items():
        stdout, stderr = p.communicate(timeout=60)
        out[k] = subprocess.CompletedProcess(p.args, p.returncode, stdout, stderr)
    return out


@pytest.mark.parametrize("key", list(BAD_NUMBERS))
def test_a_bad_number_is_one_argparse_line(quick_runs, key):
    r = quick_runs[key]
    assert r.returncode == 2, r.stderr
    assert "Traceback" not in r.stderr and r.stdout == ""
    lines = r.stderr.splitlines()
    assert len(lines) == 1 and ": error: " in lines[0] and BAD_NUMBERS[key][1] in lines[0], r.stderr


@pytest.mark.parametrize("key", list(USER_ERRORS))
def test_a_users_mistake_is_one_error_line(quick_runs, key):
    r = quick_runs[key]
    assert r.returncode == 2, r.stderr
    lines = r.stderr.splitlines()
    assert len(lines) == 1 and USER_ERRORS[key][1] in lines[0], r.stderr
    assert "error: " in lines[0] and "Traceback" not in r.stderr and "<frozen" not in r.stderr


@pytest.mark.parametrize("key", list(HELPS))
def test_help_shows_an_example(quick_runs, key):
    r = quick_runs["help " + key]
    assert r.returncode == 0 and r.stderr == "", r.stderr
    assert "example" in r.stdout.lower()
    examples = r.stdout.split("examples:", 1)[1].splitlines()[1]
    assert examples.strip().startswith("python -m "), examples


# -- progress bars: only on a terminal --------------------------------------------------

TINY_REPORT = ["routines", "report", "--quick", "--functions", "exp2", "--sizes", "L1", "--rounds", "1",
               "--samples", "1024", "--no-threads"]


def _on_a_terminal(argv, cwd):
    """Run with stderr on a pseudo-terminal (100 columns); return (status, what stderr got)."""
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))
    p = subprocess.Popen([PY, "-m", *argv], cwd=cwd, env=_env(), stdout=subprocess.DEVNULL, stderr=slave)
    os.close(slave)
    got = b""
    while True:
        ready, _, _ = select.select([master], [], [], 60)
        if not ready:
            break
        try:
            chunk = os.read(master, 65536)
        except OSError:  # the terminal's other side is closed: the command is done
            break
        if not chunk:
            break
        got += chunk
    os.close(master)
    return p.wait(timeout=60), got.decode(errors="replace")


def test_no_progress_bar_in_a_redirected_log_and_bars_on_a_terminal(tmp_path):
    piped = subprocess.Popen([PY, "-m", *TINY_REPORT, "--out", str(tmp_path / "a")], cwd=ROOT, env=_env(),
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    status, terminal = _on_a_terminal(TINY_REPORT + ["--out", str(tmp_path / "b")], ROOT)
    quiet_status, quiet = _on_a_terminal(TINY_REPORT + ["--quiet", "--out", str(tmp_path / "c")], ROOT)
    out, err = piped.communicate(timeout=60)
    assert piped.returncode == 0, err
    assert "exp2" in out and "wrote" in err
    assert not [b for b in BAR if b in out + err], err
    assert status == 0 and "%|" in terminal and "\r" in terminal  # the control: a terminal gets bars
    assert quiet_status == 0 and "%|" not in quiet and "wrote" in quiet  # ... unless --quiet


# -- Ctrl-C and closed pipes ------------------------------------------------------------

def _stat(pid: int) -> list[str]:
    """The fields of /proc/PID/stat after the command name (state, parent, ...); [] once gone."""
    try:
        return pathlib.Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except (OSError, IndexError):
        return []


def _children(pid: int) -> list[int]:
    """The processes whose parent is ``pid``."""
    return [int(d.name) for d in pathlib.Path("/proc").glob("[0-9]*") if _stat(int(d.name))[1:2] == [str(pid)]]


def _alive(pid: int) -> bool:
    return _stat(pid)[:1] not in ([], ["Z"], ["X"])


def _interrupt(argv, *, group: bool):
    """Start a command that works in worker processes; once it has started them (its work is
    under way, whatever the machine's load), send it Ctrl-C; return (status, stderr)."""
    p = subprocess.Popen([PY, "-m", *argv], cwd=ROOT, env=_env(), stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        deadline = time.monotonic() + 120
        while not _children(p.pid):
            assert p.poll() is None, p.communicate()
            assert time.monotonic() < deadline, "the command started no worker in 120 s"
            time.sleep(0.05)
        workers = _children(p.pid)
        if group:  # as Ctrl-C in a terminal: the whole process group (the workers too)
            os.killpg(p.pid, signal.SIGINT)
        else:
            p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=120)  # bounded: an exhaustive sweep alone takes longer
    finally:  # a failed check leaves nothing running
        for pid in [p.pid] + _children(p.pid):
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
        p.wait(timeout=60)
    deadline = time.monotonic() + 30
    while any(map(_alive, workers)) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not any(map(_alive, workers)), "a worker outlived the interrupted command"
    return p.returncode, err


@pytest.mark.parametrize("group", [False, True], ids=["sigint", "ctrl-c-to-the-group"])
def test_interrupting_an_exhaustive_sweep_is_one_line_and_status_130(group):
    status, err = _interrupt(["routines", "accuracy", "exp2", "--exhaustive"], group=group)
    assert status == 130, err
    assert err == "interrupted\n", err


def test_interrupting_the_fuzzer_is_one_line_and_status_130():
    status, err = _interrupt(["fuzz", "--budget", "100000"], group=True)
    assert status == 130 and err == "interrupted\n", err  # its worker (a session of its own) ended too


@pytest.mark.parametrize("argv", [["routines", "specials"], ["routines", "--help"],
                                  ["reactor", "dump", "examples/custom_routine.py:falloff", "--what", "ir"]],
                         ids=lambda a: " ".join(a[:2]))
def test_a_closed_pipe_ends_quietly(argv):
    """As ``python -m routines specials | head``, with the reader gone before the first line."""
    p = subprocess.Popen([PY, "-m", *argv], cwd=ROOT, env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    p.stdout.close()
    err = p.stderr.read().decode()
    assert p.wait(timeout=60) in (0, 141) and err == "", err


# -- the shared pieces, in process ------------------------------------------------------

def test_argument_types():
    from routines.cli import int_type, non_negative_int, positive_int, power_of_two

    assert positive_int("7") == 7 and non_negative_int("0") == 0 and power_of_two("64") == 64
    for parse, text, message in [(positive_int, "-5", "must be a positive integer, not -5"),
                                 (positive_int, "0", "must be a positive integer, not 0"),
                                 (non_negative_int, "-1", "must be a non-negative integer, not -1"),
                                 (power_of_two, "48", "must be a power of two, not 48"),
                                 (power_of_two, "0", "must be a power of two, not 0"),
                                 (int_type(15), "3", "must be an integer >= 15, not 3"),
                                 (int_type(1, 4), "5", "must be an integer from 1 to 4, not 5"),
                                 (positive_int, "2.5", "invalid int value: '2.5'")]:
        with pytest.raises(argparse.ArgumentTypeError, match=message):
            parse(text)


def test_parser_errors_are_one_line_and_help_has_examples(capsys):
    from routines.cli import parser, positive_int

    p = parser("demo", "A demo.", ("--n 3",))
    p.add_argument("--n", type=positive_int)
    with pytest.raises(SystemExit) as exc:
        p.parse_args(["--n", "-5"])
    assert exc.value.code == 2
    assert capsys.readouterr().err == ("python -m routines demo: error: argument --n: "
                                       "must be a positive integer, not -5\n")
    assert "examples:\n  python -m routines demo --n 3" in p.format_help()


def test_run_turns_what_a_user_causes_into_one_line(capsys):
    from reactor import ReactorError
    from routines.cli import CommandError, run

    def raising(exc):
        def main(argv):
            raise exc
        return main

    cases = [(ReactorError("bad width", location=("<frozen runpy>", 88)), 2, "error: bad width\n"),
             (ReactorError("bad", location=(__file__, 1)), 2, f"error: bad (at {__file__}:1)\n"),
             (CommandError("no such thing"), 2, "error: no such thing\n"),
             (FileNotFoundError(2, "No such file or directory", "/x.json"), 2,
              "error: No such file or directory: /x.json\n"),
             (KeyboardInterrupt(), 130, "interrupted\n")]
    for exc, status, err in cases:
        assert run(raising(exc), []) == status
        assert capsys.readouterr().err == err
    assert run(lambda argv: len(argv), ["a", "b"]) == 2
    with pytest.raises(ZeroDivisionError):  # a bug stays a traceback
        run(raising(ZeroDivisionError()), [])
