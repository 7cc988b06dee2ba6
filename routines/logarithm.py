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
normalized exactly. (The reference's own bit-cast version is built by the
method zoo, ``routines.zoo``, for comparison.)
"""
from __future__ import annotations

from reactor import Exponent, MulAdd, Precision, Significand

from .base import float_value, routine
from .polynomials import LOG2_FULL, LOG2_RELAXED

LN_2 = 0.6931471805599453


@routine
def log2(x, precision: Precision = Precision.FULL):
    """log2(x) for Float values of any width; see the module docstring."""
    x = float_value(x, "log2")
    m = Significand(x) - 1.0
    y = Exponent(x) + m
    if precision is Precision.FULL:
        return MulAdd(LOG2_FULL(m), m, y).named("log2")
    return MulAdd(LOG2_RELAXED(m), MulAdd(-m, m, m), y).named("log2")  # y + Q(m) * m(1-m)


@routine
def log(x, precision: Precision = Precision.FULL):
    """ln(x) = log2(x) * ln(2): one extra rounding (0.5 ULP) and the float32
    ln(2)'s relative error (2^-25.5) on top of log2's error."""
    x = float_value(x, "log")
    return (log2(x, precision=precision) * LN_2).named("log")
