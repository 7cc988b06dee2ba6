"""Operations a kind does not have, or between kinds, are type errors: each line marked with an
error code in a comment must be reported by mypy with that code, and no other line
(tests/typing/test_value_types.py)."""
from __future__ import annotations

from reactor import Bool4, Float, Float4, Float8, Int4, UInt, ivec3, mat3, vec3


def mixed(a: Float4, i: Int4, b: Float8, m: Bool4, u: UInt, s: Float, p: vec3, q: ivec3, t: mat3) -> None:
    a + i  # error: operator
    i * a  # error: operator
    a + b  # error: operator
    a & a  # error: operator
    a << 1  # error: operator
    m + m  # error: operator
    m < m  # error: operator
    i ** 2  # error: operator
    a + 1j  # error: operator
    p + q  # error: operator
    p + i  # error: operator
    t * p  # error: operator
    s < i  # error: operator
    x: Float4 = a < a  # error: assignment
    y: Int4 = a + a  # error: assignment
    ~a  # error: misc
    -m  # error: misc
    abs(u)  # error: arg-type
    _ = (x, y)
