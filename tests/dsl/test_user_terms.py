"""The DSL in its user's terms: a vector or matrix indexed by a per-lane Int (GLSL's dynamic
indexing), and messages that name ``Float``/``Int`` as written, not the 16-lane ``Float16``."""
import re

import numpy as np
import pytest

from reactor import DSLTypeError, Float, Float4, Int, Select, kernel, mat3, vec3

V = np.arange(30, dtype=np.float32).reshape(10, 3)
I = np.array([0, 1, 2, 1, 0, 2, 2, 1, 0, 0], np.int32)


def test_a_vector_indexed_per_lane_picks_each_lanes_component():
    @kernel(cache=False)
    def pick(v: vec3, i: Int) -> Float:
        return v[i]

    assert np.array_equal(pick(V, I), V[np.arange(10), I])


def test_a_matrix_indexed_per_lane_picks_each_lanes_column():
    @kernel(cache=False)
    def column(v: vec3, i: Int) -> vec3:
        return mat3(v, v * 2.0, v * 3.0)[i]

    assert np.array_equal(column(V, I), V * (I[:, None] + 1))


def test_an_index_that_is_not_an_integer_says_what_is_accepted():
    with pytest.raises(DSLTypeError, match=r"vec3 index must be an int in \[0, 3\) or an Int value, not <Float value>"):
        kernel(lambda v, x: v[x], args=[vec3, Float], returns=Float, cache=False)


@pytest.mark.parametrize("body, returns, words", [
    (lambda x, i: x + i, Float, r"operands of different types \(Float and Int\)"),
    (lambda x, i: Select(i, x, x), Float, r"Select needs a Bool mask as first argument, not <Int value>"),
    (lambda x, i: x, Int, r"expected Int, got Float"),
])
def test_messages_name_the_types_as_written(body, returns, words):
    with pytest.raises(DSLTypeError, match=words) as caught:
        kernel(body, args=[Float, Int], returns=returns, cache=False)
    assert not re.search(r"(Float|Int)\d", str(caught.value).split(" (at ")[0])


def test_a_width_the_body_does_not_run_at_keeps_its_number():
    with pytest.raises(DSLTypeError, match="Float4"):
        kernel(lambda x: x + Float4(1.0), args=[Float], returns=Float, cache=False, width=8)
