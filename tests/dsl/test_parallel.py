"""Kernels split large calls across threads: same bits as one thread, any layout."""
import numpy as np
import pytest

import routines
from reactor import Float, MulAdd, kernel
from reactor.kernels import parallel


@pytest.fixture
def two_threads_low_threshold():
    saved = parallel.settings()
    parallel.configure(threads=2, threshold=100)
    yield
    parallel.configure(threads=saved[0], threshold=saved[1])


@kernel
def fused(x: Float, y: Float) -> (Float, Float):
    return MulAdd(x, y, 1.0), x - y


def _serial(fn, *args, **kw):
    saved = parallel.settings()
    parallel.configure(threads=1)
    try:
        return fn(*args, **kw)
    finally:
        parallel.configure(threads=saved[0], threshold=saved[1])


@pytest.mark.parametrize("n", [100, 101, 1000, 4097, 100_003])
def test_parallel_matches_serial(two_threads_low_threshold, n):
    rng = np.random.default_rng(n)
    x, y = rng.normal(size=(2, n)).astype(np.float32)
    for args in [(x, y), (x[::-1], y), (x, np.float32(3.0)), (np.float32(2.0), y)]:
        got = fused(*args)
        want = _serial(fused, *args)
        for g, w in zip(got, want):
            assert np.array_equal(g, w)


def test_parallel_with_strides_out_and_where(two_threads_low_threshold):
    x = np.random.default_rng(1).uniform(-5, 5, 30_000).astype(np.float32)
    exp2 = routines.jit("exp2")
    out = np.full(x[::3].size, -1.0, np.float32)
    exp2(x[::3], out=out)
    assert np.array_equal(out, _serial(exp2, x[::3]))
    mask = x > 0
    dest = np.zeros_like(x)
    exp2(x, out=dest, where=mask)
    assert np.array_equal(dest[mask], _serial(exp2, x[mask])) and (dest[~mask] == 0).all()


def test_configure_validates_and_reports():
    saved = parallel.settings()
    try:
        assert parallel.configure(threads=1)[1] >= 2 ** 62  # one thread: never split
        with pytest.raises(ValueError):
            parallel.configure(threads=0)
    finally:
        parallel.configure(threads=saved[0], threshold=saved[1])
