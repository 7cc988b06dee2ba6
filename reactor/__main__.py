"""``python -m reactor dump TARGET [--what ir|opt|asm] [--fma on|off] [--width N] [--target T]``

TARGET names what to print:
  FILE.py:NAME           a Function or @kernel ufunc defined in a user's file
  package.module:NAME    the same, from an importable module
(the routine library has its own: ``python -m routines dump NAME``).
"""
from __future__ import annotations

import sys

from .build import options
from .cli import ArgumentParser, add_build_arguments, build_options, load, run, text

EXAMPLES = ("python -m reactor dump examples/custom_routine.py:falloff --what ir",
            "python -m reactor dump examples/custom_routine.py:falloff --fma off --width 8 --target avx2")


def _parser() -> ArgumentParser:
    parser = ArgumentParser(prog="python -m reactor", description=__doc__, examples=EXAMPLES)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    dump = sub.add_parser("dump", help="print the IR, optimized IR or assembly of a Function or kernel",
                          description=__doc__, examples=EXAMPLES)
    dump.add_argument("target", help="FILE.py:NAME or package.module:NAME")
    add_build_arguments(dump)
    return parser


def _main(argv: list[str]) -> int:
    args = _parser().parse_args(argv)
    with options(**build_options(args)):
        print(text(load(args.target), args.what))
    return 0


def main(argv: list[str] | None = None) -> int:
    """The command line; errors a user causes are one line and exit status 2 (see reactor.cli.run)."""
    return run(_main, argv)


if __name__ == "__main__":
    sys.exit(main())
