"""A large kernel body is compiled once: its vector body also serves the tail, strided operands and
accumulations, through W-lane buffers (reactor_move). Small bodies take a width-1 copy instead; here
``ONE_BODY_MIN`` is lowered so every kernel takes the one-body path, and each result is compared bit
for bit with the two-body build of the same body."""
import numpy as np
import pytest

import reactor
from reactor import Bool, Float, Int, MulAdd, Select, kernel, vec3
from reactor.kernels import kernel as kernel_module
from fuzz.generate import op_sweep
from fuzz.runner import check


@pytest.fixture
def one_body(monkeypatch):
    monkeypatch.setattr(kernel_module, "ONE_BODY_MIN", 0)


def _both(body, **options):
    """(one-body ufunc, two-body ufunc) of ``body``."""
    saved = kernel_module.ONE_BODY_MIN
    try:
        kernel_module.ONE_BODY_MIN = 0
        one = kernel(body, name=f"{body.__name__}_one", cache=False, **options)
        kernel_module.ONE_BODY_MIN = 10 ** 9
        two = kernel(body, name=f"{body.__name__}_two", cache=False, **options)
    finally:
        kernel_module.ONE_BODY_MIN = saved
    assert reactor.kernel_of(one).code.ir_text.count("define internal") == 1
    assert reactor.kernel_of(two).code.ir_text.count("define internal") == 2
    return one, two


def _same(a, b):
    a, b = (x if isinstance(x, tuple) else (x,) for x in (a, b))
    for x, y in zip(a, b):
        assert x.dtype == y.dtype and x.shape == y.shape
        assert np.array_equal(np.ascontiguousarray(x).view(np.uint8), np.ascontiguousarray(y).view(np.uint8))


@pytest.mark.parametrize("width", [4, 8, 16])
def test_every_layout_gives_the_two_body_bits(width):
    def shade(x: Float, k: Int, b: Bool) -> (Float, Bool):
        y = Select(b, MulAdd(x, Float(k), 0.5), x * x - 1.0)
        return y, y > 0.0

    one, two = _both(shade, width=width)
    rng = np.random.default_rng(width)
    n = 203
    x = rng.standard_normal(n).astype(np.float32)
    k = rng.integers(-5, 5, n).astype(np.int32)
    b = rng.random(n) < 0.5
    for sel in (slice(None), slice(0, 1), slice(0, width - 1), slice(0, width + 1), slice(None, None, 3),
                slice(None, None, -1), slice(5, 150, 7)):
        _same(one(x[sel], k[sel], b[sel]), two(x[sel], k[sel], b[sel]))
    _same(one(x, np.int32(3), b), two(x, np.int32(3), b))          # broadcast inputs
    _same(one(np.float32(0.25), k, b[0]), two(np.float32(0.25), k, b[0]))
    outs = (np.zeros(2 * n, np.float32)[::2], np.zeros(3 * n, bool)[::3])  # strided outputs
    one(x, k, b, out=outs)
    _same(outs, two(x, k, b))


@pytest.mark.parametrize("width", [4, 16])
def test_accumulate_reduce_at_outer_and_in_place(width):
    def plus(a: Float, b: Float) -> Float:
        return a + b

    one, two = _both(plus, width=width)
    rng = np.random.default_rng(1)
    for n in (1, 2, 5, 17, 64):
        x = rng.integers(-9, 9, n).astype(np.float32)
        m = x.reshape(1, n).repeat(3, axis=0) * np.arange(1, 4, dtype=np.float32)[:, None]
        assert one.reduce(x) == x.sum()
        _same(one.accumulate(x), np.cumsum(x, dtype=np.float32))
        for axis in (0, 1):
            _same(one.accumulate(m, axis=axis), two.accumulate(m, axis=axis))
            _same(one.reduce(m, axis=axis), m.sum(axis=axis))
    a = np.zeros(5, np.float32)
    one.at(a, [0, 1, 1, 4], np.float32(1))
    assert a.tolist() == [1, 2, 0, 0, 1]
    y = np.arange(40, dtype=np.float32)
    want = y[:-1] + y[1:]
    one(y[:-1], y[1:], out=y[1:])
    _same(y[1:], want)
    z = np.arange(40, dtype=np.float32)
    one(z, z, out=z)  # in place
    _same(z, 2 * np.arange(40, dtype=np.float32))


def test_vector_operands_with_strided_channels():
    def scale(v: vec3, s: Float) -> vec3:
        return v * s + vec3(1.0, 2.0, 3.0)

    one, two = _both(scale, width=8)
    v = np.random.default_rng(2).standard_normal((50, 3)).astype(np.float32)
    s = np.linspace(-1, 1, 50, dtype=np.float32)
    for vv, ss in ((v, s), (v[::2], s[::2]), (np.asfortranarray(v), s), (v[:7], s[:7])):
        _same(one(vv, ss), two(vv, ss))


def test_the_operation_sweep_through_one_body(one_body):
    """Every DSL operation on every kind as a kernel, compared with NumPy (the fuzzer's sweep)."""
    for k, program in enumerate(op_sweep("kernel", fma=True)):
        res = check(program, seed=[9, k], widths=(4, 16), targets=False)
        assert res.status == "ok", res.summary()


def test_a_large_body_is_traced_once():
    seen = []

    @kernel(width=8)
    def big(x: Float) -> Float:
        seen.append(x.width)
        for _ in range(120):
            x = x * 1.0001 + 0.5
        return x

    assert seen == [8]
    x = np.linspace(0, 1, 19, dtype=np.float32)
    assert np.array_equal(big(x[::2]), big(x)[::2])
