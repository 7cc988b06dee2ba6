"""The faithful and correct tiers of exp2, exp, log2, log and pow: float64 lanes.

A float32 input is exact in float64, and the reductions below are exact there too, so one
polynomial evaluated in float64 (``routines.polynomials``: EXP2_*, LOG2_*) gives the result to
a relative error far below float32's half ULP:

    exp2(x):  k = round(x), r = x - k in [-1/2, 1/2] (exact), 2^x = 2^k * P(r)
    exp(x):   x * log2(e) as x*L1 + x*L2 with L1 on 29 bits (x*L1 exact), then as exp2
    log2(x):  x = 2^e * m, m in [0.75, 1.5), u = m - 1 (exact), s = u / (2 + u),
              log2(x) = e + s * Q(s^2)      (Q ~ 2 atanh(s) / (s ln 2), s^2 in [0, 0.04])
    log(x):   log2(x) * ln(2)

**faithful**: with FMA on (in hardware, or emulated exactly at sse4), exp2, exp and log run
in float32 lanes (``_exp_float``, ``_log_float``: the linear term split exactly into a float
pair, one rounding at the result's scale; below 0.78 / 0.78 / 0.87 ULP); otherwise, and for
log2 and pow, the float64 value (relative error ~2^-28) rounded once to float32: below
0.54 ULP. Subnormal results are rounded, never flushed.

**correct**: the float64 value has a relative error below 2^-40 (degree-8 and degree-5
polynomials). It is converted from y(1 - 2^-38) and from y(1 + 2^-38): where both give the
same float32, every value within 2^-38 of y rounds to it, the exact result included, so it
is the correctly rounded result. Where they differ (a rounding boundary is within 2^-38
relative: about one input in 2^13), the lane is recomputed in double-double (``doubled``,
Taylor series to ~2^-80) and rounded exactly (``doubled.round_pair``). ``python -m routines
ladder --exhaustive`` checks every one of the 2^32 inputs against a correctly rounded reference.

Results whose float32 is subnormal take the double-double lane too (their rounding point
moves), as do the specials of log2 (zero, negative, subnormal, infinite and NaN inputs).

Specials follow C99 Annex F / IEEE 754 (``docs/specials.md``); NaN bits follow the routines'
rule (``base.nan_rule``): a NaN input comes back quieted, an invalid operation gives 0xffc00000.
"""
from __future__ import annotations

import functools

import reactor
from reactor import (
    Any, As, Fma, If, IsInf, IsNan, Precision, Round, Select, ShiftRightArithmetic, Trunc, ToInt, Variable,
    vector_type,
)

from . import doubled as dd
from .constants import EXP2_SERIES_HIGH, EXP2_SERIES_LOW, LOG2_SERIES_HIGH, LOG2_SERIES_LOW
from .base import DEFAULT_NAN_BITS, nan_rule, positive_normal
from .polynomials import (
    EXP2_CORRECT, EXP2_FAITHFUL, EXP2_FAITHFUL_F, EXP2_POW_CORRECT, EXP_FAITHFUL_F, LOG2_CORRECT, LOG2_FAITHFUL,
    LOG2_FAITHFUL_F, LOG2_POW, LOG2_POW_CORRECT, LOG_FAITHFUL_F,
)

#: The rounding test's relative window: above the float64 evaluation's error bound (2^-40).
WINDOW = 2.0 ** -38
#: The correct pow's window: above its float64 value's error bound (2^-43.4).
POW_WINDOW = 2.0 ** -40

# log2(e) = L1 + L2 + L3, L1 on 29 bits so that x * L1 is exact for a float32 x.
LOG2E_1, LOG2E_2, LOG2E_3 = 1.442695040255785, 6.331784189566044e-10, -7.663673822123329e-27
LN2 = (0.6931471805599453, 2.3190468138462996e-17)
LN2_F = (0.6931471824645996, -1.9046542121259336e-09)    # ln 2 as a float32 pair
LN2_CW = (0.693145751953125, 1.428606765330187e-06)      # ln 2: 16 bits (0x3f317200) + float32 rest
LOG2E_F = 1.4426950216293335
LOG2E_PAIR = (1.4426950216293335, 1.925963033500011e-08)  # 1/ln 2 as a float32 pair

EXP_OVERFLOW = 88.72283935546875    # the least float32 x with exp(x) >= 2^128 - 2^103 (rounds to +inf)
EXP_UNDERFLOW = -103.97208404541016  # the greatest float32 x with exp(x) <= 2^-150 (rounds to +0)


def _types(width):
    return (vector_type("Float", width), vector_type("Double", width), vector_type("Int", width),
            vector_type("UInt", width))


def _exp2_series():
    """2^r = sum (ln 2)^n / n! r^n, n <= 18 (remainder < 2^-86 for |r| <= 1/2), highest first:
    the terms from r^9 up in float64 (each below 2^-31, so their rounding stays below 2^-84),
    the rest as double-double constants (``routines.constants``: mpmath, 60 digits)."""
    return EXP2_SERIES_HIGH, EXP2_SERIES_LOW


def _log2_series():
    """2 atanh(s) / (s ln 2) = sum 2 / ((2n+1) ln 2) z^n, z = s^2 <= 0.04, n <= 17 (remainder
    < 2^-80); from z^6 up in float64, the rest as double-double constants (``routines.constants``)."""
    return LOG2_SERIES_HIGH, LOG2_SERIES_LOW


def _double_horner(x, coefficients):
    acc = x * coefficients[0] + coefficients[1]
    for c in coefficients[2:]:
        acc = acc * x + c
    return acc


def _pow2(k):
    """2^k as float64 lanes for a whole float64 k in [-250, 250]: two float32 powers of two."""
    F, D, I, _ = _types(k.width)
    a = reactor.Floor(k * 0.5)
    b = k - a

    def power(n):
        return D(As(F, (ToInt(F(n)) + 127) << 23))
    return power(a) * power(b)


def _rounded(y, precision, signed=True):
    """float32 of the float64 ``y`` and the lanes where the rounding test fails (None: faithful).
    ``signed=False`` where y is positive or NaN (one ordered compare; a NaN lane passes)."""
    F = vector_type("Float", y.width)
    if precision is Precision.FAITHFUL:
        return F(y), None
    lo, hi = F(y * (1.0 - WINDOW)), F(y * (1.0 + WINDOW))
    return lo, (lo != hi) if signed else lo < hi


def _insert_exponent(f, k):
    """f * 2^k for a float32 f and a whole float32 k, as an integer add to the exponent field
    (exact where the result is normal and finite, or exactly +inf; a NaN f or k gives f)."""
    _, _, I, _ = _types(f.width)
    return As(vector_type("Float", f.width), As(I, f) + (ToInt(k, saturate=False) << 23))


def _exp2_pair(k, r_hi, r_lo):
    """2^(k + r_hi + r_lo) as a double-double (k whole, |r_hi| <= 1/2, |r_lo| < 2^-40)."""
    high, low = _exp2_series()
    start = _double_horner(r_hi, high)
    p = dd.horner((r_hi, 0.0 * r_hi), low, start=(start, 0.0 * r_hi))
    p = dd.fast_two_sum(p[0], p[1] + p[0] * (r_lo * LN2[0]))  # 2^r_lo = 1 + r_lo ln 2 + O(2^-80)
    s = _pow2(k)
    return p[0] * s, p[1] * s


def _fused_float() -> bool:
    """Whether the faithful tier takes the float32 path: FMA on (in hardware or emulated exactly)."""
    return bool(reactor.build_settings().fma)


def _poly(poly, r, precision):
    """A float64 polynomial: fused only in the correct tier (whose results are unique) where the
    target has FMA; elsewhere rounded multiplies and adds, so that the faithful tier's float64
    path gives the same bits on every target (float64 FMA cannot be emulated)."""
    return poly.evaluate(r, precision is Precision.CORRECT and dd.fused())


def _exp_float(x, natural):
    """Faithful exp2/exp in float32 lanes with FMA, for results that are normal floats:
    2^r = 1 + r ln2 + r^2 Q(r) with r ln2 split exactly (FMA) into a float pair, so that the
    only rounding at the result's scale is the last add (e^r likewise, r = x - k ln2 exact
    from a 16-bit ln2). Returns (p, k): the result is p * 2^k."""
    F = vector_type("Float", x.width)
    if natural:
        k = Round(x * LOG2E_F)
        r_hi = Fma(-k, LN2_CW[0], x)                     # exact: k has 8 bits, LN2_CW[0] 16
        r_lo = k * -LN2_CW[1]
        r = r_hi + r_lo
        s = 1.0 + r_hi
        tail = r_lo + (r_hi - (s - 1.0))                # 1 + r_hi = s + (r_hi - (s - 1)) exactly
        q = EXP_FAITHFUL_F(r)
    else:
        k = Round(x)
        r = x - k                                       # exact
        a = r * LN2_F[0]
        s = 1.0 + a
        tail = Fma(r, LN2_F[0], -a) + (a - (s - 1.0))   # r ln2_hi - a exactly (ln2_lo r < 2^-29.5: left out)
        q = EXP2_FAITHFUL_F(r)
    p = s + Fma(r * r, q, tail)
    return p, k


def _exp_family(x, precision, natural):
    """The vector path covers results that are normal floats. Lanes below (subnormal or zero
    results, -inf), NaN lanes and lanes that fail the rounding test take the double-double path."""
    F, D, I, _ = _types(x.width)
    poly = EXP2_CORRECT if precision is Precision.CORRECT else EXP2_FAITHFUL
    if precision is Precision.FAITHFUL and _fused_float():
        return _exp_faithful_float(x, natural)
    if natural:
        overflow, underflow, normal_from = EXP_OVERFLOW, EXP_UNDERFLOW, -86.0
        xd = D(x)
        p1 = xd * LOG2E_1                               # exact
        kd = Round(p1)
        r = (p1 - kd) + xd * LOG2E_2
        f, hard = _rounded(_poly(poly, r, precision), precision, signed=False)
        result = Variable(F, _insert_exponent(f, F(kd)))
    else:
        overflow, underflow, normal_from = 128.0, -150.0, -125.0
        k = Round(x)
        f, hard = _rounded(_poly(poly, D(x - k), precision), precision, signed=False)  # x - k: exact
        result = Variable(F, _insert_exponent(f, k))
    tiny = (x > underflow) & (x < normal_from)          # subnormal results
    exact_lanes = tiny if hard is None else tiny | hard
    with If(Any(exact_lanes)):
        xs = D(Select(exact_lanes, x, 0.0))
        if natural:
            p1 = xs * LOG2E_1
            k2 = Round(p1)
            p2, e2 = dd.two_prod(xs, LOG2E_2)
            a, b = dd.two_sum(p1 - k2, p2)
            r_hi, r_lo = dd.fast_two_sum(a, b + (e2 + xs * LOG2E_3))
        else:
            k2 = Round(xs)
            r_hi, r_lo = xs - k2, 0.0 * xs
        result.set(Select(exact_lanes, dd.round_pair(*_exp2_pair(k2, r_hi, r_lo)), result))
    # A NaN x needs no select: every operation on it has that one NaN operand, so the vector path
    # returns it quieted (the exponent insert adds 0: ToInt(NaN) << 23), on every target.
    return Select(x >= overflow, float("inf"), Select(x <= underflow, 0.0, result.value))  # -inf: +0


def _exp_faithful_float(x, natural):
    """The faithful tier with FMA: ``_exp_float`` for normal results; a vector with a lane
    outside (overflow, subnormal or zero results, NaN) scales p by 2^k in two exact steps and
    one rounding instead (p's error is far below a subnormal's ULP), or selects the special."""
    F, D, I, _ = _types(x.width)
    overflow, underflow, normal_from = (EXP_OVERFLOW, EXP_UNDERFLOW, -86.0) if natural else (128.0, -150.0, -125.0)
    f, k = _exp_float(x, natural)
    result = Variable(F, _insert_exponent(f, k))
    slow = ~((x >= normal_from) & (x < overflow))       # NaN too
    with If(Any(slow)):
        scaled = As(F, As(I, f) + ((ToInt(k, saturate=False) + 64) << 23)) * 2.0 ** -64
        special = Select(x >= overflow, F(float("inf")), Select(x <= underflow, F(0.0), scaled))
        result.set(Select(slow, Select(IsNan(x), x + x, special), result))
    return result.value


exp2 = functools.partial(_exp_family, natural=False)
exp = functools.partial(_exp_family, natural=True)


def _decompose(x):
    """(e, u) with x = 2^e (1 + u), u in [-0.25, 0.5), both exact, for a positive normal x."""
    F, D, I, _ = _types(x.width)
    bits = As(I, x)
    e = ShiftRightArithmetic(bits - 0x3F400000, 23)    # 0.75's bits: m in [0.75, 1.5)
    u = As(F, bits - (e << 23)) - 1.0                  # exact (Sterbenz)
    return D(e), D(u)


def _log2_double(e, u, poly, precision):
    s = u / (u + 2.0)
    return e + s * _poly(poly, s * s, precision)


def _log2_pair(e, u):
    """log2(2^e (1 + u)) as a double-double (Taylor series of atanh to ~2^-80)."""
    d = u + 2.0                                         # exact
    s_hi = u / d
    p, pe = dd.two_prod(s_hi, d)
    s = dd.fast_two_sum(s_hi, ((u - p) - pe) / d)       # u - p is exact
    z = dd.mul(s, s)
    high, low = _log2_series()
    c = dd.horner(z, low, start=(_double_horner(z[0], high), 0.0 * u))
    return dd.add((e, 0.0 * u), dd.mul(s, c))


def _log_specials(x):
    """log of what is not a positive float: -inf at +-0, +inf at +inf, x quieted at NaN, the
    default NaN 0xffc00000 below 0."""
    F, _, I, _ = _types(x.width)
    special = Select(x == 0.0, F(float("-inf")), As(F, I(DEFAULT_NAN_BITS)))
    special = Select(x == float("inf"), x, special)
    return Select(IsNan(x), x + x, special)


def _log_float(x, natural, offset=None):
    """Faithful log2/log in float32 lanes with FMA, for a positive normal x = 2^e (1 + u),
    m = 1 + u in [sqrt(1/2), sqrt(2)): log2 = e + u/ln2 + u^2 Q(u), the product u/ln2 exact as
    a float pair (FMA) and e + its high part summed exactly, so the one rounding at the
    result's scale is the last add (log: e ln2 from a 16-bit ln 2, u exact). ``offset`` is
    subtracted from e (a subnormal's 24, after scaling by 2^24)."""
    F, _, I, _ = _types(x.width)
    bits = As(I, x)
    n = ShiftRightArithmetic(bits - 0x3F3504F3, 23)      # m in [sqrt(1/2), sqrt(2))
    u = As(F, bits - (n << 23)) - 1.0                    # exact (Sterbenz)
    e = F(n) if offset is None else F(n) - offset
    if natural:
        a = Fma(e, LN2_CW[0], u)                         # exact: e ln2_hi has 24 bits and a <= 0.5 + e ln2
        lo = u - (a - e * LN2_CW[0])                     # what the add lost (0 where exact)
        tail = Fma(e, LN2_CW[1], lo)
        return a + Fma(u, u * LOG_FAITHFUL_F(u), tail)
    h = u * LOG2E_PAIR[0]
    tail = Fma(u, LOG2E_PAIR[1], Fma(u, LOG2E_PAIR[0], -h))
    s = e + h
    tail = tail + (h - (s - e))                          # e + h = s + (h - (s - e)) exactly: |e| >= |h| or e = 0
    return s + Fma(u, u * LOG2_FAITHFUL_F(u), tail)


def _log_faithful_float(x, natural):
    """The faithful tier with FMA: ``_log_float``; a vector with a lane that is not a positive
    normal float normalizes subnormals (x 2^24, exact) and selects the specials."""
    F, _, I, _ = _types(x.width)
    normal = positive_normal(x)
    result = Variable(F, _log_float(x, natural))
    with If(Any(~normal)):
        subnormal = (x > 0.0) & (x < 2.0 ** -126)
        scaled = _log_float(Select(subnormal, x * 2.0 ** 24, Select(normal, x, 1.0)), natural,
                            Select(subnormal, F(24.0), F(0.0)))
        result.set(Select(normal, result, Select(subnormal, scaled, _log_specials(x))))
    return result.value


def _log_family(x, precision, natural):
    F, D, I, _ = _types(x.width)
    if precision is Precision.FAITHFUL and natural and _fused_float():
        # log2 stays in float64: its float32 form (_log_float) errs by up to 1.04 ULP near
        # x = 1.4, the product by 1/ln 2 costing what log's exact leading term u does not
        return _log_faithful_float(x, natural)
    poly = LOG2_CORRECT if precision is Precision.CORRECT else LOG2_FAITHFUL
    normal = positive_normal(x)
    e, u = _decompose(x)                                # garbage where not normal: replaced below
    y = _log2_double(e, u, poly, precision)
    f, hard = _rounded(y * LN2[0] if natural else y, precision)
    result = Variable(F, f)
    subnormal = (x > 0.0) & (x < 2.0 ** -126)
    exact_lanes = subnormal if hard is None else subnormal | (hard & normal)
    with If(Any(~normal)):                              # zeros, negatives, infinities, NaNs: selected
        result.set(Select(normal, result, _log_specials(x)))
    with If(Any(exact_lanes)):                          # subnormal inputs, and the rounding test's lanes
        xs = Select(subnormal, x * 2.0 ** 24, Select(normal, x, 1.0))   # exact
        e2, u2 = _decompose(xs)
        pair = _log2_pair(e2 - Select(subnormal, D(24.0), D(0.0)), u2)
        if natural:
            pair = dd.mul(pair, LN2)
        result.set(Select(exact_lanes, dd.round_pair(*pair), result))
    return result.value


log2 = functools.partial(_log_family, natural=False)
log = functools.partial(_log_family, natural=True)


def _whole(y):
    """(integer, odd) masks of a float32 y (every |y| >= 2^24 is an even integer)."""
    _, _, I, _ = _types(y.width)
    integer = Trunc(y) == y
    small = reactor.Abs(y) < 2.0 ** 24
    odd = integer & small & ((ToInt(Select(small, y, 0.0)) & 1) == 1)
    return integer, odd


def pow(x, y, precision):  # noqa: A001
    """x^y with C99 Annex F semantics (pow, not powr); see ``_pow_faithful`` and ``_pow_correct``."""
    F, D, I, _ = _types(x.width)
    ax = reactor.Abs(x)
    subnormal = ax < 2.0 ** -126
    xs = Select(subnormal, ax * 2.0 ** 24, Select(positive_normal(ax), ax, 1.0))
    e, u = _decompose(xs)
    e = e - Select(subnormal, D(24.0), D(0.0))              # |x| = 2^e (1 + u), both exact
    integer, odd = _whole(y)
    if precision is Precision.CORRECT:
        core = _pow_correct(ax, y, e, u, integer)
    else:
        core = _pow_faithful(y, e, u, precision)
    return _pow_specials(x, y, ax, core, integer, odd)


def _exponent(t):
    """t with its infinities and NaNs at 0 (their results are selected later), within [-200, 200]
    (2^t is 0 or inf beyond)."""
    D = vector_type("Double", t.width)
    t = Select(IsInf(t) | IsNan(t), D(0.0), t)
    return reactor.Min(reactor.Max(t, D(-200.0)), D(200.0))


def _pow_faithful(y, e, u, precision):
    """|x|^y, faithful: y log2|x| is formed in float64 from a log2 with relative error ~2^-35
    (LOG2_POW), so the exponent's error stays below 2^-28 absolute for every finite result
    (|y log2 x| < 150), and 2^t (EXP2_FAITHFUL, 2^-29) is rounded once to float32 (subnormal
    results included)."""
    F = vector_type("Float", u.width)
    t = _exponent(vector_type("Double", u.width)(y) * _log2_double(e, u, LOG2_POW, precision))
    k = Round(t)
    return F(_poly(EXP2_FAITHFUL, t - k, precision) * _pow2(k))  # one rounding, subnormals and overflow too


def _pow_correct(ax, y, e, u, integer):
    """|x|^y, correctly rounded.

    The float64 path: l = log2(1 + u) = s Q(s^2) to ~2^-51.3 relative (LOG2_POW_CORRECT, 2^-56),
    t = y e + y l (y e exact) within 2^-43.2 of y log2|x| for |t| <= 150 (|y l| <= 1.41 |t|
    where e != 0), and 2^t = 2^(t - k) 2^k (EXP2_POW_CORRECT, 2^-46.1): the float64 value is
    within 2^-43.4 relative. It is rounded from v(1 -+ 2^-40) (``POW_WINDOW``);
    where the two differ (about one lane in 2^15.5), the lane is recomputed: as a double-double
    (log2 to ~2^-80 by ``_log2_pair``, the product by y exactly, 2^t by ``_exp2_pair``) and
    rounded exactly, except for the results that are exact, which a double-double cannot round
    when they are a midpoint of two floats: x a power of two with y log2|x| whole (2^t exactly),
    and y = p / 2^k (p from 2 to 15, k <= 3) with |x|^y exact in float64 (``_exact_power``).
    No other result is a midpoint (25 significant bits); each is rounded correctly wherever it
    lies farther than the double-double's error (~2^-78) from one (the stratified sweep and the
    hard pairs find no other: ``python -m routines ladder pow``)."""
    F, D, I, _ = _types(u.width)
    fused = dd.fused()
    yd = D(y)
    s = u / (u + 2.0)
    t = _exponent(yd * e + yd * (s * LOG2_POW_CORRECT.evaluate(s * s, fused)))
    k = Round(t)
    v = EXP2_POW_CORRECT.evaluate(t - k, fused) * _pow2(k)
    lo, hi = F(v * (1.0 - POW_WINDOW)), F(v * (1.0 + POW_WINDOW))
    result = Variable(F, lo)
    hard = lo < hi                                          # v >= 0; a NaN lane is not hard
    with If(Any(hard)):
        result.set(Select(hard, _pow_pair(ax, yd, e, u, integer), result))
    return result.value


def _pow_pair(ax, yd, e, u, integer):
    """|x|^y correctly rounded, in double-double, with its exact cases (``_pow_correct``)."""
    F, D, I, _ = _types(u.width)
    t_hi, t_lo = dd.mul_double(_log2_pair(e, u), yd)
    t_hi = _exponent(t_hi)
    k = Round(t_hi)
    r_hi, r_lo = dd.fast_two_sum(t_hi - k, t_lo)
    rounded = dd.round_pair(*_exp2_pair(k, r_hi, r_lo))
    te = yd * e                                             # exact
    power_of_two = (u == 0.0) & (Round(te) == te) & (reactor.Abs(te) <= 250.0)
    rounded = Select(power_of_two, F(_pow2(Select(power_of_two, te, D(0.0)))), rounded)
    product, exact = _exact_power(D(ax), yd)
    return Select(exact, F(product), rounded)


def _exact_power(xd, yd):
    """(|x|^y, where it was computed exactly) for y = p / 2^k with p a whole number from 2 to 15
    and k <= 3: |x|'s 2^k-th root by square roots, each checked exact (its square is |x|'s
    root before it), then the p-th power by ``_small_power``. These are the y whose powers of
    a float can be exactly halfway between two floats (25 significant bits: x = n^(2^k) 2^j and
    x^y = n^p 2^i; n >= 3 bounds p by 15 and 2^k by 15)."""
    _, D, _, _ = _types(xd.width)
    base, yk, roots = xd, yd, yd == yd
    for _ in range(3):
        fraction = Trunc(yk) != yk
        root = reactor.Sqrt(base)
        square, err = dd.two_prod(root, root)
        roots = roots & (~fraction | ((square == base) & (err == 0.0)))
        base = Select(fraction, root, base)
        yk = Select(fraction, yk * 2.0, yk)
    whole = (Trunc(yk) == yk) & (yk >= 2.0) & (yk <= 15.0) & roots & (yd > 1.0)
    product, exact = _small_power(base, Select(whole, yk, D(2.0)))
    return product, whole & exact


def _small_power(xd, n):
    """(xd^n, whether every product was exact) for whole n in [2, 15], by binary powering."""
    _, D, _, _ = _types(xd.width)
    acc, base = D(1.0), xd
    exact = n == n
    for bit in range(4):
        use = (Trunc(n * 2.0 ** -bit) - Trunc(n * 2.0 ** -(bit + 1)) * 2.0) == 1.0
        p, err = dd.two_prod(acc, base)
        acc = Select(use, p, acc)
        exact = exact & (~use | (err == 0.0))
        if bit < 3:
            needed = n >= 2.0 ** (bit + 1)
            p, err = dd.two_prod(base, base)
            base = p
            exact = exact & (~needed | (err == 0.0))
    return acc, exact


def _pow_specials(x, y, ax, core, integer, odd):
    """pow's results that its formula does not give: zeros, infinities, NaNs, and the sign."""
    F, D, I, _ = _types(x.width)
    log_inf = (ax == 0.0) | (ax == float("inf")) | IsInf(y)
    toward_inf = Select(ax == 0.0, y < 0.0, Select(ax == float("inf"), y > 0.0, (ax > 1.0) == (y > 0.0)))
    edge = Select(toward_inf, F(float("inf")), F(0.0))
    magnitude = Select(log_inf, edge, core)
    signed = Select(odd & (As(I, x) < 0), -magnitude, magnitude)
    invalid = (x < 0.0) & ~IsInf(x) & ~integer & ~IsInf(y)   # a negative base to a non-integer
    out = Select(invalid, As(F, I(DEFAULT_NAN_BITS)), signed)
    out = nan_rule(Select(IsNan(x) | IsNan(y), x + y, out), x, y)
    one = (y == 0.0) | (x == 1.0) | ((x == -1.0) & IsInf(y))
    return Select(one, F(1.0), out)
