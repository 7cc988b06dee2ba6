"""``python -m reactor dump TARGET [--what ir|opt|asm] [--fma on|off] [--width N] [--target T]``

TARGET names what to print:
  FILE.py:NAME           a Function or @kernel ufunc defined in a user's file
  package.module:NAME    the same, from an importable module
(the routine library has its own: ``python -m routines dump NAME``).
"""
from __future__ import annotations

import argparse
import sys

from .build import options
from .cli import add_build_arguments, build_options, load, text
from .errors import ReactorError


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m reactor", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    dump = sub.add_parser("dump", help="print the IR, optimized IR or assembly of a Function or kernel")
    dump.add_argument("target")
    add_build_arguments(dump)
    args = parser.parse_args(argv)
    try:
        with options(**build_options(args)):
            print(text(load(args.target), args.what))
    except ReactorError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
