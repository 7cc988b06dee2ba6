"""Float64 references for the lab's float32 routines, and their mpmath audit.

``reference(func, x[, y])`` converts the float32 operands to float64 (exact)
and evaluates the function once in float64 with NumPy:

=====  =================================  =====================================
func   float64 evaluation                 special values (IEEE 754)
=====  =================================  =====================================
exp2   ``np.exp2`` (x clipped to +-1000)  exp2(-inf) = +0, exp2(+inf) = +inf
exp    ``np.exp`` (x clipped to +-690)    likewise
log2   ``np.log2``                        log2(+-0) = -inf, log2(x<0) = NaN
log    ``np.log``                         likewise
rcp    ``1.0 / x``                        rcp(+-0) = +-inf, rcp(+-inf) = +-0
rsqrt  ``1.0 / np.sqrt(x)``               rsqrt(+-0) = +-inf, rsqrt(x<0) = NaN
sqrt   ``np.sqrt``                        sqrt(-0) = -0, sqrt(x<0) = NaN
pow    ``np.power`` for finite x > 0,     the exact value of exp2(y*log2(x))
       x != 1                             with IEEE rules at each step
sin    ``np.sin`` (glibc: exact argument  sin(+-0) = +-0, sin(+-inf) = NaN
       reduction for every double)
cos    ``np.cos``                         cos(+-inf) = NaN
tan    ``np.tan``                         tan(+-0) = +-0, tan(+-inf) = NaN
asin   ``np.arcsin``                      asin(+-0) = +-0, NaN outside [-1, 1]
acos   ``np.arccos``                      acos(1) = +0, NaN outside [-1, 1]
atan   ``np.arctan``                      atan(+-inf) = +-pi/2
atan2  ``np.arctan2`` (C99 atan2)         atan2(+-0, -0) = +-pi, atan2(+-inf, -inf)
                                          = +-3pi/4, ...: every C99 special case
sinh   ``np.sinh`` (x clipped to +-1000)  sinh(+-inf) = +-inf, sinh(-0) = -0
cosh   ``np.cosh`` (x clipped to +-1000)  cosh(+-inf) = +inf
tanh   ``np.tanh``                        tanh(+-inf) = +-1, tanh(-0) = -0
=====  =================================  =====================================

The binary functions take their operands in the routine's order:
``reference("atan2", a, b)`` is atan2(a, b), the angle of the point (b, a);
the lab calls the first operand ``x`` and the second ``y`` throughout.

pow follows its Vulkan/GLSL definition exp2(y * log2(x)) rather than C99
``powf``: x < 0 gives NaN (log2 of a negative), pow(+-0, y>0) = +0,
pow(+-0, y<0) = +inf, pow(0, 0), pow(inf, 0), pow(1, +-inf), pow(NaN, 0) and
pow(1, NaN) are NaN (C99 returns 1 for several of these).

Accuracy.  Each reference is one correctly-rounded or libm float64 operation
(rsqrt: two), so its relative error is a few float64 ULPs at most; one
float64 ULP is 2**-29..2**-28 (2e-9..4e-9) ULP-32 of the float32 result, so a
reported error moves by ~1e-8 ULP-32 at most, far below the 1e-6 that could
show in a report.  ``audit`` measures it against mpmath (max 2.8e-9 ULP-32
on 3000 sample points per function).  The exp/exp2 clipping keeps NumPy off
its slow float64 overflow/underflow path; clipped values round to the same
float32 (+-inf or +0) and are within 2**-800 ULP-32 of the exact value.
"""

from __future__ import annotations

from dataclasses import dataclass

import mpmath
import numpy as np

from .measures import MIN_NORMAL32, OVERFLOW32

FUNCS = ("exp2", "exp", "log2", "log", "pow", "rcp", "rsqrt", "sqrt",
         "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh")
BINARY = ("pow", "atan2")
ARITY = {f: 2 if f in BINARY else 1 for f in FUNCS}

_F64 = np.float64


#: |x| beyond which exp2/exp overflow or underflow float32 by far; arguments
#: are clipped there (keeping +-inf) to stay off NumPy's slow float64
#: overflow/underflow path.  The clipped reference still rounds to the same
#: float32 (+-inf or +0) and differs from the exact value by < 2**-800 ULP-32.
_EXP_CLIP = {"exp2": 1000.0, "exp": 690.0, "sinh": 1000.0, "cosh": 1000.0}
_CLIPPED = {"exp2": np.exp2, "exp": np.exp, "sinh": np.sinh, "cosh": np.cosh}
_PLAIN = {"log2": np.log2, "log": np.log, "sqrt": np.sqrt, "sin": np.sin, "cos": np.cos,
          "tan": np.tan, "asin": np.arcsin, "acos": np.arccos, "atan": np.arctan, "tanh": np.tanh}


def _exp(func, x, out):
    bound = _EXP_CLIP[func]
    out = np.clip(x, -bound, bound, out=np.empty(x.shape) if out is None else out,
                  dtype=_F64)
    infinite = np.flatnonzero(np.isinf(x))
    out.flat[infinite] = x.flat[infinite]
    return _CLIPPED[func](out, out=out)


def _unary(func, x, out):
    if func in _CLIPPED:
        return _exp(func, x, out)
    if func in ("asin", "acos"):  # NumPy is slow outside the domain (the invalid flag): NaN directly
        out = np.clip(x, -1.0, 1.0, out=np.empty(x.shape) if out is None else out, dtype=_F64)
        _PLAIN[func](out, out=out)
        np.copyto(out, np.nan, where=np.abs(x) > 1)
        return out
    if func in _PLAIN:
        return _PLAIN[func](x, out=out, dtype=_F64)
    if func == "rcp":
        return np.divide(1.0, x, out=out, dtype=_F64)
    if func == "rsqrt":
        out = np.sqrt(x, out=out, dtype=_F64)
        return np.divide(1.0, out, out=out)
    raise ValueError(f"unknown function {func!r}; expected one of {FUNCS}")


def _pow(x, y, out):
    x = np.asarray(x, dtype=_F64)
    y = np.asarray(y, dtype=_F64)
    out = np.power(x, y, out=out)
    special = ~((x > 0) & (x < np.inf) & (x != 1))
    if np.any(special):
        formula = np.exp2(y * np.log2(x))
        np.copyto(out, formula, where=special)
    return out


def reference(func, x, y=None, out=None):
    """Float64 reference of ``func`` at float32 operands ``x`` (and ``y``).

    ``out`` -- optional float64 buffer of the broadcast shape.
    """
    x = np.asarray(x, dtype=np.float32)
    with np.errstate(all="ignore"):
        if func in BINARY:
            if y is None:
                raise ValueError(f"{func} needs y")
            y = np.asarray(y, dtype=np.float32)
            if func == "pow":
                return _pow(x, y, out)
            return np.arctan2(x, y, out=out, dtype=_F64)
        if y is not None:
            raise ValueError(f"{func} is unary")
        return _unary(func, x, out)


_MPMATH = {"sin": mpmath.sin, "cos": mpmath.cos, "tan": mpmath.tan, "atan": mpmath.atan,
           "sinh": mpmath.sinh, "cosh": mpmath.cosh, "tanh": mpmath.tanh}


def _exact(func, x, y):
    """Exact value (mpmath, current precision) or None outside the domain."""
    X = mpmath.mpf(float(x))
    if not mpmath.isfinite(X):
        return None
    if func in _MPMATH:  # mpmath raises its working precision for the reduction of large x
        return _MPMATH[func](X)
    if func in ("asin", "acos"):
        return None if abs(X) > 1 else (mpmath.asin(X) if func == "asin" else mpmath.acos(X))
    if func == "atan2":
        Y = mpmath.mpf(float(y))
        # zero operands: the result's sign and +-pi depend on signed zeros (fixed by C99, tested)
        return None if not mpmath.isfinite(Y) or X == 0 or Y == 0 else mpmath.atan2(X, Y)
    if func == "exp2":
        return mpmath.power(2, X)
    if func == "exp":
        return mpmath.exp(X)
    if func in ("log2", "log"):
        return None if X <= 0 else (mpmath.log(X, 2) if func == "log2" else mpmath.log(X))
    if func == "rcp":
        return None if X == 0 else 1 / X
    if func == "rsqrt":
        return None if X <= 0 else 1 / mpmath.sqrt(X)
    if func == "sqrt":
        return None if X < 0 else mpmath.sqrt(X)
    Y = mpmath.mpf(float(y))
    return None if X <= 0 or not mpmath.isfinite(Y) else mpmath.power(X, Y)


def _ulp32(e):
    if abs(e) < MIN_NORMAL32:
        return mpmath.ldexp(1, -149)
    return mpmath.ldexp(1, mpmath.frexp(e)[1] - 1 - 23)


def _error_ulp32(ref, exact):
    """Error of the float64 ``ref`` in ULP-32 of ``exact``."""
    if abs(exact) >= OVERFLOW32:  # both must round to the same float32 infinity
        same = abs(ref) >= OVERFLOW32 and (ref > 0) == (exact > 0)
        return 0.0 if same else float("inf")
    if not np.isfinite(ref):
        return float("inf")
    return float(abs(mpmath.mpf(ref) - exact) / _ulp32(exact))


@dataclass
class AuditReport:
    """Error of :func:`reference` vs mpmath, in ULP-32 of the exact value.

    ``errors`` has one entry per input (NaN where skipped: non-finite
    operands or outside the real domain, whose IEEE special values are fixed
    by definition rather than computed).
    """

    func: str
    dps: int
    audited: int
    skipped: int
    max_ulp32: float
    worst_x: float | None
    worst_y: float | None
    errors: np.ndarray


def audit(func, xs, ys=None, dps=60) -> AuditReport:
    """Compare ``reference(func, xs[, ys])`` with mpmath at ``dps`` digits.

    Points whose exact value overflows float32 count as exact (0) when the
    reference also rounds to the same-signed float32 infinity, else ``inf``.
    """
    xs = np.atleast_1d(np.asarray(xs, dtype=np.float32))
    ys = None if ys is None else np.broadcast_to(np.asarray(ys, dtype=np.float32), xs.shape)
    refs = reference(func, xs, ys)
    errors = np.full(xs.shape, np.nan)
    with mpmath.workdps(dps):
        for i, x in enumerate(xs):
            exact = _exact(func, x, None if ys is None else ys[i])
            if exact is not None:
                errors[i] = _error_ulp32(float(refs[i]), exact)
    audited = int(np.count_nonzero(~np.isnan(errors)))
    worst = int(np.nanargmax(errors)) if audited else None
    return AuditReport(
        func=func, dps=dps, audited=audited, skipped=xs.size - audited,
        max_ulp32=float(errors[worst]) if audited else 0.0,
        worst_x=None if worst is None else float(xs[worst]),
        worst_y=None if worst is None or ys is None else float(ys[worst]),
        errors=errors)
