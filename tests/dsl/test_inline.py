"""@inline helpers (GLSL functions with early returns), and what shader ports tripped on: vector
Variables' in-place operators, module-level constant vectors, whole-number pow, error hints."""
import math

import numpy as np
import pytest

import reactor
from reactor import (
    ControlFlowError, DSLTypeError, Float, For, If, Int, Return, Select, Variable, inline, kernel, mat2, vec2,
    vec3,
)


@inline
def march_shadow(x, limit):
    t = Variable(Float, 0.0)
    with For(0, 32):
        with If(t > limit):
            Return(0.5)  # leaves the helper (and its loop) for these lanes only
        t += x
    return 1.0 + t * 0.0


@pytest.mark.parametrize("width", [16, 8, 4, 1])
def test_return_in_an_inline_helper_returns_from_the_helper(width):
    @kernel(width=width)
    def lit(x: Float) -> Float:
        return march_shadow(x, 3.0) + 10.0

    x = np.float32([0.01, 0.2, 1.0, 0.0, 5.0] * 5)
    want = np.where(np.minimum(x * 31, 1e9) > 3.0, 10.5, 11.0).astype(np.float32)
    np.testing.assert_array_equal(lit(x), want)


def test_inline_helpers_return_vectors_and_tuples_in_a_loop():
    @inline
    def sign_of(v):
        with If(v.x < 0.0):
            Return((vec2(-1.0), 1))
        return (v, 0)

    @kernel
    def count(x: Float) -> (Float, Int):
        total, negative = Variable(Float, 0.0), Variable(Int, 0)
        with For(0, 3) as i:
            a, n = sign_of(vec2(x - Float(i), 1.0))  # the helper's returned lanes reset every call
            total += a.x
            negative += n
        return total, negative

    x = np.float32([0.5, 1.5, 5.0, -3.0])
    total, negative = count(x)
    want = [sum(-1.0 if v - i < 0 else v - i for i in range(3)) for v in x]
    np.testing.assert_array_equal(total, np.float32(want))
    np.testing.assert_array_equal(negative, [sum(v - i < 0 for i in range(3)) for v in x])


def test_inline_helper_in_a_function_with_uniform_returns():
    @inline
    def clamp01(v):
        with If(v < 0.0):
            Return(Float(0.0))
        with If(v > 1.0):
            Return(Float(1.0))
        return v

    @reactor.function
    def f(v: Float) -> Float:
        return clamp01(v) * 2.0

    assert [f(v) for v in (-1.0, 0.25, 7.0)] == [0.0, 0.5, 2.0]


def test_return_in_a_plain_helper_names_the_fix():
    def plain(x):
        with If(x > 0.0):
            Return(0.5)
        return x

    def body(x: Float) -> Float:
        return plain(x) + 1.0

    with pytest.raises(ControlFlowError, match=r"Return inside 'plain'.*@reactor.inline") as e:
        kernel(body)
    assert "test_inline.py" in str(e.value)


def test_in_place_operators_on_vector_variables_store():
    @kernel
    def acc(x: Float) -> Float:
        c = Variable(vec3, 0.0)
        with For(0, 3):
            with If(x > 0.0):
                c += vec3(x, 1.0, 2.0)  # stores (was: rebinds c to a plain value)
            c *= 2.0
        return c.x + c.y

    np.testing.assert_array_equal(acc(np.float32([1, -1, 2])), [28, 0, 42])


K = vec3(0.1, 0.2, 0.3)  # GLSL's const vec3 at module level
M = mat2(vec2(1.0, 2.0), vec2(3.0, 4.0))


def test_module_level_constant_vectors_and_matrices():
    assert repr(K) == "vec3(0.1, 0.2, 0.3)"

    @kernel
    def use(x: Float) -> Float:
        v = K * x + vec3(1.0)
        return v.z + K.x + (M @ vec2(x, 1.0)).y

    np.testing.assert_allclose(use(np.float32([1, 2])), [7.4, 9.7], rtol=1e-6)
    with pytest.raises(DSLTypeError, match="only numbers"):
        vec3("a", 1.0, 2.0)


def test_hints_for_python_operators_and_functions_on_dsl_values():
    with pytest.raises(DSLTypeError, match=r"bind tighter than comparisons"):
        kernel(lambda x, y: Select(x == 1.0 & y < 1.0, x, y), args=[Float, Float], returns=Float)
    with pytest.raises(DSLTypeError, match="routines.glsl"):
        kernel(lambda x: math.cos(x), args=[Float], returns=Float)
    with pytest.raises(DSLTypeError, match="routines.glsl's max"):
        kernel(lambda x: max(0.0, x), args=[Float], returns=Float)


def test_pow_of_a_small_whole_constant_is_multiplication_with_pow_specials():
    import routines

    @kernel
    def p5(x: Float) -> (Float, Float):
        return routines.pow(x, 5.0), routines.pow(x, -2)

    x = np.float32([0, -0.0, 1, 2, -2, np.inf, -np.inf, np.nan, 0.5, 3e-20])
    a, b = p5(x)
    with np.errstate(all="ignore"):
        ax = np.abs(x).astype(np.float64)
        np.testing.assert_array_equal(a, np.where(x < 0, np.nan, ax ** 5).astype(np.float32))
        np.testing.assert_array_equal(b, np.where(x < 0, np.nan, 1 / ax ** 2).astype(np.float32))
    assert "log2" not in reactor.kernel_of(p5).ir and "pow" in reactor.kernel_of(p5).ir
