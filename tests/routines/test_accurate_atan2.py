"""atan2's correct tier (routines/accurate_atan2.py): correctly rounded on its hard pairs and a
random sample, FMA on and off, and its double-double path, which the rounding test rarely
takes, correctly rounded on its own over every kind of pair."""
import numpy as np
import pytest

import reactor
import routines
from reactor import Float
from routines import accurate_atan2, doubled
from routines.accurate_inverse import operands
from routines.lab import rounding as ladder


def _random_pairs(n, seed):
    rng = np.random.default_rng(seed)
    bits = rng.integers(0, 2 ** 32, (2, n), dtype=np.uint64).astype(np.uint32)
    near = (np.exp(rng.uniform(-20, 20, (2, n))) * rng.choice([-1, 1], (2, n))).astype(np.float32).view(np.uint32)
    return np.concatenate([bits[0], near[0]]), np.concatenate([bits[1], near[1]])


@pytest.mark.parametrize("fma", [True, False])
def test_correct_atan2_on_hard_and_random_pairs(fma):
    u = routines.jit("atan2", "correct", fma=fma)
    for a, b in (ladder.atan2_hard_cases(), _random_pairs(1 << 17, 4)):
        r = ladder.score(u, "atan2", "correct", a, b)
        assert r.misrounded == 0, r.examples
        assert r.max_ulp <= 0.5 + 1e-9


@pytest.mark.parametrize("fma", [True, False])
def test_the_double_double_path_alone_rounds_correctly(fma):
    @reactor.kernel(name=f"atan2_pair_{'fma' if fma else 'nofma'}", fma=fma)
    def pair(y: Float, x: Float) -> Float:
        ay, ax = operands(y, x)
        return reactor.CopySign(doubled.round_pair(*accurate_atan2._angle(y, x, ay, ax)), y)

    a, b = _random_pairs(1 << 16, 5)
    finite = np.isfinite(a.view(np.float32)) & np.isfinite(b.view(np.float32))
    r = ladder.score(pair, "atan2", "pair", a[finite], b[finite])
    assert r.misrounded == 0, r.examples


def test_faithful_atan2_stays_below_one_ulp():
    r = ladder.score(routines.jit("atan2", "faithful"), "atan2", "faithful", *ladder.atan2_hard_cases())
    assert r.max_ulp < 0.52, (r.max_ulp, r.max_ulp_at)
