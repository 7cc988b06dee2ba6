"""@reactor.syntax: Python's own ``if``/``elif``/``else`` on per-lane values, checked lane by lane
against NumPy; a condition that is a Python value stays Python's; what cannot be honoured is an
error naming the user's line."""
import numpy as np
import pytest

import reactor
from reactor import Break, ControlFlowError, DSLTypeError, Float, For, Int, Variable, kernel, syntax, vec3

X = np.linspace(-3, 3, 1003, dtype=np.float32)  # a tail after the vector loop too


@kernel
@syntax
def branches(x: Float) -> Float:
    if x < -1.0:
        r = 2.0                      # a Python number, in the lanes of this branch only
    elif x > 1.0:
        r = x * x
        if x > 2.5:
            return x * 10.0          # these lanes' result
    else:
        return x                     # per lane
    return r + 1.0


def test_if_elif_else_per_lane_as_numpy():
    want = np.where(X < -1, 3.0, np.where(X > 2.5, X * 10, np.where(X > 1, X * X + 1, X))).astype(np.float32)
    assert np.array_equal(branches(X), want)


WIDE = True


@kernel
@syntax
def python_condition(x: Float) -> Float:
    if WIDE:                         # a Python value: decided while building, one branch traced
        y = x * 2.0
    else:
        y = x
    return y


def test_a_python_condition_stays_pythons():
    assert np.array_equal(python_condition(X), X * 2)


@kernel
@syntax
def walk(x: Float) -> Float:
    t = Variable(Float, x)
    with For(0, 40):
        if t > 2.0:
            Break()                  # per lane, in the run-time loop around
        t.set(t + 0.25)
    return t


def test_an_if_in_a_run_time_loop_breaks_per_lane():
    t = X.copy()
    for _ in range(40):
        t = np.where(t > 2.0, t, t + np.float32(0.25))
    assert np.array_equal(walk(X), t)


@kernel
@syntax
def colour(x: Float) -> vec3:
    if x > 0.0:
        c = vec3(x, 1.0, 0.0)
    else:
        c = vec3(0.0, -x, 1.0)
    return c


def test_vectors_differ_per_lane():
    got = colour(X)
    want = np.where((X > 0)[:, None], np.stack([X, np.ones_like(X), np.zeros_like(X)], -1),
                    np.stack([np.zeros_like(X), -X, np.ones_like(X)], -1))
    assert np.array_equal(got, want.astype(np.float32))


@reactor.function
@syntax
def clamp_up(k: Int) -> Int:
    if k < 10:                       # a scalar Bool in a Function: a real branch
        k = k + 100
    return k * 2


def test_a_scalar_condition_branches():
    assert [clamp_up(k) for k in (3, 10, 42)] == [206, 20, 84]


def _build(body):
    return kernel(syntax(body), name=body.__name__)


def test_a_name_set_on_one_path_only_is_an_error_naming_it():
    def one_path(x: Float) -> Float:
        if x > 0.0:
            y = x
        return y * 2.0

    with pytest.raises(DSLTypeError, match="'y' is assigned on some paths of a run-time 'if' only") as err:
        _build(one_path)
    assert err.value.location[0] == __file__


def test_a_python_object_assigned_per_lane_is_an_error_when_used():
    def listed(x: Float) -> Float:
        parts = []
        if x > 0.0:
            parts = [x, x]
        return parts[0]

    with pytest.raises(DSLTypeError, match="'parts' was assigned a list under a run-time condition"):
        _build(listed)


def test_mutating_a_value_under_a_run_time_condition_is_refused():
    def mutate(x: Float) -> vec3:
        c = vec3(x, x, x)
        if x > 0.0:
            c.x = 1.0
        return c

    with pytest.raises(DSLTypeError, match="'c.x = ...' under a run-time condition"):
        _build(mutate)


def test_leaving_a_python_loop_per_lane_is_refused():
    def unrolled(x: Float) -> Float:
        y = x
        for _ in range(3):
            if y > 1.0:
                break
            y = y * 2.0
        return y

    with pytest.raises(ControlFlowError, match="'break' under a run-time condition leaves a Python loop"):
        _build(unrolled)


def test_every_body_is_traced_as_written():
    """Kernels and Functions rewrite their bodies' control flow without the decorator."""
    def plain(x: Float) -> Float:
        if x > 0.0:
            return x
        return -x

    assert np.array_equal(kernel(plain, name="plain")(X), np.abs(X))
