"""The faithful and correct tiers of sin, cos and tan (routines/accurate_trig.py) on the compiled
kernels: correct rounding against the lab's correctly rounded reference on a sample and on the
regions where the reduction is hard, faithfulness, the special values and NaN bits, the FMA
toggle, the same bits at every x86 level, and the float64 value's error bound against mpmath.
The exhaustive proof is ``python -m routines ladder sin cos tan --exhaustive``."""
import itertools

import mpmath
import numpy as np
import pytest

import reactor
import routines
import tier_checks
from reactor import Precision
from routines import accurate_trig
from routines.correct import ERROR

FUNCS = ("sin", "cos", "tan")
#: every 65537th bit pattern (all binades and signs)
SAMPLE = np.arange(0, 2 ** 32, 65537, dtype=np.uint64).astype(np.uint32)
#: the float32 closest to a multiple of pi/2 (exact integer search over every binade; the
#: first is the closest of all, |x - k pi/2| = 1.6e-9 at x = 7.7e28; 0x437ce5f1 = 252.898 is
#: the closest below 2^17, 4.2e-9), and fl(pi/2) and its neighbour (tan's largest results)
WORST = np.array([
    0x6F79BE45, 0x50A3E87F, 0x6FF9BE45, 0x5123E87F, 0x437CE5F1, 0x7079BE45, 0x6A1976F1, 0x53B146A6,
    0x65898498, 0x51A3E87F, 0x43FCE5F1, 0x77584625, 0x4C2332E9, 0x4096CBE4, 0x6C55DA58, 0x70F9BE45,
    0x6A9976F1, 0x5C07BCD0, 0x543146A6, 0x66098498, 0x5223E87F, 0x474D246F, 0x723FA09A, 0x447CE5F1,
    0x4116CBE4, 0x47CD246F, 0x44FCE5F1, 0x416231D6, 0x3FC90FDB, 0x4196CBE4, 0x450BE628, 0x41BC7EDD,
    0x457CE5F1, 0x41E231D6, 0x3FC90FDA], np.uint32)


def _region(lo: float, hi: float, n: int = 1 << 14) -> np.ndarray:
    a, b = np.float32(lo).view(np.int32), np.float32(hi).view(np.int32)
    return np.linspace(min(a, b), max(a, b), n).astype(np.int32).view(np.uint32)


def _near_multiples_of_pio2(count: int = 4000, spread: int = 3) -> np.ndarray:
    """The float32 nearest k pi/2, k < count, and their neighbours."""
    bits = (np.arange(1, count) * (np.pi / 2)).astype(np.float32).view(np.int32)
    return np.concatenate([bits + d for d in range(-spread, spread + 1)]).view(np.uint32)


def _hard() -> np.ndarray:
    """Tiny |x| (results ~x, cos ~1), near multiples of pi/2 (small results, tan's poles), the
    worst cases of the reduction, [2^17, 2^18] (Payne-Hanek's first binade), huge |x|."""
    regions = [_region(1e-45, 1e-3), _region(1e-3, 0.8), _region(2.0 ** 17, 2.0 ** 18),
               _region(1e30, 1.001e30), _region(3.0e38, 3.4028235e38), _near_multiples_of_pio2(),
               (WORST.view(np.int32)[:, None] + np.arange(-2, 3)).ravel().view(np.uint32)]
    positive = np.concatenate(regions)
    return np.concatenate([positive, positive | np.uint32(0x80000000)])


HARD = _hard()


def _inputs() -> np.ndarray:
    return np.concatenate([SAMPLE, HARD])


@pytest.mark.parametrize("fma", [True, False])
@pytest.mark.parametrize("func", FUNCS)
def test_correct_tier_is_correctly_rounded(func, fma):
    tier_checks.assert_correctly_rounded(func, fma, _inputs())


@pytest.mark.parametrize("fma", [True, False])
@pytest.mark.parametrize("func", FUNCS)
def test_faithful_tier_is_below_one_ulp(func, fma):
    tier_checks.assert_faithful(func, fma, _inputs(), 0.6)   # bound: 0.5 + 2^24 * 2^-29.2 = 0.53


SPECIALS = np.array([0x00000000, 0x80000000, 0x7F800000, 0xFF800000, 0x00000001, 0x80000001, 0x007FFFFF,
                     0x7F7FFFFF, 0xFF7FFFFF], np.uint32)


@pytest.mark.parametrize("tier", ("faithful", "correct"))
@pytest.mark.parametrize("fma", [True, False])
def test_special_values(tier, fma):
    x = SPECIALS.view(np.float32)
    sin, cos, tan = (routines.jit(f, tier, fma=fma)(x).view(np.uint32) for f in FUNCS)
    nan = 0xFFC00000                                     # inf - inf: the default NaN (docs/specials.md)
    assert list(sin[:4]) == [0x00000000, 0x80000000, nan, nan]      # sin(+-0) = +-0
    assert list(tan[:4]) == [0x00000000, 0x80000000, nan, nan]
    assert list(cos[:4]) == [0x3F800000, 0x3F800000, nan, nan]      # cos(+-0) = 1
    assert list(sin[4:7]) == list(SPECIALS[4:7]) and list(tan[4:7]) == list(SPECIALS[4:7])  # tiny: x
    assert (cos[4:7] == 0x3F800000).all()
    with mpmath.workprec(400):
        for v, s, c, t in zip(x[7:], sin[7:], cos[7:], tan[7:]):    # +-FLT_MAX: Payne-Hanek
            for got, f in ((s, mpmath.sin), (c, mpmath.cos), (t, mpmath.tan)):
                want = np.float32(float(f(mpmath.mpf(float(v)))))
                assert abs(np.uint32(got).view(np.float32) - want) <= abs(np.spacing(want)), (v, f)


@pytest.mark.parametrize("func", FUNCS)
@pytest.mark.parametrize("tier", ("faithful", "correct"))
def test_nan_inputs_come_back_quieted(func, tier):
    payloads = np.array([0x7FC00001, 0xFFC12345, 0x7F800001, 0xFF812345, 0x7FC00000, 0xFFC00000], np.uint32)
    for fma in (True, False):
        got = routines.jit(func, tier, fma=fma)(payloads.view(np.float32)).view(np.uint32)
        assert (got == (payloads | 0x00400000)).all(), [hex(v) for v in got]


@pytest.mark.parametrize("func", ("sin", "tan"))
def test_fma_off_emits_no_fused_operation(func):
    for tier in ("faithful", "correct"):
        asm = reactor.kernel_of(routines.jit(func, tier, fma=False)).assembly
        assert "vfmadd" not in asm and "vfmsub" not in asm and "vfnmadd" not in asm


@pytest.mark.parametrize("func", FUNCS)
def test_the_same_bits_at_every_x86_level(func):
    tier_checks.assert_the_same_bits_at_every_x86_level(func, np.concatenate([SAMPLE[::4], HARD[::8]]))


def test_the_widths_agree():
    x = np.concatenate([SAMPLE[::8], HARD[::16]]).view(np.float32)
    for func, tier in itertools.product(FUNCS, ("faithful", "correct")):
        want = routines.jit(func, tier)(x).view(np.uint32)
        for width in (1, 4, 8):
            assert (routines.jit(func, tier, width=width)(x).view(np.uint32) == want).all(), (func, tier, width)


def _value_kernel(func, precision, fma):
    @reactor.kernel(fma=fma, name=f"accurate_trig_value_{func}_{precision.value}_{'fma' if fma else 'nofma'}")
    def value(x: reactor.Float) -> reactor.Double:
        return accurate_trig.value(x, precision, func)
    return value


def _error_points() -> np.ndarray:
    rng = np.random.default_rng(7)
    finite = rng.integers(0, 0x7F800000, 1200, dtype=np.int64).astype(np.uint32)   # every binade
    worst = (WORST.view(np.int32)[:, None] + np.arange(-3, 4)).ravel().view(np.uint32)
    near = _near_multiples_of_pio2(300, 1)
    x = np.concatenate([finite, worst, near, _region(2.0 ** 17, 2.0 ** 18, 300), _region(1e30, 3.4e38, 300),
                        _region(1e-40, 1e-3, 200)]).view(np.float32)
    x = x[x != 0]
    signs = np.where(rng.integers(0, 2, x.size) == 1, -1, 1).astype(np.float32)
    return x * signs


ERROR_POINTS = _error_points()
#: the float64 value's relative error bound: 2^-49 (routines.correct.ERROR) for the correct
#: tier; the faithful tier's polynomials level at 2^-35.0 (sin, cos) and 2^-29.2 (tan)
BOUND = {Precision.CORRECT: ERROR, Precision.FAITHFUL: 2.0 ** -29}


@pytest.mark.parametrize("precision,fma", [(Precision.CORRECT, True), (Precision.CORRECT, False),
                                           (Precision.FAITHFUL, True)], ids=["correct-fma", "correct-nofma",
                                                                             "faithful"])
@pytest.mark.parametrize("func", FUNCS)
def test_the_float64_value_meets_its_error_bound(func, precision, fma):
    """max |y / f(x) - 1| of the float64 value before the rounding, with mpmath at 400 bits
    (the reduction's worst cases and Payne-Hanek's huge arguments included)."""
    y = _value_kernel(func, precision, fma)(ERROR_POINTS)
    f = {"sin": mpmath.sin, "cos": mpmath.cos, "tan": mpmath.tan}[func]
    worst, at = 0.0, None
    with mpmath.workprec(400):
        for xi, yi in zip(ERROR_POINTS.tolist(), y.tolist()):
            exact = f(mpmath.mpf(xi))
            e = float(abs((mpmath.mpf(yi) - exact) / exact))
            if e > worst:
                worst, at = e, xi
    assert worst < BOUND[precision], (worst, at)


@pytest.mark.parametrize("poly", accurate_trig.DOUBLE, ids=lambda p: p.name)
def test_double_polynomials_meet_their_stated_error(poly):
    """Each fitted binary64 polynomial's weighted error, measured with mpmath on a dense grid, is
    within its stated levelled error (after rounding its coefficients to binary64); the Pade
    denominators state none."""
    if "levelled error " not in poly.provenance:
        assert poly.name.startswith("tan.den")
        return
    stated = float(poly.provenance.split("levelled error ")[1].split(" ")[0])
    lo, hi = (float(v) for v in poly.interval)
    den = accurate_trig.TAN_DEN_CORRECT if poly is accurate_trig.TAN_NUM_CORRECT else accurate_trig.TAN_DEN_FAITHFUL
    worst = mpmath.mpf(0)
    with mpmath.workdps(40):
        for v in np.linspace(lo, hi, 801)[1:]:
            z = mpmath.mpf(float(v))
            s = mpmath.sqrt(z)
            p = _horner(poly.values, z)
            if poly.name.startswith("sin"):
                approx, exact = s + s ** 3 * p, mpmath.sin(s)
            else:
                d = _horner(den.values, z)
                approx, exact = s * p / d, mpmath.tan(s)
            worst = max(worst, abs(approx / exact - 1))
    assert float(worst) <= stated * 1.01 + 2 ** -52, (float(worst), stated)


def _horner(coefficients, z):
    """sum c_i z^i in mpmath, coefficients highest degree first."""
    acc = mpmath.mpf(0)
    for c in coefficients:
        acc = acc * z + mpmath.mpf(c)
    return acc
