"""Ready-made NumPy ufuncs for every routine variant: ``jit(name, precision, fma, width)``."""
from __future__ import annotations

import functools

from reactor import Float, ReactorError, build_settings, get_target, kernel, options, travels_as

from . import exponential as _exp2
from . import logarithm as _log2
from . import power as _power
from . import reciprocal as _recip
from . import trig as _trig
from .base import check_precision, variant_of

UNARY = {
    "exp2": _exp2.exp2, "exp": _exp2.exp, "log2": _log2.log2, "log": _log2.log,
    "rcp": _recip.rcp, "rsqrt": _recip.rsqrt, "sqrt": _recip.sqrt,
    "sin": _trig.sin, "cos": _trig.cos, "tan": _trig.tan, "asin": _trig.asin, "acos": _trig.acos,
    "atan": _trig.atan, "sinh": _trig.sinh, "cosh": _trig.cosh, "tanh": _trig.tanh,
}
BINARY = {"pow": _power.pow, "atan2": _trig.atan2}
NAMES = tuple(UNARY) + tuple(BINARY)


def jit(name: str, precision="full", fma: bool | str | None = None, width: int | None = None,
        target: str | None = None):
    """The ufunc computing routine ``name`` ("exp2", "log2", "pow", "exp", "log",
    "rcp", "rsqrt", "sqrt", "sin", "cos", "tan", "asin", "acos", "atan", "sinh",
    "cosh", "tanh"; binary: "pow" and "atan2", called as atan2(y, x)) in ``precision`` ("relaxed" and
    "full": Vulkan's mediump and highp, GLSL's special values; "faithful": below 1 ULP, "correct":
    correctly rounded, both with C99 Annex F special values), with FMA on or
    off (None: fused where the target has FMA; True on a target without FMA is an error;
    "emulate": fused everywhere, in software where needed), at SIMD ``width`` (None: the
    target's natural width) for ``target`` (None: this CPU). Built once per
    variant and process (and cached on disk). Its name and doc state the
    resolved settings, e.g. ``exp2_full_fma``: "exp2, full precision, FMA on,
    16 lanes, target host (znver4), float32"."""
    if name not in NAMES:
        raise ReactorError(f"unknown routine {name!r}; choose one of {', '.join(NAMES)}")
    tier, variant = variant_of(precision, name)  # "full-d3": a continuum variant (routines.continuum)
    level = check_precision(tier, name)
    with options(fma=fma, width=width, target=target):
        build = build_settings()
    fused = "emulate" if build.fma and not build.target.has_fma else build.fma  # never libm's fmaf
    return _build(name, level, fused, build.width, build.target.name, width is not None, variant)


@functools.lru_cache(maxsize=None)
def _build(name, precision, fma, width, target, tag_width, variant=None):
    asked = variant or precision.value
    tag = f"{name}_{asked.replace('-', '_')}_{'fma' if fma else 'nofma'}" + (f"_w{width}" if tag_width else "")
    where = get_target(target)
    fused = "emulated in software" if fma == "emulate" else "on" if fma else "off"
    doc = (f"{name}, {asked} precision, FMA {fused}, {width} lane{'s' * (width > 1)}, "
           f"target {target} ({where.cpu}). float32 only: NumPy refuses a float64 array under its default "
           f"casting; compute one in float32 with dtype=np.float32, casting='same_kind'.")
    builder = BINARY[name] if name in BINARY else UNARY[name]  # the body reads only keyable values

    def binary(x: Float, y: Float) -> Float:
        return builder(x, y, precision=asked)

    def unary(x: Float) -> Float:
        return builder(x, precision=asked)

    body = binary if name in BINARY else unary
    body.__doc__ = doc
    u = kernel(body, name=tag, fma=fma, width=width, target=target, precision=precision.value)
    # pickled as this call: rebuilt on the other side for its CPU (its natural width unless one was asked)
    return travels_as(u, jit, name, asked, fma, width if tag_width else None, target)
