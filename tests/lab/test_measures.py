"""Measures, Vulkan tolerances and the float64 reference (with its mpmath audit)."""

import numpy as np
import pytest

from routines.lab import measures as M
from routines.lab.reference import audit, reference
from routines.lab.tolerance import tolerance

F32 = np.float32


def f32(*values):
    return np.array(values, dtype=np.float32)


def next_up(v):
    return np.nextafter(F32(v), F32(np.inf))


def next_down(v):
    return np.nextafter(F32(v), F32(-np.inf))


# --- ULP sizes ---------------------------------------------------------------

def test_ulp32_at_powers_of_two_and_inside_binades():
    r = np.array([1.0, 1.5, 2.0, -4.0, 3.0 * 2**100])
    assert list(M.ulp32(r)) == [2.0**-23, 2.0**-23, 2.0**-22, 2.0**-21, 2.0**78]
    # Vulkan's ulp() is the spacing *below* an exact power of two
    assert list(M.spec_ulp32(r)) == [2.0**-24, 2.0**-23, 2.0**-23, 2.0**-22, 2.0**78]


def test_ulp32_matches_float32_spacing_for_normal_values():
    rng = np.random.default_rng(0)
    r = rng.integers(0x00800000, 0x7F7FFFFF, 10_000, dtype=np.uint32).view(F32)
    assert np.array_equal(M.ulp32(r.astype(np.float64)), np.spacing(r).astype(np.float64))


def test_ulp32_subnormals_and_zero():
    r = np.array([0.0, -0.0, 2.0**-149, 2.0**-130, 2.0**-126 * 0.999, 2.0**-126, 2.0**-125])
    assert list(M.ulp32(r)) == [2.0**-149] * 6 + [2.0**-148]
    assert list(M.spec_ulp32(r)) == [2.0**-149] * 7  # below 2**-125 is 2**-149


def test_ulp16_spacing_and_range():
    r = np.array([1.0, 1.5, 65504.0, 2.0**20, 2.0**-14, 2.0**-20, 0.0])
    assert list(M.ulp16(r)) == [2.0**-10, 2.0**-10, 32.0, 2.0**10, 2.0**-24, 2.0**-24, 2.0**-24]
    assert list(M.spec_ulp16(r)) == [2.0**-11, 2.0**-10, 32.0, 2.0**9, 2.0**-24, 2.0**-24,
                                     2.0**-24]
    half = np.array([1.0, 3.0, 1000.0, 0.1, 6e-5], dtype=np.float16)
    assert np.array_equal(M.ulp16(half.astype(np.float64)), np.spacing(half).astype(np.float64))


def test_ulp16_is_2_to_13_ulp32_above_2_to_minus_14():
    r = np.geomspace(2.0**-14, 2.0**127, 1000)
    assert np.array_equal(M.ulp16(r), M.ulp32(r) * 2.0**13)


def test_ulp_error_and_abs_error():
    ref = np.array([1.0, 2.0, 1.0 + 2.0**-24])
    got = f32(next_up(1.0), next_down(2.0), 1.0)
    assert list(M.ulp_error(got, ref)) == [1.0, 0.5, 0.5]
    assert list(M.ulp_error(got, ref, bits=16)) == [2.0**-13, 2.0**-14, 2.0**-14]
    assert np.isnan(M.abs_error(f32(np.nan), np.array([1.0])))[0]


def test_margin_conformance():
    m = M.margin(np.array([0.0, 2.9, 3.0, 1.0]), np.array([3.0, 3.0, 3.0, np.inf]))
    assert list(m < 1) == [True, True, False, True]


# --- special values ---------------------------------------------------------------

def _cat(got, ref, allowed=1e-30, x_finite=True):
    code = M.classify(np.array([x_finite]), f32(got), np.array([ref]), np.array([allowed]))[0]
    return "inf_allowed" if code == M.INF_ALLOWED else M.CATEGORIES[code]


@pytest.mark.parametrize("got, ref, expected", [
    (np.nan, np.nan, "match"),
    (1.0, np.nan, "nan"),
    (np.nan, 1.0, "nan"),
    (np.inf, np.inf, "match"),
    (np.inf, 2.0**200, "match"),           # overflowing reference
    (3.4028235e38, np.inf, "inf"),         # FLT_MAX is not inf
    (-np.inf, np.inf, "inf"),
    (np.inf, 1.0, "spurious_inf"),
    (-0.0, 0.0, "zero_sign"),              # e.g. exp2: results never negative
    (-0.0, 2.0**-140, "zero_sign"),
    (0.0, 2.0**-140, "flush"),             # subnormal expected, flushed
    (0.0, 2.0**-126 * 0.9999999, "flush"),
    (0.0, 2.0**-151, "scored"),            # correctly rounded to +0
    (0.0, 0.0, "scored"),
    (-0.0, -1e-7, "scored"),               # a normal reference: an ordinary error
    (2.0**-140, 2.0**-140, "scored"),
])
def test_classify_categories(got, ref, expected):
    assert _cat(got, ref) == expected


def test_infinity_permitted_when_the_allowed_range_passes_flt_max():
    near_max = 3.4028e38
    assert _cat(np.inf, near_max, allowed=1e34) == "inf_allowed"
    assert _cat(np.inf, near_max, allowed=1e30) == "spurious_inf"
    assert _cat(-np.inf, near_max, allowed=1e34) == "spurious_inf"


def test_non_finite_inputs_need_the_exact_ieee_result():
    assert _cat(0.0, 0.0, x_finite=False) == "match"
    assert _cat(1e-30, 0.0, allowed=np.inf, x_finite=False) == "special_value"
    assert _cat(-0.0, 0.0, x_finite=False) == "zero_sign"
    assert _cat(np.inf, 0.0, allowed=np.inf, x_finite=False) == "spurious_inf"


# --- tolerances ---------------------------------------------------------------

def test_exp_tolerances():
    x = f32(0.0, 1.0, -1.0, -126.0, 10.5)
    for func in ("exp2", "exp"):
        ref = reference(func, x)
        assert list(tolerance(func, "full").ulps(x, ref)) == [3, 5, 5, 255, 24]
        assert list(tolerance(func, "relaxed").ulps(x, ref)) == [1, 3, 3, 253, 22]


@pytest.mark.parametrize("precision, bound", [("full", 2.0**-21), ("relaxed", 2.0**-7)])
def test_log_tolerance_switches_at_half_and_two(precision, bound):
    x = f32(0.5, 1.0, 2.0, 1.5, next_down(0.5), next_up(2.0), 0.25, 1e30)
    for func in ("log2", "log"):
        tol = tolerance(func, precision)
        ref = reference(func, x)
        allowed = tol.allowed(x, ref)
        assert np.allclose(allowed[:4], bound, rtol=1e-15)      # inside [0.5, 2]
        assert list(tol.ulps(x, ref)[4:]) == [3.0] * 4          # outside
        assert np.array_equal(allowed[4:], 3 * tol.unit_of(ref[4:]))


def test_rcp_tolerance_divisor_range():
    x = f32(0.0, 1.0, -3.0, 2.0**126, 2.0**-126, next_up(2.0**126), 2.0**127, 1e-40, np.inf)
    for precision in ("full", "relaxed"):
        ulps = tolerance("rcp", precision).ulps(x, reference("rcp", x))
        assert list(ulps) == [2.5] * 5 + [np.inf] * 3 + [2.5]


def test_rsqrt_tolerance():
    x = f32(1.0, 3.0, 1e-40, 1e38)
    assert list(tolerance("rsqrt", "full").ulps(x, reference("rsqrt", x))) == [2.0] * 4


def test_sqrt_inherited_tolerance():
    rng = np.random.default_rng(1)
    x = rng.integers(0x00800000, 0x7F7FFFFF, 20_000, dtype=np.uint32).view(F32)
    s = reference("sqrt", x)
    tol = tolerance("sqrt", "full")
    in_binade_ulps = tol.allowed(x, s) / M.ulp32(s)   # 2.5 + 4/m_q**2
    assert in_binade_ulps.min() > 3.5 - 1e-6 and in_binade_ulps.max() < 6.5 + 1e-6
    below_four = next_down(4.0)  # sqrt just below 2: F_max crosses the binade
    assert tol.allowed(f32(below_four), reference("sqrt", f32(below_four))) \
        / M.ulp32(reference("sqrt", f32(below_four))) == pytest.approx(9.0, abs=1e-5)
    assert tol.ulps(f32(0.5), reference("sqrt", f32(0.5))) == pytest.approx(4.5, abs=1e-6)
    assert tol.ulps(f32(0.0), np.array([0.0]))[0] == 2.5
    relaxed = tolerance("sqrt", "relaxed")
    big = f32(2.0**20, 2.0**46)
    assert list(np.isinf(relaxed.ulps(big, reference("sqrt", big)))) == [False, True]


def test_pow_inherited_tolerance():
    full = tolerance("pow", "full")
    x, y = f32(3.0), f32(50.0)
    assert full.ulps(x, y, reference("pow", x, y)) == pytest.approx(337.67, abs=0.01)
    # near x = 1 the absolute log2 bound dominates: relative ~ ln2 * |y| * 2**-21
    x, y = f32(1.0), f32(1000.0)
    rel = full.allowed(x, y, reference("pow", x, y))
    assert rel == pytest.approx(np.exp2(1000 * 2.0**-21) - 1, rel=3e-3)
    # at y = 1 it is at least exp2's own 3 ULP plus the log2 error propagated
    x, y = f32(7.0), f32(1.0)
    assert full.ulps(x, y, reference("pow", x, y)) > 3 + 3 * np.log(2) * np.log2(7)


def test_unknown_precision_is_rejected():
    with pytest.raises(ValueError):
        tolerance("exp2", "medium")


# --- reference ----------------------------------------------------------------

def test_reference_special_values():
    ninf, nan = -np.inf, np.nan
    assert reference("exp2", f32(ninf))[0] == 0 and not np.signbit(reference("exp2", f32(ninf)))[0]
    assert list(reference("exp2", f32(np.inf, 2000, -2000))) == [np.inf, 2.0**1000, 2.0**-1000]
    assert list(reference("log2", f32(0.0, -0.0, np.inf))) == [ninf, ninf, np.inf]
    assert np.isnan(reference("log", f32(-1.0)))[0]
    assert list(reference("rcp", f32(-0.0, np.inf))) == [ninf, 0.0]
    assert list(reference("rsqrt", f32(0.0, -0.0, np.inf))) == [np.inf, ninf, 0.0]
    assert np.signbit(reference("sqrt", f32(-0.0)))[0]
    x = f32(-2.0, 0.0, -0.0, 0.0, 0.0, 1.0, np.inf, nan, 2.0, 1.0)
    y = f32(3.0, 2.0, 3.0, -1.0, 0.0, np.inf, 0.0, 0.0, 3.0, 5.0)
    got = reference("pow", x, y)
    assert np.array_equal(got, [nan, 0.0, 0.0, np.inf, nan, nan, nan, nan, 8.0, 1.0],
                          equal_nan=True)
    assert not np.signbit(got[2])


def test_audit_hard_points():
    """The float64 reference is far below 1e-6 ULP-32 from the exact value."""
    x = f32(127.99999, 128.0, 127.0, -126.0, -149.5, -150.0, 2.0**-30, 0.1, 3e38, -3e38)
    assert audit("exp2", x).max_ulp32 < 1e-6
    assert audit("exp", f32(88.72283, 88.72284, -87.33654, -103.97, 1e-3, 50.5)).max_ulp32 < 1e-6
    near_one = f32(1.0, next_up(1.0), next_down(1.0), 0.5, 2.0, 1e-45, 3e38)
    for func in ("log2", "log"):
        report = audit(func, near_one)
        assert report.max_ulp32 < 1e-6 and report.audited == near_one.size
    x = f32(2.0, 10.0, next_up(1.0), 0.5, 3.0)
    y = f32(127.99, 38.5318, 2.0**30, -149.0, 50.0)
    assert audit("pow", x, y).max_ulp32 < 1e-6
    for func in ("rcp", "rsqrt", "sqrt"):
        assert audit(func, f32(3.0, 1e-40, 2.0**126, 7e37)).max_ulp32 < 1e-6


def test_audit_skips_non_finite_and_out_of_domain_points():
    report = audit("log2", f32(np.nan, np.inf, -1.0, 0.0, 4.0))
    assert (report.audited, report.skipped) == (1, 4)
    assert report.max_ulp32 == 0.0 and report.worst_x == 4.0
