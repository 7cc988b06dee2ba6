"""The same routine on the same operands is emitted once where its first result is visible
(``cos(x) + cos(x)`` computes one cosine), never across a block that ended, never across
settings, and every call site stays listed for a plan."""
import numpy as np

import reactor
import routines  # noqa: F401 - the routines
from reactor import Float, If, Variable, kernel, mat2, vec2
from reactor.cost.model import kernel_cycles
from reactor.kernels.kernel import kernel_of
from routines import glsl as gl

X = np.linspace(-20, 20, 1001, dtype=np.float32)


def cycles(ufunc) -> float:
    return kernel_cycles(kernel_of(ufunc))


def test_a_repeated_call_is_emitted_once():
    @kernel(cache=False)
    def twice(x: Float) -> Float:
        return gl.cos(x) + gl.cos(x)

    @kernel(cache=False)
    def once(x: Float) -> Float:
        c = gl.cos(x)
        return c + c

    assert np.array_equal(twice(X), once(X))
    assert cycles(twice) <= cycles(once) * 1.05
    assert [c.name for c in kernel_of(twice).routines] == ["cos"]


def test_the_rotation_matrix_computes_each_of_cos_and_sin_once():
    @kernel(cache=False)
    def rotate(x: Float, y: Float, a: Float) -> (Float, Float):
        m = mat2(gl.cos(a), gl.sin(a), -gl.sin(a), gl.cos(a))
        v = m @ vec2(x, y)
        return v.x, v.y

    @kernel(cache=False)
    def rotate_by_hand(x: Float, y: Float, a: Float) -> (Float, Float):
        c, s = gl.cos(a), gl.sin(a)
        return c * x - s * y, s * x + c * y

    got, want = rotate(X, X * 0.5, X * 0.1), rotate_by_hand(X, X * 0.5, X * 0.1)
    assert all(np.array_equal(g, w) for g, w in zip(got, want))
    assert cycles(rotate) <= cycles(rotate_by_hand) * 1.05


def test_a_result_from_an_ended_block_is_computed_again():
    @kernel(cache=False)
    def branch(x: Float) -> Float:
        y = Variable(Float, 0.0)
        with If(x > 0.0):
            y.set(gl.exp2(x * 0.1))
        return y + gl.exp2(x * 0.1) * 0.0 + gl.cos(x)

    want = np.where(X > 0, np.exp2(X * np.float32(0.1)), 0) + np.cos(X)
    np.testing.assert_allclose(branch(X), want, rtol=1e-5, atol=1e-5)


def test_other_settings_are_other_calls():
    @kernel(cache=False)
    def both(x: Float) -> Float:
        return gl.cos(x, precision="relaxed") - gl.cos(x)

    @kernel(cache=False, precision="relaxed")
    def relaxed(x: Float) -> Float:
        return gl.cos(x)

    @kernel(cache=False)
    def full(x: Float) -> Float:
        return gl.cos(x)

    assert np.array_equal(both(X), relaxed(X) - full(X))
    assert {c.precision for c in kernel_of(both).routines} == {"relaxed", "full"}


def test_each_site_is_listed_and_a_plan_can_set_it_apart():
    def body(x: Float) -> Float:
        a = gl.exp2(x)
        b = gl.exp2(x)
        return a - b

    k = reactor.kernel(body, cache=False)
    sites = [c.where for c in kernel_of(k).routines]
    assert len(sites) == 2 and sites[0] != sites[1]  # both lines, though one exp2 was emitted
    assert np.all(k(X) == 0)
    second = reactor.Site(sites[1], "exp2", "relaxed")
    apart = reactor.kernel(body, cache=False, sites=(second,))
    assert np.any(apart(X) != 0)  # the second line's own tier: computed apart


def test_a_routine_on_constants_is_computed_while_compiling():
    """The AVX-512 forms (VREDUCEPS, VGETEXPPS, VSCALEFPS ...) are calls LLVM cannot fold; on
    constant operands the portable form, the same bits, is emitted and folded: exp2(3.0) * x
    costs what 8.0 * x costs, and gives the bits the routine gives at run time."""
    @kernel(cache=False)
    def folded(x: Float) -> Float:
        return gl.exp2(3.3) * x + gl.log2(5.0)

    @kernel(cache=False)
    def plain(x: Float) -> Float:
        return 9.849155 * x + 2.321928

    @kernel(cache=False)
    def at_run_time(x: Float, c: Float, d: Float) -> Float:
        return gl.exp2(c) * x + gl.log2(d)

    assert cycles(folded) <= cycles(plain) * 1.05
    assert np.array_equal(folded(X), at_run_time(X, np.float32(3.3), np.float32(5.0)))
