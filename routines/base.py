"""What every routine builder shares: argument checks and the precision and FMA overrides.

A routine builder (``exp2(x, precision=None, fma=None)`` ...) is called while
a reactor Function or kernel is being built. It takes a Float value of any
width (or a Python number), emits inline IR and returns a Float of the same
width. ``precision=None`` follows the enclosing build (``reactor.precision``
blocks, the kernel's ``precision=`` option; "full" by default) and ``fma=None``
keeps the enclosing build's FMA setting. A build's ``sites`` (a ``reactor.plan``
Plan) override both at the call sites they name.
"""
from __future__ import annotations

import functools
import os
import typing

import reactor
from reactor import DSLTypeError, Float, Precision, Value, fma_mode

reactor.hide_frames_of(os.path.dirname(__file__))  # errors point at the caller's line

#: The precisions the routines are built in (reactor's Precision values).
PRECISIONS = tuple(p.value for p in Precision)


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


def check_precision(precision, routine: str) -> Precision:
    """``precision`` as a Precision (None: the build's); a clear error naming ``routine`` otherwise."""
    if precision is None:
        return reactor.build_settings().precision
    try:
        return Precision.of(precision)
    except reactor.ReactorError:
        names = " or ".join(repr(p) for p in PRECISIONS)
        raise reactor.ReactorError(f"{routine}: precision must be {names}, not {precision!r}") from None


def routine(fn: typing.Callable[..., Value]) -> typing.Callable[..., Value]:
    """Decorate a builder ``fn(x..., precision)``: validate, then emit under the FMA override."""
    @functools.wraps(fn)
    def build(*args: typing.Any, precision: typing.Any = None, fma: bool | None = None,
              **kwargs: typing.Any) -> Value:
        chosen = reactor.site_choice(fn.__name__)  # a plan's choice for this call site wins
        if chosen is not None:
            precision, fma = chosen.precision, chosen.fma if chosen.fma is not None else fma
        level = check_precision(precision, fn.__name__)
        with fma_mode(fma), reactor.precision(level), reactor.routine_call(fn.__name__):
            return fn(*args, precision=level, **kwargs)

    return build
