"""Random typed programs: expression graphs and small control-flow programs.

``generate(chooser, mode)`` builds a ``Program`` from a *chooser*: a
``RandomChooser`` (seeded ``random.Random``, for the ``fuzz`` command) or the
``draw`` of a hypothesis ``@composite`` strategy (``programs()``), which then
shrinks failing programs. Choices are ordered simple-first so shrinking moves
toward small programs with plain operations.

Generated programs always terminate (loop trip counts are bounded by
construction) and only use names where the DSL allows them (values of a block
inside it; loop counters inside their loop; top-level variables anywhere).
"""
from __future__ import annotations

import math
import random

import numpy as np

import reactor

from .ast import (FLOATS, INTS, KINDS, Arg, Const, For, If, Lanes, Let, Op, Program, Ref, Return, Set, Ty,
                  Var, While)
from .ops import BINARY_ARITH, BITS32, CLASSIFY, COMPARES, OPS, UNARY_ARITH

I32_MIN, I32_MAX, U32_MAX = -(2**31), 2**31 - 1, 2**32 - 1


def _f32(x: float) -> float:
    return float(np.float32(x))


FLOAT_CONSTS = [_f32(v) for v in (
    1.0, 0.0, -0.0, -1.0, 0.5, 2.0, 3.0, 1.5, -2.5, 2.5, 0.1, 1e-45, 1.1754944e-38, 5.877472e-39,
    3.4028235e38, -3.4028235e38, math.inf, -math.inf, math.nan, 2.0**31, -(2.0**31), 2.0**32, 2.0**24,
    2147483520.0, 4294967040.0, 0.49999997, 8388608.5 - 0.5, 1e10, -7.0, 255.0, 1e-30)]
DOUBLE_CONSTS = [1.0, 0.0, -0.0, -1.0, 0.5, 2.5, 0.1, 5e-324, 2.2250738585072014e-308, 1.7976931348623157e308,
                 math.inf, -math.inf, math.nan, 2.0**31, 2.0**31 - 0.5, -(2.0**31) - 1, 2.0**32, 3.4028235677973366e38,
                 1e300, 1e-300, 2.0**53 + 2, 1.0000000000000002]
INT_CONSTS = [1, 0, -1, 2, 3, 7, 31, 32, 33, -32, 255, 65535, I32_MAX, I32_MIN, I32_MIN + 1, 0x55555555,
              2**24 + 1, 1000003, -7, 16, 100]
UINT_CONSTS = [1, 0, 2, 31, 32, 33, 255, 2**31, U32_MAX, I32_MAX, 0xAAAAAAAA, 7, 2**24 + 1, 100]


class RandomChooser:
    """Choices from a seeded ``random.Random``."""

    def __init__(self, seed):
        self.r = random.Random(seed)

    def int(self, lo: int, hi: int) -> int:
        return self.r.randint(lo, hi)

    def choice(self, seq):
        return seq[self.r.randrange(len(seq))]

    def chance(self, p: float) -> bool:
        return self.r.random() < p


class DrawChooser:
    """Choices from hypothesis's ``draw`` (inside a ``@st.composite`` strategy)."""

    def __init__(self, draw):
        from hypothesis import strategies as st
        self.draw, self.st = draw, st

    def int(self, lo: int, hi: int) -> int:
        return self.draw(self.st.integers(lo, hi))

    def choice(self, seq):
        return seq[self.draw(self.st.integers(0, len(seq) - 1))]

    def chance(self, p: float) -> bool:
        return self.draw(self.st.integers(0, 99)) >= 100 - round(100 * p)


def _weighted(ch, options):
    """Pick from ``[(weight, value), ...]`` (zero weights skipped; order is simple-first)."""
    options = [(w, v) for w, v in options if w > 0]
    total = sum(w for w, _ in options)
    k = ch.int(0, total - 1)
    for w, v in options:
        if k < w:
            return v
        k -= w
    raise AssertionError


class Generator:
    def __init__(self, ch, mode: str, *, max_depth: int = 3, max_stmts: int = 6, fma: bool = False,
                 flat: bool = False):
        self.ch, self.mode, self.max_depth, self.max_stmts, self.fma = ch, mode, max_depth, max_stmts, fma
        self.flat = flat  # straight-line code: operations on the inputs, no control flow
        self.scopes: list[dict[str, tuple[Ty, str]]] = [{}]
        self.inputs: tuple[Ty, ...] = ()
        self.counter = 0
        self.loops = 0

    # -- names ---------------------------------------------------------------------
    def fresh(self, prefix: str) -> str:
        self.counter += 1
        return f"{prefix}{self.counter}"

    def visible(self, pred=lambda ty, role: True):
        return [(n, ty, role) for scope in self.scopes for n, (ty, role) in scope.items() if pred(ty, role)]

    def declare(self, name, ty, role):
        self.scopes[-1][name] = (ty, role)

    # -- constants -----------------------------------------------------------------
    def const_value(self, kind: str):
        ch = self.ch
        if kind == "Bool":
            return ch.chance(0.5)
        if kind == "Float":
            return ch.choice(FLOAT_CONSTS) if ch.chance(0.8) else _f32(ch.choice([-1, 1]) * 2.0 ** ch.int(-30, 30)
                                                                        * ch.int(1, 2**12) / 2**11)
        if kind == "Double":
            return ch.choice(DOUBLE_CONSTS) if ch.chance(0.8) else ch.int(-2**40, 2**40) / 2.0 ** ch.int(0, 60)
        pool = INT_CONSTS if kind == "Int" else UINT_CONSTS
        if ch.chance(0.75):
            return ch.choice(pool)
        lo = I32_MIN if kind == "Int" else 0
        return ch.int(lo, lo + U32_MAX)

    def literal(self, kind: str):
        v = self.const_value(kind)
        if kind in INTS and self.ch.chance(0.1):  # an unsigned-range literal in an Int (or negative in UInt): wraps
            v = (v & 0xFFFFFFFF) if self.ch.chance(0.5) or v >= 0 else v
        if kind in FLOATS and isinstance(v, float) and v.is_integer() and abs(v) < 2**31 and self.ch.chance(0.3):
            v = int(v)  # a Python int where a float is expected
        return Const(v, Ty(kind, True), literal=True)

    # -- expressions -----------------------------------------------------------------
    def expr(self, ty: Ty, depth: int, exact: bool = True):
        """An expression of type ``ty``; with ``exact=False`` a vector ``ty`` may also be
        satisfied by a scalar of the same kind (broadcast by the consumer)."""
        ch = self.ch
        if not exact and not ty.scalar and ch.chance(0.15):
            ty = Ty(ty.kind, True)
        if depth <= 0 or ch.chance(0.25 + 0.1 * (self.max_depth - depth)):
            return self.leaf(ty)
        return self.operation(ty, depth)

    def leaf(self, ty: Ty):
        ch = self.ch
        refs = self.visible(lambda t, role: t == ty)
        args = [k for k, t in enumerate(self.inputs) if t.kind == ty.kind]
        lane_of_arg = bool(args) and ty.scalar and self.mode == "function"
        options = [(8 if args and not ty.scalar else 0, "arg"), (6 if refs else 0, "ref"),
                   (6 if lane_of_arg else 0, "lane"), (2, "const"),
                   (1 if not ty.scalar and self.mode == "function" else 0, "lanes")]
        pick = _weighted(ch, options)
        if pick == "ref":
            recent = refs[-2:] if ch.chance(0.5) else refs  # recent values: fewer dead computations
            name, t, _ = ch.choice(recent)
            return Ref(name, t)
        if pick in ("arg", "lane"):
            k = ch.choice(args)
            arg = Arg(k, self.inputs[k])
            return arg if pick == "arg" else Op("extract", (arg,), ty, ch.int(0, 15))
        if pick == "lanes":
            return Lanes(tuple(self.const_value(ty.kind) for _ in range(16)), ty)
        return Const(self.const_value(ty.kind), ty)

    def operand_shapes(self, ty: Ty, n: int):
        """Scalar flags for n operands of an op whose result has type ``ty``."""
        if ty.scalar:
            return [True] * n
        flags = [self.ch.chance(0.2) for _ in range(n)]
        if all(flags):
            flags[self.ch.int(0, n - 1)] = False
        return flags

    def operation(self, ty: Ty, depth: int):
        ch, kind, fn = self.ch, ty.kind, self.mode == "function"
        d = depth - 1
        cands = []
        for name in BINARY_ARITH:
            if kind in OPS[name].kinds:
                cands.append((4 if name in ("add", "sub", "mul", "and", "or", "xor", "min", "max") else 2,
                              ("binary", name)))
        for name in UNARY_ARITH:
            if kind in OPS[name].kinds:
                cands.append((1, ("unary", name)))
        if kind == "Bool":
            cands += [(4, ("compare",)), (1, ("classify",))]
            if fn and ty.scalar:
                cands += [(4, ("reduce",))]
        cands.append((2, ("select",)))
        cands.append((2, ("convert",)))
        if kind in INTS:
            cands.append((1, ("toint",)))
        if kind in BITS32:
            cands.append((1, ("bitcast",)))
        if kind in FLOATS and (kind == "Float" or not self.fma):
            cands.append((1, ("muladd",)))
        if kind == "Float" and self.fma:
            cands.append((1, ("fma",)))
        if fn and ty.scalar:
            cands += [(2, ("extract",)), (1, ("extract_dyn",))]
        if fn and not ty.scalar:
            cands.append((1, ("insert",)))
            if kind == "Int":
                cands.append((1, ("laneindex",)))
        what = _weighted(ch, cands)
        tag = what[0]

        if tag == "binary":
            name = what[1]
            if name in ("shl", "shr", "lshr", "ashr", "div", "rem") and ch.chance(0.5):
                # shift counts (and divisors) where results differ: small, past 32, -1, 0
                other = self.expr(ty, d, exact=True)
                v = ch.int(0, 40) if name not in ("div", "rem") else ch.choice([-1, 0, 1, 2, 3, 7, -7, 10])
                return Op(name, (other, Const(v & 0xFFFFFFFF if kind == "UInt" else v, Ty(kind, True),
                                              literal=ch.chance(0.5))), other.ty)
            if ch.chance(0.2):  # one operand a bare Python number
                other = self.expr(ty, d, exact=True)
                lit = self.literal(kind)
                args = (other, lit) if ch.chance(0.7) else (lit, other)
            else:
                s = self.operand_shapes(ty, 2)
                args = tuple(self.expr(Ty(kind, f), d) for f in s)
            return Op(name, args, _result(args, kind))
        if tag == "unary":
            a = self.expr(ty, d)
            return Op(what[1], (a,), a.ty)
        if tag == "compare":
            src = ch.choice(["Float", "Float", "Int", "UInt", "Double", "Bool"])
            names = COMPARES if src != "Bool" else ("eq", "ne")
            name = ch.choice(names)
            if ch.chance(0.25) and src != "Bool":
                other = self.expr(Ty(src, ty.scalar), d)
                args = (other, self.literal(src))
            else:
                s = self.operand_shapes(ty, 2)
                args = tuple(self.expr(Ty(src, f), d) for f in s)
            return Op(name, args, _result(args, "Bool"))
        if tag == "classify":
            a = self.expr(Ty(ch.choice(["Float", "Double"]), ty.scalar), d)
            return Op(ch.choice(CLASSIFY), (a,), Ty("Bool", a.ty.scalar))
        if tag == "reduce":
            a = self.expr(Ty("Bool", False), d)
            return Op(ch.choice(["any", "all"]), (a,), Ty("Bool", True))
        if tag == "select":
            s = self.operand_shapes(ty, 3)
            mask = self.expr(Ty("Bool", s[0]), d)
            if ch.chance(0.2):
                a_scalar = ty.scalar or (not s[0] and ch.chance(0.3))
                a = self.expr(Ty(kind, a_scalar), d)
                lit = self.literal(kind)
                args = (mask, a, lit) if ch.chance(0.5) else (mask, lit, a)
            else:
                args = (mask, self.expr(Ty(kind, s[1]), d), self.expr(Ty(kind, s[2]), d))
            return Op("select", args, _result(args, kind))
        if tag == "convert":
            src = ch.choice([k for k in KINDS if k != kind])
            a = self.expr(Ty(src, ty.scalar), d)
            return Op("convert", (a,), Ty(kind, a.ty.scalar), kind)
        if tag == "toint":
            a = self.expr(Ty(ch.choice(["Float", "Double"]), ty.scalar), d)
            return Op("toint", (a,), Ty(kind, a.ty.scalar),
                      (ch.choice(["trunc", "nearest"]), kind == "UInt", ch.chance(0.7)))
        if tag == "bitcast":
            src = ch.choice([k for k in ("Float", "Int", "UInt") if k != kind])
            a = self.expr(Ty(src, ty.scalar), d)
            return Op("bitcast", (a,), Ty(kind, a.ty.scalar), kind)
        if tag in ("muladd", "fma"):
            s = self.operand_shapes(ty, 3)
            args = tuple(self.expr(Ty(kind, f), d) for f in s)
            return Op(tag, args, _result(args, kind))
        if tag == "extract":
            v = self.expr(Ty(kind, False), d)
            return Op("extract", (v,), ty, ch.int(0, 15))
        if tag == "extract_dyn":
            v = self.expr(Ty(kind, False), d)
            i = self.expr(Ty(ch.choice(["Int", "UInt"]), True), d)
            return Op("extract_dyn", (v, i), ty)
        if tag == "insert":
            v = self.expr(Ty(kind, False), d)
            x = self.expr(Ty(kind, True), d)
            return Op("insert", (v, x), ty, ch.int(0, 15))
        if tag == "laneindex":
            return Op("laneindex", (), ty)
        raise AssertionError(what)

    # -- statements -----------------------------------------------------------------
    def any_type(self, scalar_p: float = 0.25) -> Ty:
        kind = _weighted(self.ch, [(5, "Float"), (3, "Int"), (2, "Bool"), (2, "UInt"), (1, "Double")])
        return Ty(kind, self.ch.chance(scalar_p))

    def cond(self, depth=2):
        return self.expr(Ty("Bool", True), depth)

    def small_int(self, depth=1):
        """A scalar Int expression in [0, 7] (so loops stay short)."""
        e = self.expr(Ty("Int", True), depth)
        return Op("and", (e, Const(7, Ty("Int", True), literal=True)), Ty("Int", True))

    def block(self, nest: int, count: int):
        self.scopes.append({})
        try:
            return self.stmts(nest, count)
        finally:
            self.scopes.pop()

    def stmts(self, nest: int, count: int) -> tuple:
        out = []
        for _ in range(count):
            s = self.stmt(nest)
            out.append(s)
            if isinstance(s, Let) and self.ch.chance(0.5):
                sink = self.sink(Ref(s.name, s.expr.ty))
                if sink is not None:
                    out.append(sink)
            if isinstance(s, (Let, Var, Set)) and s.name != HASH and self.ch.chance(0.8):
                ty = s.expr.ty if isinstance(s, Let) else self.type_of(s.name)
                out.append(mix(Ref(s.name, ty)))
        return tuple(out)

    def type_of(self, name):
        return next(ty for n, ty, _ in self.visible() if n == name)

    def sink(self, src):
        """A Set that makes ``src`` reach a variable (so it reaches the outputs)."""
        ch = self.ch
        targets = self.visible(lambda t, role: role == "var" and (t.scalar is False or src.ty.scalar))
        if not targets:
            return None
        name, ty, _ = ch.choice(targets)
        if src.ty.kind != ty.kind:
            src = Op("convert", (src,), Ty(ty.kind, src.ty.scalar), ty.kind)
        how = _weighted(ch, [(4, "replace"), (2, "combine"), (2, "select")])
        var = Ref(name, ty)
        if how == "replace":
            return Set(name, src)
        if how == "select":
            mask = self.expr(Ty("Bool", ty.scalar), 1)
            return Set(name, Op("select", (mask, src, var), ty))
        ops = {"Float": ["add", "sub", "min", "max", "mul"], "Double": ["add", "sub", "max"],
               "Int": ["add", "xor", "sub", "or"], "UInt": ["add", "xor", "sub"], "Bool": ["xor", "or", "and"]}
        return Set(name, Op(ch.choice(ops[ty.kind]), (var, src), ty))

    def stmt(self, nest: int):
        ch = self.ch
        assignable = self.visible(lambda t, role: role == "var")
        flow = not self.flat
        options = [(4, "let"), (5 if assignable else 0, "set"), (1, "var"),
                   (3 if flow and nest < 3 else 0, "if"),
                   (2 if flow and nest < 2 and self.loops < 3 else 0, "for"),
                   (1 if flow and nest < 2 and self.loops < 3 else 0, "while"),
                   (1 if self.mode == "function" and nest > 0 else 0, "return")]
        pick = _weighted(ch, options)
        inner = max(1, self.max_stmts // 2)
        if pick == "let":
            e = self.expr(self.any_type(), self.max_depth)
            name = self.fresh("t")
            self.declare(name, e.ty, "let")
            return Let(name, e)
        if pick == "set":
            name, ty, _ = ch.choice(assignable)
            return Set(name, self.expr(ty, self.max_depth, exact=False))
        if pick == "var":
            return self.var()
        if pick == "if":
            cond = self.cond()
            then = self.block(nest + 1, ch.int(1, inner))
            elifs = tuple((self.cond(), self.block(nest + 1, ch.int(1, inner))) for _ in range(ch.int(0, 2)))
            orelse = self.block(nest + 1, ch.int(1, inner)) if ch.chance(0.5) else None
            return If(cond, then, elifs, orelse)
        if pick == "for":
            self.loops += 1
            start, stop, step = self.loop_bounds()
            name = self.fresh("i")
            self.scopes.append({name: (Ty(_counter_kind(start, stop), True), "counter")})
            try:
                body = self.stmts(nest + 1, ch.int(1, inner))
            finally:
                self.scopes.pop()
            return For(name, start, stop, step, body)
        if pick == "while":
            self.loops += 1
            name = self.fresh("k")
            bound = Const(ch.int(0, 6), Ty("Int", True), literal=True) if ch.chance(0.5) else self.small_int()
            self.declare(name, Ty("Int", True), "counter")
            extra = self.cond(1) if ch.chance(0.5) else None
            body = self.block(nest + 1, ch.int(1, inner))
            return While(name, bound, extra, body)
        return Return()

    def var(self):
        ty = self.any_type(0.2)
        name = self.fresh("v")
        init = self.expr(ty, self.max_depth - 1, exact=False)
        self.declare(name, ty, "var")
        return Var(name, ty, init)

    def loop_bounds(self):
        ch = self.ch
        lit = lambda v, kind="Int": Const(v, Ty(kind, True), literal=True)  # noqa: E731
        typed = lambda v, kind="Int": Const(v, Ty(kind, True))  # noqa: E731
        pick = _weighted(ch, [(5, "small"), (3, "dynamic"), (1, "edge")])
        if pick == "small":
            step = ch.choice([1, 1, 1, 2, 3, -1, -2])
            a = ch.int(-3, 3)
            b = a + ch.int(-1, 8) * (1 if step > 0 else -1)
            return lit(a), lit(b), step
        if pick == "dynamic":
            step = ch.choice([1, 1, 2, -1])
            e = self.small_int()
            if step > 0:
                return lit(ch.int(-2, 1)), e, step
            return e, lit(ch.int(-2, 0)), step
        # near the ends of the counter's range, where i + step wraps around
        step = ch.choice([2, 3, 5, -2, -3])
        if ch.chance(0.5):
            if step > 0:
                return typed(I32_MAX - ch.int(0, 9)), lit(I32_MAX), step
            return typed(I32_MIN + ch.int(0, 9)), lit(I32_MIN), step
        if step > 0:
            return typed(U32_MAX - ch.int(0, 9), "UInt"), lit(U32_MAX, "UInt"), step
        return typed(ch.int(0, 9), "UInt"), lit(0, "UInt"), step

    def program(self) -> Program:
        ch = self.ch
        nin = ch.int(1, 4)
        self.inputs = tuple(Ty(self.any_type(0).kind) for _ in range(nin))
        hash_var = Var(HASH, Ty("Int"), Const(17, Ty("Int")))
        self.declare(HASH, hash_var.ty, "hash")
        top = [hash_var] + [self.var() for _ in range(ch.int(1, 4))]
        body = tuple(top) + self.stmts(0, ch.int(1, self.max_stmts))
        top_vars = [(s.name, s.ty) for s in top[1:]]
        self.scopes = [{n: (t, "var") for n, t in top_vars}]  # outputs see inputs and top-level variables
        outputs = []
        for name, ty in top_vars:
            if ch.chance(0.9):
                outputs.append(Ref(name, ty) if not ty.scalar or ch.chance(0.5)
                               else self.expr(ty.vector(), 1))
        while not outputs or ch.chance(0.3):
            outputs.append(self.expr(Ty(self.any_type(0).kind), 2))
            if len(outputs) >= 4:
                break
        outputs.append(Ref(HASH, hash_var.ty))
        return Program(self.mode, self.inputs, body, tuple(outputs), fma=self.fma)


HASH = "h"  # a top-level Int variable every value is mixed into (an output): little dead code
_INT = Ty("Int")


def _bits(e):
    """An Int expression that changes whenever ``e`` does (NaNs all alike)."""
    ty, s = e.ty, e.ty.scalar
    it = Ty("Int", s)
    if ty.kind == "Int":
        return e
    if ty.kind in ("UInt", "Bool"):
        return Op("convert", (e,), it, "Int")
    if ty.kind == "Double":
        f = Op("convert", (e,), Ty("Float", s), "Float")
        return Op("xor", (_bits(f), Op("convert", (e,), it, "Int")), it)
    nan = Op("isnan", (e,), Ty("Bool", s))
    return Op("select", (nan, Const(0x7FC00000, Ty("Int", True), literal=True), Op("bitcast", (e,), it, "Int")), it)


def mix(value):
    """``h = (h ^ bits(value)) * 1000003``."""
    h = Ref(HASH, _INT)
    x = Op("xor", (h, _bits(value)), _INT)
    return Set(HASH, Op("mul", (x, Const(1000003, Ty("Int", True), literal=True)), _INT))


def _result(args, kind: str) -> Ty:
    scalar = all(a.ty.scalar for a in args if not (isinstance(a, Const) and a.literal))
    return Ty(kind, scalar)


def _counter_kind(start, stop) -> str:
    typed = [e for e in (start, stop) if not (isinstance(e, Const) and e.literal)]
    return typed[0].ty.kind if typed else "Int"


#: The forced targets this CPU runs (an AVX-512 target is only built and run on an AVX-512 host).
RUNNABLE_FORCED = [t for t in ("avx512", "avx2", "sse4") if reactor.get_target(t).runnable]


def generate(ch, mode: str | None = None) -> Program:
    """One random program (``mode`` "function" or "kernel"; None: the chooser picks)."""
    mode = mode or ch.choice(["function", "function", "kernel"])
    fma = ch.chance(0.5)
    if ch.chance(0.4):  # straight-line: many shallow operations applied to the (special) inputs
        gen = Generator(ch, mode, max_depth=ch.int(1, 2), max_stmts=ch.int(4, 12), fma=fma, flat=True)
    else:
        gen = Generator(ch, mode, max_depth=ch.int(1, 4), max_stmts=ch.int(1, 7), fma=fma)
    prog = gen.program()
    opt = ch.choice([3, 3, 3, 2, 1, 0])
    target = ch.choice(["host", "host", "host"] + RUNNABLE_FORCED)
    return Program(prog.mode, prog.inputs, prog.body, prog.outputs, fma=fma, opt=opt, target=target)


def programs(mode: str | None = None):
    """A hypothesis strategy of random programs."""
    from hypothesis import strategies as st

    @st.composite
    def strategy(draw):
        return generate(DrawChooser(draw), mode)

    return strategy()



def op_sweep(mode: str = "function", fma: bool = False, target: str = "host", group: int = 16) -> list[Program]:
    """Programs applying every operation of the table, on every kind it accepts, directly
    to the inputs: deterministic coverage of the whole table (one program per kind and
    group of operations, with only the inputs it uses)."""
    arg = {k: Arg(i, Ty(k)) for i, k in enumerate(KINDS)}
    arg2 = {k: Arg(i + len(KINDS), Ty(k)) for i, k in enumerate(KINDS)}
    fn = mode == "function"
    lane_i = Op("extract", (arg["Int"],), Ty("Int", True), 0)
    by_kind: dict[str, list] = {k: [] for k in KINDS}
    for name, spec in OPS.items():
        if spec.cross_lane and not fn:
            continue
        for k in KINDS:
            if k not in spec.kinds:
                continue
            a, b, m = arg[k], arg2[k], arg2["Bool"]
            outs = by_kind[k]
            if name in BINARY_ARITH:
                outs.append(Op(name, (a, b), Ty(k)))
            elif name in UNARY_ARITH:
                outs.append(Op(name, (a,), Ty(k)))
            elif name in COMPARES:
                outs.append(Op(name, (a, b), Ty("Bool")))
            elif name in CLASSIFY:
                outs.append(Op(name, (a,), Ty("Bool")))
            elif name == "select":
                outs.append(Op(name, (m, a, b), Ty(k)))
                if fn:
                    outs.append(Op(name, (Op("extract", (m,), Ty("Bool", True), 5), a, b), Ty(k)))
            elif name == "convert":
                outs += [Op(name, (a,), Ty(dst), dst) for dst in KINDS if dst != k]
            elif name == "toint":
                outs += [Op(name, (a,), Ty(dst), (r, dst == "UInt", sat)) for dst in INTS
                         for r in ("trunc", "nearest") for sat in (True, False)]
            elif name == "bitcast":
                outs += [Op(name, (a,), Ty(dst), dst) for dst in BITS32 if dst != k]
            elif name == "muladd" and (k == "Float" or not fma):
                outs.append(Op(name, (a, b, Op("neg", (b,), Ty(k))), Ty(k)))
                outs.append(Op(name, (a, a, b), Ty(k)))
            elif name == "fma" and fma:
                outs.append(Op(name, (a, b, Op("neg", (a,), Ty(k))), Ty(k)))
                outs.append(Op(name, (b, b, a), Ty(k)))
            elif name in ("any", "all"):
                outs.append(Op(name, (a,), Ty(k, True)))
            elif name == "extract":
                outs.append(Op(name, (a,), Ty(k, True), 3))
            elif name == "extract_dyn":
                outs.append(Op(name, (a, lane_i), Ty(k, True)))
            elif name == "insert":
                outs.append(Op(name, (a, Op("extract", (b,), Ty(k, True), 1)), Ty(k), 2))
            elif name == "laneindex" and k == "Int":
                outs.append(Op(name, (), Ty("Int")))
    progs = []
    for k, outs in by_kind.items():
        for start in range(0, len(outs), group):
            chunk = tuple(outs[start:start + group])
            used = sorted({n.index for o in chunk for n in _walk_expr(o) if isinstance(n, Arg)})
            remap = {old: new for new, old in enumerate(used)}
            chunk = tuple(_renumber(o, remap) for o in chunk)
            inputs = tuple(Ty(KINDS[i % len(KINDS)]) for i in used)
            progs.append(Program(mode, inputs, (), chunk, fma=fma, target=target))
    return progs


def _walk_expr(e):
    yield e
    if isinstance(e, Op):
        for a in e.args:
            yield from _walk_expr(a)


def _renumber(e, remap):
    if isinstance(e, Arg):
        return Arg(remap[e.index], e.ty)
    if isinstance(e, Op):
        return Op(e.name, tuple(_renumber(a, remap) for a in e.args), e.ty, e.param)
    return e
