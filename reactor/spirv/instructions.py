"""The arithmetic, comparison, logical and conversion instructions: per lane on DSL values, and
while building, in float32 and int32, on what is known then."""
from __future__ import annotations

import typing

import numpy as np

from ..dsl.values import Value, value_class
from ..ir.types import KINDS, VType
from .cells import INVOCATION, LENGTH, _dsl, componentwise, invocation_compare


# -- instructions ---------------------------------------------------------------------------------

def _arith(fn):
    return lambda fr, ins: fr.put(ins, componentwise(fn, *[fr.get(a) for a in ins.args]))


def _fl(fn, py=None):
    """A float operation: on DSL values per lane; on Python numbers while building, in float32
    (as the shader's constant folding would)."""
    return _arith(_float_op(fn, py))


def _float_op(fn, py=None):
    def op(*xs):
        if any(isinstance(x, Value) for x in xs):
            return fn(*[_dsl(x) if not isinstance(x, Value) else x for x in xs])
        return _python((py or fn)(*[np.float32(x) for x in xs]))
    return op


def _int(fn, py=None):
    """An integer operation: per lane, or while building with int32 wrap-around."""
    def op(*xs):
        if any(x is INVOCATION or x is LENGTH for x in xs):
            return invocation_compare(py or fn, xs)
        if any(isinstance(x, Value) for x in xs):
            return fn(*[_dsl(x, "Int") if not isinstance(x, Value) else x for x in xs])
        return _python((py or fn)(*[int(x) for x in xs]))
    return _arith(op)


def _bool(fn, py):
    return _arith(_bool_op(fn, py))


def _python(r):
    """A result computed while building, as a Python number (ints wrapped to int32)."""
    if isinstance(r, (bool, np.bool_)):
        return bool(r)
    if isinstance(r, (int, np.integer)):
        r = int(r)
        return (r + (1 << 31)) % (1 << 32) - (1 << 31)
    return float(np.float32(r))


def _tdiv(a: int, b: int) -> int:
    """int32 division truncated toward zero, as the kernel computes it: x / 0 is 0 (GLSL leaves it
    undefined; no lane traps), INT_MIN / -1 wraps to INT_MIN."""
    if b == 0:
        return 0
    q = abs(a) // abs(b)
    return q if (a < 0) == (b < 0) else -q


def _trem(a: int, b: int) -> int:
    return 0 if b == 0 else a - b * _tdiv(a, b)


def _u32(a: int) -> int:
    return a & 0xFFFFFFFF


def _smod(a, b):
    """OpSMod on DSL values: the remainder with the divisor's sign (x mod 0 is 0)."""
    from ..dsl.intrinsics import Select
    r = a % b
    return Select((r != 0) & ((r < 0) != (b < 0)), r + b, r)


def _unsigned(op):
    """An operation on uint32 values (kept as Int bits): done on their UInt view."""
    from ..dsl.intrinsics import As

    def run(*xs):
        uint = [As(value_class(VType(KINDS["UInt"], x.width)), x) for x in xs]
        return As(value_class(VType(KINDS["Int"], xs[0].width)), op(*uint))
    return run


def _uint_to_float(x):
    """A uint32 (kept as Int bits) to float, rounded."""
    from ..dsl.intrinsics import As
    if not isinstance(x, Value):
        return float(np.float32(_u32(int(x))))
    return value_class(VType(KINDS["Float"], x.width))(As(value_class(VType(KINDS["UInt"], x.width)), x))


def _float_to_uint(x):
    """A float to uint32 (kept as Int bits): NaN and negatives 0, too large the largest."""
    from ..dsl.intrinsics import As, Select
    if not isinstance(x, Value):
        return _python(0 if x != x else int(min(max(x, 0.0), 2.0 ** 32 - 1)))
    uint, int_ = (value_class(VType(KINDS[k], x.width)) for k in ("UInt", "Int"))
    return As(int_, Select(x == x, uint(x), uint(0)))


def _to_int32(x: float) -> int:
    """float to int32 while building, as the kernel's conversion: NaN 0, out of range clamped."""
    if x != x:
        return 0
    return int(min(max(x, -2.0 ** 31), 2.0 ** 31 - 1))


def _fmul(a, b):
    return _float_op(lambda x, y: x * y)(a, b)


def _fadd(a, b):
    return _float_op(lambda x, y: x + y)(a, b)


def _convert(kind: str):
    from ..dsl.intrinsics import ToInt

    def convert(x):
        if not isinstance(x, Value):
            return float(np.float32(x)) if kind == "Float" else _to_int32(x) if isinstance(x, float) else int(x)
        if kind == "Int" and x.kind.is_float:
            return ToInt(x)
        return value_class(VType(KINDS[kind], x.width))(x)
    return _arith(convert)


def _select(fr, ins):
    from ..dsl.intrinsics import Select
    cond, a, b = (fr.get(x) for x in ins.args)
    if isinstance(cond, bool):
        fr.put(ins, a if cond else b)
        return
    fr.put(ins, componentwise(lambda c, x, y: Select(c, x, y), cond, a, b))


def _bool_op(fn, py):
    def op(*xs):
        if any(isinstance(x, Value) for x in xs):
            return fn(*[_dsl(x, "Bool") if not isinstance(x, Value) else x for x in xs])
        return bool(py(*[bool(x) for x in xs]))
    return op


_AND = _bool_op(lambda a, b: a & b, lambda a, b: a and b)
_OR = _bool_op(lambda a, b: a | b, lambda a, b: a or b)


def _reduce(combine):
    """``OpAll``/``OpAny``: a bool vector's components combined into one bool."""
    def op(fr, ins):
        parts = fr.get(ins.args[0])
        total = parts[0]
        for part in parts[1:]:
            total = combine(total, part)
        fr.put(ins, total)
    return op


def _fmod(x, y):
    from ..dsl.intrinsics import Floor
    return x - y * Floor(x / y)


OPS: dict[str, typing.Callable] = {
    "OpFAdd": _fl(lambda a, b: a + b), "OpFSub": _fl(lambda a, b: a - b), "OpFMul": _fl(lambda a, b: a * b),
    "OpFDiv": _fl(lambda a, b: a / b), "OpFNegate": _fl(lambda a: -a),
    "OpFMod": _fl(_fmod, lambda a, b: a - b * np.floor(a / b)),
    "OpIAdd": _int(lambda a, b: a + b), "OpISub": _int(lambda a, b: a - b), "OpIMul": _int(lambda a, b: a * b),
    "OpSNegate": _int(lambda a: -a), "OpSDiv": _int(lambda a, b: a / b, _tdiv),
    "OpSRem": _int(lambda a, b: a % b, _trem),
    "OpSMod": _int(_smod, lambda a, b: 0 if b == 0 else a % b),
    "OpUDiv": _int(_unsigned(lambda a, b: a / b), lambda a, b: 0 if _u32(b) == 0 else _u32(a) // _u32(b)),
    "OpUMod": _int(_unsigned(lambda a, b: a % b), lambda a, b: 0 if _u32(b) == 0 else _u32(a) % _u32(b)),
    "OpShiftRightLogical": _int(_unsigned(lambda a, b: a >> b), lambda a, b: _u32(a) >> (b & 31)),
    "OpBitwiseAnd": _int(lambda a, b: a & b), "OpBitwiseOr": _int(lambda a, b: a | b),
    "OpBitwiseXor": _int(lambda a, b: a ^ b), "OpNot": _int(lambda a: ~a),
    "OpShiftLeftLogical": _int(lambda a, b: a << b), "OpShiftRightArithmetic": _int(lambda a, b: a >> b),
    "OpFOrdEqual": _fl(lambda a, b: a == b),
    "OpFOrdNotEqual": _fl(lambda a, b: (a != b) & (a == a) & (b == b)),
    "OpFUnordNotEqual": _fl(lambda a, b: a != b),
    "OpFOrdLessThan": _fl(lambda a, b: a < b), "OpFOrdGreaterThan": _fl(lambda a, b: a > b),
    "OpFOrdLessThanEqual": _fl(lambda a, b: a <= b), "OpFOrdGreaterThanEqual": _fl(lambda a, b: a >= b),
    "OpIEqual": _int(lambda a, b: a == b), "OpINotEqual": _int(lambda a, b: a != b),
    "OpSLessThan": _int(lambda a, b: a < b), "OpSGreaterThan": _int(lambda a, b: a > b),
    "OpSLessThanEqual": _int(lambda a, b: a <= b), "OpSGreaterThanEqual": _int(lambda a, b: a >= b),
    # unsigned: the same on values below 2^31 (an index, a count), which is what shaders compare
    "OpULessThan": _int(lambda a, b: a < b), "OpUGreaterThan": _int(lambda a, b: a > b),
    "OpULessThanEqual": _int(lambda a, b: a <= b), "OpUGreaterThanEqual": _int(lambda a, b: a >= b),
    "OpLogicalAnd": _bool(lambda a, b: a & b, lambda a, b: a and b),
    "OpLogicalOr": _bool(lambda a, b: a | b, lambda a, b: a or b),
    "OpLogicalNot": _bool(lambda a: ~a, lambda a: not a),
    "OpLogicalEqual": _bool(lambda a, b: ~(a ^ b), lambda a, b: a == b),
    "OpLogicalNotEqual": _bool(lambda a, b: a ^ b, lambda a, b: a != b),
    "OpConvertSToF": _convert("Float"), "OpConvertFToS": _convert("Int"),
    "OpConvertUToF": _arith(lambda x: _uint_to_float(x)), "OpConvertFToU": _arith(lambda x: _float_to_uint(x)),
    "OpSelect": _select, "OpAll": _reduce(_AND), "OpAny": _reduce(_OR),
}


def _dot(a, b):
    total = None
    for x, y in zip(a, b):
        term = _fmul(x, y)
        total = term if total is None else _fadd(total, term)
    return total


def _insert(value, path, composite):
    k, rest = path[0], path[1:]
    parts = list(composite)
    parts[k] = _insert(value, rest, parts[k]) if rest else value
    return tuple(parts)
