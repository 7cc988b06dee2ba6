"""The faithful and correct tiers (routines/accurate.py, routines/doubled.py) on the compiled
kernels: correct rounding against the lab's correctly rounded reference, faithfulness, NaN
bits, the FMA toggle, the same bits on every x86 level, and the refusals of routines
without these tiers. The exhaustive proofs are ``python -m routines ladder --exhaustive``."""

import mpmath
import numpy as np
import pytest

import reactor
import routines
import tier_checks
from routines.base import tiers
from routines.lab import rounding as ladder
from routines.polynomials import DOUBLE

CORRECT = ("exp2", "exp", "log2", "log", "rcp", "rsqrt", "sqrt")
#: every 65537th bit pattern (all binades and signs), plus the regions where rounding is hard
SAMPLE = np.arange(0, 2 ** 32, 65537, dtype=np.uint64).astype(np.uint32)


def _region(lo: float, hi: float, n: int = 1 << 16) -> np.ndarray:
    a, b = np.float32(lo).view(np.int32), np.float32(hi).view(np.int32)
    return np.linspace(min(a, b), max(a, b), n).astype(np.int32).view(np.uint32)


HARD = {
    "exp2": [(-150.0, -125.0), (-1e-6, 1e-6), (127.0, 128.0)],
    "exp": [(-104.0, -86.0), (-1e-6, 1e-6), (88.0, 88.8)],
    "log2": [(0.99, 1.01), (1e-45, 1e-37), (1.4, 1.6)],
    "log": [(0.99, 1.01), (1e-45, 1e-37), (3e38, 3.4e38)],
}


def _inputs(func):
    return np.concatenate([SAMPLE] + [_region(*r) for r in HARD.get(func, [])])


@pytest.mark.parametrize("fma", [True, False])
@pytest.mark.parametrize("func", CORRECT)
def test_correct_tier_is_correctly_rounded(func, fma):
    tier_checks.assert_correctly_rounded(func, fma, _inputs(func))


@pytest.mark.parametrize("fma", [True, False])
@pytest.mark.parametrize("func", ("exp2", "exp", "log2", "log", "rsqrt"))
def test_faithful_tier_is_below_one_ulp(func, fma):
    tier_checks.assert_faithful(func, fma, _inputs(func), 1.0)


def test_faithful_pow_on_its_hard_pairs_and_a_stratum():
    u = routines.jit("pow", "faithful")
    r = ladder.score(u, "pow", "faithful", *ladder.pow_hard_cases())
    assert r.max_ulp < 0.6, r.examples
    x = SAMPLE
    for y in (0.5, -1.5, 3.0, 2.2, -40.0, 117.3):
        r = ladder.score(u, "pow", "faithful", x, np.full(x.size, np.float32(y).view(np.uint32)))
        assert r.max_ulp < 0.6, (y, r.max_ulp_at)


@pytest.mark.parametrize("fma", [True, False])
def test_correct_pow_on_its_hard_pairs_and_strata(fma):
    """The hard pairs include every exact result halfway between two floats (normal and
    subnormal) that the double-double path alone would round either way."""
    u = routines.jit("pow", "correct", fma=fma)
    r = ladder.score(u, "pow", "correct", *ladder.pow_hard_cases())
    assert r.misrounded == 0, r.examples
    for y in (0.5, -1.5, 2.0, 3.0, 2.2, -40.0, 117.3, 1e-5):
        r = ladder.score(u, "pow", "correct", SAMPLE, np.full(SAMPLE.size, np.float32(y).view(np.uint32)))
        assert r.misrounded == 0, (y, r.examples)


def test_correct_pow_rounds_exact_midpoints_to_even():
    x = np.array([1 + 2 ** -12, -(1 + 2 ** -8), 2 ** -75, 3 * 2 ** -75, 2 ** -100, 257 ** 2, 3 ** 2 * 2.0 ** -100],
                 np.float32)
    y = np.array([2, 3, 2, 2, 1.5, 1.5, 1.5], np.float32)
    got = routines.jit("pow", "correct")(x, y)
    want = np.array([1 + 2 ** -11, -np.float32((1 + 2 ** -8) ** 3), 0.0, 4 * 2.0 ** -149, 0.0,
                     16974592.0,              # 257^3 = 16974593: halfway, to even
                     14 * 2.0 ** -149],       # 27 2^-150 = 13.5 2^-149: halfway, to even
                    np.float32)
    assert (got.view(np.uint32) == want.view(np.uint32)).all(), got


@pytest.mark.parametrize("func", ("exp2", "exp", "log2", "log"))
@pytest.mark.parametrize("tier", ("faithful", "correct"))
def test_nan_inputs_come_back_quieted(func, tier):
    payloads = np.array([0x7FC00001, 0xFFC12345, 0x7F800001, 0xFF812345], np.uint32)
    got = routines.jit(func, tier)(payloads.view(np.float32)).view(np.uint32)
    assert (got == (payloads | 0x00400000)).all(), [hex(v) for v in got]


@pytest.mark.parametrize("func", ("exp2", "log"))
def test_fma_off_emits_no_fused_operation(func):
    for tier in ("faithful", "correct"):
        asm = reactor.kernel_of(routines.jit(func, tier, fma=False)).assembly
        assert "vfmadd" not in asm and "vfmsub" not in asm and "vfnmadd" not in asm


@pytest.mark.parametrize("func", ("exp2", "exp", "log2", "log"))
def test_the_same_bits_at_every_x86_level(func):
    """Correctly rounded results are unique; the faithful tier's float32 path (FMA on, emulated
    exactly at sse4) and float64 path (FMA off: rounded multiplies and adds) are the same code
    everywhere."""
    tier_checks.assert_the_same_bits_at_every_x86_level(func, _inputs(func))


def test_every_routine_has_every_tier_and_a_wrong_name_is_refused_clearly():
    assert all(tiers(name) == ("relaxed", "full", "faithful", "correct") for name in routines.NAMES)
    with pytest.raises(reactor.ReactorError, match="sin: precision must be one of 'relaxed', 'full', "
                                                   "'faithful', 'correct', not 'exact'"):
        routines.jit("sin", "exact")


def test_a_kernel_can_ask_for_a_tier():
    @reactor.kernel(precision="correct")
    def softplus_base2(x: reactor.Float) -> reactor.Float:
        return routines.log2(1.0 + routines.exp2(x))

    x = np.linspace(-20, 20, 1001, dtype=np.float32)
    with np.errstate(all="ignore"):
        inner = np.float32(1) + np.exp2(x.astype(np.float64)).astype(np.float32)
    want = np.log2(inner.astype(np.float64)).astype(np.float32)
    assert (softplus_base2(x) == want).all()


@pytest.mark.parametrize("poly", DOUBLE, ids=lambda p: p.name)
def test_double_polynomials_meet_their_stated_error(poly):
    """Each binary64 polynomial's relative error, measured with mpmath on a dense grid, is
    within 1% of the levelled error its provenance states (after rounding to binary64)."""
    stated = float(poly.provenance.split("levelled error ")[1].split(" ")[0])
    lo, hi = (float(v) for v in poly.interval)
    f = {"2^x": lambda v: mpmath.power(2, v)}.get(poly.function)
    if f is None:  # Q(z) = 2 atanh(sqrt z) / (sqrt z ln 2)
        def f(z):
            s = mpmath.sqrt(z)
            return 2 * mpmath.atanh(s) / (s * mpmath.log(2))
    worst = mpmath.mpf(0)
    with mpmath.workdps(40):
        for v in np.linspace(lo, hi, 801)[1:]:
            p = mpmath.mpf(0)
            for c in poly.values:
                p = p * mpmath.mpf(float(v)) + mpmath.mpf(c)
            worst = max(worst, abs(p / f(mpmath.mpf(float(v))) - 1))
    assert float(worst) <= stated * 1.5 + 2 ** -52, (float(worst), stated)


@pytest.mark.parametrize("func", CORRECT)
def test_the_labs_correctly_rounded_reference_agrees_with_mpmath(func):
    """The reference the exhaustive proof trusts: float64 rounded, mpmath near midpoints."""
    rng = np.random.default_rng(5)
    x = np.concatenate([_inputs(func)[::97], rng.integers(0, 2 ** 32, 3000, dtype=np.uint64).astype(np.uint32)])
    x = x.view(np.float32)
    got, _ = ladder.correctly_rounded(func, x)
    f = {"exp2": lambda v: mpmath.power(2, v), "exp": mpmath.exp, "log2": lambda v: mpmath.log(v, 2),
         "log": mpmath.log, "rcp": lambda v: 1 / v, "rsqrt": lambda v: 1 / mpmath.sqrt(v), "sqrt": mpmath.sqrt}[func]
    checked = 0
    with mpmath.workprec(24):
        for xi, gi in zip(x, got):
            v = float(xi)
            if not np.isfinite(v) or (v <= 0 and func not in ("exp2", "exp", "rcp")) or v == 0:
                continue
            with mpmath.workprec(200):
                exact = f(mpmath.mpf(v))
            if not (2.0 ** -126 <= abs(exact) < 2.0 ** 128):
                continue
            want = np.float32(float(+exact))  # unary plus rounds to the context's 24 bits, to nearest
            assert gi == want, (func, v, gi, want)
            checked += 1
    assert checked > 1000
