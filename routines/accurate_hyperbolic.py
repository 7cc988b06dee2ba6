"""The faithful and correct tiers of sinh, cosh and tanh: float64 lanes, rounded by ``routines.correct``.

Reduction
---------
a = min(|x|, clamp) (89.5 for sinh and cosh, 10 for tanh; a float32, exact in float64), and

    k = round(a * log2(e))      in float32: |a log2(e) - k| <= 1/2 + 5e-6, 0 <= k <= 130
    r = a - k ln2               in float64, ln 2 = LN2_HI + LN2_LO with LN2_HI on 45 bits

k * LN2_HI is exact (k < 2^8) and so is a - k * LN2_HI (Sterbenz for k >= 1; both on the 2^-45
grid, |r| < 1/2); subtracting k * LN2_LO rounds once: r is within 2^-53 |r| + 2^-94 of a - k ln 2
(for k = 0, r = a exactly). |r| <= 0.346577 (ln2/2 + 3.3e-6: checked on every float32 a within
2e-3 of the switch points (k + 1/2) ln 2, elsewhere the float32 product is far from a tie), so
z = r^2 <= 0.12012, inside the fits' interval [0, 0.1202].

Formula
-------
The addition theorem with cosh r = 1 + z E1(z), sinh r = r + r z O1(z):

    sinh(k ln2 + r) = 4 [(sh + ch r) + z (sh E1 + (ch r) O1)]
    cosh(k ln2 + r) = 4 [(ch + sh r) + z (ch E1 + (sh r) O1)]
    sh, ch = sinh(k ln2) / 4, cosh(k ln2) / 4 = 2^(k-3) -+ 2^(-k-3)

2^(k-3) and 2^(-k-3) are float32 powers of two built in the exponent field (the second flushed to
+0 for k > 123, where it is below 2^-56 of the first) and converted exactly; their difference and
sum are exact for k <= 26 and within 2^-53 above. For k = 0 (|x| < ln2/2) sh = 0 and ch = 1/4:
sinh = r + r^3 O1 is the odd polynomial of small |x| and cosh = 1 + z E1, so there is no switch
between formulas and no cancellation of e^x - e^-x near 0; what cancellation remains is at k = 1,
r = -ln2/2 (sinh: 0.75 - 0.433 = 0.317 before the small terms), which the bound below includes.
tanh is the ratio of the two brackets with (sh, ch) = (1 - 4^-k, 1 + 4^-k) (the factor 2^(k+1)
cancels; 4^-k >= 2^-28 is a normal float32 for k <= 14, and both are exact): one float64
division. With FMA (correct tier, ``doubled.fused()``) sh + ch r, the inner sum and the last
add are fused; elsewhere every operation is a rounded multiply or add.

Polynomials (``POLYNOMIALS``, Remez fits of the absolute error of z E1(z) = cosh(sqrt z) - 1 and
z O1(z) = sinh(sqrt z)/sqrt z - 1 on z in [0, 0.1202], tolerance 1/x): correct tier E1 and O1 of
degree 4 (7.6e-18 and 5.1e-19 with binary64 coefficients), faithful tier degree 2 (4.7e-11 and
5.3e-12); the faithful tier also leaves LN2_LO out (|k LN2_LO| < 2^-41.9).

Error of the float64 value (what ``correct.finish`` rounds; contract: below 2^-49 relative)
---------------------------------------------------------------------------------------
First order in u = 2^-53 (second-order terms are below 2^-100), over every k in [0, 130] and r
on a grid of [-0.346577, 0.346577] (the worst case is r = -ln2/2: k = 130 for sinh and cosh,
where sh and ch round, k = 1 for tanh, where the numerator cancels most): r's rounding (u |r|, through d/dr = big sinh r + small cosh r), E1 and O1 as Horner's
rule gives them (relative 1.02 u: their terms beyond the constant are below 1% of it) plus the fit
errors above, z = fl(r^2) (u z |t|), sh and ch (u each above k = 26), and every rounding of the
combination (7 plain, 5 fused):

    sinh, cosh:  2^-50.60 (plain), 2^-50.79 (fused)
    tanh:        2^-49.88 (plain), 2^-50.22 (fused): numerator + denominator + the division
    faithful:    2^-32.5 (tanh; sinh 2^-33.1, cosh 2^-33.7): below 0.5 + 2^-8.5 ULP once rounded

Measured against mpmath (tests/routines/test_accurate_hyperbolic.py's points plus 20,000 per
function around every switch point, k = 1's cancelling region and tiny values): correct tier
sinh 2^-51.6, cosh 2^-52.1, tanh 2^-51.1 (FMA on or off); faithful 2^-33.3, 2^-33.9, 2^-34.5.

Compiled routine (``python -m routines ladder``, every 256th float32): correct tier 0 misrounded
(FMA on and off); faithful max 0.5009 ULP (sinh), 0.5008 (cosh), 0.5006 (tanh), the same bits
with FMA on and off and at sse4, avx2 and avx512.

Specials and edges
------------------
Overflow: sinh and cosh round to +-inf exactly from |x| = 89.41599 (0x42b2d4fd; the last finite
is 89.415985): |x| is clamped at 89.5, whose sinh (3.7e38) rounds to inf, so +-inf, and every
|x| beyond, give +-inf; the correct tier's hard-case table holds the inputs near the threshold.
tanh: |x| is clamped at 10, tanh(10) = 1 - 4e-9 rounds to 1 (tanh rounds to 1 from 9.0109), so
tanh(+-inf) = +-1. sinh and tanh are computed for |x| (the rounding test and the table lookup of
``correct.finish`` on |x|: both functions are odd and rounding to nearest is symmetric) and take
x's sign at the end, so sinh(-0) = tanh(-0) = -0 and sinh(x) = tanh(x) = x for subnormal x;
cosh(+-0) = 1 exactly. NaN in: the same NaN quieted (x + x; ``base.nan_rule`` off x86).

Speed (AVX-512, 64K float32 over [-10, 10] ([-5, 5] for tanh), median of 40 interleaved calls against
NumPy's float32 function, same run; the machine is shared and noisy): with the default two
threads, faithful 1.3x (sinh), 1.4x (cosh), 1.55x (tanh), correct with FMA 1.65x, 1.75x, 1.8x
(exp's tiers alongside: 0.31x and 0.94x); one thread, faithful 2.5-2.85x, correct 3.2-3.3x (exp
0.48x and 1.7x). The float64 lanes are the cost: 16 float32 lanes are two 512-bit registers of
doubles, and the hot loop is ~75 instructions per 16 lanes (the two degree-4 polynomials alone
are 16 fused multiply-adds; the faithful tier's degree-2 ones, without FMA, as many operations).
"""
from __future__ import annotations

from reactor import Abs, As, CopySign, Fma, IsNan, Max, Min, Precision, Round, Select, ToInt, vector_type

from . import correct
from . import doubled as dd
from .base import nan_rule
from .polynomials import DoublePolynomial

LOG2E_F = 1.4426950216293335                 # float32(log2 e)
LN2_HI = 0.6931471805599472                  # ln 2 on 45 bits (0x1.62e42fefa3a00p-1): k * LN2_HI exact for k < 2^8
LN2_LO = -1.8641886737243033e-15             # ln 2 - LN2_HI (remainder 1.9e-31)
SINH_CLAMP = 89.5                            # sinh, cosh overflow float32 above 89.4159851: k <= 130
TANH_CLAMP = 10.0                            # tanh rounds to +-1 above 9.0109

_E1 = "(cosh(sqrt(x))-1)/x"
_O1 = "(sinh(sqrt(x))/sqrt(x)-1)/x"

COSH_CORRECT = DoublePolynomial(
    name="cosh.reduced.correct", function=_E1, weight="1/x", interval=("0", "0.1202"),
    coefficients=("0.000000276313885207013927576386678732", "0.0000248014896207270890469595285685",
                  "0.00138888889473528884222021360044", "0.0416666666665139694202883713507",
                  "0.50000000000000129508532480216"),
    provenance="our Remez fitter: python -m routines remez -d 4 -r \"0:0.1202\" \"" + _E1 + "\" \"1/x\" --json "
               "--dps 60; levelled error 3.42e-18 (2^-58.0); binary64 coefficients: 7.56e-18 (2^-56.9)",
    measured="float64 value against mpmath (tests/routines/test_accurate_hyperbolic.py): relative error "
             "2^-51.6 (sinh), 2^-52.1 (cosh), 2^-51.1 (tanh), a priori bound 2^-49.9; compiled: 0 misrounded, "
             "FMA on and off (python -m routines ladder sinh cosh tanh, every 256th input)")

SINH_CORRECT = DoublePolynomial(
    name="sinh.reduced.correct", function=_O1, weight="1/x", interval=("0", "0.1202"),
    coefficients=("0.0000000251090752726581594849893817237", "0.00000275572441016739974805530011743",
                  "0.000198412698862307291222668970059", "0.00833333333332159060873290887556",
                  "0.166666666666666766259762966833"),
    provenance="our Remez fitter: python -m routines remez -d 4 -r \"0:0.1202\" \"" + _O1 + "\" \"1/x\" --json "
               "--dps 60; levelled error 2.63e-19 (2^-61.7); binary64 coefficients: 5.10e-19 (2^-60.8)",
    measured="float64 value against mpmath (tests/routines/test_accurate_hyperbolic.py): relative error "
             "2^-51.6 (sinh), 2^-52.1 (cosh), 2^-51.1 (tanh), a priori bound 2^-49.9; compiled: 0 misrounded, "
             "FMA on and off (python -m routines ladder sinh cosh tanh, every 256th input)")

COSH_FAITHFUL = DoublePolynomial(
    name="cosh.reduced.faithful", function=_E1, weight="1/x", interval=("0", "0.1202"),
    coefficients=("0.00139462601068143907326938327325", "0.0416662666567251557531497139561",
                  "0.500000007926110998774567068373"),
    provenance="our Remez fitter: python -m routines remez -d 2 -r \"0:0.1202\" \"" + _E1 + "\" \"1/x\" --json "
               "--dps 60; levelled error 4.74e-11 (2^-34.3); binary64 coefficients: 4.74e-11 (2^-34.3)",
    measured="float64 value against mpmath: relative error 2^-33.3 (sinh), 2^-33.9 (cosh), 2^-34.5 (tanh); "
             "compiled: max 0.5009 / 0.5008 / 0.5006 ULP (python -m routines ladder sinh cosh tanh, every "
             "256th input)")

SINH_FAITHFUL = DoublePolynomial(
    name="sinh.reduced.faithful", function=_O1, weight="1/x", interval=("0", "0.1202"),
    coefficients=("0.000199049939545664568143348926726", "0.00833328890827699990351555222024",
                  "0.166666667546877448618275559528"),
    provenance="our Remez fitter: python -m routines remez -d 2 -r \"0:0.1202\" \"" + _O1 + "\" \"1/x\" --json "
               "--dps 60; levelled error 5.26e-12 (2^-37.5); binary64 coefficients: 5.26e-12 (2^-37.5)",
    measured="float64 value against mpmath: relative error 2^-33.3 (sinh), 2^-33.9 (cosh), 2^-34.5 (tanh); "
             "compiled: max 0.5009 / 0.5008 / 0.5006 ULP (python -m routines ladder sinh cosh tanh, every "
             "256th input)")

POLYNOMIALS = (COSH_CORRECT, SINH_CORRECT, COSH_FAITHFUL, SINH_FAITHFUL)


def _types(width):
    return vector_type("Float", width), vector_type("Double", width), vector_type("Int", width)


def _reduce(x, precision, clamp, scaled=True):
    """((sh, ch, r, z, E1(z), O1(z)), fused) for a = min(|x|, clamp) = k ln2 + r in float64 lanes, z = r^2,
    (sh, ch) = (sinh(k ln2), cosh(k ln2)) / 4, or with ``scaled=False`` (tanh: a ratio)
    (1 - 4^-k, 1 + 4^-k), the same up to the factor 2^(k+1); see the module docstring."""
    F, D, I = _types(x.width)
    correct_tier = precision is Precision.CORRECT
    fused = correct_tier and dd.fused()
    a = Min(F(clamp), Abs(x))                          # inf -> clamp; NaN stays NaN (replaced at the end)
    k = Round(a * LOG2E_F)                             # 0 <= k <= 130
    ki = ToInt(k, saturate=False)
    if scaled:
        p = D(As(F, (ki + (127 - 3)) << 23))           # 2^(k-3)
        q = D(As(F, Max(124 - ki, I(0)) << 23))        # 2^(-k-3); +0 for k > 123 (below 2^-56 of p)
        sh, ch = p - q, p + q                          # exact for k <= 26, else within 2^-53
    else:
        w = D(As(F, (127 - ki - ki) << 23))            # 4^-k (k <= 14 here)
        sh, ch = 1.0 - w, 1.0 + w                      # exact
    ad, kd = D(a), D(k)
    if not correct_tier:
        r = ad - kd * LN2_HI                           # exact; LN2_LO left out: |k LN2_LO| < 2^-41.9
    elif fused:
        r = Fma(kd, -LN2_LO, Fma(kd, -LN2_HI, ad))
    else:
        r = (ad - kd * LN2_HI) - kd * LN2_LO
    z = r * r
    e1 = (COSH_CORRECT if correct_tier else COSH_FAITHFUL).evaluate(z, fused)
    o1 = (SINH_CORRECT if correct_tier else SINH_FAITHFUL).evaluate(z, fused)
    return (sh, ch, r, z, e1, o1), fused


def _combine(big, small, r, z, e1, o1, fused):
    """(big + small r) + z (big E1 + small r O1) = big cosh(r) + small sinh(r): sinh(k ln2 + r) with
    (big, small) = (sh, ch), cosh(k ln2 + r) with (ch, sh)."""
    sr = small * r
    if fused:
        return Fma(z, Fma(big, e1, sr * o1), Fma(small, r, big))
    return (big + sr) + z * (big * e1 + sr * o1)


def _specials(x, out):
    return nan_rule(Select(IsNan(x), x + x, out), x)


def sinh_value(x, precision):
    """sinh(min(|x|, 89.5)) in float64 lanes (what ``sinh`` rounds)."""
    (sh, ch, *rest), fused = _reduce(x, precision, SINH_CLAMP)
    return _combine(sh, ch, *rest, fused) * 4.0


def cosh_value(x, precision):
    """cosh(min(|x|, 89.5)) in float64 lanes (what ``cosh`` rounds)."""
    (sh, ch, *rest), fused = _reduce(x, precision, SINH_CLAMP)
    return _combine(ch, sh, *rest, fused) * 4.0


def tanh_value(x, precision):
    """tanh(min(|x|, 10)) in float64 lanes (what ``tanh`` rounds)."""
    (sh, ch, *rest), fused = _reduce(x, precision, TANH_CLAMP, scaled=False)
    return _combine(sh, ch, *rest, fused) / _combine(ch, sh, *rest, fused)


def sinh(x, precision):
    """sinh(x) as float32, faithful or correctly rounded (see the module docstring)."""
    y = sinh_value(x, precision)
    return _specials(x, CopySign(correct.finish(Abs(x), y, precision, "sinh"), x))


def cosh(x, precision):
    """cosh(x) as float32, faithful or correctly rounded (see the module docstring)."""
    return _specials(x, correct.finish(x, cosh_value(x, precision), precision, "cosh"))


def tanh(x, precision):
    """tanh(x) as float32, faithful or correctly rounded (see the module docstring)."""
    y = tanh_value(x, precision)
    return _specials(x, CopySign(correct.finish(Abs(x), y, precision, "tanh"), x))
