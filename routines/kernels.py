"""Ready-made NumPy ufuncs for every routine variant: ``jit(name, precision, fma, width)``."""
from __future__ import annotations

import functools

from reactor import Float, kernel
from reactor.errors import ReactorError

from . import exponential as _exp2
from . import logarithm as _log2
from . import power as _power
from . import reciprocal as _recip
from .base import check_precision

UNARY = {
    "exp2": _exp2.exp2, "exp": _exp2.exp, "log2": _log2.log2, "log": _log2.log,
    "rcp": _recip.rcp, "rsqrt": _recip.rsqrt, "sqrt": _recip.sqrt,
}
BINARY = {"pow": _power.pow}
NAMES = tuple(UNARY) + tuple(BINARY)


def jit(name: str, precision: str = "full", fma: bool | None = True, width: int | None = None,
        target: str | None = None):
    """The ufunc computing routine ``name`` ("exp2", "log2", "pow", "exp", "log",
    "rcp", "rsqrt", "sqrt") in ``precision`` ("full"/"relaxed"), with FMA on or
    off (None: the target's capability), at SIMD ``width`` (None: the target's
    natural width). Built once per variant and process (and cached on disk)."""
    if name not in NAMES:
        raise ReactorError(f"unknown routine {name!r}; choose one of {', '.join(NAMES)}")
    check_precision(precision, name)
    return _build(name, precision, fma, width, target)


@functools.lru_cache(maxsize=None)
def _build(name, precision, fma, width, target):
    tag = f"{name}_{precision}_{'fma' if fma else 'nofma'}" + (f"_w{width}" if width else "")
    doc = f"{name} ({precision} precision, FMA {'on' if fma else 'off'}), float32."
    if name in BINARY:
        builder = BINARY[name]

        def body(x: Float, y: Float) -> Float:
            return builder(x, y, precision=precision)
    else:
        builder = UNARY[name]

        def body(x: Float) -> Float:
            return builder(x, precision=precision)
    body.__doc__ = doc
    return kernel(body, name=tag, fma=fma, width=width, target=target)
