"""The precision continuum: variants of exp2, log2 (and so of exp, log and pow), sin, cos, tan,
atan, atan2, asin, acos, sinh, cosh and tanh between the tiers.

Two kinds of variant, both keeping every special value and exact point of full precision:

* **Lower degree.** Full's form (docs/search.md: ``rscalef`` for exp2, ``m1mc`` for log2: the same
  reduction and exact scaling) with a polynomial of lower degree, fitted by our Remez fitter on
  full's interval with full's weight. Each degree removes one FMA.
* **Another reduction: log2 by a table.** The significand is reduced to r = m/c - 1 around the
  nearest of 32 points c (or 8, after folding m around 1), with 1/c and log2(c) read from
  registers (``reactor.Lookup``: one VPERMI2PS with AVX-512, one VPERMPS for 8 points with AVX2),
  so a short polynomial in the small r suffices: ``full-t2`` is as accurate as full with 4 FMAs
  where full takes 8.

``reactor.plan`` tries them at every call site, between ``relaxed`` and ``full``, and keeps the
cheapest whose stored outputs are those of the most accurate build (docs/plan.md); a call may
also ask for one itself: ``routines.exp2(x, precision="full-d3")``.

Names, least accurate first in ``VARIANTS``: ``full-dN`` for exp2, exp, log2 and log (the
polynomial's degree; full itself is d5 for exp2 and d6 for log2); ``full-tN`` (32 points) and
``full-sN`` (8 points) for log2 and log (Q's degree); ``full-eAlB``, ``full-eAtB`` and
``full-eAsB`` for pow (exp2's degree A, then log2's variant); ``full-d6`` for sin, cos and tan
(cos(r) of degree 6, sin(r) of 5, after full's reduction); ``full-d3`` .. ``full-d6`` for atan and
atan2 and ``full-d2``, ``full-d3`` for asin and acos (their polynomial's degree; full: 7 and 4);
``full-d2``, ``full-d3`` for sinh, cosh and tanh (the degree of E in their e^r = 1 + r + r^2 E(r);
full: 4). Each polynomial below states its fit
and the error measured on the compiled routine over a stated domain (``python -m routines
continuum`` measures them all again, with their modelled and timed cost).
"""
from __future__ import annotations

import contextlib
import contextvars
import itertools
import math
import re
import typing

import numpy as np

from reactor import register_variants

from .polynomials import (
    ASIN_FULL, ATAN_FULL, COS_FULL, COS_RELAXED, EXP2_FULL, EXP_FULL, EXP_RELAXED, LOG2_FULL, SIN_FULL, SIN_RELAXED,
    SINH_FULL, SINH_RELAXED, TANH_FULL, TANH_RELAXED, Polynomial, odd_poly,
)


def _fit(name: str, base: Polynomial, coefficients: tuple[str, ...], weighted: str, measured: str) -> Polynomial:
    degree = len(coefficients) - 1
    lo, hi = base.interval
    return Polynomial(
        name=name, function=base.function, weight=base.weight, interval=base.interval, coefficients=coefficients,
        provenance=f"our Remez fitter, degree {degree} on [{lo}, {hi}] with {base.name}'s function and weight "
                   f"(python -m routines remez -d {degree} -r \"{lo}:{hi}\" \"{base.function}\" \"{base.weight}\"), "
                   f"coefficients rounded to float32; max weighted error {weighted}; evaluated in {base.name}'s form",
        measured=measured)


#: exp2's polynomials by degree (5: full's own). Measured: the compiled exp2 (FMA on, AVX-512) on every
#: float32 x with 1/2 <= |x| < 8, in float32 ULP, against float64 NumPy (``python -m routines continuum``;
#: full: 0.92 ULP there).
EXP2_DEGREES: dict[int, Polynomial] = {
    2: _fit("exp2.full.d2", EXP2_FULL, ("5.4773077e-2", "2.4218316e-1", "-3.0666274e-1"), "5.0836426e-5",
            "max 1281 ULP on 1/2 <= |x| < 8 (python -m routines continuum exp2)"),
    3: _fit("exp2.full.d3", EXP2_FULL, ("9.555757e-3", "5.5878803e-2", "2.4024683e-1", "-3.0687028e-1"),
            "1.6370879e-6", "max 41.98 ULP on 1/2 <= |x| < 8 (python -m routines continuum exp2)"),
    4: _fit("exp2.full.d4", EXP2_FULL, ("1.3226039e-3", "9.6706245e-3", "5.550875e-2", "2.402226e-1",
                                        "-3.0685315e-1"), "4.6833616e-8", "max 2.042 ULP on 1/2 <= |x| < 8 (python -m routines continuum exp2)"),
    5: EXP2_FULL,
}

#: log2's polynomials by degree (6: full's own). Measured: the compiled log2 (FMA on, AVX-512) on every
#: float32 x in [1/16, 16), the largest absolute error (log2's error is absolute near its zero) and the
#: ULP where |log2 x| >= 1, against float64 NumPy (``python -m routines continuum``; full: 1.9e-7, 1.07 ULP).
LOG2_DEGREES: dict[int, Polynomial] = {
    2: _fit("log2.full.d2", LOG2_FULL, ("8.2130715e-2", "-1.5692754e-1", "3.397293e-1"), "1.1318551e-4",
            "max 1.134e-4 absolute, 950.2 ULP where |result| >= 1, on [1/16, 16)"),
    3: _fit("log2.full.d3", LOG2_FULL, ("-4.514906e-2", "8.070308e-2", "-1.5261453e-1", "3.3979037e-1"),
            "1.5521274e-5", "max 1.566e-5 absolute, 130.9 ULP where |result| >= 1, on [1/16, 16)"),
    4: _fit("log2.full.d4", LOG2_FULL, ("2.584145e-2", "-4.4273563e-2", "7.677637e-2", "-1.5269805e-1",
                                        "3.3985254e-1"), "2.2162051e-6", "max 2.355e-6 absolute, 19.26 ULP where |result| >= 1, on [1/16, 16)"),
    5: _fit("log2.full.d5", LOG2_FULL, ("-1.5209109e-2", "2.5303092e-2", "-4.107484e-2", "7.685811e-2",
                                        "-1.5281916e-1", "3.3985126e-1"), "3.2546532e-7", "max 4.651e-7 absolute, 3.397 ULP where |result| >= 1, on [1/16, 16)"),
    6: LOG2_FULL,
}

#: sin's and cos's polynomials (in z = r^2, after full's three-part reduction) by degree: sin(r) =
#: r + r^3 P(z), cos(r) = 1 + z Q(z). Full is P of degree 2 (sin of degree 7) and Q of degree 3 (cos of
#: degree 8); degree 1 of each is the fit relaxed uses (its command is the same), here after full's
#: reduction. Measured on the compiled routines (``python -m routines continuum sin cos tan``).
SIN_DEGREES: dict[int, Polynomial] = {1: SIN_RELAXED, 2: SIN_FULL}
COS_DEGREES: dict[int, Polynomial] = {
    1: COS_RELAXED,
    2: Polynomial(
        name="cos.full.d2", function=COS_FULL.function, weight=COS_FULL.weight, interval=COS_FULL.interval,
        coefficients=("-1.3587008e-3", "4.1655507e-2", "-4.9999884e-1"),
        provenance='our Remez fitter: python -m routines remez -d 2 -r "0:0.64" "(cos(sqrt(x))-1)/x" "1/x"; '
                   "cos of degree 6; max weighted error 3.7312605e-8, coefficients rounded to float32",
        measured="with P of degree 1 (full-d6): cos max 1.3732e-6 absolute for 2^-20 <= |x| <= pi "
                 "(python -m routines continuum cos)"),
    3: COS_FULL,
}

#: atan's P (atan(t) = t + t^3 P(t^2), t in [0, 1]; atan2 evaluates the same) by degree (7: full's),
#: and asin's R (asin(v) = v + v^3 R(v^2), v^2 in [0, 1/4]; acos the same) by degree (4: full's),
#: fitted like full's (the command in each provenance). Measured on the compiled routine (FMA on,
#: AVX-512) against float64 NumPy on every float32 of 2^-20 <= |x| <= 4 (atan) or <= 1 (asin, acos),
#: in ULP of the float32 result (full: atan 1.57, asin 2.36, acos 1.13); ``python -m routines
#: continuum atan asin acos`` measures every 7th of them again, with the costs.
ATAN_DEGREES: dict[int, Polynomial] = {
    3: odd_poly("atan.full.d3", "atan", ("0", "1"), ("0.024840286", "-0.09409795", "0.18681417", "-0.33213073"),
                 "max 590.7 ULP (atan)", "weighted error 3.5185166e-5"),
    4: odd_poly("atan.full.d4", "atan", ("0", "1"),
                 ("-0.013955099", "0.05877025", "-0.12251501", "0.19618309", "-0.333089"),
                 "max 77.81 ULP (atan)", "weighted error 5.0023868e-6"),
    5: odd_poly("atan.full.d5", "atan", ("0", "1"),
                 ("0.0081063695", "-0.037796725", "0.08484104", "-0.13544576", "0.19897874", "-0.3332849"),
                 "max 10.64 ULP (atan)", "weighted error 7.3285986e-7"),
    6: odd_poly("atan.full.d6", "atan", ("0", "1"),
                 ("-0.004822535", "0.024734065", "-0.06020313", "0.09968473", "-0.14041328", "0.19974214",
                  "-0.33332393"), "max 2.455 ULP (atan)", "weighted error 1.0971886e-7"),
    7: ATAN_FULL,
}
ASIN_DEGREES: dict[int, Polynomial] = {
    2: odd_poly("asin.full.d2", "asin", ("0", "0.25"), ("0.06410731", "0.071899794", "0.16680126"),
                 "max 32.33 ULP (asin; acos 29.11)", "weighted error 1.740204e-6"),
    3: odd_poly("asin.full.d3", "asin", ("0", "0.25"), ("0.049953125", "0.04003498", "0.075405315", "0.1666558"),
                 "max 3.788 ULP (asin; acos 2.500)", "weighted error 8.8983261e-8"),
    4: ASIN_FULL,
}

#: sinh's, cosh's and tanh's polynomials: e^r = 1 + r + r^2 E(r) of their e^|x|/2 (``exp_half``, by
#: E's degree; 4: full's, 2: the fit relaxed uses, after full's reduction and exact division), and the
#: odd polynomials of small |x| (sinh's for |x| < 1, tanh's for |x| < 0.55; by degree in z = x^2).
#: Each variant's error, measured on the compiled routine, is stated in HYPERBOLIC_VARIANTS.
EXP_HALF_DEGREES: dict[int, Polynomial] = {
    2: EXP_RELAXED,
    3: Polynomial(
        name="exp.full.d3", function=EXP_FULL.function, weight=EXP_FULL.weight, interval=EXP_FULL.interval,
        coefficients=("8.312055e-3", "4.189445e-2", "1.6667134e-1", "4.99992e-1"),
        provenance='our Remez fitter: python -m routines remez -d 3 -r "-0.35:0.35" "(exp(x)-1-x)/x^2" '
                   '"exp(x)/x^2"; max weighted (relative) error 1.1112268e-7, coefficients rounded to float32',
        measured="in sinh, cosh and tanh full-d3: max 2.93, 2.68, 2.04 ULP (HYPERBOLIC_VARIANTS)"),
    4: EXP_FULL,
}
SINH_DEGREES: dict[int, Polynomial] = {1: SINH_RELAXED, 2: SINH_FULL}
TANH_DEGREES: dict[int, Polynomial] = {
    1: TANH_RELAXED,
    2: odd_poly("tanh.full.d2", "tanh", ("0", "0.3025"), ("-4.3099646e-2", "1.3152356e-1", "-3.3324513e-1"),
                "in tanh full-d2 (HYPERBOLIC_VARIANTS)", "weighted error 1.3195134e-6"),
    3: TANH_FULL,
}

#: sinh's, cosh's and tanh's variants: full's form (its reduction and exact division) with E of
#: degree 3 (``full-d3``) or 2 (``full-d2``), sinh's and tanh's small-|x| polynomial one degree lower
#: where that is alike in error (tanh d2: degree 2). Measured on the compiled
#: routines (FMA on, AVX-512) against float64 NumPy, every 7th float32 of 2^-20 <= |x| <= 10, in ULP of
#: the float32 result (``python -m routines continuum sinh cosh tanh``; full: sinh 1.62, cosh 1.34,
#: tanh 1.55): sinh full-d2 80.9, full-d3 2.93; cosh full-d2 73.4, full-d3 2.68; tanh full-d2 36.2, full-d3
#: 2.04 (relaxed: 117, 178, 804). sinh's and tanh's small-|x| polynomials of relaxed's degree would
#: make d2 as inaccurate as relaxed near |x| = 1 at more cost: d2 keeps full's (tanh: degree 2).
HYPERBOLIC_VARIANTS = {
    "sinh": {"full-d2": {"exp_half": 2}, "full-d3": {"exp_half": 3}},
    "cosh": {"full-d2": {"exp_half": 2}, "full-d3": {"exp_half": 3}},
    "tanh": {"full-d2": {"exp_half": 2, "tanh": 2}, "full-d3": {"exp_half": 3}},
}

FULL_DEGREE = {"exp2": max(EXP2_DEGREES), "log2": max(LOG2_DEGREES), "sin": max(SIN_DEGREES),
               "cos": max(COS_DEGREES), "atan": max(ATAN_DEGREES), "asin": max(ASIN_DEGREES),
               "exp_half": max(EXP_HALF_DEGREES), "sinh": max(SINH_DEGREES), "tanh": max(TANH_DEGREES)}
_TABLES = {"exp2": EXP2_DEGREES, "log2": LOG2_DEGREES, "sin": SIN_DEGREES, "cos": COS_DEGREES,
           "atan": ATAN_DEGREES, "asin": ASIN_DEGREES, "exp_half": EXP_HALF_DEGREES, "sinh": SINH_DEGREES,
           "tanh": TANH_DEGREES}

#: sin, cos and tan's variant (each evaluates both polynomials): ``full-d6``, sin(r) of degree 5 and
#: cos(r) of degree 6 (P and Q of degree 1 and 2), after full's reduction. Its errors, measured on the
#: compiled routines (FMA on, AVX-512) against float64 NumPy on every 7th float32 of 2^-20 <= |x| <=
#: pi: sin max 1.3610e-6 absolute, cos 1.3732e-6 absolute, tan 2.269e-6 relative (full: 6.3e-8, 7.3e-8,
#: 2.1e-7). (Degree 1 for both is relaxed's accuracy at more cost than relaxed: not a variant.)
SIN_COS_VARIANTS = {"full-d6": {"sin": 1, "cos": 2}}


# -- another reduction form: log2 by a table of 32 points (``full-tN``) -------------------------
#
# For x = 2^e m, m in [1, 2): i = the top 5 bits of m's fraction, c_i = 1 for i = 0 and the middle
# of [1 + i/32, 1 + (i+1)/32) otherwise, INVC[i] = 1/c_i rounded to float32, LOGC[i] = -log2(INVC[i])
# rounded to float32. Then r = m INVC[i] - 1 (one FMA, rounded once) lies in [-0.0149254, 0.03125],
# and log2 x = (e + LOGC[i]) + r Q(r) with Q ~ log2(1+r)/r. The tables are read from registers
# (``reactor.Lookup``: one VPERMI2PS each with AVX-512), so Q of degree 2 matches full's accuracy
# with 4 FMAs where full's centred form takes 8. c_0 = 1 keeps log2(1) = 0 and log2(2^k) = k exact
# and the error relative near x = 1 (log2(1+r) = r Q(r) there). Specials come from e and m as in
# full's form (Exponent/Significand), so every special value is full's.

LOG2_TABLE_BITS = 5
LOG2_INVC = tuple([1.0] + [float(np.float32(1.0 / (1.0 + (i + 0.5) / 32))) for i in range(1, 32)])
LOG2_LOGC = tuple(float(np.float32(-math.log2(c))) for c in LOG2_INVC)


def _table_fit(degree: int, coefficients: tuple[str, ...], weighted: str, measured: str,
               form: str = "t", interval: tuple[str, str] = ("-0.0149254", "0.03125")) -> Polynomial:
    lo, hi = interval
    points = 32 if form == "t" else 8
    return Polynomial(
        name=f"log2.table.{form}{degree}", function="log2(1+x)/x", weight="log2(1+x)/x",
        interval=interval, coefficients=coefficients,
        provenance=f"our Remez fitter, degree {degree} on [{lo}, {hi}] (the range of r over the {points} "
                   f"table points), relative error (python -m routines remez -d {degree} -r \"{lo}:{hi}\" "
                   f"\"log2(1+x)/x\" \"log2(1+x)/x\"), coefficients rounded to float32; max weighted error "
                   f"{weighted}; evaluated as (e + LOGC[i]) + r Q(r)",
        measured=measured)


# The same with 8 points (``full-sN``), for targets whose register permute holds 8 floats (AVX2's
# VPERMPS): the significand is folded first, z = m or m/2 in [1 - 1/32, 2 - 1/16), so that the point
# c_0 = 1 sits in the middle of its subinterval [1 - 1/32, 1 + 1/16); c_i = 1 + i/8 for i = 1..7.
# With t = bits(m) - bits(1 - 1/32): k = t >> 23 (1 where m >= 2 - 1/16, then z = m/2 and e + 1),
# i = (t >> 20) mod 8, r = z INVC[i] - 1 in [-0.0555556, 0.0625], log2 x = (e + (k + LOGC[i])) + r Q(r)
# (k = 1 only where LOGC[i] = 0, so k + LOGC[i] is exact).

LOG2_FOLD_BITS = 3
LOG2_FOLD_OFFSET = 0x3F780000  # the bits of 1 - 1/32
LOG2_FOLD_INVC = tuple([1.0] + [float(np.float32(1.0 / (1.0 + i / 8))) for i in range(1, 8)])
LOG2_FOLD_LOGC = tuple(float(np.float32(-math.log2(c))) for c in LOG2_FOLD_INVC)


#: Q's of the table form by degree. Measured as LOG2_DEGREES' (``python -m routines continuum``).
LOG2_TABLE_DEGREES: dict[int, Polynomial] = {
    1: _table_fit(1, ("-7.136934e-1", "1.4427903"), "8.7605961e-5", "max 3.9992e-6 absolute, 33.1 ULP where |result| >= 1, on [1/16, 16)"),
    2: _table_fit(2, ("4.7232e-1", "-7.2141945e-1", "1.442696"), "7.5274255e-7", "max 2.6933e-7 absolute, 1.13 ULP where |result| >= 1, on [1/16, 16)"),
    3: _table_fit(3, ("-3.515587e-1", "4.8093793e-1", "-7.2134936e-1", "1.442695"), "6.8981065e-9", "max 2.6391e-7 absolute, 1.111 ULP where |result| >= 1, on [1/16, 16)"),
}

#: Q's of the 8-point folded form by degree (``full-s2``, ``full-s3``).
LOG2_FOLD_DEGREES: dict[int, Polynomial] = {
    2: _table_fit(2, ("4.780931e-1", "-7.222749e-1", "1.442698"), "1.2765044e-5", "max 1.2377e-6 absolute, 9.9 ULP where |result| >= 1, on [1/16, 16)", "s",
                  ("-0.0555556", "0.0625")),
    3: _table_fit(3, ("-3.5768524e-1", "4.818812e-1", "-7.213536e-1", "1.4426947"), "3.0064221e-7",
                  "max 2.6525e-7 absolute, 1.33 ULP where |result| >= 1, on [1/16, 16)",
                  "s", ("-0.0555556", "0.0625")),
}

#: the polynomial kinds each routine's variant names set
_ONE = {"exp2": "exp2", "exp": "exp2", "log2": "log2", "log": "log2", "atan": "atan", "atan2": "atan",
        "asin": "asin", "acos": "asin"}


#: full's own errors on the continuum's domains (the comments of EXP2_DEGREES and LOG2_DEGREES)
_FULL_ERRORS = {EXP2_FULL.name: 0.92, LOG2_FULL.name: 1.9e-7, ATAN_FULL.name: 1.57, ASIN_FULL.name: 2.36}


def _measured(p: Polynomial) -> float:
    """The error a variant's polynomial states first (exp2's in ULP, log2's absolute)."""
    found = re.search(r"max ([0-9.e+-]+)", p.measured)
    return float(found.group(1)) if found else _FULL_ERRORS[p.name]


def _single(kind: str) -> dict[str, dict[str, int]]:
    """exp2's or log2's variants (exp's and log's), least accurate first."""
    names = {f"full-d{d}": (kind, d) for d in sorted(_TABLES[kind]) if d < FULL_DEGREE[kind]}
    if kind == "log2":
        names.update({f"full-t{q}": ("log2t", q) for q in sorted(LOG2_TABLE_DEGREES)})
        names.update({f"full-s{q}": ("log2s", q) for q in sorted(LOG2_FOLD_DEGREES)})
    polys = {**_TABLES, "log2t": LOG2_TABLE_DEGREES, "log2s": LOG2_FOLD_DEGREES}
    ordered = sorted(names.items(), key=lambda item: -_measured(polys[item[1][0]][item[1][1]]))
    return {name: {k: d} for name, (k, d) in ordered}


def _pow() -> dict[str, dict[str, int]]:
    """pow's variants, least accurate first by the error their halves state (exp2's ULP as a
    relative error, log2's absolute error times ln 2: its share of the result's relative error at
    |y| = 1)."""
    # log2's degree b from exp2's a to a + 2: their errors in pow's result are alike there (an
    # unbalanced pair costs for accuracy its weaker half throws away), and planning stays in time
    names: dict[str, tuple[int, str, int]] = {}
    for a, b in itertools.product(sorted(EXP2_DEGREES), sorted(LOG2_DEGREES)):
        if 0 <= b - a <= 2 and (a, b) != (FULL_DEGREE["exp2"], FULL_DEGREE["log2"]):
            names[f"full-e{a}l{b}"] = (a, "log2", b)
    for a in (3, 4, 5):  # log2 by a table: Q of degree 1 or 2 (32 points), 2 or 3 (8 points)
        names.update({f"full-e{a}t{q}": (a, "log2t", q) for q in (1, 2)})
        names.update({f"full-e{a}s{q}": (a, "log2s", q) for q in (2, 3)})
    logs = {"log2": LOG2_DEGREES, "log2t": LOG2_TABLE_DEGREES, "log2s": LOG2_FOLD_DEGREES}

    def error(item) -> float:
        a, kind, b = item[1]
        return _measured(EXP2_DEGREES[a]) * 2.0 ** -24 + _measured(logs[kind][b]) * math.log(2)
    return {name: {"exp2": a, kind: b} for name, (a, kind, b) in sorted(names.items(), key=error, reverse=True)}


#: every routine's variants: name -> {polynomial kind: degree}, cheapest first
VARIANTS: dict[str, dict[str, dict[str, int]]] = {**{r: _single(k) for r, k in _ONE.items()}, "pow": _pow(),
                                                  **{r: dict(SIN_COS_VARIANTS) for r in ("sin", "cos", "tan")},
                                                  **HYPERBOLIC_VARIANTS}
for _routine, _names in VARIANTS.items():
    register_variants(_routine, _names)

_current: contextvars.ContextVar[dict[str, int]] = contextvars.ContextVar("routines_continuum", default={})


@contextlib.contextmanager
def using(routine: str, variant: str | None) -> typing.Iterator[None]:
    """Emit the block with ``routine``'s ``variant`` (``"full-d3"``; None: the tier's own
    polynomials) in force for the polynomials it sets, nested routines (pow's exp2 and log2)
    included."""
    if variant is None:
        yield
        return
    token = _current.set({**_current.get(), **VARIANTS[routine][variant]})
    try:
        yield
    finally:
        _current.reset(token)


def polynomial(kind: str) -> Polynomial:
    """The polynomial of kind ``"exp2"`` or ``"log2"`` that full precision evaluates here: full's
    own, or the degree the variant in force asks for."""
    table = _TABLES[kind]
    return table[_current.get().get(kind, FULL_DEGREE[kind])]


def log2_table() -> tuple[str, Polynomial] | None:
    """Log2's table form where a variant in force asks for it: ("t", Q) for the 32 points
    (``full-t2``, pow's ``full-e4t2``), ("s", Q) for the 8 folded ones (``full-s3``); None: full's
    centred form."""
    now = _current.get()
    if "log2t" in now:
        return "t", LOG2_TABLE_DEGREES[now["log2t"]]
    if "log2s" in now:
        return "s", LOG2_FOLD_DEGREES[now["log2s"]]
    return None


# -- ranges a plan proved: the special-case paths a call site can drop ---------------------------

class Span(typing.NamedTuple):
    """An operand's values at a call site: [lo, hi] and whether a NaN comes."""

    lo: float
    hi: float
    nan: bool

    def within(self, lo: float, hi: float) -> bool:
        """No NaN, and every value in [lo, hi]."""
        return not self.nan and lo <= self.lo and self.hi <= hi


_spans: contextvars.ContextVar[tuple[str, tuple[Span, ...]] | None] = \
    contextvars.ContextVar("routines_spans", default=None)


@contextlib.contextmanager
def operand_ranges(routine: str, spans) -> typing.Iterator[None]:
    """Emit the block knowing that ``routine``'s operands lie in ``spans`` ((lo, hi, nan) each; a
    plan's ``Site.ranges``, proved on an exhaustive domain). Only a call of ``routine`` reads them:
    a routine that calls another states that one's ranges itself (pow: log2's and exp2's)."""
    token = _spans.set((routine, tuple(Span(*s) for s in spans)) if spans else None)
    try:
        yield
    finally:
        _spans.reset(token)


def operand_range(routine: str, k: int = 0) -> Span | None:
    """The range of operand ``k`` of the ``routine`` being emitted, where a plan proved one."""
    known = _spans.get()
    if known is None or known[0] != routine or k >= len(known[1]):
        return None
    return known[1][k]


def scaled(span: Span | None, factor: float) -> tuple[Span, ...] | None:
    """``span`` times the constant ``factor`` (exp's x log2(e)), as operand_ranges takes it."""
    if span is None or not math.isfinite(factor):
        return None
    ends = sorted((span.lo * factor, span.hi * factor))
    return None if any(math.isnan(e) for e in ends) else (Span(ends[0], ends[1], span.nan),)


def product_of_log2(x: Span | None, y: Span | None) -> tuple[Span, ...] | None:
    """The range of y * log2(x) (pow's exponent), where both are known and it is defined."""
    if x is None or y is None or x.lo < 0 or math.isnan(x.lo):
        return None
    lx = [math.log2(v) if v > 0 else -math.inf for v in (x.lo, x.hi)]
    ends = [a * b for a in lx for b in (y.lo, y.hi)]
    if any(math.isnan(e) for e in ends):  # 0 * inf
        return None
    return (Span(min(ends), max(ends), x.nan or y.nan),)
