"""Double-double arithmetic in float64 lanes, and the exact rounding of a value to float32.

The faithful and correct tiers (``routines.accurate``) evaluate in float64 lanes. Where one
float64 evaluation cannot decide a float32 rounding, the correct tier recomputes the lane as a
double-double: an unevaluated sum ``hi + lo`` with ``|lo| <= ulp(hi) / 2`` (about 106 bits).
The error-free transformations are the classic ones (Dekker 1971, Knuth TAOCP 4.2.2):

    two_sum(a, b)       s + e = a + b exactly               (6 operations)
    fast_two_sum(a, b)  the same, for |a| >= |b|             (3 operations)
    two_prod(a, b)      p + e = a * b exactly                (FMA: 2; without: Dekker's split, 17)

and on them products, sums, quotients (``div``) and Horner's scheme to about 2^-104.

The FMA toggle is honoured: a build with FMA off computes products' errors by splitting,
and no fused operation is emitted.
"""
from __future__ import annotations

import typing

import reactor
from reactor import Fma, Select, vector_type
from reactor import require

SPLIT = 134217729.0  # 2^27 + 1: Veltkamp's splitter for binary64

Pair = tuple[typing.Any, typing.Any]


def fused() -> bool:
    """FMA on and in the target's hardware (float64 FMA has no exact emulation)."""
    settings = reactor.build_settings()
    return settings.fma is True and settings.target.has_fma


def two_sum(a, b) -> Pair:
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


def fast_two_sum(a, b) -> Pair:
    s = a + b
    return s, b - (s - a)


def _split(a) -> Pair:
    t = a * SPLIT
    hi = t - (t - a)
    return hi, a - hi


def two_prod(a, b) -> Pair:
    p = a * b
    if fused():
        return p, Fma(a, b, -p)
    ah, al = _split(a)
    bh, bl = _split(b)
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl


def mul(x: Pair, y: Pair) -> Pair:
    """(x.hi + x.lo) * (y.hi + y.lo), relative error ~2^-104."""
    p, e = two_prod(x[0], y[0])
    return fast_two_sum(p, e + (x[0] * y[1] + x[1] * y[0]))


def mul_double(x: Pair, b) -> Pair:
    p, e = two_prod(x[0], b)
    return fast_two_sum(p, e + x[1] * b)


def add(x: Pair, y: Pair) -> Pair:
    """(x.hi + x.lo) + (y.hi + y.lo) (Knuth's sum of the high parts, then the low parts)."""
    s, e = two_sum(x[0], y[0])
    return fast_two_sum(s, e + (x[1] + y[1]))


def div(x: Pair, y: Pair) -> Pair:
    """(x.hi + x.lo) / (y.hi + y.lo), relative error ~2^-104: three quotient digits, each from
    the remainder so far."""
    q1 = x[0] / y[0]
    r = add(x, negate(mul_double(y, q1)))
    q2 = r[0] / y[0]
    r = add(r, negate(mul_double(y, q2)))
    q3 = r[0] / y[0]
    q = fast_two_sum(q1, q2)
    return add(q, (q3, 0.0 * q3))


def negate(x: Pair) -> Pair:
    return -x[0], -x[1]


def horner(x: Pair, coefficients: typing.Sequence[Pair], start=None) -> Pair:
    """sum c_i x^i by Horner's scheme in double-double; ``coefficients`` highest degree first,
    ``start`` the (double-double) value already accumulated for the higher terms."""
    acc = start if start is not None else coefficients[0]
    rest = coefficients if start is not None else coefficients[1:]
    for c in rest:
        acc = add(mul(acc, x), c)
    return acc


def constant(value) -> Pair:
    """An mpmath number as the double-double (hi, lo) of Python floats."""
    mpmath = require("mpmath", "lab", "routines.doubled.constant")
    with mpmath.workdps(60):
        hi = float(value)
        return hi, float(mpmath.mpf(value) - hi)


def round_pair(hi, lo):
    """The float32 nearest to hi + lo (ties to even), subnormals and overflow included.

    Converting ``hi`` is right unless ``hi`` is exactly halfway between two floats: then the
    sign of ``lo`` picks the side. ``hi`` is a midpoint exactly when ``2 hi - f`` (the float
    on the other side, computed exactly) is itself a float different from ``f``."""
    Float_ = vector_type("Float", hi.width)
    Double_ = vector_type("Double", hi.width)
    f = Float_(hi)
    fd = Double_(f)
    d = hi - fd                 # exact: f is hi rounded
    other = fd + (d + d)        # exact when hi is a midpoint
    g = Float_(other)
    midpoint = (Double_(g) == other) & (other != fd)
    beyond = ((lo > 0.0) & (d > 0.0)) | ((lo < 0.0) & (d < 0.0))  # past the midpoint, towards g
    return Select(midpoint & beyond, g, f)
