"""What each call site can see over the whole declared domain: interval arithmetic on the traced IR.

``site_ranges`` (``ranges.py``) measures a site's operands on the check rows: exact where the check
is exhaustive, a sample otherwise. ``site_bounds`` proves them for every input of the domain: the
kernel's body is traced at width 1 (not compiled), each input's argument is given the hull of its
declared domain (``domains.hull``), and ``reactor.ir.intervals`` propagates intervals through the
IR. A routine call's result is not followed through the routine's bit manipulations: it is the
routine's function of its operands' intervals (:data:`ROUTINES`, on the ends, in float64), widened by
the error its least accurate tier is allowed (Vulkan's relaxed bounds, docs/accuracy.md), so the
bound holds whatever tier the plan gives the sites upstream. pow is exp2(y log2 x), as its bound is.

The bounds are checked against the measured ranges (every measured value must lie inside); a
site where one does not is reported and its bound is not used.
"""
from __future__ import annotations

import math
import typing

import numpy as np

from ..ir import intervals as iv
from ..ir.intervals import INF, Interval

Fn = typing.Callable[..., Interval]
_ULP16 = 2.0 ** -10  # binary16's relative spacing: the unit of relaxed precision's bounds


# -- widening by a tier's error ------------------------------------------------------------------

def _widen(v: float, rel: float, err: float, up: bool) -> float:
    """The end ``v`` moved outward by ``err`` and ``rel`` of itself (an infinite end stays; an
    unbounded ``rel`` sends a nonzero end to the infinity on its side)."""
    if not math.isfinite(v):
        return v
    step = err + (abs(v) * rel if v else 0.0)
    return v + step if up else v - step


def _relative(r: Interval, rel: float, tiny: float = 0.0, keep_sign: bool = True) -> Interval:
    """``r`` widened by ``rel`` of its ends and ``tiny`` absolute (a result that may flush or go
    subnormal); ``keep_sign``: a result that cannot be negative stays so."""
    if r.lo > r.hi:
        return r
    lo, hi = _widen(r.lo, rel, tiny, False), _widen(r.hi, rel, tiny, True)
    if keep_sign and r.lo >= 0:
        lo = max(lo, 0.0)
    return Interval(lo, hi, r.nan)


def _absolute(r: Interval, err: float, rel: float = 0.0) -> Interval:
    if r.lo > r.hi:
        return r
    return Interval(_widen(r.lo, rel, err, False), _widen(r.hi, rel, err, True), r.nan)


def _monotone(x: Interval, fn, lo_domain: float = -INF, increasing: bool = True) -> Interval:
    """fn over x where fn is monotone on [lo_domain, inf] (NaN below it)."""
    nan = x.nan or x.lo < lo_domain
    lo, hi = max(x.lo, lo_domain), x.hi
    if lo > hi:
        return Interval(INF, -INF, nan or not x.empty)
    a, b = _safe(fn, lo), _safe(fn, hi)
    return Interval(min(a, b), max(a, b), nan) if increasing else Interval(b, a, nan)


def _safe(fn, v: float) -> float:
    try:
        return fn(v)
    except OverflowError:
        return INF
    except ValueError:  # log(0)
        return -INF


# -- the routines' functions --------------------------------------------------------------------

def _exp2_of(t: Interval) -> Interval:
    r = _monotone(t, lambda v: 2.0 ** v if v < 1024 else INF)
    reach = max(abs(t.lo), abs(t.hi)) if t.finite else INF
    return _relative(r, (1 + 2 * reach) * _ULP16, tiny=2.0 ** -14)  # relaxed: 1 + 2|t| ULP-16


def exp2(x: Interval) -> Interval:
    return _exp2_of(x)


def exp(x: Interval) -> Interval:
    return _exp2_of(iv.mul(x, Interval(math.log2(math.e), math.log2(math.e)), "f64"))


def _log2_of(x: Interval) -> Interval:
    r = _monotone(x, lambda v: math.log2(v) if v > 0 else -INF, lo_domain=0.0)
    return _absolute(r, 2.0 ** -7, 3 * _ULP16)  # relaxed: 2^-7 absolute near 1, 3 ULP-16 elsewhere


def log2(x: Interval) -> Interval:
    return _log2_of(x)


def log(x: Interval) -> Interval:
    return iv.mul(_log2_of(x), Interval(math.log(2.0), math.log(2.0)), "f64")


def pow_(x: Interval, y: Interval) -> Interval:
    """exp2(y log2 x) for x >= 0; anything where x may be negative (NaN or a signed power)."""
    if x.lo < 0 and not x.empty:
        return iv.ANY
    r = _exp2_of(iv.mul(y, _log2_of(x), "f64"))
    return _signed_zero(x, r) if y.lo < 0 else r


def sqrt(x: Interval) -> Interval:
    return _relative(_monotone(x, math.sqrt, lo_domain=0.0), 4 * _ULP16)


def rsqrt(x: Interval) -> Interval:
    r = _monotone(x, lambda v: 1 / math.sqrt(v) if v > 0 else INF, lo_domain=0.0, increasing=False)
    r = _relative(r, 4 * _ULP16)
    return _signed_zero(x, r)


def _signed_zero(x: Interval, r: Interval) -> Interval:
    """``r`` joined with -inf where x may be zero: intervals do not tell -0 from +0, and
    rsqrt(-0) and pow(-0, y < 0) are -inf."""
    return r.join(Interval(-INF, -INF)) if x.has(0.0) else r


def rcp(x: Interval) -> Interval:
    return _relative(iv.div(Interval(1.0, 1.0), x, "f64"), 4 * _ULP16)


def _periodic(x: Interval, fn, peaks: float) -> Interval:
    """sin or cos over x: its ends, and +-1 where a peak (peaks + k pi/2 ... ) lies inside."""
    if not x.finite or x.hi - x.lo >= 2 * math.pi or max(-x.lo, x.hi) > 2.0 ** 20:  # (far out, the
        # peaks k pi + c cannot be stepped through in float64: a period is below its spacing)
        r = Interval(-1.0, 1.0, x.nan or not x.finite)
    else:
        a, b = fn(x.lo), fn(x.hi)
        lo, hi = min(a, b), max(a, b)
        k = math.ceil((x.lo - peaks) / math.pi)
        while peaks + k * math.pi <= x.hi:
            v = fn(peaks + k * math.pi)
            lo, hi = min(lo, v), max(hi, v)
            k += 1
        r = Interval(lo, hi, x.nan)
    return _absolute(r, 2.0 ** -6)  # relaxed: 2^-7 absolute on [-pi, pi]


def sin(x: Interval) -> Interval:
    return _periodic(x, math.sin, math.pi / 2)


def cos(x: Interval) -> Interval:
    return _periodic(x, math.cos, 0.0)


def tan(x: Interval) -> Interval:
    return iv.div(sin(x), cos(x), "f64")  # as its bound is: sin / cos


def _bounded(r: Interval) -> Interval:
    return _absolute(r, 2.0 ** -10, 2.0 ** -5)  # relaxed: 5 to ~20 ULP-16


def atan(x: Interval) -> Interval:
    return _bounded(_monotone(x, math.atan))


def asin(x: Interval) -> Interval:
    return _bounded(_clamped(x, math.asin, True))


def acos(x: Interval) -> Interval:
    return _bounded(_clamped(x, math.acos, False))


def _clamped(x: Interval, fn, increasing: bool) -> Interval:
    nan = x.nan or x.lo < -1 or x.hi > 1
    lo, hi = max(x.lo, -1.0), min(x.hi, 1.0)
    if lo > hi:
        return Interval(INF, -INF, True)
    a, b = fn(lo), fn(hi)
    return Interval(min(a, b), max(a, b), nan)


def atan2(y: Interval, x: Interval) -> Interval:
    return _bounded(Interval(-math.pi, math.pi, x.nan or y.nan or (not x.finite and not y.finite)))


def _hyperbolic_error(x: Interval) -> float:
    reach = max(abs(x.lo), abs(x.hi)) if x.finite else INF
    return (1 + 2 * reach * math.log2(math.e)) * _ULP16


def sinh(x: Interval) -> Interval:
    return _absolute(_monotone(x, lambda v: math.sinh(v) if abs(v) < 710 else math.copysign(INF, v)),
                     2.0 ** -10, _hyperbolic_error(x))


def cosh(x: Interval) -> Interval:
    m = iv.fabs(x)
    r = _monotone(m, lambda v: math.cosh(v) if v < 710 else INF)
    return _relative(r, _hyperbolic_error(x))


def tanh(x: Interval) -> Interval:
    return _absolute(_monotone(x, math.tanh), 2.0 ** -10, 2.0 ** -5)


#: routine -> its function on intervals (an operand's interval each), widened by its relaxed error
ROUTINES: dict[str, Fn] = {
    "exp2": exp2, "exp": exp, "log2": log2, "log": log, "pow": pow_, "sqrt": sqrt, "rsqrt": rsqrt,
    "rcp": rcp, "sin": sin, "cos": cos, "tan": tan, "atan": atan, "asin": asin, "acos": acos,
    "atan2": atan2, "sinh": sinh, "cosh": cosh, "tanh": tanh,
}


# -- the kernel, traced and analysed -----------------------------------------------------------

def site_bounds(kernel, hulls: dict[str, Interval]) -> dict[tuple[str, str], tuple]:
    """Per call site (the user's line, the routine) of the reactor ``kernel``: an
    ``ranges.OperandRange`` per operand, proved for every input whose element operands lie in
    ``hulls`` (input name -> Interval; an input not named: anything)."""
    from ..dsl.calls import recording_results
    from ..dsl.syntax import as_written
    from ..ir.emitter import ModuleEmitter
    from ..kernels.loop import emit_body

    module = ModuleEmitter(f"{kernel.name}_bounds", kernel.build)
    calls: list = []
    with recording_results(calls):
        function, _ = emit_body(module, kernel.name, as_written(kernel.body), kernel.ins, kernel.outs, 1)
    params: dict[int, Interval] = {}
    at = 0
    for name, o in zip(kernel.signature.names, kernel.ins):
        count = len(o.body_params(1))
        if name in hulls and not o.uniform:
            for k in range(at, at + count):
                params[k] = hulls[name]
        at += count
    summaries = {}
    for call in calls:
        fn = ROUTINES.get(call.name)
        result = getattr(call.result, "_ir", None)
        if fn is not None and result is not None and hasattr(result, "opname"):
            summaries[id(result)] = _summary(fn, call.args, call.block)
    analysis = iv.analyse(function, params, summaries)
    found: dict[tuple[str, str], list] = {}
    for call in calls:
        if not call.where:
            continue
        operands = [_operand(analysis, a, call.block) for a in call.args[:2 if call.name in ("pow", "atan2") else 1]]
        old = found.get((call.where, call.name))
        found[(call.where, call.name)] = operands if old is None else \
            [a if a is None or b is None else a.join(b) for a, b in zip(old, operands)]
    return {site: tuple(_as_range(x) for x in ops) for site, ops in found.items()}


def checked_bounds(search, seen: dict) -> tuple[dict, list]:
    """(per site of ``search``, its operands' bounds over the declared domain; the sites whose bound
    misses a value ``seen``, the ranges measured on the check rows, holds: not returned)."""
    from .domains import hulls
    spans = hulls(search.element_names, search.declared)
    found = site_bounds(search.kernel, {n: Interval(*h) for n, h in spans.items()})
    unsound = [site for site, ops in found.items()
               if not all(b.holds(m) for b, m in zip(ops, seen.get(site, ())))]
    return {k: v for k, v in found.items() if k not in unsound}, unsound


def _summary(fn: Fn, args: tuple, block):
    def interval(analysis) -> Interval:
        ops = [_operand(analysis, a, block) for a in args]
        if any(o is None for o in ops):
            return iv.ANY
        return as_float32(fn(*ops))
    return interval


_MAX32 = float(np.finfo(np.float32).max)


def as_float32(r: Interval) -> Interval:
    """A routine's float64 interval as its float32 results lie: an end beyond the largest float32
    goes to the infinity it may round to (and a lower end there stays at the largest float)."""
    if r.lo > r.hi:
        return r
    lo = -INF if r.lo < -_MAX32 else _MAX32 if r.lo > _MAX32 else r.lo
    hi = INF if r.hi > _MAX32 else -_MAX32 if r.hi < -_MAX32 else r.hi
    return Interval(lo, hi, r.nan)


def _operand(analysis, a, block) -> Interval | None:
    """A call's operand: its interval where the call runs (``block``: narrowed by the branches
    taken to it); None where it is not a float value the analysis follows."""
    if isinstance(a, bool):
        return None
    if isinstance(a, (int, float)):  # the float32 it becomes (routines take Float values: float_value)
        if math.isnan(a):
            return Interval(INF, -INF, True)
        with np.errstate(over="ignore"):
            single = float(np.float32(a))
        return Interval(single, single)
    ir_value = getattr(a, "_ir", None)
    kind = getattr(getattr(a, "kind", None), "name", None)
    if ir_value is None or kind != "Float":
        return None
    return analysis.at(ir_value, block)


def _as_range(x: Interval | None):
    from .ranges import OperandRange
    if x is None:
        return OperandRange(math.nan, math.nan, False, True, known=False)
    return OperandRange(x.lo, x.hi, x.nan, not x.empty)
