"""The correct tier of atan2: the float64 value of ``accurate_inverse.atan2_double`` (within
2^-49), the rounding test of ``routines.correct`` (window 2^-47), and for the lanes it cannot
decide, a double-double evaluation rounded exactly.

atan2 takes two operands, so no table can list its hard cases (``routines.correct``'s tables
are for functions of one float32). Instead the lanes that fail the test (about one pair in
2^21) are recomputed to about 2^-100 relative:

    t = min(|y|, |x|) / max(|y|, |x|)      in [0, 1], as a double-double: the quotient rounded,
                                            its remainder exact (``doubled.two_prod``)
    k = round(32 t), c = k / 32             (exact)
    d = (t - c) / (1 + t c)                 |d| <= 1/64, double-double (``doubled.div``)
    atan(t) = atan(c) + d S(d^2)            S: atan's series to z^8 (remainder < 2^-110),
                                            atan(k/32) from a table (``routines.constants``)

then pi/2 - atan(t) where |y| > |x|, pi - that where x is negative (its sign bit: -0 too),
rounded exactly (``doubled.round_pair``) and given y's sign. atan2 of two floats is never a
midpoint of two floats (atan of a rational other than 0 is irrational), so this rounds every
pair correctly unless its exact value lies within ~2^-100 of a midpoint; the stratified sweep
of ``python -m routines ladder atan2`` and the hard pairs find none.
"""
from __future__ import annotations

import numpy as np

import reactor
from reactor import Abs, Any, ConstantTable, CopySign, If, IsNan, Precision, Round, Select, Variable, vector_type

from . import correct
from . import doubled as dd
from .accurate_inverse import PI, PIO2, atan2_double, operands
from .base import nan_rule
from .constants import ATAN_SERIES, ATAN_TABLE

_TABLE_HI = ConstantTable(np.array([hi for hi, _ in ATAN_TABLE]), reactor.Double)
_TABLE_LO = ConstantTable(np.array([lo for _, lo in ATAN_TABLE]), reactor.Double)


def atan2(y, x, precision):
    """atan2(y, x), faithful or correctly rounded, C99 specials (``accurate_inverse.atan2``)."""
    if precision is Precision.FAITHFUL:
        from .accurate_inverse import atan2 as faithful
        return faithful(y, x, precision)
    F = vector_type("Float", x.width)
    ay, ax = operands(y, x)
    v = atan2_double(y, x, precision, (ay, ax))
    lo, hi = F(v * (1.0 - correct.WINDOW)), F(v * (1.0 + correct.WINDOW))
    result = Variable(F, lo)
    hard = lo < hi                                      # v >= 0; NaN lanes are not hard
    with If(Any(hard)):
        result.set(Select(hard, dd.round_pair(*_angle(y, x, ay, ax)), result))
    r = CopySign(result.value, y)
    return nan_rule(Select(IsNan(y) | IsNan(x), y + x, r), y, x)


def _angle(y, x, ay, ax):
    """|atan2(y, x)| as a double-double, from the operands' magnitudes ``ay``, ``ax`` (float32,
    finite, not both zero: ``operands``)."""
    D = vector_type("Double", x.width)
    n, d = D(ay), D(ax)
    swap = n > d
    num, den = Select(swap, d, n), Select(swap, n, d)
    t_hi = num / den
    p, e = dd.two_prod(t_hi, den)
    t = dd.fast_two_sum(t_hi, ((num - p) - e) / den)    # num - p - e: the exact remainder
    k = Round(t[0] * 32.0)
    c = k * (1.0 / 32.0)
    numer = dd.fast_two_sum(t[0] - c, t[1])             # t - c: exact (Sterbenz, or c = 0)
    tc = dd.mul_double(t, c)
    denom = dd.add((D(1.0), D(0.0)), tc)
    q = dd.div(numer, denom)
    z = dd.mul(q, q)
    series = dd.horner(z, [(D(hi), D(lo)) for hi, lo in ATAN_SERIES])
    index = reactor.ToInt(reactor.Float(k))
    base = (_TABLE_HI[index], _TABLE_LO[index])
    a = dd.add(base, dd.mul(q, series))
    a = _select(swap, dd.add((D(PIO2[0]), D(PIO2[1])), dd.negate(a)), a)
    negative = reactor.As(vector_type("Int", x.width), x) < 0
    return _select(negative, dd.add((D(PI[0]), D(PI[1])), dd.negate(a)), a)


def _select(mask, a, b):
    return Select(mask, a[0], b[0]), Select(mask, a[1], b[1])
