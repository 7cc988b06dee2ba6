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
=========  ==========================================  ========================================

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
"""

from __future__ import annotations

import math

from ..base import PRECISIONS
import threading
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .measures import spec_ulp16, spec_ulp32

SPEC = ("Vulkan 1.4.360, Appendix 'Vulkan Environment for SPIR-V', "
        "'Precision and Operation of SPIR-V Instructions'")

_UNIT = {"full": spec_ulp32, "relaxed": spec_ulp16}
_EXP_BASE = {"full": 3.0, "relaxed": 1.0}
_LOG_ABS = {"full": 2.0**-21, "relaxed": 2.0**-7}
_MUL_ROUNDING_ULP = 1.0  # implementation-defined rounding mode: < 1 ULP


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
