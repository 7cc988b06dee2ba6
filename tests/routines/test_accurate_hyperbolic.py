"""The faithful and correct tiers of sinh, cosh and tanh (routines/accurate_hyperbolic.py) on the
compiled kernels: correct rounding against the lab's correctly rounded reference on a sample and
on the regions where these functions are hard, faithfulness, both FMA settings, the specials
(signed zeros, infinities, overflow, saturation, NaN payloads), and the float64 value's error
bound against mpmath. The exhaustive proof is ``python -m routines ladder --exhaustive``."""
import math

import mpmath
import numpy as np
import pytest

import reactor
import routines
import tier_checks
from routines import accurate_hyperbolic as H
from routines import correct
from routines.lab import rounding as ladder

FUNCS = ("sinh", "cosh", "tanh")
#: every 65537th bit pattern (all binades and signs)
SAMPLE = np.arange(0, 2 ** 32, 65537, dtype=np.uint64).astype(np.uint32)
#: the greatest float32 whose sinh and cosh round to a finite float (89.415985, 0x42b2d4fc); the
#: next one overflows
LAST_FINITE = np.uint32(0x42B2D4FC).view(np.float32)


def _region(lo: float, hi: float, n: int = 1 << 14) -> np.ndarray:
    a, b = np.float32(lo).view(np.int32), np.float32(hi).view(np.int32)
    return np.linspace(min(a, b), max(a, b), n).astype(np.int32).view(np.uint32)


#: tiny |x| (results ~x or ~1), the switch from k = 0 to k = 1 at ln2/2 (where sinh's two terms
#: cancel most), k = 1 and 2, the overflow threshold, tanh's saturation to 1
HARD = {
    "sinh": [(1e-45, 1e-37), (1e-6, 1e-3), (0.33, 0.5), (1.0, 1.1), (89.0, 89.6)],
    "cosh": [(1e-6, 3e-3), (0.33, 0.5), (1.0, 1.1), (89.0, 89.6)],
    "tanh": [(1e-45, 1e-37), (1e-6, 1e-3), (0.33, 0.5), (1.0, 1.1), (8.0, 10.0)],
}


def _inputs(func):
    keys, _ = correct.table(func)  # the hard cases themselves: the correct tier's lookup path
    regions = [_region(*r) for r in HARD[func]]
    both_signs = [v for r in regions for v in (r, r | np.uint32(0x80000000))]
    return np.concatenate([SAMPLE, keys.view(np.uint32)] + both_signs)


@pytest.mark.parametrize("fma", [True, False])
@pytest.mark.parametrize("func", FUNCS)
def test_correct_tier_is_correctly_rounded(func, fma):
    tier_checks.assert_correctly_rounded(func, fma, _inputs(func))


@pytest.mark.parametrize("fma", [True, False])
@pytest.mark.parametrize("func", FUNCS)
def test_faithful_tier_is_below_one_ulp(func, fma):
    tier_checks.assert_faithful(func, fma, _inputs(func), 0.51)  # 0.5 + 2^24 * (float64 error < 2^-33)


def _bits(v):
    return np.asarray(v, np.float32).view(np.uint32)


SPECIALS = [  # (x, (sinh, cosh, tanh)), compared bit for bit (None: the correctly rounded value)
    (0.0, (0.0, 1.0, 0.0)),
    (-0.0, (-0.0, 1.0, -0.0)),
    (math.inf, (math.inf, math.inf, 1.0)),
    (-math.inf, (-math.inf, math.inf, -1.0)),
    (1e-45, (1e-45, 1.0, 1e-45)),
    (-1e-45, (-1e-45, 1.0, -1e-45)),
    (float(LAST_FINITE), (None, None, 1.0)),
    (-float(LAST_FINITE), (None, None, -1.0)),
    (float(np.nextafter(LAST_FINITE, np.float32(np.inf))), (math.inf, math.inf, 1.0)),
    (-89.5, (-math.inf, math.inf, -1.0)),
    (1e30, (math.inf, math.inf, 1.0)),
    (9.02, (None, None, 1.0)),
    (-9.02, (None, None, -1.0)),
]


@pytest.mark.parametrize("fma", [True, False])
@pytest.mark.parametrize("tier", ["faithful", "correct"])
def test_specials(tier, fma):
    x = np.array([v for v, _ in SPECIALS], np.float32)
    for i, func in enumerate(FUNCS):
        rounded, _ = ladder.correctly_rounded(func, x)
        want = np.array([rounded[j] if v[i] is None else v[i] for j, (_, v) in enumerate(SPECIALS)], np.float32)
        got = routines.jit(func, tier, fma=fma)(x)
        bad = _bits(got) != _bits(want)
        assert not bad.any(), (func, x[bad], got[bad], want[bad])
    assert np.isfinite(routines.jit("sinh", tier, fma=fma)(LAST_FINITE))


def test_the_overflow_threshold_is_where_the_reference_puts_it():
    x = np.array([LAST_FINITE, np.nextafter(LAST_FINITE, np.float32(np.inf))], np.float32)
    with mpmath.workdps(30):
        assert mpmath.sinh(mpmath.mpf(float(x[0]))) < 2 ** 128 - 2 ** 103 < mpmath.sinh(mpmath.mpf(float(x[1])))


@pytest.mark.parametrize("func", FUNCS)
@pytest.mark.parametrize("tier", ["faithful", "correct"])
def test_nan_inputs_come_back_quieted(func, tier):
    payloads = np.array([0x7FC00001, 0xFFC12345, 0x7F800001, 0xFF812345], np.uint32)
    got = routines.jit(func, tier)(payloads.view(np.float32)).view(np.uint32)
    assert (got == (payloads | 0x00400000)).all(), [hex(v) for v in got]


@pytest.mark.parametrize("func", FUNCS)
def test_fma_off_emits_no_fused_operation(func):
    for tier in ("faithful", "correct"):
        asm = reactor.kernel_of(routines.jit(func, tier, fma=False)).assembly
        assert "vfmadd" not in asm and "vfmsub" not in asm and "vfnmadd" not in asm


def test_the_faithful_tier_gives_the_same_bits_with_fma_on_and_off():
    """Its float64 evaluation uses rounded multiplies and adds only."""
    for func in FUNCS:
        x = _inputs(func).view(np.float32)
        on, off = (routines.jit(func, "faithful", fma=fma)(x).view(np.uint32) for fma in (True, False))
        assert (on == off).all(), func


def _value_kernel(func, tier, fma):
    value = getattr(H, f"{func}_value")
    precision = reactor.Precision(tier)

    def body(x: reactor.Float) -> reactor.Double:
        return value(x, precision)
    return reactor.kernel(body, name=f"{func}_{tier}_{'fma' if fma else 'nofma'}_value", fma=fma)


def _value_points(func):
    """|x| over the whole range, around the switch between every two k (x = (k + 1/2) ln 2, where
    |r| is largest), the cancelling region of k = 1, and tiny values."""
    rng = np.random.default_rng(11)
    top = 9.5 if func == "tanh" else 89.41
    ks = np.arange(int(top / math.log(2)) + 1)
    edges = (ks[:, None] + 0.5) * math.log(2) + rng.uniform(-0.02, 0.02, (ks.size, 8))
    x = np.concatenate([rng.uniform(0, top, 600), rng.uniform(0.34, 0.45, 300), edges.ravel(),
                        2.0 ** rng.uniform(-60, -1, 200)]).astype(np.float32)
    return x[(x > 0) & (x <= top)]


@pytest.mark.parametrize("func", FUNCS)
def test_the_float64_value_meets_the_error_bound(func):
    """The value the tiers round: relative error below 2^-49 (correct, the bound ``correct.finish``
    assumes; the docstring's analysis gives 2^-49.8) and 2^-33 (faithful), against mpmath."""
    x = _value_points(func)
    f = getattr(mpmath, func)
    with mpmath.workprec(120):
        exact = [f(mpmath.mpf(float(v))) for v in x]
        for tier, fma, bound in (("correct", True, 2.0 ** -49), ("correct", False, 2.0 ** -49),
                                 ("faithful", False, 2.0 ** -33)):
            y = _value_kernel(func, tier, fma)(x)
            worst = max(abs((mpmath.mpf(float(yi)) - e) / e) for yi, e in zip(y, exact))
            assert worst < bound, (func, tier, fma, float(worst))


@pytest.mark.parametrize("poly", H.POLYNOMIALS, ids=lambda p: p.name)
def test_polynomials_meet_their_stated_error(poly):
    """z * P(z) against cosh(r) - 1 or sinh(r)/r - 1 (z = r^2) on a dense grid, with the binary64
    coefficients: within 1% of the error the provenance states for them (the fitter's levelled error
    plus the coefficients' rounding)."""
    stated = float(poly.provenance.split("binary64 coefficients: ")[1].split(" ")[0])
    f = {"cosh": lambda s: mpmath.cosh(s) - 1, "sinh": lambda s: mpmath.sinh(s) / s - 1}[poly.name.split(".")[0]]
    worst = mpmath.mpf(0)
    with mpmath.workdps(40):
        for v in np.linspace(0, float(poly.interval[1]), 1201)[1:]:
            z = mpmath.mpf(float(v))
            p = mpmath.mpf(0)
            for c in poly.values:
                p = p * z + mpmath.mpf(c)
            worst = max(worst, abs(z * p - f(mpmath.sqrt(z))))
    assert float(worst) <= stated * 1.01, (float(worst), stated)


@pytest.mark.parametrize("func", FUNCS)
def test_the_same_bits_at_every_x86_level(func):
    tier_checks.assert_the_same_bits_at_every_x86_level(func, _inputs(func))
