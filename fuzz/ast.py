"""The fuzzer's program representation: a small typed AST of dataclasses.

A ``Program`` is emitted as DSL code (``emit.py``) and evaluated independently
with NumPy (``evaluate.py``); the runner compares the two lane by lane.

Types are ``Ty(kind, scalar)``: ``scalar=False`` is a vector at the build's
width (``SIMD.Float``), ``scalar=True`` one element (``Float``); at width 1 they
coincide. ``repr(program)`` is valid Python over this module's names (plus
``nan`` and ``inf``), which is how regression tests store programs.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

KINDS = ("Float", "Double", "Int", "UInt", "Bool")
FLOATS = frozenset({"Float", "Double"})
INTS = frozenset({"Int", "UInt"})
NUMS = FLOATS | INTS
DTYPES = {"Float": np.dtype(np.float32), "Double": np.dtype(np.float64), "Int": np.dtype(np.int32),
          "UInt": np.dtype(np.uint32), "Bool": np.dtype(np.bool_)}


@dataclass(frozen=True)
class Ty:
    kind: str
    scalar: bool = False

    @property
    def dtype(self) -> np.dtype:
        return DTYPES[self.kind]

    def vector(self) -> "Ty":
        return Ty(self.kind, False)


# -- expressions -----------------------------------------------------------------

@dataclass(frozen=True)
class Arg:
    """Program input ``index`` (a vector)."""
    index: int
    ty: Ty


@dataclass(frozen=True)
class Ref:
    """A Let value, Variable or loop counter by name."""
    name: str
    ty: Ty


@dataclass(frozen=True)
class Const:
    """A constant; ``literal`` emits a bare Python number (broadcast against the other operand)."""
    value: object
    ty: Ty
    literal: bool = False


@dataclass(frozen=True)
class Lanes:
    """A per-lane constant ``T(v0, ..., v{W-1})`` (16 values; the first W are used)."""
    values: tuple
    ty: Ty


@dataclass(frozen=True)
class Op:
    """Operation ``name`` of ``fuzz.ops.OPS`` on ``args``; ``param`` e.g. a target kind or lane."""
    name: str
    args: tuple
    ty: Ty
    param: object = None


# -- statements ------------------------------------------------------------------

@dataclass(frozen=True)
class Let:
    name: str
    expr: object


@dataclass(frozen=True)
class Var:
    """``name = Variable(T, init)``."""
    name: str
    ty: Ty
    init: object


@dataclass(frozen=True)
class Set:
    name: str
    expr: object


@dataclass(frozen=True)
class If:
    cond: object
    then: tuple
    elifs: tuple = ()  # ((cond, body), ...)
    orelse: tuple | None = None


@dataclass(frozen=True)
class For:
    """``with For(start, stop, step) as name`` (counter kind Int or UInt)."""
    name: str
    start: object
    stop: object
    step: int
    body: tuple


@dataclass(frozen=True)
class While:
    """``counter = Variable(Int, 0); with While(lambda: (counter < bound) & extra): body; counter += 1``."""
    counter: str
    bound: object
    extra: object
    body: tuple


@dataclass(frozen=True)
class Return:
    """Early return (function mode): store the outputs as they are now, and leave."""


@dataclass(frozen=True)
class Program:
    """``mode`` "function": a DSL function called once per vector (control flow on scalar
    conditions, cross-lane operations, early returns). ``mode`` "kernel": a @kernel body
    (lane-wise; only uniform conditions). ``outputs`` are vector expressions over the
    inputs and the top-level variables."""
    mode: str
    inputs: tuple
    body: tuple
    outputs: tuple
    fma: bool = False
    opt: int = 3
    target: str = "host"


NAMESPACE = {c.__name__: c for c in (Ty, Arg, Ref, Const, Lanes, Op, Let, Var, Set, If, For, While,
                                     Return, Program)}
NAMESPACE.update(nan=math.nan, inf=math.inf)


def parse(text: str) -> Program:
    """The Program whose ``repr`` is ``text``."""
    return eval(text, {"__builtins__": {}}, dict(NAMESPACE))  # noqa: S307 - our own reprs


# -- statistics and printing -------------------------------------------------------

def walk(node):
    """Every expression and statement node under ``node`` (a Program, statement or expression)."""
    yield node
    if isinstance(node, Program):
        children = list(node.body) + list(node.outputs)
    elif isinstance(node, (Let, Set)):
        children = [node.expr]
    elif isinstance(node, Var):
        children = [node.init]
    elif isinstance(node, If):
        children = [node.cond, *node.then] + [x for c, b in node.elifs for x in (c, *b)] + list(node.orelse or ())
    elif isinstance(node, For):
        children = [node.start, node.stop, *node.body]
    elif isinstance(node, While):
        children = [node.bound] + ([node.extra] if node.extra is not None else []) + list(node.body)
    elif isinstance(node, Op):
        children = list(node.args)
    else:
        children = []
    for child in children:
        yield from walk(child)


def op_names(program: Program) -> set[str]:
    return {n.name for n in walk(program) if isinstance(n, Op)} | {
        type(n).__name__ for n in walk(program) if isinstance(n, (If, For, While, Return))}


def _tyname(ty: Ty) -> str:
    return ty.kind if ty.scalar else f"SIMD.{ty.kind}"


def expr_source(e) -> str:
    """Readable DSL-like text for an expression (for reports; not executed)."""
    if isinstance(e, Arg):
        return f"x{e.index}"
    if isinstance(e, Ref):
        return e.name
    if isinstance(e, Const):
        return repr(e.value) if e.literal else f"{_tyname(e.ty)}({e.value!r})"
    if isinstance(e, Lanes):
        return f"{_tyname(e.ty)}(*{list(e.values)!r}[:W])"
    a = [expr_source(x) for x in e.args]
    sym = {"add": "+", "sub": "-", "mul": "*", "div": "/", "rem": "%", "and": "&", "or": "|", "xor": "^",
           "shl": "<<", "shr": ">>", "lt": "<", "le": "<=", "gt": ">", "ge": ">=", "eq": "==", "ne": "!="}
    if e.name in sym:
        return f"({a[0]} {sym[e.name]} {a[1]})"
    if e.name == "neg":
        return f"(-{a[0]})"
    if e.name == "invert":
        return f"(~{a[0]})"
    param = "" if e.param is None else f"[{e.param!r}]"
    return f"{e.name}{param}({', '.join(a)})"


def source(program: Program) -> str:
    """Readable DSL-like text of a whole program (for mismatch reports)."""
    lines = [f"# mode={program.mode} fma={program.fma} opt={program.opt} target={program.target}",
             f"def prog({', '.join(f'x{k}: {_tyname(t)}' for k, t in enumerate(program.inputs))}):"]

    def block(stmts, ind):
        if not stmts:
            lines.append("    " * ind + "pass")
        for s in stmts:
            pad = "    " * ind
            if isinstance(s, Let):
                lines.append(f"{pad}{s.name} = {expr_source(s.expr)}")
            elif isinstance(s, Var):
                lines.append(f"{pad}{s.name} = Variable({_tyname(s.ty)}, {expr_source(s.init)})")
            elif isinstance(s, Set):
                lines.append(f"{pad}{s.name}.set({expr_source(s.expr)})")
            elif isinstance(s, If):
                lines.append(f"{pad}with If({expr_source(s.cond)}):")
                block(s.then, ind + 1)
                for c, b in s.elifs:
                    lines.append(f"{pad}with Elif({expr_source(c)}):")
                    block(b, ind + 1)
                if s.orelse is not None:
                    lines.append(f"{pad}with Else():")
                    block(s.orelse, ind + 1)
            elif isinstance(s, For):
                lines.append(f"{pad}with For({expr_source(s.start)}, {expr_source(s.stop)}, {s.step}) as {s.name}:")
                block(s.body, ind + 1)
            elif isinstance(s, While):
                extra = "" if s.extra is None else f" & {expr_source(s.extra)}"
                lines.append(f"{pad}{s.counter} = Variable(Int, 0)")
                lines.append(f"{pad}with While(lambda: ({s.counter} < {expr_source(s.bound)}){extra}):")
                block(s.body, ind + 1)
                lines.append(f"{pad}    {s.counter} += 1")
            elif isinstance(s, Return):
                lines.append(f"{pad}return_outputs()")

    block(program.body, 1)
    lines.append(f"    return ({', '.join(expr_source(o) for o in program.outputs)})")
    return "\n".join(lines)


def size(program: Program) -> int:
    return sum(1 for _ in walk(program))


__all__ = [n for n in NAMESPACE if n[0].isupper()] + ["parse", "source", "walk", "op_names", "size",
                                                      "KINDS", "FLOATS", "INTS", "NUMS", "DTYPES"]

