"""``python -m reactor dump TARGET [--what ir|opt|asm] [--fma on|off] [--width N] [--target T]``,
``python -m reactor explain TARGET [--html OUT] [--diff fma=off] [--plumbing]``

TARGET names what to print:
  FILE.py:NAME           a Function or @kernel ufunc defined in a user's file
  package.module:NAME    the same, from an importable module
(the routine library has its own: ``python -m routines dump NAME``).
"""
from __future__ import annotations

import sys

from .build import options
from .cli import ArgumentParser, add_build_arguments, build_options, load, run, text
from .errors import ReactorError

EXAMPLES = ("python -m reactor dump examples/custom_routine.py:falloff --what ir",
            "python -m reactor dump examples/custom_routine.py:falloff --fma off --width 8 --target avx2")


EXPLAIN = """python -m reactor explain TARGET [--html OUT.html] [--diff KEY=VALUE] [--plumbing] [build options]

Each Python line of a kernel or Function with the IR and the machine instructions it
became, the routines it called as their own groups, and its cost (operations by pipe,
share of the work, critical path) from the dataflow model; --diff compares with a
second build (fma=off, precision=relaxed, target=avx2, width=8 ...) line by line;
--html writes one self-contained page with three linked columns."""
EXPLAIN_EXAMPLES = ("python -m reactor explain examples/custom_routine.py:falloff",
                    "python -m reactor explain examples/custom_routine.py:falloff --diff fma=off --html falloff.html")


def _parser() -> ArgumentParser:
    parser = ArgumentParser(prog="python -m reactor", description=__doc__, examples=EXAMPLES)
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    dump = sub.add_parser("dump", help="print the IR, optimized IR or assembly of a Function or kernel",
                          description=__doc__, examples=EXAMPLES)
    dump.add_argument("target", help="FILE.py:NAME or package.module:NAME")
    add_build_arguments(dump)
    explain = sub.add_parser("explain", help="each source line with its IR, assembly and cost; diffs; HTML",
                             description=EXPLAIN, examples=EXPLAIN_EXAMPLES)
    explain.add_argument("target", help="FILE.py:NAME or package.module:NAME")
    explain.add_argument("--html", metavar="OUT", help="write the page to OUT (an .html file)")
    explain.add_argument("--diff", action="append", default=[], metavar="KEY=VALUE",
                         help="compare with a build that differs so (fma=off, precision=relaxed, target=avx2, "
                              "width=8, opt=2); repeatable")
    explain.add_argument("--plumbing", action="store_true", help="also the loop control, tail and dispatcher")
    explain.add_argument("--brief", action="store_true", help="per line totals only, no instructions")
    add_build_arguments(explain)
    explain.add_argument("--precision", help="full, relaxed (or GLSL's highp, mediump)")
    return parser


def _diff_options(specs: list[str]) -> dict:
    out: dict = {}
    for spec in specs:
        if "=" not in spec:
            raise ReactorError(f"--diff takes KEY=VALUE (fma=off, precision=relaxed, target=avx2), not {spec!r}")
        key, value = spec.split("=", 1)
        if key == "fma":
            out[key] = {"on": True, "off": False}.get(value)
            if out[key] is None:
                raise ReactorError(f"--diff fma= takes on or off, not {value!r}")
        elif key in ("width", "opt"):
            out[key] = int(value)
        elif key in ("precision", "target"):
            out[key] = value
        else:
            raise ReactorError(f"--diff: unknown setting {key!r} (fma, precision, target, width, opt)")
    return out


def _explain(args) -> int:
    from .explain import explain
    target = load(args.target)
    chosen = {k: v for k, v in build_options(args).items() if v is not None}
    if args.precision:
        chosen["precision"] = args.precision
    first = explain(target, plumbing=args.plumbing, **chosen)
    diff = None
    if args.diff:
        second = explain(target, plumbing=args.plumbing, **{**chosen, **_diff_options(args.diff)})
        diff = first.diff(second)
    print(first.text(instructions=not args.brief))
    if diff is not None:
        print("\n" + diff.text())
    if args.html:
        print(f"\nwrote {first.write_html(args.html, diff)}")
    return 0


def _main(argv: list[str]) -> int:
    args = _parser().parse_args(argv)
    if args.command == "explain":
        return _explain(args)
    with options(**build_options(args)):
        print(text(load(args.target), args.what))
    return 0


def main(argv: list[str] | None = None) -> int:
    """The command line; errors a user causes are one line and exit status 2 (see reactor.cli.run)."""
    return run(_main, argv)


if __name__ == "__main__":
    sys.exit(main())
