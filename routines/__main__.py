"""``python -m routines COMMAND ...``: the routine library's command line.

Commands: remez (fit a minimax polynomial), specials (print the special-value
tables of docs/specials.md), accuracy (measure a variant's error on the
compiled code), bench (time every variant against NumPy), zoo (the reference's
methods, its figures beside ours), chart (the cost/error chart),
report (every variant's accuracy and speed, a one-screen summary, chart and JSON),
docs (write docs/routines/*.md from the measurements), search (the variant
search: the Pareto set of cost vs error), fingerprint (a hash of every
variant's output bits, to prove a change left them alone), crosstarget (every
variant's output bits on each target, aarch64 under qemu, against the host's), dump (the IR or
assembly of a routine's kernel), pixels (prove the sRGB8 encode exact, time it), ladder (the
faithful and correct tiers against a correctly rounded reference, every input with --exhaustive),
hardcases (the correct tier's tables of inputs near a rounding boundary), continuum (the
variants between relaxed and full, their error and cost). ``python -m routines COMMAND --help`` tells more.

Exit status: 0 done, 1 a finding (a variant does not conform, fingerprints
differ), 2 a usage error, 130 interrupted.
"""
from __future__ import annotations

import sys

COMMANDS = {
    "remez": "routines.remez.cli",
    "specials": "routines.cli.specials",
    "accuracy": "routines.cli.accuracy",
    "bench": "routines.cli.bench",
    "zoo": "routines.cli.zoo",
    "chart": "routines.cli.chart",
    "report": "routines.cli.report",
    "docs": "routines.cli.docs",
    "search": "routines.cli.search",
    "fingerprint": "routines.lab.fingerprint",
    "crosstarget": "routines.lab.crosstarget",
    "dump": "routines.cli.dump",
    "pixels": "routines.cli.pixels",
    "ladder": "routines.cli.ladder",
    "hardcases": "routines.cli.hardcases",
    "continuum": "routines.cli.continuum",
}
#: what the laboratory needs beyond the library (the ``lab`` extra)
LAB_DEPENDENCIES = ("mpmath", "tqdm", "matplotlib")
USAGE = "usage: python -m routines [--version] {" + ",".join(COMMANDS) + "} [options]"
EXAMPLES = """examples:
  python -m routines report --quick
  python -m routines accuracy exp2 --precision relaxed --fma off
  python -m routines dump exp2 --what ir"""


def main(argv: list[str] | None = None) -> int:
    """Run ``python -m routines COMMAND ...`` through :func:`routines.cli.run`."""
    from .cli import run

    return run(_dispatch, argv)


def _dispatch(argv: list[str]) -> int:
    if argv and argv[0] in ("-h", "--help"):
        print(f"{USAGE}\n\n{__doc__.strip()}\n\n{EXAMPLES}")
        return 0
    if argv and argv[0] == "--version":
        from reactor import __version__
        print(f"python -m routines (reactor-simd) {__version__}")
        return 0
    if not argv or argv[0] not in COMMANDS:
        what = f"unknown command {argv[0]!r}" if argv else "a command is required"
        print(f"python -m routines: error: {what} (choose from {', '.join(COMMANDS)}; --help tells more)",
              file=sys.stderr)
        return 2
    import importlib

    try:
        return importlib.import_module(COMMANDS[argv[0]]).main(argv[1:])
    except ModuleNotFoundError as exc:
        missing = (exc.name or "").split(".")[0]
        if missing not in LAB_DEPENDENCIES:
            raise
        from .cli import CommandError
        raise CommandError(f"python -m routines {argv[0]} needs {missing}, part of the laboratory's extra: "
                           "pip install 'reactor-simd[lab]'") from None


if __name__ == "__main__":
    sys.exit(main())
