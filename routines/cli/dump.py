"""``python -m routines dump NAME [--precision relaxed|full|faithful|correct] [--what ir|opt|asm] [--fma on|off] ...``

Prints the IR, optimized IR or assembly of a routine's ready-made kernel
(``routines.jit(NAME, ...)``), e.g. ``python -m routines dump exp2 --fma off``.
"""
from __future__ import annotations

from reactor.cli import add_build_arguments, build_options, text

from .. import NAMES, jit
from ..base import LADDER
from . import CommandError, parser as command_parser


def main(argv: list[str]) -> int:
    parser = command_parser("dump", __doc__, ("exp2 --fma off", "pow --precision relaxed --what ir",
                                              "log2 --what opt --width 8 --target avx2"))
    parser.add_argument("name", choices=NAMES)
    parser.add_argument("--precision", choices=LADDER, default="full")
    add_build_arguments(parser)
    args = parser.parse_args(argv)
    opts = build_options(args)
    if opts["opt"] is not None:  # the ready-made kernels are built once, at the library's level
        raise CommandError("--opt is not a setting of the routines' kernels (python -m reactor dump has it)")
    print(text(jit(args.name, precision=args.precision, fma=opts["fma"], width=opts["width"],
                   target=opts["target"]), args.what, args.everything))
    return 0
