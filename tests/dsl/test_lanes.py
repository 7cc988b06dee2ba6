"""Per-lane control flow in kernels: the execution mask (If/Elif/Else, While, For, Break,
Continue, Return under per-lane conditions), tail lanes, and max_iterations."""
import numpy as np
import pytest

import reactor
from reactor import (
    All, Any, Break, Continue, Elif, Else, Float, For, If, Int, LoopLimitError, Return, Variable,
    While, function, kernel,
)

WIDTHS = [16, 8, 4, 1]


@pytest.fixture
def two_threads():
    saved = reactor.thread_settings()
    reactor.configure_threads(threads=2, threshold=64, min_work=0)
    yield
    reactor.configure_threads(**saved._asdict())


def _data(n, seed=1):
    return np.random.default_rng(seed).uniform(-4, 4, n).astype(np.float32)


@pytest.mark.parametrize("width", WIDTHS)
def test_if_elif_else_assigns_only_the_active_lanes(width):
    @kernel(width=width)
    def piecewise(x: Float) -> Float:
        y = Variable(Float, 7.0)
        with If(x < -1.0):
            y.set(-x)
        with Elif(x > 1.0):
            y.set(1.0)
            with If(x > 3.0):  # nested, per lane too
                y.set(3.0)
        with Else():
            y += x
        return y

    for n in (0, 1, 5, 17, 33, 1000):
        x = _data(n)
        want = np.where(x < -1, -x, np.where(x > 1, np.where(x > 3, 3, 1), 7 + x)).astype(np.float32)
        np.testing.assert_array_equal(piecewise(x), want)


@pytest.mark.parametrize("width", WIDTHS)
def test_while_runs_each_lane_its_own_number_of_times(width):
    @kernel(width=width)
    def halvings(x: Float) -> Int:
        n = Variable(Int, 0)
        v = Variable(x)
        with While(lambda: v >= 1.0):
            v.set(v * 0.5)
            n += 1
        return n

    x = np.array([0.5, 1, 2, 3, 8, 100, 1e6, 0, 65536, 3e9, 1.5] * 3, np.float32)
    want = []
    for v in x:
        k = 0
        while v >= 1:
            v = np.float32(v * 0.5)
            k += 1
        want.append(k)
    np.testing.assert_array_equal(halvings(x), np.array(want, np.int32))


@pytest.mark.parametrize("width", WIDTHS)
def test_for_with_break_and_continue_per_lane(width):
    @kernel(width=width)
    def walk(x: Float) -> Float:
        t = Variable(Float, 0.0)
        with For(0, 50) as i:
            with If((i & 1) == 1):
                Continue()  # odd steps do nothing
            d = x - t
            with If(d < 0.01):
                Break()
            t += d * 0.5
        return t

    x = np.abs(_data(37)) + np.float32(0.001)

    def ref(v):
        t = np.float32(0)
        for i in range(50):
            if i & 1:
                continue
            d = np.float32(v - t)
            if d < np.float32(0.01):
                break
            t = np.float32(t + d * np.float32(0.5))
        return t

    np.testing.assert_array_equal(walk(x), np.array([ref(v) for v in x], np.float32))


@pytest.mark.parametrize("width", WIDTHS)
def test_early_return_per_lane(width):
    @kernel(width=width)
    def early(x: Float) -> Float:
        with If(x < 0.0):
            Return(-1.0)
        acc = Variable(Float, 0.0)
        with While(lambda: acc < x):
            acc += 1.0
            with If(acc > 2.5):
                Return(acc * 10.0)  # from inside a loop
        return acc

    x = np.array([-5, 0.5, 2, 0, 7.5, 1.25, -0.0, 3] * 5, np.float32)

    def ref(v):
        if v < 0:
            return -1.0
        acc = 0.0
        while acc < v:
            acc += 1
            if acc > 2.5:
                return acc * 10
        return acc

    np.testing.assert_array_equal(early(x), np.array([ref(v) for v in x], np.float32))


@pytest.mark.parametrize("n", range(34))
def test_loop_until_every_lane_is_done_at_every_tail_length(n):
    """The hand-written form (an active mask and While(Any(...))) ends at every length: the
    tail's padding lanes are never active (this hung at 5 and 17 elements)."""
    @kernel(width=16)
    def settle(x: Float) -> Float:
        v = Variable(x)
        with While(lambda: Any(v > 1.0), max_iterations=1000):
            v.set(reactor.Select(v > 1.0, v * 0.5, v))
        return v

    @kernel(width=16)
    def all_small(x: Float) -> Int:
        return reactor.Select(All(x < 100.0), 1, 0) + reactor.Select(Any(x > 100.0), 2, 0)

    x = (np.arange(n, dtype=np.float32) + 1) * 3
    want = x.copy()
    while (want > 1).any():
        want = np.where(want > 1, want * np.float32(0.5), want).astype(np.float32)
    np.testing.assert_array_equal(settle(x), want)
    # the lanes of one body call agree: all < 100 and none > 100 in every block of this data
    assert (all_small(x) == 1).all()


def test_a_block_no_lane_enters_is_skipped():
    @kernel
    def guarded(x: Float) -> Float:
        y = Variable(x)
        with If(x > 100.0):
            with While(lambda: y > 0.0, max_iterations=10):  # would run away, if entered
                y += 1.0
        return y

    x = _data(40)
    np.testing.assert_array_equal(guarded(x), x)
    x[3] = 200.0
    with pytest.raises(LoopLimitError, match="max_iterations"):
        guarded(x)


def test_max_iterations_stops_a_runaway_kernel_with_a_clear_error(two_threads):
    @kernel
    def spin(x: Float) -> Float:
        v = Variable(x)
        with While(lambda: v > 0.0, max_iterations=100):
            v += 1.0
        return v

    np.testing.assert_array_equal(spin(-np.ones(5, np.float32)), -np.ones(5, np.float32))
    for n in (5, 17, 1 << 16):  # the largest is split between the two threads
        x = -np.ones(n, np.float32)
        x[n - 2] = 1.0  # in the last chunk
        with pytest.raises(LoopLimitError) as e:
            spin(x)
        assert "ran 100 iterations" in str(e.value) and "test_lanes.py" in str(e.value)
        assert "While loop at" in str(e.value)
    np.testing.assert_array_equal(spin(-np.ones(3, np.float32)), -np.ones(3, np.float32))  # reset


def test_max_iterations_in_a_function():
    @function
    def spin(x: Float) -> Float:
        v = Variable(x)
        with For(0, 1 << 30, max_iterations=50) as i:
            with If(v > 0.0):
                v += 1.0
            with Else():
                Break()
        return v

    assert spin(-2.0) == -2.0
    with pytest.raises(LoopLimitError, match="For loop at .*ran 50 iterations"):
        spin(1.0)
    assert spin(-3.0) == -3.0


def test_max_iterations_must_be_a_positive_integer():
    @function
    def f(x: Float) -> Float:
        v = Variable(x)
        with While(lambda: v > 0.0, max_iterations=0):
            v -= 1.0
        return v

    with pytest.raises(reactor.ReactorError, match="max_iterations"):
        f(1.0)


def test_constructors_and_variables_take_the_kernels_width():
    @kernel
    def conv(x: Float, i: Int) -> Float:
        acc = Variable(Float, 0.0)  # one value per lane
        acc += Float(i) + Float(x > 0.0)  # Float(Int), Float(mask): 1.0 where true
        return acc

    x, i = _data(21), np.arange(21, dtype=np.int32)
    np.testing.assert_array_equal(conv(x, i), (i + (x > 0)).astype(np.float32))


def test_a_uniform_variable_under_a_per_lane_condition_is_an_error_naming_the_fix():
    def bad(x: Float) -> Float:
        count = Variable(Int, 0, uniform=True)
        with If(x > 0.0):
            count += 1
        return x

    with pytest.raises(reactor.ControlFlowError) as e:
        kernel(bad)
    assert "test_lanes.py" in str(e.value) and "one value per lane" in str(e.value)


def test_cheap_blocks_run_unguarded_and_expensive_ones_are_skipped_when_no_lane_enters():
    import routines

    @kernel(width=16)
    def cheap(x: Float) -> Float:
        y = Variable(x)
        with If(x > 0.5):
            y.set(x * 2.0 + 1.0)
        return y

    @kernel(width=16)
    def costly(x: Float) -> Float:
        y = Variable(x)
        with If(x > 0.5):
            y.set(routines.pow(x, 2.4) + routines.exp2(x) * routines.log2(x))
        return y

    def guards(u):  # the "any lane active?" branches left (a cheap block's is 'br i1 1')
        import re
        return len(re.findall(r'br i1 %.*label %"lanes.if"', reactor.kernel_of(u).code.ir_text))

    assert guards(cheap) == 0 and guards(costly) == 1
    x = _data(50)
    np.testing.assert_array_equal(cheap(x), np.where(x > 0.5, x * 2 + 1, x))


@pytest.mark.parametrize("body", [
    lambda x: Variable(reactor.Float4, 0.0).set(x),
    lambda x: reactor.Float16(x) + x,
    lambda x: reactor.Select(x > 0.0, reactor.Float4(1.0), x),
])
def test_a_fixed_width_in_a_kernel_names_the_fix_and_the_fix_works(body):
    def bad(x: Float) -> Float:
        return body(x)

    with pytest.raises(reactor.WidthMismatchError) as e:
        kernel(bad)
    assert "write the scalar types (Float, Int, Bool ...)" in str(e.value) and "test_lanes.py" in str(e.value)

    @kernel
    def fixed(x: Float) -> Float:  # the fix: scalar types, one value per lane
        v = Variable(Float, 0.0)
        v.set(x)
        return reactor.Select(x > 0.0, Float(1.0), Float(x) + v * 0.0)

    np.testing.assert_array_equal(fixed(np.array([-2, 3], np.float32)), [-2, 1])
