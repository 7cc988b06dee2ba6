"""Vulkan accuracy requirements for the lab's float32 routines.

Source: Vulkan specification 1.4.360 (KhronosGroup/Vulkan-Docs, change log
of 2026-08-14), Appendix "Vulkan Environment for SPIR-V", section
"Precision and Operation of SPIR-V Instructions" (``spirvenv-op-prec``),
tables "Precision of Core SPIR-V Instructions" (OpFDiv) and "Precision of
GLSL.std.450 Instructions".  Each table has a column "Single precision,
unless decorated with RelaxedPrecision" (our ``"full"``, GLSL highp) and a
column "Half precision" (our ``"relaxed"``: RelaxedPrecision / mediump).

=========  ==========================================  ========================================
routine    full (ULP-32)                               relaxed (ULP-16)
=========  ==========================================  ========================================
exp, exp2  3 + 2|x| ULP                                1 + 2|x| ULP
log, log2  3 ULP outside [0.5, 2]; absolute            3 ULP outside [0.5, 2]; absolute
           error < 2**-21 inside                       error < 2**-7 inside
rcp        OpFDiv 1/x: 2.5 ULP for |x| = 0 or          2.5 ULP (spec: |x| in [2**-14, 2**14];
           |x| in [2**-126, 2**126], else no bound     see *assumptions*)
rsqrt      inversesqrt: 2 ULP                          2 ULP
sqrt       inherited from 1.0 / inversesqrt(x)         same, in binary16 spacing
pow        inherited from exp2(y * log2(x))            same, in binary16 spacing
sin, cos   absolute error <= 2**-11 inside [-pi, pi],  absolute error <= 2**-7 inside
           no bound outside                            [-pi, pi]
tan        inherited from sin() / cos()                same (relaxed sin, cos, OpFDiv)
asin       inherited from atan2(x, sqrt(1.0 - x * x))  same, in binary16 spacing
acos       inherited from atan2(sqrt(1.0 - x * x), x)  same, in binary16 spacing
atan,      4096 ULP                                    5 ULP
atan2
sinh       inherited from (exp(x) - exp(-x)) * 0.5     same (1 + 2|x| ULP-16 exp)
cosh       inherited from (exp(x) + exp(-x)) * 0.5     same
tanh       inherited from sinh() / cosh()              same
=========  ==========================================  ========================================

(The rows from sin on are those of the same table in Vulkan-Docs 1.4.360,
``appendices/spirvenv.adoc``, anchor ``precision-of-glsl-std-450-instructions``:
"Absolute error <= 2^-11 inside the range [-pi, pi]" / "<= 2^-7" for sin()
and cos(); the inherited rows span both columns; atan(), atan2(): "4096 ULP"
single precision, "5 ULP." half precision.)

Units.  ``ULP`` is the spec's ``ulp()`` of the exact result
(:func:`~routines.lab.measures.spec_ulp32`, or ``spec_ulp16`` for relaxed:
binary16 spacing of the float32 result, 2**-24 below 2**-14).  Every
tolerance function returns the allowed error *in those units* (float64,
``inf`` = no bound); :meth:`Tolerance.allowed` converts to an absolute error.
Absolute bounds (log inside [0.5, 2]) are divided by the unit, so they are
exact in ULPs too.

Inherited tolerances (spec: the result must lie within E of the exact value,
E the largest distance to any value the formula can produce when each step
is given its own allowance; NaN among them means no bound):

pow(x, y) = exp2(y * log2(x)), t = y*log2(x), r = 2**t.
    log2(x) may be off by e_L = A (2**-21 full, 2**-7 relaxed) for x in
    [0.5, 2], else 3 ULP of log2(x).  Multiplying by y scales that to
    |y|*e_L; OpFMul is "correctly rounded" with an implementation-defined
    rounding mode, so the product adds up to 1 ULP of |t| + |y|*e_L (0.5 ULP
    under RoundingModeRTE).  So exp2 sees t' in [t - dt, t + dt] with
    dt = |y|*e_L + ulp(|t| + |y|*e_L), and returns 2**t' within
    (3 + 2|t'|) ULP (1 + 2|t'| relaxed).  Hence
    E = max(F_max - r, r - F_min), F_max = 2**(t+dt) + n(t+dt)*ulp(2**(t+dt)),
    F_min = 2**(t-dt) - n(t-dt)*ulp(2**(t-dt)).  To first order, since
    d(2**t) = 2**t ln2 dt:  E/ulp(r) ~= 3 + 2|t| + ln2*dt * r/ulp(r), with
    r/ulp(r) in [2**23, 2**24) -- i.e. about ln2*dt*2**23..2**24 ULP-32 on top
    of exp2's own 3 + 2|t|.  Example: x = 3, y = 50 (t = 79.25): log2(3) is
    outside [0.5, 2], e_L = 3*2**-23, dt = 150*2**-23 + 2**-17 = 2.55e-5, and
    the bound is 3 + 158.5 + 176 = 337.7 ULP-32 (relaxed: 349.5 ULP-16).
    Near x = 1, |y|*2**-21 dominates (absolute log2 bound).  Where log2(x)
    is infinite (x = 0) the bound is unbounded.

sqrt(x) = 1 / inversesqrt(x), s = sqrt(x), q = 1/s.
    inversesqrt gives R in [q - 2 ulp(q), q + 2 ulp(q)]; OpFDiv then adds
    2.5 ULP of 1/R.  E = max(F_max - s, s - F_min) with
    F_max = 1/(q - 2ulp(q)) + 2.5 ulp(.), F_min likewise.  The relative error
    2 ulp(q)/q of R carries over to s, but q and s = 1/q sit in different
    binades: with mantissas m_q, m_s in [1, 2), 2 ULP of q is 2*m_s/m_q ULP
    of s, and m_s = 2/m_q for m_q > 1, so the rsqrt share is 4/m_q**2, in
    (1, 4) ULP (1 when q is a power of two, whose spec ulp is the spacing
    below).  Total: 2.5 + 4/m_q**2, i.e. 3.5 to 6.5 ULP; "about 4.5"
    (= 2 + 2.5) holds only near m_q = sqrt(2).  Within ~4 ULP below a power
    of two, F_max crosses into the next binade, where the division's 2.5 ULP
    count double: up to 4 + 5 = 9 ULP.  (Counts are in the binade ULP of s;
    in the spec's ulp, which halves at an exact power of two, s = 2**k gets
    7.)  At x = +-0 (rsqrt = inf, 1/inf outside OpFDiv's
    divisor range) we take the strict reading: 2.5 ULP of the exact 0.
    Relaxed: the same formula in binary16 spacing; because ulp16 stops at
    2**-24 below 2**-14, q = rsqrt(x) < 2**-14 (x > 2**28) loses relative
    accuracy and the bound grows, becoming unbounded for x >= 2**46.

tan(x) = sin(x) / cos(x), inside [-pi, pi] only (sin and cos have no bound
    outside), A = 2**-11 (relaxed 2**-7).  S in [s - A, s + A], C in
    [c - A, c + A]; if |c| <= A the divisor range contains 0: unbounded.
    Otherwise S/C is monotone in each operand on that rectangle, so its
    extremes are corner quotients q_i, and OpFDiv adds 2.5 ULP of each:
    F_max = max(q_i + 2.5 ulp(q_i)), F_min = min(q_i - 2.5 ulp(q_i)).  To
    first order E = A (|c| + |s|) / c**2: about 2**-11 absolute near x = 0.

asin(x) = atan2(x, sqrt(1 - x*x)), acos(x) = atan2(sqrt(1 - x*x), x).
    Every operation correctly rounded with implementation-defined rounding
    mode returns its exact value rounded down or up to the grid (``_to_grid``):
    M = x*x in [rd(x^2), ru(x^2)] (<= 1 for |x| <= 1: 1 is representable),
    D = 1 - M in [rd(1 - M_hi), ru(1 - M_lo)], Q = sqrt(D) within the
    inherited sqrt bound above at each end of D, clipped at +0 (a square root
    is never negative; otherwise acos(-1) would admit atan2(-0.., -1) = -pi).
    atan2 is monotone in Q (asin: decreasing; acos: increasing for x > 0,
    decreasing for x < 0), so F_max/F_min are atan2 at Q_lo and Q_hi plus or
    minus atan2's own 4096 ULP (relaxed 5 ULP).  At x = 0 and +-1 nearly only
    those remain (4096 ULP; acos(1) = 0: 4098.5, sqrt(0)'s 2.5 ULP of 0 added);
    elsewhere the spread of Q adds a few ULP (full 4096-4110 ULP-32; relaxed
    5-20 ULP-16).

sinh(x) = (exp(x) - exp(-x)) * 0.5, cosh(x) = (exp(x) + exp(-x)) * 0.5.
    exp(+-x) within n = 3 + 2|x| ULP (relaxed 1 + 2|x| ULP-16); if the range
    of exp(|x|) passes FLT_MAX an infinity is allowed and E is unbounded
    (|x| > 88.72).  The difference (sum) and the * 0.5 are rounded down or up
    to the grid: sinh in [rd(rd(E1_lo - E2_hi)/2), ru(ru(E1_hi - E2_lo)/2)],
    cosh in [rd(rd(E1_lo + E2_lo)/2), ru(ru(E1_hi + E2_hi)/2)].  cosh(0):
    exp(+-0) = 1 +- 3 * 2**-24 (the spec's ulp of 1 is the spacing below),
    the sum rounds up to 2 + 2**-21, halved 1 + 2**-22: 4 ULP.  sinh near 0:
    about 2**-22 absolute; both ~3 + 2|x| ULP for large |x|.

tanh = sinh() / cosh(): sinh and cosh each within their own inherited bound
    (independently), the corner quotients and OpFDiv's 2.5 ULP as for tan;
    unbounded where cosh passes 2**126 (OpFDiv's divisor range) or either
    bound is unbounded.

Assumptions and readings (documented in docs/accuracy.md):

* Relaxed results are float32: they are scored in binary16 spacing with no
  binary16 overflow limit.  Accordingly the relaxed OpFDiv divisor range is
  taken as the float32 one, [2**-126, 2**126] (the spec's [2**-14, 2**14] is
  the binary16 normal range of a binary16 divisor); this is stricter.
* At non-finite inputs the tolerances do not apply: the IEEE-754 result is
  required exactly (see :mod:`routines.lab.measures`).  For rcp at |x| = inf
  (outside the divisor range) we keep the 2.5 ULP of the exact 0.
* The log bound "3 ULP outside [0.5, 2]" for relaxed is read from the same
  table row (confirmed, not assumed).
* Inherited formulas are evaluated as written; the spec also admits their
  rearrangements by associativity, commutativity and distributivity (taking
  the widest range), which can only loosen the bound.
* "Inside the range [-pi, pi]" is decided exactly: float32(pi) = 3.1415927 is
  above pi, hence outside (no bound).
"""

from __future__ import annotations

import math

from ..base import PRECISIONS
import threading
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .measures import F32_MAX, spec_ulp16, spec_ulp32, ulp16, ulp32

SPEC = ("Vulkan 1.4.360, Appendix 'Vulkan Environment for SPIR-V', "
        "'Precision and Operation of SPIR-V Instructions'")

_UNIT = {"full": spec_ulp32, "relaxed": spec_ulp16}
_EXP_BASE = {"full": 3.0, "relaxed": 1.0}
_LOG_ABS = {"full": 2.0**-21, "relaxed": 2.0**-7}
_MUL_ROUNDING_ULP = 1.0  # implementation-defined rounding mode: < 1 ULP
_TRIG_ABS = {"full": 2.0**-11, "relaxed": 2.0**-7}   # sin, cos inside [-pi, pi]
_ATAN_ULP = {"full": 4096.0, "relaxed": 5.0}         # atan, atan2
_DIV_ULP = 2.5                                       # OpFDiv, |divisor| in [2^-126, 2^126]
_GRID = {"full": ulp32, "relaxed": ulp16}            # spacing of the format results round to


def _buf(shape, out):
    return np.empty(shape) if out is None else out


_SCRATCH = threading.local()


def _scratch(shape, count):
    """``count`` float64 work arrays of ``shape``, reused per thread (fresh
    temporaries of sweep-block size would each cost page faults)."""
    size = math.prod(shape)
    pool = getattr(_SCRATCH, "pool", [])
    if len(pool) < count or pool[0].size < size:
        pool = [np.empty(max(size, 1)) for _ in range(count)]
        _SCRATCH.pool = pool
    return [a[:size].reshape(shape) for a in pool[:count]]


_WORK = threading.local()


def _work(shape, count):
    """Like :func:`_scratch`, from a second pool: the inherited trigonometric and
    hyperbolic bounds call the sqrt bound, which uses :func:`_scratch`."""
    size = math.prod(shape)
    pool = getattr(_WORK, "pool", [])
    if len(pool) < count or pool[0].size < size:
        pool = [np.empty(max(size, 1)) for _ in range(max(count, len(pool)))]
        _WORK.pool = pool
    return [a[:size].reshape(shape) for a in pool[:count]]


def _exp(precision):
    base = _EXP_BASE[precision]

    def ulps(x, ref, out=None):
        out = np.abs(x, out=_buf(np.shape(x), out), dtype=np.float64)
        np.multiply(out, 2.0, out=out)
        return np.add(out, base, out=out)
    return ulps


def _log(precision):
    unit, bound = _UNIT[precision], _LOG_ABS[precision]

    def ulps(x, ref, out=None):
        out = unit(ref, out=out)
        np.divide(bound, out, out=out)
        outside = (x < 0.5) | (x > 2.0)  # NaN inputs: inside, irrelevant
        np.copyto(out, 3.0, where=outside)
        return out
    return ulps


def _rcp(precision):
    def ulps(x, ref, out=None):
        ax = np.abs(x)
        bounded = ((ax >= 2.0**-126) & (ax <= 2.0**126)) | (ax == 0) | np.isinf(ax)
        out = _buf(np.shape(x), out)
        out[...] = np.inf
        np.copyto(out, 2.5, where=bounded)
        return out
    return ulps


def _rsqrt(precision):
    def ulps(x, ref, out=None):
        out = _buf(np.shape(x), out)
        out[...] = 2.0
        return out
    return ulps


def _sqrt(precision):
    unit = _UNIT[precision]

    def ulps(x, ref, out=None):
        # Closed form of the inherited bound (F_max is always the farther end):
        # delta = 2 ulp(q)/q, E = s*delta/(1-delta) + 2.5 ulp(s/(1-delta)).
        s = np.asarray(ref, dtype=np.float64)
        out = _buf(s.shape, out)
        ratio, part = _scratch(s.shape, 2)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            q = np.divide(1.0, s, out=ratio)
            delta = unit(q, out=out)
            np.divide(delta, q, out=delta)
            np.multiply(delta, 2.0, out=delta)
            np.subtract(1.0, delta, out=part)
            np.divide(delta, part, out=ratio)            # delta / (1 - delta)
            np.multiply(s, ratio, out=part)              # s * ratio
            f1 = np.add(s, part, out=out)
            e = unit(f1, out=out)
            np.multiply(e, 2.5, out=e)
            np.add(e, part, out=e)
            np.divide(e, unit(s, out=part), out=e)
        unbounded = ~(ratio >= 0)                        # delta >= 1, or NaN
        unbounded |= np.isinf(ratio)
        np.copyto(e, np.inf, where=unbounded)
        np.copyto(e, 2.5, where=(s == 0))
        return e
    return ulps


def _pow(precision):
    unit, bound, base = _UNIT[precision], _LOG_ABS[precision], _EXP_BASE[precision]

    def ulps(x, y, ref, out=None):
        x, y = np.asarray(x), np.asarray(y)
        r = np.asarray(ref, dtype=np.float64)
        shape = np.broadcast(x, y, r).shape
        out = _buf(shape, out)
        a, t, b, c, u = _scratch(shape, 5)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            np.log2(x, out=a, dtype=np.float64)                 # log2(x)
            np.multiply(y, a, out=t, dtype=np.float64)          # t = y log2(x)
            e_log = np.multiply(unit(a, out=b), 3.0, out=b)     # log2 error bound
            np.copyto(e_log, bound, where=(x >= 0.5) & (x <= 2.0))
            spread = np.abs(np.multiply(e_log, y, out=b), out=b)   # |y| e_log
            dt = np.add(np.abs(t, out=c), spread, out=c)        # rounding of y*log2
            np.multiply(unit(dt, out=dt), _MUL_ROUNDING_ULP, out=dt)
            np.add(dt, spread, out=dt)
            hi, lo = np.add(t, dt, out=a), np.subtract(t, dt, out=b)
            f_max = np.exp2(hi, out=c)                          # exp2(hi) + n(hi) ulp
            n_hi = np.add(np.multiply(np.abs(hi, out=hi), 2.0, out=hi), base, out=hi)
            np.add(f_max, np.multiply(n_hi, unit(f_max, out=u), out=n_hi), out=f_max)
            f_min = np.exp2(lo, out=a)                          # exp2(lo) - n(lo) ulp
            n_lo = np.add(np.multiply(np.abs(lo, out=lo), 2.0, out=lo), base, out=lo)
            np.subtract(f_min, np.multiply(n_lo, unit(f_min, out=u), out=n_lo), out=f_min)
            np.subtract(f_max, r, out=f_max)
            np.subtract(r, f_min, out=f_min)
            e = np.maximum(f_max, f_min, out=out)
            np.divide(e, unit(r, out=u), out=e)
        np.copyto(e, np.inf, where=np.isnan(e))
        return e
    return ulps


# -- trigonometric and hyperbolic ------------------------------------------------

def _to_grid(v, precision, up, out, tmp):
    """``v`` rounded down (or up) to the precision's floating-point grid: what a
    correctly rounded operation with implementation-defined rounding mode may
    return (binade spacing; binary16 spacing has no overflow limit here)."""
    g = _GRID[precision](v, out=tmp)
    np.divide(v, g, out=out)
    (np.ceil if up else np.floor)(out, out=out)
    return np.multiply(out, g, out=out)


#: The largest float32 in [-pi, pi] in magnitude (float32(pi) = 3.1415927 lies above pi).
PI_DOWN32 = np.nextafter(np.float32(np.pi), np.float32(0))


def inside_pi(x):
    """|x| <= pi for float32 (or float64) operands, decided exactly."""
    x = np.asarray(x)
    limit = PI_DOWN32 if x.dtype == np.float32 else np.pi
    return np.abs(x) <= limit


def _sincos(precision):
    unit, bound = _UNIT[precision], _TRIG_ABS[precision]

    def ulps(x, ref, out=None):
        out = unit(ref, out=out)
        np.divide(bound, out, out=out)
        np.copyto(out, np.inf, where=~inside_pi(x))             # no bound outside [-pi, pi]
        return out
    return ulps


def _atan(precision):
    n = _ATAN_ULP[precision]

    def ulps(*args, out=None):
        out = _buf(np.broadcast(*args).shape, out)
        out[...] = n
        return out
    return ulps


def _corner_quotients(s, es, c, ec, precision, fmax, fmin, q, u):
    """F_max, F_min of S/C, S in [s - es, s + es], C in [c - ec, c + ec] (C not
    crossing 0), with OpFDiv's 2.5 ULP at each corner quotient."""
    unit = _UNIT[precision]
    fmax.fill(-np.inf)
    fmin.fill(np.inf)
    for sa in (1.0, -1.0):
        for ca in (1.0, -1.0):
            np.multiply(es, sa, out=q)
            np.add(s, q, out=q)
            np.multiply(ec, ca, out=u)
            np.add(c, u, out=u)
            np.divide(q, u, out=q)
            np.multiply(unit(q, out=u), _DIV_ULP, out=u)
            np.add(q, u, out=u)
            np.maximum(fmax, u, out=fmax)
            np.multiply(unit(q, out=u), -_DIV_ULP, out=u)
            np.add(q, u, out=u)
            np.minimum(fmin, u, out=fmin)


def _spread(r, fmax, fmin, unit, out):
    """max(F_max - r, r - F_min) / unit(r); NaN -> inf (no bound)."""
    np.subtract(fmax, r, out=fmax)
    np.subtract(r, fmin, out=fmin)
    np.maximum(fmax, fmin, out=out)
    np.divide(out, unit(r, out=fmin), out=out)
    np.copyto(out, np.inf, where=np.isnan(out))
    return out


def _tan(precision):
    unit, bound = _UNIT[precision], _TRIG_ABS[precision]

    def ulps(x, ref, out=None):
        xd = np.asarray(x, dtype=np.float64)
        t = np.asarray(ref, dtype=np.float64)
        out = _buf(t.shape, out)
        c, s, e, fmax, fmin, q, u = _work(t.shape, 7)
        with np.errstate(all="ignore"):
            # sin and cos from the reference tan: c = +-1/sqrt(1 + t^2), s = t c
            np.multiply(t, t, out=c)
            np.add(c, 1.0, out=c)
            np.sqrt(c, out=c)
            np.divide(1.0, c, out=c)
            np.negative(c, out=c, where=np.abs(xd) > np.pi / 2)
            np.multiply(t, c, out=s)
            e.fill(bound)
            _corner_quotients(s, e, c, e, precision, fmax, fmin, q, u)
            _spread(t, fmax, fmin, unit, out)
            np.abs(c, out=c)
            unbounded = ~(inside_pi(xd) & (c - bound > 2.0**-126))
            np.copyto(out, np.inf, where=unbounded)
        return out
    return ulps


def _asin_acos(func, precision):
    unit, n, sqrt_ulps = _UNIT[precision], _ATAN_ULP[precision], _sqrt(precision)

    def ulps(x, ref, out=None):
        xd = np.asarray(x, dtype=np.float64)
        r = np.asarray(ref, dtype=np.float64)
        out = _buf(r.shape, out)
        if not np.any(np.abs(xd) <= 1.0):                        # NaN everywhere: no bound needed
            out[...] = np.inf
            return out
        ax, d_lo, d_hi, q_lo, q_hi, t1, t2 = _work(r.shape, 7)
        with np.errstate(all="ignore"):
            np.abs(xd, out=ax)
            np.multiply(ax, ax, out=t1)                          # x*x (exact in float64) ...
            _to_grid(t1, precision, False, d_hi, t2)             # ... rounded down or up
            _to_grid(t1, precision, True, d_lo, t2)
            np.subtract(1.0, d_lo, out=t1)                       # 1 - x*x, rounded
            _to_grid(t1, precision, False, d_lo, t2)
            np.subtract(1.0, d_hi, out=t1)
            _to_grid(t1, precision, True, d_hi, t2)
            for d, q, sign in ((d_lo, q_lo, -1.0), (d_hi, q_hi, 1.0)):   # sqrt within its bound
                np.sqrt(d, out=q)
                sqrt_ulps(d, q, out=t1)
                np.multiply(t1, unit(q, out=t2), out=t1)
                np.multiply(t1, sign, out=t1)
                np.add(q, t1, out=q)
            np.maximum(q_lo, 0.0, out=q_lo)                      # a square root is >= +0
            if func == "asin":                                   # atan2(|x|, Q): decreasing in Q
                np.arctan2(ax, q_hi, out=t1)
                np.arctan2(ax, q_lo, out=t2)
                r = np.abs(r)
            else:                                                # atan2(Q, x): monotone in Q
                np.arctan2(q_lo, xd, out=d_lo)
                np.arctan2(q_hi, xd, out=d_hi)
                np.minimum(d_lo, d_hi, out=t1)
                np.maximum(d_lo, d_hi, out=t2)
            np.multiply(unit(t2, out=q_lo), n, out=q_lo)         # atan2's own n ULP at each end
            np.add(t2, q_lo, out=t2)
            np.multiply(unit(t1, out=q_hi), -n, out=q_hi)
            np.add(t1, q_hi, out=t1)
            _spread(r, t2, t1, unit, out)
        return out
    return ulps


def _asin(precision):
    return _asin_acos("asin", precision)


def _acos(precision):
    return _asin_acos("acos", precision)


def _exp_ends(ax, precision, e1_lo, e1_hi, e2_lo, e2_hi, tmp):
    """Ranges of exp(|x|) and exp(-|x|) (3 + 2|x| ULP; relaxed 1 + 2|x|); returns
    the mask where exp(|x|) may be infinite (its range passes FLT_MAX)."""
    unit, base = _UNIT[precision], _EXP_BASE[precision]
    np.multiply(ax, 2.0, out=tmp)
    np.add(tmp, base, out=tmp)                                   # n = base + 2|x|
    np.exp(ax, out=e1_lo)
    np.multiply(unit(e1_lo, out=e1_hi), tmp, out=e1_hi)
    np.subtract(e1_lo, e1_hi, out=e2_lo)
    np.add(e1_lo, e1_hi, out=e1_hi)
    np.copyto(e1_lo, e2_lo)
    np.negative(ax, out=e2_lo)
    np.exp(e2_lo, out=e2_lo)
    np.multiply(unit(e2_lo, out=e2_hi), tmp, out=e2_hi)
    np.subtract(e2_lo, e2_hi, out=tmp)
    np.add(e2_lo, e2_hi, out=e2_hi)
    np.copyto(e2_lo, tmp)
    return ~(e1_hi <= F32_MAX)


def _hyperbolic_bound(kind, ax, precision, out, bufs):
    """Absolute bound of (exp(x) -+ exp(-x)) * 0.5 (kind 'sinh'/'cosh') at |x| = ax,
    as (value, allowed) with the value exact; inf where unbounded."""
    e1_lo, e1_hi, e2_lo, e2_hi, f_lo, f_hi, tmp = bufs
    overflow = _exp_ends(ax, precision, e1_lo, e1_hi, e2_lo, e2_hi, tmp)
    if kind == "sinh":
        np.subtract(e1_lo, e2_hi, out=tmp)
        _to_grid(tmp, precision, False, f_lo, out)
        np.subtract(e1_hi, e2_lo, out=tmp)
        _to_grid(tmp, precision, True, f_hi, out)
    else:
        np.add(e1_lo, e2_lo, out=tmp)
        _to_grid(tmp, precision, False, f_lo, out)
        np.add(e1_hi, e2_hi, out=tmp)
        _to_grid(tmp, precision, True, f_hi, out)
    np.multiply(f_lo, 0.5, out=tmp)                              # * 0.5, correctly rounded
    _to_grid(tmp, precision, False, f_lo, out)
    np.multiply(f_hi, 0.5, out=tmp)
    _to_grid(tmp, precision, True, f_hi, out)
    (np.sinh if kind == "sinh" else np.cosh)(ax, out=tmp)         # the exact value
    np.subtract(f_hi, tmp, out=f_hi)
    np.subtract(tmp, f_lo, out=f_lo)
    np.maximum(f_hi, f_lo, out=out)
    np.copyto(out, np.inf, where=overflow | np.isnan(out))
    return tmp, out


def _sinh_cosh(kind, precision):
    unit = _UNIT[precision]

    def ulps(x, ref, out=None):
        r = np.asarray(ref, dtype=np.float64)
        out = _buf(r.shape, out)
        ax, *bufs = _work(r.shape, 8)
        with np.errstate(all="ignore"):
            np.minimum(np.abs(np.asarray(x, dtype=np.float64), out=ax), 100.0, out=ax)
            _hyperbolic_bound(kind, ax, precision, out, bufs)
            np.divide(out, unit(r, out=ax), out=out)
            np.copyto(out, np.inf, where=np.isnan(out))
        return out
    return ulps


def _sinh(precision):
    return _sinh_cosh("sinh", precision)


def _cosh(precision):
    return _sinh_cosh("cosh", precision)


def _tanh(precision):
    unit = _UNIT[precision]

    def ulps(x, ref, out=None):
        r = np.asarray(ref, dtype=np.float64)
        out = _buf(r.shape, out)
        ax, s, es, c, ec, fmax, fmin, q, u, *bufs = _work(r.shape, 16)
        with np.errstate(all="ignore"):
            np.minimum(np.abs(np.asarray(x, dtype=np.float64), out=ax), 100.0, out=ax)
            value, bound = _hyperbolic_bound("sinh", ax, precision, es, bufs)
            np.copyto(s, value)
            value, bound = _hyperbolic_bound("cosh", ax, precision, ec, bufs)
            np.copyto(c, value)
            _corner_quotients(s, es, c, ec, precision, fmax, fmin, q, u)
            _spread(np.abs(r), fmax, fmin, unit, out)
            np.add(c, ec, out=c)                                 # OpFDiv's divisor range
            np.copyto(out, np.inf, where=~(c <= 2.0**126) | np.isinf(es) | np.isinf(ec))
        return out
    return ulps


@dataclass(frozen=True)
class Tolerance:
    """One row of the table for one precision.

    ``ulps(x, ref, out=None)`` (``ulps(x, y, ref, out=None)`` for pow) returns
    the allowed error in ``unit`` (float64 array, ``inf`` = no bound).
    """

    func: str
    precision: str
    rule: str
    unit: str
    citation: str
    ulps: Callable[..., np.ndarray]

    def unit_of(self, ref, out=None):
        """The ULP size (absolute) the tolerance is counted in, at ``ref``."""
        return _UNIT[self.precision](ref, out=out)

    def allowed(self, *args):
        """Absolute allowed error: ``ulps(*args) * unit_of(ref)``."""
        ref = args[-1]
        return self.ulps(*args) * self.unit_of(ref)


_GLSL = SPEC + ", table 'Precision of GLSL.std.450 Instructions', row "
_CORE = SPEC + ", table 'Precision of Core SPIR-V Instructions', row "

_ROWS = {
    "exp2": (_exp, _GLSL + "exp(x), exp2(x)",
             {"full": "3 + 2|x| ULP", "relaxed": "1 + 2|x| ULP"}),
    "exp": (_exp, _GLSL + "exp(x), exp2(x)",
            {"full": "3 + 2|x| ULP", "relaxed": "1 + 2|x| ULP"}),
    "log2": (_log, _GLSL + "log(), log2()",
             {"full": "3 ULP outside [0.5, 2]; |error| < 2^-21 inside",
              "relaxed": "3 ULP outside [0.5, 2]; |error| < 2^-7 inside"}),
    "log": (_log, _GLSL + "log(), log2()",
            {"full": "3 ULP outside [0.5, 2]; |error| < 2^-21 inside",
             "relaxed": "3 ULP outside [0.5, 2]; |error| < 2^-7 inside"}),
    "rcp": (_rcp, _CORE + "OpFDiv(x, y) with x = 1",
            {"full": "2.5 ULP for |x| = 0 or |x| in [2^-126, 2^126], else unbounded",
             "relaxed": "2.5 ULP for |x| = 0 or |x| in [2^-126, 2^126] "
                        "(spec: [2^-14, 2^14]), else unbounded"}),
    "rsqrt": (_rsqrt, _GLSL + "inversesqrt()", {"full": "2 ULP", "relaxed": "2 ULP"}),
    "sqrt": (_sqrt, _GLSL + "sqrt(): inherited from 1.0 / inversesqrt()",
             {"full": "inherited: 2.5 + 4/m_q^2 ULP (3.5..6.5; up to 9 just below 2^k)",
              "relaxed": "inherited: 2.5 + 4/m_q^2 ULP-16 (looser for x > 2^28)"}),
    "pow": (_pow, _GLSL + "pow(x, y): inherited from exp2(y * log2(x))",
            {"full": "inherited: ~3 + 2|t| + ln2*dt*r/ulp(r) ULP, t = y log2 x",
             "relaxed": "inherited: ~1 + 2|t| + ln2*dt*r/ulp(r) ULP-16"}),
    "sin": (_sincos, _GLSL + "sin()",
            {"full": "absolute error <= 2^-11 inside [-pi, pi], else unbounded",
             "relaxed": "absolute error <= 2^-7 inside [-pi, pi], else unbounded"}),
    "cos": (_sincos, _GLSL + "cos()",
            {"full": "absolute error <= 2^-11 inside [-pi, pi], else unbounded",
             "relaxed": "absolute error <= 2^-7 inside [-pi, pi], else unbounded"}),
    "tan": (_tan, _GLSL + "tan(): inherited from sin() / cos()",
            {"full": "inherited: (sin +- 2^-11) / (cos +- 2^-11) + 2.5 ULP; unbounded outside "
                     "[-pi, pi] and where |cos x| <= 2^-11",
             "relaxed": "inherited: (sin +- 2^-7) / (cos +- 2^-7) + 2.5 ULP-16; unbounded outside "
                        "[-pi, pi] and where |cos x| <= 2^-7"}),
    "asin": (_asin, _GLSL + "asin(x): inherited from atan2(x, sqrt(1.0 - x * x))",
             {"full": "inherited: atan2's 4096 ULP plus the spread of sqrt(1 - x*x) (>= 4096 ULP)",
              "relaxed": "inherited: atan2's 5 ULP-16 plus the spread of sqrt(1 - x*x)"}),
    "acos": (_acos, _GLSL + "acos(x): inherited from atan2(sqrt(1.0 - x * x), x)",
             {"full": "inherited: atan2's 4096 ULP plus the spread of sqrt(1 - x*x) (>= 4096 ULP)",
              "relaxed": "inherited: atan2's 5 ULP-16 plus the spread of sqrt(1 - x*x)"}),
    "atan": (_atan, _GLSL + "atan(), atan2()", {"full": "4096 ULP", "relaxed": "5 ULP"}),
    "atan2": (_atan, _GLSL + "atan(), atan2()", {"full": "4096 ULP", "relaxed": "5 ULP"}),
    "sinh": (_sinh, _GLSL + "sinh(x): inherited from (exp(x) - exp(-x)) * 0.5",
             {"full": "inherited: ~3 + 2|x| ULP for |x| >= 1; ~2^-22 absolute near 0; unbounded "
                      "where exp(|x|) may overflow (|x| > 88.72)",
              "relaxed": "inherited: ~1 + 2|x| ULP-16 for |x| >= 1; ~2^-10 absolute near 0"}),
    "cosh": (_cosh, _GLSL + "cosh(x): inherited from (exp(x) + exp(-x)) * 0.5",
             {"full": "inherited: 3.2-4 ULP near 0, ~3 + 2|x| ULP for large |x|; unbounded "
                      "where exp(|x|) may overflow",
              "relaxed": "inherited: 1-2 ULP-16 near 0, ~1 + 2|x| ULP-16 for large |x|"}),
    "tanh": (_tanh, _GLSL + "tanh(): inherited from sinh() / cosh()",
             {"full": "inherited: (sinh +- E_sinh) / (cosh +- E_cosh) + 2.5 ULP (~2^-22 absolute "
                      "near 0, ~2(3 + 2|x|) ULP for large |x|)",
              "relaxed": "inherited: the same in binary16 spacing"}),
}


def tolerance(func: str, precision: str) -> Tolerance:
    """The :class:`Tolerance` of ``func`` ('exp2', ..., 'pow') at
    ``precision`` ('full' or 'relaxed')."""
    if precision not in PRECISIONS:
        raise ValueError(f"precision must be one of {PRECISIONS}, not {precision!r}")
    if func not in _ROWS:
        raise ValueError(f"unknown function {func!r}; expected one of {tuple(_ROWS)}")
    make, citation, rules = _ROWS[func]
    unit = "ULP-32 (Vulkan ulp)" if precision == "full" else "ULP-16 (Vulkan ulp, binary16 spacing)"
    return Tolerance(func, precision, rules[precision], unit, citation, make(precision))
