"""The correct tier's tables of hard cases (routines/correct.py, routines/hard_cases/*.npy):
every listed result is the correctly rounded one (mpmath, 60 digits), every listed input lies
near a rounding boundary, and on stretches of inputs the tables miss no input the criterion
names (``python -m routines hardcases`` regenerates them from an exhaustive sweep)."""
import mpmath
import numpy as np
import pytest

from routines.cli.hardcases import FUNCS
from routines.correct import NEAR, table
from routines.lab import rounding

EXACT = {"sin": mpmath.sin, "cos": mpmath.cos, "tan": mpmath.tan, "asin": mpmath.asin, "acos": mpmath.acos,
         "atan": mpmath.atan, "sinh": mpmath.sinh, "cosh": mpmath.cosh, "tanh": mpmath.tanh}


@pytest.mark.parametrize("func", FUNCS)
def test_every_listed_result_is_correctly_rounded_and_near_a_boundary(func):
    keys, values = table(func)
    assert 50 <= keys.size <= 4000 and (np.diff(keys) > 0).all()
    rng = np.random.default_rng(3)
    for i in rng.choice(keys.size, size=min(60, keys.size), replace=False):
        x = float(keys[i:i + 1].view(np.float32)[0])
        got = float(values[i:i + 1].view(np.float32)[0])
        with mpmath.workdps(60):
            exact = EXACT[func](mpmath.mpf(x))
            # the float32 neighbours around the exact value: the nearest one is the result
            lo = np.float32(float(exact))
            cands = [np.nextafter(lo, np.float32(-np.inf)), lo, np.nextafter(lo, np.float32(np.inf))]
            best = min(cands, key=lambda c: (abs(mpmath.mpf(float(c)) - exact), int(np.float32(c).view(np.uint32)) % 2))
            assert got == float(best), (func, x, got, float(best))
            b = np.float32(best)
            other = np.nextafter(b, np.float32(-np.inf if exact < mpmath.mpf(float(b)) else np.inf))
            mid = (mpmath.mpf(float(b)) + mpmath.mpf(float(other))) / 2
            assert abs(exact - mid) <= 2 * NEAR * abs(exact), (func, x)


@pytest.mark.parametrize("func", ["sin", "atan", "tanh"])
def test_a_stretch_of_inputs_has_every_hard_case_listed(func):
    start = {"sin": 0x3F000000, "atan": 0x3E800000, "tanh": 0x3E000000}[func]
    bits = np.arange(start, start + 2 ** 21, dtype=np.uint64).astype(np.uint32)
    found = rounding.hard_cases(func, bits, NEAR)
    keys, values = table(func)
    at = np.searchsorted(keys, found[:, 0])
    assert (keys[at] == found[:, 0]).all() and (values[at] == found[:, 1]).all()
    listed = keys[(keys >= np.int32(start)) & (keys < np.int32(start + 2 ** 21))]
    assert listed.size == found.shape[0]


@pytest.mark.parametrize("fma", [True, False])
@pytest.mark.parametrize("func", FUNCS)
def test_the_correct_tier_gives_every_listed_result(func, fma):
    import routines
    keys, values = table(func)
    got = routines.jit(func, "correct", fma=fma)(keys.view(np.float32))
    assert (got.view(np.int32) == values).all(), keys[got.view(np.int32) != values][:5]
