"""Kernels with several signatures (numba's @vectorize([...])), and names that tell the truth."""
import numpy as np
import pytest

import reactor
import routines
from reactor import Float, Sqrt, kernel, kernel_of

from dsl_helpers import assert_bits_equal


@kernel(["float32(float32, float32)", "float64(float64, float64)", "int32(int32, int32)", "uint32(uint32, uint32)"])
def sumsq(x, y):
    """x^2 + y^2, for any kind."""
    return x * x + y * y


def test_one_ufunc_one_loop_per_signature(rng):
    assert sumsq.types == ["ff->f", "dd->d", "ii->i", "II->I"]
    for dtype in (np.float32, np.float64, np.int32, np.uint32):
        x = (rng.random(37) * 100).astype(dtype)
        y = (rng.random(37) * 100).astype(dtype)
        got = sumsq(x, y)
        assert got.dtype == dtype
        assert_bits_equal(got, (x * x + y * y).astype(dtype))
        assert_bits_equal(sumsq(x[::3], y[::3]), (x * x + y * y)[::3].astype(dtype))  # the scalar loop too
    assert kernel_of(sumsq, "dd->d").build.width == kernel_of(sumsq).build.width // 2  # same bytes per vector
    assert kernel_of(sumsq, (np.int32, np.int32)).types == "ii->i"
    assert "x^2 + y^2, for any kind." in sumsq.__doc__ and "dd->d: target=" in sumsq.__doc__


def test_several_results_and_reactor_kind_names():
    @kernel(["(Float, Bool)(Float)", "(float64, bool)(float64)"])
    def split(x):
        return Sqrt(x), x > 1.0

    for dtype in (np.float32, np.float64):
        x = np.linspace(0, 4, 9, dtype=dtype)
        r, m = split(x)
        assert r.dtype == dtype and m.dtype == bool
        assert_bits_equal(r, np.sqrt(x)) and np.array_equal(m, x > 1)


@pytest.mark.parametrize("bad, words", [
    (["complex64(complex64)"], "unknown type 'complex64'"),
    (["float32(float32, float32)"], "has 2 input(s), but the body takes 1"),
    (["float32 of float32"], "not of the form"),
    (["float32(float32)", "float32(float32)"], "different input types"),
])
def test_bad_signatures_are_clear_errors(bad, words):
    with pytest.raises(reactor.DSLTypeError, match=words.replace("(", r"\(").replace(")", r"\)")):
        kernel(bad)(lambda x: x)


def test_a_signature_the_body_does_not_fit_names_the_line():
    with pytest.raises(reactor.DSLTypeError) as info:
        @kernel(["float32(float32)", "float64(float64)"])
        def mixed(x):
            return x + Float(1.0)  # a Float constant: fine for float32, not for float64
    assert info.value.location[1] > 0 and "Double" in str(info.value)


def test_names_docs_and_reprs_state_the_resolved_settings():
    u = routines.jit("exp2", fma=None)
    host_fma = reactor.get_target("host").has_fma
    assert u.__name__ == f"exp2_full_{'fma' if host_fma else 'nofma'}"
    assert f"FMA {'on' if host_fma else 'off'}" in u.__doc__ and "float32 only" in u.__doc__
    assert f"fma={'on' if host_fma else 'off'}" in repr(kernel_of(u))
    with pytest.raises(TypeError):
        u(np.arange(3.0))  # float64 is refused under NumPy's default casting
    got = u(np.arange(3.0), dtype=np.float32, casting="same_kind")
    assert got.dtype == np.float32 and got.tolist() == [1.0, 2.0, 4.0]

    @kernel(fma=False, width=8)
    def k(x: Float) -> Float:
        return x * 2.0

    assert "target=host width=8 fma=off precision=full" in k.__doc__
