"""What every routine builder shares: argument checks and the FMA override.

A routine builder (``exp2(x, precision="full", fma=None)`` ...) is called while
a reactor Function or kernel is being built. It takes a Float value of any
width (or a Python number), emits inline IR and returns a Float of the same
width. ``fma=None`` keeps the enclosing build's FMA setting.
"""
from __future__ import annotations

import functools

from reactor import Float, Value, fma_mode
from reactor.errors import DSLTypeError, ReactorError

PRECISIONS = ("full", "relaxed")


def float_value(x, routine: str, arg: str = "x") -> Value:
    """``x`` as a DSL Float value (Python numbers become scalar constants)."""
    if isinstance(x, Value):
        if x.kind.name != "Float":
            raise DSLTypeError(f"{routine}: argument '{arg}' must be a Float value (any width), "
                               f"not {x.vtype.name}")
        return x
    if isinstance(x, (int, float)) and not isinstance(x, bool):
        return Float(float(x))
    raise DSLTypeError(f"{routine}: argument '{arg}' must be a Float value or a number, not {x!r}")


def check_precision(precision: str, routine: str) -> str:
    if precision not in PRECISIONS:
        raise ReactorError(f"{routine}: precision must be 'full' or 'relaxed', not {precision!r}")
    return precision


def routine(fn):
    """Decorate a builder ``fn(x..., precision, fma)``: validate, then emit under the FMA override."""
    @functools.wraps(fn)
    def build(*args, precision: str = "full", fma: bool | None = None, **kwargs):
        check_precision(precision, fn.__name__)
        with fma_mode(fma):
            return fn(*args, precision=precision, **kwargs)

    return build
