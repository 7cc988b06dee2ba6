"""GLSL vectors and matrices: constructors, swizzles, operators, ``@``, Select, Variables."""
import numpy as np
import pytest

import reactor
from reactor import (
    DSLTypeError, Else, Float, For, If, Int, ScopeError, Select, Variable, bvec3, function, ivec2, kernel,
    mat2, mat3, vec2, vec3, vec4,
)


def _xyz(n=37, seed=3):
    r = np.random.default_rng(seed)
    return [r.uniform(-2, 2, n).astype(np.float32) for _ in range(3)]


def test_constructors_swizzles_and_operators_in_a_kernel():
    @kernel
    def f(x: Float, y: Float, z: Float) -> (Float, Float, Float, Float):
        v = vec3(x, y, z)
        w = vec4(v.zyx * 0.5 + 0.5, 1.0)  # GLSL constructor from a swizzle and a scalar
        u = 2.0 * w.xy - w.ba + vec2(x)  # numbers on either side, a scalar filling a vec2
        c = w.rgb.bgr  # rgba and stpq name the same components
        return u.s, u.t, c.p + w.a, (v % 1.0).x  # % is GLSL's mod

    x, y, z = _xyz()
    h = lambda a: (a * np.float32(0.5) + np.float32(0.5)).astype(np.float32)  # noqa: E731
    w = [h(z), h(y), h(x), np.ones_like(x)]
    u = [2 * w[0] - w[2] + x, 2 * w[1] - w[3] + x]
    got = f(x, y, z)
    np.testing.assert_array_equal(got[0], u[0].astype(np.float32))
    np.testing.assert_array_equal(got[1], u[1].astype(np.float32))
    np.testing.assert_array_equal(got[2], (w[0] + 1).astype(np.float32))
    np.testing.assert_array_equal(got[3], (x - np.floor(x)).astype(np.float32))


def test_dsl_scalars_defer_to_vectors_in_either_order():
    @kernel
    def f(x: Float) -> (Float, Float, Float):
        v = vec3(1.0, 2.0, 3.0)
        a = x * v  # Float * vec3: the scalar defers to the vector
        b = v / x
        c = x - v
        return a.z, b.y, c.x

    x = np.array([1, 2, 4, -0.5], np.float32)
    a, b, c = f(x)
    np.testing.assert_array_equal(a, 3 * x)
    np.testing.assert_array_equal(b, (2 / x).astype(np.float32))
    np.testing.assert_array_equal(c, x - 1)


def test_comparisons_give_bvecs_and_select_mixes_per_component():
    @kernel
    def f(x: Float, y: Float) -> (Float, Float, Int):
        a, b = vec2(x, y), vec2(y, x)
        m = a < b  # bvec2, per component (GLSL's lessThan)
        lo = Select(m, a, b)  # per component
        flat = Select(x > 0.0, a, b)  # one Bool for the whole vector
        return lo.x, flat.y, Select(m.x | m.y, 1, 0)

    x, y, _ = _xyz()
    lo, flat, anyv = f(x, y)
    np.testing.assert_array_equal(lo, np.minimum(x, y))
    np.testing.assert_array_equal(flat, np.where(x > 0, y, x))
    np.testing.assert_array_equal(anyv, (x != y).astype(np.int32))


def test_matrices_are_column_major_and_multiply_with_at():
    @kernel
    def f(x: Float, y: Float, z: Float) -> (Float, Float, Float, Float):
        m = mat3(vec3(1.0, 2.0, 3.0), vec3(4.0, 5.0, 6.0), vec3(7.0, 8.0, 10.0))  # columns
        v = vec3(x, y, z)
        mv = m @ v
        vm = v @ m  # row vector times matrix
        mm = (m @ m.transpose()) @ v
        return mv.x, vm.y, mm.z, (mat2(2.0) @ vec2(x, y)).y

    x, y, z = _xyz()
    M = np.array([[1, 4, 7], [2, 5, 8], [3, 6, 10]], np.float64)  # rows: what m[col][row] lays out
    V = np.stack([x, y, z]).astype(np.float64)
    mv, vm, mm, d = f(x, y, z)
    np.testing.assert_allclose(mv, (M @ V)[0], rtol=1e-6, atol=1e-5)
    np.testing.assert_allclose(vm, (V.T @ M)[:, 1], rtol=1e-6, atol=1e-5)
    np.testing.assert_allclose(mm, (M @ M.T @ V)[2], rtol=1e-5, atol=1e-5)
    np.testing.assert_array_equal(d, 2 * y)


def test_star_between_matrix_and_vector_names_at():
    def f(x: Float) -> Float:
        return (mat3(1.0) * vec3(x)).x

    with pytest.raises(DSLTypeError, match="written with '@'"):
        kernel(f)


def test_vector_variables_per_lane_under_conditions_and_loops():
    @kernel
    def f(x: Float) -> (Float, Float):
        c = Variable(vec3, 0.0)
        with For(0, 4) as i:
            with If(x > Float(i)):
                c.xy = c.xy + vec2(1.0, 2.0)  # swizzle assignment, active lanes only
            with Else():
                c.z = c.z - 1.0
        return c.x + c.y, c.z

    x = np.array([-1, 0.5, 1.5, 2.5, 3.5, 10] * 3, np.float32)
    k = np.clip(np.ceil(x), 0, 4).astype(np.float32)  # iterations with x > i
    a, b = f(x)
    np.testing.assert_array_equal(a, 3 * k)
    np.testing.assert_array_equal(b, -(4 - k))


def test_vectors_in_functions():
    @function
    def f(x: Float, y: Float) -> Float:
        v = vec2(x, y)
        acc = Variable(v)
        with For(0, 3):
            acc.set(acc.yx * 2.0)
        return acc.x - acc.y

    assert f(1.0, 3.0) == 8.0 * 3.0 - 8.0 * 1.0


def test_integer_and_bool_vectors():
    @kernel
    def f(i: Int) -> (Int, Int):
        v = ivec2(i, i * 2)
        w = (v << 1) + ivec2(1, 2)
        b = bvec3(True, i > 3, False)
        return w.y, Select(b.y, 1, 0) + Select(b.x, 10, 0)

    i = np.arange(-3, 20, dtype=np.int32)
    w, b = f(i)
    np.testing.assert_array_equal(w, (i * 2 << 1) + 2)
    np.testing.assert_array_equal(b, (i > 3) + 10)


@pytest.mark.parametrize("build, message", [
    (lambda x: vec3(x, x), "takes 3 components, got 2"),
    (lambda x: vec3(x).w, "no component or swizzle 'w'"),
    (lambda x: vec4(vec2(x)), "needs more components"),
    (lambda x: vec2(x) + vec3(x), "differ in size"),
])
def test_misuse_is_a_clear_error(build, message):
    def f(x: Float) -> Float:
        v = build(x)
        return v.x if hasattr(v, "x") else v

    with pytest.raises((DSLTypeError, AttributeError), match=message):
        kernel(f)


def test_assigning_a_swizzle_of_an_outside_value_inside_a_block_is_an_error():
    def f(x: Float) -> Float:
        v = vec2(x, x)
        with If(x > 0.0):
            v.x = 1.0
        return v.x

    with pytest.raises(DSLTypeError, match="'v.x = ...' under a run-time condition changes a vec2 for every lane"):
        kernel(f)


def test_power_operator():
    import routines  # noqa: F401 - installs pow for non-integer exponents

    @kernel
    def f(x: Float) -> (Float, Float, Float):
        v = vec2(x, 2.0)
        return x ** 3, x ** -2.0, (v ** 0.5).y

    x = np.array([0.5, 2, 3, -1.5], np.float32)
    a, b, c = f(x)
    np.testing.assert_array_equal(a, x * x * x)
    np.testing.assert_allclose(b, 1 / (x * x), rtol=1e-7)
    np.testing.assert_allclose(c, np.sqrt(np.float32(2)), rtol=1e-6)


def test_a_vector_variable_of_a_wide_value_and_numbers_has_one_width_in_a_function():
    import routines.glsl as gl
    F8 = reactor.vector_type("Float", 8)

    @reactor.function
    def swap(x: F8) -> F8:
        v = reactor.Variable(reactor.vec3, reactor.vec3(x, 2.0, 3.0))
        v.xz = v.zx
        return v.x + v.z + gl.atan2(x, 1.0) - gl.atan(x, 1.0)
    x = np.arange(8, dtype=np.float32)
    assert np.allclose(swap(x), 3.0 + x, rtol=0, atol=1e-6)  # x + 3 once swapped; atan2 is atan(y, x)
