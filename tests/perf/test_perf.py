"""Fast tests of the performance tools: Pareto frontier and hull, the chart,
clock calibration, the cost model's pipe sharing and loop iteration, peers
reported absent, the trigonometric peers and inputs, a tiny run of the report
(its JSON keys, exp2 and the trigonometric functions), the bench, and the
report's command without matplotlib."""
from __future__ import annotations

import json
import re
import math
import subprocess
import sys

import numpy as np
import pytest

from reactor.cost import cpus, model
from routines.perf.report.summary import summary
from routines.perf import chart, clock, peers, report, timing


# -- Pareto frontier and lower convex hull ------------------------------------------------

POINTS = [(1, 10), (2, 5), (3, 4.5), (4, 1), (2.5, 8), (5, 0.9), (6, 0.95), (1, 12), (4, 1)]


def test_pareto_front_known_points():
    # (2.5, 8) is beaten by (2, 5); (6, .95) by (5, .9); (1, 12) by (1, 10);
    # the second (4, 1) duplicates the first.
    assert chart.pareto_front(POINTS) == [0, 1, 2, 3, 5]


def test_lower_hull_known_points():
    # (3, 4.5) is efficient but above the segment (2, 5)-(4, 1): not on the hull.
    assert chart.lower_hull(POINTS) == [0, 1, 3, 5]


def test_hull_drops_collinear_and_handles_degenerate_input():
    assert chart.lower_hull([(0, 2), (1, 1), (2, 0)]) == [0, 2]
    assert chart.pareto_front([]) == [] and chart.lower_hull([]) == []
    assert chart.lower_hull([(1, 1)]) == [0]
    assert chart.pareto_front([(1, math.nan), (2, 3)]) == [1]


def test_hull_points_minimise_a_weighted_sum():
    rng = np.random.default_rng(5)
    pts = [tuple(p) for p in rng.uniform(0, 10, (40, 2))]
    hull = set(chart.lower_hull(pts))
    for w in np.linspace(0.01, 0.99, 25):
        best = min(range(len(pts)), key=lambda i: w * pts[i][0] + (1 - w) * pts[i][1])
        assert best in hull


def test_frontier_in_log_coordinates():
    pts = [{"x": 1, "y": 1000}, {"x": 2, "y": 10}, {"x": 3, "y": 1}, {"x": 2.5, "y": 0}]
    front, hull = chart.frontier(pts, log_y=True)  # y = 0 is drawn at FLOOR
    assert front == [0, 1, 3] and hull[0] == 0 and hull[-1] == 3


def test_chart_written(tmp_path):
    panels = {
        "exp2": [{"x": 0.5, "y": 30, "label": "f w16", "family": "ours full", "width": 16, "fma": True,
                  "conforming": True},
                 {"x": 0.4, "y": 1000, "label": "r w16", "family": "ours relaxed", "width": 16,
                  "fma": False, "conforming": True},
                 {"x": 0.7, "y": 1, "label": "np", "family": "numpy", "width": None, "fma": None,
                  "conforming": False}],
        "log2": [{"x": 0.6, "y": 0.4, "label": "f w8", "family": "ours full", "width": 8, "fma": True,
                  "conforming": True}],
    }
    for error in ("ulp", "margin"):
        paths = chart.draw(panels, str(tmp_path / f"c-{error}"), error=error)
        assert [p.rsplit(".", 1)[1] for p in paths] == ["png", "svg"]
        for p in paths:
            with open(p, "rb") as f:
                head = f.read(64)
            assert len(head) == 64
        assert open(paths[0], "rb").read(8) == b"\x89PNG\r\n\x1a\n"
        assert b"<svg" in open(paths[1], "rb").read()


def test_a_far_point_does_not_squeeze_the_panel(tmp_path):
    assert chart.x_limit([1.0, 1.2, 1.5, 2.0, 31.0]) == pytest.approx(2.2)
    assert chart.x_limit([1.0, 1.2, 1.5, 2.0, 5.0]) is None and chart.x_limit([1.0, 40.0]) is None
    pts = [{"x": x, "y": y, "label": lab, "family": fam, "width": None, "fma": None, "conforming": True}
           for x, y, lab, fam in ((1.0, 2.0, "a", "ours full"), (1.2, 1.5, "b", "numpy"),
                                  (1.5, 1.0, "c", "sleef"), (31.0, 0.5, "numba", "numba"))]
    paths = chart.draw({"sin": pts}, str(tmp_path / "far"))
    assert b"numba 31 c/e" in open(paths[1], "rb").read()  # the far point, labelled at the edge


# -- clock ----------------------------------------------------------------------------------

def test_clock_calibration_runs_with_the_hosts_table():
    # How well the two chains agree is a timing question: benchmarks/bench_clock.py reports it.
    cal = clock.calibrate(ops=1 << 14, repeats=3)
    assert cal.ghz > 0 and cal.check_ghz > 0 and cal.fadd_latency_measured > 0
    assert cal.uarch == cpus.host().name and cal.latency == cpus.host().fma
    assert set(cal.to_json()) >= {"ghz", "op", "latency_cycles", "uarch", "check_ghz",
                                  "fadd_latency_measured"}


def test_cpu_model_reads_the_family():
    info = clock.cpu_model()
    assert {"llvm_cpu", "known", "uarch"} <= set(info) and info["uarch"] in cpus.TABLE


@pytest.mark.parametrize("info, uarch", [
    ({"vendor": "AuthenticAMD", "family": 25, "model": 17}, "zen4"),
    ({"vendor": "AuthenticAMD", "family": 25, "model": 1}, "zen3"),
    ({"vendor": "AuthenticAMD", "family": 26, "model": 2}, "zen5"),
    ({"vendor": "GenuineIntel", "family": 6, "model": 143}, "goldencove"),  # Sapphire Rapids
    ({"vendor": "GenuineIntel", "family": 6, "model": 106}, "sunnycove"),  # Ice Lake SP
    ({"vendor": "GenuineIntel", "family": 6, "model": 85}, "skylakex"),
    ({"vendor": None, "family": None, "model": None, "llvm_cpu": "rocketlake"}, "sunnycove"),
    ({"vendor": None, "family": None, "model": None, "llvm_cpu": "neoverse-v1"}, "neoversev1"),
    ({"vendor": "HygonGenuine", "family": 24, "model": 0, "llvm_cpu": "generic"}, "generic"),
])
def test_microarchitecture_from_cpuinfo(info, uarch):
    row = cpus.identify(info)
    assert row.name == uarch and row.known == (uarch != "generic")
    assert row.latency("fma") >= 4 and row.latency("fadd") >= 2


# -- model ----------------------------------------------------------------------------------

def test_model_classes_share_pipes():
    # 10 FMAs and 10 multiplies share FP0/FP1: 20 slots over 2 pipes.
    b = model._pipe_bounds({"fma": 10, "fmul": 10}, model.ZEN4)
    assert max(b.values()) == pytest.approx(10.0)
    # FMAs (FP0/FP1) and adds (FP2/FP3) do not compete.
    b = model._pipe_bounds({"fma": 10, "fadd": 10}, model.ZEN4)
    assert max(b.values()) == pytest.approx(5.0)
    # A square root keeps FP1 busy for 5 cycles per 256-bit half.
    b = model._pipe_bounds({"sqrt": 2}, model.ZEN4)
    assert max(b.values()) == pytest.approx(10.0)


def test_the_model_takes_the_blocks_every_iteration_runs():
    """exp2's loop is one block with AVX-512; sin's has an If(Any(|x| > 2^17)) block (Payne-Hanek) that
    typical arguments never enter: the model and the window bound leave it out."""
    import llvmlite.binding as llvm

    import reactor
    import routines
    # without AVX-512, log2 (and so pow) has a cold block too: the general Exponent/Significand path
    portable_log2 = "avx512f" not in reactor.get_target().feature_set
    # and exp2 one for subnormal results (VSCALEFPS rounds them in one instruction)
    for name, skipped in (("exp2", portable_log2), ("pow", portable_log2), ("sin", True), ("tan", True),
                          ("asin", False), ("log2", portable_log2)):
        k = reactor.kernel_of(routines.jit(name, "full", True))
        fn = llvm.parse_assembly(k.optimized_ir).get_function(f"{k.name}.loop")
        body, left_out = model.iteration(fn)
        blocks = {b.name: b for b in fn.blocks}
        assert bool(left_out) == skipped, (name, left_out)
        vec_body = len(list(blocks["vec.body"].instructions))
        assert len(body) > vec_body if skipped else len(body) == vec_body  # no If: one block
        pred = model.predict_kernel(routines.jit(name, "full", True))
        assert pred.skipped == left_out and "call" not in pred.counts
        assert ("not modelled" in pred.explain()) == skipped
    # sin: the polynomial (in the block after the If) is counted: > 8 FMAs
    assert model.predict_kernel(routines.jit("sin", "full", True)).counts["fma"] >= 8


def test_window_bound_and_verdicts():
    import routines
    u = routines.jit("exp2", "full", True, 8)
    w = report.window_bound(u)
    assert w["fp_ops"] > 5 and w["cycles_per_vector"] > 0
    assert report.gap_verdict(5.0, 4.0, 1.0)[0] == "met"
    assert report.gap_verdict(9.0, 4.0, 8.0)[0] == "window"
    assert report.gap_verdict(9.0, 4.0, 1.0, 8.0)[0] == "memory"
    assert report.gap_verdict(7.0, 4.0, 4.0)[0] == "pipes+window"
    assert report.gap_verdict(20.0, 4.0, 4.0)[0] == "unexplained"
    # a probe that saw 70% of the FMA pipes explains a pipe-bound kernel at 1.6x
    assert report.gap_verdict(6.4, 4.0, 1.0, pipe_factor=0.7)[0] == "pipes (shared core)"


# -- peers and harness ------------------------------------------------------------------------

def test_missing_peer_library_is_absent():
    ps = peers.peers(["exp2", "pow"], {"sleef": "libsleef-not-here.so.9"})
    sleef = [p for p in ps if p.family == "sleef"]
    assert len(sleef) == 4
    for p in sleef:
        assert not p.present and p.to_json()["status"] == "absent"
        assert "not installed" in p.reason
    assert next(p for p in ps if p.key == "numpy exp2").present


def test_trig_peers_and_families():
    ps = peers.peers(["sin", "atan2"], {"sleef": "libsleef-not-here.so.9", "libmvec": "libmvec-not-here.so.1"})
    keys = {p.key: p for p in ps}
    assert set(keys) == {"numpy sin", "libmvec sin", "sleef sin u10", "sleef sin u35", "sleef fastsin u3500",
                         "numba sin", "numpy atan2", "libmvec atan2", "sleef atan2 u10", "sleef atan2 u35",
                         "numba atan2"} | {f"svml {f} {tier}" for f in ("sin", "atan2")
                                           for tier in ("la", "ha", "ep", "br", "cr")}
    lanes, isa = peers.vector_level()  # the host's widest level: an entry point the CPU lacks is never called
    assert keys["libmvec atan2"].label == f"_ZGV{isa}N{lanes}vv_atan2f"
    assert keys["libmvec sin"].label == f"_ZGV{isa}N{lanes}v_sinf"
    assert peers.mvec_symbol("pow") == f"_ZGV{isa}N{lanes}vv_powf"
    assert peers.sleef_symbols("exp2") == [f"Sleef_exp2f{lanes}_u10", f"Sleef_exp2f{lanes}_u35"]
    assert not keys["libmvec sin"].present and "not installed" in keys["libmvec sin"].reason
    assert keys["numpy atan2"].present and keys["sleef fastsin u3500"].claimed == "350 ULP"
    only = peers.peers(["cos"], families=("libmvec", "sleef"))
    assert {p.family for p in only} == {"libmvec", "sleef"} and len(only) == 4
    # where libmvec is there, its symbols are called with the routine's operand order: atan2(y, x)
    mvec = peers.peers(["atan2"], families=("libmvec",))[0]
    if mvec.present:
        y, x = np.float32([1, 1, -1, -1] * 5), np.float32([1, -1, 1, -1] * 5)
        got = peers.as_array_function(mvec.fn)(y, x)
        assert np.allclose(got, np.arctan2(y, x), atol=1e-6)


def test_trig_inputs():
    (a,) = timing.inputs("asin", 4096)
    assert a.min() >= -1 and a.max() <= 1 and a.min() < -0.9 and a.max() > 0.9
    y, x = timing.inputs("atan2", 4096)
    assert (x < 0).any() and (y < 0).any() and not np.array_equal(x, y)
    for name in ("sin", "cos", "tan", "atan", "sinh", "cosh", "tanh"):
        (v,) = timing.inputs(name, 4096)
        assert np.array_equal(v, timing.inputs("exp2", 4096)[0])  # [-10, 10]
    assert np.array_equal(timing.inputs("pow", 64)[1], timing.inputs("exp2", 64)[0])  # unchanged draws


def test_timing_same_inputs_and_passes():
    cands = [timing.Candidate("np", "exp2", np.exp2), timing.Candidate("np2", "exp2", np.exp2)]
    res = timing.time_candidates(cands, "L1", 1024, 2, 3.0)
    assert [t.key for t in res] == ["np", "np2"]
    assert all(t.best_ns > 0 and t.passes >= 1 and t.threads == 1 for t in res)
    a, b = timing.inputs("pow", 64), timing.inputs("pow", 64)
    assert all(np.array_equal(x, y) for x, y in zip(a, b))


# -- the report, tiny -------------------------------------------------------------------------

def test_report_tiny(tmp_path):
    r = report.run(("exp2",), sizes={"L2": 4096}, rounds={"L2": 2}, samples=2 ** 10, threads2=False,
                   progress=False, libraries={"sleef": "libsleef-not-here.so.9"}, calibrate_ops=1 << 14)
    data = json.loads(json.dumps(report.to_json(r)))
    assert set(data) >= {"version", "machine", "settings", "clock", "load", "variants", "peers",
                         "floors", "probes", "machine_state", "targets", "seconds"}
    state = data["machine_state"]["L2"]
    assert 0 < state["pipe_factor"] <= 1 and 0 < state["window"] <= report.FP_SCHEDULER
    assert len(data["variants"]) == 2 * 2 * 3
    v = data["variants"][0]
    assert set(v) >= {"key", "func", "precision", "fma", "width", "model", "accuracy", "timing", "gap"}
    assert v["timing"]["L2"]["1"]["cycles_per_element"] > 0
    assert set(v["model"]) >= {"cycles_per_vector", "window_cycles_per_vector", "bottleneck"}
    assert {"max_ulp32", "max_margin", "conforming", "full_margin"} <= set(v["accuracy"])
    statuses = {p["key"]: p["status"] for p in data["peers"]}
    assert statuses["sleef exp2 u10"] == "absent" and statuses["numpy exp2"] == "present"
    numpy_peer = next(p for p in data["peers"] if p["key"] == "numpy exp2")
    assert numpy_peer["accuracy"]["verdict"]["class"] in ("highp", "relaxed", "neither")
    names = [t["target"] for t in data["targets"]]
    assert any("exp2 full" in n for n in names) and any("two cores" in n for n in names)
    text = report.print_table(r)
    assert "exp2" in text and "absent" in text and "Targets" in text
    short = summary(data)  # what the command prints without --verbose: one screen, in words
    assert len(short.splitlines()) <= 40 and short.count("\nexp2 ") == 1
    assert re.search(r"^Absent: \d+ peer variants?[:( ]", short, re.M) and "libsleef-not-here" in short
    assert not re.search(r"\d\.\d{4,}", short), short  # every figure rounded
    targets = short.split("Targets (same-run ratios):\n")[1].split("\n\n")[0].splitlines()
    assert len(targets) == len(data["targets"]) and all(re.match(r"  (met|missed|not measured)", t) for t in targets)
    paths = chart.draw(report.chart_panels(data), str(tmp_path / "chart"))
    assert all((tmp_path / p.rsplit("/", 1)[1]).stat().st_size > 1000 for p in paths)


def test_report_tiny_trig(tmp_path):
    """The trigonometric functions in the report: accuracy measured by the lab on the JIT output
    (and on the peers), the two-operand floor on atan2's inputs, one chart panel each."""
    r = report.run(("sin", "atan2"), sizes={"L2": 4096}, rounds={"L2": 2}, samples=2 ** 10,
                   threads2=False, progress=False, libraries={"sleef": "libsleef-not-here.so.9"},
                   calibrate_ops=1 << 14)
    data = json.loads(json.dumps(report.to_json(r)))
    assert len(data["variants"]) == 2 * 2 * 2 * 3
    for v in data["variants"]:
        a = v["accuracy"]
        assert a["conforming"] and a["count"] > 2 ** 10, (v["key"], a)
        assert a["max_ulp32"] < 3 if v["precision"] == "full" else a["max_margin"] < 0.2
        assert "model" in v and v["model"]["cycles_per_vector"] > 0
    sin_model = next(v for v in data["variants"] if v["key"] == "sin full fma w16")["model"]
    assert "not modelled (conditional)" in sin_model["explain"]
    floors = {f["key"]: f["func"] for f in data["floors"]}
    assert floors["floor add w16"] == "atan2" and floors["floor copy w16"] == "sin"
    peer = next(p for p in data["peers"] if p["key"] == "numpy atan2")
    assert peer["accuracy"]["full"]["count"] > 2 ** 10 and peer["accuracy"]["verdict"]["class"] == "highp"
    assert next(p for p in data["peers"] if p["key"] == "sleef sin u10")["status"] == "absent"
    panels = report.chart_panels(data)
    assert set(panels) == {"sin", "atan2"} and all(len(p) >= 12 for p in panels.values())
    assert "atan2" in report.print_table(r)


def test_report_functions_option():
    from routines.cli.report import _expand
    assert report.DEFAULT_FUNCTIONS == report.EXP_LOG and set(report.TRIG) <= set(report.FUNCTIONS)
    assert _expand(["trig"]) == list(report.TRIG)
    assert _expand(["exp2", "all"]) == list(report.FUNCTIONS)
    assert _expand(["sin", "trig", "exp2"]) == list(report.TRIG) + ["exp2"]


def test_bench_rows_with_peers_and_absent_ones(capsys):
    from routines.cli import bench
    rows = bench.run(["sin", "atan2"], size=1024, rounds=1,
                     libraries={"sleef": "libsleef-not-here.so.9"})
    by = {(r["function"], r["variant"]): r for r in rows}
    for f in ("sin", "atan2"):
        assert by[(f, "numpy")]["speedup_vs_numpy"] == 1.0
        assert by[(f, "full fma=on")]["ns_per_element"] > 0
        assert by[(f, "sleef u10")]["absent"].startswith("libsleef-not-here.so.9 not installed")
    assert by[("sin", "sleef fastsin u3500")]["ns_per_element"] is None
    text = bench.table(rows)
    assert "absent: libsleef-not-here.so.9 not installed" in text and "atan2" in text
    import routines
    assert set(bench.DEFAULT_FUNCTIONS) == set(routines.NAMES) == set(bench.NUMPY) >= set(report.TRIG)
    assert bench.expand(["trig", "sin", "exp2"]) == list(report.TRIG) + ["exp2"]


TINY = {"sizes": {"L2": 4096}, "rounds": {"L2": 2}, "samples": 2 ** 10, "threads2": False,
        "libraries": {"sleef": "libsleef-not-here.so.9"}, "calibrate_ops": 1 << 14}


def test_report_path_does_not_import_matplotlib():
    code = ("import sys, routines.cli.report, routines.cli.chart, routines.perf.report, routines.perf.chart; "
            "sys.exit('matplotlib' in sys.modules)")
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0


def test_report_command_without_matplotlib(tmp_path, monkeypatch, capsys):
    from routines.cli import chart as chart_cli, report as report_cli
    real_run = report.run
    monkeypatch.setattr(report, "run", lambda *a, **k: real_run(*a, **(k | TINY)))  # the tiny settings
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # `import matplotlib` raises ImportError
    assert report_cli.main(["--functions", "exp2", "--no-threads", "--quiet", "--out", str(tmp_path)]) == 0
    out, err = capsys.readouterr()
    data = json.loads((tmp_path / "report.json").read_text())
    assert len(data["variants"]) == 2 * 2 * 3 and data["chart"] == [] and data["targets"]
    assert "exp2" in out and "Targets" in out
    hint = [line for line in err.splitlines() if "matplotlib" in line]
    assert len(hint) == 1 and 'pip install "reactor-simd[plot]"' in hint[0]
    assert not list(tmp_path.glob("chart*"))
    assert chart_cli.main(["--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert out.count("\n") == 1 and 'pip install "reactor-simd[plot]"' in out
