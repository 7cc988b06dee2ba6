"""Command-line pieces shared by ``python -m reactor`` and the command lines of libraries
built on reactor (``python -m routines dump``): loading a user's object, printing its
code, and the options that choose a build."""
from __future__ import annotations

import importlib
import importlib.util
import os

from .errors import ReactorError
from .ir.types import WIDTHS
from .targets import TARGETS


def load(spec: str):
    """The object ``NAME`` of ``FILE.py:NAME`` or ``package.module:NAME``."""
    if ":" not in spec:
        raise ReactorError(f"dump target must be FILE.py:NAME or module:NAME, not {spec!r}")
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


def text(obj, what: str) -> str:
    """The IR ("ir"), optimized IR ("opt") or assembly ("asm") of a Function or kernel ufunc."""
    import numpy as np

    from .kernels.kernel import kernel_of
    from .runtime.function import Function

    if isinstance(obj, Function):
        item = obj.compile()
    elif isinstance(obj, np.ufunc):
        item = kernel_of(obj)
    else:
        raise ReactorError(f"{obj!r} is neither a reactor Function nor a reactor kernel")
    return {"ir": item.ir, "opt": item.optimized_ir, "asm": item.assembly}[what]


def add_build_arguments(parser) -> None:
    """The options of ``dump`` that choose the build (shared with ``python -m routines dump``)."""
    parser.add_argument("--what", choices=("ir", "opt", "asm"), default="asm")
    parser.add_argument("--fma", choices=("on", "off"))
    parser.add_argument("--width", type=int, choices=WIDTHS)
    parser.add_argument("--target", dest="cpu", choices=TARGETS, help="code-generation target")
    parser.add_argument("--opt", type=int, choices=(0, 1, 2, 3))


def build_options(args) -> dict:
    return {"fma": None if args.fma is None else args.fma == "on", "width": args.width,
            "target": args.cpu, "opt": args.opt}
