"""The special-value contract of every routine, as data.

``ROWS`` lists single inputs with their exact expected result (bit-exact,
including the sign of zero; NaN means any NaN). ``RULES`` are exactness
families (exp2(k) = 2^k for every integer k with a normal result, ...). Both
hold in both precisions, with FMA on and off, at every width; the test suite
checks them on the compiled kernels, and ``python -m routines specials``
prints them as the tables of docs/specials.md.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from .base import PRECISIONS

INF, NAN = float("inf"), float("nan")
TINY = float(np.float32(1e-40))  # a subnormal
MIN_NORMAL = 2.0 ** -126
MAX_FLOAT = float(np.finfo(np.float32).max)
BOTH = PRECISIONS
ACCURATE = ("faithful", "correct")  # C99 Annex F / IEEE 754 (routines/accurate.py)


@dataclasses.dataclass(frozen=True)
class Row:
    function: str
    args: tuple[float, ...]
    expected: float
    case: str
    precisions: tuple[str, ...] = BOTH


NOTES = {
    "exp2": "Full precision reduces to the nearest integer (f = x - round(x), exact) and scales "
            "like VSCALEFPS: subnormal results are rounded, never flushed. Relaxed precision reduces "
            "to floor(x): negative inputs closer to 0 than about 2^-25 reduce to f = 1 - 2^-24 with "
            "floor(x) = -1 (the reference discusses this wrap-around), within its tolerance, and "
            "results below 2^-126 are flushed to +0. Both are monotone and never negative.",
    "exp": "exp(x) = exp2(x * log2(e)): thresholds follow from exp2's.",
    "log2": "Subnormal inputs are exact in both precisions (exponent extraction normalizes them).",
    "pow": "relaxed and full: IEEE 754 powr semantics (what GLSL's pow means), from exp2(y * log2(x)) "
           "with no extra code. faithful and correct: C99 Annex F pow (what NumPy's power and C's powf give): "
           "pow(x, +-0) = 1 and pow(1, y) = 1 even for NaN, a negative base to an integer power is "
           "signed, to a non-integer power NaN.",
    "rcp": "|x| > 2^126 gives the correctly rounded subnormal 1/x (RCP14 does not flush).",
    "sin": "Vulkan bounds sin only inside [-pi, pi]; the routine reduces every finite argument "
           "exactly (Payne-Hanek above 2^17), so it stays accurate far outside (the accuracy lab "
           "reports the error there separately).",
    "cos": "cos(x) = 1 exactly for |x| <= 2^-12; cos(fl(pi/2)) = -4.371139e-8, the float32 of the "
           "exact value.",
    "atan2": "C99/IEEE 754 special cases, y first: atan2(y, x). The sign of a zero x is read from its "
             "sign bit, so -0 counts as negative (atan2(+-0, -0) = +-pi).",
    "sinh": "sinh and cosh overflow where e^|x|/2 does (|x| > 89.4159851), not where e^|x| does "
            "(88.7228391): the exponential is scaled by 2^(k-1) in one step.",
    "tanh": "tanh(x) rounds to +-1 for |x| > 9.0109; no result is above 1 in magnitude.",
}


def _f32(v: float) -> float:
    return float(np.float32(v))


def _exp_rows():
    rows = []
    for fn in ("exp2", "exp"):
        rows += [
            Row(fn, (0.0,), 1.0, "+0"), Row(fn, (-0.0,), 1.0, "-0"),
            Row(fn, (INF,), INF, "+inf"), Row(fn, (-INF,), 0.0, "-inf (+0, never -0)"),
            Row(fn, (NAN,), NAN, "NaN"), Row(fn, (TINY,), 1.0, "subnormal input"),
            Row(fn, (1000.0,), INF, "far above overflow"), Row(fn, (-1000.0,), 0.0, "far below underflow"),
        ]
    rows += [
        Row("exp2", (-1.0,), 0.5, "negative input"),
        Row("exp2", (128.0,), INF, "overflow threshold: x >= 128"),
        Row("exp2", (-126.0,), MIN_NORMAL, "smallest normal result"),
        Row("exp2", (_f32(-126.0001),), 0.0, "below -126: flushed to +0", ("relaxed",)),
        Row("exp2", (-149.0,), 0.0, "subnormal result 2^-149: flushed to +0", ("relaxed",)),
        Row("exp2", (-149.0,), 2.0 ** -149, "subnormal result 2^-149: not flushed", ("full",)),
        Row("exp2", (-150.0,), 0.0, "2^-150: halfway, ties to even give +0", ("full",)),
        Row("exp2", (-126.5,), _f32(_f32(2.0 ** 0.5) * 2.0 ** -127), "subnormal result, rounded once", ("full",)),
        Row("exp", (89.0,), INF, "overflow: x > 88.7228 (ln FLT_MAX)"),
        Row("exp", (-88.0,), 0.0, "below -87.3365 (ln 2^-126): flushed to +0", ("relaxed",)),
        Row("exp", (-110.0,), 0.0, "below -103.97 (2^-150): +0", ("full",)),
    ]
    return rows


def _log_rows():
    rows = []
    for fn in ("log2", "log"):
        rows += [
            Row(fn, (0.0,), -INF, "+0"), Row(fn, (-0.0,), -INF, "-0"),
            Row(fn, (INF,), INF, "+inf"), Row(fn, (-INF,), NAN, "-inf"),
            Row(fn, (NAN,), NAN, "NaN"), Row(fn, (-1.0,), NAN, "negative input"),
            Row(fn, (-TINY,), NAN, "negative subnormal"), Row(fn, (1.0,), 0.0, "log(1) = +0 exactly"),
        ]
    rows += [
        Row("log2", (2.0 ** -149,), -149.0, "smallest subnormal: exact"),
        Row("log2", (2.0 ** -130,), -130.0, "subnormal power of two: exact"),
        Row("log2", (MAX_FLOAT,), 128.0, "largest float: rounds to 128", ("full",)),
    ]
    return rows


def _pow_rows():
    r = []
    for x in (0.0, -0.0):
        z = "+0" if x == 0 and np.signbit(x) == 0 else "-0"
        r += [Row("pow", (x, 2.0), 0.0, f"{z} ^ y>0 = +0"), Row("pow", (x, -2.0), INF, f"{z} ^ y<0 = +inf"),
              Row("pow", (x, 0.0), NAN, f"{z} ^ 0 = NaN"), Row("pow", (x, INF), 0.0, f"{z} ^ +inf = +0"),
              Row("pow", (x, -INF), INF, f"{z} ^ -inf = +inf")]
    r += [
        Row("pow", (INF, 2.0), INF, "+inf ^ y>0 = +inf"), Row("pow", (INF, -2.0), 0.0, "+inf ^ y<0 = +0"),
        Row("pow", (INF, 0.0), NAN, "+inf ^ 0 = NaN"), Row("pow", (INF, INF), INF, "+inf ^ +inf = +inf"),
        Row("pow", (INF, -INF), 0.0, "+inf ^ -inf = +0"),
        Row("pow", (1.0, 5.5), 1.0, "1 ^ finite = 1"), Row("pow", (1.0, INF), NAN, "1 ^ +inf = NaN"),
        Row("pow", (1.0, -INF), NAN, "1 ^ -inf = NaN"), Row("pow", (1.0, NAN), NAN, "1 ^ NaN = NaN (powr)"),
        Row("pow", (3.0, 0.0), 1.0, "x ^ +0 = 1"), Row("pow", (3.0, -0.0), 1.0, "x ^ -0 = 1"),
        Row("pow", (NAN, 0.0), NAN, "NaN ^ 0 = NaN (powr)"), Row("pow", (NAN, 1.0), NAN, "NaN ^ y"),
        Row("pow", (2.0, NAN), NAN, "x ^ NaN"),
        Row("pow", (-2.0, 2.0), NAN, "x < 0: NaN"), Row("pow", (-INF, 2.0), NAN, "-inf ^ y: NaN"),
        Row("pow", (0.5, INF), 0.0, "x in (0,1) ^ +inf = +0"), Row("pow", (0.5, -INF), INF, "x in (0,1) ^ -inf = +inf"),
        Row("pow", (2.0, INF), INF, "x > 1 ^ +inf = +inf"), Row("pow", (2.0, -INF), 0.0, "x > 1 ^ -inf = +0"),
        Row("pow", (2.0, 10.0), 1024.0, "2 ^ integer: exact"), Row("pow", (2.0, 200.0), INF, "overflow"),
        Row("pow", (2.0, -200.0), 0.0, "underflow: +0"),
    ]
    return r


def _recip_rows():
    r = []
    r += [Row("rcp", (0.0,), INF, "+0"), Row("rcp", (-0.0,), -INF, "-0"), Row("rcp", (INF,), 0.0, "+inf"),
          Row("rcp", (-INF,), -0.0, "-inf"), Row("rcp", (NAN,), NAN, "NaN"), Row("rcp", (-4.0,), -0.25, "negative"),
          Row("rcp", (TINY,), INF, "subnormal: 1/x overflows"), Row("rcp", (1.0,), 1.0, "1")]
    r += [Row("rsqrt", (0.0,), INF, "+0"), Row("rsqrt", (-0.0,), -INF, "-0"), Row("rsqrt", (INF,), 0.0, "+inf"),
          Row("rsqrt", (-INF,), NAN, "-inf"), Row("rsqrt", (NAN,), NAN, "NaN"), Row("rsqrt", (-4.0,), NAN, "negative"),
          Row("rsqrt", (1.0,), 1.0, "1"), Row("rsqrt", (4.0,), 0.5, "4")]
    r += [Row("sqrt", (0.0,), 0.0, "+0"), Row("sqrt", (-0.0,), -0.0, "-0"), Row("sqrt", (INF,), INF, "+inf"),
          Row("sqrt", (-INF,), NAN, "-inf"), Row("sqrt", (NAN,), NAN, "NaN"), Row("sqrt", (-4.0,), NAN, "negative"),
          Row("sqrt", (4.0,), 2.0, "4"), Row("sqrt", (1.0,), 1.0, "1"),
          Row("sqrt", (2.0 ** -148,), 2.0 ** -74, "subnormal input: exact", ("full",))]
    # IEEE operations in the faithful and correct tiers: the same rows hold there
    return [dataclasses.replace(row, precisions=row.precisions + ACCURATE) if row.precisions == BOTH else row
            for row in r] + [Row("sqrt", (2.0 ** -148,), 2.0 ** -74, "subnormal input: exact", ACCURATE)]


PIO2 = _f32(np.pi / 2)
PI32 = _f32(np.pi)
ONE_UP = float(np.nextafter(np.float32(1), np.float32(2)))  # 1 + 2^-23


def _trig_rows():
    """sin ... tanh, atan2: the same rows hold in every tier (C99 Annex F agrees with GLSL's here),
    but for the full tier's own (``("full",)``), which hold in the accurate tiers too."""
    r = []
    for fn in ("sin", "tan"):
        r += [Row(fn, (0.0,), 0.0, "+0"), Row(fn, (-0.0,), -0.0, "-0"), Row(fn, (INF,), NAN, "+inf"),
              Row(fn, (-INF,), NAN, "-inf"), Row(fn, (NAN,), NAN, "NaN"),
              Row(fn, (TINY,), TINY, "subnormal: x"), Row(fn, (-TINY,), -TINY, "negative subnormal: x"),
              Row(fn, (1e-20,), _f32(1e-20), "tiny: x")]
    r += [Row("cos", (0.0,), 1.0, "+0"), Row("cos", (-0.0,), 1.0, "-0"), Row("cos", (INF,), NAN, "+inf"),
          Row("cos", (-INF,), NAN, "-inf"), Row("cos", (NAN,), NAN, "NaN"),
          Row("cos", (TINY,), 1.0, "subnormal: 1"), Row("cos", (-1e-20,), 1.0, "tiny: 1"),
          Row("cos", (PIO2,), _f32(np.cos(np.float64(PIO2))), "fl(pi/2): -4.371139e-8"),
          Row("sin", (PIO2,), 1.0, "fl(pi/2): 1"), Row("sin", (3e38,), _f32(np.sin(np.float64(_f32(3e38)))),
                                                        "3e38: Payne-Hanek reduction", ("full",) + ACCURATE)]
    for fn in ("asin", "acos"):
        r += [Row(fn, (ONE_UP,), NAN, "1 + 2^-23: NaN"), Row(fn, (-ONE_UP,), NAN, "-(1 + 2^-23): NaN"),
              Row(fn, (2.0,), NAN, "|x| > 1: NaN"), Row(fn, (INF,), NAN, "+inf"), Row(fn, (-INF,), NAN, "-inf"),
              Row(fn, (NAN,), NAN, "NaN")]
    r += [Row("asin", (0.0,), 0.0, "+0"), Row("asin", (-0.0,), -0.0, "-0"), Row("asin", (1.0,), PIO2, "1: pi/2"),
          Row("asin", (-1.0,), -PIO2, "-1: -pi/2"), Row("asin", (TINY,), TINY, "subnormal: x"),
          Row("acos", (0.0,), PIO2, "+0: pi/2"), Row("acos", (-0.0,), PIO2, "-0: pi/2"),
          Row("acos", (1.0,), 0.0, "1: +0"), Row("acos", (-1.0,), PI32, "-1: pi"),
          Row("acos", (TINY,), PIO2, "subnormal: pi/2")]
    r += [Row("atan", (0.0,), 0.0, "+0"), Row("atan", (-0.0,), -0.0, "-0"), Row("atan", (INF,), PIO2, "+inf: pi/2"),
          Row("atan", (-INF,), -PIO2, "-inf: -pi/2"), Row("atan", (NAN,), NAN, "NaN"),
          Row("atan", (TINY,), TINY, "subnormal: x"), Row("atan", (1e30,), PIO2, "huge: pi/2"),
          Row("atan", (-1e30,), -PIO2, "-huge: -pi/2")]
    a = "atan2"
    r += [Row(a, (0.0, 0.0), 0.0, "(+0, +0) = +0"), Row(a, (-0.0, 0.0), -0.0, "(-0, +0) = -0"),
          Row(a, (0.0, -0.0), PI32, "(+0, -0) = +pi"), Row(a, (-0.0, -0.0), -PI32, "(-0, -0) = -pi"),
          Row(a, (0.0, -3.0), PI32, "(+0, x<0) = +pi"), Row(a, (-0.0, -3.0), -PI32, "(-0, x<0) = -pi"),
          Row(a, (0.0, 3.0), 0.0, "(+0, x>0) = +0"), Row(a, (-0.0, 3.0), -0.0, "(-0, x>0) = -0"),
          Row(a, (2.0, 0.0), PIO2, "(y>0, +0) = pi/2"), Row(a, (2.0, -0.0), PIO2, "(y>0, -0) = pi/2"),
          Row(a, (-2.0, 0.0), -PIO2, "(y<0, +0) = -pi/2"), Row(a, (-2.0, -0.0), -PIO2, "(y<0, -0) = -pi/2"),
          Row(a, (2.0, -INF), PI32, "(y>0, -inf) = +pi"), Row(a, (-2.0, -INF), -PI32, "(y<0, -inf) = -pi"),
          Row(a, (2.0, INF), 0.0, "(y>0, +inf) = +0"), Row(a, (-2.0, INF), -0.0, "(y<0, +inf) = -0"),
          Row(a, (INF, 5.0), PIO2, "(+inf, x) = pi/2"), Row(a, (-INF, -5.0), -PIO2, "(-inf, x) = -pi/2"),
          Row(a, (INF, INF), _f32(np.pi / 4), "(+inf, +inf) = pi/4"),
          Row(a, (-INF, INF), -_f32(np.pi / 4), "(-inf, +inf) = -pi/4"),
          Row(a, (INF, -INF), _f32(3 * np.pi / 4), "(+inf, -inf) = 3pi/4"),
          Row(a, (-INF, -INF), -_f32(3 * np.pi / 4), "(-inf, -inf) = -3pi/4"),
          Row(a, (NAN, 1.0), NAN, "(NaN, x) = NaN"), Row(a, (1.0, NAN), NAN, "(y, NaN) = NaN"),
          Row(a, (NAN, INF), NAN, "(NaN, inf) = NaN"), Row(a, (0.0, NAN), NAN, "(0, NaN) = NaN"),
          Row(a, (TINY, 1e30), 0.0, "underflow of y/x: +0"),
          Row(a, (1e30, TINY), PIO2, "overflow of y/x: pi/2"),
          Row(a, (MAX_FLOAT, MAX_FLOAT), _f32(np.pi / 4), "FLT_MAX on the diagonal: pi/4", ("full",) + ACCURATE)]
    for fn in ("sinh", "tanh"):
        r += [Row(fn, (0.0,), 0.0, "+0"), Row(fn, (-0.0,), -0.0, "-0"), Row(fn, (NAN,), NAN, "NaN"),
              Row(fn, (TINY,), TINY, "subnormal: x"), Row(fn, (-1e-20,), -_f32(1e-20), "tiny: x")]
    r += [Row("sinh", (INF,), INF, "+inf"), Row("sinh", (-INF,), -INF, "-inf"),
          Row("sinh", (89.5,), INF, "overflow: x > 89.4159851"), Row("sinh", (-89.5,), -INF, "x < -89.4159851"),
          Row("sinh", (1000.0,), INF, "far above overflow"),
          Row("cosh", (0.0,), 1.0, "+0"), Row("cosh", (-0.0,), 1.0, "-0"), Row("cosh", (INF,), INF, "+inf"),
          Row("cosh", (-INF,), INF, "-inf"), Row("cosh", (NAN,), NAN, "NaN"), Row("cosh", (TINY,), 1.0, "subnormal: 1"),
          Row("cosh", (89.5,), INF, "overflow: |x| > 89.4159851"), Row("cosh", (-89.5,), INF, "-89.5: +inf"),
          Row("tanh", (INF,), 1.0, "+inf: 1"), Row("tanh", (-INF,), -1.0, "-inf: -1"),
          Row("tanh", (10.0,), 1.0, "10: 1"), Row("tanh", (-1000.0,), -1.0, "-1000: -1")]
    return [dataclasses.replace(row, precisions=row.precisions + ACCURATE) if row.precisions == BOTH else row
            for row in r]


def _accurate_rows():
    """The faithful and correct tiers: C99 Annex F, subnormal results rounded, never flushed."""
    a, sub = ACCURATE, float(2.0 ** -149)
    r = []
    for fn in ("exp2", "exp"):
        r += [Row(fn, (0.0,), 1.0, "+0", a), Row(fn, (-0.0,), 1.0, "-0", a), Row(fn, (INF,), INF, "+inf", a),
              Row(fn, (-INF,), 0.0, "-inf: +0", a), Row(fn, (NAN,), NAN, "NaN", a),
              Row(fn, (TINY,), 1.0, "subnormal input", a), Row(fn, (1000.0,), INF, "far above overflow", a),
              Row(fn, (-1000.0,), 0.0, "far below underflow", a)]
    r += [Row("exp2", (-149.0,), sub, "2^-149: the least subnormal, not flushed", a),
          Row("exp2", (-149.5,), sub, "2^-149.5 rounds up to 2^-149", a),
          Row("exp2", (-150.0,), 0.0, "2^-150: halfway, ties to even give +0", a),
          Row("exp2", (-126.5,), _f32(2.0 ** -126.5), "subnormal result, correctly rounded", a),
          Row("exp2", (128.0,), INF, "overflow threshold: x >= 128", a),
          Row("exp2", (_f32(127.99999),), _f32(2.0 ** float(np.float32(127.99999))), "just below overflow", a),
          Row("exp", (88.72283935546875,), INF, "overflow: the least x with exp(x) >= FLT_MAX + ulp/2", a),
          Row("exp", (88.72283172607422,), _f32(np.exp(88.72283172607422)), "largest finite result", a),
          Row("exp", (-103.97208404541016,), 0.0, "the greatest x rounding to +0", a),
          Row("exp", (-103.97207641601562,), sub, "the least x rounding to 2^-149", a)]
    for fn in ("log2", "log"):
        r += [Row(fn, (0.0,), -INF, "+0: -inf", a), Row(fn, (-0.0,), -INF, "-0: -inf", a),
              Row(fn, (INF,), INF, "+inf", a), Row(fn, (-INF,), NAN, "-inf: NaN", a), Row(fn, (NAN,), NAN, "NaN", a),
              Row(fn, (-1.0,), NAN, "x < 0: NaN", a), Row(fn, (1.0,), 0.0, "1: +0", a)]
    r += [Row("log2", (sub,), -149.0, "least subnormal: -149", a),
          Row("log", (sub,), _f32(np.log(sub)), "least subnormal", a)]
    f = ACCURATE
    r += [Row("pow", (NAN, 0.0), 1.0, "NaN ^ +0 = 1", f), Row("pow", (INF, -0.0), 1.0, "+inf ^ -0 = 1", f),
          Row("pow", (0.0, 0.0), 1.0, "+0 ^ +0 = 1", f), Row("pow", (-3.0, 0.0), 1.0, "x ^ 0 = 1", f),
          Row("pow", (1.0, NAN), 1.0, "1 ^ NaN = 1", f), Row("pow", (1.0, INF), 1.0, "1 ^ inf = 1", f),
          Row("pow", (-1.0, INF), 1.0, "-1 ^ +inf = 1", f), Row("pow", (-1.0, -INF), 1.0, "-1 ^ -inf = 1", f),
          Row("pow", (0.0, -3.0), INF, "+0 ^ odd y<0 = +inf", f), Row("pow", (-0.0, -3.0), -INF, "-0 ^ odd y<0 = -inf", f),
          Row("pow", (-0.0, -2.0), INF, "-0 ^ even y<0 = +inf", f), Row("pow", (-0.0, -INF), INF, "-0 ^ -inf = +inf", f),
          Row("pow", (-0.0, 3.0), -0.0, "-0 ^ odd y>0 = -0", f), Row("pow", (-0.0, 2.0), 0.0, "-0 ^ even y>0 = +0", f),
          Row("pow", (0.5, INF), 0.0, "|x| < 1 ^ +inf = +0", f), Row("pow", (-0.5, -INF), INF, "|x| < 1 ^ -inf = +inf", f),
          Row("pow", (-2.0, INF), INF, "|x| > 1 ^ +inf = +inf", f), Row("pow", (2.0, -INF), 0.0, "|x| > 1 ^ -inf = +0", f),
          Row("pow", (-8.0, 3.0), -512.0, "negative base, odd power: -512", f),
          Row("pow", (-2.0, 2.0), 4.0, "negative base, even power", f),
          Row("pow", (-2.0, 0.5), NAN, "negative base, non-integer power: NaN", f),
          Row("pow", (-INF, 3.0), -INF, "-inf ^ odd y>0 = -inf", f), Row("pow", (-INF, -3.0), -0.0, "-inf ^ odd y<0 = -0", f),
          Row("pow", (-INF, 2.0), INF, "-inf ^ even y>0 = +inf", f), Row("pow", (-INF, -0.5), 0.0, "-inf ^ y<0 = +0", f),
          Row("pow", (INF, -1.0), 0.0, "+inf ^ y<0 = +0", f), Row("pow", (INF, 0.5), INF, "+inf ^ y>0 = +inf", f),
          Row("pow", (NAN, 1.0), NAN, "NaN ^ y = NaN", f), Row("pow", (2.0, NAN), NAN, "x ^ NaN = NaN", f),
          Row("pow", (2.0, -149.0), sub, "2 ^ -149: subnormal, not flushed", f),
          Row("pow", (4.0, 0.5), 2.0, "4 ^ 0.5 = 2 exactly", f), Row("pow", (2.0, 128.0), INF, "overflow", f)]
    return r


ROWS: tuple[Row, ...] = tuple(_exp_rows() + _log_rows() + _pow_rows() + _recip_rows() + _trig_rows()
                              + _accurate_rows())


@dataclasses.dataclass(frozen=True)
class Rule:
    """An exactness family: ``inputs()`` -> (args..., expected) arrays."""

    function: str
    text: str
    inputs: object
    precisions: tuple[str, ...] = BOTH


def _exp2_integers():
    k = np.arange(-126, 128, dtype=np.float32)
    return (k,), np.exp2(k.astype(np.float64)).astype(np.float32)


def _exp2_all_integers():
    k = np.arange(-149, 128, dtype=np.float32)
    return (k,), np.exp2(k.astype(np.float64)).astype(np.float32)


def _pow_two_all_integers():
    y = np.arange(-149, 128, dtype=np.float32)
    return (np.full_like(y, 2.0), y), np.exp2(y.astype(np.float64)).astype(np.float32)


def _log2_powers():
    k = np.arange(-149, 128)
    x = np.ldexp(np.float64(1.0), k).astype(np.float32)
    return (x,), k.astype(np.float32)


def _pow_two_integers():
    y = np.arange(-126, 128, dtype=np.float32)
    return (np.full_like(y, 2.0), y), np.exp2(y.astype(np.float64)).astype(np.float32)


def _rcp_powers():
    k = np.arange(-126, 127)
    x = np.ldexp(np.float64(1.0), k).astype(np.float32)
    return (x,), np.ldexp(np.float64(1.0), -k).astype(np.float32)


def _rsqrt_powers():
    k = np.arange(-63, 64)
    x = np.ldexp(np.float64(1.0), 2 * k).astype(np.float32)
    return (x,), np.ldexp(np.float64(1.0), -k).astype(np.float32)


def _tiny_grid():
    """Every power of two from 2^-149 to 2^-12, and 64 random significands per binade above 2^-126."""
    rng = np.random.default_rng(0)
    k = np.arange(-126, -12)
    x = np.ldexp(1.0 + rng.random((k.size, 64)), k[:, None]).ravel()
    x = np.concatenate([np.ldexp(1.0, np.arange(-149, -11)), x]).astype(np.float32)
    x = np.concatenate([x, -x])
    return x[np.abs(x) <= 2.0 ** -12]


def _identity_near_zero():
    x = _tiny_grid()
    return (x,), x


def _one_near_zero():
    x = _tiny_grid()
    return (x,), np.ones_like(x)


RULES: tuple[Rule, ...] = (
    Rule("exp2", "exp2(k) = 2^k exactly for every integer k in [-126, 127]", _exp2_integers),
    Rule("exp2", "exp2(k) = 2^k exactly for every integer k in [-149, 127] (subnormal results included)",
         _exp2_all_integers, ("full",) + ACCURATE),
    Rule("log2", "log2(2^k) = k exactly for every k in [-149, 127] (subnormals included)", _log2_powers,
         BOTH + ACCURATE),
    Rule("pow", "pow(2, k) = 2^k exactly for every integer k in [-126, 127]", _pow_two_integers),
    Rule("pow", "pow(2, k) = 2^k exactly for every integer k in [-149, 127] (subnormal results included)",
         _pow_two_all_integers, ACCURATE),
    Rule("rcp", "rcp(2^k) = 2^-k exactly for k in [-126, 126]", _rcp_powers, BOTH + ACCURATE),
    Rule("rsqrt", "rsqrt(4^k) = 2^-k exactly for k in [-63, 63]", _rsqrt_powers, BOTH + ACCURATE),
    *(Rule(fn, f"{fn}(x) = x exactly for 0 < |x| <= 2^-12 (subnormals included)", _identity_near_zero,
           BOTH + ACCURATE) for fn in ("sin", "tan", "asin", "atan", "sinh", "tanh")),
    Rule("cos", "cos(x) = 1 exactly for 0 < |x| <= 2^-12 (subnormals included)", _one_near_zero, BOTH + ACCURATE),
    Rule("cosh", "cosh(x) = 1 exactly for 0 < |x| <= 2^-12 (subnormals included; relaxed: within "
                 "RCP14's 2^-14 of 1)", _one_near_zero, ("full",) + ACCURATE),
)


def same(got: np.ndarray, expected: np.ndarray) -> np.ndarray:
    """Bit-exact equality, except that any NaN matches any NaN."""
    got, expected = np.asarray(got, np.float32), np.asarray(expected, np.float32)
    both_nan = np.isnan(got) & np.isnan(expected)
    return both_nan | (got.view(np.uint32) == expected.view(np.uint32))


def _fmt(v: float) -> str:
    if np.isnan(v):
        return "NaN"
    if np.isinf(v):
        return "+inf" if v > 0 else "-inf"
    if v == 0:
        return "-0" if np.signbit(v) else "+0"
    return np.format_float_positional(np.float32(v), unique=True, trim="-") if 1e-4 < abs(v) < 1e7 \
        else np.format_float_scientific(np.float32(v), unique=True)


def markdown() -> str:
    """The tables of docs/specials.md, one per function."""
    out = []
    for fn in ("exp2", "exp", "log2", "log", "pow", "rcp", "rsqrt", "sqrt",
               "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh"):
        out.append(f"### {fn}\n")
        out.append("| input | result | case | precisions |\n|---|---|---|---|")
        for row in (r for r in ROWS if r.function == fn):
            args = ", ".join(_fmt(a) for a in row.args)
            out.append(f"| {fn}({args}) | {_fmt(row.expected)} | {row.case} | {', '.join(row.precisions)} |")
        for rule in (r for r in RULES if r.function == fn):
            out.append(f"\nExactness: {rule.text} ({', '.join(rule.precisions)}).")
        if fn in NOTES:
            out.append(f"\n{NOTES[fn]}")
        out.append("")
    return "\n".join(out)
