"""What each call site sees (reactor.planner.ranges), and the special-case paths a plan drops with it."""
from __future__ import annotations

import numpy as np
import pytest

import reactor
import routines
from reactor import Float, Min, Range, Site
from reactor.cost import kernel_cycles
from reactor.errors import ReactorError
from reactor.planner.ranges import site_ranges
from reactor.planner.search import Search
from reactor.targets import get_target
from routines import glsl as gl


def _search(ufunc, inputs, **kw):
    return Search(ufunc, inputs, "unorm8", samples=kw.get("samples", 1 << 14), seed=0, max_rows=1 << 24, fma=None,
                  log=None)


@reactor.kernel
def branchy(x: Float) -> Float:
    r = x * 0.0
    if x > 0.5:
        r = gl.log2(x)
    return r + gl.exp2(-3.0 * x) + gl.pow(x, 2.5)


def test_each_site_sees_the_values_of_the_rows_that_reach_it():
    found = site_ranges(_search(branchy, {"x": "unorm8"}))
    by = {routine: [(r.lo, r.hi, r.nan) for r in spans] for (_, routine), spans in found.items()}
    assert by["log2"] == [(np.float32(128 / 255), 1.0, False)]  # only the lanes that take the branch
    assert by["exp2"] == [(-3.0, 0.0, False)]
    assert by["pow"] == [(0.0, 1.0, False), (2.5, 2.5, False)]  # a constant operand: one value


@reactor.kernel
def never(x: Float) -> Float:
    r = x
    if x > 2.0:  # no unorm8 value takes it
        r = gl.log2(x)
    return r


def test_a_site_no_row_reaches_says_so_and_nan_is_counted():
    (spans,) = site_ranges(_search(never, {"x": "unorm8"})).values()
    assert spans[0].text() == "never reached"

    @reactor.kernel
    def nan_in(x: Float) -> Float:
        return gl.exp2(x / x)  # 0 / 0 at x = 0
    (spans,) = site_ranges(_search(nan_in, {"x": "unorm8"})).values()
    assert spans[0].nan and (spans[0].lo, spans[0].hi) == (1.0, 1.0)


def _two(x: Float) -> Float:
    return routines.exp2(x * 8.0 - 4.0) + routines.log2(x + 0.5)


def test_a_site_built_for_its_range_drops_special_paths_and_keeps_its_bits_there():
    base = reactor.kernel(_two, name="two", target="avx2")  # the portable paths: branches for special lanes
    where = reactor.kernel_of(base).routines[0].where
    ranged = reactor.kernel(_two, name="two", target="avx2", sites=[
        Site(where, "exp2", "full", None, ((-4.0, 4.0, False),)),
        Site(where, "log2", "full", None, ((0.5, 1.5, False),))])
    x = np.arange(1 << 16, dtype=np.float32) / (1 << 16)
    assert np.array_equal(base(x), ranged(x))
    assert kernel_cycles(reactor.kernel_of(ranged)) < kernel_cycles(reactor.kernel_of(base))
    # exp2's subnormal lanes and log2's special lanes were branches: gone
    assert reactor.kernel_of(ranged).code.ir_text.count("br i1") < reactor.kernel_of(base).code.ir_text.count("br i1")


def _lengths(x: Float, y: Float) -> Float:
    return gl.inversesqrt(x * x + y * y) + routines.rcp(x + 2.0)


def test_rsqrt_and_rcp_built_for_a_proved_range_drop_the_newton_steps_nan_select():
    """AVX-512's estimates refined by one Newton step keep the estimate where the step gives NaN
    (0, inf, subnormal reciprocals): not needed where a plan proved the operand away from them."""
    base = reactor.kernel(_lengths, name="lengths", target="avx512")
    calls = reactor.kernel_of(base).routines
    where = {c.name: c.where for c in calls}
    assert set(where) == {"rsqrt", "rcp"}
    ranged = reactor.kernel(_lengths, name="lengths", target="avx512", sites=[
        Site(where["rsqrt"], "rsqrt", "full", None, ((1e-4, 2.0, False),)),
        Site(where["rcp"], "rcp", "full", None, ((2.0, 3.0, False),))])
    count = lambda k: reactor.kernel_of(k).code.ir_text.count("fcmp uno")  # noqa: E731 - IsNan
    assert count(base) > 0 and count(ranged) == 0  # (the vector loop and the tail each had them)
    assert kernel_cycles(reactor.kernel_of(ranged)) < kernel_cycles(reactor.kernel_of(base))
    if "avx512f" in get_target("host").feature_set:  # runs here: the same bits there
        x = (np.arange(1, 1 << 12, dtype=np.float32) / (1 << 12))
        np.testing.assert_array_equal(base(x, x[::-1]), ranged(x, x[::-1]))


def test_site_ranges_are_checked():
    with pytest.raises(ReactorError, match=r"\(lo, hi, nan\) per operand"):
        Site("a.py:1", "exp2", "full", None, (1.0, 2.0))


@reactor.kernel
def gamma(c: Float, s: Float) -> Float:
    v = gl.pow(c, 2.2) * gl.exp2(s * 4.0 - 2.0)
    return gl.pow(Min(v, 1.0), 1.0 / 2.2)


def test_an_exhaustive_plan_builds_sites_for_their_proved_ranges_and_a_sampled_one_does_not(tmp_path):
    p = reactor.plan(gamma, inputs={"c": "unorm8", "s": "unorm8"}, output="unorm8", timing_rows=1 << 12)
    # the precision continuum: relaxed changes thousands of codes, and every site plans to a point
    # below full (full's form, a shorter polynomial) that changes none
    assert p.proof == "exhaustive" and p.changes["plan"] == 0 and p.changes["all relaxed"] > 1000
    tiers = [r.tier for r in p.reports]
    assert any(t.startswith("full-") for t in tiers) and "relaxed" not in tiers
    assert p.cycles["plan"] < p.cycles["all full"]
    pows = [r for r in p.reports if r.routine == "pow"]
    assert all(r.in_range for r in pows) and pows[0].sees == ["[0, 1]", "2.20000005"]
    assert "built for that range" in str(p) and p.changes["plan"] == 0
    assert any(s.ranges for s in p.sites)
    p.save(str(tmp_path / "p.json"))
    again = reactor.Plan.load(str(tmp_path / "p.json"))
    assert again.sites == p.sites  # the ranges travel with the plan
    c = np.arange(256, dtype=np.float32) / 255
    assert np.array_equal(again.apply(gamma)(c, c[::-1]), p.ufunc(c, c[::-1]))
    sampled = reactor.plan(gamma, inputs={"c": Range(0.0, 1.0), "s": "unorm8"}, output="unorm8",
                           samples=1 << 14, timing_rows=1 << 12)
    assert not any(s.ranges for s in sampled.sites) and not any(r.in_range for r in sampled.reports)
    assert all(r.sees for r in sampled.reports)  # measured on the sample all the same
