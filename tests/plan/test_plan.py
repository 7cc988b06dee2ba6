"""reactor.plan: per-call-site tiers that change no stored output, proved on the compiled kernels."""
import json
import subprocess
import sys

import numpy as np
import pytest

import reactor
from reactor import Float, Range, ReactorError, Rows, Select, Site, kernel
from reactor.planner.outputs import Output
from routines import glsl as gl


def decode(c):
    return Select(c <= 0.04045, c * (1.0 / 12.92), gl.pow((c + 0.055) * (1.0 / 1.055), 2.4))


def encode(v):
    return Select(v <= 0.0031308, v * 12.92, 1.055 * gl.pow(v, 1.0 / 2.4) - 0.055)


@kernel
def blit(c: Float) -> Float:
    return encode(decode(c))


@kernel
def scaled(x: Float, k: Float) -> Float:
    return gl.pow(x * k, 1.0 / 2.2) + gl.exp2(k)


CODES = np.arange(256, dtype=np.float64) / 255


def test_a_site_setting_changes_that_call_only():
    sites = [c for c in reactor.kernel_of(scaled).routines]
    assert [c.name for c in sites] == ["pow", "exp2"] and all(c.precision == "full" for c in sites)
    relaxed_pow = kernel(reactor.kernel_of(scaled).body, name="scaled", sites=[(sites[0].where, "pow", "relaxed")])
    got = {(c.name, c.precision) for c in reactor.kernel_of(relaxed_pow).routines}
    assert got == {("pow", "relaxed"), ("exp2", "full")}
    x = np.linspace(0, 1, 4096, dtype=np.float32)
    assert (relaxed_pow(x, np.float32(0.7)) != scaled(x, np.float32(0.7))).any()
    with pytest.raises(ReactorError, match="two settings"):
        kernel(reactor.kernel_of(scaled).body, name="scaled",
               sites=[(sites[0].where, "pow", "relaxed"), (sites[0].where, "pow", "full")])


def test_blit_to_unorm8_is_relaxed_everywhere_and_proved_on_every_code():
    p = reactor.plan(blit, inputs={"c": "unorm8"}, output="unorm8")
    assert p.proof == "exhaustive" and p.checked == 256
    assert [r.tier for r in p.reports] == ["relaxed", "relaxed"]
    assert p.changes["plan"] == 0 and p.changes["all relaxed"] == 0
    # independently: the planned kernel's stored codes equal the all-full kernel's on every code
    c = CODES.astype(np.float32)
    full = kernel(reactor.kernel_of(blit).body, name="blit", precision="full")
    q = Output("unorm8").quantize
    np.testing.assert_array_equal(q(p.ufunc(c)), q(full(c)))
    assert {x.precision for x in reactor.kernel_of(p.ufunc).routines} == {"relaxed"}
    assert p.cycles["plan"] < p.cycles["all full"]


def test_a_finer_format_keeps_full_and_shows_what_relaxed_would_change():
    p = reactor.plan(blit, inputs={"c": "unorm8"}, output="unorm10")
    assert p.changes["plan"] == 0 and p.changes["all relaxed"] > 0
    # full, or a point of the continuum below it (full's form, a shorter polynomial): never relaxed
    assert all(r.tier == "full" or r.tier.startswith("full-") for r in p.reports)
    for r in p.reports:  # the example input really changes with that site at its nearest cheaper point
        if r.below is None:  # already the cheapest point of its ladder
            continue
        assert r.below_changes > 0
        sites = [(s.where, s.routine, s.precision) for s in p.sites if (s.where, s.routine) != (r.where, r.routine)]
        lower = kernel(reactor.kernel_of(blit).body, name="blit", sites=sites + [(r.where, r.routine, r.below)])
        x = np.float32([r.below_example["c"]])
        q = Output("unorm10").quantize
        assert q(lower(x)) != q(p.ufunc(x))


def test_sampled_domains_say_so_and_are_checked_twice():
    p = reactor.plan(scaled, inputs={"x": Range(0.0, 1.0), "k": [1.0, 2.0]}, output="unorm8", samples=20000,
                     timing_rows=1 << 14)
    assert p.proof == "sample" and p.checked > 40000
    assert "sampled" in p.domain and "neighbours" in p.domain
    exp2 = [r for r in p.reports if r.routine == "exp2"][0]
    # exp2 of the whole numbers 1 and 2 is exact at every tier: nothing cheaper changes an output, so
    # the site is at its cheapest point (or at one whose cheaper neighbour is the same machine code)
    assert exp2.below is None or exp2.below_changes == 0


def test_joint_rows_and_tolerances():
    x = np.linspace(0.01, 1, 5000, dtype=np.float32)
    rows = Rows(x=x, k=np.full(x.size, 0.5, np.float32))
    p = reactor.plan(scaled, inputs={"rows": rows}, output={"ulp": 0}, timing_rows=1 << 14)
    assert p.proof == "exhaustive" and p.checked == 5000
    loose = reactor.plan(scaled, inputs={"rows": rows}, output={"abs": 0.01}, timing_rows=1 << 14)
    assert all(r.below is None or r.below_changes == 0 for r in loose.reports)
    assert any(r.tier == "relaxed" for r in loose.reports)


def test_output_formats_round_like_glsl():
    u8 = Output("unorm8").quantize
    assert list(u8(np.float32([0.49 / 255, 0.51 / 255, 1.51 / 255, -1, 2, np.nan]))) == [0, 1, 2, 0, 255, 0]
    h = Output("float16").quantize(np.float32([np.nan, -np.nan, 1.0]))
    assert h[0] == h[1] and h[2] == 0x3C00
    changed = Output({"ulp": 1}).changed(np.float32([1.0, 1.0, np.nan]),
                                         np.float32([np.nextafter(np.float32(1), np.float32(2)), 1.0000003, np.nan]))
    assert list(changed) == [False, True, False]


def test_mistakes_are_named():
    with pytest.raises(ReactorError, match="input 'k' has no domain"):
        reactor.plan(scaled, inputs={"x": "unorm8"})
    with pytest.raises(ReactorError, match="does not take"):
        reactor.plan(scaled, inputs={"x": "unorm8", "k": 1.0, "z": "unorm8"})
    with pytest.raises(ReactorError, match="output must be"):
        reactor.plan(blit, inputs={"c": "unorm8"}, output="unorm9")
    with pytest.raises(ReactorError, match="unknown input format"):
        reactor.plan(blit, inputs={"c": "unorm7"})
    with pytest.raises(ReactorError, match="no cost table for machine 'pentium'; the tables are zen4"):
        reactor.plan(blit, inputs={"c": "unorm8"}, machine="pentium")


def test_a_plan_ranks_by_the_cost_table_it_is_given(tmp_path):
    """An AVX2 kernel planned for a Zen 3 host: its cycles are the Zen 3 table's, and it says so."""
    from reactor.cost.model import kernel_cycles
    u = kernel(reactor.kernel_of(blit).body, name="blit", target="avx2")
    p = reactor.plan(u, inputs={"c": "unorm8"}, output="unorm10", machine="zen3", timing_rows=4096)
    assert p.machine == "zen3" and "(cycles modelled for zen3)" in str(p)
    assert p.cycles["plan"] == pytest.approx(kernel_cycles(reactor.kernel_of(p.ufunc), "zen3"))
    assert p.changes["plan"] == 0
    p.save(str(tmp_path / "p.json"))
    assert reactor.Plan.load(str(tmp_path / "p.json")).machine == "zen3"


SCENE = """
from reactor import Float, Select, kernel
from routines import glsl as gl

@kernel
def blit(c: Float) -> Float:
    v = gl.pow(c, 2.2)
    return gl.pow(v, 1.0 / 2.2)
"""


def _load(path):
    import importlib.util
    spec = importlib.util.spec_from_file_location(f"plan_scene_{abs(hash(str(path)))}_{path.stat().st_mtime_ns}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_saved_plan_is_reused_and_refused_once_the_kernel_changes(tmp_path):
    scene = tmp_path / "scene.py"
    scene.write_text(SCENE)
    module = _load(scene)
    p = reactor.plan(module.blit, inputs={"c": "unorm8"}, output="unorm8", timing_rows=1 << 12)
    p.save(tmp_path / "blit.plan.json")
    data = json.loads((tmp_path / "blit.plan.json").read_text())
    assert data["proof"] == "exhaustive" and data["sites"]
    again = reactor.Plan.load(tmp_path / "blit.plan.json")
    u = again.apply(module.blit)
    c = CODES.astype(np.float32)
    np.testing.assert_array_equal(u(c), p.ufunc(c))
    scene.write_text(SCENE.replace("2.2)", "2.4)"))
    changed = _load(scene)
    with pytest.raises(reactor.PlanStaleError, match="changed"):
        again.apply(changed.blit)


def test_command_line(tmp_path):
    scene = tmp_path / "scene.py"
    scene.write_text(SCENE)
    out = subprocess.run([sys.executable, "-m", "reactor", "plan", f"{scene}:blit", "--input", "c=unorm8",
                          "--save", str(tmp_path / "p.json")], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "exhaustive" in out.stdout and "pow" in out.stdout and (tmp_path / "p.json").exists()
    bad = subprocess.run([sys.executable, "-m", "reactor", "plan", f"{scene}:blit", "--input", "c=maybe"],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and "Traceback" not in bad.stderr and "domain" in bad.stderr


def test_vector_inputs_are_planned_over_rows():
    from reactor import vec3

    @kernel
    def lit(n: vec3, l: vec3) -> Float:
        return gl.pow(gl.max(gl.dot(gl.normalize(n), l), 0.0), 7.5)

    rng = np.random.default_rng(0)
    n = rng.standard_normal((3000, 3)).astype(np.float32)
    l = np.tile(np.float32([0, 0, 1]), (3000, 1))
    p = reactor.plan(lit, inputs={"rows": Rows(n=n, l=l)}, output="unorm8", timing_rows=1 << 12)
    assert p.proof == "exhaustive" and p.changes["plan"] == 0
    assert {r.routine for r in p.reports} == {"rsqrt", "pow"}
    with pytest.raises(ReactorError, match="3 channels"):
        reactor.plan(lit, inputs={"n": "unorm8", "l": "unorm8"})


@kernel
def natural_log(x: Float) -> Float:
    return gl.log(x)


def test_the_reference_is_correctly_rounded_and_a_site_full_would_change_is_raised():
    """The reference is every routine at the most accurate tier (correct); where full changes a
    stored output (log near 1: thousands of ULP), the plan keeps the site above it: faithful when
    the format tolerates its last-bit differences, correct when it stores every bit."""
    x = np.linspace(1.0, 1.001, 4097, dtype=np.float32)
    loose = reactor.plan(natural_log, inputs={"x": x}, output={"ulp": 1})
    assert [r.tier for r in loose.reports] == ["faithful"] and loose.reports[0].below_changes > 0
    assert loose.changes["all full"] > 0 and loose.changes["plan"] == 0
    exact = reactor.plan(natural_log, inputs={"x": x}, output="float32")
    assert [r.tier for r in exact.reports] == ["correct"] and exact.changes["all faithful"] > 0
    assert (exact.ufunc(x) == np.log(x.astype(np.float64)).astype(np.float32)).all()
    assert "the speed of all full" in str(loose) and "the speed of all correct" in str(loose)


def test_a_second_plan_takes_the_modelled_costs_from_the_cache(monkeypatch):
    """Modelling a build reads its optimized IR, which a build from the disk cache would trace and
    optimize again: the costs are kept under the code's key, so planning again models nothing."""
    from reactor.planner import search
    first = reactor.plan(blit, inputs={"c": "unorm8"}, output="unorm8", timing_rows=1 << 12)
    search._cycles.clear()  # as a fresh process: only the disk cache remembers

    def unused(kern, machine=None):
        raise AssertionError(f"modelled again: {kern.name}")
    monkeypatch.setattr(search, "kernel_cycles", unused)
    again = reactor.plan(blit, inputs={"c": "unorm8"}, output="unorm8", timing_rows=1 << 12)
    assert again.sites == first.sites and again.cycles == first.cycles
