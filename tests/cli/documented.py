"""Every command line the project documents, and a check that its command parses it.

Where commands are documented: README.md, docs/**/*.md and examples/README.md (code
blocks and inline code), and the ``examples:`` of every command's ``--help``. A synopsis
is made concrete: ``[optional parts]`` are taken both left out and put in, ``a|b|c`` and
``{a,b,c}`` give one command per choice, ``...`` (more of the same) is dropped and the
placeholders of :data:`PLACEHOLDERS` become real values; shell pieces (``| head``,
``> file``, ``&&``, ``# comment``, ``VAR=value`` before the command) are cut off.

:func:`check` runs a command in this process as ``python`` would run it (``runpy``, the
same ``sys.argv``), up to the end of its argument parsing: argparse's ``parse_args`` is
replaced by one that parses and then stops the command (:class:`Parsed`), so no work is
done; ``--help`` counts as parsed when it exits with status 0.

Run as a script (``python tests/cli/documented.py``) it checks them all with the
interpreter that runs it and prints one line per failure (exit status 1 if any): the
suite runs it so under every Python the project supports that the machine has.
"""
from __future__ import annotations

import argparse
import contextlib
import io
import itertools
import pathlib
import re
import runpy
import shlex
import sys
import warnings
from collections.abc import Iterator

ROOT = pathlib.Path(__file__).resolve().parents[2]
DOCS = ["README.md", "examples/README.md", "docs/**/*.md"]
#: a documented placeholder -> the value a check uses for it
PLACEHOLDERS = {
    "F": "exp2", "W": "1", "N": "16", "S": "7", "GLOB": "exp2*", "DEGREE": "3", "XMIN:XMAX": "0:1",
    "TARGET": "examples/custom_routine.py:falloff", "FILE.py:NAME": "examples/custom_routine.py:falloff",
    "OUT": "out/falloff.html", "OUT.html": "out/falloff.html", "PLAN.json": "out/plan.json", "FILE": "out/x.json",
    "KEY=VALUE": "fma=off", "NAME=DOMAIN": "x=unorm8", "FORMAT": "unorm8", "T": "avx2",
}
#: python -m routines COMMAND: every command
ROUTINES_COMMANDS = ("remez", "specials", "accuracy", "bench", "zoo", "chart", "report", "docs", "search",
                     "fingerprint", "crosstarget", "dump", "pixels", "ladder")
#: the commands whose --help examples are documented command lines too
HELPS = ([["-m", "routines", "--help"]] + [["-m", "routines", c, "--help"] for c in ROUTINES_COMMANDS]
         + [["-m", "reactor", c, "--help"] for c in ("dump", "explain", "plan", "cache")]
         + [["-m", "fuzz", "--help"], ["-m", "fuzz.memcheck", "--help"]])
SHELL_ENDS = {"|", "||", ">", ">>", "2>&1", "&&", ";", "<"}
NOT_OURS = {"pytest", "pip"}  # python -m pytest (the suite itself), python -m pip


class Parsed(BaseException):
    """Raised by the replaced ``parse_args`` once a command's arguments parsed."""


# -- finding command lines --------------------------------------------------------------

def documented() -> dict[str, list[str]]:
    """Every concrete command line of the documentation: ``"python -m ..."`` -> where it is
    documented (``file:line``, or ``--help of ...``)."""
    found: dict[str, list[str]] = {}
    for pattern in DOCS:
        for path in sorted(ROOT.glob(pattern)):
            for line_no, text in _command_texts(path.read_text()):
                for argv in concrete(text):
                    found.setdefault(shlex.join(argv), []).append(f"{path.relative_to(ROOT)}:{line_no}")
    for argv in HELPS:
        for text in _help_examples(argv):
            for concrete_argv in concrete(text):
                found.setdefault(shlex.join(concrete_argv), []).append(f"--help of {' '.join(argv[:-1])}")
    return found


def _command_texts(markdown: str) -> Iterator[tuple[int, str]]:
    """(line number, text) of each shell command of a markdown page that runs python."""
    fenced = False
    for no, line in enumerate(markdown.splitlines(), 1):
        if line.lstrip().startswith("```"):
            fenced = not fenced
            continue
        pieces = [line] if fenced else re.findall(r"``?([^`]+)``?", line)
        for piece in pieces:
            for part in re.split(r"\s&&\s", piece.replace("\\|", "|")):
                m = re.search(r"(?:^|\s)((?:[A-Z_]+=\S+\s+)*python3? \S.*)$", part.strip())
                if m:
                    yield no, m.group(1)


def _help_examples(argv: list[str]) -> list[str]:
    out = io.StringIO()
    problem = check(argv, out)
    if problem:
        raise AssertionError(f"python {' '.join(argv)}: {problem}")
    text = out.getvalue()
    if "examples:" not in text:
        return []
    lines = text.split("examples:", 1)[1].splitlines()[1:]
    return [x.strip() for x in itertools.takewhile(lambda x: x.startswith("  "), lines)]


def concrete(text: str) -> list[list[str]]:
    """The concrete argument lists (after ``python``) that a documented command line stands for."""
    try:
        tokens = shlex.split(text, comments=True)
    except ValueError:  # an unbalanced quote: an excerpt cut by the page, not a command
        return []
    while tokens and re.fullmatch(r"[A-Z_][A-Z0-9_]*=.*", tokens[0]):  # VAR=value python ...
        tokens.pop(0)
    if not tokens or tokens[0] not in ("python", "python3"):
        return []
    tokens = list(itertools.takewhile(lambda t: t not in SHELL_ENDS, tokens[1:]))
    if not tokens or (tokens[0] == "-m" and tokens[1:2] and tokens[1] in NOT_OURS):
        return []
    if tokens[-1] == "..." and not [t for t in tokens[:-1] if t.startswith("-") and t != "-m"]:
        tokens[-1] = "--help"  # "python -m routines remez ...": a mention of the command, not a use
    items = _optional_groups(tokens)
    lines: list[list[str]] = []
    for with_options in (False, True):
        kept = [t for t, group in items if group is None or with_options]
        for combo in itertools.product(*map(_alternatives, kept)):
            argv = [t for t in combo if t is not None]
            if argv not in lines:
                lines.append(argv)
    return lines


def _optional_groups(tokens: list[str]) -> list[tuple]:
    """Each token with the ``[...]`` group it is in: (token, group number or None)."""
    out, group, next_group = [], None, 0
    for t in tokens:
        if t.startswith("[") and group is None:
            group, next_group = next_group, next_group + 1
            t = t[1:]
        closes = group is not None and t.endswith("]")
        out.append((t.rstrip("]") if closes else t, group))
        if closes:
            group = None
    return out


def _alternatives(token: str) -> list:
    """The values one token stands for (None: none, as ``...``)."""
    if token in ("...", ""):
        values: list = [None]
    elif re.fullmatch(r"\{[^{}]+\}", token):
        values = token[1:-1].split(",")
    elif "|" in token and re.fullmatch(r"[\w.:=,+\-|]+", token):
        values = token.split("|")
    else:
        values = [token]
    return [PLACEHOLDERS.get(v, v) if v is not None else None for v in values]


# -- checking one command line ----------------------------------------------------------

def check(argv: list[str], out: io.StringIO | None = None) -> str | None:
    """Run ``python ARGV`` here up to the end of its argument parsing (what it prints goes to
    ``out``): None if it parsed, printed its help, or, taking no arguments, ran to its end with
    status 0; else what went wrong (argparse's message, the exception)."""
    argv = _settle(argv)
    if argv is None:
        return None
    err = io.StringIO()
    saved = argparse.ArgumentParser.parse_args, sys.argv[:], sys.path[:]

    def parse_then_stop(self, args=None, namespace=None):
        saved[0](self, args, namespace)
        raise Parsed()

    argparse.ArgumentParser.parse_args = parse_then_stop  # type: ignore[method-assign]
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out or io.StringIO()), \
                warnings.catch_warnings():
            # a module run again (reactor.__main__ after the first check): runpy says so; harmless here
            warnings.filterwarnings("ignore", "'.*' found in sys.modules", RuntimeWarning)
            if argv[0] == "-m":
                sys.argv = [argv[1]] + argv[2:]
                runpy.run_module(argv[1], run_name="__main__", alter_sys=True)
            else:
                script = ROOT / argv[0]
                if not script.is_file():
                    return f"no such script: {argv[0]}"
                sys.argv = [str(script)] + argv[1:]
                sys.path.insert(0, str(script.parent))
                runpy.run_path(str(script), run_name="__main__")
        return None  # a command without arguments to parse: it ran
    except Parsed:
        return None
    except SystemExit as exc:
        return None if exc.code in (0, None) else (err.getvalue().strip() or f"exit status {exc.code}")
    except Exception as exc:  # noqa: BLE001 - reported as the command's failure
        return f"{type(exc).__name__}: {exc}"
    finally:
        argparse.ArgumentParser.parse_args = saved[0]  # type: ignore[method-assign]
        sys.argv[:], sys.path[:] = saved[1], saved[2]


def _settle(argv: list[str]) -> list[str] | None:
    """``argv`` with its remaining generic names made concrete; None: nothing to check."""
    if argv[:2] == ["-m", "routines"] and argv[2:3] == ["COMMAND"]:
        return None  # the synopsis of every command: each is checked by name (HELPS)
    if "NAME" in argv[0]:
        return None  # python examples/NAME.py: every example is listed by name too
    return argv


def main() -> int:
    """Check every documented command line; print each failure; status 1 if any."""
    failures = 0
    for line, where in documented().items():
        problem = check(shlex.split(line))
        if problem:
            failures += 1
            print(f"python {line}  ({', '.join(where)}): {problem}")
    print(f"{len(documented())} documented command lines, {failures} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT))
    sys.exit(main())
