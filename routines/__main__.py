"""``python -m routines COMMAND ...``: the routine library's command line.

Commands: remez (fit a minimax polynomial), specials (print the special-value
tables of docs/specials.md), accuracy (measure a variant's error on the
compiled code), bench (time every variant against NumPy), zoo (the reference's
methods, its figures beside ours), chart (the cost/error chart), report (the
main job: every variant's accuracy and speed, the table, chart and JSON),
docs (write docs/routines/*.md from the measurements), fingerprint (a hash of
every variant's output bits, to prove a change left them alone), dump (the IR or
assembly of a routine's kernel).
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
    "dump": "routines.cli.dump",
}


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] in ("-h", "--help") or argv[0] not in COMMANDS:
        print(__doc__.strip(), file=sys.stderr if argv and argv[0] not in ("-h", "--help") else sys.stdout)
        print("\nusage: python -m routines {" + ",".join(COMMANDS) + "} [options]")
        return 0 if argv and argv[0] in ("-h", "--help") else 2
    import importlib
    return importlib.import_module(COMMANDS[argv[0]]).main(argv[1:])


if __name__ == "__main__":
    sys.exit(main())
