"""rcp (1/x), rsqrt (1/sqrt(x)) and sqrt.

Full precision refines the hardware estimate (RCP14/RSQRT14 with AVX-512,
relative error < 2^-14; RCPPS/RSQRTPS, < 1.5 * 2^-12, elsewhere) with one
Newton-Raphson step, written so the residual is computed with one rounding
when FMA is on:

    rcp:   e = 1 - x*r,         r' = r + r*e
    rsqrt: e = 1 - (x*r)*r,     r' = r + (r/2)*e

The step turns 0 -> inf and inf -> 0 into NaN (0 * inf in the residual; see
shared/refs/004), and so does an infinite estimate of a subnormal's
reciprocal (inf + inf * -inf). Wherever the refined value is NaN the estimate
is kept, which is exactly right in all these cases, and for NaN inputs (and
negative inputs of rsqrt) the estimate is NaN too.
Relaxed precision uses the estimate alone: its error is at most 1/16 (AVX-512)
or 3/8 of a binary16 ULP. Where a plan proved the operand's range (``Site.ranges``,
``routines.continuum.operand_range``) excludes every such case, the keep-the-estimate select is
not emitted: rsqrt of x in (0, +inf), rcp of a normal x of either sign (1/x normal or
subnormal, never infinite), relaxed sqrt of x in (0, +inf).

The faithful and correct tiers are correctly rounded: 1/x and sqrt(x) are single IEEE
operations, and rsqrt is 1/sqrt(x) in float64 (two roundings of relative 2^-53) rounded
once to float32, which the accuracy ladder's exhaustive sweep finds correctly rounded for
every input (``python -m routines ladder rsqrt --exhaustive``).

sqrt: full precision is the correctly rounded hardware square root; relaxed is
x * rsqrt_estimate(x), with ±0 and +inf (where that product is 0 * inf) passed
through.

The estimates are used only on AVX-512 targets: RCP14/RSQRT14 handle
subnormal inputs and results. The older RCPPS/RSQRTPS treat subnormal inputs
as zero and flush tiny results, which breaks both precisions at the edges, so
on other targets these routines divide and take square roots exactly
(correct everywhere, slower).
"""
from __future__ import annotations

from reactor import IsNan, MulAdd, Precision, RcpApprox, RsqrtApprox, Select, Sqrt, target_features, vector_type

from . import continuum
from .base import float_value, routine

_MIN_NORMAL, _MIN_SUBNORMAL, _MAX_FINITE = 2.0 ** -126, 2.0 ** -149, 3.4028234663852886e38


def _estimates_exact_at_edges() -> bool:
    return "avx512f" in target_features()


def _proved_positive(routine: str) -> bool:
    """A plan proved every operand of this call positive and finite (no NaN)."""
    span = continuum.operand_range(routine)
    return span is not None and span.within(_MIN_SUBNORMAL, _MAX_FINITE)


def _proved_normal(routine: str) -> bool:
    """A plan proved every operand of this call normal, all of one sign (no zero, infinity or NaN)."""
    span = continuum.operand_range(routine)
    return span is not None and (span.within(_MIN_NORMAL, _MAX_FINITE) or span.within(-_MAX_FINITE, -_MIN_NORMAL))


def _exact_tier(precision) -> bool:
    return precision in (Precision.FAITHFUL, Precision.CORRECT)


def _keep_estimate_where_nan(estimate, refined):
    return Select(IsNan(refined), estimate, refined)


@routine
def rcp(x, precision: Precision = Precision.FULL):
    """1/x: IEEE specials (1/±0 = ±inf, 1/±inf = ±0, NaN -> NaN)."""
    x = float_value(x, "rcp")
    if _exact_tier(precision) or not _estimates_exact_at_edges():
        return (1.0 / x).named("rcp")
    r = RcpApprox(x)
    if precision is Precision.RELAXED:
        return r.named("rcp")
    e = MulAdd(-x, r, 1.0)
    if _proved_normal("rcp"):  # the step is never NaN there
        return MulAdd(r, e, r).named("rcp")
    return _keep_estimate_where_nan(r, MulAdd(r, e, r)).named("rcp")


@routine
def rsqrt(x, precision: Precision = Precision.FULL):
    """1/sqrt(x): ±0 -> ±inf, +inf -> +0, x < 0 -> NaN, NaN -> NaN."""
    x = float_value(x, "rsqrt")
    if _exact_tier(precision):
        Double_ = vector_type("Double", x.width)
        return vector_type("Float", x.width)(1.0 / Sqrt(Double_(x))).named("rsqrt")
    if not _estimates_exact_at_edges():
        return (1.0 / Sqrt(x)).named("rsqrt")
    r = RsqrtApprox(x)
    if precision is Precision.RELAXED:
        return r.named("rsqrt")
    e = MulAdd(-(x * r), r, 1.0)
    if _proved_positive("rsqrt"):  # the step is never NaN there
        return MulAdd(r * 0.5, e, r).named("rsqrt")
    return _keep_estimate_where_nan(r, MulAdd(r * 0.5, e, r)).named("rsqrt")


@routine
def sqrt(x, precision: Precision = Precision.FULL):
    """sqrt(x): ±0 -> ±0, +inf -> +inf, x < 0 -> NaN, NaN -> NaN."""
    x = float_value(x, "sqrt")
    if precision is not Precision.RELAXED or not _estimates_exact_at_edges():
        return Sqrt(x).named("sqrt")
    s = x * RsqrtApprox(x)
    if _proved_positive("sqrt"):  # x * rsqrt(x) is 0 * inf only at 0 and +inf
        return s.named("sqrt")
    return Select(IsNan(s) & (x >= 0.0), x, s).named("sqrt")
