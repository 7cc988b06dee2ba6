"""The faithful and correct tiers of asin, acos and atan (and a faithful atan2): float64 lanes.

A float32 input is exact in float64, and so are the reductions below; one float64 polynomial
then gives f(x) as ``y`` with a small relative error, and ``routines.correct.finish`` rounds it
(once for faithful; with the rounding test and the hard-case table for correct). u = 2^-53
below (a float64 rounding), a = |x|.

asin, acos
----------
Both are built on asin(r) = r Q(u), u = 4 r^2 in [0, 1] (Q: ASIN_CORRECT, degree 12, or
ASIN_FAITHFUL, degree 6; fitted with their constant term free, relative error of asin; the fit
of asin(sqrt(z))/sqrt(z) on [0, 1/4] scaled exactly):

    a <= 1/2:  r = a, u = (2a)^2 (rounded)
    a > 1/2:   u = 4w = 2 - 2a (exact), w = (1 - a)/2, and v = sqrt(u) = 2 sqrt(w) (float64 sqrt,
               correctly rounded): asin(a) = pi/2 - 2 asin(sqrt(w)) = pi/2 - v Q(u),
               acos(x) = 2 asin(sqrt(w)) = v Q(u) for x > 1/2, pi - v Q(u) for x < -1/2

    asin(a) = H + v Q(u) with (H, v) = (0, a) or (pi/2, -sqrt(u)); the sign of x is put back
    on the float32 result (asin is odd, asin(-0) = -0).
    acos(x) = H + v Q(u) with (H, v) = (pi/2, -x), (0, sqrt(u)) for x > 1/2, (pi, -sqrt(u)) for
    x < -1/2.

In the correct tier H is a double-double constant (pi/2, pi: head, then its tail added last);
v Q + H is one fused multiply-add where the target has FMA (``doubled.fused()``).

atan
----
Three sectors, so that the reduced argument stays within |t| <= tan(pi/8):

    a <= 0.41421357:             t = a,               H = 0
    0.41421357 < a <= 2.4142137: t = (a - 1)/(a + 1),  H = pi/4
    a > 2.4142137:               t = -1/a,             H = pi/2

one float64 division t = (a p - q)/(a q + p) with (p, q) = (1, 0), (1, 1), (0, 1): numerator and
denominator are exact, so t has one rounding. atan(a) = H + t R(t^2) (R: ATAN_CORRECT, degree 10
in t^2, or ATAN_FAITHFUL, degree 5, on t^2 in [0, 0.1716] which holds max t^2 = 0.1715729).
a is clamped to 2^64 first (inf * 0 would be NaN): atan(+-inf) = +-pi/2 rounded, the float32
0x3FC90FDB; the clamp moves atan by at most 2^-64. Huge a needs nothing else (t = -1/a).
The sign of x is put back on the float32 result (atan(-0) = -0).

Error analysis (correct tier; relative error of y against f(x), before the float32 rounding)
---------------------------------------------------------------------------------------------
e: the polynomial's fit error (levelled, relative): 2^-56.0 (asin), 2^-54.7 (atan). Horner's
scheme adds <= 1.1u to Q and R (1.2u unfused: their terms beyond the constant are < 0.06 of it),
the rounded u = (2a)^2 or t^2 another <= 0.06u through Q' and R'.

* asin, a <= 1/2: y = a Q, one rounding: 0.06u + 1.2u + e + u = 2.3u + e.
* asin, a > 1/2: |v Q - 2 asin(sqrt(w))| <= 2 asin(sqrt(w)) (u [sqrt] + 1.2u + e) with
  2 asin(sqrt(w)) <= pi/3 and y >= pi/6, so relative to y that is at most 2 (2.2u + e); then the
  fused multiply-add and the tail's add, u each (unfused: one more rounding, of v Q, 2u relative
  to y): 6.4u + 2e (8.4u + 2e) < 8.7u < 2^-49.8 at most, near a = 1/2.
* acos, |x| <= 1/2: y >= pi/3 and |x Q| <= pi/6: (1.3u + e)/2 + 2u (+0.5u) <= 3.2u + e.
* acos, x > 1/2: y = v Q: u + 1.3u + e + u = 3.3u + e; x < -1/2: y >= 2pi/3 >= 2 |v Q|: 3.6u + e.
* atan: the division's rounding moves atan(t) by <= |t| u <= 0.415u, and y >= pi/8 wherever
  H = pi/4 (y >= |t|, 3pi/8 in the other sectors): <= 1.06u; R, z: <= 1.26u + e (|atan t| <= y);
  the fused multiply-add and the tail's add: 2u (unfused 3u): <= 5.4u + e < 2^-50.5.
* a <= 2^-126 (subnormal x, asin and atan): x^2 and x^3 are normal float64 numbers; nothing
  underflows, the analysis holds (Q(0) and R(0) round to exactly 1).

So every error is below 2^-49 (``correct.ERROR``). Measured max of y's relative error (long
double reference; about 2 million points per function, dense near 1/2, 1, the sector edges,
tiny and huge inputs, both signs for acos, plus 8 million random bit patterns; FMA on / off):
asin 2^-50.70 / 2^-50.40 (at a = 1/2 + 2^-12), acos 2^-51.40, atan 2^-51.69 / 2^-51.44.

Faithful tier
-------------
The same reductions with lower-degree polynomials, evaluated with rounded multiplies and adds
(no float64 FMA: the same bits on every target; the exact products, (1 - a)/2, a p - q and
a q + p, may fuse since they are exact), and no tails of pi/2, pi (< 2^-52 relative). Fit
errors 2^-31.9 (asin, twice that relative to asin(a) near a = 1/2) and 2^-30.6 (atan), so
|y - f(x)| <= 2^-30.6 |f(x)| and the result errs by at most 0.5 + 2^24 2^-30.6 = 0.51 ULP
(measured on y: asin 2^-30.87, acos 2^-31.87, atan 2^-30.63). The faithful bits are the same
with FMA on and off.

Measured on the compiled routines (``python -m routines ladder asin acos atan``, every 256th
input, FMA on and off): correct 0 misrounded; faithful max 0.5041 ULP (asin), 0.5034 (acos),
0.5098 (atan). atan2 on 0.66M pairs (strata of x, the sector edges): max 0.5094 ULP.

Speed (AVX-512, Zen 4, 64K float32 inputs, medians, same run as NumPy's float32 function: asin,
acos on [-1, 1], atan on [-10, 10]): faithful 0.9-1.0x NumPy (asin 0.9x, acos 1.0x, atan
1.02x), correct 1.25-1.4x with FMA (1.7-1.9x without); atan2 faithful 0.92x np.arctan2. About
a quarter of the correct tier's time is ``correct.finish``'s rounding test.

Specials (C99 Annex F, ``docs/specials.md``; NaN bits as ``base.nan_rule``)
-------------------------------------------------------------------------
asin(+-0) = +-0, asin(+-1) = +-pi/2, acos(1) = +0, acos(-1) = pi, acos(+-0) = pi/2 (all from
the formulas). |x| > 1 and +-inf: the default NaN 0xffc00000; a NaN input comes back quieted
(x + x). atan(+-0) = +-0, atan(+-inf) = +-pi/2 (0x3FC90FDB), NaN quieted.

atan2 (faithful)
----------------
atan2(y, x) = s_y (H' + s_x t R(t^2)), the same sectors chosen on the ratio |y|/|x| (a float32
division: near a sector's edge its 2^-24 error moves |t| by ~2^-25, within R's interval) and
t = (|y| p - |x| q)/(|y| q + |x| p) in float64 with exact numerator and denominator (|y| - |x|
is exact where their ratio lies within [0.41, 2.42]): t has one rounding, as in atan, no ratio
y/x rounded first. H' = H where x >= +0, pi - H where x <= -0 (the sign bit: atan2(+-0, -0) =
+-pi), and s_x t then -t. So the error is atan's (pi - H - tR >= pi/2 >= |tR|): <= 0.51 ULP.
Infinities are replaced first (a rare branch): both infinite -> |y| = |x| = 1 (+-pi/4,
+-3pi/4), y infinite -> (1, 0), x infinite -> (0, 1), and (0, 0) -> (0, 1) (+-0 or +-pi by x's
sign bit). A NaN in either operand gives the first NaN (y's, else x's) quieted.
"""
from __future__ import annotations

import reactor
from reactor import Abs, Any, As, CopySign, Fma, If, IsInf, IsNan, Min, Precision, Select, Sqrt, Variable, vector_type

from . import correct
from . import doubled as dd
from .base import DEFAULT_NAN_BITS, nan_rule
from .polynomials import DoublePolynomial

#: pi/2, pi, pi/4 as double-doubles (head, tail; mpmath at 50 digits)
PIO2 = (1.5707963267948966, 6.123233995736766e-17)
PI = (3.141592653589793, 1.2246467991473532e-16)
PIO4 = (0.7853981633974483, 3.061616997868383e-17)
#: atan's sector boundaries, float32 values just above tan(pi/8) and tan(3pi/8)
TAN_PI_8 = 0.4142135679721832
TAN_3PI_8 = 2.4142136573791504
#: atan's clamp: |x| above it is 2^64 (atan moves by < 2^-64)
ATAN_CLAMP = 2.0 ** 64

_ASIN_Q = "2*asin(sqrt(x)/2)/sqrt(x)"
_ATAN_Q = "atan(sqrt(x))/sqrt(x)"


def _fit(name, function, interval, degree, error, coefficients, note, measured):
    lo, hi = interval
    return DoublePolynomial(
        name=name, function=function, weight=function, interval=interval, coefficients=coefficients,
        provenance=(f'our Remez fitter: python -m routines remez -d {degree} -r "{lo}:{hi}" "{function}" '
                    f'"{function}" --json --dps 60; relative error, constant term free; levelled error '
                    f"{error}; {note}"),
        measured=measured + "; python -m routines ladder asin acos atan (--exhaustive: every input)")


_SAMPLED = "compiled kernel, every 256th input (2^24), FMA on and off"


ASIN_CORRECT = _fit(
    "asin.correct", _ASIN_Q, ("0", "1"), 12, "1.42e-17 (2^-56.0)",
    ('0.00000000191308694691777596547590722346', '-0.00000000393670844430119161261335957906',
     '0.0000000188120725043655851534314959254', '0.0000000246025286921427138895522657924',
     '0.00000018599229595526837013584392091', '0.000000847280447991668451841778840652',
     '0.00000423830435493923250109389258997', '0.0000218473905960140900647975183823',
     '0.000118679533790452012248556306633', '0.000697544637209508658517803256345',
     '0.00468750000026123114992171258145', '0.0416666666666619257885111004063',
     '1.00000000000000001424422572537'),
    "asin(r) = r Q(4 r^2), 4 r^2 in [0, 1] (the fit of asin(sqrt(z))/sqrt(z) on [0, 1/4] with its "
    "coefficients scaled by 4^-k, the same binary64 values); degree 12 rather than 11 (2^-52.0): near "
    "|x| = 1/2 asin = pi/2 - 2 asin(s) doubles the fit error",
    "float64 value's relative error (long double reference, ~10M points): asin 2^-50.70 (FMA on) / 2^-50.40 "
    f"(off) at |x| = 1/2 + 2^-12, acos 2^-51.40; {_SAMPLED}: asin and acos correct, 0 misrounded")
ASIN_FAITHFUL = _fit(
    "asin.faithful", _ASIN_Q, ("0", "1"), 6, "2.55e-10 (2^-31.9)",
    ('0.00000924942105296422154821587342953', '0.00001380806315392247510119692446',
     '0.000124612555198227734489094474162', '0.000695360707605846448768971696337',
     '0.00468787756662186328324841841856', '0.0416666423617345402314240944466',
     '1.00000000025460678255255462137'),
    "asin(r) = r Q(4 r^2), 4 r^2 in [0, 1]",
    f"float64 value's relative error: asin 2^-30.87 (near |x| = 1/2), acos 2^-31.87; {_SAMPLED}: max "
    "0.5041 ULP (asin), 0.5034 ULP (acos)")
ATAN_CORRECT = _fit(
    "atan.correct", _ATAN_Q, ("0", "0.1716"), 10, "3.32e-17 (2^-54.7)",
    ('0.0211681256497928244342077410375', '-0.0435087791335876885219113742049',
     '0.0568938549924764590810095493808', '-0.0664044437544556664260970337761',
     '0.0768997932894458009264817868724', '-0.090907750379970809069002452281',
     '0.111111062713181337600650172623', '-0.142857141833931109827610768072',
     '0.199999999988877716443831228716', '-0.333333333333286099437826139523',
     '0.99999999999999996680509719211'),
    "atan(t) = t R(t^2), t^2 in [0, 0.1716] (|t| <= tan(pi/8) after the three sectors; "
    "degree 9 gives 2^-49.9, too close)",
    f"float64 value's relative error: 2^-51.69 (FMA on) / 2^-51.44 (off); {_SAMPLED}: 0 misrounded")
ATAN_FAITHFUL = _fit(
    "atan.faithful", _ATAN_Q, ("0", "0.1716"), 5, "6.04e-10 (2^-30.6)",
    ('-0.0603442203081566470748279132523', '0.105733377305230250726343769281',
     '-0.142400640682341783689833112179', '0.199982159334592626804233580776',
     '-0.333333076072322579241959320948', '0.999999999396139801843562998047'),
    "atan(t) = t R(t^2), t^2 in [0, 0.1716]",
    f"float64 value's relative error: 2^-30.63; {_SAMPLED}: max 0.5098 ULP; atan2, 0.66M sampled pairs: "
    "0.5094 ULP")

POLYNOMIALS = (ASIN_CORRECT, ASIN_FAITHFUL, ATAN_CORRECT, ATAN_FAITHFUL)


def _types(width):
    return vector_type("Float", width), vector_type("Double", width)


def _correct(precision) -> bool:
    return precision is Precision.CORRECT


def _fused(precision) -> bool:
    """Fused float64 arithmetic where it changes bits: the correct tier only, on FMA hardware."""
    return _correct(precision) and dd.fused()


def _exact(a, b, c):
    """a b + c where it is exact: one fused instruction where the target has FMA, the same bits."""
    return Fma(a, b, c) if dd.fused() else a * b + c


def _constant(mask, pair_true, pair_false, D, precision):
    """(head, tail or None) of a double-double constant chosen per lane; the faithful tier drops
    the tail (below 2^-52 relative)."""
    head = Select(mask, D(pair_true[0]), D(pair_false[0]))
    tail = Select(mask, D(pair_true[1]), D(pair_false[1])) if _correct(precision) else None
    return head, tail


def _sum(head, tail, v, q, precision):
    """head + v q (+ tail), in this order: one fused multiply-add in the correct tier on FMA hardware."""
    if tail is None:
        return v * q + head
    return (Fma(v, q, head) if _fused(precision) else v * q + head) + tail


def _asin_q(high, w4, vd, precision):
    """Q(u) with u = 4w = 2 - 2a where ``high`` (exact), (2 vd)^2 elsewhere."""
    twice = vd + vd
    u = Select(high, w4, twice * twice)
    poly = ASIN_CORRECT if _correct(precision) else ASIN_FAITHFUL
    return poly.evaluate(u, _fused(precision))


def asin_double(x, precision):
    """asin(|x|) as float64 lanes (see the module docstring)."""
    _, D = _types(x.width)
    a = Abs(x)
    high = a > 0.5                                   # NaN: false (its lanes are replaced)
    minus_a = D(-a)
    w4 = _exact(minus_a, 2.0, 2.0)                   # 4w = 2 - 2a, exact for a in [1/2, 1]
    q = _asin_q(high, w4, minus_a, precision)
    v = Select(high, Sqrt(w4), minus_a)              # 2 sqrt(w) = sqrt(4w), or -a
    head, tail = _constant(high, PIO2, (0.0, 0.0), D, precision)
    return _sum(head, tail, -v, q, precision)         # pi/2 - 2s Q, or a Q


def acos_double(x, precision):
    """acos(x) as float64 lanes (see the module docstring)."""
    _, D = _types(x.width)
    xd = D(x)
    high = Abs(x) > 0.5
    w4 = _exact(Abs(xd), -2.0, 2.0)                  # 4w = 2 - 2|x|
    q = _asin_q(high, w4, xd, precision)
    v = Select(high, CopySign(Sqrt(w4), xd), -xd)    # +-2s, or -x
    negative = x < 0.0
    head = Select(high, Select(negative, D(PI[0]), D(0.0)), D(PIO2[0]))
    tail = Select(high, Select(negative, D(PI[1]), D(0.0)), D(PIO2[1])) if _correct(precision) else None
    return _sum(head, tail, v, q, precision)


def _sectors(ratio):
    """The sector masks of atan(|ratio|) (NaN: the first sector)."""
    return ratio > TAN_PI_8, ratio > TAN_3PI_8


def _reduced(n, d, m1, m2, precision):
    """(t, R(t^2)) for atan(n/d), n, d >= 0 float64 (exact), in the sectors m1, m2:
    t = (n p - d q)/(n q + d p), one rounding."""
    D = type(n)
    p = Select(m2, D(0.0), D(1.0))
    q = Select(m1, D(1.0), D(0.0))
    t = _exact(n, p, -(d * q)) / _exact(n, q, d * p)
    poly = ATAN_CORRECT if _correct(precision) else ATAN_FAITHFUL
    return t, poly.evaluate(t * t, _fused(precision))


def _sector_head(m1, m2, D, precision):
    """0, pi/4 or pi/2 as (head, tail or None)."""
    head = Select(m2, D(PIO2[0]), Select(m1, D(PIO4[0]), D(0.0)))
    tail = Select(m2, D(PIO2[1]), Select(m1, D(PIO4[1]), D(0.0))) if _correct(precision) else None
    return head, tail


def atan_double(x, precision):
    """atan(|x|) as float64 lanes (see the module docstring)."""
    F, D = _types(x.width)
    a = Abs(x)
    m1, m2 = _sectors(a)
    t, r = _reduced(D(Min(a, F(ATAN_CLAMP))), D(1.0), m1, m2, precision)  # inf -> 2^64, NaN -> 2^64
    head, tail = _sector_head(m1, m2, D, precision)
    return _sum(head, tail, t, r, precision)


def _domain(x, a, result):
    """NaN where |x| > 1 (the default NaN) or x is NaN (x quieted)."""
    F = type(x)
    out = Variable(F, result)
    outside = ~(a <= 1.0)
    with If(Any(outside)):
        default = As(F, vector_type("Int", x.width)(DEFAULT_NAN_BITS))
        out.set(Select(outside, Select(IsNan(x), x + x, default), out))
    return out.value


def asin(x, precision):
    """asin(x), faithful or correctly rounded (``precision``); see the module docstring."""
    a = Abs(x)
    y = asin_double(x, precision)
    return _domain(x, a, CopySign(correct.finish(a, y, precision, "asin"), x))


def acos(x, precision):
    """acos(x), faithful or correctly rounded (``precision``); see the module docstring."""
    return _domain(x, Abs(x), correct.finish(x, acos_double(x, precision), precision, "acos"))


def atan(x, precision):
    """atan(x), faithful or correctly rounded (``precision``); see the module docstring."""
    a = Abs(x)
    r = CopySign(correct.finish(a, atan_double(x, precision), precision, "atan"), x)
    return Select(IsNan(x), x + x, r)


def operands(y, x):
    """(|y|, |x|) with the infinities as (1, 0), (0, 1) or (1, 1) and (0, 0) as (0, 1): the
    magnitudes whose angle is |atan2(y, x)| (x's sign is applied from its sign bit)."""
    F, _ = _types(x.width)
    ay, ax = Variable(F, Abs(y)), Variable(F, Abs(x))
    infinite = IsInf(y) | IsInf(x)
    with If(Any(infinite | ((ay.value + ax.value) == 0.0))):        # rare: infinities, (0, 0)
        one, zero = F(1.0), F(0.0)
        ay_v, ax_v = ay.value, ax.value
        ay.set(Select(infinite, Select(IsInf(y), one, zero), ay_v))
        ax.set(Select(infinite, Select(IsInf(x), one, zero), Select((ay_v + ax_v) == 0.0, one, ax_v)))
    return ay.value, ax.value


def atan2_double(y, x, precision=Precision.FAITHFUL, magnitudes=None):
    """|atan2(y, x)| as float64 lanes (see the module docstring; y's sign is put back later), from
    ``magnitudes`` (``operands(y, x)``, computed here if None)."""
    F, D = _types(x.width)
    ay, ax = operands(y, x) if magnitudes is None else magnitudes
    m1, m2 = _sectors(ay / ax)
    t, r = _reduced(D(ay), D(ax), m1, m2, precision)
    head, tail = _sector_head(m1, m2, D, precision)
    x_negative = As(vector_type("Int", x.width), x) < 0                 # the sign bit: -0 too
    head = Select(x_negative, D(PI[0]) - head, head)                    # exact: pi - 0, pi/4, pi/2
    t = Select(x_negative, -t, t)
    if tail is not None:
        tail = Select(x_negative, D(PI[1]) - tail, tail)
    return _sum(head, tail, t, r, precision)


def atan2(y, x, precision=Precision.FAITHFUL):
    """atan2(y, x), the angle of (x, y) in [-pi, pi], faithful, C99 specials; see the docstring."""
    if precision is not Precision.FAITHFUL:
        raise reactor.ReactorError(f"atan2 has a faithful tier here, not {precision.value!r}")
    r = CopySign(correct.finish(y, atan2_double(y, x, precision), precision, "atan2"), y)
    return nan_rule(Select(IsNan(y) | IsNan(x), y + x, r), y, x)
