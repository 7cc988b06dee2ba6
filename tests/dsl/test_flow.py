"""The control-flow core as plain calls (reactor.dsl.flow): the same code as the with blocks,
per-lane masks pushed and popped without a block, and a front end saying how a loop is left."""
import numpy as np
import pytest

import reactor
from reactor import Break, ControlFlowError, Elif, Else, Float, For, If, Int, Return, Variable, kernel
from reactor.dsl import flow

X = np.linspace(-3, 3, 1001, dtype=np.float32)


@kernel
def with_blocks(x: Float) -> Float:
    y = Variable(Float, 0.0)
    with If(x < -1.0):
        y.set(-x)
    with Elif(x > 1.0):
        y.set(x * 2.0)
    with Else():
        y.set(x * x)
    with For(0, 50) as i:
        with If(y > 4.0):
            Break()
        y.set(y + Float(i) * 0.1)
    return y


@kernel
def with_calls(x: Float) -> Float:
    y = Variable(Float, 0.0)
    b = flow.if_begin(x < -1.0)
    flow.assign(y, -x)
    flow.end(b)
    b = flow.elif_begin(x > 1.0)
    flow.assign(y, x * 2.0)
    flow.end(b)
    b = flow.else_begin()
    flow.assign(y, x * x)
    flow.end(b)
    loop, i = flow.for_begin(0, 50, lane_exits=True)
    b = flow.if_begin(y > 4.0)
    flow.loop_break()
    flow.end(b)
    flow.assign(y, y + Float(i) * 0.1)
    flow.end(loop)
    return y


def test_calls_build_what_the_with_blocks_build():
    assert np.array_equal(with_calls(X).view(np.uint32), with_blocks(X).view(np.uint32))


def test_a_pushed_mask_limits_assignments_to_its_lanes():
    @kernel
    def masked(x: Float) -> Float:
        y = Variable(Float, 1.0)
        flow.push_mask(x > 0.0)
        assert flow.active_mask() is not None
        flow.assign(y, x)
        flow.pop_mask()
        assert flow.active_mask() is None
        return y

    assert np.array_equal(masked(X), np.where(X > 0, X, np.float32(1)))


def test_a_while_loop_and_a_return_per_lane():
    @kernel
    def halve(x: Float) -> Float:
        v = Variable(Float, x)
        loop = flow.while_begin(lambda: v > 1.0, max_iterations=1000)
        flow.assign(v, v * 0.5)
        flow.end(loop)
        b = flow.if_begin(v < -2.0)
        flow.return_value(v * 0.0)
        flow.end(b)
        return v

    want = np.where(X < -2, 0, X)
    for k in range(12):
        want = np.where(want > 1, want * np.float32(0.5), want)
    assert np.array_equal(halve(X), want.astype(np.float32))


def test_mistakes_are_clear_errors():
    def pop_alone(x: Float) -> Float:
        flow.pop_mask()
        return x

    def pop_across_a_block(x: Float) -> Float:
        flow.push_mask(x > 0.0)
        b = flow.if_begin(x > 1.0)
        flow.pop_mask()
        flow.end(b)
        return x

    def push_left_in_a_block(x: Float) -> Float:
        b = flow.if_begin(x > 1.0)
        flow.push_mask(x > 2.0)
        flow.end(b)
        return x

    def assign_to_a_value(x: Float) -> Float:
        flow.assign(x, 1.0)
        return x

    for body, message in ((pop_alone, "pop_mask without|pop_mask must undo"),
                          (pop_across_a_block, "pop_mask must undo"),
                          (push_left_in_a_block, "push_mask of its own not popped"),
                          (assign_to_a_value, "assign needs a Variable")):
        with pytest.raises((ControlFlowError, reactor.DSLTypeError), match=message):
            kernel(body, name=body.__name__)


def _leave_if_done(y):
    with If(y > 4.0):
        Break()  # in a helper: the loop cannot see it in its own source


def test_a_front_end_says_how_a_loop_is_left():
    @kernel
    def told(x: Float) -> Float:
        y = Variable(Float, x)
        with For(0, 50, lane_exits=True) as i:
            _leave_if_done(y)
            y.set(y + 0.25)
        return y

    @kernel
    def read(x: Float) -> Float:
        y = Variable(Float, x)
        with For(0, 50) as i:
            with If(y > 4.0):
                Break()
            y.set(y + 0.25)
        return y

    assert np.array_equal(told(X), read(X))
    with pytest.raises(ControlFlowError, match="does not track lanes"):
        @kernel
        def not_told(x: Float) -> Float:
            y = Variable(Float, x)
            with For(0, 50, lane_exits=False):
                _leave_if_done(y)
                y.set(y + 0.25)
            return y
