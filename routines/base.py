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
from reactor import SHADER_TIERS, As, DSLTypeError, Float, Precision, Value, fma_mode
from reactor import split_precision

from . import continuum

reactor.hide_frames_of(os.path.dirname(__file__))  # errors point at the caller's line

#: The precisions every routine is built in: Vulkan's (reactor's shader tiers).
PRECISIONS = SHADER_TIERS

#: Every tier, least accurate first, and the routines that have the tiers beyond Vulkan's
#: (``routines.accurate``; sqrt and rcp are correctly rounded by the hardware).
LADDER = tuple(p.value for p in Precision)
BEYOND_VULKAN = {
    "exp2": ("faithful", "correct"), "exp": ("faithful", "correct"), "log2": ("faithful", "correct"),
    "log": ("faithful", "correct"), "pow": ("faithful", "correct"), "rcp": ("faithful", "correct"),
    "rsqrt": ("faithful", "correct"), "sqrt": ("faithful", "correct"),
    **{name: ("faithful", "correct") for name in ("sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh",
                                                   "cosh", "tanh")},
}


def tiers(routine_name: str) -> tuple[str, ...]:
    """The precisions ``routine_name`` can be built in, least accurate first."""
    return PRECISIONS + BEYOND_VULKAN.get(routine_name, ())


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
        names = ", ".join(repr(p) for p in tiers(routine))
        raise reactor.ReactorError(f"{routine}: precision must be one of {names}, not {precision!r}") from None


def check_tier(level: Precision, routine: str) -> Precision:
    """``level`` if ``routine`` has that tier; a clear error naming the tiers it has otherwise."""
    if level.value not in tiers(routine):
        names = ", ".join(repr(p) for p in tiers(routine))
        raise reactor.ReactorError(f"{routine} has no {level.value!r} precision; its precisions are {names}")
    return level


_V = typing.TypeVar("_V", bound=Value)


class Builder(typing.Protocol):
    """What ``@routine`` makes: on DSL values of one type, a value of that type (``exp2(Float4)`` is a
    ``Float4``; a Python number beside a value takes its type)."""

    @typing.overload
    def __call__(self, x: _V, /, *more: _V | float, precision: typing.Any = None,
                 fma: bool | None = None) -> _V: ...
    @typing.overload
    def __call__(self, x: float, y: _V, /, *, precision: typing.Any = None, fma: bool | None = None) -> _V: ...
    @typing.overload
    def __call__(self, *args: typing.Any, precision: typing.Any = None, fma: bool | None = None) -> Value: ...


def routine(fn: typing.Callable[..., Value]) -> Builder:
    """Decorate a builder ``fn(x..., precision)``: validate, then emit under the FMA override."""
    @functools.wraps(fn)
    def build(*args: typing.Any, precision: typing.Any = None, fma: bool | None = None,
              **kwargs: typing.Any) -> Value:
        chosen = reactor.site_choice(fn.__name__)  # a plan's choice for this call site wins
        spans = None
        if chosen is not None:
            precision, fma = chosen.precision, chosen.fma if chosen.fma is not None else fma
            spans = chosen.ranges or None  # its operands' proved ranges: special paths it may drop
        reactor.site_probe(fn.__name__, args)  # reactor.plan measuring what this call site sees
        precision, variant = variant_of(precision, fn.__name__)
        level = check_tier(check_precision(precision, fn.__name__), fn.__name__)
        def emit() -> Value:
            with reactor.routine_call(fn.__name__, variant), continuum.using(fn.__name__, variant):
                if spans is None:
                    return fn(*args, precision=level, **kwargs)
                with continuum.operand_ranges(fn.__name__, spans):
                    return fn(*args, precision=level, **kwargs)
        with fma_mode(fma), reactor.precision(level):
            return reactor.pure_call(fn.__name__, (level.value, variant, fma, spans), args, kwargs, emit)

    return typing.cast(Builder, build)


def variant_of(precision, routine: str) -> tuple[typing.Any, str | None]:
    """(the tier, the continuum variant's name or None) of a ``precision`` that may name one
    (``"full-d3"``, see ``routines.continuum``); a clear error for a variant ``routine`` has not."""
    if isinstance(precision, str) and "-" in precision:
        level, _ = split_precision(precision, routine)
        if routine not in continuum.VARIANTS:
            raise reactor.ReactorError(f"{routine} has no precision variants; its precisions are "
                                       + ", ".join(repr(p) for p in tiers(routine)))
        return level, precision
    return precision, None


_MIN_NORMAL_BITS, _INF_BITS = 0x00800000, 0x7F800000


def positive_normal(x: Value) -> Value:
    """The lanes of the Float value ``x`` holding a positive normal float (not zero, subnormal,
    negative, infinite or NaN): one unsigned compare on the bits."""
    Int_, UInt_ = reactor.vector_type("Int", x.width), reactor.vector_type("UInt", x.width)
    return As(UInt_, As(Int_, x) - _MIN_NORMAL_BITS) < UInt_(_INF_BITS - _MIN_NORMAL_BITS)


#: The NaN an invalid operation gives on x86 (0 * inf, inf - inf, a negative's square root): the
#: routines give it on every target (AArch64 hardware gives 0x7fc00000).
DEFAULT_NAN_BITS = -0x00400000  # 0xffc00000


def nan_rule(result: Value, *sources: Value) -> Value:
    """``result`` with the routines' NaN rule, the same bits on every target: where it is NaN,
    the first NaN among ``sources`` quieted (sign and payload kept), else the default NaN
    0xffc00000 (an invalid operation such as 0 * inf or inf - inf).

    x86 hardware gives exactly this when ``sources`` are the operands in the order the routine
    combines them (its default NaN is 0xffc00000, and its instructions return their first NaN
    operand), so nothing is emitted there. Other architectures get it by selects: AArch64's
    default NaN is 0x7fc00000, and LLVM may order operands differently.
    ``python -m routines crosstarget`` compares every bit of both on every variant."""
    if reactor.build_settings().target.arch == "x86_64":
        return result
    Int_ = reactor.vector_type("Int", result.width)
    Float_ = reactor.vector_type("Float", result.width)
    fixed = As(Float_, Int_(DEFAULT_NAN_BITS))
    for a in reversed(sources):
        quiet = As(Float_, As(Int_, Float_(a)) | 0x00400000)
        fixed = reactor.Select(reactor.IsNan(a), quiet, fixed)
    return reactor.Select(reactor.IsNan(result), fixed, result)
