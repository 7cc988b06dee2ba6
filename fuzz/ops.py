"""The fuzzer's operations: for each, how to emit it as DSL code and how to
evaluate it independently with NumPy (the DSL's contract, docs/dsl.md and the
``reactor.ir.ops`` docstring, written out explicitly where NumPy differs).

Evaluation works on arrays of shape ``(rows, W)`` (vectors) or ``(rows, 1)``
(scalars; at width 1 the two coincide). Each evaluator returns the value and an
optional *taint* mask: lanes whose exact value the contract leaves open (the
sign of a zero from ``MinNum(+0, -0)``, the bits of a NaN seen through a bit
cast or ``CopySign``), which the comparison then skips.
"""
from __future__ import annotations

import dataclasses
from typing import Callable

import numpy as np

import reactor

from .ast import DTYPES, FLOATS, INTS, NUMS

I32_MIN, I32_MAX, U32_MAX = -(2**31), 2**31 - 1, 2**32 - 1
ALL = NUMS | {"Bool"}
BITS32 = frozenset({"Float", "Int", "UInt"})


@dataclasses.dataclass(frozen=True)
class Spec:
    name: str
    arity: int
    kinds: frozenset  # operand kinds accepted (all operands share one kind unless noted)
    result: str  # "same", "bool", or "param" (the target kind is the node's param)
    emit: Callable
    ev: Callable
    cross_lane: bool = False  # function mode only (not lane-wise)


# -- NumPy helpers -------------------------------------------------------------------

def _u(x):
    return x.astype(np.uint32)


def _as(kind, x):
    return x.astype(DTYPES[kind])


def _ints(kind, fn):
    """Integer op through uint32 (wrapping) arithmetic."""
    def ev(args, tys, node, ctx):
        return _as(tys[0].kind, fn(*[_u(a) for a in args])), None
    return ev


def _sign_bit(x):
    return np.signbit(x)


def is_snan(x):
    """Lanes of a float array holding a signalling NaN (quiet bit clear), any float size."""
    x = np.ascontiguousarray(x)
    ints = {2: np.uint16, 4: np.uint32, 8: np.uint64}[x.dtype.itemsize]
    quiet = ints({2: 0x0200, 4: 0x00400000, 8: 0x0008000000000000}[x.dtype.itemsize])
    return np.isnan(x) & ((x.view(ints) & quiet) == 0)


def _div_ev(rem: bool):
    def ev(args, tys, node, ctx):
        kind = tys[0].kind
        a, b = (x.astype(np.int64) for x in args)
        bz = b == 0
        sb = np.where(bz, 1, b)
        q = np.abs(a) // np.abs(sb) * np.sign(a) * np.sign(sb)  # C: truncate toward zero
        r = np.where(bz, 0, a - sb * q if rem else q)
        return (r & 0xFFFFFFFF).astype(np.uint32).astype(DTYPES[kind]), None
    return ev


def _float_div(args, tys, node, ctx):
    if tys[0].kind in INTS:
        return _div_ev(False)(args, tys, node, ctx)
    return args[0] / args[1], None


def _shift(how: str):
    def ev(args, tys, node, ctx):
        kind = tys[0].kind
        a, c = args[0], _u(args[1]) & np.uint32(31)
        mode = {"shr": "ashr" if kind == "Int" else "lshr"}.get(how, how)
        if mode == "shl":
            r = _u(a) << c
        elif mode == "lshr":
            r = _u(a) >> c
        else:
            r = a.astype(np.int32) >> c.astype(np.int32)
        return _as(kind, r), None
    return ev


def _minmax(is_min: bool):
    def ev(args, tys, node, ctx):
        a, b = args
        if tys[0].kind in FLOATS:  # x86 MINPS/MAXPS: a < b ? a : b (NaN -> b)
            return np.where(a < b if is_min else a > b, a, b), None
        return (np.minimum if is_min else np.maximum)(a, b), None
    return ev


def _minmaxnum(is_min: bool):
    def ev(args, tys, node, ctx):
        a, b = args
        r = (np.fmin if is_min else np.fmax)(a, b)
        # minnum(+0, -0) may return either zero; a signalling NaN operand may give a quiet NaN
        taint = ((a == 0) & (b == 0) & (_sign_bit(a) != _sign_bit(b))) | is_snan(a) | is_snan(b)
        return r, taint
    return ev


def _copysign(args, tys, node, ctx):
    a, b = args
    return np.copysign(a, b), np.isnan(b)  # the sign of a computed NaN is not specified


def _fract(args, tys, node, ctx):
    """GLSL's fract: x - floor(x), the float32 subtraction rounded to nearest."""
    (x,) = args
    with np.errstate(all="ignore"):
        return (x - np.floor(x)).astype(np.float32), None


def _reduce_down(args, tys, node, ctx):
    """x - floor(x) rounded toward -inf (VREDUCEPS): from the float64 difference, which is
    exact unless -2^-29 < x < 0, where the answer is the float just below 1."""
    (x,) = args
    x64 = x.astype(np.float64)
    v = x64 - np.floor(x64)
    c = v.astype(np.float32)
    c = np.where(c.astype(np.float64) > v, np.nextafter(c, np.float32(-np.inf)), c)
    c = np.where((x < 0) & (x > -(2.0 ** -29)), np.float32(1 - 2.0 ** -24), c)
    c = np.where(v == 0, np.float32(-0.0), c)
    return np.where(np.isinf(x), np.float32(0), c).astype(np.float32), None


def _exponent(args, tys, node, ctx):
    (x,) = args
    _, e = np.frexp(x)
    r = (e - 1).astype(np.float32)
    r = np.where(x == 0, np.float32(-np.inf), r)
    r = np.where(np.isinf(x), np.float32(np.inf), r)
    return np.where(np.isnan(x), x, r).astype(np.float32), None


def _significand(args, tys, node, ctx):
    (x,) = args
    m, _ = np.frexp(np.abs(x))
    r = (m * 2).astype(np.float32)
    r = np.where(np.isinf(x), np.float32(1), r)
    r = np.where(x < 0, np.float32(np.nan), r)
    r = np.where(x == 0, np.copysign(np.float32(1), x), r)
    return np.where(np.isnan(x), x, r).astype(np.float32), None


def _round_to_odd_f32(p, c):
    """fl32(p + c) for float64 p (an exact product of float32s) and c, with one rounding:
    add in float64 rounding to odd (TwoSum gives the error), then round to float32."""
    s = p + c
    bb = s - p
    err = (p - (s - bb)) + (c - bb)
    bits = np.ascontiguousarray(s).view(np.int64)
    inexact = (err != 0) & ((bits & 1) == 0) & np.isfinite(s)
    toward = np.where(np.sign(err) == np.sign(s), 1, -1)
    s = np.where(inexact, (bits + toward).view(np.float64), s)
    return s.astype(np.float32)


def _muladd(fused_always: bool):
    def ev(args, tys, node, ctx):
        a, b, c = args
        fused = fused_always or ctx.fma
        if not fused:
            return a * b + c, None
        if tys[0].kind == "Double":
            raise ValueError("fused Double MulAdd has no exact NumPy reference; the generator avoids it")
        p = a.astype(np.float64) * b.astype(np.float64)  # exact: 24 + 24 bits
        exact = _round_to_odd_f32(p, c.astype(np.float64))
        fallback = (a.astype(np.float64) * b + c.astype(np.float64)).astype(np.float32)
        ok = np.isfinite(p) & np.isfinite(c)
        return np.where(ok, exact, fallback).astype(np.float32), None
    return ev


def _float_to_int(x, kind, rounding):
    f = x.astype(np.float64)
    f = np.rint(f) if rounding == "nearest" else np.trunc(f)
    lo, hi = (I32_MIN, I32_MAX) if kind == "Int" else (0, U32_MAX)
    f = np.where(np.isnan(f), 0, np.clip(f, lo, hi))
    return f.astype(np.int64).astype(DTYPES[kind])


def _convert(args, tys, node, ctx):
    (x,) = args
    src, dst = tys[0].kind, node.param
    if dst == "Bool":
        return x != 0, None  # floats: unordered, NaN -> True
    if src in FLOATS and dst in INTS:
        return _float_to_int(x, dst, "trunc"), None
    return x.astype(DTYPES[dst]), None  # Bool -> 0/1; int <-> uint wrap; int -> float rounds


def _toint(args, tys, node, ctx):
    rounding, unsigned, *rest = node.param
    kind = "UInt" if unsigned else "Int"
    r = _float_to_int(args[0], kind, rounding)
    if rest and rest[0] is False:  # saturate=False: out-of-range and NaN inputs give unspecified values
        f = args[0].astype(np.float64)
        f = np.rint(f) if rounding == "nearest" else np.trunc(f)
        lo, hi = (I32_MIN, I32_MAX) if kind == "Int" else (0, U32_MAX)
        return r, ~((f >= lo) & (f <= hi))
    return r, None


def _bitcast(args, tys, node, ctx):
    (x,) = args
    r = np.ascontiguousarray(x).view(DTYPES[node.param])
    return r, np.isnan(x) if tys[0].kind in FLOATS else None


def _compare(sym: str):
    fn = {"lt": np.less, "le": np.less_equal, "gt": np.greater, "ge": np.greater_equal,
          "eq": np.equal, "ne": np.not_equal}[sym]
    return lambda args, tys, node, ctx: (fn(*args), None)  # NumPy: ordered except !=


def _lane(node, ctx):
    return node.param % ctx.W


def _extract(args, tys, node, ctx):
    (v,) = args
    if v.shape[1] == 1:
        return v, None
    k = _lane(node, ctx)
    return v[:, k:k + 1], None


def _extract_dyn(args, tys, node, ctx):
    v, i = args
    W = ctx.W
    v = np.broadcast_to(v, (max(v.shape[0], i.shape[0]), W))
    lane = (_u(i) & np.uint32(W - 1)).astype(np.intp)
    lane = np.broadcast_to(lane, (v.shape[0], 1))
    return np.take_along_axis(v, lane, axis=1), None


def _insert(args, tys, node, ctx):
    v, x = args
    W = ctx.W
    if W == 1:
        return np.broadcast_to(x, np.broadcast_shapes(v.shape, x.shape)).copy(), None
    rows = max(v.shape[0], x.shape[0])
    r = np.broadcast_to(v, (rows, W)).copy()
    r[:, _lane(node, ctx)] = np.broadcast_to(x, (rows, 1))[:, 0]
    return r, None


def _laneindex(args, tys, node, ctx):
    return np.arange(ctx.W, dtype=np.int32)[None, :], None


def _reduce(fn):
    return lambda args, tys, node, ctx: (fn(args[0], axis=1, keepdims=True), None)


# -- DSL emission helpers -------------------------------------------------------------

def _dsl_type(kind: str, scalar: bool, width: int):
    return reactor.vector_type(kind, 1 if scalar else width)


def _width():
    return reactor.SIMD.width


def _emit_convert(node, x):
    target = _dsl_type(node.param, node.ty.scalar, _width())
    return target(x)


def _emit_bitcast(node, x):
    return reactor.As(_dsl_type(node.param, node.ty.scalar, _width()), x)


def _emit_extract(node, v):
    W = _width()
    return v if W == 1 else reactor.Extract(v, node.param % W)


def _emit_extract_dyn(node, v, i):
    return v if _width() == 1 else reactor.Extract(v, i)


def _emit_insert(node, v, x):
    W = _width()
    if W == 1:
        return x
    return reactor.Insert(v, x, node.param % W)


def _b(fn):
    return lambda node, a, b: fn(a, b)


def _u1(fn):
    return lambda node, a: fn(a)


def _intr(name, arity):
    def emit(node, *args):
        return getattr(reactor, name)(*args)
    return emit


_BIN = {
    "add": lambda a, b: a + b, "sub": lambda a, b: a - b, "mul": lambda a, b: a * b,
    "div": lambda a, b: a / b, "rem": lambda a, b: a % b, "and": lambda a, b: a & b,
    "or": lambda a, b: a | b, "xor": lambda a, b: a ^ b, "shl": lambda a, b: a << b,
    "shr": lambda a, b: a >> b, "lt": lambda a, b: a < b, "le": lambda a, b: a <= b,
    "gt": lambda a, b: a > b, "ge": lambda a, b: a >= b, "eq": lambda a, b: a == b,
    "ne": lambda a, b: a != b,
}

_BOOLISH = INTS | {"Bool"}
_SPECS = [
    Spec("add", 2, NUMS, "same", _b(_BIN["add"]),
         lambda a, t, n, ctx: _ints(t[0].kind, np.add)(a, t, n, ctx) if t[0].kind in INTS else (a[0] + a[1], None)),
    Spec("sub", 2, NUMS, "same", _b(_BIN["sub"]),
         lambda a, t, n, ctx: _ints(t[0].kind, np.subtract)(a, t, n, ctx) if t[0].kind in INTS else (a[0] - a[1], None)),
    Spec("mul", 2, NUMS, "same", _b(_BIN["mul"]),
         lambda a, t, n, ctx: _ints(t[0].kind, np.multiply)(a, t, n, ctx) if t[0].kind in INTS else (a[0] * a[1], None)),
    Spec("div", 2, NUMS, "same", _b(_BIN["div"]), _float_div),
    Spec("rem", 2, INTS, "same", _b(_BIN["rem"]), _div_ev(True)),
    Spec("and", 2, _BOOLISH, "same", _b(_BIN["and"]), lambda a, t, n, ctx: (a[0] & a[1], None)),
    Spec("or", 2, _BOOLISH, "same", _b(_BIN["or"]), lambda a, t, n, ctx: (a[0] | a[1], None)),
    Spec("xor", 2, _BOOLISH, "same", _b(_BIN["xor"]), lambda a, t, n, ctx: (a[0] ^ a[1], None)),
    Spec("shl", 2, INTS, "same", _b(_BIN["shl"]), _shift("shl")),
    Spec("shr", 2, INTS, "same", _b(_BIN["shr"]), _shift("shr")),
    Spec("lshr", 2, INTS, "same", _intr("ShiftRightLogical", 2), _shift("lshr")),
    Spec("ashr", 2, INTS, "same", _intr("ShiftRightArithmetic", 2), _shift("ashr")),
    Spec("min", 2, NUMS, "same", _intr("Min", 2), _minmax(True)),
    Spec("max", 2, NUMS, "same", _intr("Max", 2), _minmax(False)),
    Spec("minnum", 2, FLOATS, "same", _intr("MinNum", 2), _minmaxnum(True)),
    Spec("maxnum", 2, FLOATS, "same", _intr("MaxNum", 2), _minmaxnum(False)),
    Spec("copysign", 2, FLOATS, "same", _intr("CopySign", 2), _copysign),
    Spec("neg", 1, NUMS, "same", _u1(lambda a: -a),
         lambda a, t, n, ctx: (_as(t[0].kind, np.negative(_u(a[0]))) if t[0].kind in INTS else -a[0], None)),
    Spec("invert", 1, _BOOLISH, "same", _u1(lambda a: ~a), lambda a, t, n, ctx: (~a[0], None)),
    Spec("abs", 1, FLOATS | {"Int"}, "same", _intr("Abs", 1), lambda a, t, n, ctx: (np.abs(a[0]), None)),
    Spec("floor", 1, FLOATS, "same", _intr("Floor", 1), lambda a, t, n, ctx: (np.floor(a[0]), None)),
    Spec("ceil", 1, FLOATS, "same", _intr("Ceil", 1), lambda a, t, n, ctx: (np.ceil(a[0]), None)),
    Spec("trunc", 1, FLOATS, "same", _intr("Trunc", 1), lambda a, t, n, ctx: (np.trunc(a[0]), None)),
    Spec("round", 1, FLOATS, "same", _intr("Round", 1), lambda a, t, n, ctx: (np.rint(a[0]), None)),
    Spec("sqrt", 1, FLOATS, "same", _intr("Sqrt", 1), lambda a, t, n, ctx: (np.sqrt(a[0]), None)),
    Spec("fract", 1, frozenset({"Float"}), "same", _intr("Fract", 1), _fract),
    Spec("reducedown", 1, frozenset({"Float"}), "same", _intr("ReduceDown", 1), _reduce_down),
    Spec("exponent", 1, frozenset({"Float"}), "same", _intr("Exponent", 1), _exponent),
    Spec("significand", 1, frozenset({"Float"}), "same", _intr("Significand", 1), _significand),
    Spec("isnan", 1, FLOATS, "bool", _intr("IsNan", 1), lambda a, t, n, ctx: (np.isnan(a[0]), None)),
    Spec("isinf", 1, FLOATS, "bool", _intr("IsInf", 1), lambda a, t, n, ctx: (np.isinf(a[0]), None)),
    Spec("isfinite", 1, FLOATS, "bool", _intr("IsFinite", 1), lambda a, t, n, ctx: (np.isfinite(a[0]), None)),
    # MulAdd: param = the build's fma option (fused iff on); Fma: always fused
    Spec("muladd", 3, FLOATS, "same", lambda node, a, b, c: reactor.MulAdd(a, b, c), _muladd(False)),
    Spec("fma", 3, frozenset({"Float"}), "same", lambda node, a, b, c: reactor.Fma(a, b, c), _muladd(True)),
    # Select: args (mask, a, b); kinds is the kinds of a and b
    Spec("select", 3, ALL, "same", lambda node, m, a, b: reactor.Select(m, a, b),
         lambda a, t, n, ctx: (np.where(a[0], a[1], a[2]), None)),
    Spec("convert", 1, ALL, "param", _emit_convert, _convert),
    Spec("toint", 1, FLOATS, "param",
         lambda node, x: reactor.ToInt(x, node.param[0], unsigned=node.param[1],
                                    saturate=node.param[2] if len(node.param) > 2 else True), _toint),
    Spec("bitcast", 1, BITS32, "param", _emit_bitcast, _bitcast),
    Spec("any", 1, frozenset({"Bool"}), "same", _intr("Any", 1), _reduce(np.any), cross_lane=True),
    Spec("all", 1, frozenset({"Bool"}), "same", _intr("All", 1), _reduce(np.all), cross_lane=True),
    Spec("extract", 1, ALL, "same", _emit_extract, _extract, cross_lane=True),
    Spec("extract_dyn", 2, ALL, "same", _emit_extract_dyn, _extract_dyn, cross_lane=True),
    Spec("insert", 2, ALL, "same", _emit_insert, _insert, cross_lane=True),
    Spec("laneindex", 0, frozenset(), "same", lambda node: reactor.LaneIndex(), _laneindex, cross_lane=True),
]
for _sym in ("lt", "le", "gt", "ge"):
    _SPECS.append(Spec(_sym, 2, NUMS, "bool", _b(_BIN[_sym]), _compare(_sym)))
for _sym in ("eq", "ne"):
    _SPECS.append(Spec(_sym, 2, ALL, "bool", _b(_BIN[_sym]), _compare(_sym)))

OPS: dict[str, Spec] = {s.name: s for s in _SPECS}

BINARY_ARITH = ("add", "sub", "mul", "div", "rem", "and", "or", "xor", "shl", "shr", "lshr", "ashr",
                "min", "max", "minnum", "maxnum", "copysign")
UNARY_ARITH = ("neg", "invert", "abs", "floor", "ceil", "trunc", "round", "sqrt", "fract", "reducedown", "exponent",
               "significand")
COMPARES = ("lt", "le", "gt", "ge", "eq", "ne")
CLASSIFY = ("isnan", "isinf", "isfinite")
