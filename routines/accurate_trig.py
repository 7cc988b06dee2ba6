"""The faithful and correct tiers of sin, cos and tan: float64 lanes, one rounding.

Each routine computes y, float64 lanes within 2^-49 relative of f(x) (``routines.correct.ERROR``)
for every finite float32 x, and ends in ``correct.finish`` (one rounding for faithful; for
correct a rounding test at 2^-47 and the table ``hard_cases/<name>.npy`` for the few inputs it
cannot decide), then the specials.

Reduction
---------
sin and cos are reduced modulo pi, so that one polynomial serves both:

    sin(|x|) = (-1)^k sin(t),  |x| = k pi + t,          k = round(|x| / pi)
    cos(|x|) = (-1)^k sin(t),  |x| = (k - 1/2) pi + t,  k = round(|x| / pi + 1/2)

tan modulo pi/2: |x| = q pi/2 + r. k and q are rounded in float32 lanes from fl32(1/pi) and
fl32(2/pi) (any whole k keeps the result right; the rounding only widens |t| to <= 1.584 and
|r| to <= 0.797, which the polynomials cover). Then, for |x| <= 2^17 (k < 2^16, q < 2^17):

* Cody-Waite in float64, t = ((|x| - h P1) - h P2) - h P3 (h = k, k - 1/2 or q; P1 + P2 + P3
  = pi or pi/2 within 4.3e-35 * 2, each part of <= 35 significant bits), so every product h Pi
  is exact and each step is one rounding, fused (where the target has FMA) or not: the same
  bits on every target. The first step is exact (Sterbenz; cos's k = 0 excepted, where there
  is no cancellation), the next two round to 2^-53 of their result, and h times the rest of pi
  is < 4e-30. The float32 x nearest a multiple of pi/2 below 2^17 is 252.898 (0x437ce5f1),
  4.19e-9 away (an exact search of every binade), so t's relative error is <= 2^-52 + 2^-70.
* Beyond (and +-inf), only when some lane needs it (``If(Any(...))``): Payne-Hanek in
  float64, ``trig.reduce_large_double(extended=True)``: the reduction of the full tier with a
  sixth 28-bit piece of 2/pi, so that the tail's error (2^-53 |x| tail, up to 2^-66 near 2^128
  with five pieces) falls below 2^-95 next to a fraction that is never below 2^-30 (the float32
  nearest a multiple of pi/2 overall: 7.73e28 = 0x6f79be45, 1.6e-9 away), r = fraction * pi/2.
  For sin and cos the quadrant becomes t = r (even q) or t = (pi/2 - |r|) (odd q, pi/2 as a
  double pair, t in [pi/4, pi/2]: no cancellation).

Measured relative error of t (and r), mpmath, on the 516 float32 nearest a multiple of pi/2 in
every binade, their neighbours and 3,000 random arguments: <= 3.0e-16 (2^-51.6).

Evaluation
----------
sin(t) = t (1 + z P(z)), z = t^2, |t| <= 1.6 (a product, so that sin(-0) = -0), the sign
(-1)^k (and x's sign for sin) applied to t first. tan(r) = r N(z) / D(z), z = r^2, for even q
and -D(z) / (r N(z)) for odd q (one division; near a pole tan ~ -1/r and r's relative error
decides it). D is the Pade denominator of tan(sqrt z)/sqrt z and N its minimax numerator for
that D (``TAN_*``). The correct tier evaluates the polynomials with fused multiply-adds where
``doubled.fused()``; the faithful tier with rounded multiplies and adds, the same bits on every
target and FMA setting.

Error analysis (relative, float64 value)
----------------------------------------
correct: sin, cos: t 2^-52, polynomial 2^-52.1 (SIN_PI_CORRECT, degree 6 in z on [0, 2.56]),
evaluation ~3 roundings of 2^-53 (z, the Horner sum's last steps scaled by z P <= 0.37, the
product) -- total < 2^-50.2. tan: r 2^-52, rational 2^-55.5 (N degree 4, D degree 3), r N, N,
D and the division ~5 roundings -- total < 2^-50.2. Both below 2^-49.
faithful: the polynomials level at 2^-35.0 (sin, cos: degree 4) and 2^-29.2 (tan: degrees 2
and 2), so the result errs by at most 0.5 + 2^24 * 2^-29.2 = 0.53 ULP.

Measured (mpmath at 400 bits, 9,000-13,000 arguments: the worst cases of the reduction and their
neighbours, the float32 nearest k pi/2 for k < 2,000, [2^17, 2^18], [1e30, 3.4e38], tiny |x|,
random bit patterns of every binade; both signs): correct 5.4e-16 (2^-50.7) for tan, 5.0e-16
(2^-50.8) for sin and cos, FMA on or off; faithful 2.96e-11 (2^-35.0), tan 1.62e-9 (2^-29.2).
Compiled routines (``python -m routines ladder sin cos tan``, every 256th bit pattern, FMA on
and off): correct 0 misrounded; faithful max 0.5005 ULP (sin, cos), 0.527 ULP (tan).

Specials (docs/specials.md)
---------------------------
sin(+-0) = +-0, tan(+-0) = +-0, cos(+-0) = 1; tiny and subnormal x give sin(x) = tan(x) = x
and cos(x) = 1 as the rounding of the exact value; +-inf gives the default NaN 0xffc00000, a NaN
comes back quieted (``base.nan_rule``), selected in a branch taken only when some lane is not
finite.
"""
from __future__ import annotations

import reactor
from reactor import Abs, Any, As, Fma, If, IsFinite, IsNan, Precision, Round, Select, ToInt, Variable, vector_type

from . import correct
from . import doubled as dd
from .base import DEFAULT_NAN_BITS, nan_rule
from .polynomials import DoublePolynomial

#: |x| up to which the Cody-Waite reduction runs (q <= 83443 < 2^17: q * PIO2_PARTS[i] exact).
FAST_LIMIT = 2.0 ** 17
#: pi/2 = P1 + P2 + P3 + 4.3e-35, each part of <= 35 significant bits (35, 35, 33), so that
#: q * Pi is exact for a whole q < 2^17 (and 2h Pi for a half-integer h) and every step is one
#: rounding, fused or not.
PIO2_PARTS = (1.5707963267923333, 2.5633441515839558e-12, 1.0562999066944068e-23)

#: 1/pi and 2/pi rounded to float32: k = round(|x| * INV_PI_F32), q = round(|x| * TWO_OVER_PI_F32)
#: in float32 lanes (then |t| <= 1.584, |r| <= 0.797: the polynomials' intervals cover them).
INV_PI_F32 = 0.31830987334251404
TWO_OVER_PI_F32 = 0.6366197466850281
#: pi = 2 PIO2_PARTS (the same bits): q * Pi exact for q a multiple of 1/2 below 2^16.
PI_PARTS = tuple(2.0 * p for p in PIO2_PARTS)
#: pi/2 as a double pair (head: the double nearest pi/2).
PIO2_PAIR = (1.5707963267948966, 6.123233995736766e-17)

_SIN_F = "(sin(sqrt(x))-sqrt(x))/x^1.5"
_SIN_W = "sin(sqrt(x))/x^1.5"


def _provenance(f, w, degree, error, note, interval="0:0.64"):
    return (f'our Remez fitter: python -m routines remez -d {degree} -r "{interval}" "{f}" "{w}" --json --dps 60; '
            f"levelled error {error}; {note}")


_TAN_F43 = ("tan(sqrt(x))/sqrt(x)*((1.0)+(-0.4642857142857143)*x^1+(0.02454212454212454)*x^2"
            "+(-0.0002553002553002553)*x^3)")
_TAN_F22 = "tan(sqrt(x))/sqrt(x)*((1.0)+(-0.4444444444444444)*x^1+(0.015873015873015872)*x^2)"

TAN_DEN_CORRECT = DoublePolynomial(
    name="tan.den.correct", function="the Pade [4/3] denominator of tan(sqrt(x))/sqrt(x)", weight="",
    interval=("0", "0.64"),
    coefficients=("-0.0002553002553002553", "0.02454212454212454", "-0.4642857142857143", "1.0"),
    provenance="D(z) = 1 - 13/28 z + 67/2730 z^2 - 23/90090 z^3 (mpmath.pade of the Taylor series of "
               "tan(sqrt(z))/sqrt(z), orders 4 and 3, scaled to D(0) = 1), each coefficient rounded to float64; "
               "tan(r) = r N(r^2) / D(r^2) with N fitted to this D (tan.num.correct)",
    measured="see routines/accurate_trig.py")

TAN_NUM_CORRECT = DoublePolynomial(
    name="tan.num.correct", function=_TAN_F43, weight=_TAN_F43, interval=("0", "0.64"),
    coefficients=("-0.0000000176190199705873581400780644993", "-0.0000111000111428246532625402663177",
                  "0.00311355311356610262336797713805", "-0.130952380952382248330031581653",
                  "1.00000000000000001993243732359"),
    provenance=_provenance(_TAN_F43, _TAN_F43, 4, "1.99e-17 (2^-55.5)",
                           "relative error of tan(r) = r N(z) / D(z), z = r^2, |r| <= 0.8, for the float64 "
                           "D of tan.den.correct (the function's D is its coefficients' exact values)"),
    measured="see routines/accurate_trig.py")

TAN_DEN_FAITHFUL = DoublePolynomial(
    name="tan.den.faithful", function="the Pade [2/2] denominator of tan(sqrt(x))/sqrt(x)", weight="",
    interval=("0", "0.64"), coefficients=("0.015873015873015872", "-0.4444444444444444", "1.0"),
    provenance="D(z) = 1 - 4/9 z + 1/63 z^2 (mpmath.pade, orders 2 and 2, as tan.den.correct)",
    measured="see routines/accurate_trig.py")

TAN_NUM_FAITHFUL = DoublePolynomial(
    name="tan.num.faithful", function=_TAN_F22, weight=_TAN_F22, interval=("0", "0.64"),
    coefficients=("0.0010582802535704698698138516811", "-0.111111142759249812294260665379",
                  "1.00000000161882168985257610014"),
    provenance=_provenance(_TAN_F22, _TAN_F22, 2, "1.62e-9 (2^-29.2)", "as tan.num.correct for tan.den.faithful"),
    measured="see routines/accurate_trig.py")

SIN_PI_CORRECT = DoublePolynomial(
    name="sin.pi.correct", function=_SIN_F, weight=_SIN_W, interval=("0", "2.56"),
    coefficients=("-7.36309310750838544332684859554e-13", "1.60472541680246239687786681147e-10",
                  "-0.0000000250518533638183562731473745424", "0.00000275573161785073348759756050289",
                  "-0.000198412698217218011663351941701", "0.00833333333327347556387737826542",
                  "-0.166666666666660415420007354197"),
    provenance=_provenance(_SIN_F, _SIN_W, 6, "2.08e-16 (2^-52.1)",
                           "relative error of sin(t) = t + t^3 P(t^2) for |t| <= 1.6 (sin and cos reduced "
                           "modulo pi), fitted in z = t^2", interval="0:2.56"),
    measured="see routines/accurate_trig.py")

SIN_PI_FAITHFUL = DoublePolynomial(
    name="sin.pi.faithful", function=_SIN_F, weight=_SIN_W, interval=("0", "2.56"),
    coefficients=("-0.000000023845378330018404084212872673", "0.0000027522924805667911957130064828",
                  "-0.000198408206053885560506759114888", "0.0083333307480697007555214325626",
                  "-0.166666666177272826566296873995"),
    provenance=_provenance(_SIN_F, _SIN_W, 4, "2.96e-11 (2^-35.0)", "as sin.pi.correct with degree 4",
                           interval="0:2.56"),
    measured="see routines/accurate_trig.py")

DOUBLE = (SIN_PI_CORRECT, SIN_PI_FAITHFUL, TAN_NUM_CORRECT, TAN_DEN_CORRECT, TAN_NUM_FAITHFUL, TAN_DEN_FAITHFUL)


def _types(width):
    return vector_type("Float", width), vector_type("Double", width), vector_type("Int", width)


def _fused(precision) -> bool:
    """Fused float64 polynomial steps: the correct tier only, where the target has FMA."""
    return precision is Precision.CORRECT and dd.fused()


def reduce(x):
    """(r, q): |x| = q pi/2 + r with r in float64 lanes (relative error ~2^-52, |r| <= 0.797)
    and q & 3 the quadrant (Int lanes)."""
    F, D, _ = _types(x.width)
    ax = Abs(x)
    q = Round(ax * TWO_OVER_PI_F32)                       # whole; < 2^17 where |x| <= 2^17
    r_var, q_var = Variable(D, _cody_waite(D(ax), D(q), PIO2_PARTS)), Variable(F, q)
    huge = ax > FAST_LIMIT                                # +-inf too; NaN not
    with If(Any(huge)):
        from .trig import reduce_large_double
        r_h, q_h = reduce_large_double(ax, extended=True)
        r_var.set(Select(huge, r_h, r_var))
        q_var.set(Select(huge, F(q_h), q_var))
    return r_var.value, ToInt(q_var.value, saturate=False) & 3


def _specials(x, result):
    """NaN -> x quieted; +-inf -> the default NaN 0xffc00000."""
    F, _, I = _types(x.width)
    special = Select(IsNan(x), nan_rule(x + x, x), As(F, I(DEFAULT_NAN_BITS)))
    return Select(IsFinite(x), result, special)


def _negative_x(x):
    _, _, I = _types(x.width)
    return As(I, x) < 0


def _cody_waite(d, k, parts):
    """d - k (P1 + P2 + P3) in float64 lanes (each k * Pi exact: see PIO2_PARTS)."""
    exact = dd.fused()                                    # every product exact: the same bits
    r = d
    for part in parts:
        r = Fma(k, -part, r) if exact else r - k * part
    return r


def _reduce_pi(x, cosine):
    """(t, odd): sin(|x|) (cos(|x|) if ``cosine``) = (-1)^k sin(t) with t in float64 lanes
    (relative error ~2^-52), |t| <= 1.584, and ``odd`` the lanes where k is odd."""
    F, D, _ = _types(x.width)
    ax = Abs(x)
    if cosine:                                            # |x| = (k - 1/2) pi + t
        k = Round(ax * INV_PI_F32 + 0.5)
        t = _cody_waite(D(ax), D(k - 0.5), PI_PARTS)
    else:                                                 # |x| = k pi + t
        k = Round(ax * INV_PI_F32)
        t = _cody_waite(D(ax), D(k), PI_PARTS)
    t_var, k_var = Variable(D, t), Variable(F, k)
    huge = ax > FAST_LIMIT                                # +-inf too; NaN not
    with If(Any(huge)):
        from .trig import reduce_large_double
        r, q = reduce_large_double(ax, extended=True)    # |x| = q pi/2 + r, |r| <= pi/4
        if cosine:
            q = q + 1.0                                   # cos(v) = sin(v + pi/2)
        half = reactor.Floor(q * 0.5)
        odd = q != half * 2.0                             # sin(2j pi/2 + r) = (-1)^j sin(r),
        t_huge = Select(odd, (PIO2_PAIR[0] - Abs(r)) + PIO2_PAIR[1], r)  # sin((2j+1) pi/2 + r) =
        t_var.set(Select(huge, t_huge, t_var))          # (-1)^j sin(pi/2 - |r|)
        k_var.set(Select(huge, F(half), k_var))
    return t_var.value, (ToInt(k_var.value, saturate=False) & 1) != 0


def _sin_poly(t, negative, precision):
    """+-sin(t) (- where ``negative``) in float64 for |t| <= 1.6, as t (1 + z P(z)), z = t^2
    (a product, so that sin(-0) = -0)."""
    poly = SIN_PI_CORRECT if precision is Precision.CORRECT else SIN_PI_FAITHFUL
    fused = _fused(precision)
    t = Select(negative, -t, t)
    z = t * t
    p = poly.evaluate(z, fused)
    return t * (Fma(z, p, 1.0) if fused else z * p + 1.0)


def _tan(x, precision):
    """tan(x) in float64: |x| = q pi/2 + r, tan(r) = r N(z) / D(z) (z = r^2) for even q,
    -1/tan(r) = -D(z) / (r N(z)) for odd q; one division."""
    num_p, den_p = ((TAN_NUM_CORRECT, TAN_DEN_CORRECT) if precision is Precision.CORRECT
                    else (TAN_NUM_FAITHFUL, TAN_DEN_FAITHFUL))
    fused = _fused(precision)
    r, q = reduce(x)
    odd = (q & 1) != 0
    z = r * r
    n = r * num_p.evaluate(z, fused)
    d = den_p.evaluate(z, fused)
    v = Select(odd, d, n) / Select(odd, n, d)
    return Select(odd ^ _negative_x(x), -v, v)


def value(x, precision, name):
    """name(x) ("sin", "cos" or "tan") in float64 lanes, signed, before the one rounding
    (garbage where x is not finite)."""
    if name == "tan":
        return _tan(x, precision)
    t, negative = _reduce_pi(x, name == "cos")
    if name == "sin":
        negative = negative ^ _negative_x(x)
    return _sin_poly(t, negative, precision)


def _function(x, precision, name):
    F = vector_type("Float", x.width)
    result = Variable(F, correct.finish(x, value(x, precision, name), precision, name))
    finite = IsFinite(x)
    with If(Any(~finite)):                                # infinities and NaNs: rare
        result.set(_specials(x, result.value))
    return result.value


def sin(x, precision):
    """sin(x), faithful or correctly rounded; see the module docstring."""
    return _function(x, precision, "sin")


def cos(x, precision):
    """cos(x), faithful or correctly rounded; see the module docstring."""
    return _function(x, precision, "cos")


def tan(x, precision):
    """tan(x), faithful or correctly rounded; see the module docstring."""
    return _function(x, precision, "tan")
