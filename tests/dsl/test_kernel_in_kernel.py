"""A kernel called in another kernel's body is inlined, as GLSL inlines a function call: its body
on the caller's values, at the precision it was built with and the caller's FMA setting."""
import numpy as np
import pytest

import reactor
import routines
from reactor import DSLTypeError, Float, kernel, vec3

X = np.linspace(-4, 4, 301, dtype=np.float32)


@kernel(cache=False)
def square(x: Float) -> Float:
    return x * x


@kernel(cache=False)
def length2(v: vec3) -> Float:
    return v.x * v.x + v.y * v.y + v.z * v.z


def test_a_kernel_in_a_body_is_its_body_inlined():
    @kernel(cache=False)
    def caller(x: Float) -> Float:
        return square(x) + square(x + 1.0)

    assert np.array_equal(caller(X), X * X + (X + 1) * (X + 1))


def test_vector_kernels_inline_too():
    @kernel(cache=False)
    def caller(x: Float) -> Float:
        return length2(vec3(x, 2.0 * x, 1.0))

    assert np.array_equal(caller(X), X * X + (2 * X) * (2 * X) + 1)


def test_the_called_kernels_precision_is_kept():
    relaxed = routines.jit("exp2", "relaxed")

    @kernel(cache=False)
    def caller(x: Float) -> Float:
        return relaxed(x)

    assert np.array_equal(caller(X), relaxed(X))
    assert [(c.name, c.precision) for c in reactor.kernel_of(caller).routines] == [("exp2", "relaxed")]


def test_the_callers_fma_setting_is_kept():
    fused = routines.jit("exp2", fma=True)
    with reactor.options(fma=False):
        @kernel(cache=False)
        def caller(x: Float) -> Float:
            return fused(x)
    assert [c.fma for c in reactor.kernel_of(caller).routines] == [False]
    assert np.array_equal(caller(X), routines.jit("exp2", fma=False)(X))


def test_numpys_options_on_a_kernel_call_in_a_body_are_refused():
    with pytest.raises(DSLTypeError, match="kernel square called in a kernel body with NumPy's options"):
        kernel(lambda x: square(x, dtype=np.float32), args=[Float], returns=Float, cache=False)
