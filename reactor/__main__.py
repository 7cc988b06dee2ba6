"""``python -m reactor dump TARGET [--what ir|opt|asm] [--fma on|off] [--width N] [--target T]``
``python -m reactor fuzz --budget N [--seed S]`` (differential fuzzing; see docs/reliability.md)

TARGET names what to print:
  routines:NAME          a kernel of the routine library, e.g. routines:exp2
                         (with --precision full|relaxed)
  FILE.py:NAME           a Function or @kernel ufunc defined in a user's file
  package.module:NAME    the same, from an importable module
"""
from __future__ import annotations

import argparse
import importlib
import importlib.util
import os
import sys

from .errors import ReactorError
from .options import options


def _load(spec: str):
    if ":" not in spec:
        raise ReactorError(f"dump target must be FILE.py:NAME, module:NAME or routines:NAME, not {spec!r}")
    where, name = spec.rsplit(":", 1)
    if where.endswith(".py"):
        if not os.path.exists(where):
            raise ReactorError(f"no such file: {where}")
        mod_spec = importlib.util.spec_from_file_location("reactor_dump_target", where)
        module = importlib.util.module_from_spec(mod_spec)
        mod_spec.loader.exec_module(module)
    else:
        module = importlib.import_module(where)
    try:
        return getattr(module, name)
    except AttributeError:
        raise ReactorError(f"{where} has no attribute {name!r}") from None


def _text(obj, what: str, args) -> str:
    import numpy as np

    from .dsl.function import Function
    from .kernels.kernel import kernel_of

    if isinstance(obj, Function):
        item = obj.compile()
    elif isinstance(obj, np.ufunc):
        item = kernel_of(obj)
    else:
        raise ReactorError(f"{obj!r} is neither a reactor Function nor a reactor kernel")
    return {"ir": item.ir, "opt": item.optimized_ir, "asm": item.assembly}[what]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m reactor", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    dump = sub.add_parser("dump", help="print the IR, optimized IR or assembly of a routine or kernel")
    dump.add_argument("target")
    dump.add_argument("--what", choices=("ir", "opt", "asm"), default="asm")
    dump.add_argument("--fma", choices=("on", "off"))
    dump.add_argument("--width", type=int, choices=(1, 4, 8, 16))
    dump.add_argument("--target", dest="cpu", help="code-generation target: host, avx512, avx2, sse4")
    dump.add_argument("--precision", choices=("full", "relaxed"), default="full")
    dump.add_argument("--opt", type=int, choices=(0, 1, 2, 3))
    from .fuzz.runner import add_arguments as fuzz_arguments
    fuzz = sub.add_parser("fuzz", help="differential fuzzing of the DSL against NumPy (docs/reliability.md)")
    fuzz_arguments(fuzz)
    args = parser.parse_args(argv)
    if args.command == "fuzz":
        from .fuzz.runner import run as run_fuzz
        return run_fuzz(args)
    fma = None if args.fma is None else args.fma == "on"
    try:
        with options(fma=fma, width=args.width, target=args.cpu, opt=args.opt):
            if args.target.startswith("routines:"):
                import routines
                name = args.target.split(":", 1)[1]
                obj = routines.jit(name, precision=args.precision, fma=fma, width=args.width)
            else:
                obj = _load(args.target)
            print(_text(obj, args.what, args))
    except ReactorError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
