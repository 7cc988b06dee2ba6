"""Kernels split large calls across threads: same bits as one thread, any layout."""
import numpy as np
import pytest

import reactor

import routines
from reactor import Float, MulAdd, kernel
from dsl_helpers import serial


@pytest.fixture
def two_threads_low_threshold():
    saved = reactor.thread_settings()
    reactor.configure_threads(threads=2, threshold=100, min_work=0)
    yield
    reactor.configure_threads(**saved._asdict())


@kernel
def fused(x: Float, y: Float) -> (Float, Float):
    return MulAdd(x, y, 1.0), x - y


@pytest.mark.parametrize("n", [100, 101, 1000, 4097, 100_003])
def test_parallel_matchesserial(two_threads_low_threshold, n):
    rng = np.random.default_rng(n)
    x, y = rng.normal(size=(2, n)).astype(np.float32)
    for args in [(x, y), (x[::-1], y), (x, np.float32(3.0)), (np.float32(2.0), y)]:
        got = fused(*args)
        want = serial(fused, *args)
        for g, w in zip(got, want):
            assert np.array_equal(g, w)


def test_parallel_with_strides_out_and_where(two_threads_low_threshold):
    x = np.random.default_rng(1).uniform(-5, 5, 30_000).astype(np.float32)
    exp2 = routines.jit("exp2")
    out = np.full(x[::3].size, -1.0, np.float32)
    exp2(x[::3], out=out)
    assert np.array_equal(out, serial(exp2, x[::3]))
    mask = x > 0
    dest = np.zeros_like(x)
    exp2(x, out=dest, where=mask)
    assert np.array_equal(dest[mask], serial(exp2, x[mask])) and (dest[~mask] == 0).all()


def test_configure_validates_and_reports():
    saved = reactor.thread_settings()
    try:
        assert reactor.configure_threads(threads=1, min_work=5).threads == 1
        assert reactor.thread_settings() == (1, saved.threshold, 5)
        for bad in (dict(threads=0), dict(threshold=0), dict(min_work=-1), dict(threads=1.5)):
            with pytest.raises(ValueError):
                reactor.configure_threads(**bad)
    finally:
        reactor.configure_threads(**saved._asdict())


def test_splitting_follows_the_estimated_work():
    cheap = kernel(lambda x: x + 1.0, args=[Float], returns=Float, name="cheap_copy")
    costly = kernel(lambda x: routines.pow(x, x) + routines.exp2(x), args=[Float], returns=Float, name="costly")
    from reactor import kernel_of
    assert kernel_of(costly).cycles_per_element > 3 * kernel_of(cheap).cycles_per_element
    min_work = reactor.thread_settings().min_work
    # a copy of 16,384 floats is not worth waking a worker; the same call of the costly kernel is,
    # and so is a copy of a million floats
    assert 16384 * kernel_of(cheap).cycles_per_element < min_work < 16384 * kernel_of(costly).cycles_per_element
    assert 2 ** 20 * kernel_of(cheap).cycles_per_element > min_work
