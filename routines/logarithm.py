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
normalized exactly. Without AVX-512 those emulations cost ~25 operations, so a
vector of positive normal inputs reads the two bit fields directly instead (the
same values), and the general path runs only when a lane is zero, subnormal,
negative, infinite or NaN. (The reference's own bit-cast version is built by the
method zoo, ``routines.zoo``, for comparison.)
"""
from __future__ import annotations

import typing

from reactor import (
    Any, As, Exponent, If, MulAdd, Precision, Select, ShiftRightLogical, Significand, Variable, target_features,
    vector_type,
)

from . import accurate
from .base import float_value, routine
from .polynomials import LOG2_FULL, LOG2_RELAXED

LN_2 = 0.6931471805599453
_MIN_NORMAL_BITS, _INF_BITS = 0x00800000, 0x7F800000


def _log2_of(e, m, precision):
    y = e + m
    if precision is Precision.FULL:
        return MulAdd(LOG2_FULL(m), m, y)
    return MulAdd(LOG2_RELAXED(m), MulAdd(-m, m, m), y)  # y + Q(m) * m(1-m)


def _general(x, precision):
    """Every input: the exponent and significand by ``Exponent``/``Significand``."""
    return _log2_of(Exponent(x), Significand(x) - 1.0, precision)


@routine
def log2(x, precision: Precision = Precision.FULL):
    """log2(x) for Float values of any width; see the module docstring."""
    x = float_value(x, "log2")
    if precision in (Precision.FAITHFUL, Precision.CORRECT):
        return accurate.log2(x, precision).named("log2")
    if "avx512f" in target_features():  # VGETEXPPS/VGETMANTPS: one instruction each, specials included
        return _general(x, precision).named("log2")
    # Elsewhere the portable Exponent/Significand handle subnormals, zeros, infinities and NaNs in
    # ~25 vector operations. For positive normal x they are two bit fields, so the vector takes
    # that path, and the general one only runs when some lane needs it (the same bits: for
    # normal x both give e = biased exponent - 127 and m = the fraction field / 2^23).
    Int_, UInt_, Float_ = (vector_type(k, x.width) for k in ("Int", "UInt", "Float"))
    bits = As(Int_, x)
    normal = As(UInt_, bits - _MIN_NORMAL_BITS) < UInt_(_INF_BITS - _MIN_NORMAL_BITS)
    e = Float_(ShiftRightLogical(bits, 23) - 127)
    m = As(Float_, (bits & 0x007FFFFF) | 0x3F800000) - 1.0
    result: typing.Any = Variable(Float_, _log2_of(e, m, precision))  # (Variable's overloads say Value)
    with If(Any(~normal)):
        result.set(Select(normal, result, _general(x, precision)))
    return result.value.named("log2")


@routine
def log(x, precision: Precision = Precision.FULL):
    """ln(x) = log2(x) * ln(2): one extra rounding (0.5 ULP) and the float32
    ln(2)'s relative error (2^-25.5) on top of log2's error."""
    x = float_value(x, "log")
    if precision in (Precision.FAITHFUL, Precision.CORRECT):
        return accurate.log(x, precision).named("log")
    return (log2(x, precision=precision) * LN_2).named("log")
