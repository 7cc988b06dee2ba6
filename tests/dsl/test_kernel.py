"""Kernels are NumPy ufuncs: every tail length, strides, broadcasting, out=, where=."""
import gc

import numpy as np
import pytest

import reactor
from reactor import (
    Bool, Double, Float, Int, IsNan, MulAdd, SIMD, Select, UInt, kernel, kernel_of,
)

from dsl_helpers import assert_bits_equal

LENGTHS = range(0, 34)  # every tail case for widths 4, 8 and 16, plus empty


def _body(a: Float, b: Float, c: Float) -> (Float, Float, Bool):
    """Three inputs, three outputs of two kinds."""
    return a * b + c, Select(a < b, a - c, b), IsNan(a) | (b > c)


def _want(a, b, c):
    with np.errstate(all="ignore"):
        return a * b + c, np.where(a < b, a - c, b), np.isnan(a) | (b > c)


@pytest.fixture(scope="module", params=[4, 8, 16])
def ufunc3(request):
    return kernel(_body, width=request.param, fma=False, name=f"k3w{request.param}")


def _check(ufunc, a, b, c, **kw):
    got = ufunc(a, b, c, **kw)
    for g, w in zip(got, _want(a, b, c)):
        assert_bits_equal(g, w)
    return got


def test_is_a_real_ufunc(ufunc3):
    assert isinstance(ufunc3, np.ufunc)
    assert (ufunc3.nin, ufunc3.nout, ufunc3.types[0]) == (3, 3, "fff->ff?")
    # the other loops only raise: float64 and 32/64-bit integers given to float32 arguments
    assert all(t.endswith("->FF?") and set(t[:3]) <= set("fild") for t in ufunc3.types[1:])
    assert "Three inputs" in ufunc3.__doc__
    kern = kernel_of(ufunc3)
    assert kern.build.width in (4, 8, 16) and kern.build.fma is False


def test_every_length_contiguous_and_strided(ufunc3, rng):
    for n in LENGTHS:
        a, b, c = (rng.standard_normal(2 * n + 3).astype(np.float32) for _ in range(3))
        a[::5] = np.nan
        _check(ufunc3, a[:n], b[:n], c[:n])                       # contiguous: vector loop + tail
        _check(ufunc3, a[: 2 * n : 2], b[1 : 2 * n + 1 : 2], c[:n])  # strided path
        _check(ufunc3, a[n - 1 :: -1] if n else a[:0], b[:n], c[:n])  # negative stride
        for k in range(3):                                          # one broadcast scalar input
            args = [a[:n], b[:n], c[:n]]
            args[k] = np.float32(args[k][0] if n else 1.5)
            _check(ufunc3, *args)


def test_every_length_strided_outputs(ufunc3, rng):
    for n in LENGTHS:
        a, b, c = (rng.standard_normal(n).astype(np.float32) for _ in range(3))
        outs = (np.full(2 * n, -7, np.float32), np.full(3 * n, -7, np.float32), np.zeros(n, bool))
        views = (outs[0][::2], outs[1][::-3], outs[2])
        got = ufunc3(a, b, c, out=views)
        assert all(g is v for g, v in zip(got, views))
        for g, w in zip(views, _want(a, b, c)):
            assert_bits_equal(g, w)
        assert np.all(outs[0][1::2] == -7)  # untouched between the strided elements


def test_broadcasting_shapes_and_0d(ufunc3, rng):
    a = rng.standard_normal((3, 1, 5)).astype(np.float32)
    b = rng.standard_normal((4, 1)).astype(np.float32)
    c = np.float32(0.25)
    got = _check(ufunc3, a, b, c)
    assert got[0].shape == (3, 4, 5)
    got = _check(ufunc3, np.float32(2), np.float32(3), np.float32(4))     # all 0-d: scalars back
    assert isinstance(got[0], np.float32) and got[0] == 10
    got = _check(ufunc3, np.array(2, np.float32), np.array(3, np.float32), np.array(1, np.float32))
    assert np.ndim(got[0]) == 0
    t = rng.standard_normal((6, 9)).astype(np.float32)
    _check(ufunc3, t.T, t.T, t.T[::-1])  # Fortran-ordered / transposed views
    _check(ufunc3, t[:, ::3], t[:, 1::3], t[:, 2::3])


def test_out_and_where(ufunc3, rng):
    n = 37
    a, b, c = (rng.standard_normal(n).astype(np.float32) for _ in range(3))
    o1, o2, o3 = np.full(n, 9, np.float32), np.full(n, 9, np.float32), np.zeros(n, bool)
    mask = rng.random(n) < 0.5
    ufunc3(a, b, c, out=(o1, o2, o3), where=mask)
    want = _want(a, b, c)
    assert_bits_equal(o1, np.where(mask, want[0], np.float32(9)))
    assert_bits_equal(o2, np.where(mask, want[1], np.float32(9)))
    assert_bits_equal(o3, np.where(mask, want[2], False))
    # in place: out aliases an input
    x = a.copy()
    ufunc3(x, b, c, out=(x, None, None))
    assert_bits_equal(x, want[0])


def test_casting_comes_from_numpy():
    @kernel
    def half(x: Float) -> Float:
        return x * 0.5

    assert_bits_equal(half(np.arange(5, dtype=np.int16)), np.arange(5, dtype=np.float32) / 2)
    assert_bits_equal(half(np.arange(3, dtype=np.float32), out=None), np.arange(3, dtype=np.float32) / 2)
    with pytest.raises(TypeError):
        half(np.arange(3.0))  # float64 -> float32 is not a safe cast
    got = half(np.arange(3.0), dtype=np.float32, casting="unsafe")
    assert_bits_equal(got, np.array([0, 0.5, 1], np.float32))
    out = np.zeros(3)
    half(np.ones(3, np.float32), out=out)  # float32 -> float64 output cast
    assert out.tolist() == [0.5, 0.5, 0.5]


@pytest.mark.parametrize("width", [1, 4, 8, 16])
def test_integer_bool_and_double_kernels(width, rng):
    @kernel(width=width, name=f"ints{width}")
    def ints(i: Int, u: UInt, b: Bool) -> (Int, UInt, Bool):
        return Select(b, i >> 1, -i), u >> 1, b ^ (i < 0)

    @kernel(width=width, name=f"dbl{width}")
    def dbl(x: Double) -> Double:
        return x * 3.0 + 1.0

    for n in (0, 1, width - 1, 3 * width + 1, 33):
        i = rng.integers(-1000, 1000, n).astype(np.int32)
        u = rng.integers(0, 2**32, n).astype(np.uint32)
        b = rng.random(n) < 0.5
        gi, gu, gb = ints(i, u, b)
        assert_bits_equal(gi, np.where(b, i >> 1, -i))
        assert_bits_equal(gu, u >> 1)
        assert_bits_equal(gb, b ^ (i < 0))
        gi, gu, gb = ints(i[::-1], u[::-1], b[::-1])
        assert_bits_equal(gb, b[::-1] ^ (i[::-1] < 0))
        x = rng.standard_normal(n)
        assert_bits_equal(dbl(x), x * 3.0 + 1.0)


def test_width_generic_body_is_traced_once_per_width():
    seen = []

    @kernel(width=8)
    def probe(x: Float) -> Float:
        seen.append(x.width)
        assert SIMD.width == x.width
        return x + SIMD.Float(1.0) + float(SIMD.width) * 0.0

    assert sorted(seen) == [1, 8]  # the vector loop at width 8; the tail and strided elements at 1
    x = np.arange(40, dtype=np.float32)
    assert_bits_equal(probe(x[:20]), x[:20] + 1)
    assert_bits_equal(probe(x[::2]), x[::2] + 1)


def test_kernel_memo_and_lifetime():
    def body(x: Float) -> Float:
        return x * 4.0

    u = kernel(body)
    assert kernel(body) is u                       # memo hit: nothing rebuilt
    assert kernel(body, fma=False) is not u        # other options: another kernel
    kern = kernel_of(u)
    del u
    gc.collect()
    u2 = kernel(body)  # the old ufunc is gone though its Kernel lives on: build a new one
    assert isinstance(u2, np.ufunc) and u2.__name__ == "body"
    assert_bits_equal(u2(np.ones(3, np.float32)), np.full(3, 4, np.float32))
    assert kernel_of(u2) is not kern
    with pytest.raises(reactor.ReactorError, match="not a reactor kernel"):
        kernel_of(np.add)


@pytest.mark.parametrize("width", [4, 16])
def test_ufunc_methods(width, rng):
    """reduce/accumulate hand the loop overlapping operands (out[i-1] is input i)."""
    @kernel(width=width, name=f"plus{width}")
    def plus(a: Float, b: Float) -> Float:
        return a + b

    for n in (1, 2, 5, 17, 64):
        x = rng.integers(-9, 9, n).astype(np.float32)
        assert plus.reduce(x) == x.sum()
        assert_bits_equal(plus.accumulate(x), np.cumsum(x, dtype=np.float32))
        m = x.reshape(1, n).repeat(3, axis=0) * np.arange(1, 4, dtype=np.float32)[:, None]
        assert_bits_equal(plus.accumulate(m, axis=1), np.cumsum(m, axis=1, dtype=np.float32))
        assert_bits_equal(plus.accumulate(m, axis=0), np.cumsum(m, axis=0, dtype=np.float32))
        assert_bits_equal(plus.reduce(m, axis=0), m.sum(axis=0))
    a = np.zeros(5, np.float32)
    plus.at(a, [0, 1, 1, 4], np.float32(1))
    assert a.tolist() == [1, 2, 0, 0, 1]
    assert_bits_equal(plus.outer(np.arange(3, dtype=np.float32), np.arange(4, dtype=np.float32)),
                      np.add.outer(np.arange(3, dtype=np.float32), np.arange(4, dtype=np.float32)))
    # overlapping operands in a plain call: NumPy copies, results as if no overlap
    y = np.arange(40, dtype=np.float32)
    want = y[:-1] + y[1:]
    plus(y[:-1], y[1:], out=y[1:])
    assert_bits_equal(y[1:], want)


@pytest.mark.parametrize("width", [4, 16])
def test_mixed_kinds_with_each_input_broadcast(width):
    @kernel(width=width, name=f"mixed{width}")
    def mixed(x: Float, k: Int, b: Bool) -> Float:
        return Select(b, x * SIMD.Float(k), x)

    for n in (1, 7, 17, 40):
        x = np.arange(n, dtype=np.float32)
        k = np.arange(n, dtype=np.int32) - 3
        b = np.arange(n) % 3 == 0
        xk = x * k.astype(np.float32)
        assert_bits_equal(mixed(x, k, b), np.where(b, xk, x))
        assert_bits_equal(mixed(np.float32(2), k, b), np.where(b, 2 * k, 2).astype(np.float32))
        assert_bits_equal(mixed(x, np.int32(5), b), np.where(b, x * 5, x))
        assert_bits_equal(mixed(x, k, np.True_), xk)
        assert_bits_equal(mixed(x, k, np.False_), x)


def test_single_input_broadcast_and_large_arrays(rng):
    @kernel
    def sq(x: Float) -> Float:
        return MulAdd(x, x, -1.0)

    x = rng.standard_normal(100_003).astype(np.float32)
    want = (x.astype(np.float64) ** 2 - 1).astype(np.float32)  # exact product, then one rounding
    np.testing.assert_allclose(sq(x), want, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(sq(np.broadcast_to(np.float32(3), (17,))), np.full(17, 8, np.float32))


def test_a_vectors_components_returned_apart_say_how_to_return_the_vector():
    from reactor import DSLTypeError, vec3

    def body(x: Float) -> vec3:
        return x, x * 2.0, x * 3.0
    with pytest.raises(DSLTypeError, match=r"returned 3 value\(s\).* write 'return vec3\(\.\.\.\)' with its 3 components"):
        kernel(body, cache=False)
