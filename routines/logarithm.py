"""log2 and log.

For float32 x = 2^e * (1 + m), e = exponent of x, m = mantissa in [0, 1) (exact,
subnormals included), the polynomial only supplies the small correction log2(1+m) - m
in [0, 0.086], which vanishes at m = 0, so log2(2^k) = k exactly.

**Full precision** (the variant search's ``m1mc``, docs/search.md) centres the mantissa,
u = m - 1/2 in [-1/2, 1/2) (exact):

    log2(x) = (R(u) * (1/4 - u^2) + u) + (e + 1/2)     R ~ (log2(u + 3/2) - u - 1/2) / ((u + 1/2)(1/2 - u))

The correction is factored by both of its zeros (m = 0 and m = 1), and the partial sum
u + correction lies in [-1/2, 0.59) instead of [0, 1), so it rounds on a grid twice as
fine: exhaustive margin 0.356 against the reference form's 0.502, with the same FMA count.

**Relaxed precision** (the reference write-up's "Second Try" form, y = e + m and
log2(x) = P(m) * m + y, was full precision's until the accuracy ladder) writes the correction as m * (1 - m) * Q(m)
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
    Any, As, Exponent, If, Lookup, MulAdd, Precision, Select, ShiftRightArithmetic, ShiftRightLogical, Significand,
    Variable, target_features, vector_type,
)

from . import accurate, continuum
from .base import float_value, positive_normal, routine
from .polynomials import LOG2_RELAXED

LN_2 = 0.6931471805599453
MIN_NORMAL, MAX_FINITE = 2.0 ** -126, 3.4028234663852886e38


def _full(exponent_plus, m):
    """Full precision from the significand m in [1, 2) and ``exponent_plus(k)``, e + k computed
    exactly in one operation: full's centred form, or where a continuum variant is in force
    (``routines.continuum``) its polynomial of lower degree or the table form."""
    table = continuum.log2_table()
    if table is not None:
        form, q = table
        return (_by_table if form == "t" else _by_folded_table)(exponent_plus(0.0), m, q)
    u = m - 1.5
    return MulAdd(continuum.polynomial("log2")(u), MulAdd(-u, u, 0.25), u) + exponent_plus(0.5)


def _by_table(e, m, q):
    """The table form (``routines.continuum``, ``full-tN``): (e + LOGC[i]) + r Q(r), r = m INVC[i] - 1,
    i the top bits of m's fraction; the tables read from registers by ``Lookup``."""
    i = ShiftRightLogical(As(vector_type("Int", m.width), m), 23 - continuum.LOG2_TABLE_BITS)
    r = MulAdd(m, Lookup(continuum.LOG2_INVC, i), -1.0)
    return MulAdd(q(r), r, e + Lookup(continuum.LOG2_LOGC, i))


def _by_folded_table(e, m, q):
    """The 8-point form (``full-sN``): m folded to z = m or m/2 around 1, then as ``_by_table``."""
    Int_, Float_ = vector_type("Int", m.width), vector_type("Float", m.width)
    bits = As(Int_, m)
    t = bits - continuum.LOG2_FOLD_OFFSET
    k = ShiftRightLogical(t, 23) & 1                               # 1 where m >= 2 - 1/16 (a NaN m: 0)
    i = ShiftRightLogical(t, 23 - continuum.LOG2_FOLD_BITS)
    r = MulAdd(As(Float_, bits - (k << 23)), Lookup(continuum.LOG2_FOLD_INVC, i), -1.0)
    return MulAdd(q(r), r, e + (Float_(k) + Lookup(continuum.LOG2_FOLD_LOGC, i)))


def _folded_from_bits(bits, q):
    """``_by_folded_table`` for positive normal x from its bits: x = 2^E z with z in [1 - 1/32,
    2 - 1/16) read off t = bits - bits(1 - 1/32) directly (E = t >> 23, arithmetic), the same
    E, z and i, so the same result, in fewer operations."""
    Float_ = vector_type("Float", bits.width)
    t = bits - continuum.LOG2_FOLD_OFFSET
    z = As(Float_, bits - (t & -(1 << 23)))
    i = ShiftRightLogical(t, 23 - continuum.LOG2_FOLD_BITS)
    r = MulAdd(z, Lookup(continuum.LOG2_FOLD_INVC, i), -1.0)
    return MulAdd(q(r), r, Float_(ShiftRightArithmetic(t, 23)) + Lookup(continuum.LOG2_FOLD_LOGC, i))


def _relaxed(e, m):
    return MulAdd(LOG2_RELAXED(m), MulAdd(-m, m, m), e + m)  # y + Q(m) * m(1-m)


def _general(x, precision):
    """Every input: the exponent and significand by ``Exponent``/``Significand``."""
    if precision is Precision.FULL:
        e = Exponent(x)
        return _full(lambda k: e + k if k else e, Significand(x))
    return _relaxed(Exponent(x), Significand(x) - 1.0)


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
    Int_, Float_ = vector_type("Int", x.width), vector_type("Float", x.width)
    bits = As(Int_, x)
    normal = positive_normal(x)
    biased = Float_(ShiftRightLogical(bits, 23))
    significand = As(Float_, (bits & 0x007FFFFF) | 0x3F800000)
    table = continuum.log2_table()
    if precision is Precision.FULL and table is not None and table[0] == "s":
        fast = _folded_from_bits(bits, table[1])
    elif precision is Precision.FULL:
        fast = _full(lambda k: biased - (127.0 - k), significand)  # e + k: exact
    else:
        fast = _relaxed(biased - 127.0, significand - 1.0)
    span = continuum.operand_range("log2")
    if span is not None and span.within(MIN_NORMAL, MAX_FINITE):  # a plan proved every x positive and normal
        return fast.named("log2")
    result: typing.Any = Variable(Float_, fast)  # (Variable's overloads say Value)
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
    span = continuum.operand_range("log")
    with continuum.operand_ranges("log2", (span,) if span else None):
        return (log2(x, precision=precision) * LN_2).named("log")
