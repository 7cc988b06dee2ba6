"""Candidate variants of exp2 and log2 for the variant search (docs/search.md).

A :class:`Candidate` is one point of the design space, fully specified: the
reduction/correction *form*, the polynomial (degree, the Remez weight it was
fitted with, its float32 coefficients), the *evaluation* order, FMA on or
off and, for exp2, how ``y`` is converted to the result's bits. It builds
the whole routine (special values included, as the library's routines do)
as a DSL builder and compiles it with ``reactor.kernel``.

Forms (``f = ReduceDown(x)``, ``m = Significand(x) - 1``, ``e = Exponent(x)``):

exp2 (the result's bits are ``int(y * 2^23) + (127 << 23)``, clamped to +inf
as unsigned, +0 below -126, NaN for NaN -- the production structure):

``additive``    ``y = P(f) * f + x``, P ~ (2^f - f - 1)/f: production's form
                (the reference's "Gaining Significance");
``additive01``  ``y = R(f) * (f*f - f) + x``, R ~ (2^f - f - 1)/(f(f - 1)):
                the correction is factored by both of its zeros (f = 0 and
                f = 1). ``f*f - f`` is one FMA and R has one degree less, so
                the operation count equals ``additive``'s for the same total
                degree; R lies in [0.307, 0.386], so Horner does not cancel
                near f = 1 (P(1) = 0 does: its terms are ~0.3 and sum to 0);
``floorsum``    ``y = (P(f) * f + f) + floor(x)``: the alternative the
                reference rejects (the sum is rounded twice; one more op).

exp2 by VSCALEFPS (AVX-512: ``scalef(a, b) = a * 2^floor(b)``, exact, with
IEEE overflow to +inf, underflow to subnormals/0, NaN and infinities
handled: no clamp, no exponent insertion, no special-value fix-up):

``scalef``      ``scalef((P(f) * f + f) + 1, x)``: the same small correction
                as ``additive``, then 2^f = 1 + (2^f - 1) rounded once more;
``scalef01``    ``scalef((R(f) * (f*f - f) + f) + 1, x)``;
``scalefmul``   ``scalef(P(f) * f + 1, x)``, P ~ (2^f - 1)/f: the reference's
                multiplicative form ("Watch your Weight"), one add fewer.

Rounding the *rounded* f = ReduceDown(x) (inexact for x in (-1/2, 0)) costs up to
0.7 ULP in these three; the additive forms absorb it (y adds the exact x).
Round-to-nearest reduction has no such error and no overflow with VSCALEFPS
(the reference rejected it because 2^round(x) overflows at x = 127.5 when
multiplied out; scalef scales the product exactly):

``rscalef``     ``f = x - round(x)`` (one VREDUCEPS, exact, 0 for infinities),
                ``k = x - f`` (exact), ``scalef((P(f) * f + f) + 1, k)``,
                P ~ (2^f - f - 1)/f on [-1/2, 1/2];
``rscalefmul``  ``scalef(P(f) * f + 1, k)``, P ~ (2^f - 1)/f on [-1/2, 1/2]
                (the reference's "Symmetrical Range Reduction" with FMA).

log2:

``m``           ``P(m) * m + (e + m)``: production's form ("Second Try");
``m1m``         ``R(m) * (m - m*m) + (e + m)``, R ~ (log2(1+m) - m)/(m(1-m)):
                again both zeros factored (log2(2) - 1 = 0), same operation
                count as ``m`` for the same total degree, exact at m = 1 too;
``m1m_re``      ``(R(m) * (m - m*m) + m) + e``: the small sum first, the
                exponent last (rounds once at the result's scale instead of
                rounding ``e + m`` for |e| >= 2; same count);
``m1mc``        the same, centred: ``u = Significand(x) - 1.5`` (= m - 1/2, exact),
                ``(R(u) * (1/4 - u*u) + u) + (e + 1/2)``: the partial sum
                ``u + correction`` lies in [-1/2, 0.59) instead of [0, 1), so
                it rounds on a grid twice as fine (1/8 instead of 1/4 of a
                result ULP in [1, 4)); ``e + 1/2`` is one more add, on the
                FP2/FP3 pipes that log2 leaves idle (same cycle count).

Conversion (exp2): ``trunc`` (VCVTTPS2DQ, production) or ``nearest``
(``llvm.lrint``: VCVTPS2DQ under the default rounding mode, also one
instruction); ``roundeven`` is the same rounding through reactor's
``ToInt(v, "nearest")``, which emits VRNDSCALEPS + VCVTTPS2DQ (identical
results, one more instruction: listed to show that cost).
Insertion (exp2): ``integer`` (production full) or ``float`` (relaxed: one
FMA ``int(fma(y, 2^23, 127 * 2^23))``; with FMA off the production relaxed
routine takes the integer path).

Evaluation: ``horner`` (production) or ``estrin`` (pairs, then powers of x:
shorter dependency chain, one more multiply per level).
"""
from __future__ import annotations

import dataclasses
import functools
import hashlib
import itertools

import numpy as np

from reactor import (As, Exponent, Float, Floor, LRint, Min, MulAdd, ReduceDown, ReduceNearest, ScaleF, Select,
                     Significand, ToInt, fma_mode, kernel, vector_type)

from ..base import PRECISIONS

MANTISSA_SCALE = float(2 ** 23)
BIAS_BITS = 127 << 23
INF_BITS = 0x7F800000

FUNCTIONS = ("exp2", "log2")

#: What each form's polynomial approximates, on [0, 1], and the factor the
#: polynomial is multiplied by (the weight's denominator: the fit's weight is
#: the tolerance of the product, divided by that factor).
FITTED = {
    ("exp2", "additive"): ("(2^x-x-1)/x", "x"),
    ("exp2", "floorsum"): ("(2^x-x-1)/x", "x"),
    ("exp2", "additive01"): ("(2^x-x-1)/(x*(x-1))", "(x*(1-x))"),
    ("exp2", "scalef"): ("(2^x-x-1)/x", "x"),
    ("exp2", "scalef01"): ("(2^x-x-1)/(x*(x-1))", "(x*(1-x))"),
    ("exp2", "scalefmul"): ("(2^x-1)/x", "x"),
    ("exp2", "rscalef"): ("(2^x-x-1)/x", "x"),
    ("exp2", "rscalefmul"): ("(2^x-1)/x", "x"),
    ("log2", "m"): ("(log2(x+1)-x)/x", "x"),
    ("log2", "m1m"): ("(log2(x+1)-x)/(x*(1-x))", "(x*(1-x))"),
    ("log2", "m1m_re"): ("(log2(x+1)-x)/(x*(1-x))", "(x*(1-x))"),
    ("log2", "m1mc"): ("(log2(x+1.5)-x-0.5)/((x+0.5)*(0.5-x))", "((x+0.5)*(0.5-x))"),
}
FORMS = {"exp2": ("additive", "additive01", "floorsum", "scalef", "scalef01", "scalefmul", "rscalef",
                  "rscalefmul"), "log2": ("m", "m1m", "m1m_re", "m1mc")}

#: Tolerance shapes T(f) for the absolute error of the correction, as Remez
#: weights T/factor (LolRemez's convention: the weight is the tolerance).
#: "tent<c>": c - 2|f - 1/2|. Floor reduction evaluates P at f for x = k + f,
#: and for x in [-1, 0) at f = x + 1: in units of the result's mantissa the
#: tolerance there is 3 + 2|x| = 5 - 2f, for x in [0, 1) it is 3 + 2f, so the
#: binding tolerance is min(3 + 2f, 5 - 2f) = 4 - 2|f - 1/2| ("tent4"); a
#: smaller c reserves a constant budget for the roundings (c = 4 - budget/margin).
SHAPES = {
    "abs": "1",
    "w35": "(3+3.5*x)",
    "tent4": "(4-2*abs(x-0.5))",
    "tent3.5": "(3.5-2*abs(x-0.5))",
    "tent3": "(3-2*abs(x-0.5))",
    "tent2.5": "(2.5-2*abs(x-0.5))",
    "tent2.2": "(2.2-2*abs(x-0.5))",
    # round reduction, f in [-1/2, 1/2]: p = 2^f is below 1 for f < 0, where a
    # result ULP is half as large; the tolerance of p is (3 + 2|f|) ULP for
    # f >= 0 and half of that for f < 0 (the reference's erf weight), minus a
    # rounding budget for c < 3
    "erf3": "(0.25*erf(1000*x)+0.75)*(3+2*abs(x))",
    "erf2.5": "(0.25*erf(1000*x)+0.75)*(2.5+2*abs(x))",
    "erf2": "(0.25*erf(1000*x)+0.75)*(2+2*abs(x))",
    "erf1.5": "(0.25*erf(1000*x)+0.75)*(1.5+2*abs(x))",
}
#: Forms whose polynomial lives on [-1/2, 1/2] (round-to-nearest reduction).
ROUND_FORMS = ("rscalef", "rscalefmul", "m1mc")


def weight_of(function: str, form: str, shape: str) -> str:
    """The Remez weight (tolerance of the fitted quotient) for a shape."""
    t = SHAPES[shape]
    factor = FITTED[(function, form)][1]
    return f"1/{factor}" if t == "1" else f"{t}/{factor}"


@functools.lru_cache(maxsize=None)
def fit(function: str, form: str, degree: int, shape: str) -> tuple[tuple[str, ...], float]:
    """Remez fit (our fitter, 50 digits) rounded to float32: coefficients as
    shortest decimals, highest degree first, and the levelled weighted error."""
    from ..remez import remez
    f, _ = FITTED[(function, form)]
    lo, hi = interval(form)
    r = remez(f, lo, hi, degree, weight_of(function, form, shape))
    return tuple(str(np.float32(v)) for v in r.float32[::-1]), float(r.error)


def interval(form: str) -> tuple[float, float]:
    return (-0.5, 0.5) if form in ROUND_FORMS else (0.0, 1.0)


def remez_command(function: str, form: str, degree: int, shape: str) -> str:
    f, _ = FITTED[(function, form)]
    lo, hi = interval(form)
    return (f'python -m routines remez -d {degree} -r "{lo:g}:{hi:g}" "{f}" '
            f'"{weight_of(function, form, shape)}"')


# --------------------------------------------------------------------------
# Polynomial evaluation

def horner(x, c):
    """c highest degree first; MulAdd is fused iff the build's FMA is on."""
    if len(c) == 1:
        return c[0]  # a constant: MulAdd takes it in any position
    acc = MulAdd(x, c[0], c[1])
    for coeff in c[2:]:
        acc = MulAdd(acc, x, coeff)
    return acc


def estrin(x, c):
    """Estrin's scheme: a0 + a1 x, a2 + a3 x, ... then combined with x^2, x^4, ..."""
    a = list(c[::-1])  # lowest degree first
    if len(a) == 1:
        return a[0]
    terms = [MulAdd(x, a[i + 1], a[i]) if i + 1 < len(a) else a[i] for i in range(0, len(a), 2)]
    power = x * x
    while len(terms) > 1:
        nxt = []
        for i in range(0, len(terms), 2):
            if i + 1 < len(terms):
                hi = terms[i + 1]
                nxt.append(MulAdd(hi, power, terms[i]) if not isinstance(hi, float)
                           else MulAdd(power, hi, terms[i]))
            else:
                nxt.append(terms[i])
        terms = nxt
        if len(terms) > 1:
            power = power * power
    return terms[0]


EVALUATIONS = {"horner": horner, "estrin": estrin}


# --------------------------------------------------------------------------
# Candidates

@dataclasses.dataclass(frozen=True)
class Candidate:
    """One variant: everything that determines its compiled code."""

    function: str                     # "exp2" | "log2"
    precision: str                    # "full" | "relaxed": the tolerance it is scored against
    form: str
    degree: int                       # degree of the evaluated polynomial (P or R)
    shape: str                        # key of SHAPES the coefficients were fitted with ("" if none)
    coefficients: tuple[str, ...]     # float32 decimals, highest degree first
    fma: bool
    evaluation: str = "horner"
    conversion: str = "trunc"         # exp2 only
    insertion: str = "integer"        # exp2 only
    provenance: str = ""
    tag: str = ""                     # extra name part ("retuned", "production", ...)
    production: bool = False          # the shipped routine (built with routines.kernels.jit)

    @property
    def values(self) -> tuple[float, ...]:
        return tuple(float(np.float32(c)) for c in self.coefficients)

    @property
    def name(self) -> str:
        if self.production:
            return f"{self.function}.{self.precision}.production{'' if self.fma else '.nofma'}"
        parts = [self.function, self.precision, self.form, f"d{self.degree}"]
        if self.shape:
            parts.append(self.shape)
        if self.function == "exp2" and "scalef" not in self.form:
            parts.append(self.conversion)
            if self.insertion != "integer":
                parts.append(self.insertion)
        if self.evaluation != "horner":
            parts.append(self.evaluation)
        if self.tag:
            parts.append(self.tag)
        if not self.fma:
            parts.append("nofma")
        return ".".join(parts)

    @property
    def weight(self) -> str:
        return weight_of(self.function, self.form, self.shape) if self.shape else ""

    @property
    def total_degree(self) -> int:
        """Degree of the whole correction polynomial (P(f) f or R(f) f (f - 1))."""
        return self.degree + (2 if self.form in ("additive01", "scalef01", "m1m", "m1m_re", "m1mc") else 1)

    @property
    def description(self) -> str:
        if self.production:
            return (f"the library's {self.function} ({self.precision}) as shipped "
                    f"(routines.kernels.jit), FMA {'on' if self.fma else 'off'}")
        what = {
            "additive": "y = P(f) f + x",
            "additive01": "y = R(f) (f^2 - f) + x",
            "floorsum": "y = (P(f) f + f) + floor(x)",
            "scalef": "scalef((P(f) f + f) + 1, x)",
            "scalef01": "scalef((R(f) (f^2 - f) + f) + 1, x)",
            "scalefmul": "scalef(P(f) f + 1, x)",
            "rscalef": "f = x - round(x), scalef((P(f) f + f) + 1, x - f)",
            "rscalefmul": "f = x - round(x), scalef(P(f) f + 1, x - f)",
            "m": "P(m) m + (e + m)",
            "m1m": "R(m) (m - m^2) + (e + m)",
            "m1m_re": "(R(m) (m - m^2) + m) + e",
            "m1mc": "u = m - 1/2: (R(u) (1/4 - u^2) + u) + (e + 1/2)",
        }[self.form]
        poly = "R" if self.form in ("additive01", "scalef01", "m1m", "m1m_re", "m1mc") else "P"
        s = (f"{what}, {poly} of degree {self.degree} (total {self.total_degree}), "
             f"{self.evaluation}")
        if self.weight:
            s += f", fitted with weight {self.weight}"
        if self.tag == "retuned":
            s += ", coefficients retuned against the compiled error"
        if self.function == "exp2" and "scalef" not in self.form:
            s += (f"; bits = {'int' if self.conversion == 'trunc' else 'round'}"
                  + ("(fma(y, 2^23, 127<<23))" if self.insertion == "float" else "(y * 2^23) + (127<<23)"))
        return s + f"; FMA {'on' if self.fma else 'off'}"

    def with_coefficients(self, coefficients, tag="retuned", provenance="") -> "Candidate":
        return dataclasses.replace(self, coefficients=tuple(str(np.float32(c)) for c in coefficients),
                                   tag=tag, provenance=provenance or self.provenance)

    # -- building ---------------------------------------------------------

    def build(self, x):
        """Emit the routine for the Float value ``x`` (any width)."""
        if self.production:
            from ..kernels import UNARY
            return UNARY[self.function](x, precision=self.precision)
        return (_build_exp2 if self.function == "exp2" else _build_log2)(self, x)

    def kernel(self):
        """The compiled ufunc (once per process)."""
        return _kernel(self)

    def to_json(self) -> dict:
        d = {"form": self.form, "degree": self.degree, "total_degree": self.total_degree,
             "weight": self.weight, "shape": self.shape, "coefficients": list(self.coefficients),
             "evaluation": self.evaluation, "production": self.production,
             "provenance": self.provenance}
        if self.function == "exp2" and "scalef" not in self.form:
            d |= {"conversion": self.conversion, "insertion": self.insertion}
        return d


_serial = itertools.count()


@functools.lru_cache(maxsize=None)
def _kernel(c: Candidate):
    if c.production:
        from ..kernels import jit
        return jit(c.function, c.precision, c.fma)

    def body(x: Float) -> Float:
        return c.build(x)

    body.__doc__ = f"search candidate {c.name}"
    digest = hashlib.sha1(repr(c).encode()).hexdigest()[:10]
    return kernel(body, name=f"search_{c.function}_{digest}_{next(_serial)}", fma=c.fma,
                  cache=False)


def _to_int(v, conversion: str):
    if conversion == "nearest":
        return LRint(v)  # one VCVTPS2DQ; ToInt(v, "nearest") is VRNDSCALEPS + VCVTTPS2DQ, same results
    if conversion == "roundeven":
        return ToInt(v, "nearest", saturate=False)
    return ToInt(v, saturate=False)


def _poly(c: Candidate, x):
    return EVALUATIONS[c.evaluation](x, c.values)


def _build_exp2(c: Candidate, x):
    Int_, UInt_, Float_ = (vector_type(k, x.width) for k in ("Int", "UInt", "Float"))
    if c.form in ROUND_FORMS:
        f = ReduceNearest(x)
        k = x - f
        if c.form == "rscalef":
            p = MulAdd(_poly(c, f), f, f) + 1.0
        else:
            p = MulAdd(_poly(c, f), f, 1.0)
        return ScaleF(p, k)
    f = ReduceDown(x)
    if c.form.startswith("scalef"):
        if c.form == "scalef":
            p = MulAdd(_poly(c, f), f, f) + 1.0
        elif c.form == "scalef01":
            p = MulAdd(_poly(c, f), MulAdd(f, f, -f), f) + 1.0
        else:
            p = MulAdd(_poly(c, f), f, 1.0)
        return ScaleF(p, x)
    if c.form == "additive":
        y = MulAdd(_poly(c, f), f, x)
    elif c.form == "additive01":
        y = MulAdd(_poly(c, f), MulAdd(f, f, -f), x)
    elif c.form == "floorsum":
        y = MulAdd(_poly(c, f), f, f) + Floor(x)
    else:
        raise ValueError(f"unknown exp2 form {c.form!r}")
    if c.insertion == "float":
        with fma_mode(True):
            bits = _to_int(MulAdd(y, MANTISSA_SCALE, float(BIAS_BITS)), c.conversion)
    else:
        bits = _to_int(y * MANTISSA_SCALE, c.conversion) + Int_(BIAS_BITS)
    r = As(Float_, Min(As(UInt_, bits), UInt_(INF_BITS)))  # y >= 128 and overflows -> +inf
    tiny_or_nan = ~(x >= -126.0)
    return Select(tiny_or_nan, f - f, r)  # +0 below 2^-126 (and -inf), NaN for NaN


def _build_log2(c: Candidate, x):
    if c.form == "m1mc":
        u = Significand(x) - 1.5
        t = MulAdd(-u, u, 0.25)  # (u + 1/2)(1/2 - u) = m (1 - m), one rounding
        return MulAdd(_poly(c, u), t, u) + (Exponent(x) + 0.5)
    m = Significand(x) - 1.0
    e = Exponent(x)
    if c.form == "m":
        return MulAdd(_poly(c, m), m, e + m)
    t = MulAdd(-m, m, m)  # m (1 - m), one rounding
    if c.form == "m1m":
        return MulAdd(_poly(c, m), t, e + m)
    if c.form == "m1m_re":
        return MulAdd(_poly(c, m), t, m) + e
    raise ValueError(f"unknown log2 form {c.form!r}")


# --------------------------------------------------------------------------
# Production and the candidate grids

def production(function: str, precision: str, fma: bool = True) -> Candidate:
    """The shipped routine, with its polynomial's provenance."""
    from .. import polynomials as P
    poly = {("exp2", "full"): P.EXP2_FULL, ("exp2", "relaxed"): P.EXP2_RELAXED,
            ("log2", "full"): P.LOG2_FULL, ("log2", "relaxed"): P.LOG2_RELAXED}[(function, precision)]
    form = {("exp2", "full"): "rscalef", ("exp2", "relaxed"): "additive",
            ("log2", "full"): "m1mc", ("log2", "relaxed"): "m1m"}[(function, precision)]
    return Candidate(function, precision, form, poly.degree, "", tuple(poly.coefficients), fma,
                     provenance=f"routines.polynomials.{poly.name}: {poly.provenance}",
                     tag="production", production=True,
                     insertion="float" if (function, precision) == ("exp2", "relaxed") and fma
                     else "integer")


def fitted(function, precision, form, degree, shape, fma, **kw) -> Candidate:
    coeffs, _ = fit(function, form, degree, shape)
    return Candidate(function, precision, form, degree, shape, coeffs, fma,
                     provenance=remez_command(function, form, degree, shape), **kw)


#: Coefficients found by ``retune`` in our runs (``python -m routines search
#: ... --retune`` reproduces them from the fitted start; docs/search.md).
#: key: the name of the candidate they were retuned from.
RETUNED: dict[str, tuple[str, ...]] = {
    # exhaustive margin 0.2519 -> 0.2349 (one retune round; a second one made it worse)
    "exp2.full.rscalef.d5.erf2": ("0.00015319258", "0.001339585", "0.009618554", "0.055503443",
                                  "0.24022645", "-0.30685282"),
    # 0.5037 -> 0.4970 (two rounds)
    "exp2.full.rscalefmul.d4.w35": ("0.0013146093", "0.009671387", "0.05551089", "0.24022251",
                                    "0.69314677"),
    # 0.0860 -> 0.0854
    "exp2.relaxed.rscalefmul.d2.erf3": ("0.054769844", "0.24219444", "0.69333684"),
    # 0.3607 -> 0.3560 (one round; a second one made it worse)
    "log2.full.m1mc.d6.abs": ("0.009136402", "-0.014875774", "0.022838062", "-0.041144915",
                              "0.07701328", "-0.15281655", "0.33984995"),
}


def retuned(c: Candidate) -> Candidate | None:
    coeffs = RETUNED.get(c.name)
    if coeffs is None:
        return None
    return c.with_coefficients(coeffs, provenance=f"retuned from {c.name} ({c.provenance}) with "
                                                  "routines.remez.retune against the compiled error")


def grid(function: str, precision: str, quick: bool = False) -> list[Candidate]:
    """The candidates searched for (function, precision), production first."""
    out = [production(function, precision, True), production(function, precision, False)]
    key = (function, precision)
    F = functools.partial(fitted, function, precision)
    if key == ("exp2", "full"):
        shapes = ("abs", "w35", "tent4", "tent3.5", "tent3", "tent2.5", "tent2.2")
        for shape, conv, fma in itertools.product(shapes, ("trunc", "nearest"), (True, False)):
            out.append(F("additive", 4, shape, fma, conversion=conv))
        for shape, conv, fma in itertools.product(("abs", "tent4", "tent3", "tent2.5"),
                                                  ("trunc", "nearest"), (True, False)):
            out.append(F("additive01", 3, shape, fma, conversion=conv))
        for form, deg in (("additive", 4), ("additive01", 3)):
            out.append(F(form, deg, "tent3", True, conversion="nearest", evaluation="estrin"))
        out.append(F("floorsum", 4, "abs", True, conversion="nearest"))
        out.append(F("additive", 4, "tent3", True, conversion="roundeven"))
        out.append(F("additive", 3, "abs", True, conversion="nearest"))      # cheaper: fails
        out.append(F("additive01", 2, "abs", True, conversion="nearest"))
        for form, deg in (("additive", 5), ("additive01", 4)):               # one FMA more
            for shape in ("abs", "tent3"):
                out.append(F(form, deg, shape, True, conversion="nearest"))
        out.append(F("additive01", 4, "tent3", False, conversion="nearest"))
        out.append(F("additive", 6, "abs", True, conversion="nearest"))
        out.append(F("scalef", 4, "abs", True))
        out.append(F("scalef01", 3, "abs", True))
        out.append(F("scalefmul", 4, "abs", True))
        for shape, fma in itertools.product(("abs", "w35", "erf3", "erf2.5", "erf2", "erf1.5"),
                                            (True, False)):
            out.append(F("rscalef", 4, shape, fma))
            out.append(F("rscalefmul", 4, shape, fma))
        out.append(F("rscalef", 3, "erf2", True))                            # cheaper: fails
        for shape in ("abs", "erf2"):
            out.append(F("rscalef", 5, shape, True))
        out.append(F("rscalef", 5, "erf2", False))
        out.append(F("rscalef", 6, "erf2", True))
    elif key == ("exp2", "relaxed"):
        for fma in (True, False):
            for ins in (("float", "integer") if fma else ("integer",)):
                for conv in ("trunc", "nearest"):
                    out.append(F("additive", 2, "abs", fma, conversion=conv, insertion=ins))
                    out.append(F("additive01", 1, "abs", fma, conversion=conv, insertion=ins))
        out.append(F("additive", 1, "abs", True, conversion="nearest", insertion="float"))
        out.append(F("additive01", 0, "abs", True, conversion="nearest", insertion="float"))
        out.append(F("additive", 2, "tent4", True, conversion="trunc", insertion="float"))
        for fma in (True, False):
            out.append(F("scalefmul", 2, "abs", fma))
            for shape in ("abs", "erf3"):
                out.append(F("rscalefmul", 2, shape, fma))
                out.append(F("rscalef", 2, shape, fma))
        out.append(F("rscalefmul", 1, "erf3", True))                         # cheaper: fails
    elif key == ("log2", "full"):
        for fma in (True, False):
            out.append(F("m", 7, "abs", fma))
            out.append(F("m1m", 6, "abs", fma))
            out.append(F("m1m_re", 6, "abs", fma))
        out.append(F("m", 7, "abs", True, evaluation="estrin"))
        out.append(F("m1m", 6, "abs", True, evaluation="estrin"))
        out.append(F("m", 6, "abs", True))          # cheaper: fails
        out.append(F("m1m", 5, "abs", True))        # cheaper: fails
        for fma in (True, False):
            out.append(F("m1mc", 6, "abs", fma))
        out.append(F("m1mc", 6, "abs", True, evaluation="estrin"))
        out.append(F("m1mc", 5, "abs", True))       # cheaper: fails
        for form, deg in (("m", 8), ("m1m", 7), ("m1m_re", 7), ("m1m_re", 8), ("m1mc", 7),
                          ("m1mc", 8)):            # more FMAs
            out.append(F(form, deg, "abs", True))
    elif key == ("log2", "relaxed"):
        for fma in (True, False):
            out.append(F("m", 2, "abs", fma))
            out.append(F("m1m", 1, "abs", fma))
            out.append(F("m1m_re", 1, "abs", fma))
        for fma in (True, False):
            out.append(F("m1mc", 1, "abs", fma))
        out.append(F("m", 1, "abs", True))          # cheaper: fails
        out.append(F("m1m", 0, "abs", True))        # cheaper: fails
    else:
        raise ValueError(f"no candidates for {key}")
    extra = [r for c in out if (r := retuned(c)) is not None]
    out += extra
    if quick:
        out = [c for c in out if _in_quick(c)]
    seen, uniq = set(), []
    for c in out:
        if c.name not in seen:
            seen.add(c.name)
            uniq.append(c)
    return uniq


def _in_quick(c: Candidate) -> bool:
    """--quick keeps the baselines, FMA-on Horner points and the retuned ones."""
    return c.production or (c.fma and c.evaluation == "horner"
                            and c.shape in ("abs", "tent3", "tent4", "w35", "erf3", "erf2", ""))
