"""ScaleF, ReduceNearest, LRint, Exponent and Significand: the portable paths give the AVX-512
instructions' bits."""
import numpy as np
import pytest

import reactor
from reactor import Exponent, Float, Int, LRint, ReduceNearest, ScaleF, Significand, kernel

NATIVE = "avx512f" in reactor.get_target("host").feature_set and "avx512dq" in reactor.get_target("host").feature_set


def _kernels(target):
    sc = kernel(lambda a, b: ScaleF(a, b), args=[Float, Float], returns=Float, name=f"scalef_{target}",
                target=target)
    rn = kernel(lambda x: ReduceNearest(x), args=[Float], returns=Float, name=f"reduce_{target}", target=target)
    lr = kernel(lambda x: LRint(x), args=[Float], returns=Int, name=f"lrint_{target}", target=target)
    ex = kernel(lambda x: Exponent(x), args=[Float], returns=Float, name=f"getexp_{target}", target=target)
    sg = kernel(lambda x: Significand(x), args=[Float], returns=Float, name=f"getmant_{target}", target=target)
    return sc, rn, lr, ex, sg


def _inputs(rng, n):
    bits = rng.integers(0, 2 ** 32, n, dtype=np.uint64).astype(np.uint32)
    special = np.array([0, 0x80000000, 0x7F800000, 0xFF800000, 0x7FC00000, 0xFFC02904, 0x7F800001, 0xFF812345,
                        1, 0x80000001, 0x007FFFFF, 0x00800000, 0x7F7FFFFF, 0x3F800000, 0x3F000000, 0xBF000000,
                        0x3FC00000, 0x40200000, 0x4B000000, 0xCB000001], np.uint32)
    return np.concatenate([special, bits]).view(np.float32)


@pytest.mark.skipif(not NATIVE, reason="needs an AVX-512 host to run the native instructions")
@pytest.mark.parametrize("portable", ["avx2", "sse4"])
def test_portable_paths_match_avx512_bits(portable, rng):
    native = _kernels("avx512")
    other = _kernels(portable)
    x = _inputs(rng, 1 << 18)
    for k in (1, 2, 3, 4):  # ReduceNearest, LRint (in range: |x| < 2^31), Exponent, Significand
        xs = x if k == 1 else x[np.abs(x) < 2.0 ** 30]
        assert np.array_equal(native[k](xs).view(np.uint32), other[k](xs).view(np.uint32))
    bs = np.array([0, -0.0, 1, -1, 0.5, -0.5, 1.5, -1.5, 127, 128, 200, 300, 400, -126, -149, -150, -200,
                   -300, -400, np.inf, -np.inf, np.nan, -np.nan, 1e-40, -1e-40, 3e38, -3e38, 22.7, -22.7],
                  np.float32)
    a = x[: 1 << 14]
    for b in bs:
        got, want = other[0](a, b).view(np.uint32), native[0](a, b).view(np.uint32)
        bad = np.flatnonzero(got != want)
        assert bad.size == 0, (b, a[bad[:4]], got[bad[:4]], want[bad[:4]])
    y = rng.uniform(-400, 400, x.size).astype(np.float32)
    assert np.array_equal(native[0](x, y).view(np.uint32), other[0](x, y).view(np.uint32))


def test_scalef_is_correctly_rounded_into_the_subnormals():
    sc = _kernels("sse4" if not NATIVE else "host")[0]
    a = np.array([1.0, 1.5, 1.75, 3.0, -1.25, 1.0], np.float32)
    b = np.array([-149, -150, -149, -150, -148, 128], np.float32)
    got = sc(a, b)
    want = np.array([2.0 ** -149, 2.0 ** -149, 2.0 ** -148, 2.0 ** -148, -2.0 ** -148, np.inf], np.float32)
    assert np.array_equal(got.view(np.uint32), want.view(np.uint32))


def test_build_settings_and_precision_scopes():
    seen = []

    @kernel(fma=True, name="settings_probe", precision="relaxed")
    def probe(x: Float) -> Float:
        seen.append((reactor.build_settings().fma, reactor.build_settings().precision))
        with reactor.fma_mode(False), reactor.precision("full"):
            seen.append((reactor.build_settings().fma, reactor.build_settings().precision))
        seen.append((reactor.build_settings().fma, reactor.build_settings().precision))
        return x

    full, relaxed = reactor.Precision.FULL, reactor.Precision.RELAXED
    assert seen[:3] == [(True, relaxed), (False, full), (True, relaxed)]
    with reactor.precision("relaxed"):
        assert reactor.build_settings().precision is relaxed
    assert reactor.build_settings().precision is full
    with pytest.raises(reactor.ReactorError, match="precision must be one of"):
        reactor.precision("medium").__enter__()


def test_exponent_and_significand_nan_bits_are_one_rule_on_every_target():
    """A NaN operand gives itself quieted (sign and payload kept), a negative one x86's default
    NaN 0xffc00000: on the portable paths as on VGETEXPPS/VGETMANTPS, so that NaNs meeting in
    log2 have one value and no operand order can change a result's bits."""
    x = np.array([0x7F800001, 0xFF812345, 0x7FC00000, 0xFFC02904, 0xBF800000, 0xFF800000, 0x80000001],
                 np.uint32).view(np.float32)
    quiet = [0x7FC00001, 0xFFC12345, 0x7FC00000, 0xFFC02904]
    runnable = [t for t in ("host", "avx2", "sse4") if reactor.get_target(t).runnable]
    for target in runnable:
        _, _, _, ex, sg = _kernels(target)
        assert list(ex(x).view(np.uint32)[:4]) == quiet and ex(x)[4] == 0.0 and ex(x)[5] == np.inf
        assert list(sg(x).view(np.uint32)) == quiet + [0xFFC00000] * 3
