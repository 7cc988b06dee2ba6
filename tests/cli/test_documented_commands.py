"""Every command line shown in README.md, docs/, examples/README.md and the ``--help``
examples parses (``documented.py`` finds them and makes synopses concrete), under this
Python and under every other supported Python listed in REACTOR_TEST_PYTHONS (``.ci/run``
makes one environment each for 3.10 to 3.13 where the machine has them); and the cheap
commands, or a tiny form of them, run to the end."""
from __future__ import annotations

import os
import pathlib
import shlex
import subprocess
import sys

import pytest

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import documented  # noqa: E402

ROOT = documented.ROOT
LINES = documented.documented()
OTHER_PYTHONS = [p for p in os.environ.get("REACTOR_TEST_PYTHONS", "").split(os.pathsep) if p]
#: documented command -> the form that runs here (the same command on less work), with what it must print
RUNS = {
    "-m routines ladder --exhaustive": (["-m", "routines", "ladder", "exp2", "--precisions", "correct", "--fma", "on",
                                         "--json", "{tmp}/ladder.json"], "misrounded 0"),
    "-m routines specials": (["-m", "routines", "specials"], "exp2"),
    "-m reactor cache info": (["-m", "reactor", "cache", "info"], "directory"),
    "-m routines dump exp2 --what ir": (["-m", "routines", "dump", "exp2", "--what", "ir"], "define"),
    "-m reactor explain examples/custom_routine.py:falloff": (
        ["-m", "reactor", "explain", "examples/custom_routine.py:falloff"], "falloff"),
    "-m fuzz --budget 20 --in-process": (["-m", "fuzz", "--budget", "3", "--in-process"], "mismatches: 0"),
}


def test_the_documentation_shows_command_lines():
    """The finder works: the README's main job and the proof command are among them."""
    assert len(LINES) > 100
    assert "-m routines report" in LINES and "-m routines ladder --exhaustive" in LINES
    assert any(where.startswith("--help of") for places in LINES.values() for where in places)


@pytest.mark.parametrize("line", sorted(LINES))
def test_a_documented_command_line_parses(line):
    problem = documented.check(shlex.split(line))
    assert problem is None, f"python {line} (shown in {', '.join(LINES[line])}): {problem}"


def test_synopses_become_concrete_command_lines():
    lines = documented.concrete("python -m routines dump exp2 --what ir|opt [--fma off]  # a comment")
    assert lines == [["-m", "routines", "dump", "exp2", "--what", "ir"], ["-m", "routines", "dump", "exp2", "--what", "opt"],
                     ["-m", "routines", "dump", "exp2", "--what", "ir", "--fma", "off"],
                     ["-m", "routines", "dump", "exp2", "--what", "opt", "--fma", "off"]]
    assert documented.concrete("REACTOR_CACHE_DIR=/tmp/rc python -m reactor cache {info,clear} | head") == [
        ["-m", "reactor", "cache", "info"], ["-m", "reactor", "cache", "clear"]]
    assert documented.concrete("python -m fuzz --budget N [--seed S]")[-1] == ["-m", "fuzz", "--budget", "16",
                                                                             "--seed", "7"]
    assert documented.concrete("python -m routines remez ...") == [["-m", "routines", "remez", "--help"]]
    assert documented.concrete("python -m pytest -q") == [] and documented.concrete("pip install .") == []


def test_a_bad_command_line_is_reported():
    """The control: the check fails where argparse fails, and names the argument."""
    assert "invalid choice: 'sine'" in documented.check(["-m", "routines", "report", "--functions", "sine"])
    assert "no such script" in documented.check(["examples/no_such_example.py"])


@pytest.mark.parametrize("python", OTHER_PYTHONS or [None], ids=lambda p: os.path.basename(os.path.dirname(
    os.path.dirname(p))) if p else "none-listed")
def test_documented_command_lines_parse_under_every_supported_python(python):
    if python is None:
        pytest.skip("no other Python listed in REACTOR_TEST_PYTHONS (.ci/run lists 3.10 to 3.13 where present)")
    version = subprocess.run([python, "-c", "import sys; print(sys.version_info[:2] >= (3, 10))"],
                             capture_output=True, text=True, timeout=60)
    assert version.stdout.strip() == "True", f"{python} is not a supported Python (3.10 or newer)"
    r = subprocess.run([python, str(ROOT / "tests" / "cli" / "documented.py")], capture_output=True, text=True,
                       cwd=ROOT, timeout=600, env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert r.returncode == 0 and " 0 failed" in r.stdout, (r.stdout + r.stderr)[-4000:]


def test_cheap_documented_commands_run(tmp_path):
    """Each runs as a real process (all at once), exits 0 and prints what it is for."""
    for line in RUNS:
        assert line in LINES, f"{line} is no longer documented: update RUNS"
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    procs = {line: subprocess.Popen([sys.executable] + [a.format(tmp=tmp_path) for a in argv], cwd=ROOT, env=env,
                                    stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for line, (argv, _) in RUNS.items()}
    for line, p in procs.items():
        out, err = p.communicate(timeout=600)
        assert p.returncode == 0, f"python {line}: {err[-2000:]}"
        assert RUNS[line][1] in out, f"python {line}: {out[-2000:]}"
