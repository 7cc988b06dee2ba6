"""Value and vector types as a type checker sees them: each line states the type of an expression
(``assert_type`` is checked by mypy, tests/typing/test_value_types.py runs it with ``--strict``)."""
from __future__ import annotations

from typing_extensions import assert_type

from reactor import (
    Bool, Bool4, Double8, Float, Float4, Float16, Int, Int4, UInt8, Value, bvec3, ivec2, mat3, vec3, vec4,
)


def lanes(a: Float4, b: Float4, s: Float, i: Int4, n: Int, m: Bool4, d: Double8, u: UInt8, v: Value) -> Float4:
    assert_type(a + b, Float4)
    assert_type(a * 2.0 - 1, Float4)
    assert_type(0.5 * a, Float4)
    assert_type(a / s, Float4)  # a scalar broadcasts
    assert_type(s - a, Float4)
    assert_type(a % b, Float4)
    assert_type(a ** 2, Float4)
    assert_type(-a, Float4)
    assert_type(abs(a), Float4)
    assert_type(a < b, Bool4)
    assert_type(s >= a, Bool4)
    assert_type(a == 1.0, Bool4)
    assert_type((a < b) & (a > 0.0) | ~m, Bool4)
    assert_type(i << 2, Int4)
    assert_type(i & n ^ 3, Int4)
    assert_type(u >> 1, UInt8)
    assert_type(d + 1.0, Double8)
    assert_type(a + v, Value)  # a value of no known kind combines with any
    assert_type(Float4(1.0), Float4)
    assert_type(Float(n), Float)
    assert_type(Bool(True), Bool)
    return a + b


def components(p: vec3, q: vec3, s: Float, f16: Float16, k: ivec2, m: mat3) -> vec4:
    assert_type(p + q, vec3)
    assert_type(p * s, vec3)
    assert_type(2.0 * p, vec3)
    assert_type(p / f16, vec3)
    assert_type(p < q, bvec3)
    assert_type(k * 3, ivec2)
    assert_type(p[0], Float)
    assert_type(m @ p, vec3)
    assert_type(p @ m, vec3)
    assert_type(m @ m, mat3)
    assert_type(m * 2.0 + m, mat3)
    assert_type(m[1], vec3)
    assert_type(vec3(1.0, 2.0, 3.0), vec3)
    return vec4(p, 1.0)
