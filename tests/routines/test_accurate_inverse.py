"""The faithful and correct tiers of asin, acos, atan and the faithful atan2
(routines/accurate_inverse.py) on the compiled kernels: correct rounding against the lab's
correctly rounded reference on a sample and the hard regions, faithfulness, every hard case of
the tables, specials and NaN bits, the FMA toggle, the same bits on every x86 level, and the
float64 value's error bound against mpmath. The exhaustive proofs are
``python -m routines ladder asin acos atan --exhaustive``."""
import itertools

import mpmath
import numpy as np
import pytest

import reactor
import routines
import tier_checks
from reactor import Double, Float, Precision
from routines import accurate_inverse as inverse
from routines import correct
from routines.lab import rounding as ladder
from routines.lab.pairs import atan2_strata
from routines.specials import ROWS, RULES, same

NAMES = ("asin", "acos", "atan")
#: every 65537th bit pattern (all binades and signs), plus the regions where rounding is hard
SAMPLE = np.arange(0, 2 ** 32, 65537, dtype=np.uint64).astype(np.uint32)


def _region(lo: float, hi: float, n: int = 1 << 14) -> np.ndarray:
    a, b = np.float32(lo).view(np.int32), np.float32(hi).view(np.int32)
    return np.linspace(min(a, b), max(a, b), n).astype(np.int32).view(np.uint32)


HARD = {   # tiny |x| (x - x^3/3), |x| near 1/2 and 1, atan's sector edges, large |x|
    "asin": [(1e-12, 1e-3), (0.49, 0.51), (-0.51, -0.49), (0.99, 1.0), (-1.0, -0.99), (1e-45, 1e-38)],
    "acos": [(1e-12, 1e-3), (0.49, 0.51), (-0.51, -0.49), (0.999, 1.0), (-1.0, -0.999), (-1e-3, -1e-12)],
    "atan": [(1e-12, 1e-3), (0.41, 0.42), (0.99, 1.01), (2.41, 2.42), (-2.42, -2.41), (3e7, 1e9),
             (1e30, 3.4e38), (1e-45, 1e-38)],
}


def _inputs(func):
    return np.concatenate([SAMPLE] + [_region(*r) for r in HARD[func]])


@pytest.mark.parametrize("fma", [True, False])
@pytest.mark.parametrize("func", NAMES)
def test_correct_tier_is_correctly_rounded(func, fma):
    tier_checks.assert_correctly_rounded(func, fma, _inputs(func))


@pytest.mark.parametrize("fma", [True, False])
@pytest.mark.parametrize("func", NAMES)
def test_faithful_tier_is_below_one_ulp(func, fma):
    """0.5 + 2^24 * 2^-30.6 ULP at most (the float64 value's error, module docstring)."""
    tier_checks.assert_faithful(func, fma, _inputs(func), 0.511)


@pytest.mark.parametrize("func", NAMES)
def test_every_hard_case_of_the_table_comes_out_right(func):
    """The inputs the rounding test cannot decide (``routines/hard_cases``): looked up."""
    keys, values = correct.table(func)
    if keys.size == 0:
        pytest.skip(f"routines/hard_cases/{func}.npy not generated yet (python -m routines hardcases)")
    x = keys.view(np.float32)
    for fma in (True, False):
        got = routines.jit(func, "correct", fma=fma)(x).view(np.int32)
        assert (got == values).all(), (func, fma, x[got != values][:4])


def _rows(func):
    return [r for r in ROWS if r.function == func]


@pytest.mark.parametrize("tier", ["faithful", "correct"])
@pytest.mark.parametrize("func", NAMES)
def test_special_values(func, tier):
    """docs/specials.md's rows (C99 Annex F) and exactness rules, bit for bit, and the NaN bits:
    out of [-1, 1] the default NaN 0xffc00000, a NaN input quieted (payload and sign kept)."""
    for fma in (True, False):
        u = routines.jit(func, tier, fma=fma)
        for row in _rows(func):
            got, want = u(np.float32(row.args[0])), np.float32(row.expected)
            assert (np.isnan(got) and np.isnan(want)) or got.view(np.uint32) == want.view(np.uint32), (row, got)
        for rule in RULES:                               # asin(x) = x, atan(x) = x for |x| <= 2^-12
            if rule.function == func:
                inputs, expected = rule.inputs()
                assert same(u(*inputs), expected).all(), rule.text
        payloads = np.array([0x7FC00001, 0xFFC12345, 0x7F800001, 0xFF812345], np.uint32)
        got = u(payloads.view(np.float32)).view(np.uint32)
        assert (got == (payloads | 0x00400000)).all(), [hex(v) for v in got]
        x = np.array([0.0, -0.0, 1.0, -1.0, np.inf, -np.inf, 1.0000001, -1.0000001, 3e38, 1e-45, -1e-45], np.float32)
        bits = u(x).view(np.uint32)
        if func == "asin":
            assert list(bits[:2]) == [0, 0x80000000]                            # asin(-0) = -0
            assert bits[2] == 0x3FC90FDB and bits[3] == 0xBFC90FDB
            assert (bits[4:9] == 0xFFC00000).all()
            assert bits[9] == 1 and bits[10] == 0x80000001                     # asin(x) = x for tiny x
        elif func == "acos":
            assert bits[0] == bits[1] == 0x3FC90FDB and bits[2] == 0 and bits[3] == 0x40490FDB   # acos(1) = +0
            assert (bits[4:9] == 0xFFC00000).all()
            assert bits[9] == bits[10] == 0x3FC90FDB
        else:
            assert list(bits[:2]) == [0, 0x80000000]                            # atan(-0) = -0
            assert bits[4] == 0x3FC90FDB and bits[5] == 0xBFC90FDB             # the float32 nearest pi/2
            assert bits[8] == 0x3FC90FDB and bits[9] == 1 and bits[10] == 0x80000001


def test_fma_off_emits_no_fused_operation():
    for func, tier in itertools.product(NAMES, ("faithful", "correct")):
        asm = reactor.kernel_of(routines.jit(func, tier, fma=False)).assembly
        assert not any(op in asm for op in ("vfmadd", "vfmsub", "vfnmadd", "vfnmsub")), (func, tier)


@pytest.mark.parametrize("func", NAMES)
def test_the_same_bits_at_every_x86_level(func):
    tier_checks.assert_the_same_bits_at_every_x86_level(func, _inputs(func)[::7])


_DOUBLE = {"asin": inverse.asin_double, "acos": inverse.acos_double, "atan": inverse.atan_double}
_EXACT = {"asin": lambda v: mpmath.asin(abs(v)), "acos": mpmath.acos, "atan": lambda v: mpmath.atan(abs(v))}


def _double_kernel(func, tier, fma):
    build, level = _DOUBLE[func], Precision(tier)

    def body(x: Float) -> Double:
        return build(x, level)
    return reactor.kernel(body, name=f"{func}_{tier}_double_{'fma' if fma else 'nofma'}", fma=fma)


def _worst_points(func):
    """A few thousand inputs, dense where the analysis puts the largest error."""
    rng = np.random.default_rng(1)

    def f32(*regions):
        return [_region(*r).view(np.float32) for r in regions]
    if func == "atan":
        parts = f32((0.56, 0.58, 800), (0.41, 0.42, 600), (2.41, 2.42, 600), (1e-9, 0.4, 400), (50, 3e38, 300))
        parts.append(rng.uniform(0, 50, 800).astype(np.float32))
    else:
        parts = f32((0.5, 0.5005, 1200), (0.97, 1.0, 600), (1e-9, 0.5, 600))
        parts.append(rng.uniform(0, 1, 800).astype(np.float32))
    x = np.concatenate(parts)
    return np.concatenate([x, -x]) if func == "acos" else x


@pytest.mark.parametrize("func", NAMES)
def test_the_float64_value_meets_its_error_bound(func):
    """y's relative error against mpmath: below 2^-49 (routines.correct.ERROR) in the correct
    tier, 2^-30 in the faithful one, with FMA on and off (docstring: measured 2^-50.4 at most)."""
    x = _worst_points(func)
    with mpmath.workdps(40):
        exact = [_EXACT[func](mpmath.mpf(float(v))) for v in x]
    for tier, fma in itertools.product(("faithful", "correct"), (True, False)):
        y = _double_kernel(func, tier, fma)(x)
        with mpmath.workdps(40):
            worst = max(abs(mpmath.mpf(float(yi)) / e - 1) for yi, e in zip(y, exact) if e != 0)
        bound = correct.ERROR if tier == "correct" else 2.0 ** -30
        assert worst < bound, (tier, fma, float(worst))


@pytest.mark.parametrize("poly", inverse.POLYNOMIALS, ids=lambda p: p.name)
def test_polynomials_meet_their_stated_error(poly):
    """Each binary64 polynomial's relative error on a dense grid (mpmath) is within 1.5 times its
    provenance's levelled error (after rounding to binary64)."""
    stated = float(poly.provenance.split("levelled error ")[1].split(" ")[0])
    if poly.name.startswith("asin"):      # 2 asin(sqrt(u)/2)/sqrt(u)
        def f(u):
            return 2 * mpmath.asin(mpmath.sqrt(u) / 2) / mpmath.sqrt(u)
    else:                                 # atan(sqrt(z))/sqrt(z)
        def f(z):
            return mpmath.atan(mpmath.sqrt(z)) / mpmath.sqrt(z)
    lo, hi = (float(v) for v in poly.interval)
    worst = mpmath.mpf(0)
    with mpmath.workdps(40):
        for z in np.linspace(lo, hi, 401)[1:]:
            zm = mpmath.mpf(float(z))
            p = mpmath.mpf(0)
            for c in poly.values:
                p = p * zm + mpmath.mpf(c)
            worst = max(worst, abs(p / f(zm) - 1))
    assert float(worst) <= stated * 1.5 + 2 ** -53, (float(worst), stated)


def _atan2_kernel(fma):
    def body(y: Float, x: Float) -> Float:
        return inverse.atan2(y, x, Precision.FAITHFUL)
    return reactor.kernel(body, name=f"atan2_faithful_{'fma' if fma else 'nofma'}", fma=fma)


def _atan2_pairs():
    rng = np.random.default_rng(11)
    ys, xs = [], []
    for b in atan2_strata(0)[::8]:                       # 32 strata of x, random y over all patterns
        ys.append(rng.integers(0, 2 ** 32, 1024, dtype=np.uint64).astype(np.uint32))
        xs.append(np.full(1024, b, np.uint32))
    x = rng.uniform(-100, 100, 1 << 13).astype(np.float32)
    for k in (np.float32(inverse.TAN_PI_8), np.float32(inverse.TAN_3PI_8), np.float32(1.0)):  # sector edges
        y = (x * k * (1 + rng.uniform(-1e-6, 1e-6, x.size))).astype(np.float32)
        ys += [y.view(np.uint32), (-y).view(np.uint32)]
        xs += [x.view(np.uint32), x.view(np.uint32)]
    return np.concatenate(ys), np.concatenate(xs)


def test_atan2_is_faithful_with_c99_specials():
    """atan2(y, x) (called y first, as the lab's reference): below 0.511 ULP on strata and the
    sector edges, docs/specials.md's rows bit for bit, the first NaN (y's, else x's) quieted."""
    ys, xs = _atan2_pairs()
    for fma in (True, False):
        u = _atan2_kernel(fma)
        r = ladder.score(u, "atan2", "faithful", ys, xs)
        assert r.max_ulp < 0.511, (fma, r.max_ulp, r.max_ulp_at)
        for row in _rows("atan2"):
            got = u(np.float32(row.args[0]), np.float32(row.args[1]))
            want = np.float32(row.expected)
            assert (np.isnan(got) and np.isnan(want)) or got.view(np.uint32) == want.view(np.uint32), (row, got)
        nan_y, nan_x = np.array([0x7FC00001, 0xFF812345], np.uint32), np.array([0xFFC00002, 0x7F800003], np.uint32)
        one = np.ones(2, np.float32)
        assert (u(nan_y.view(np.float32), one).view(np.uint32) == nan_y | 0x00400000).all()
        assert (u(one, nan_x.view(np.float32)).view(np.uint32) == nan_x | 0x00400000).all()
        assert (u(nan_y.view(np.float32), nan_x.view(np.float32)).view(np.uint32) == nan_y | 0x00400000).all()
    def correct_body(y: Float, x: Float) -> Float:
        return inverse.atan2(y, x, Precision.CORRECT)
    with pytest.raises(reactor.ReactorError, match="faithful"):
        reactor.kernel(correct_body, name="atan2_correct")(np.ones(1, np.float32), np.ones(1, np.float32))
