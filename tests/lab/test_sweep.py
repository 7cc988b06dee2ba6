"""The sweep engine, with NumPy's float32 ufuncs standing in for our kernels."""

import json

import numpy as np
import pytest

from routines.lab.sweep import evaluate, sample_inputs, sweep

F32 = np.float32
ONE = 0x3F800000
AROUND_ONE = dict(start=ONE - 2**19, stop=ONE + 2**19)  # 2**20 patterns, x in ~[0.94, 1.06)


def bits(v):
    return int(np.float32(v).view(np.uint32))


def quiet(**kw):
    return dict(progress=False, **kw)


def test_numpy_exp2_log2_conform_around_one():
    # NumPy's exp2f is < 1 ULP; log2f near 1 is accurate in absolute terms
    # (the spec's 2**-21 there) but its ULP error relative to log2(x) ~ 0 is larger.
    for func, ufunc, ulp_max in (("exp2", np.exp2, 1.0), ("log2", np.log2, 4.0)):
        r = sweep(ufunc, func, "full", **AROUND_ONE, **quiet())
        assert r.count == 2**20
        assert r.conforming and r.nonconforming == 0 and r.mismatches == 0
        assert 0.3 < r.max_ulp32 < ulp_max
        assert r.max_ulp16 == pytest.approx(r.max_ulp32 * 2.0**-13)
        assert 0 < r.max_margin < 1
        assert len(r.worst) == 10
        assert [c.margin for c in r.worst] == sorted((c.margin for c in r.worst), reverse=True)
        assert r.worst[0].margin == r.max_margin
        case = r.max_ulp32_case
        assert case.ulp32 == r.max_ulp32 and ONE - 2**19 <= case.x_bits < ONE + 2**19
        assert np.float32(case.got) == getattr(np, func)(np.float32(case.x))


def test_parallel_serial_and_evaluate_agree():
    lo, hi = bits(-130.0), bits(-130.0) + 3 * 2**18 + 12345  # subnormal results, flushes
    a = sweep(np.exp2, "exp2", "full", start=lo, stop=hi, chunk=2**18, workers=2, **quiet())
    b = sweep(np.exp2, "exp2", "full", start=lo, stop=hi, chunk=2**17, workers=1, **quiet())
    c = evaluate(np.exp2, "exp2", "full", np.arange(lo, hi, dtype=np.uint32))
    for r in (b, c):
        assert (r.count, r.max_ulp32, r.max_ulp16, r.max_margin, r.nonconforming, r.flushed) \
            == (a.count, a.max_ulp32, a.max_ulp16, a.max_margin, a.nonconforming, a.flushed)
        assert [w.x_bits for w in r.worst] == [w.x_bits for w in a.worst]


def test_bad_kernel_is_non_conforming():
    def bad(x):
        return (np.exp2(x) * F32(1 + 2.0**-20)).astype(F32)
    r = sweep(bad, "exp2", "full", **AROUND_ONE, **quiet())
    assert not r.conforming
    assert r.nonconforming > 2**19 and r.max_margin >= 1 and r.worst[0].margin >= 1
    assert 8 <= r.max_ulp32 <= 17             # 2**-20 relative is 8..16 ULP-32, plus np.exp2's own error
    assert r.mismatches == 0
    relaxed = sweep(bad, "exp2", "relaxed", **AROUND_ONE, **quiet())
    assert relaxed.conforming                 # ~2**-3 ULP-16 is far inside 1 + 2|x|


def test_special_value_mismatches_are_reported():
    def broken(x):
        r = np.exp2(x)
        r = np.where(x < -150, F32(-0.0), r)          # -0 where +0 is expected
        r = np.where(x > 130, F32(np.nan), r)         # NaN where +inf is expected
        r = np.where(np.isnan(x), F32(0.0), r)        # 0 where NaN is expected
        return np.where(x == -np.inf, F32(1e-30), r).astype(F32)
    r = evaluate(broken, "exp2", "full", *sample_inputs("exp2", 20_000, seed=3))
    assert not r.conforming
    counts = r.special_mismatches
    assert counts["zero_sign"] > 0 and counts["nan"] > 0 and counts["special_value"] == 1
    assert {c.category for c in r.special_examples} == {"zero_sign", "nan", "special_value"}
    example = next(c for c in r.special_examples if c.category == "zero_sign")
    assert example.got == 0 and np.signbit(example.got) and example.x < -150


def test_overflowing_results_are_scored_against_the_reference():
    """A finite result where the float32 rounding overflows is scored (the spec's
    tolerance decides); saturating at FLT_MAX far past 128 is non-conforming,
    and at an infinite operand only the exact infinity is accepted."""
    def clamped(x):
        return np.minimum(np.exp2(x), F32(3.4028235e38))
    r = sweep(clamped, "exp2", "full", start=bits(127.5), stop=bits(129.0), **quiet())
    assert r.special_mismatches["inf"] == 0
    assert 0 < r.nonconforming < bits(129.0) - bits(128.0)
    inf_bits = int(np.float32(np.inf).view(np.uint32))
    r = sweep(clamped, "exp2", "full", start=inf_bits, stop=inf_bits + 1, **quiet())
    assert r.special_mismatches["inf"] == 1


def test_infinity_near_overflow_is_permitted_only_within_tolerance():
    hi = bits(128.0)          # 2**x is within 3 + 2|x| ULP of FLT_MAX for the last 2 x

    def early_inf(first):
        threshold = np.uint32(first).view(F32)
        return lambda x: np.where(x >= threshold, F32(np.inf), np.exp2(x)).astype(F32)
    ok = sweep(early_inf(hi - 2), "exp2", "full", start=hi - 64, stop=hi, **quiet())
    assert ok.conforming and 0.5 < ok.max_margin < 1 and ok.max_margin_case.got == np.inf
    bad = sweep(early_inf(hi - 3), "exp2", "full", start=hi - 64, stop=hi, **quiet())
    assert bad.special_mismatches["spurious_inf"] == 1


def test_flush_to_zero_is_counted_not_a_mismatch():
    def ftz(x):
        r = np.exp2(x)
        return np.where(np.abs(r) < F32(2.0**-126), F32(0.0), r).astype(F32)
    r = sweep(ftz, "exp2", "full", start=bits(-126.0), stop=bits(-140.0), **quiet())
    assert r.flushed > 0.99 * (bits(-140.0) - bits(-126.0))
    assert r.conforming and r.mismatches == 0
    assert r.flush_examples and all(c.got == 0 for c in r.flush_examples)


def test_whole_range_bookkeeping_and_output_formats():
    r = sweep(np.sqrt, "sqrt", "full", start=0x7F000000, stop=0x80800000, chunk=2**20,
              **quiet())   # huge, inf, NaNs, -0 and negative subnormals
    assert r.count == 0x80800000 - 0x7F000000 and r.conforming
    data = json.loads(json.dumps(r.to_json()))
    assert data["count"] == r.count and data["special_mismatches"]["nan"] == 0
    assert data["max_ulp32_at"]["x_bits"].startswith("0x")
    text = r.table()
    assert "sqrt (full)" in text and "CONFORMS" in text and "max margin" in text


def test_pow_sweep_with_fixed_exponent_and_sample():
    r = sweep(np.power, "pow", "full", start=ONE, stop=ONE + 2**18, y=2.5, **quiet())
    assert r.conforming and r.count == 2**18 and r.max_margin_case.y == 2.5
    x, y = sample_inputs("pow", 2_000, seed=1)
    assert x.shape == y.shape and x.size > 2_000
    r = evaluate(np.power, "pow", "full", x, y)
    assert r.nonconforming == 0              # C99 powf differs only in special values
    assert r.special_mismatches["nan"] > 0   # e.g. powf(-2, 3) = -8, exp2(3*log2(-2)) = NaN


def test_sample_inputs_cover_the_hard_regions():
    (s,) = sample_inputs("exp2", 1000, seed=7)
    must = [0, 0x80000000, 0x7F800000, 0xFF800000, 0x7FC00000, 0x00000001, 0x007FFFFF,
            0x00800000, 0x7F7FFFFF, bits(128.0), bits(128.0) - 1, bits(-126.0),
            bits(-150.0) + 5, bits(2.0**-100), bits(-37.0), bits(1.0) + 4000]
    assert np.isin(np.array(must, dtype=np.uint32), s).all()
    assert np.array_equal(s, sample_inputs("exp2", 1000, seed=7)[0])
    assert not np.array_equal(s, sample_inputs("exp2", 1000, seed=8)[0])
    (log_s,) = sample_inputs("log2", 10, seed=0)
    assert np.isin(np.array([bits(0.5) - 3, bits(2.0) + 3], dtype=np.uint32), log_s).all()


def test_arguments_are_checked():
    with pytest.raises(ValueError):
        sweep(np.power, "pow", "full", **quiet())          # pow needs y
    with pytest.raises(ValueError):
        sweep(np.exp2, "exp2", "full", y=2.0, **quiet())
    with pytest.raises(ValueError):
        sweep(np.exp2, "exp2", "highp", **quiet())
    with pytest.raises(ValueError):
        sweep(np.exp2, "exp2", "full", start=5, stop=5, **quiet())
    with pytest.raises(TypeError):
        evaluate(lambda x: x.astype(np.float64), "exp2", "full", np.arange(4, dtype=np.uint32))


def _naive(kernel, func, precision, xb):
    """The definitions of measures/tolerance applied directly, input by input."""
    from routines.lab import measures as M
    from routines.lab.reference import reference
    from routines.lab.tolerance import tolerance
    x = xb.view(F32)
    with np.errstate(all="ignore"):
        got, ref = kernel(x), reference(func, x)
        allowed = tolerance(func, precision).allowed(x, ref)
        cat = M.classify(np.isfinite(x), got, ref, allowed)
        d = np.where(cat == M.INF_ALLOWED, M.F32_MAX - np.abs(ref), M.abs_error(got, ref))
        scored = (cat == M.SCORED) | (cat == M.INF_ALLOWED)
        e32 = np.where(scored, d / M.ulp32(ref), 0)
        margin = np.where(scored, d / allowed, 0)
    names = {M.CATEGORIES[c]: int(np.count_nonzero(cat == c)) for c in M.MISMATCHES}
    return e32.max(), margin.max(), int(np.count_nonzero(margin >= 1)), names, \
        int(np.count_nonzero(cat == M.FLUSH))


@pytest.mark.parametrize("func, kernel", [
    ("exp2", lambda x: np.where(x > 127.9, F32(np.inf), np.exp2(x) * F32(1 + 2.0**-21))),
    ("exp", lambda x: np.where(x < -87.5, F32(-0.0), np.exp(x))),
    ("log2", lambda x: np.where(x == 1, F32(-0.0), np.log2(x) + F32(1e-7))),
    ("rcp", lambda x: np.where(np.isinf(x), F32(1e-30), F32(1) / x)),
    ("sqrt", lambda x: np.sqrt(x) * F32(1 + 2.0**-22)),
])
@pytest.mark.parametrize("precision", ["full", "relaxed"])
def test_fast_paths_agree_with_the_definitions(func, kernel, precision):
    def k(x):
        return np.asarray(kernel(x), dtype=F32)
    (xb,) = sample_inputs(func, 30_000, seed=5)
    r = evaluate(k, func, precision, xb)
    e32, margin, bad, mismatches, flushed = _naive(k, func, precision, xb)
    assert (r.max_ulp32, r.max_margin, r.nonconforming, r.flushed) \
        == (e32, margin, bad, flushed)
    assert r.special_mismatches == mismatches
