"""Several results written as type checkers accept them: ``-> tuple[Float, Float]`` (and
``typing.Tuple``, and string annotations) behaves exactly as ``-> (Float, Float)``; a tuple that
names no fixed list of DSL types is one clear error."""
from __future__ import annotations

import typing

import numpy as np
import pytest

import reactor
from reactor import Bool, DSLTypeError, Float, Int, kernel, vec3


def _split(x: Float, y: Float):
    return x * y + 1.0, x - y


def _as_kernel(returns):
    """``_split`` compiled with the return annotation ``returns`` (as if written on its def line)."""
    def body(x: Float, y: Float):
        return _split(x, y)
    body.__annotations__["return"] = returns
    return kernel(body)


X = np.linspace(-3, 3, 37, dtype=np.float32)
Y = np.linspace(5, -1, 37, dtype=np.float32)


@pytest.mark.parametrize("returns", [tuple[Float, Float], typing.Tuple[Float, Float], "tuple[Float, Float]"],
                         ids=["tuple", "typing.Tuple", "string"])
def test_a_tuple_annotation_gives_what_the_parenthesised_form_gives(returns):
    expected = _as_kernel((Float, Float))(X, Y)
    got = _as_kernel(returns)(X, Y)
    assert isinstance(got, tuple) and len(got) == 2
    for g, e in zip(got, expected):
        assert g.dtype == np.float32
        np.testing.assert_array_equal(g, e)
    np.testing.assert_array_equal(got[0], X * Y + np.float32(1.0))


def test_mixed_kinds_and_vectors_in_a_tuple():
    @kernel
    def parts(x: Float, i: Int) -> tuple[vec3, Bool, Int]:
        return vec3(x, 2.0 * x, 3.0 * x), x > 0.0, i + 1

    v, m, j = parts(X, np.arange(37, dtype=np.int32))
    assert v.shape == (37, 3) and m.dtype == np.bool_ and j.dtype == np.int32
    np.testing.assert_array_equal(v[:, 1], 2.0 * X)
    np.testing.assert_array_equal(m, X > 0)
    np.testing.assert_array_equal(j, np.arange(1, 38))


def test_a_function_takes_a_tuple_annotation_like_the_parenthesised_one():
    def body(x: Float) -> tuple[Float, Float]:
        return x, x

    plain = reactor.Function(body)
    assert plain.signature.returns == (Float, Float)
    assert reactor.Function(body, returns=(Float, Float)).signature == plain.signature


@pytest.mark.parametrize("returns, words", [
    (tuple[Float, ...], ["tuple[Float, ...]", "one type per result", "'...'"]),
    (tuple[int, Float], ["tuple[int, Float]", "result 1 of 2 is int", "not a DSL type"]),
    ((Float, float), ["(Float, float)", "result 2 of 2 is float"]),
    (tuple[()], ["tuple[]", "empty tuple"]),
    (tuple[Float, tuple[Float, Float]], ["result 2 of 2 is tuple[Float, Float]"]),
])
def test_a_bad_tuple_is_one_error_naming_the_problem(returns, words):
    with pytest.raises(DSLTypeError) as info:
        _as_kernel(returns)
    message = str(info.value)
    assert "'body' returns" in message
    for word in words:
        assert word in message, message
