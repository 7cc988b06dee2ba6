"""The trigonometric and hyperbolic routines (routines/trig.py) beyond what test_accuracy and
test_specials check for every routine: sin, cos and tan stay accurate far outside [-pi, pi]
(where Vulkan sets no bound), the lab's references, inherited tolerances, regions and atan2
pairs, the polynomials' provenance, the FMA toggle, and use inside a user's own kernel.
Sampled inputs only (>= 2^18 per variant plus the hard regions); the exhaustive sweeps are
`python -m routines accuracy F --exhaustive`."""
import itertools
import re
from pathlib import Path

import numpy as np
import pytest

import reactor
import routines
from reactor import Float
from routines import polynomials as P
from routines.lab import audit, evaluate, reference, sample_inputs, tolerance
from routines.lab.pairs import atan2_strata
from routines.specials import ROWS

NAMES = ("sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh")
VARIANTS = list(itertools.product(("full", "relaxed"), (True, False)))
F32 = np.float32


def _f32(v):
    return np.asarray(v, np.float32)


@pytest.mark.parametrize("name", ["sin", "cos", "tan"])
@pytest.mark.parametrize("precision,fma", VARIANTS)
def test_sin_cos_tan_stay_accurate_far_outside_the_vulkan_range(name, precision, fma):
    """No tolerance applies for |x| > pi, but the reduction is exact: the error there is
    the error inside (2^18 random arguments up to 1e5 and over all 2^32 patterns, the
    floats next to k pi/2, every binade's hardest reduction, the 2^17 switch)."""
    result = evaluate(routines.jit(name, precision, fma), name, precision,
                      *sample_inputs(name, 2 ** 18, seed=3))
    inside, outside = result.regions["|x| <= pi"], result.regions["|x| > pi"]
    assert outside["count"] > 2 ** 16 and inside["count"] > 2 ** 15
    if precision == "full":   # FMA off, 800 < |x| <= 2^17: one more rounding in the reduction
        assert outside["max_ulp32"] < (4.0 if name == "tan" else 2.5), result.table()
        assert inside["max_ulp32"] < (4.0 if name == "tan" else 2.0)
        if name != "tan":
            assert outside["max_abs"] < 2.0 ** -23
    else:
        assert outside["max_ulp16"] < 0.05 and inside["max_ulp16"] < 0.05, result.table()
    assert result.conforming


def test_the_shader_hash_keeps_its_bits_up_to_1e5():
    """fract(sin(x) * 43758.5453) for x up to 1e5: full precision within 2 ULP of the exact sine."""
    x = _f32(np.random.default_rng(0).uniform(-1e5, 1e5, 2 ** 18))
    exact = np.sin(x.astype(np.float64))
    for fma in (True, False):
        got = routines.jit("sin", "full", fma)(x).astype(np.float64)
        assert np.max(np.abs(got - exact)) < 2.0 ** -23


def test_the_payne_hanek_path_matches_the_cody_waite_path_at_the_switch():
    near = np.float32(2.0 ** 17)
    bits = near.view(np.uint32).astype(np.int64) + np.arange(-4096, 4097)
    x = bits.astype(np.uint32).view(np.float32)
    for name, (precision, fma) in itertools.product(("sin", "cos"), VARIANTS):
        got = routines.jit(name, precision, fma)(x).astype(np.float64)
        err = np.abs(got - reference(name, x))
        assert err.max() < (2.0 ** -23 if precision == "full" else 2.0 ** -15), (name, precision, fma)


@pytest.mark.parametrize("name", NAMES)
def test_references_agree_with_mpmath(name):
    """The float64 references (NumPy/glibc) against mpmath at 60 digits on hard and random
    points: the hardest argument reductions and huge arguments included."""
    ops = sample_inputs(name, 64, seed=1)
    rng = np.random.default_rng(2)
    pick = rng.choice(ops[0].size, 240, replace=False)
    ops = [o[pick] for o in ops]
    if name in ("sin", "cos", "tan"):
        from routines.lab.sweep import _REDUCTION_WORST
        ops = [np.concatenate([ops[0], _REDUCTION_WORST[::4]])]
    report = audit(name, *[o.view(np.float32) for o in ops])
    assert report.audited > 80          # asin/acos: about half the points are outside [-1, 1]
    assert report.max_ulp32 < 1e-6, (report.worst_x, report.worst_y)


def test_the_tolerances_follow_the_vulkan_table():
    x = _f32([0.5, -3.0, 3.1415925, 3.1415927, 100.0])
    for precision, bound in (("full", 2.0 ** -11), ("relaxed", 2.0 ** -7)):
        for name in ("sin", "cos"):
            allowed = tolerance(name, precision).allowed(x, reference(name, x))
            assert np.allclose(allowed[:3], bound, rtol=0, atol=0) and np.isinf(allowed[3:]).all()
        for name, n in (("atan", 4096.0), ("atan2", 4096.0)) if precision == "full" else \
                (("atan", 5.0), ("atan2", 5.0)):
            args = (x,) if name == "atan" else (x, x)
            assert (tolerance(name, precision).ulps(*args, reference(name, *args)) == n).all()


def test_inherited_tolerances_at_derived_points():
    def ulps(name, precision, values):
        x = _f32(values)
        return tolerance(name, precision).ulps(x, reference(name, x))

    # cosh(0): exp(+-0) within 3 ULP (spec ulp of 1 is 2^-24), the sum rounded up to the
    # float above 2 (2 + 2^-21), halved: 2^-22 = 4 ULP; relaxed: 1 ULP-16 each, the same way: 2
    assert ulps("cosh", "full", [0.0])[0] == 4.0 and ulps("cosh", "relaxed", [0.0])[0] == 2.0
    # sinh(10): exp(10)'s 23 ULP plus at most one of the subtraction's rounding
    assert 23.0 <= ulps("sinh", "full", [10.0])[0] <= 24.0
    # no bound where exp(|x|) may overflow, or outside [-pi, pi], or where cos may vanish
    assert np.isinf(ulps("sinh", "full", [88.8, -89.0])).all()
    assert np.isinf(ulps("tanh", "full", [88.8])).all()
    assert np.isinf(ulps("tan", "full", [4.0, 1.5704])).all()          # |cos(1.5704)| < 2^-11
    assert np.isfinite(ulps("tan", "full", [1.57, 3.0])).all()         # |cos(1.57)| > 2^-11
    assert np.isinf(ulps("tan", "relaxed", [1.57])).all()              # but < 2^-7
    # asin/acos at 0 and +-1: 1 - x*x is exact (1 or 0), so only atan2's own 4096 ULP remain,
    # plus, where the result is 0 (acos(1) = atan2(sqrt(0), 1)), sqrt(0)'s 2.5 ULP of 0
    assert (ulps("asin", "full", [0.0, 1.0, -1.0]) == 4096.0).all()
    assert ulps("acos", "full", [-1.0])[0] == 4096.0 and ulps("acos", "full", [1.0])[0] == 4098.5
    # relaxed: sqrt(0) may be 2.5 * 2^-24 (binary16 spacing at 0), 1.5e-4 ULP-16 of pi/2
    assert np.allclose(ulps("asin", "relaxed", [1.0, -1.0]), 5.0 + 2.5 * 2.0 ** -24 / 2.0 ** -10, rtol=1e-6)
    # elsewhere the spread of x*x, 1 - x*x and the inherited sqrt adds to them
    assert (ulps("asin", "full", [0.3, 0.9, -0.999]) > 4096.0).all()
    assert (ulps("acos", "relaxed", [0.3, 0.9, -0.999]) > 5.0).all()
    # tanh near 0: sinh's ~2^-22 absolute over cosh ~1
    x = _f32([1e-3])
    allowed = tolerance("tanh", "full").allowed(x, reference("tanh", x))
    assert 2.0 ** -23 < allowed[0] < 2.0 ** -20


def test_regions_are_reported_apart():
    x = sample_inputs("sin", 2 ** 12, seed=4)[0]
    r = evaluate(routines.jit("sin", "full"), "sin", "full", x)
    assert set(r.regions) == {"|x| <= pi", "|x| > pi"}
    assert r.regions["|x| > pi"]["max_margin"] == 0.0            # no bound there
    assert r.regions["|x| <= pi"]["max_margin"] == r.max_margin
    assert "region |x| > pi" in r.table() and "regions" in r.to_json()
    half = evaluate(routines.jit("sin", "full"), "sin", "full", x[: x.size // 2])
    half.merge(evaluate(routines.jit("sin", "full"), "sin", "full", x[x.size // 2:]))
    for name, stats in r.regions.items():
        assert half.regions[name]["count"] == stats["count"]
        assert half.regions[name]["max_ulp32"] == stats["max_ulp32"]


def test_atan2_pairs_and_strata():
    y, x = sample_inputs("atan2", 2 ** 10, seed=0)
    pairs = set(zip(y.tolist(), x.tolist()))
    for a, b in [(0.0, -0.0), (-0.0, -0.0), (np.inf, -np.inf), (-np.inf, np.inf), (1.0, -1.0)]:
        assert (int(_f32(a).view(np.uint32)), int(_f32(b).view(np.uint32))) in pairs
    strata = atan2_strata(0).view(np.float32)
    assert strata.size == 256 and np.isnan(strata).sum() == 1 and np.isinf(strata).sum() == 2
    exps = np.frexp(strata[np.isfinite(strata) & (strata != 0)].astype(np.float64))[1]
    assert exps.min() < -140 and exps.max() > 120


def _recorded_command(poly):
    """The ``python -m routines remez ...`` command in the provenance, as an argv."""
    import shlex
    found = re.search(r'python -m routines remez(?: +(?:"[^"]*"|[^\s";)]+))+', poly.provenance)
    assert found, poly.provenance
    argv = shlex.split(found.group(0))
    assert argv[:4] == ["python", "-m", "routines", "remez"]
    return argv[4:]


@pytest.mark.parametrize("poly", P.TRIG, ids=lambda p: p.name)
def test_polynomials_reproduce_from_the_fitter(poly, capsys):
    """Each coefficient list is the float32 rounding of our Remez fit (routines.remez), as the
    provenance states: the command recorded there (run in process, ~0.3 s each) prints these
    digits, and so do the same fits through the Python API with mpmath callables."""
    import json

    import mpmath

    from routines.remez import remez
    from routines.remez.cli import main
    assert poly.remez_command() in poly.provenance  # the command states the recorded f, weight, range
    argv = _recorded_command(poly)
    assert main(argv + ["--json"]) == 0
    assert tuple(json.loads(capsys.readouterr().out)["coefficients"]) == poly.coefficients
    fits = P._trig_fits()
    if poly.name in fits:
        f, w, a, b, degree = fits[poly.name]
        fit = remez(f, mpmath.mpf(a), mpmath.mpf(b), degree, w)
        assert tuple(reversed(fit.float32_strings)) == poly.coefficients


def test_a_trig_polynomial_reproduces_from_its_command_line():
    """The recorded command itself, as a user runs it: sin's full-precision polynomial."""
    import subprocess
    import sys
    argv = _recorded_command(P.SIN_FULL)
    out = subprocess.run([sys.executable, "-m", "routines", "remez", *argv], capture_output=True,
                         text=True, check=True, cwd=Path(__file__).resolve().parents[2]).stdout
    literals = re.findall(r"([-+0-9.e]+)f;", out)
    assert [np.float32(v) for v in literals] == [np.float32(c) for c in P.SIN_FULL.coefficients], out


@pytest.mark.parametrize("name", NAMES)
def test_fma_off_has_no_fused_instruction(name):
    import re
    fused = re.compile(r"\bv?f(n)?m(add|sub)")
    for precision in ("full", "relaxed"):
        assert not fused.search(reactor.kernel_of(routines.jit(name, precision, False)).assembly)
        assert fused.search(reactor.kernel_of(routines.jit(name, precision, True)).assembly)


def test_results_stay_in_their_ranges():
    bounds = {"sin": 1.0, "cos": 1.0, "tanh": 1.0, "asin": np.pi / 2, "atan": np.pi / 2,
              "acos": np.pi, "atan2": np.pi}
    for name, bound in bounds.items():
        ops = [o.view(np.float32) for o in sample_inputs(name, 2 ** 16, seed=9)]
        for precision, fma in VARIANTS:
            got = routines.jit(name, precision, fma)(*ops)
            finite = got[~np.isnan(got)]
            assert np.abs(finite).max() <= np.float32(bound), (name, precision, fma)
            if name == "acos":
                assert finite.min() >= 0 and not np.signbit(finite).any()


def test_routines_inside_a_users_kernel():
    """Any width, the build's precision by default, precision= and fma= per call, a scalar
    broadcast in atan2, and the same bits as the ready-made ufuncs."""
    @reactor.kernel(precision="relaxed")
    def polar(x: Float, y: Float) -> (Float, Float, Float):
        angle = routines.atan2(y, x)                      # the kernel's precision: relaxed
        wave = routines.sin(x, precision="full", fma=False)
        return angle, wave, routines.tanh(routines.atan2(y, 2.0, precision="full"))

    rng = np.random.default_rng(5)
    x, y = _f32(rng.uniform(-50, 50, 1000)), _f32(rng.uniform(-50, 50, 1000))
    angle, wave, t = polar(x, y)
    assert np.array_equal(angle, routines.jit("atan2", "relaxed")(y, x))
    assert np.array_equal(wave, routines.jit("sin", "full", False)(x))
    inner = routines.jit("atan2", "full")(y, np.full_like(y, 2.0))
    assert np.array_equal(t, routines.jit("tanh", "relaxed")(inner))

    @reactor.function
    def four(v: reactor.Pointer[reactor.Float4]) -> reactor.Float4:
        return routines.cos(v[0]) + routines.acos(v[0] * 0.25)

    v = _f32([0.0, 1.0, -2.0, 3.0])
    expected = routines.jit("cos", "full")(v) + routines.jit("acos", "full")(v * _f32(0.25))
    assert np.array_equal(four(v), expected)

    with pytest.raises(reactor.DSLTypeError, match="sin: argument 'x'"):
        @reactor.kernel
        def bad(i: reactor.Int) -> Float:
            return routines.sin(i)
        bad(np.arange(3, dtype=np.int32))


def test_special_rows_cover_the_required_cases():
    required = {
        "sin": ("+0", "-0", "+inf", "-inf", "NaN"), "tan": ("+0", "-0", "+inf", "-inf", "NaN"),
        "cos": ("+0", "+inf", "-inf", "NaN"), "asin": ("+0", "-0", "NaN", "|x| > 1", "+inf"),
        "acos": ("|x| > 1", "-1: pi", "1: +0", "NaN"), "atan": ("+0", "-0", "+inf: pi/2", "-inf: -pi/2", "NaN"),
        "atan2": ("(+0, +0) = +0", "(-0, -0) = -pi", "(+inf, +inf) = pi/4", "(-inf, -inf) = -3pi/4",
                  "(y>0, -inf) = +pi", "(y<0, +inf) = -0", "(NaN, x)", "(y, NaN)"),
        "sinh": ("+0", "-0", "+inf", "-inf", "overflow", "NaN"), "cosh": ("+0", "-inf", "overflow", "NaN"),
        "tanh": ("+0", "-0", "+inf: 1", "-inf: -1", "NaN"),
    }
    for name, cases in required.items():
        text = " ".join(r.case for r in ROWS if r.function == name)
        for case in cases:
            assert case in text, (name, case)


def test_each_routine_has_a_docs_page():
    docs = Path(__file__).resolve().parents[2] / "docs" / "routines"
    for name in NAMES:
        page = (docs / f"{name}.md").read_text()
        assert page.startswith(f"# {name}\n") and "## Accuracy" in page and "## Special values" in page
