"""sin, cos, tan, asin, acos, atan, atan2, sinh, cosh, tanh.

Every routine takes Float values of any width, ``precision`` ("full" or
"relaxed"; None: the build's) and ``fma`` (None: the build's), like exp2.
This module builds Vulkan's two tiers; the faithful and correct tiers evaluate
in float64 lanes and round once (``routines.accurate_trig``,
``accurate_inverse``, ``accurate_hyperbolic``, ``accurate_atan2``, ``correct``). The
polynomials and their provenance are in routines/polynomials.py; the Vulkan
tolerances (absolute 2^-11 / 2^-7 for sin and cos inside [-pi, pi], 4096 ULP /
5 ULP-16 for atan and atan2, inherited from their defining formulas for the
others) in routines/lab/tolerance.py and docs/accuracy.md.

sin, cos, tan: argument reduction
---------------------------------
|x| = q * pi/2 + r with q = round(|x| * 2/pi) and r in [-pi/4, pi/4] (a little
beyond in the float32 path, |r| < 0.797; the polynomials are fitted to 0.8):

* |x| <= 2^17 with FMA on: Cody-Waite in float32, |x| - q*C1 - q*C2 [- q*C3]
  with C1 + C2 + C3 = pi/2 within 1.1e-23 (three parts for full precision and
  for tan; two for relaxed sin and cos), each step one fused multiply-add.
  The first step is exact (|x| - q*C1 is a multiple of 2^-24 below 1 in
  magnitude), so near a multiple of pi/2 the cancellation is exact and r
  keeps its relative accuracy; what the parts leave out, q times the rest of
  pi/2, is < 2^-59 (two parts: < 2^-32).
* With FMA off (no fused instruction): |x| <= 800 in float32 with four
  parts, three of <= 15 significant bits (q*Di is exact for q < 2^9) and C3;
  800 < |x| <= 2^17 in double lanes (when some lane needs it), |x| - q*P1 -
  q*P2 with a 36-bit P1 (q*P1 exact for q < 2^17) and a 53-bit P2, r rounded
  to float32 once.
* |x| > 2^17 (and +-inf): Payne-Hanek in double lanes, only when some lane
  needs it (``If(Any(...))``; a shader's arguments rarely do). 2/pi is split
  into five 28-bit pieces T0..T4 and a 53-bit tail; |x| * Ti is exact (24 + 28
  bits), is reduced modulo 4 exactly (p - 4 round(p/4)), and is added to an
  accumulator that is brought back to [-1/2, 1/2] after every piece (its
  integer part goes to q), so the fraction keeps 53 bits relative to itself
  even when |x| * 2/pi lies within 2^-30 of an integer. r = frac * pi/2 in
  double, rounded once to float32. Valid for every finite float32; inf gives
  NaN (inf - inf).

Then with s = sin(r) = r + r^3 P(r^2) and c = cos(r) = 1 + r^2 Q(r^2)
(full: P of degree 2 and Q of degree 3, i.e. sin of degree 7 and cos of degree
8; relaxed: degrees 5 and 4): sin(|x|) = (s, c, -s, -c)[q mod 4],
cos(|x|) = (c, -s, -c, s)[q mod 4], tan(|x|) = s/c for even q, -c/s for odd
q (one division). The quadrant's sign and, for the odd functions, the sign of
x are applied as one XOR of the sign bit, so sin(-0) = -0 and tan(-0) = -0
(a fused x - q*C1 would turn -0 into +0). cos(+-0) = 1 exactly.

asin, acos
----------
For |x| <= 1/2: asin(|x|) = v + v^3 R(v^2) with v = |x|; for |x| > 1/2:
asin(|x|) = pi/2 - 2 asin(v) with v = sqrt(w), w = (1 - |x|)/2 (exact), the
same polynomial R on [0, 1/4]. acos(x) = pi/2 - asin(x) for |x| <= 1/2,
2 asin(v) for x > 1/2 and pi - 2 asin(v) for x < -1/2. The constants pi/2 and
pi are added in two parts (float32 head, then tail), the head last, so
asin(+-1) = +-pi/2, acos(-1) = pi and acos(+-0) = pi/2 round to the float32
constant exactly. |x| > 1 (and +-inf) gives NaN through sqrt of a negative.
The square root is routines.sqrt of the same precision (relaxed: x times the
reciprocal-square-root estimate).

atan, atan2
-----------
t = min(|x|, 1) / max(|x|, 1) (one division), atan(t) = t + t^3 A(t^2) on
[0, 1] (full: A of degree 7, relaxed: degree 2), then pi/2 - atan(t) where
|x| > 1. atan2(y, x) divides the smaller of |x|, |y| by the larger (t in
[0, 1], and 0 when both are zero) and places atan(t) by the signs: (pi/2 or
pi or 0 as a two-part constant) +- atan(t), with the sign of x read from its
sign bit, so atan2(+-0, -0) = +-pi; the result gets y's sign. Both operands
infinite give +-pi/4 or +-3pi/4 (float32 constants). NaN in either operand
gives NaN: comparisons with a NaN are false, so the NaN reaches the division
(atan's Min/Max and atan2's Max take it as their second operand, which they
return).

sinh, cosh, tanh
----------------
h = e^a / 2 for a = |x| (or 2|x|), computed directly: k = round(a log2 e),
r = a - k ln2 (Cody-Waite, ln2 in a 15-bit head, exact without FMA, and a
tail), e^r = 1 + r + r^2 E(r) on [-0.35, 0.35], h = ScaleF(e^r, k - 1), so h
overflows only where e^a / 2 does (sinh and cosh overflow at |x| > 89.415, not
at ln(FLT_MAX) = 88.72); a is clamped to 100 first (inf -> 100, NaN kept).
cosh = h + 1/(4h); sinh = h - 1/(4h) for |x| >= 1 and |x| + |x|^3 S(x^2)
below; tanh = 1 - 1/(h + 1/2) with h = e^(2|x|)/2 for |x| >= 0.55 and
|x| + |x|^3 T(x^2) below. The reciprocals are divisions in full precision
and routines.rcp's estimate in relaxed precision. sinh and tanh take x's
sign at the end (odd, sinh(-0) = -0); tanh(+-inf) = +-1, cosh(+-inf) = +inf,
sinh(+-inf) = +-inf.
"""
from __future__ import annotations

import math

import numpy as np

import reactor
from reactor import (
    Abs, Any, As, CopySign, If, IsInf, Max, Min, MulAdd, Precision, Round, ScaleF, Select, ToInt,
    Variable, vector_type,
)

from . import continuum
from . import polynomials as P
from .base import float_value, nan_rule, routine
from .reciprocal import rcp, sqrt


def _f32(v: float) -> float:
    return float(np.float32(v))


PI = math.pi
PI_HI = _f32(PI)                                  # 3.1415927 (0x40490FDB)
PI_LO = _f32(PI - PI_HI)                          # -8.742278e-08
PIO2_HI = _f32(PI / 2)                            # 1.5707964 (0x3FC90FDB)
PIO2_LO = _f32(PI / 2 - PIO2_HI)                  # -4.371139e-08
PIO4 = _f32(PI / 4)                               # 0.7853982
PIO4_3 = _f32(3 * PI / 4)                         # 2.3561945

#: |x| up to which sin/cos/tan reduce with Cody-Waite; above, Payne-Hanek.
FAST_LIMIT = 2.0 ** 17
TWO_OVER_PI = 0.6366197723675814                  # 2/pi (rounded to float32 or used in double)
#: pi/2 = C1 + C2 + C3 + 1.06e-23 (float32 parts; the first two for relaxed sin and cos)
PIO2_F32 = (1.5707963705062866, -4.371138828673793e-08, -1.7151245100058819e-15)
#: pi/2 = D1 + D2 + D3 + C3 + 1.06e-23 (float32; D1..D3 have <= 15 significant bits, so
#: q * Di is exact without a fused multiply-add for q < 2^9)
PIO2_SPLIT = (1.57080078125, -4.454515874385834e-06, 6.077272018956137e-11, -1.7151245100058819e-15)
#: |x| up to which the reduction without FMA uses PIO2_SPLIT (q <= 510 < 2^9)
SPLIT_LIMIT = 800.0
#: pi/2 = P1 + P2 (double: P1 has 36 significant bits, so q * P1 is exact for q < 2^17)
PIO2_F64 = (1.5707963267923333, 2.563344151594519e-12)
#: 2/pi = T0 + ... + T4 (28-bit pieces) + tail (53 bits); T0 starts at 2^-1
TWO_OVER_PI_PIECES = (0.6366197690367699, 3.3308114738561656e-09, 2.276010047810136e-18,
                      2.5268260189002822e-26, 1.6682867657019525e-34)
TWO_OVER_PI_TAIL = 1.1588713353428143e-43         # 2/pi - T0 - ... - T4, to float64
#: a sixth 28-bit piece T5 and the tail after it: for the float64 r of routines.accurate_trig,
#: where |x| * TWO_OVER_PI_TAIL's rounding (~2^-66 near 2^128) is too much next to a tiny r
TWO_OVER_PI_PIECE_5 = 1.158871328288855e-43
TWO_OVER_PI_TAIL_5 = 7.053959263504975e-52        # 2/pi - T0 - ... - T5, to float64
PIO2_DOUBLE = math.pi / 2
SIGN = 0x80000000

LOG2E = 1.4426950408889634
LN2_HI = 0.693145751953125                        # 0x3F317200: 15 significant bits
LN2_LO = 1.428606765330187e-06                   # ln2 - LN2_HI, to float32 (0x35BFBE8E)
EXP_CLAMP = 100.0                                 # e^100/2 overflows float32; inf -> 100


def _types(x):
    return (vector_type("Float", x.width), vector_type("Int", x.width), vector_type("Double", x.width))


def _beyond_vulkan(precision) -> bool:
    """The faithful and correct tiers: float64 lanes (routines.accurate_*, routines.correct)."""
    return precision in (Precision.FAITHFUL, Precision.CORRECT)


def _full(precision) -> bool:
    return precision is Precision.FULL


# -- sin, cos, tan ----------------------------------------------------------

def _reduce_large(ax):
    """(r, q) for any float32 |x| (Payne-Hanek in double lanes; see the module doc)."""
    Float_ = _types(ax)[0]
    r, q = reduce_large_double(ax)
    return Float_(r), Float_(q)                             # q: a small integer (mod 4 later)


def reduce_large_double(ax, extended: bool = False):
    """(r, q) as double lanes for any float32 |x|: |x| = q pi/2 + r, |r| <= pi/4, q a whole
    number congruent to the quadrant mod 4 (not |x|'s quotient: the pieces' integer parts
    are dropped mod 4). The fraction's error is that of the tail term, 2^-53 |x| tail
    (< 2^-66 absolute), and ~2^-53 relative to itself for the rest. ``extended`` (used by
    ``routines.accurate_trig``, which keeps r unrounded) adds a sixth piece, so the tail's
    error falls to < 2^-95 and r's relative error stays ~2^-52 for every float32 |x|."""
    Double_ = _types(ax)[2]
    d = Double_(ax)
    acc = q = None
    pieces = TWO_OVER_PI_PIECES + ((TWO_OVER_PI_PIECE_5,) if extended else ())
    for piece in pieces:
        p = d * piece                                       # exact: 24 x 28 bits
        p = p - Round(p * 0.25) * 4.0                       # p mod 4 in [-2, 2], exact (no FMA needed)
        acc = p if acc is None else acc + p
        k = Round(acc)
        acc = acc - k                                       # in [-1/2, 1/2], exact
        q = k if q is None else q + k
    acc = acc + d * (TWO_OVER_PI_TAIL_5 if extended else TWO_OVER_PI_TAIL)  # < 2^-14: error < 2^-66
    k = Round(acc)
    return (acc - k) * PIO2_DOUBLE, q + k


def _reduce_double(ax):
    """(r, q) for |x| <= 2^17 in double lanes, without a fused multiply-add."""
    Float_, _, Double_ = _types(ax)
    d = Double_(ax)
    q = Round(d * TWO_OVER_PI)
    r = (d - q * PIO2_F64[0]) - q * PIO2_F64[1]             # q * P1 exact
    return Float_(r), Float_(q)


def _reduce_fast(ax, parts):
    """|x| = q pi/2 + r on the float32 path, right where |x| <= the fast path's limit: (r, q as
    Float, the lanes beyond that limit); ``parts`` of pi/2 with FMA (2 or 3)."""
    fma = reactor.build_settings().fma
    q = Round(ax * TWO_OVER_PI)
    r = ax
    for part in (PIO2_F32[:parts] if fma else PIO2_SPLIT):
        r = MulAdd(q, -part, r)                             # fused: the first step is exact;
    limit = FAST_LIMIT if fma else SPLIT_LIMIT              # unfused: q * part is exact
    return r, q, ax > limit                                 # NaN stays on the fast path (NaN)


def _reduce_beyond(ax, large, r, q):
    """(r, q) of the lanes ``large`` beyond the float32 path (double lanes, Payne-Hanek beyond
    2^17), the others' ``r``, ``q`` kept; emitted where some lane is large."""
    Float_ = _types(ax)[0]
    r_var, q_var = Variable(Float_, r), Variable(Float_, q)
    if not reactor.build_settings().fma:
        r_mid, q_mid = _reduce_double(ax)
        r_var.set(Select(large, r_mid, r_var))
        q_var.set(Select(large, q_mid, q_var))
    huge = ax > FAST_LIMIT
    with If(Any(huge)):
        r_large, q_large = _reduce_large(ax)
        r_var.set(Select(huge, r_large, r_var))
        q_var.set(Select(huge, q_large, q_var))
    return r_var.value, q_var.value


def _reduced(x, parts, finish):
    """``finish(r, q)`` (q: the quadrant mod 4, as Int) of |x| = q pi/2 + r, the whole function
    first on the float32 path, straight-line, then again where some lane lies beyond it (the same
    operations on those lanes' r and q, so the same bits as one pass over a merged r and q). The
    common path ends in one value and one rare branch, so a kernel computes it once per call
    when x is broadcast (reactor.ir.hoist)."""
    ax = Abs(x)
    r, q, large = _reduce_fast(ax, parts)
    result = Variable(type(x), finish(r, ToInt(q, saturate=False) & 3))
    with If(Any(large)):
        r_far, q_far = _reduce_beyond(ax, large, r, q)
        result.set(Select(large, finish(r_far, ToInt(q_far, saturate=False) & 3), result))
    return result.value


def _parts(precision) -> int:
    """Parts of pi/2 for sin and cos: three (full), two (relaxed: < 2^-32 absolute left out)."""
    return 3 if _full(precision) else 2


def _sin_cos_of_reduced(r, precision):
    """(sin r, cos r) for |r| <= 0.8."""
    z = r * r
    sin_p, cos_p = (continuum.polynomial("sin"), continuum.polynomial("cos")) if _full(precision) \
        else (P.SIN_RELAXED, P.COS_RELAXED)  # full's, or a continuum variant's (routines.continuum)
    s = MulAdd(r * z, sin_p(z), r)
    c = MulAdd(z, cos_p(z), 1.0)
    return s, c


def _flip(v, sign_bits):
    Float_, Int_, _ = _types(v)
    return As(Float_, As(Int_, v) ^ sign_bits)


def _sign_of(x):
    _, Int_, _ = _types(x)
    return As(Int_, x) & SIGN


@routine
def sin(x, precision: Precision = Precision.FULL):
    """sin(x) for Float values of any width; see the module docstring."""
    x = float_value(x, "sin")
    if _beyond_vulkan(precision):
        from . import accurate_trig
        return accurate_trig.sin(x, precision).named("sin")

    def finish(r, q):
        s, c = _sin_cos_of_reduced(r, precision)
        v = Select((q & 1) != 0, c, s)
        return _flip(nan_rule(v, Abs(x)), ((q & 2) << 30) ^ _sign_of(x))
    return _reduced(x, _parts(precision), finish).named("sin")


@routine
def cos(x, precision: Precision = Precision.FULL):
    """cos(x) for Float values of any width; see the module docstring."""
    x = float_value(x, "cos")
    if _beyond_vulkan(precision):
        from . import accurate_trig
        return accurate_trig.cos(x, precision).named("cos")

    def finish(r, q):
        s, c = _sin_cos_of_reduced(r, precision)
        q = q + 1
        v = Select((q & 1) != 0, c, s)
        return _flip(nan_rule(v, Abs(x)), (q & 2) << 30)
    return _reduced(x, _parts(precision), finish).named("cos")


@routine
def tan(x, precision: Precision = Precision.FULL):
    """tan(x) for Float values of any width; see the module docstring."""
    x = float_value(x, "tan")
    if _beyond_vulkan(precision):
        from . import accurate_trig
        return accurate_trig.tan(x, precision).named("tan")

    def finish(r, q):                                       # near a pole, tan ~ 1/r: r's error counts
        s, c = _sin_cos_of_reduced(r, precision)
        odd = (q & 1) != 0
        v = Select(odd, c, s) / Select(odd, -s, c)
        return _flip(nan_rule(v, Abs(x)), _sign_of(x))
    return _reduced(x, 3, finish).named("tan")


# -- asin, acos --------------------------------------------------------------

def _asin_core(x, precision):
    """(asin(v), |x| > 1/2) with v = |x| or sqrt((1 - |x|)/2)."""
    ax = Abs(x)
    high = ax > 0.5                                         # NaN: low branch, NaN throughout
    w = MulAdd(ax, -0.5, 0.5)                               # (1 - |x|)/2, exact for |x| >= 1/2
    s = sqrt(w, precision=precision)
    z = Select(high, w, ax * ax)
    v = Select(high, s, ax)
    poly = continuum.polynomial("asin") if _full(precision) else P.ASIN_RELAXED  # full's or a variant's
    return MulAdd(v * z, poly(z), v), high


@routine
def asin(x, precision: Precision = Precision.FULL):
    """asin(x) for Float values of any width; NaN outside [-1, 1]; see the module docstring."""
    x = float_value(x, "asin")
    if _beyond_vulkan(precision):
        from . import accurate_inverse
        return accurate_inverse.asin(x, precision).named("asin")
    p, high = _asin_core(x, precision)
    v = Select(high, MulAdd(p, -2.0, PIO2_LO) + PIO2_HI, p)  # pi/2 - 2p
    return CopySign(v, x).named("asin")


@routine
def acos(x, precision: Precision = Precision.FULL):
    """acos(x) for Float values of any width; NaN outside [-1, 1]; see the module docstring."""
    x = float_value(x, "acos")
    if _beyond_vulkan(precision):
        from . import accurate_inverse
        return accurate_inverse.acos(x, precision).named("acos")
    p, high = _asin_core(x, precision)
    low = (PIO2_LO - CopySign(p, x)) + PIO2_HI               # pi/2 - asin(x)
    negative = x < 0.0
    two_p = p + p
    high_v = Select(negative, MulAdd(p, -2.0, PI_LO) + PI_HI, two_p)   # pi - 2p or 2p
    return nan_rule(Select(high, high_v, low), x).named("acos")


# -- atan, atan2 -------------------------------------------------------------

def _atan01(t, precision):
    """atan(t) for t in [0, 1] (NaN propagates)."""
    z = t * t
    poly = continuum.polynomial("atan") if _full(precision) else P.ATAN_RELAXED  # full's or a variant's
    return MulAdd(t * z, poly(z), t)


@routine
def atan(x, precision: Precision = Precision.FULL):
    """atan(x) for Float values of any width; atan(+-inf) = +-pi/2; see the module docstring."""
    x = float_value(x, "atan")
    if _beyond_vulkan(precision):
        from . import accurate_inverse
        return accurate_inverse.atan(x, precision).named("atan")
    ax = Abs(x)
    t = Min(1.0, ax) / Max(1.0, ax)                         # both keep a NaN (it is their 2nd operand)
    a = _atan01(t, precision)
    v = Select(ax > 1.0, (PIO2_LO - a) + PIO2_HI, a)
    return CopySign(v, x).named("atan")


@routine
def atan2(y, x, precision: Precision = Precision.FULL):
    """atan2(y, x), the angle of (x, y) in [-pi, pi], with C99/IEEE special values;
    y and x are Float values (a scalar broadcasts); see the module docstring."""
    y = float_value(y, "atan2", "y")
    x = float_value(x, "atan2", "x")
    Float_, Int_, _ = _types(x * y)                         # the common width (a scalar broadcasts)
    x, y = (v if v.width == Float_.vtype.width else Float_(v) for v in (x, y))
    if _beyond_vulkan(precision):
        from . import accurate_atan2
        return accurate_atan2.atan2(y, x, precision).named("atan2")
    ax, ay = Abs(x), Abs(y)
    swap = ay > ax                                          # false with a NaN
    num = Select(swap, ax, ay)
    den = Max(2.0 ** -149, Select(swap, ay, ax))            # 0/0 -> 0/2^-149 = 0; keeps a NaN
    a = _atan01(num / den, precision)
    x_negative = (As(Int_, x) & SIGN) != 0                  # -0 included
    # result = head + (tail +- a): 0 + a, pi/2 - a, pi/2 + a, pi - a
    head = Select(swap, Float_(PIO2_HI), Select(x_negative, Float_(PI_HI), Float_(0.0)))
    tail = Select(swap, Float_(PIO2_LO), Select(x_negative, Float_(PI_LO), Float_(0.0)))
    minus = swap ^ x_negative                               # pi/2 - a or pi - a
    v = (tail + _flip(a, Select(minus, Int_(SIGN), Int_(0)))) + head
    both_inf = IsInf(x) & IsInf(y)
    v = Select(both_inf, Select(x_negative, Float_(PIO4_3), Float_(PIO4)), v)
    return CopySign(v, y).named("atan2")


# -- sinh, cosh, tanh --------------------------------------------------------

def _exp_half(a, precision):
    """e^a / 2 for a >= 0 (a > 100 and inf give +inf, NaN gives NaN)."""
    a = Min(EXP_CLAMP, a)                                   # inf -> 100; NaN is the 2nd operand: kept
    k = Round(a * LOG2E)
    r = MulAdd(k, -LN2_HI, a)                               # exact: k * LN2_HI has <= 24 bits
    r = MulAdd(k, -LN2_LO, r)
    poly = continuum.polynomial("exp_half") if _full(precision) else P.EXP_RELAXED  # full's or a variant's
    e_r = MulAdd(r, MulAdd(r, poly(r), 1.0), 1.0)           # 1 + r + r^2 E(r)
    return ScaleF(e_r, k - 1.0)


def _reciprocal(v, numerator, precision):
    """numerator / v: a division in full precision (correctly rounded, and faster here than the
    refined estimate), the reciprocal estimate (routines.rcp) in relaxed precision."""
    if _full(precision):
        return numerator / v
    return numerator * rcp(v, precision=precision)


def _odd_small(ax, poly):
    z = ax * ax
    return MulAdd(ax * z, poly(z), ax)


@routine
def sinh(x, precision: Precision = Precision.FULL):
    """sinh(x) for Float values of any width; see the module docstring."""
    x = float_value(x, "sinh")
    if _beyond_vulkan(precision):
        from . import accurate_hyperbolic
        return accurate_hyperbolic.sinh(x, precision).named("sinh")
    ax = Abs(x)
    h = _exp_half(ax, precision)
    large = h - _reciprocal(h, 0.25, precision)
    small = _odd_small(ax, continuum.polynomial("sinh") if _full(precision) else P.SINH_RELAXED)
    return CopySign(Select(ax < 1.0, small, large), x).named("sinh")


@routine
def cosh(x, precision: Precision = Precision.FULL):
    """cosh(x) for Float values of any width; see the module docstring."""
    x = float_value(x, "cosh")
    if _beyond_vulkan(precision):
        from . import accurate_hyperbolic
        return accurate_hyperbolic.cosh(x, precision).named("cosh")
    h = _exp_half(Abs(x), precision)
    return (h + _reciprocal(h, 0.25, precision)).named("cosh")


@routine
def tanh(x, precision: Precision = Precision.FULL):
    """tanh(x) for Float values of any width; see the module docstring."""
    x = float_value(x, "tanh")
    if _beyond_vulkan(precision):
        from . import accurate_hyperbolic
        return accurate_hyperbolic.tanh(x, precision).named("tanh")
    ax = Abs(x)
    h = _exp_half(ax + ax, precision)
    large = 1.0 - _reciprocal(h + 0.5, 1.0, precision)
    small = _odd_small(ax, continuum.polynomial("tanh") if _full(precision) else P.TANH_RELAXED)
    return CopySign(Select(ax < 0.55, small, large), x).named("tanh")
