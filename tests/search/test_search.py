"""Variant search: candidate generation, the building blocks (one-instruction
round-to-nearest conversion, VSCALEFPS, VREDUCEPS), the lean scorer against
the lab, Pareto selection, and one small end-to-end search. ~30 s, one core."""
import json

import numpy as np
import pytest

from routines.lab import evaluate, sample_inputs
from routines.remez import remez
from routines.search import candidates as C
from routines.search import run as R
from routines.search.candidates import Candidate, grid
from routines.zoo.methods import Domain

import reactor

#: VSCALEFPS, VREDUCEPS and VRNDSCALEPS exist (AVX-512F and DQ); elsewhere their portable paths run.
AVX512 = {"avx512f", "avx512dq"} <= reactor.get_target("host").feature_set

EXP2_BEST = ("exp2.full.rscalef.d5.erf2", "exp2.full.rscalefmul.d4.w35",
             "exp2.full.additive01.d3.abs.nearest")


# -- candidates ------------------------------------------------------------------

@pytest.mark.parametrize("function,precision", [("exp2", "full"), ("exp2", "relaxed"),
                                                ("log2", "full"), ("log2", "relaxed")])
def test_grid_is_well_formed(function, precision, monkeypatch):
    monkeypatch.setattr(C, "fit", lambda f, form, d, shape: (("0.5",) * (d + 1), 0.0))  # no fits
    g = grid(function, precision, quick=True)
    names = [c.name for c in g]
    assert len(names) == len(set(names))
    assert g[0].production and g[0].fma and g[1].production and not g[1].fma
    for c in g:
        assert (c.function, c.precision) == (function, precision)
        assert all(np.isfinite(np.float32(v)) for v in c.coefficients)
        assert c.description and c.name.startswith(f"{function}.{precision}.")
        if not c.production:
            assert len(c.coefficients) == c.degree + 1
            assert c.provenance.startswith("python -m routines remez") or c.tag == "retuned"


def test_full_grid_contains_the_quick_one(monkeypatch):
    monkeypatch.setattr(C, "fit", lambda f, form, d, shape: (("0.5",) * (d + 1), 0.0))  # names only
    full = {c.name for c in grid("exp2", "full")}
    assert {c.name for c in grid("exp2", "full", quick=True)} <= full
    assert set(EXP2_BEST) <= full
    assert len(full) > 60


def test_fitted_coefficients_are_the_remez_fit_rounded_to_float32():
    c = C.fitted("exp2", "full", "rscalef", 5, "erf2", True)
    r = remez("(2^x-x-1)/x", -0.5, 0.5, 5, C.weight_of("exp2", "rscalef", "erf2"))
    assert c.values == tuple(float(v) for v in r.float32[::-1])
    assert c.weight == "(0.25*erf(1000*x)+0.75)*(2+2*abs(x))/x"
    assert '-r "-0.5:0.5"' in c.provenance
    c01 = C.fitted("exp2", "full", "additive01", 3, "abs", True)
    assert c01.weight == "1/(x*(1-x))" and c01.total_degree == 5


def test_production_candidate_is_the_shipped_kernel():
    from routines.kernels import jit
    p = C.production("exp2", "full")
    assert p.kernel() is jit("exp2", "full", True)


def test_retuned_candidates_join_the_grid(monkeypatch):
    base = C.fitted("log2", "full", "m1m", 6, "abs", True)
    monkeypatch.setitem(C.RETUNED, base.name, base.coefficients)
    monkeypatch.setattr(C, "fit", lambda f, form, d, shape: (("0.5",) * (d + 1), 0.0))
    names = [c.name for c in grid("log2", "full")]
    assert base.name + ".retuned" in names


# -- building blocks ---------------------------------------------------------------

def test_nearest_conversion_is_one_vcvtps2dq_and_equals_roundeven():
    from reactor import kernel_of
    a = C.fitted("exp2", "full", "additive", 4, "tent3", True, conversion="nearest")
    b = C.fitted("exp2", "full", "additive", 4, "tent3", True, conversion="roundeven")
    x = np.random.default_rng(3).uniform(-130, 130, 1 << 16).astype(np.float32)
    x[:8] = [0.0, -0.0, np.inf, -np.inf, np.nan, 127.99999, -126.0, -1e-30]
    assert np.array_equal(a.kernel()(x).view(np.uint32), b.kernel()(x).view(np.uint32))
    assert np.array_equal(a.kernel()(x[::3]).view(np.uint32), b.kernel()(x)[::3].view(np.uint32))
    asm_a, asm_b = kernel_of(a.kernel()).assembly, kernel_of(b.kernel()).assembly
    assert "vcvtps2dq" in asm_a
    if AVX512:  # elsewhere the reduction's portable floor is a VROUNDPS in both
        assert "vrndscaleps" not in asm_a and "vrndscaleps" in asm_b
    # the model costs lrint as the conversion it is (not as an opaque call)
    pa, pb = R.model_cost(a.kernel()), R.model_cost(b.kernel())
    assert "call" not in pa.counts and pa.counts["convert"] == 1
    assert pb.counts["round"] == pa.counts["round"] + 1


def test_scalef_forms_handle_special_values_without_fixups():
    from reactor import kernel_of
    c = C.fitted("exp2", "full", "rscalef", 5, "erf2", True)
    k = c.kernel()
    x = np.array([np.inf, -np.inf, np.nan, 128.0, 127.99999, 200.0, -126.0, -149.0, -160.0,
                  0.0, -0.0, 1.0, -1.0, 0.5, -0.5, 2.5], np.float32)
    got = k(x)
    assert got[0] == np.inf and got[1] == 0 and np.isnan(got[2]) and got[3] == np.inf
    assert np.isfinite(got[4]) and got[5] == np.inf and got[8] == 0
    assert not np.signbit(got[1]) and not np.signbit(got[8])
    assert got[9] == 1.0 and got[10] == 1.0 and got[11] == 2.0 and got[12] == 0.5  # exact at integers
    assert got[13] == pytest.approx(np.sqrt(2), rel=3e-7) and got[15] == pytest.approx(2 ** 2.5, rel=3e-7)
    assert np.array_equal(k(x[::2]).view(np.uint32), got[::2].view(np.uint32))  # scalar path agrees
    asm = kernel_of(k).assembly
    cost = R.model_cost(k)
    assert "call" not in cost.counts
    if AVX512:  # elsewhere: the portable paths, with the same bits (tests/dsl/test_intrinsics_portable.py)
        assert "vscalefps" in asm and "vreduceps" in asm
        from reactor.cost import model
        zen4 = model.predict(R._model_ir(kernel_of(k)), f"{kernel_of(k).name}.loop", kernel_of(k).build.width,
                             machine="zen4")
        assert zen4.throughput_bound == 7.0                       # 6 FMAs + VSCALEFPS on Zen 4's FP0/FP1
    else:
        assert "vscalefps" not in asm and "vreduceps" not in asm
    r = evaluate(k, "exp2", "full", sample_inputs("exp2", 1 << 14, seed=5)[0])
    assert r.mismatches == 0 and r.conforming


# -- scoring -----------------------------------------------------------------

@pytest.mark.parametrize("func,form,degree,shape", [
    ("exp2", "production", 0, ""), ("exp2", "rscalef", 5, "erf2"), ("log2", "m1m_re", 6, "abs")])
def test_lean_scorer_agrees_with_the_lab(func, form, degree, shape):
    c = (C.production(func, "full") if form == "production"
         else C.fitted(func, "full", form, degree, shape, True))
    big, _ = R.core_ranges(func)
    bits = R.range_sample(big, 1 << 18, seed=11)
    s = R.score_bits(c.kernel(), func, "full", bits)
    lab = evaluate(c.kernel(), func, "full", bits)
    assert s.count == lab.count
    assert s.max_margin == pytest.approx(lab.max_margin, rel=1e-12)
    assert s.nonconforming == lab.nonconforming == 0
    ulp_bits = np.concatenate([bits[(bits >= a) & (bits < b)] for a, b in R.ULP_DOMAIN[func].ranges])
    assert s.max_ulp32 == pytest.approx(evaluate(c.kernel(), func, "full", ulp_bits).max_ulp32,
                                        rel=1e-12)


def test_exhaustive_ranges_match_sampled_scoring():
    c = C.production("log2", "full")
    d = Domain(2.0, 2.0 + 1.0 / 32)  # 2^17 inputs
    ex = R.score_ranges(c.kernel(), "log2", "full", d.ranges)
    ev = evaluate(c.kernel(), "log2", "full", d.values().view(np.uint32))
    assert ex.count == ev.count == 1 << 17
    assert ex.max_margin == pytest.approx(ev.max_margin, rel=1e-12)


# -- Pareto ------------------------------------------------------------------

class P:
    def __init__(self, name, cost, err, ok=True):
        self.name, self.cycles_per_element, self.max_margin, self.conforming = name, cost, err, ok


def test_pareto_on_known_points():
    pts = [P("a", 1.0, 0.9), P("b", 1.0, 0.5), P("c", 2.0, 0.5), P("d", 2.0, 0.2),
           P("e", 0.5, 2.0, ok=False), P("f", 3.0, 0.2), P("g", 0.8, 0.95), P("h", 1.0, 0.5)]
    assert [p.name for p in R.pareto(pts)] == ["g", "b", "h", "d"]
    assert R.pareto([]) == []
    assert [p.name for p in R.pareto([P("x", 1, 1, ok=False)])] == []


# -- end to end ----------------------------------------------------------------

def test_small_end_to_end_search(monkeypatch, tmp_path):
    """Three exp2 candidates, the core domain cut to two binades (exhaustive)."""
    monkeypatch.setitem(R.CORE, "exp2", (Domain(-0.125, -0.0625), Domain(0.25, 0.5)))
    monkeypatch.setattr(R, "WIDE_SAMPLE", 1 << 12)
    R._WIDE_CACHE.clear()
    cands = [C.production("exp2", "full"),
             C.fitted("exp2", "full", "rscalef", 5, "erf2", True),
             C.fitted("exp2", "full", "additive", 3, "abs", True, conversion="nearest")]
    monkeypatch.setattr(R, "grid", lambda f, p, quick=False: cands)
    from routines.cli.search import main
    out = tmp_path / "s.json"
    assert main(["exp2", "--precision", "full", "--json", str(out), "--no-time"]) == 0
    R._WIDE_CACHE.clear()
    pts = json.loads(out.read_text())
    assert len(pts) == 3
    keys = {"function", "precision", "name", "description", "fma", "cost_cycles_per_element",
            "ns_per_element", "max_ulp32", "max_margin", "conforming", "pareto", "measured"}
    for p in pts:
        assert keys <= set(p)
        assert p["exhaustive"] == ("exhaustive" in p["measured"])
        assert p["exhaustive"] or not p["conforming"]   # finalists and baselines are swept
    by = {p["name"]: p for p in pts}
    assert not by["exp2.full.additive.d3.abs.nearest"]["conforming"]      # degree 3 fails
    assert by["exp2.full.rscalef.d5.erf2"]["pareto"]
    assert by["exp2.full.rscalef.d5.erf2"]["max_margin"] < by["exp2.full.production"]["max_margin"]
    if AVX512:  # with VSCALEFPS and VREDUCEPS; their portable paths cost more than production's
        assert by["exp2.full.rscalef.d5.erf2"]["cost_cycles_per_element"] <= \
            by["exp2.full.production"]["cost_cycles_per_element"]
