"""What every test of a faithful or correct tier checks, on given float32 bit patterns: correct
rounding (0 misrounded), the faithful bound, and the same bits at every x86 level (correct
results are unique; the faithful tiers use rounded float64 multiplies and adds, or exact fused
steps, so they are the same code everywhere), FMA on and off."""
import itertools

import numpy as np

import reactor
import routines
from routines.lab import rounding as ladder


def assert_correctly_rounded(func: str, fma: bool, bits: np.ndarray) -> None:
    r = ladder.score(routines.jit(func, "correct", fma=fma), func, "correct", bits)
    assert r.misrounded == 0, r.examples
    assert r.max_ulp <= 0.5 + 1e-9


def assert_faithful(func: str, fma: bool, bits: np.ndarray, bound: float) -> None:
    r = ladder.score(routines.jit(func, "faithful", fma=fma), func, "faithful", bits)
    assert r.max_ulp < bound, (r.max_ulp, r.max_ulp_at)


def assert_the_same_bits_at_every_x86_level(func: str, bits: np.ndarray) -> None:
    x = bits.view(np.float32)
    host = reactor.get_target("host").feature_set
    for tier, fma in itertools.product(("faithful", "correct"), (True, False)):
        want = routines.jit(func, tier, fma=fma)(x).view(np.uint32)
        for target in ("avx2", "sse4"):
            if target == "avx2" and "avx2" not in host:
                continue
            emulated = "emulate" if fma and target == "sse4" else fma
            got = routines.jit(func, tier, fma=emulated, target=target)(x).view(np.uint32)
            assert (got == want).all(), (func, tier, fma, target)
