"""``python -m routines dump NAME [--precision full|relaxed] [--what ir|opt|asm] [--fma on|off] ...``

Prints the IR, optimized IR or assembly of a routine's ready-made kernel
(``routines.jit(NAME, ...)``), e.g. ``python -m routines dump exp2 --fma off``.
"""
from __future__ import annotations

import argparse
import sys

from reactor import ReactorError
from reactor.cli import add_build_arguments, build_options, text

from .. import NAMES, jit
from ..base import PRECISIONS


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m routines dump", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("name", choices=NAMES)
    parser.add_argument("--precision", choices=PRECISIONS, default="full")
    add_build_arguments(parser)
    args = parser.parse_args(argv)
    opts = build_options(args)
    try:
        print(text(jit(args.name, precision=args.precision, fma=opts["fma"], width=opts["width"],
                       target=opts["target"]), args.what))
    except ReactorError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0
