"""Every polynomial the routines evaluate, with its provenance.

Each ``Polynomial`` records what it approximates, on which interval, with
which weight (LolRemez's convention: the weight is the *tolerance*, larger
means less accurate there), its coefficients as float32 decimals (highest
degree first, exactly as they appear in the emitted IR), where they came from,
and the error measured on the compiled routine that uses it.

The coefficients below are those of the reference write-up
(``shared/refs/000_84390b1a4f8484b8.txt``, produced there by LolRemez); our own
fitter reproduces each to within one float32 ulp
(``python -m routines remez ...``, see docs/remez.md).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from reactor import MulAdd


@dataclasses.dataclass(frozen=True)
class Polynomial:
    """A float32 polynomial and its provenance (coefficients highest degree first)."""

    name: str
    function: str
    weight: str
    interval: tuple[str, str]
    coefficients: tuple[str, ...]
    provenance: str
    measured: str = ""

    @property
    def degree(self) -> int:
        return len(self.coefficients) - 1

    @property
    def values(self) -> tuple[float, ...]:
        """The coefficients as the float32 values the code uses."""
        return tuple(float(np.float32(c)) for c in self.coefficients)

    def remez_command(self) -> str:
        lo, hi = self.interval
        w = f' "{self.weight}"' if self.weight else ""
        return f'python -m routines remez -d {self.degree} -r "{lo}:{hi}" "{self.function}"{w}'

    def __call__(self, x):
        """Emit Horner's scheme in ``x`` with ``MulAdd`` (fused iff FMA is on)."""
        c = self.values
        acc = MulAdd(x, c[0], c[1])
        for coeff in c[2:]:
            acc = MulAdd(acc, x, coeff)
        return acc


EXP2_FULL = Polynomial(
    name="exp2.full",
    function="(2^x-x-1)/x", weight="(0.25*erf(1000*x)+0.75)*(2+2*abs(x))/x", interval=("-0.5", "0.5"),
    coefficients=("0.00015319258", "0.001339585", "0.009618554", "0.055503443", "0.24022645", "-0.30685282"),
    provenance="the variant search's best full exp2 (docs/search.md, exp2.full.rscalef.d5.erf2.retuned): "
               "our Remez fitter (python -m routines remez -d 5 -r \"-0.5:0.5\" \"(2^x-x-1)/x\" "
               "\"(0.25*erf(1000*x)+0.75)*(2+2*abs(x))/x\"), then one round of routines.remez.retune "
               "against the compiled kernel's exhaustive margin (0.2519 -> 0.2349); evaluated as "
               "2^f = (P(f) f + f) + 1 on f = x - round(x)",
    measured="exhaustive, all 2^32 inputs, compiled kernel (AVX2 portable path, the same bits as VSCALEFPS's): "
             "max margin 0.2348 (FMA on) / 0.2329 (off), max ULP-32 0.920 (FMA on, x = -0.459) / 0.842 (off), "
             "0 non-conforming, 0 special mismatches, 0 flushes (subnormal results rounded); `python -m routines "
             "accuracy exp2 --precision full --fma on --exhaustive`",
)

EXP2_FULL_REFERENCE = Polynomial(
    name="exp2.full.reference",
    function="(2^x-x-1)/x", weight="1/x", interval=("0", "1"),
    coefficients=("1.8852974e-3", "8.9733787e-3", "5.5835927e-2", "2.4015281e-1", "-3.0684753e-1"),
    provenance="reference write-up, section 'Gaining Significance' (LolRemez --float -d 4 -r 0:1 "
               "\"(2^x-x-1)/x\" \"1/x\"); our fitter's 8-digit p(x) line matches these digits exactly "
               "(rounded straight to float32, one coefficient is 1 ulp away: LolRemez's double rounding). "
               "Full exp2's polynomial until the accuracy ladder adopted the search's rscalef form; the "
               "method zoo and the search's production baseline still build it",
    measured='exhaustive, all 2^32 inputs, compiled kernel: max margin 0.632 (FMA on) / 0.662 (off), max ULP-32 33.09 (at x = 96.76, where the tolerance is 196.5 ULP), 0 non-conforming'
)

EXP2_RELAXED = Polynomial(
    name="exp2.relaxed",
    function="(2^x-x-1)/x", weight="1/x", interval=("0", "1"),
    coefficients=("7.8145574e-2", "2.2617357e-1", "-3.0444314e-1"),
    provenance="reference write-up, section 'Relaxing with a Halfling': the degree-2 fit of "
               "(2^x-1)/x with weight 1/x, constant term minus 1 (exact in decimal)",
    measured='exhaustive, all 2^32 inputs: max margin 0.131 (FMA on) / 0.127 (off), max ULP-16 0.139 / 0.131, 0 non-conforming; `python -m routines accuracy exp2 --precision relaxed --fma on --exhaustive`'
)

LOG2_FULL = Polynomial(
    name="log2.full",
    function="(log2(x+1.5)-x-0.5)/((x+0.5)*(0.5-x))", weight="1/((x+0.5)*(0.5-x))", interval=("-0.5", "0.5"),
    coefficients=("0.009136402", "-0.014875774", "0.022838062", "-0.041144915", "0.07701328", "-0.15281655",
                  "0.33984995"),
    provenance="the variant search's best full log2 (docs/search.md, log2.full.m1mc.d6.abs.retuned): our "
               "Remez fitter (python -m routines remez -d 6 -r \"-0.5:0.5\" "
               "\"(log2(x+1.5)-x-0.5)/((x+0.5)*(0.5-x))\" \"1/((x+0.5)*(0.5-x))\"), then one round of "
               "routines.remez.retune against the compiled kernel's exhaustive margin (0.3607 -> 0.3560); "
               "evaluated centred, u = m - 1/2: (R(u) (1/4 - u^2) + u) + (e + 1/2)",
    measured="exhaustive, all 2^32 inputs, compiled kernel: max margin 0.3560 (FMA on) / 0.3652 (off), "
             "0 non-conforming, 0 special mismatches (max ULP-32 480710 at x = 1.00000024: Vulkan's absolute "
             "tolerance near log2's zero); `python -m routines accuracy log2 --precision full --fma on --exhaustive`",
)

LOG2_FULL_REFERENCE = Polynomial(
    name="log2.full.reference",
    function="(log2(x+1)-x)/x", weight="1/x", interval=("0", "1"),
    coefficients=("-9.3091638e-3", "5.2059003e-2", "-1.3752135e-1", "2.4186478e-1",
                  "-3.4730109e-1", "4.786837e-1", "-7.2116581e-1", "4.4268988e-1"),
    provenance="reference write-up, section 'Second Try' (LolRemez --float -d 7 -r 0:1 "
               "\"(log2(x+1)-x)/x\" \"1/x\"); our fitter's 8-digit p(x) line matches these digits exactly "
               "(rounded straight to float32, three coefficients are 1 ulp away: LolRemez's double rounding). "
               "Full log2's polynomial until the accuracy ladder adopted the search's m1mc form",
    measured='exhaustive, all 2^32 inputs: max margin 0.502 (FMA on) / 0.565 (off), 0 non-conforming, 0 special mismatches'
)

LOG2_RELAXED = Polynomial(
    name="log2.relaxed",
    function="(log2(x+1)-x)/(x*(1-x))", weight="1/(x*(1-x))", interval=("0", "1"),
    coefficients=("-0.15922019", "0.42286536"),
    provenance="our Remez fitter (python -m routines remez -d 1 -r 0:1 \"(log2(x+1)-x)/(x*(1-x))\" "
               "\"1/(x*(1-x))\"). Evaluated as m*(1-m)*P(m), the correction vanishes at both ends of "
               "the mantissa interval, so relaxed log2 is exact at powers of two and has the right sign "
               "just below them (the reference's degree-2 fit is 7.7e-4 off at m = 1, which made "
               "log2(0.99999994) positive and pow(0.99999994, -inf) = +0). Same 3 FMAs; weighted "
               "error 8.8e-4 (absolute, the product) against the reference's 7.7e-4",
    measured='exhaustive, all 2^32 inputs: max margin 0.300 (FMA on and off), max ULP-16 42.6 near x = 1 (absolute tolerance there), 0 non-conforming; `python -m routines accuracy log2 --precision relaxed --fma on --exhaustive`'
)

LOG2_RELAXED_REFERENCE = Polynomial(
    name="log2.relaxed.reference",
    function="(log2(x+1)-x)/x", weight="1/x", interval=("0", "1"),
    # The reference's un-normalized fit on [0, 2^23] (2.8017103e-22, -8.373131e-15,
    # 5.0615534e-8) with x scaled by 2^-23: coefficient k times 2^(23(k+1)), exact.
    coefficients=("0.16538379", "-0.5892067", "0.42459387"),
    provenance="reference write-up, section 'The Vanishingly Small and Unfathomably Large', "
               "rescaled exactly by powers of two to the normalized mantissa in [0, 1)",
)


# -- trigonometric and hyperbolic (routines/trig.py) --------------------------------
#
# Fitted by the remez command (its expressions have sin cos tan asin acos atan sinh cosh
# tanh), at its default 50 digits, and rounded to float32: the command in each provenance
# below prints these coefficients, highest degree first (the C function's literals, or
# "coefficients" with --json). The odd functions f(r) = r + r^3 p(r^2) are fitted in
# z = r^2: f(x) = (f(sqrt(x)) - sqrt(x))/x^1.5 with weight f(sqrt(x))/x^1.5, the relative
# error of f(r); cos(r) = 1 + r^2 q(r^2): (cos(sqrt(x))-1)/x with weight 1/x, its absolute
# error. ``_trig_fits()`` below gives the same fits as mpmath callables for the fitter's
# Python API; tests/routines/test_trig.py reruns both forms and checks these digits.

_ODD = "relative error of {f}(r) = r + r^3 p(r^2): fitted in z = r^2"


def odd_poly(name, f, interval, coefficients, measured, note=""):
    """The polynomial p of an odd function, f(r) = r + r^3 p(r^2), fitted in z = r^2 for relative
    error, with its provenance."""
    lo, hi = interval
    return Polynomial(
        name=name, function=f"({f}(sqrt(x))-sqrt(x))/x^1.5", weight=f"{f}(sqrt(x))/x^1.5",
        interval=(lo, hi), coefficients=coefficients,
        provenance=(f'our Remez fitter: python -m routines remez -d {len(coefficients) - 1} -r "{lo}:{hi}" '
                    f'"({f}(sqrt(x))-sqrt(x))/x^1.5" "{f}(sqrt(x))/x^1.5"; {_ODD.format(f=f)}'
                    + (f"; {note}" if note else "")),
        measured=measured)


SIN_FULL = odd_poly(
    "sin.full", "sin", ("0", "0.64"), ("-0.00019503069", "0.008332071", "-0.16666654"),
    measured="exhaustive, all 2^32 inputs, compiled kernel, FMA on: sin max 1.38 ULP-32, 6.5e-8 absolute inside [-pi, pi] (max margin 1.3e-4 of 2^-11), 1.55 ULP-32, 7.4e-8 absolute outside (no bound); cos 1.49 / 1.55 ULP-32; 0 non-conforming, 0 special mismatches; `python -m routines accuracy sin --precision full --fma on --exhaustive`",
    note="|r| <= 0.8 covers the float32 reduction's |r| < 0.797; weighted error 4.4e-9 (2^-27.8)")

SIN_RELAXED = odd_poly(
    "sin.relaxed", "sin", ("0", "0.64"), ("0.008156913", "-0.16663139"),
    measured="exhaustive, all 2^32 inputs, compiled kernel, FMA on: sin and cos max 0.0282 ULP-16, 1.38e-5 absolute inside and outside [-pi, pi] (max margin 1.8e-3 of 2^-7), 0 non-conforming; `python -m routines accuracy sin --precision relaxed --fma on --exhaustive`", note="weighted error 2.1e-6 (2^-18.9)")

COS_FULL = Polynomial(
    name="cos.full", function="(cos(sqrt(x))-1)/x", weight="1/x", interval=("0", "0.64"),
    coefficients=("2.4375144e-05", "-0.0013886602", "0.04166662", "-0.5"),
    provenance='our Remez fitter: python -m routines remez -d 3 -r "0:0.64" "(cos(sqrt(x))-1)/x" "1/x"; '
               "absolute error of cos(r) = 1 + r^2 q(r^2) for |r| <= 0.8, fitted in z = r^2 "
               "(cos(0) = 1 exactly); weighted error 6.4e-11 (2^-33.9)",
    measured="exhaustive, all 2^32 inputs, compiled kernel, FMA on: cos max 1.49 ULP-32, 7.4e-8 absolute inside [-pi, pi] (max margin 1.5e-4 of 2^-11), 1.55 ULP-32 outside; tan (with sin.full) 3.07 / 3.53 ULP-32 (margin 1.4e-4); `python -m routines accuracy cos --precision full --fma on --exhaustive`")

COS_RELAXED = Polynomial(
    name="cos.relaxed", function="(cos(sqrt(x))-1)/x", weight="1/x", interval=("0", "0.64"),
    coefficients=("0.04044532", "-0.49975935"),
    provenance='our Remez fitter: python -m routines remez -d 1 -r "0:0.64" "(cos(sqrt(x))-1)/x" "1/x"; '
               "cos of degree 4; weighted error 1.4e-5 (2^-16.2)",
    measured="exhaustive, all 2^32 inputs, compiled kernel, FMA on: cos max 0.0282 ULP-16, 1.38e-5 absolute (max margin 1.8e-3 of 2^-7); tan 0.0269 ULP-16 (margin 6.6e-4); `python -m routines accuracy cos --precision relaxed --fma on --exhaustive`")

ATAN_FULL = odd_poly(
    "atan.full", "atan", ("0", "1"),
    ("0.002920693", "-0.01636793", "0.043211866", "-0.07552215", "0.106660046", "-0.14211056",
     "0.19993773", "-0.33333153"),
    measured="exhaustive, all 2^32 inputs, compiled kernel, FMA on: atan max 1.57 ULP-32 (max margin 3.8e-4 of 4096 ULP); atan2, stratified 1.09e9 pairs: 1.74 ULP-32 (4.3e-4); 0 non-conforming, 0 special mismatches; `python -m routines accuracy atan --precision full --fma on --exhaustive`", note="t = min(|x|,1)/max(|x|,1) in [0, 1]; weighted error "
                                               "1.7e-8 (2^-25.8)")

ATAN_RELAXED = odd_poly(
    "atan.relaxed", "atan", ("0", "1"), ("-0.046496473", "0.15931422", "-0.32762277"),
    measured="exhaustive, all 2^32 inputs, compiled kernel, FMA on: atan max 0.469 ULP-16 (max margin 0.094 of 5 ULP-16); atan2, stratified 1.09e9 pairs: 0.469 ULP-16 (0.094); `python -m routines accuracy atan --precision relaxed --fma on --exhaustive`", note="weighted error 2.6e-4 (2^-11.9): 0.25-0.5 ULP-16, "
                                               "against 5 ULP-16 allowed")

ASIN_FULL = odd_poly(
    "asin.full", "asin", ("0", "0.25"),
    ("0.042166308", "0.024179514", "0.045470376", "0.074952975", "0.16666752"),
    measured="exhaustive, all 2^32 inputs, compiled kernel, FMA on: asin max 2.36 ULP-32 (max margin 5.8e-4 of its inherited ~4100 ULP), acos 1.13 ULP-32 (2.7e-4); 0 non-conforming, 0 special mismatches; `python -m routines accuracy asin --precision full --fma on --exhaustive`", note="v = |x| <= 1/2 or sqrt((1-|x|)/2); weighted error "
                                               "4.8e-9 (2^-27.6)")

ASIN_RELAXED = odd_poly(
    "asin.relaxed", "asin", ("0", "0.25"), ("0.09429868", "0.16505776"),
    measured="exhaustive, all 2^32 inputs, compiled kernel, FMA on: asin max 0.137 ULP-16 (max margin 0.016), acos 0.160 ULP-16 (0.016); `python -m routines accuracy asin --precision relaxed --fma on --exhaustive`", note="weighted error 3.8e-5 (2^-14.7)")

SINH_FULL = odd_poly(
    "sinh.full", "sinh", ("0", "1"), ("0.00020372194", "0.008330284", "0.16666716"),
    measured="exhaustive, all 2^32 inputs, compiled kernel, FMA on (AVX2, Zen 3): sinh max 1.62 ULP-32, max margin 0.208 (x = 1.0074), 0 non-conforming; FMA off sampled: margin 0.21; `python -m routines accuracy sinh --precision full --fma on --exhaustive`", note="|x| < 1; weighted error 2.4e-8 (2^-25.3)")

SINH_RELAXED = odd_poly(
    "sinh.relaxed", "sinh", ("0", "1"), ("0.008610608", "0.16658214"),
    measured="exhaustive, all 2^32 inputs, FMA on (AVX2): sinh max 0.0143 ULP-16, max margin 0.0025, 0 non-conforming; `python -m routines accuracy sinh --precision relaxed --fma on --exhaustive`", note="weighted error 7.2e-6 (2^-17.1)")

TANH_FULL = odd_poly(
    "tanh.full", "tanh", ("0", "0.3025"), ("0.01643758", "-0.052671812", "0.13320725", "-0.33332947"),
    measured="exhaustive, all 2^32 inputs, FMA on (AVX2): tanh max 1.56 ULP-32, max margin 0.138 (x = 0.555), 0 non-conforming; FMA off sampled: margin 0.11; `python -m routines accuracy tanh --precision full --fma on --exhaustive`", note="|x| < 0.55; weighted error 3.7e-8 (2^-24.7)")

TANH_RELAXED = odd_poly(
    "tanh.relaxed", "tanh", ("0", "0.3025"), ("0.113320686", "-0.33153343"),
    measured="exhaustive, all 2^32 inputs, FMA on (AVX2): tanh max 0.098 ULP-16, max margin 0.0084, 0 non-conforming; `python -m routines accuracy tanh --precision relaxed --fma on --exhaustive`", note="weighted error 4.8e-5 (2^-14.3)")

EXP_FULL = Polynomial(
    name="exp.full", function="(exp(x)-1-x)/x^2", weight="exp(x)/x^2", interval=("-0.35", "0.35"),
    coefficients=("0.0013813161", "0.00836941", "0.041668456", "0.16666515", "0.49999994"),
    provenance='our Remez fitter (python -m routines remez -d 4 -r "-0.35:0.35" "(exp(x)-1-x)/x^2" '
               '"exp(x)/x^2"): e^r = 1 + r + r^2 p(r) after r = a - k ln2 (|r| <= ln2/2 = 0.3466), '
               'the e^a/2 of sinh, cosh and tanh; weighted (relative) error 3.3e-9 (2^-28.2)',
    measured="exhaustive, all 2^32 inputs, FMA on (AVX2): cosh max 1.35 ULP-32, max margin 0.250 (x = 0.361, where the inherited bound is ~3.2-4 ULP), 0 non-conforming; FMA off sampled: 1.56 ULP-32; `python -m routines accuracy cosh --precision full --fma on --exhaustive`")

EXP_RELAXED = Polynomial(
    name="exp.relaxed", function="(exp(x)-1-x)/x^2", weight="exp(x)/x^2", interval=("-0.35", "0.35"),
    coefficients=("0.041270223", "0.16755237", "0.50005317"),
    provenance='our Remez fitter (python -m routines remez -d 2 -r "-0.35:0.35" "(exp(x)-1-x)/x^2" '
               '"exp(x)/x^2"): weighted (relative) error 5.6e-6 (2^-17.5)',
    measured="exhaustive, all 2^32 inputs, FMA on, AVX2 (exact 1/e^x; AVX-512's RCP14 estimate, sampled there, gave 0.0216 ULP-16, margin 0.021): cosh max 0.0090 ULP-16, max margin 0.0020, 0 non-conforming; `python -m routines accuracy cosh --precision relaxed --fma on --exhaustive`")

def _trig_fits():
    """name -> (f, weight, a, b, degree): the fits above as mpmath callables of z, for the
    fitter's Python API (the same functions as the commands' expressions)."""
    from reactor import require
    mp = require("mpmath", "lab", "the fits' mpmath callables")
    S = mp.sqrt

    def odd(f):
        return (lambda z: (f(S(z)) - S(z)) / (z * S(z))), (lambda z: f(S(z)) / (z * S(z)))

    def cos_f(z):
        return (mp.cos(S(z)) - 1) / z

    def cos_w(z):
        return 1 / z

    fits = {"cos.full": (cos_f, cos_w, "0", "0.64", 3), "cos.relaxed": (cos_f, cos_w, "0", "0.64", 1)}
    for poly in (SIN_FULL, SIN_RELAXED, ATAN_FULL, ATAN_RELAXED, ASIN_FULL, ASIN_RELAXED,
                 SINH_FULL, SINH_RELAXED, TANH_FULL, TANH_RELAXED):
        f = getattr(mp, poly.name.split(".")[0])
        fits[poly.name] = (*odd(f), *poly.interval, poly.degree)
    return fits


TRIG = (SIN_FULL, SIN_RELAXED, COS_FULL, COS_RELAXED, ATAN_FULL, ATAN_RELAXED, ASIN_FULL, ASIN_RELAXED,
        SINH_FULL, SINH_RELAXED, TANH_FULL, TANH_RELAXED, EXP_FULL, EXP_RELAXED)

ALL = (EXP2_FULL, EXP2_FULL_REFERENCE, EXP2_RELAXED, LOG2_FULL, LOG2_FULL_REFERENCE, LOG2_RELAXED,
       LOG2_RELAXED_REFERENCE) + TRIG


# -- double lanes: the faithful and correct tiers (routines/accurate.py) ---------------------
#
# Evaluated in float64 lanes, so the coefficients are kept as the fitter's exact digits (30
# significant, ``coefficients_exact`` of ``--json``) and rounded once to binary64. The error
# below is the fitter's levelled relative error; tests/routines/test_accurate.py reruns each
# fit and measures the binary64-rounded polynomial against mpmath.


@dataclasses.dataclass(frozen=True)
class DoublePolynomial(Polynomial):
    """A binary64 polynomial (coefficients highest degree first, rounded once to binary64)."""

    @property
    def values(self) -> tuple[float, ...]:
        return tuple(float(c) for c in self.coefficients)

    def remez_command(self) -> str:
        return super().remez_command() + " --json --dps 60"

    def evaluate(self, x, fused: bool):
        """Horner's scheme in ``x``, fused (``Fma``: the caller checks the build allows it) or as
        rounded multiplies and adds whatever the FMA setting: the same bits on every target."""
        from reactor import Fma
        c = self.values
        acc = Fma(x, c[0], c[1]) if fused else x * c[0] + c[1]
        for coeff in c[2:]:
            acc = Fma(acc, x, coeff) if fused else acc * x + coeff
        return acc


_LOG2_Q = "log((1+sqrt(x))/(1-sqrt(x)))/(sqrt(x)*log(2))"

EXP2_FAITHFUL = DoublePolynomial(
    name="exp2.faithful", function="2^x", weight="2^x", interval=("-0.5", "0.5"),
    coefficients=("0.00015345812002903347502792957286", "0.00133999312193408904131367435338",
                  "0.00961848895711507093541686419872", "0.0555032877696472560634700262452",
                  "0.240226468906340877635191018759", "0.693147205737268080112932362886",
                  "1.00000000055416646332646419172"),
    provenance="our Remez fitter, relative error of 2^r on the reduced interval: python -m routines "
               "remez -d 6 -r \"-0.5:0.5\" \"2^x\" \"2^x\" --json --dps 60; levelled error 1.86e-9 (2^-29.0)",
    measured="see docs/accuracy-ladder.md (python -m routines ladder --exhaustive)")

EXP2_CORRECT = DoublePolynomial(
    name="exp2.correct", function="2^x", weight="2^x", interval=("-0.5", "0.5"),
    coefficients=("0.00000131758581136080196979164153715", "0.0000153097374222449818625592024804",
                  "0.00015403851748734642383795842528", "0.00133334520622475414686487640647",
                  "0.00961812854286237687576649053401", "0.0555041093934171194207333456921",
                  "0.240226506988803699009367375899", "0.693147180546514159878378374612",
                  "0.999999999999762345385640465291"),
    provenance="our Remez fitter: python -m routines remez -d 8 -r \"-0.5:0.5\" \"2^x\" \"2^x\" --json "
               "--dps 60; levelled error 7.74e-13 (2^-40.2), under the correct tier's rounding-test window "
               "2^-38",
    measured="see docs/accuracy-ladder.md (python -m routines ladder --exhaustive)")

LOG2_FAITHFUL = DoublePolynomial(
    name="log2.faithful", function=_LOG2_Q, weight=_LOG2_Q, interval=("1e-60", "0.04"),
    coefficients=("0.439083157030882817526331457852", "0.576395234614523674217607315218",
                  "0.961802200896678131773729232112", "2.88539007485738646840380892875"),
    provenance="our Remez fitter, relative error of Q(z) = 2 atanh(s)/(s ln 2), z = s^2, s = u/(2+u) for "
               "u = m - 1 with m in [0.75, 1.5): z in [0, 0.04]: python -m routines remez -d 3 -r "
               f"\"1e-60:0.04\" \"{_LOG2_Q}\" \"{_LOG2_Q}\" --json --dps 60; levelled error 2.40e-9 (2^-28.6)",
    measured="see docs/accuracy-ladder.md (python -m routines ladder --exhaustive)")

LOG2_CORRECT = DoublePolynomial(
    name="log2.correct", function=_LOG2_Q, weight=_LOG2_Q, interval=("1e-60", "0.04"),
    coefficients=("0.290798114338830994172722210293", "0.319288039555405934096171689537",
                  "0.412226079384548006784812777897", "0.577077756779160174766818760552",
                  "0.96179669482029602540569867337", "2.88539008177742808386685827796"),
    provenance="our Remez fitter, as log2.faithful with degree 5: python -m routines remez -d 5 -r "
               f"\"1e-60:0.04\" \"{_LOG2_Q}\" \"{_LOG2_Q}\" --json --dps 60; levelled error 1.73e-13 (2^-42.4), "
               "under the correct tier's rounding-test window 2^-38",
    measured="see docs/accuracy-ladder.md (python -m routines ladder --exhaustive)")

LOG2_POW = DoublePolynomial(
    name="log2.pow", function=_LOG2_Q, weight=_LOG2_Q, interval=("1e-60", "0.04"),
    coefficients=("0.348373226007343715693487462389", "0.411207856197582509539616187127",
                  "0.577092307422044812082476656595", "0.961796622034959891905236139382",
                  "2.88539008183569478004661564476"),
    provenance="our Remez fitter, as log2.faithful with degree 4, for the faithful pow (y log2 x needs log2 "
               "to ~2^-34 relative for |y log2 x| up to 150): python -m routines remez -d 4 -r "
               f"\"1e-60:0.04\" \"{_LOG2_Q}\" \"{_LOG2_Q}\" --json --dps 60; levelled error 2.00e-11 (2^-35.5)",
    measured="see docs/accuracy-ladder.md (python -m routines ladder pow --exhaustive)")

EXP2_POW_CORRECT = DoublePolynomial(
    name="exp2.pow.correct", function="2^x", weight="2^x", interval=("-0.5", "0.5"),
    coefficients=("0.000000101503367053096482115886137542", "0.00000132594056093451350036707402656",
                  "0.0000152529848386534274803564943329", "0.00015403434948071790222902304849",
                  "0.00133335576176044431687119896539", "0.00961812919206724613191174758044",
                  "0.0555041086686856115549025181211", "0.240226506956496528745328578278",
                  "0.693147180559870970863536363883", "1.00000000000001276211230111769"),
    provenance="our Remez fitter: python -m routines remez -d 9 -r \"-0.5:0.5\" \"2^x\" \"2^x\" --json "
               "--dps 60; levelled error 1.34e-14 (2^-46.1): the correct pow's 2^r, whose exponent t = y log2 x "
               "is within 2^-43.2 (absolute) of its exact value, under the rounding test's window 2^-40",
    measured="see docs/accuracy-ladder.md (python -m routines ladder pow --exhaustive)")

LOG2_POW_CORRECT = DoublePolynomial(
    name="log2.pow.correct", function=_LOG2_Q, weight=_LOG2_Q, interval=("1e-60", "0.04"),
    coefficients=("0.222010465880726045197641499663", "0.219969595110197499661163292002",
                  "0.262376300510355862766371018989", "0.320597609589738053728202863909",
                  "0.412198596308330419000885643029", "0.577078016289305451593149512613",
                  "0.961796693926102296145885439838", "2.88539008177792677501195497675"),
    provenance="our Remez fitter, as log2.faithful with degree 7, for the correct pow (y log2 x to 2^-43 "
               "absolute for |y log2 x| up to 150 needs log2 to ~2^-51 relative): python -m routines remez -d 7 "
               f"-r \"1e-60:0.04\" \"{_LOG2_Q}\" \"{_LOG2_Q}\" --json --dps 60; levelled error 1.38e-17 (2^-56.0)",
    measured="see docs/accuracy-ladder.md (python -m routines ladder pow --exhaustive)")

DOUBLE = (EXP2_FAITHFUL, EXP2_CORRECT, LOG2_FAITHFUL, LOG2_CORRECT, LOG2_POW, EXP2_POW_CORRECT, LOG2_POW_CORRECT)

# The faithful tier's float32 path (FMA on): e^r = 1 + r + r^2 Q(r) on |r| <= ln2/2, and
# 2^r = 1 + r ln2 + r^2 Q2(r) on |r| <= 1/2 with Q2(r) = ln2^2 Q(r ln2), the same fit rescaled
# (coefficient of r^k times ln2^(k+2), from the exact digits, rounded once to float32).
_EXP_Q = "(exp(x)-1-x)/x^2"

EXP_FAITHFUL_F = Polynomial(
    name="exp.faithful.float", function=_EXP_Q, weight="exp(x)/x^2",
    interval=("-0.34657359027997264", "0.34657359027997264"),
    coefficients=("0.0013814613", "0.00836871", "0.04166839", "0.16666521", "0.49999994"),
    provenance="our Remez fitter: python -m routines remez -d 4 -r "
               "\"-0.34657359027997264:0.34657359027997264\" \"(exp(x)-1-x)/x^2\" \"exp(x)/x^2\" --json "
               "--dps 60; levelled error 3.06e-9 (relative to e^r)",
    measured="see docs/accuracy-ladder.md (python -m routines ladder --exhaustive)")

EXP2_FAITHFUL_F = Polynomial(
    name="exp2.faithful.float", function="(2^x-1-x*log(2))/x^2", weight="2^x/x^2", interval=("-0.5", "0.5"),
    coefficients=("0.00015321154", "0.0013390161", "0.009618526", "0.05550362", "0.24022648"),
    provenance="exp.faithful.float's exact coefficients q_k (coefficients_exact) rescaled to "
               "q_k ln2^(k+2) and rounded once to float32",
    measured="see docs/accuracy-ladder.md (python -m routines ladder --exhaustive)")


_LOG2_Q = "(log(1+x)/log(2)-x/log(2))/x^2"
_LN_Q = "(log(1+x)-x)/x^2"

LOG2_FAITHFUL_F = Polynomial(
    name="log2.faithful.float", function=_LOG2_Q, weight="abs(log(1+x)/log(2))/x^2",
    interval=("-0.29289321881345254", "0.41421356237309515"),
    coefficients=("-0.10995901", "0.18617162", "-0.19105592", "0.20460048", "-0.2396184", "0.28856748",
                  "-0.36069658", "0.48089823", "-0.72134733"),
    provenance="our Remez fitter, relative error of log2(1+u) = u/ln2 + u^2 Q(u), u = m - 1 with m in "
               "[sqrt(1/2), sqrt(2)) (so that e + log2(m) never cancels by more than half): python -m routines "
               f"remez -d 8 -r \"-0.29289321881345254:0.41421356237309515\" \"{_LOG2_Q}\" "
               "\"abs(log(1+x)/log(2))/x^2\" --json --dps 60; levelled error 4.09e-9 (2^-27.9)",
    measured="see docs/accuracy-ladder.md (python -m routines ladder --exhaustive)")

LOG_FAITHFUL_F = Polynomial(
    name="log.faithful.float", function=_LN_Q, weight="abs(log(1+x))/x^2",
    interval=("-0.29289321881345254", "0.41421356237309515"),
    coefficients=("-0.07621778", "0.12904432", "-0.13242988", "0.14181826", "-0.16609083", "0.20001973",
                  "-0.25001583", "0.33333325", "-0.49999988"),
    provenance="our Remez fitter, relative error of log(1+u) = u + u^2 Q(u), m in [sqrt(1/2), sqrt(2)): "
               "python -m routines remez -d 8 -r \"-0.29289321881345254:0.41421356237309515\" "
               f"\"{_LN_Q}\" \"abs(log(1+x))/x^2\" --json --dps 60; levelled error 4.09e-9",
    measured="see docs/accuracy-ladder.md (python -m routines ladder --exhaustive)")
