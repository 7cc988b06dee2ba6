"""log2 and log.

Algorithm (reference write-up, "Second Try"), for float32 x = 2^e * (1 + m):

    e  = exponent of x, m = mantissa in [0, 1)     (exact, subnormals included)
    y  = e + m                                     piecewise-linear log2, exact at 2^k
    log2(x) = P(m) * m + y                         P ~ (log2(1 + m) - m) / m

so the polynomial only supplies the small correction log2(1+m) - m in
[0, 0.086], and log2(2^k) = k exactly (m = 0). Full precision uses the
degree-7 P. Relaxed precision writes the correction as m * (1 - m) * Q(m)
with a linear Q (three FMAs, like the reference's degree-2 P): it vanishes at
m = 1 too, so log2 has the right sign just below every power of two, and
pow(x < 1, -inf) = +inf holds in relaxed precision as well.

Exponent extraction: ``Exponent``/``Significand`` (AVX-512 VGETEXPPS and
VGETMANTPS; an exact integer-bit emulation on other targets). They give the
specials directly: log2(±0) = -inf (e = -inf), log2(+inf) = +inf,
log2(x < 0) = NaN, log2(-inf) = NaN, log2(NaN) = NaN, and subnormal inputs are
normalized exactly. ``log2_integer_path`` is the reference's own bit-cast
version (relaxed: the polynomial in the un-normalized mantissa), kept as a
variant for comparison.
"""
from __future__ import annotations

from reactor import As, Exponent, MulAdd, Select, Significand, vector_type

from .base import float_value, routine
from .polynomials import LOG2_FULL, LOG2_RELAXED, LOG2_RELAXED_UNNORMALIZED

LN_2 = 0.6931471805599453


@routine
def log2(x, precision: str = "full"):
    """log2(x) for Float values of any width; see the module docstring."""
    x = float_value(x, "log2")
    m = Significand(x) - 1.0
    y = Exponent(x) + m
    if precision == "full":
        return MulAdd(LOG2_FULL(m), m, y).named("log2")
    return MulAdd(LOG2_RELAXED(m), MulAdd(-m, m, m), y).named("log2")  # y + Q(m) * m(1-m)


@routine
def log(x, precision: str = "full"):
    """ln(x) = log2(x) * ln(2): one extra rounding (0.5 ULP) and the float32
    ln(2)'s relative error (2^-25.5) on top of log2's error."""
    x = float_value(x, "log")
    return (log2(x, precision=precision) * LN_2).named("log")


@routine
def log2_integer_path(x, precision: str = "full"):
    """The reference's bit-cast log2: y = float(bits - (127 << 23)) * 2^-23 and
    m from the mantissa bits. Handles +inf and the other specials with selects;
    subnormal inputs are treated as 0 (-> -inf)."""
    x = float_value(x, "log2")
    Int_, Float_ = vector_type("Int", x.width), vector_type("Float", x.width)
    bits = As(Int_, x)
    if precision == "full":
        y = Float_(bits - (127 << 23)) * float(2 ** -23)
        m = Float_(bits & 0x007FFFFF) * float(2 ** -23)
        r = MulAdd(LOG2_FULL(m), m, y)
    else:
        y = MulAdd(Float_(bits), float(2 ** -23), -127.0)
        m = Float_(bits & 0x007FFFFF)
        r = MulAdd(LOG2_RELAXED_UNNORMALIZED(m), m, y)
    normal = (x >= float(2 ** -126)) & (x < float("inf"))  # false for NaN
    inf = float("inf")
    special = Select(x >= 0.0, Select(x == inf, x, -inf), float("nan"))  # +inf, [0, 2^-126), else NaN
    return Select(normal, r, special).named("log2")
