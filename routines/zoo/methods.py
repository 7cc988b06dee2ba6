"""The method zoo: every exp2/log2 method of the reference write-up as a DSL builder.

The reference (``shared/refs/000_84390b1a4f8484b8.txt``, N. Capens,
"Optimizing Exp/Log for SwiftShader") walks through a sequence of methods and
states, for most of them, the maximum ULP-32 error, the ULP-16 error or the
'margin' (error / Vulkan tolerance, conforming iff < 1). Each method is a
:class:`Variant` here: a builder ``body(x: Float) -> Float`` written with
reactor intrinsics exactly as the reference's C code computes it (same
reduction, same polynomial, same Horner order; ``MulAdd`` is a separate
multiply and add when the variant is built with ``fma=False`` and one fused
operation with ``fma=True``), the polynomial(s) with their provenance, the
figures the reference states and the input domain over which we read them.

The reference's own C code is followed literally, including its
non-IEEE parts: the clamps ``min(x, 128)``, ``max(x, -126.999992)``, the
truncating ``(int)`` conversions, no NaN handling. So the measurements are
over finite inputs; special values are none of the zoo's business (the
library's routines handle them, see docs/specials.md).

``routines.zoo.table`` measures every variant on its compiled kernel with the
accuracy lab and prints the reference's figures beside ours.
"""
from __future__ import annotations

import dataclasses
import decimal
import functools

import numpy as np

from reactor import As, Float, Floor, Max, Min, MulAdd, Round, Select, ToInt, kernel, vector_type

from ..polynomials import Polynomial

REFERENCE = "shared/refs/000_84390b1a4f8484b8.txt"
MANTISSA_SCALE = float(2 ** 23)
BIAS_BITS = 127 << 23
LOWER_CLAMP = float(np.uint32(0xC2FDFFFF).view(np.float32))  # -126.999992, the reference's
WIDTH = 16


# --------------------------------------------------------------------------
# Input domains (sets of float32 bit patterns, swept exhaustively)

def _bits(v: float) -> int:
    return int(np.float32(v).view(np.uint32))


@dataclasses.dataclass(frozen=True)
class Domain:
    """All float32 values in ``[lo, hi)`` (as bit-pattern ranges; -0 goes with +0)."""

    lo: float
    hi: float
    label: str = ""

    @property
    def ranges(self) -> tuple[tuple[int, int], ...]:
        """Half-open bit-pattern ranges; negative x have bits 0x80000000 + |x|'s."""
        out = []
        if self.lo < 0:  # lo <= x < min(hi, 0): |min(hi, 0)| < |x| <= |lo|
            top = min(self.hi, 0.0)
            out.append((0x80000001 if top == 0.0 else _bits(top) + 1, _bits(self.lo) + 1))
        if self.hi > 0:
            out.append((_bits(max(self.lo, 0.0)), _bits(self.hi)))
        return tuple(out)

    @property
    def count(self) -> int:
        return sum(b - a for a, b in self.ranges)

    def values(self) -> np.ndarray:
        """Every float32 in the domain (only for small domains)."""
        return np.concatenate([np.arange(a, b, dtype=np.uint32) for a, b in self.ranges]).view(np.float32)

    def __str__(self) -> str:
        return self.label or f"[{self.lo:g}, {self.hi:g})"


def binade(x: float) -> Domain:
    """The binade of x: [2^e, 2^(e+1)) or, for x < 0, (-2^(e+1), -2^e]."""
    e = int(np.floor(np.log2(abs(x))))
    lo, hi = 2.0 ** e, 2.0 ** (e + 1)
    if x > 0:
        return Domain(lo, hi)
    return Domain(-hi, -lo)


# --------------------------------------------------------------------------
# Variants

@dataclasses.dataclass(frozen=True)
class Stated:
    """The reference's figures for a method, as printed there (None: not
    stated), and its words."""

    ulp32: str | None = None
    ulp16: str | None = None
    margin: str | None = None
    quote: str = ""

    def value(self, measure: str) -> float | None:
        text = getattr(self, measure)
        return None if text is None else float(text)

    def unit(self, measure: str) -> float:
        """One unit in the last printed digit ("2.80" -> 0.01)."""
        return 10.0 ** decimal.Decimal(getattr(self, measure)).as_tuple().exponent


@dataclasses.dataclass(frozen=True)
class Variant:
    """One method of the reference, ready to compile and measure.

    ``domain``: where the reference's figures are read (swept exhaustively);
    ``wide``: the larger domain over which the method's conformance is
    judged (swept exhaustively too; for exp2 every x with a normal result);
    ``verdict``: whether the reference calls the method conformant, and
    ``failure`` where it says it fails; ``explain``: one line on how our
    figures compare with the reference's, and why they differ if they do;
    ``peaks``: inputs where the exhaustive run found the largest ULP error,
    margin and (wide) failure; their binades are swept exhaustively by
    ``--quick`` and the tests.
    """

    name: str
    function: str            # "exp2" or "log2"
    precision: str           # the Vulkan tolerance scored against: "full" or "relaxed"
    fma: bool
    section: str             # the reference's section
    description: str
    polynomials: tuple[Polynomial, ...]
    build: object            # builder: Float value -> Float value
    stated: Stated
    domain: Domain
    wide: Domain
    verdict: bool
    failure: str = ""
    explain: str = ""
    peaks: tuple[float, ...] = ()

    def kernel(self, width: int = WIDTH):
        """The compiled ufunc (built once per process)."""
        return _kernel(self, width)


@functools.lru_cache(maxsize=None)
def _kernel(variant: Variant, width: int):
    build = variant.build

    def body(x: Float) -> Float:
        return build(x)

    body.__doc__ = f"zoo variant {variant.name} ({variant.function}), float32."
    tag = "zoo_" + variant.name.replace(".", "_").replace("-", "_")
    return kernel(body, name=tag, fma=variant.fma, width=width)


# --------------------------------------------------------------------------
# Polynomials (coefficients highest degree first, as float32 decimals)

REF = "quoted from the reference, section "
OURS = ("fitted with our Remez fitter; the coefficients are its '// p(x)=' line (8 significant "
        "digits, as LolRemez --float prints them and the reference's C code uses them, "
        "rounded to float32 by the compiler): ")


def _poly(name, function, weight, interval, coefficients, provenance):
    p = Polynomial(name=name, function=function, weight=weight, interval=interval,
                   coefficients=tuple(coefficients), provenance=provenance)
    if provenance.startswith(REF):  # quoted: say that our fitter reproduces the digits
        p = dataclasses.replace(p, provenance=provenance + "; our fitter's '// p(x)=' line has "
                                "exactly these digits: " + p.remez_command())
    return p



P_PLAIN5 = _poly(
    "exp2.plain5", "2^x", "", ("0", "1"),
    ("1.8964611e-3", "8.942829e-3", "5.5866246e-2", "2.4013971e-1", "6.9315475e-1", "9.9999989e-1"),
    REF + "'Exp2 Range Reduction' (lolremez --float -d 5 -r \"0:1\" \"2^x\")")
P_FX1_UNWEIGHTED = _poly(
    "exp2.fx1", "(2^x-1)/x", "", ("0", "1"),
    ("1.7909619e-3", "9.1942073e-3", "5.5660287e-2", "2.4020655e-1", "6.9314759e-1"),
    REF + "'Integer Exactness' (lolremez --float -d 4 -r \"0:1\" \"(2^x - 1) / x\")")
P_FX1_WEIGHTED = _poly(
    "exp2.fx1w", "(2^x-1)/x", "1/x", ("0", "1"),
    ("1.8852974e-3", "8.9733787e-3", "5.5835927e-2", "2.4015281e-1", "6.9315247e-1"),
    REF + "'Watch your Weight' (lolremez --float -d 4 -r \"0:1\" \"(2^x-1)/x\" \"1/x\")")
P_ROUND = _poly(
    "exp2.round", "(2^x-1)/x", "1/x", ("-0.5", "0.5"),
    ("1.3407259e-3", "9.6718751e-3", "5.5503084e-2", "2.4022235e-1", "6.9314721e-1"),
    REF + "'Symmetrical Range Reduction' (lolremez --float -d 4 -r \"-0.5:0.5\" \"(2^x-1)/x\" \"1/x\")")
P_ROUND_ERF = _poly(
    "exp2.round_erf", "(2^x-1)/x", "(0.25*erf(1000*x)+0.75)*(3+2*abs(x))/x", ("-0.5", "0.5"),
    ("1.3225936e-3", "9.6709409e-3", "5.5508796e-2", "2.4022254e-1", "6.9314685e-1"),
    OURS + "python -m routines remez -d 4 -r \"-0.5:0.5\" \"(2^x-1)/x\" "
    "\"(0.25*erf(1000*x)+0.75)*(3+2*abs(x))/x\" (the reference states the weight's numerator "
    "only, 'Symmetrical Range Reduction'; the division by x as in its other weights)")
P_ROUND_W35 = _poly(
    "exp2.round_w35", "(2^x-1)/x", "(3+3.5*x)/x", ("-0.5", "0.5"),
    ("1.3146092e-3", "9.6713871e-3", "5.5510935e-2", "2.4022245e-1", "6.9314677e-1"),
    OURS + "python -m routines remez -d 4 -r \"-0.5:0.5\" \"(2^x-1)/x\" \"(3+3.5*x)/x\" "
    "(weight from the reference, 'Symmetrical Range Reduction'; no coefficients given there)")
P_EXP2_FULL = _poly(
    "exp2.full", "(2^x-x-1)/x", "1/x", ("0", "1"),
    ("1.8852974e-3", "8.9733787e-3", "5.5835927e-2", "2.4015281e-1", "-3.0684753e-1"),
    REF + "'Gaining Significance' (lolremez --float -d 4 -r \"0:1\" \"(2^x-x-1)/x\" \"1/x\")")
P_RELAXED_MUL = _poly(
    "exp2.relaxed_mul", "(2^x-1)/x", "1/x", ("0", "1"),
    ("7.8145574e-2", "2.2617357e-1", "6.9555686e-1"),
    REF + "'Relaxing with a Halfling' (lolremez --float -d 2 -r \"0:1\" \"(2^x-1)/x\" \"1/x\")")
P_RELAXED_ADD = _poly(
    "exp2.relaxed_add", "(2^x-x-1)/x", "1/x", ("0", "1"),
    ("7.8145574e-2", "2.2617357e-1", "-3.0444314e-1"),
    REF + "'Relaxing with a Halfling' (exp2_relaxed: the degree-2 fit above, constant minus 1)")

#: log2 "first attempt": P(y) ~ log2(y)/(y-1) on y in [1, 2] (the piecewise-linear
#: y = 1 + m of an input in [2, 4)), result P(y) * (y - 1) + 1. The reference's
#: command reads -r "2:4", but its degree-5 example ('Second Try') is fitted on
#: "1:2" and "ranges between 1.436 and 1.0", i.e. [1, 2]; its ULP-16 figures
#: (6.48 for D=1, 0.790 for D=2) are exactly our [1, 2] fits' errors / 2^-10.
_FIRST_ATTEMPT = {
    1: ("-3.6327725e-1", "1.7202288"),
    2: ("1.6538379e-1", "-9.1997429e-1", "2.1791844"),
    3: ("-8.4768744e-2", "5.799021e-1", "-1.5854421", "2.5293235"),
    4: ("4.6385369e-2", "-3.8181114e-1", "1.284717", "-2.3192049", "2.8118793"),
    5: ("-2.645745e-2", "2.5573874e-1", "-1.0379186", "2.3021687", "-3.0995312", "3.048553"),
    6: ("1.5529917e-2", "-1.7273724e-1", "8.2503174e-1", "-2.2092549", "3.6455513", "-3.9135437",
        "3.2520907"),
    7: ("-9.3091638e-3", "1.1722315e-1", "-6.4536781e-1", "2.0361773", "-4.0569746", "5.3233667",
        "-4.7530205", "3.4305948"),
}


def _first_attempt_poly(d: int) -> Polynomial:
    cmd = f"python -m routines remez -d {d} -r \"1:2\" \"log2(x)/(x-1)\" \"1/(x-1)\""
    prov = (REF + "'Second Try' (lolremez --float -d 5 -r \"1:2\" \"log2(x)/(x-1)\" \"1/(x-1)\")"
            if d == 5 else
            OURS + cmd + " (the reference gives only the command, with -r \"2:4\", "
            "'Logarithm = Exponential^-1')")
    return _poly(f"log2.first{d}", "log2(x)/(x-1)", "1/(x-1)", ("1", "2"), _FIRST_ATTEMPT[d], prov)


P_LOG2_6 = _poly(
    "log2.second6", "(log2(x+1)-x)/x", "1/x", ("0", "1"),
    ("1.5529917e-2", "-7.9557731e-2", "1.9429432e-1", "-3.2590197e-1", "4.7355341e-1",
     "-7.2058547e-1", "4.4266783e-1"),
    REF + "'Second Try' (lolremez --float -d 6 -r \"0:1\" \"(log2(x+1)-x)/x\" \"1/x\")")
P_LOG2_7 = _poly(
    "log2.second7", "(log2(x+1)-x)/x", "1/x", ("0", "1"),
    ("-9.3091638e-3", "5.2059003e-2", "-1.3752135e-1", "2.4186478e-1", "-3.4730109e-1",
     "4.786837e-1", "-7.2116581e-1", "4.4268988e-1"),
    REF + "'Second Try' (lolremez --float -d 7 -r \"0:1\" \"(log2(x+1)-x)/x\" \"1/x\")")
P_LOG2_RELAXED = _poly(
    "log2.relaxed", "(log2(x/2^23+1)-x/2^23)/x", "1/x", ("0", "2^23"),
    ("2.8017103e-22", "-8.373131e-15", "5.0615534e-8"),
    REF + "'The Vanishingly Small and Unfathomably Large' (lolremez --float -d 2 -r \"0:2^23\" "
    "\"(log2(x/2^23+1)-x/2^23)/x\" \"1/x\")")


# --------------------------------------------------------------------------
# Builders (the reference's C code, statement by statement)

def _types(x):
    return vector_type("Int", x.width), vector_type("Float", x.width)


def _clamp(x):
    """x = min(x, 128); x = max(x, -126.999992) (constants first: NaN propagates)."""
    return Max(LOWER_CLAMP, Min(128.0, x))


def _exp2i(xi):
    """bit_cast<float>((i + 127) << 23) for the integral float xi (i = (int)xi)."""
    Int_, Float_ = _types(xi)
    return As(Float_, (ToInt(xi) + 127) << 23)


def _exp2_multiplicative(reduce, poly_then):
    """2^i * Q(f): ``reduce`` gives the integral part (Floor or Round), ``poly_then``
    maps f to the fraction's polynomial value Q(f)."""
    def build(x):
        x = _clamp(x)
        xi = reduce(x)
        f = x - xi
        return _exp2i(xi) * poly_then(f)
    return build


def _times_x_plus_one(p):
    return lambda f: MulAdd(p(f), f, 1.0)


def _exp2_additive(p, exponent: str):
    """y = P(f) * f + x; the exponent inserted with integer arithmetic
    ``(int)(y * 2^23) + (127 << 23)`` or the float FMA trick
    ``(int)fma(y, 2^23, 127 << 23)`` (fused iff the build's FMA is on)."""
    def build(x):
        Int_, Float_ = _types(x)
        x = _clamp(x)
        f = x - Floor(x)
        y = MulAdd(p(f), f, x)
        if exponent == "integer":
            bits = ToInt(y * MANTISSA_SCALE, saturate=False) + BIAS_BITS
        else:
            bits = ToInt(MulAdd(y, MANTISSA_SCALE, float(BIAS_BITS)), saturate=False)
        return As(Float_, bits)
    return build


def _exp2_relaxed_fma_exponent(p):
    """The multiplicative relaxed exp2 with exp2i = bit_cast<float>((int)fma(x0, 1 << 23, 127 << 23))."""
    def build(x):
        Int_, Float_ = _types(x)
        x = _clamp(x)
        x0 = Floor(x)
        f = x - x0
        exp2i = As(Float_, ToInt(MulAdd(x0, MANTISSA_SCALE, float(BIAS_BITS)), saturate=False))
        return exp2i * MulAdd(p(f), f, 1.0)
    return build


def _log2_first(p):
    """log2(2^e (1 + m)) = e + P(y) * (y - 1) with y = 1 + m in [1, 2): the
    reference's "P(y) * (y - 1) + 1" for its test interval [2, 4) (e = 1),
    with the exponent added back for other binades. Positive normal x only."""
    def build(x):
        Int_, Float_ = _types(x)
        bits = As(Int_, x)
        y = As(Float_, (bits & 0x007FFFFF) | 0x3F800000)      # 1 + m, exact
        e = Float_((bits >> 23) - 127)
        return MulAdd(p(y), y - 1.0, e)
    return build


def _log2_second(p, inf_fix: bool):
    """The reference's log2: y = (float)(im - (127 << 23)) * 2^-23,
    m = (float)(im & 0x7FFFFF) * 2^-23, P(m) * m + y (optionally y = inf
    for x = +inf). Positive normal x only."""
    def build(x):
        Int_, Float_ = _types(x)
        im = As(Int_, x)
        y = Float_(im - BIAS_BITS) * float(2 ** -23)
        if inf_fix:
            y = Select(im == 0x7F800000, float("inf"), y)
        m = Float_(im & 0x007FFFFF) * float(2 ** -23)
        return MulAdd(p(m), m, y)
    return build


def _log2_relaxed(p):
    """log2_relaxed: y = fma((float)im, 2^-23, -127), m = (float)(im & 0x7FFFFF)
    (not normalized), fma(P(m), m, y)."""
    def build(x):
        Int_, Float_ = _types(x)
        im = As(Int_, x)
        y = MulAdd(Float_(im), float(2 ** -23), -127.0)
        m = Float_(im & 0x007FFFFF)
        return MulAdd(p(m), m, y)
    return build


# --------------------------------------------------------------------------
# The zoo

#: Where the reference's exp2 figures are read: x in [-1, 1) (its margins
#: peak just below 0, so its domain includes negative x; [-1, 1) reproduces
#: every figure that [0, 1) or [-1, 0) alone does not, see docs/zoo.md).
EXP2_DOMAIN = Domain(-1.0, 1.0, "[-1,1)")
#: Every x whose 2^x is a normal float32: conformance of an exp2 method.
EXP2_WIDE = Domain(-126.0, 128.0, "[-126,128)")
#: The reference states log2's figures "over [2,4)".
LOG2_DOMAIN = Domain(2.0, 4.0, "[2,4)")
#: Eight binades around 1, with log2's absolute-error zone [0.5, 2].
LOG2_WIDE = Domain(2.0 ** -4, 2.0 ** 4, "[1/16,16)")

ROUND_OVERFLOW = "+inf for x in (127.5, 128): round(x) = 128 makes 2^128 overflow (x = 127.7)"


#: Where ``python -m routines zoo`` (exhaustive) finds each variant's largest
#: ULP-32 and margin on its domain, its largest margin on the wide domain, and
#: (round variants) the overflow: the "max_*_at" entries of its JSON output.
#: Every log2 maximum lies in [2,4), the domain itself (one binade).
PEAKS = {
    "exp2.plain5": (-0.000273258,),
    "exp2.fx1": (-0.0853159, -0.000448197),
    "exp2.fx1w": (-0.0686109,),
    "exp2.round": (-0.429733, 127.7),
    "exp2.round_erf": (-0.428963, 127.7),
    "exp2.round_w35": (-0.500201, -0.255736, 127.7),
    "exp2.fma_trick": (0.998891, -0.000894468, 1.01741),
    "exp2.fma_trick.fma": (0.749964, -0.000184268, 1.01741),
    "exp2.final": (-0.0626507,),
    "exp2.final.fma": (-0.0645294, -0.0625447),
    "exp2.relaxed_mul": (-0.147662, -2.35438e-06),
    "exp2.relaxed_fmaexp": (-0.147662, -2.35438e-06),
    "exp2.relaxed": (-0.510475, -1.34133e-06),
    "exp2.relaxed.nofma": (-0.511056, -1.34129e-06),
}


def _v(name, function, precision, fma, section, description, polys, build, stated, verdict,
       failure="", explain=""):
    domain, wide = (EXP2_DOMAIN, EXP2_WIDE) if function == "exp2" else (LOG2_DOMAIN, LOG2_WIDE)
    peaks = PEAKS.get(name, (3.0,))
    return Variant(name, function, precision, fma, section, description, tuple(polys), build,
                   stated, domain, wide, verdict, failure, explain, peaks)


def _exp2_variants():
    vs = [
        _v("exp2.plain5", "exp2", "full", False, "Exp2 Range Reduction",
           "2^floor(x) * P5(f), P5 the degree-5 minimax 2^x on [0,1]",
           [P_PLAIN5], _exp2_multiplicative(Floor, P_PLAIN5),
           Stated("2.56", None, "0.855", "it's actually 2.56 ULP when using binary32 ... [the "
                  "margin] peaks at 0.855"), True,
           explain="reproduced; both maxima just below x = 0 (f = x + 1 near 1, tolerance ~3 ULP); "
                   "2.567 is quoted as 2.56 (truncated)"),
        _v("exp2.fx1", "exp2", "full", False, "Integer Exactness",
           "2^floor(x) * (f(x)*x + 1), f the unweighted degree-4 fit of (2^x-1)/x",
           [P_FX1_UNWEIGHTED], _exp2_multiplicative(Floor, _times_x_plus_one(P_FX1_UNWEIGHTED)),
           Stated(None, None, "1.56", "the margin is exceeded by 1.56 ... for a very small "
                  "negative value of x"), False,
           failure="margin > 1 for small negative x (the polynomial evaluated near f = 1)",
           explain="reproduced; margin > 1 only for x in [-0.25, -2^-25) (f = x + 1 near 1), "
                   "never for x >= 0"),
        _v("exp2.fx1w", "exp2", "full", False, "Watch your Weight",
           "2^floor(x) * (f(x)*x + 1), f fitted with weight 1/x",
           [P_FX1_WEIGHTED], _exp2_multiplicative(Floor, _times_x_plus_one(P_FX1_WEIGHTED)),
           Stated("2.66", None, "0.85", "the single-precision results are also good: 2.66 ULP and "
                  "a margin value of 0.85"), True,
           explain="reproduced; both maxima at x = -0.0686 (f = 0.93)"),
        _v("exp2.round", "exp2", "full", False, "Symmetrical Range Reduction",
           "2^round(x) * (f(x)*x + 1), f fitted on [-0.5,0.5] with weight 1/x",
           [P_ROUND], _exp2_multiplicative(Round, _times_x_plus_one(P_ROUND)),
           Stated("2.80", None, "0.73", "an effective ULP error of 2.80 ... the 'margin' measure "
                  "improved from 0.85 to 0.73"), False, ROUND_OVERFLOW,
           explain="reproduced; conforms on [-1,1) but fails at 127.7 as the reference says "
                   "('Watch your Extremities')"),
        _v("exp2.round_erf", "exp2", "full", False, "Symmetrical Range Reduction",
           "as exp2.round, weight (0.25 erf(1000x) + 0.75)(3 + 2|x|)/x",
           [P_ROUND_ERF], _exp2_multiplicative(Round, _times_x_plus_one(P_ROUND_ERF)),
           Stated("2.29", None, "0.59", "This gives us 2.29 ULP and a 0.59 margin"), False,
           ROUND_OVERFLOW,
           explain="reproduced within 1% with our own fit (the reference gives no coefficients "
                   "for this weight); overflows at 127.7 like every round() variant"),
        _v("exp2.round_w35", "exp2", "full", False, "Symmetrical Range Reduction",
           "as exp2.round, weight (3 + 3.5x)/x",
           [P_ROUND_W35], _exp2_multiplicative(Round, _times_x_plus_one(P_ROUND_W35)),
           Stated("1.88", None, "0.54", "a weight function of (3 + 3.5x)/x produces an even better "
                  "result: 1.88 ULP, and 0.54 margin"), False, ROUND_OVERFLOW,
           explain="margin reproduced, ULP-32 NOT (2.07 vs 1.88, at x = -0.5002): our minimax "
                   "fit for this weight is already 1.31 ULP off at |f| = 0.5 before rounding; the "
                   "reference's coefficients ('trial and error') are not given; FMA gives 1.93; "
                   "unexplained"),
    ]
    for fma in (False, True):
        vs.append(_v(
            f"exp2.fma_trick{'.fma' if fma else ''}", "exp2", "full", fma, "Gaining Significance",
            "y = P(f)*f + x, exponent by (int)fma(y, 2^23, 127<<23) in float"
            + (" (fused)" if fma else " (separate multiply and add)"),
            [P_EXP2_FULL], _exp2_additive(P_EXP2_FULL, "float"),
            Stated("33.4", None, None, "the ULP-32 error increases to 33.4, failing to meet "
                   "Vulkan's requirement ... with both separate multiplies and additions, and "
                   "with 32-bit FMA"), False,
            "~33 ULP-32 everywhere: y * 2^23 + 127 * 2^23 ~ 2^30 is rounded to a multiple of 64",
            "reproduced; 32 of the 33.4 ULP are the float rounding of y*2^23 + 127*2^23 (spacing "
            "64 in [2^29, 2^30))"))
    for fma in (False, True):
        vs.append(_v(
            f"exp2.final{'.fma' if fma else ''}", "exp2", "full", fma, "Gaining Significance",
            "y = P(f)*f + x, exponent by (int)(y * 2^23) + (127<<23) in integers",
            [P_EXP2_FULL], _exp2_additive(P_EXP2_FULL, "integer"),
            Stated("2.06" if fma else "2.15", None, None,
                   "an excellent accuracy of 2.15 ULP (2.06 when using fma32())"), True,
            explain="reproduced; maximum at x ~ -0.06 (the positive half alone gives "
                    + ("1.98" if fma else "2.04") + "); the ULP error grows with |x| outside "
                    "[-1,1) (y = x + P(f)f keeps fewer fraction bits) but stays within 3 + 2|x|"))
    vs += [
        _v("exp2.relaxed_mul", "exp2", "relaxed", True, "Relaxing with a Halfling",
           "2^floor(x) * fma(fma(fma(a,f,b),f,c),f,1), degree-2 fit of (2^x-1)/x",
           [P_RELAXED_MUL], _exp2_multiplicative(Floor, _times_x_plus_one(P_RELAXED_MUL)),
           Stated(None, "0.13", None, "This achieves 0.13 ULP"), True,
           explain="reproduced (0.127 ULP-16; margin peak at x = -2.4e-6)"),
        _v("exp2.relaxed_fmaexp", "exp2", "relaxed", True, "Relaxing with a Halfling",
           "as exp2.relaxed_mul, exp2i = bit_cast((int)fma(x0, 1<<23, 127<<23))",
           [P_RELAXED_MUL], _exp2_relaxed_fma_exponent(P_RELAXED_MUL),
           Stated(None, "0.13", None, "[the same code with the exponent inserted by one FMA]"),
           True, explain="reproduced; bit-identical to exp2.relaxed_mul (x0 is integral, so "
                         "the FMA is exact)"),
    ]
    for fma in (True, False):
        vs.append(_v(
            f"exp2.relaxed{'' if fma else '.nofma'}", "exp2", "relaxed", fma,
            "Relaxing with a Halfling",
            "exp2_relaxed: y = fma(P(f), f, x), (int)fma(y, 1<<23, 127<<23)"
            + ("" if fma else " with separate multiplies and adds"),
            [P_RELAXED_ADD], _exp2_additive(P_RELAXED_ADD, "float"),
            Stated(None, "0.13", None, "The accuracy is still the same as the one above"
                   + ("" if fma else " ... If I replace the fma() calls ... with multiplies and "
                      "additions, the achieved accuracy remains the same")), True,
            explain="reproduced (0.131 ULP-16); the float exponent insertion costs <= 32 ULP-32 "
                    "= 0.004 ULP-16"))
    return vs


_FIRST_STATED = {  # D: (ULP-32, ULP-32 with FMA, ULP-16), the reference's table
    1: (None, None, "6.47766"), 2: (None, None, "0.78980"), 3: ("862.56", None, "0.10535"),
    4: ("124.86", None, "0.015259"), 5: ("25.176", "22.872", "0.0030518"),
    6: ("26.249", "21.116", "0.0031738"), 7: ("54.680", "40.117", None),
}

ULP16_NOTE = "the reference's ULP-16 is round(ULP-32)/2^13, ours ULP-32/2^13"


def _first_explain(d, fma):
    if fma and d >= 5:
        return {5: "reproduced (22.860 vs 22.872; every Horner step fused here, the reference's "
                   "exact fusing is not shown)",
                6: "within 0.3% (21.05 vs 21.12): which operations the reference fused is not "
                   "shown; ours fuses every Horner step and the final multiply-add",
                7: "reproduced"}[d]
    if fma:
        return "no figure stated; fails as the reference says for every D"
    coeffs = ("quoted coefficients" if d == 5 else
              "our fit, printed to 8 digits as LolRemez does (correctly rounded float32 "
              "coefficients give 19.2, not 26.2, for D=6)")
    if d <= 2:
        return f"ULP-16 reproduced; {ULP16_NOTE}; {coeffs}"
    return f"reproduced; {coeffs}" + ("" if d == 7 else f"; {ULP16_NOTE}")


def _log2_variants():
    vs = []
    for d in range(1, 8):
        p = _first_attempt_poly(d)
        u32, u32f, u16 = _FIRST_STATED[d]
        for fma in (False, True):
            vs.append(_v(
                f"log2.first{d}{'.fma' if fma else ''}", "log2", "full", fma,
                "Logarithm = Exponential^-1",
                f"e + P{d}(y) * (y - 1), y = 1 + m, P{d} ~ log2(y)/(y-1) on [1,2]",
                [p], _log2_first(p),
                Stated(u32f if fma else u32, None if fma else u16, None,
                       f"table, D={d}: ULP-32 over [2,4) {u32 or '-'}, with FMA {u32f or '-'}, "
                       f"ULP-16 {u16 or '-'}"), False,
                "> 3 ULP-32 in [2,4) for every D" + ("; ULP-16 < 1 for D >= 2" if d >= 2 else
                                                     "; ULP-16 > 1"),
                _first_explain(d, fma)))
    for d, p, s32, quote, fix in (
            (6, P_LOG2_6, "3.71", "an effective ULP error of 3.71 in the [2,4) interval", False),
            (7, P_LOG2_7, "1.70", "for D=7 ... This achieves 1.70 ULP. Success!", True)):
        for fma in (False, True):
            vs.append(_v(
                f"log2.second{d}{'.fma' if fma else ''}", "log2", "full", fma, "Second Try",
                f"P{d}(m) * m + y, y = (float)(im - (127<<23)) * 2^-23, m the mantissa"
                + (" (+inf fix)" if fix else ""),
                [p], _log2_second(p, fix),
                Stated(None if fma else s32, None, None,
                       quote + (" ... FMA operations can lower it a bit further" if fma else "")),
                d == 7, "" if d == 7 else "> 3 ULP-32 in [2,4) (up to 3.71 just below x = 4)",
                ("lower with FMA, as the reference says; no figure stated" if fma else
                 "reproduced" + ("; fails only near x = 4 (m near 1)" if d == 6 else ""))))
    vs.append(_v(
        "log2.relaxed", "log2", "relaxed", True, "The Vanishingly Small and Unfathomably Large",
        "fma(P(m), m, fma((float)im, 2^-23, -127)), m the un-normalized mantissa (0..2^23)",
        [P_LOG2_RELAXED], _log2_relaxed(P_LOG2_RELAXED),
        Stated(None, None, None, "It's fine for a relaxed precision version though"), True,
        explain="no figure stated; conforms (relaxed) as the reference says"))
    return vs


VARIANTS: tuple[Variant, ...] = tuple(_exp2_variants() + _log2_variants())
BY_NAME = {v.name: v for v in VARIANTS}


def variant(name: str) -> Variant:
    """The variant called ``name`` (KeyError listing the names otherwise)."""
    try:
        return BY_NAME[name]
    except KeyError:
        raise KeyError(f"unknown zoo variant {name!r}; one of {', '.join(BY_NAME)}") from None
