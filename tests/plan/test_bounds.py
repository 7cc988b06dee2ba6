"""Interval arithmetic on the traced IR (reactor.ir.intervals, reactor.planner.bounds): sound against
float32 arithmetic and against the compiled kernel run on its domain, and used by sampled plans."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import reactor
from reactor import Float, Max, Min, Range, Select, Variable
from reactor.ir import intervals as iv
from reactor.ir.intervals import Interval
from reactor.planner import bounds
from reactor.planner.bounds import checked_bounds, site_bounds
from reactor.planner.ranges import site_ranges
from reactor.planner.search import Search
from routines import glsl as gl

F32 = st.floats(width=32, allow_nan=False, allow_infinity=True)


def _interval(draw_a, draw_b) -> Interval:
    lo, hi = sorted((draw_a, draw_b))
    return Interval(lo, hi)


def _inside(r: Interval, values: np.ndarray) -> bool:
    v = values[~np.isnan(values)].astype(np.float64)
    return bool(np.all((v >= r.lo) & (v <= r.hi))) and (r.nan or not np.isnan(values).any())


def _points(r: Interval, t: float) -> np.float32:
    if r.lo == r.hi:
        return np.float32(r.lo)
    if not (math.isfinite(r.lo) and math.isfinite(r.hi)):
        return np.float32(r.lo if t < 0.5 else r.hi)
    return np.float32(np.clip(r.lo + (r.hi - r.lo) * t, r.lo, r.hi))


@settings(max_examples=400, deadline=None)
@given(F32, F32, F32, F32, st.lists(st.tuples(st.floats(0, 1), st.floats(0, 1)), min_size=1, max_size=8))
def test_float32_arithmetic_lands_inside_its_interval(a0, a1, b0, b1, ts):
    a, b = _interval(a0, a1), _interval(b0, b1)
    x = np.array([_points(a, s) for s, _ in ts] + [np.float32(a.lo), np.float32(a.hi)], np.float32)
    y = np.array([_points(b, t) for _, t in ts] + [np.float32(b.hi), np.float32(b.lo)], np.float32)
    with np.errstate(all="ignore"):
        assert _inside(iv.add(a, b), x + y)
        assert _inside(iv.add(a, iv.neg(b)), x - y)
        assert _inside(iv.mul(a, b), x * y)
        assert _inside(iv.square(a), x * x)
        assert _inside(iv.div(a, b), x / y)
        assert _inside(iv.sqrt(a), np.sqrt(x))
        exact = (x.astype(np.float64) * y + y).astype(np.float32)  # fma(x, y, y), rounded once
        assert _inside(iv.fma(a, b, b), exact) or not np.all(np.isfinite(exact))
        assert _inside(iv.minimum(a, b, False), np.where(x < y, x, y))
        assert _inside(iv.maximum(a, b, True), np.fmax(x, y))


def test_outward_rounding_keeps_exact_ends_and_signs():
    assert iv.mul(Interval(0.0, 1.0), Interval(0.5, 2.0)) == Interval(0.0, 2.0)
    third = iv.div(Interval(1.0, 1.0), Interval(3.0, 3.0))
    assert third.lo <= float(np.float32(1 / 3)) <= third.hi and third.hi - third.lo <= 2 ** -24  # one step
    assert iv.add(Interval(math.inf, math.inf), Interval(-math.inf, -math.inf)).nan  # inf - inf
    assert iv.mul(Interval(0.0, 0.0), Interval(math.inf, math.inf)).nan  # 0 * inf
    assert not iv.mul(Interval(1.0, 2.0), Interval(3.0, 4.0)).nan


def _site(kernel_fn, hull):
    found = site_bounds(reactor.kernel_of(kernel_fn), hull)
    (spans,) = found.values()
    return spans


@reactor.kernel
def shapes(x: Float, y: Float) -> Float:
    v = Min(x * x + 0.25 * y, 1.0)               # clipped: at most 1
    w = Select(x > 0.5, v, Max(y - x, 0.0))       # both sides joined
    acc = Variable(w)
    acc.set(Max(acc.value * 0.5, w))
    return gl.sqrt(acc.value + abs(y) * 0.125)


@reactor.kernel
def shapes_value(x: Float, y: Float) -> Float:
    v = Min(x * x + 0.25 * y, 1.0)
    w = Select(x > 0.5, v, Max(y - x, 0.0))
    acc = Variable(w)
    acc.set(Max(acc.value * 0.5, w))
    return acc.value + abs(y) * 0.125


def test_a_bound_holds_on_the_compiled_kernel_over_its_domain():
    hull = {"x": Interval(-2.0, 3.0), "y": Interval(-1.0, 4.0)}
    (span,) = _site(shapes, hull)
    assert span.known and not span.nan and -0.25 <= span.lo and span.hi <= 6.5  # by hand: [-0.25, 6.5]
    rng = np.random.default_rng(1)
    x = np.concatenate([rng.uniform(-2, 3, 200_000), [-2, 3]]).astype(np.float32)
    y = np.concatenate([rng.uniform(-1, 4, 200_000), [-1, 4]]).astype(np.float32)
    got = shapes_value(x, y)
    assert span.lo <= got.min() and got.max() <= span.hi


@reactor.kernel
def looped(x: Float) -> Float:
    acc = Variable(x)
    i = Variable(reactor.Int(0))
    with reactor.While(lambda: i.value < 4):
        acc.set(acc.value * 1.5 + 1.0)
        i.set(i.value + 1)
    return gl.exp2(acc.value)


@reactor.kernel
def guarded(x: Float) -> Float:
    r = x * 0.0
    if x > 0.25:
        r = gl.log2(x)
    elif x < -0.5:
        r = gl.exp2(x)
    else:
        r = gl.sqrt(x + 1.0)
    return r


def test_a_site_inside_a_branch_is_bounded_by_the_conditions_that_lead_to_it():
    found = site_bounds(reactor.kernel_of(guarded), {"x": Interval(-1.0, 1.0)})
    by = {routine: (spans[0].lo, spans[0].hi) for (_, routine), spans in found.items()}
    assert by == {"log2": (0.25, 1.0), "exp2": (-1.0, -0.5), "sqrt": (0.5, 1.25)}
    search = Search(guarded, {"x": Range(-1.0, 1.0)}, "unorm8", samples=1 << 12, seed=0, max_rows=1 << 24,
                    fma=None, log=None)
    proved, unsound = checked_bounds(search, site_ranges(search))
    assert not unsound and len(proved) == 3


def test_a_loop_widens_to_a_sound_bound():
    (span,) = _site(looped, {"x": Interval(0.0, 1.0)})
    assert span.lo <= 0.0 and span.hi >= 1.5 ** 4 * 1 + 1.5 ** 3 + 1.5 ** 2 + 1.5 + 1


@reactor.kernel
def chain(c: Float, s: Float) -> Float:
    v = gl.pow(c, 2.2) * gl.exp2(s * 4.0 - 2.0)
    return gl.pow(Min(v, 1.0), 1.0 / 2.2)


def test_routine_results_are_their_functions_widened_by_their_error():
    found = site_bounds(reactor.kernel_of(chain), {"c": Interval(0.0, 1.0), "s": Interval(0.0, 1.0)})
    by = {(routine, k): r for (_, routine), spans in found.items() for k, r in enumerate(spans)}
    assert (by[("exp2", 0)].lo, by[("exp2", 0)].hi) == (-2.0, 2.0)
    assert by[("pow", 0)].lo >= 0.0 and by[("pow", 0)].hi <= 1.0  # both pow sites: [0, 1]
    assert by[("pow", 1)].lo <= np.float32(1 / 2.2) <= by[("pow", 1)].hi or by[("pow", 1)].lo >= 2.2


def test_bounds_are_checked_against_the_rows_run(monkeypatch):
    search = Search(chain, {"c": "unorm8", "s": Range(0.0, 1.0)}, "unorm8", samples=1 << 12, seed=0,
                    max_rows=1 << 24, fma=None, log=None)
    seen = site_ranges(search)
    proved, unsound = checked_bounds(search, seen)
    assert not unsound and len(proved) == 3
    for site, spans in proved.items():
        assert all(b.holds(m) for b, m in zip(spans, seen[site]))
    monkeypatch.setitem(bounds.ROUTINES, "pow", lambda x, y: Interval(0.5, 0.6))  # a wrong summary
    proved, unsound = checked_bounds(search, seen)
    assert [r for _, r in unsound] == ["pow"]  # the second pow's base, pow(c, 2.2) * exp2(...): [0.125, 1]
    assert {r for _, r in proved} == {"pow", "exp2"} and len(proved) == 2


@reactor.kernel
def sampled(x: Float, y: Float) -> Float:
    return gl.pow(x * 0.5 + 0.25, y * 2.0 + 1.0)


def test_a_sampled_plan_builds_a_site_for_its_proved_range():
    plan = reactor.plan(sampled, inputs={"x": Range(0, 1), "y": Range(0, 1)}, output="unorm8", samples=1 << 13,
                        timing_rows=1 << 12)
    assert plan.proof == "sample" and plan.changes["plan"] == 0
    (report,) = plan.reports
    assert report.in_range and report.bounds and report.bounds[0].startswith("[0.25")
    (site,) = plan.sites
    assert site.ranges and site.ranges[0][0] >= 0.25  # the bound over the domain, not the sample's


def test_neighbour_rows_stay_in_the_declared_domain():
    search = Search(sampled, {"x": Range(0, 1), "y": Range(0, 1)}, "unorm8", samples=1 << 12, seed=0,
                    max_rows=1 << 24, fma=None, log=None)
    search.sharpen()
    for name in ("x", "y"):
        col = search.check.columns[name]
        assert col.min() >= 0.0 and col.max() <= 1.0


@pytest.mark.parametrize("routine, lo, hi", [
    ("exp2", -30.0, 30.0), ("exp", -20.0, 20.0), ("log2", 0.0, 8.0), ("log", 1e-3, 100.0), ("pow", 0.0, 3.0),
    ("sqrt", 0.0, 9.0), ("rsqrt", 0.0, 4.0), ("rcp", 0.25, 8.0), ("sin", -10.0, 10.0), ("cos", -100.0, 100.0),
    ("tan", 0.0, 1.5), ("atan", -10.0, 10.0), ("asin", -1.0, 1.0), ("acos", -1.0, 1.0), ("atan2", -1.0, 1.0),
    ("sinh", -5.0, 5.0), ("cosh", -3.0, 2.0), ("tanh", -5.0, 5.0)])
def test_routine_summaries_hold_on_the_routines(routine, lo, hi):
    """Every routine's interval function, on its relaxed build (the least accurate tier it covers)."""
    assert set(bounds.ROUTINES) == {"exp2", "exp", "log2", "log", "pow", "sqrt", "rsqrt", "rcp", "sin", "cos", "tan",
                                    "atan", "asin", "acos", "atan2", "sinh", "cosh", "tanh"}
    fn = (lambda *ops: bounds.as_float32(bounds.ROUTINES[routine](*ops)))
    x = np.linspace(lo, hi, 4097).astype(np.float32)
    import routines
    body = getattr(routines, routine)
    if routine in ("atan2", "pow"):
        u = reactor.kernel(lambda a, b: body(a, b, precision="relaxed"), signatures="float32(float32, float32)")
        got = u(x, x[::-1].copy())
        r = fn(Interval(lo, hi), Interval(lo, hi))
    else:
        u = reactor.kernel(lambda a: body(a, precision="relaxed"), signatures="float32(float32)")
        got = u(x)
        r = fn(Interval(lo, hi))
    assert _inside(r, got)


_RELAXED: dict = {}


def _relaxed(routine: str):
    import routines
    if routine not in _RELAXED:
        body = getattr(routines, routine)
        two = routine in ("atan2", "pow")
        _RELAXED[routine] = reactor.kernel(
            (lambda a, b: body(a, b, precision="relaxed")) if two else (lambda a: body(a, precision="relaxed")),
            signatures="float32(float32, float32)" if two else "float32(float32)")
    return _RELAXED[routine]


ANY_F32 = st.floats(width=32, allow_nan=False, allow_infinity=True)


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(sorted(bounds.ROUTINES)), ANY_F32, ANY_F32, ANY_F32, ANY_F32,
       st.lists(st.floats(0, 1), min_size=1, max_size=16))
def test_routine_summaries_hold_anywhere(routine, a0, a1, b0, b1, ts):
    """On any intervals (infinities included), the relaxed routine's results at their ends and
    points inside lie in the summary's interval (NaN only where it allows NaN)."""
    a, b = _interval(a0, a1), _interval(b0, b1)
    x = np.array([_points(a, t) for t in ts] + [a.lo, a.hi], np.float32)
    y = np.array([_points(b, t) for t in ts] + [b.hi, b.lo], np.float32)
    fn = (lambda *ops: bounds.as_float32(bounds.ROUTINES[routine](*ops)))
    with np.errstate(all="ignore"):
        if routine in ("atan2", "pow"):
            assert _inside(fn(a, b), _relaxed(routine)(x, y)), (routine, a, b)
        else:
            assert _inside(fn(a), _relaxed(routine)(x)), (routine, a)


_LEAVES = st.one_of(st.sampled_from(["x", "y"]), st.floats(-4, 4, width=32))
_TREES = st.recursive(_LEAVES, lambda inner: st.one_of(
    st.tuples(st.sampled_from(["+", "-", "*", "/", "min", "max"]), inner, inner),
    st.tuples(st.sampled_from(["abs", "neg", "floor", "sqrt_abs", "square"]), inner),
    st.tuples(st.sampled_from(["select", "if"]), st.sampled_from(["<", ">"]), inner, inner, inner, inner)),
    max_leaves=8)


def _evaluate(tree, x, y):
    """A DSL expression of the tree (leaves: the inputs and float32 constants)."""
    if isinstance(tree, str):
        return x if tree == "x" else y
    if isinstance(tree, float):
        return tree
    op, *args = tree
    if op in ("select", "if"):
        test, a, b, yes, no = args
        a, b = _evaluate(a, x, y), _evaluate(b, x, y)
        cond = (x * 0.0 + a) < b if test == "<" else (x * 0.0 + a) > b
        if op == "select":
            return Select(cond, _evaluate(yes, x, y) + x * 0.0, _evaluate(no, x, y) + x * 0.0)
        r = Variable(x * 0.0)            # a per-lane branch: each side computed where it is taken
        with reactor.If(cond):
            r.set(_evaluate(yes, x, y) + x * 0.0)
        with reactor.Else():
            r.set(_evaluate(no, x, y) + x * 0.0)
        return r.value
    vals = [_evaluate(a, x, y) for a in args]
    vals = [v if not isinstance(v, float) else x * 0.0 + v for v in vals]
    if op in ("+", "-", "*", "/"):
        a, b = vals
        return {"+": a + b, "-": a - b, "*": a * b, "/": a / b}[op]
    if op in ("min", "max"):
        return (Min if op == "min" else Max)(*vals)
    (a,) = vals
    return {"abs": abs(a), "neg": -a, "floor": reactor.Floor(a), "sqrt_abs": reactor.Sqrt(abs(a)),
            "square": a * a}[op]


@settings(max_examples=25, deadline=None)
@given(_TREES)
def test_random_expressions_stay_in_their_bound_on_the_compiled_kernel(tree):
    """A random expression of x in [-2, 3] and y in [0.5, 4], with selects and per-lane branches:
    its interval (the operand of a sqrt site) holds every value the compiled kernel computes on 4,096
    rows of the domain and its ends."""
    site = reactor.kernel(lambda x, y: gl.sqrt(_evaluate(tree, x, y)), signatures="float32(float32, float32)")
    value = reactor.kernel(lambda x, y: _evaluate(tree, x, y), signatures="float32(float32, float32)")
    (span,) = _site(site, {"x": Interval(-2.0, 3.0), "y": Interval(0.5, 4.0)})
    rng = np.random.default_rng(0)
    x = np.concatenate([rng.uniform(-2, 3, 4096), [-2, 3, -2, 3, 0]]).astype(np.float32)
    y = np.concatenate([rng.uniform(0.5, 4, 4096), [0.5, 4, 4, 0.5, 1]]).astype(np.float32)
    with np.errstate(all="ignore"):
        got = value(x, y)
    bound = Interval(span.lo, span.hi, span.nan)
    assert _inside(bound, got), (tree, span, got[~np.isnan(got)].min(), got[~np.isnan(got)].max())
