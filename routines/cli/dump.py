"""``python -m routines dump NAME [--precision relaxed|full|faithful|correct] [--what ir|opt|asm] [--fma on|off] ...``

Prints the IR, optimized IR or assembly of a routine's ready-made kernel
(``routines.jit(NAME, ...)``), e.g. ``python -m routines dump exp2 --fma off``.

The assembly (``--what asm``, the default) starts with the routine's core: the vector loop,
W lanes an iteration, each instruction with the constants it reads shown by value (from the
constant pool, ``.LCPI0_3 = 0.055503443f (0x3d635794)``, also where a constant was loaded into
a register before the loop) and the step of the algorithm it belongs to (range reduction,
the polynomial named from routines' tables with its scheme and degree, reconstruction,
special cases: ``routines.cli.annotate`` says how each is recognised). The whole loop
function follows, its constants annotated; ``--raw`` prints the listing exactly as LLVM
wrote it, ``--all`` the whole module.
"""
from __future__ import annotations

import reactor
from reactor.cli import add_build_arguments, build_options, text

from .. import NAMES, jit
from .. import polynomials
from ..base import LADDER
from . import CommandError, annotate, parser as command_parser


def main(argv: list[str]) -> int:
    parser = command_parser("dump", __doc__, ("exp2 --fma off", "pow --precision relaxed --what ir",
                                              "log2 --what opt --width 8 --target avx2", "exp2 --raw"))
    parser.add_argument("name", choices=NAMES)
    parser.add_argument("--precision", choices=LADDER, default="full")
    parser.add_argument("--raw", action="store_true",
                        help="the assembly as LLVM wrote it (no core first, no values, no steps)")
    add_build_arguments(parser)
    args = parser.parse_args(argv)
    opts = build_options(args)
    if opts["opt"] is not None:  # the ready-made kernels are built once, at the library's level
        raise CommandError("--opt is not a setting of the routines' kernels (python -m reactor dump has it)")
    ufunc = jit(args.name, precision=args.precision, fma=opts["fma"], width=opts["width"], target=opts["target"])
    core = None if args.what != "asm" or args.raw or args.everything else core_text(ufunc)
    print(core if core is not None else text(ufunc, args.what, args.everything))
    return 0


def core_text(ufunc) -> str | None:
    """The annotated assembly of a kernel's loop function, its core first (see the module
    docstring); None when it has no vector loop to show (then the listing is printed as is)."""
    kern = reactor.kernel_of(ufunc)
    name = f"{kern.name}.loop"
    lines = annotate.function_lines(kern.assembly, name)
    known = [(p.name, p.values) for p in vars(polynomials).values() if isinstance(p, polynomials.Polynomial)]
    return annotate.render(lines, annotate.constant_pool(kern.assembly), known, name, kern.build.width)
