"""Value ranges of a traced function by interval arithmetic on its IR (what ``reactor.plan`` proves
each call site's operands lie in, over a whole declared domain).

:func:`analyse` runs forward over the instructions of one function as llvmlite holds them (before
LLVM sees them) and gives each value an :class:`Interval`: the least and greatest non-NaN value any
lane can hold, and whether NaN can come. It is sound, not tight:

* float arithmetic (``fadd`` ... ``fdiv``, ``fma``, ``sqrt``, ``fabs``, min and max, rounding) is
  computed on the ends in float64 and rounded outward to the value's type, so every result of
  round-to-nearest float32 lies inside; NaN is raised where the operands allow it (``inf - inf``,
  ``0 * inf``, ``0 / 0``, a NaN operand);
* a vector's interval is the hull of its lanes;
* ``select`` and ``phi`` join their operands (``select`` takes one side where its condition is
  decided, each side narrowed by the comparison that chooses it); comparisons are decided where the
  intervals do not overlap;
* a value used in a block is narrowed by the comparisons every path to that block took
  (:func:`branch_facts`: a conditional branch's edge, through ``and``, ``or`` and ``not``);
* memory: a load from a local variable (``alloca``, DSL Variables) is the hull of every store to
  it anywhere in the function, so a loop's variables reach a fixed point; where a pass still
  widens a value after :data:`PASSES` passes, it goes to "anything" (widening); a load from any
  other pointer, a bit cast, a call the table does not know and integer arithmetic beyond a few
  operations give "anything" of their type;
* ``summaries`` (from the caller) replace the computed interval of chosen values: ``reactor.plan``
  gives each routine call's result as the routine's mathematical function of its operands'
  intervals, widened by its error, instead of following the routine's bit manipulations.
"""
from __future__ import annotations

import dataclasses
import itertools
import math
import typing

import numpy as np
from llvmlite import ir

from .types import mangle

INF = math.inf
PASSES = 4  # passes before a value that still moves is widened to "anything"


@dataclasses.dataclass(frozen=True)
class Interval:
    """[lo, hi] of the non-NaN values (lo > hi: none), and whether NaN may come."""

    lo: float
    hi: float
    nan: bool = False

    @property
    def empty(self) -> bool:
        return self.lo > self.hi and not self.nan

    def join(self, other: Interval) -> Interval:
        return Interval(min(self.lo, other.lo), max(self.hi, other.hi), self.nan or other.nan)

    def contains(self, lo: float, hi: float, nan: bool) -> bool:
        """Whether values in [lo, hi] (and NaN if ``nan``) all lie inside."""
        return (lo > hi or (self.lo <= lo and hi <= self.hi)) and (self.nan or not nan)

    def has(self, v: float) -> bool:
        return self.lo <= v <= self.hi

    @property
    def finite(self) -> bool:
        return math.isfinite(self.lo) and math.isfinite(self.hi)


ANY = Interval(-INF, INF, True)
NONE = Interval(INF, -INF, False)
BOOL = Interval(0.0, 1.0)
Summary = typing.Callable[["Analysis"], Interval]


# -- rounding outward to a type ----------------------------------------------------------------

def _scalar(t):
    return t.element if isinstance(t, ir.VectorType) else t


def _kind(t) -> str:
    """"f16", "f32", "f64" (LLVM's suffixes), "i" for any integer, "other"."""
    s = _scalar(t)
    if not isinstance(s, (ir.IntType, ir.HalfType, ir.FloatType, ir.DoubleType)):
        return "other"
    suffix = mangle(s)
    return "i" if suffix.startswith("i") else suffix


_NP: dict[str, typing.Any] = {"f32": np.float32, "f16": np.float16, "f64": np.float64}


def _down(x: float, kind: str) -> float:
    """The greatest value of the float type ``kind`` not above the exact x that x rounds."""
    if math.isnan(x) or kind not in _NP:
        return x
    t = _NP[kind]
    with np.errstate(over="ignore"):
        r = t(x)
    if float(r) > x or (float(r) != x and kind == "f64"):
        r = np.nextafter(r, t(-INF))
    elif float(r) != x:  # rounded down already; a tie of the narrower type is also stepped past
        r = np.nextafter(r, t(-INF)) if kind != "f64" and _tie(x, r, t) else r
    return float(r)


def _up(x: float, kind: str) -> float:
    return -_down(-x, kind)


def _tie(x: float, r, t) -> bool:
    up = np.nextafter(r, t(INF))
    return float(up) - x == x - float(r)


def _out(lo: float, hi: float, nan: bool, kind: str) -> Interval:
    """[lo, hi] computed in float64, rounded outward (round-to-nearest results of ``kind`` in
    [lo, hi] exactly lie inside); an overflowing end becomes the infinity it rounds to."""
    if lo > hi:
        return Interval(INF, -INF, nan)
    return Interval(_down(lo, kind), _up(hi, kind), nan)


def anything(t) -> Interval:
    """Every value of type ``t``."""
    kind = _kind(t)
    if kind == "i":
        bits = _scalar(t).width
        return BOOL if bits == 1 else Interval(-float(2 ** (bits - 1)), float(2 ** (bits - 1) - 1))
    return ANY


# -- float arithmetic ----------------------------------------------------------------------------

def _products(a: Interval, b: Interval) -> tuple[float, float, bool]:
    """Ends of a * b over [a.lo, a.hi] x [b.lo, b.hi]; whether 0 * inf can happen."""
    ends = []
    for x in (a.lo, a.hi):
        for y in (b.lo, b.hi):
            p = x * y
            ends.append(0.0 if math.isnan(p) else p)  # 0 * inf: the limit 0 (the NaN is flagged)
    zero_inf = (a.has(0.0) and (math.isinf(b.lo) or math.isinf(b.hi))) or \
               (b.has(0.0) and (math.isinf(a.lo) or math.isinf(a.hi)))
    return min(ends), max(ends), zero_inf


def add(a: Interval, b: Interval, kind: str = "f32") -> Interval:
    if a.lo > a.hi or b.lo > b.hi:
        return Interval(INF, -INF, a.nan or b.nan)
    lo, hi = a.lo + b.lo, a.hi + b.hi
    opposed = (a.hi == INF and b.lo == -INF) or (a.lo == -INF and b.hi == INF)
    lo = -INF if math.isnan(lo) else lo
    hi = INF if math.isnan(hi) else hi
    return _out(lo, hi, a.nan or b.nan or opposed, kind)


def neg(a: Interval) -> Interval:
    return Interval(-a.hi, -a.lo, a.nan)


def mul(a: Interval, b: Interval, kind: str = "f32") -> Interval:
    if a.lo > a.hi or b.lo > b.hi:
        return Interval(INF, -INF, a.nan or b.nan)
    lo, hi, zero_inf = _products(a, b)
    return _out(lo, hi, a.nan or b.nan or zero_inf, kind)


def div(a: Interval, b: Interval, kind: str = "f32") -> Interval:
    if a.lo > a.hi or b.lo > b.hi:
        return Interval(INF, -INF, a.nan or b.nan)
    both_inf = not a.finite and not b.finite  # inf / inf
    nan = a.nan or b.nan or both_inf
    if b.has(0.0):  # x / 0 is an infinity of either sign (zeros carry a sign we do not follow)
        return Interval(-INF, INF, nan or a.has(0.0))
    ends = [x / y for x in (a.lo, a.hi) for y in (b.lo, b.hi)]
    ends = [e for e in ends if not math.isnan(e)] or [0.0]
    return _out(min(ends), max(ends), nan, kind)


def square(a: Interval, kind: str = "f32") -> Interval:
    """a * a (one value times itself: never negative)."""
    m = fabs(a)
    if m.lo > m.hi:
        return m
    return _out(m.lo * m.lo, m.hi * m.hi, a.nan, kind)


def fma(a: Interval, b: Interval, c: Interval, kind: str = "f32", same: bool = False) -> Interval:
    """a * b + c rounded once (``same``: b is a itself): the exact product's range, then the sum,
    rounded outward once."""
    if min(a.lo - a.hi, b.lo - b.hi, c.lo - c.hi) > 0:
        return Interval(INF, -INF, a.nan or b.nan or c.nan)
    if same:
        m = fabs(a)
        return add(Interval(m.lo * m.lo, m.hi * m.hi, a.nan), c, kind)
    lo, hi, zero_inf = _products(a, b)
    return add(Interval(lo, hi, a.nan or b.nan or zero_inf), c, kind)


def sqrt(a: Interval, kind: str = "f32") -> Interval:
    nan = a.nan or a.lo < 0
    lo, hi = max(a.lo, 0.0), a.hi
    if hi < 0:
        return Interval(INF, -INF, True)
    return _out(math.sqrt(lo), math.sqrt(hi), nan, kind)


def fabs(a: Interval) -> Interval:
    if a.lo > a.hi:
        return a
    if a.lo >= 0:
        return a
    if a.hi <= 0:
        return neg(a)
    return Interval(0.0, max(-a.lo, a.hi), a.nan)


def minimum(a: Interval, b: Interval, ignore_nan: bool) -> Interval:
    """min(a, b); ``ignore_nan``: the other operand where one is NaN (minnum)."""
    return _minmax(a, b, ignore_nan, min)


def maximum(a: Interval, b: Interval, ignore_nan: bool) -> Interval:
    return _minmax(a, b, ignore_nan, max)


def _minmax(a: Interval, b: Interval, ignore_nan: bool, pick) -> Interval:
    if a.lo > a.hi or b.lo > b.hi:
        joined = a.join(b)
        return Interval(joined.lo, joined.hi, a.nan and b.nan if ignore_nan else a.nan or b.nan)
    lo, hi = pick(a.lo, b.lo), pick(a.hi, b.hi)
    if ignore_nan:  # a NaN operand gives the other one: its whole range
        if a.nan:
            lo, hi = min(lo, b.lo), max(hi, b.hi)
        if b.nan:
            lo, hi = min(lo, a.lo), max(hi, a.hi)
        return Interval(lo, hi, a.nan and b.nan)
    return Interval(lo, hi, a.nan or b.nan)


def rounded(a: Interval, name: str) -> Interval:
    """``math.floor``, ``ceil`` or ``trunc`` (``name``) of a: monotone, exact on the ends."""
    if a.lo > a.hi:
        return a
    fn = getattr(math, name)
    return Interval(float(fn(a.lo)) if math.isfinite(a.lo) else a.lo,
                    float(fn(a.hi)) if math.isfinite(a.hi) else a.hi, a.nan)


def compare(pred: str, a: Interval, b: Interval, ordered: bool) -> Interval:
    """An fcmp: decided (0 or 1) where the intervals settle it, else either."""
    nan = a.nan or b.nan
    if a.lo > a.hi or b.lo > b.hi:
        return Interval(0.0, 0.0) if not ordered or not nan else BOOL
    truth = _decided(pred, a, b)
    if nan:  # an unordered pair: false for ordered predicates, true for unordered ones
        nan_truth = 0.0 if ordered else 1.0
        if truth is None or truth != nan_truth:
            return BOOL
    return BOOL if truth is None else Interval(truth, truth)


def _decided(pred: str, a: Interval, b: Interval) -> float | None:
    if pred in ("<", "<="):
        if (a.hi < b.lo) or (pred == "<=" and a.hi <= b.lo):
            return 1.0
        if (a.lo > b.hi) or (pred == "<" and a.lo >= b.hi):
            return 0.0
    elif pred in (">", ">="):
        return _decided("<" if pred == ">" else "<=", b, a)
    elif pred == "==":
        if a.hi < b.lo or b.hi < a.lo:
            return 0.0
        if a.lo == a.hi == b.lo == b.hi:
            return 1.0
    elif pred == "!=":
        eq = _decided("==", a, b)
        return None if eq is None else 1.0 - eq
    return None


# -- the analysis ------------------------------------------------------------------------------

class Analysis:
    """Intervals of one function's values (see the module docstring)."""

    def __init__(self, function, params: dict[int, Interval], summaries: dict[int, Summary] | None = None):
        self.function = function
        self.values: dict[int, Interval] = {}
        self.params = params
        self.summaries = summaries or {}
        self.stored: dict[int, Interval] = {}  # alloca -> hull of what is stored to it
        self.escaped: set[int] = set()
        self.roots: dict[int, int] = {}  # pointer derived from an alloca -> that alloca
        self.keep: list = []  # the IR objects whose ids are keys, kept alive
        self.passes = 0
        self.moved = False  # whether a store grew an alloca's hull in this pass
        self.block = None  # the block of the instruction being evaluated
        self.facts: dict[int, tuple] = {}  # block -> (fcmp, truth) its paths all took (branch_facts)

    def of(self, v) -> Interval:
        """The interval of the IR value ``v`` (an instruction, argument or constant) in the block
        being evaluated (``block``): narrowed by the branch conditions every path to it took."""
        found = self.raw(v)
        for cond, truth in self.facts.get(id(self.block), ()):
            found = narrowed(self, found, cond, v, truth)
        return found

    def at(self, v, block) -> Interval:
        """The interval of ``v`` where ``block`` runs."""
        outer, self.block = self.block, block
        try:
            return self.of(v)
        finally:
            self.block = outer

    def raw(self, v) -> Interval:
        """The interval of ``v`` anywhere in the function."""
        if isinstance(v, ir.Constant):
            return _constant(v)
        if isinstance(v, ir.Argument):
            return self.params.get(self.function.args.index(v), anything(v.type))
        if isinstance(v, (ir.Instruction, ir.Value)) and id(v) in self.values:
            return self.values[id(v)]
        if isinstance(v, ir.Instruction):
            return NONE  # not reached yet (a loop's back edge): joined in a later pass
        return anything(v.type)

    def run(self) -> Analysis:
        instructions = [i for b in self.function.blocks for i in b.instructions]
        self.keep = instructions
        self._memory(instructions)
        self.facts = branch_facts(self.function)
        for n in itertools.count():  # ends: past PASSES a value or store changes once more at most
            self.passes, self.moved = n, False
            changed = False
            for inst in instructions:
                self.block = inst.parent
                new = self._eval(inst)
                if new is None:
                    continue
                key = id(inst)
                old = self.values.get(key)
                if old is not None:
                    new = old.join(new)
                    if new == old:
                        continue
                    if n >= PASSES:
                        new = anything(inst.type)  # still moving: widened
                self.values[key] = new
                changed = True
            self.block = None
            if not changed and not self.moved:
                return self
        raise AssertionError("unreachable")

    # -- memory ----------------------------------------------------------------------------
    def _memory(self, instructions) -> None:
        """Which pointers come from which alloca, and which allocas escape (their loads: anything)."""
        for inst in instructions:
            if inst.opname == "alloca":
                self.roots[id(inst)] = id(inst)
                self.stored[id(inst)] = NONE
        for inst in instructions:
            if inst.opname in ("getelementptr", "bitcast") and id(inst.operands[0]) in self.roots:
                self.roots[id(inst)] = self.roots[id(inst.operands[0])]
        for inst in instructions:
            for k, op in enumerate(inst.operands):
                root = self.roots.get(id(op))
                if root is None:
                    continue
                if inst.opname == "load" or (inst.opname == "store" and k == 1) or \
                        (inst.opname in ("getelementptr", "bitcast") and k == 0):
                    continue
                self.escaped.add(root)

    def _store(self, inst) -> bool:
        """Join the stored value into its alloca's hull: whether that grew."""
        root = self.roots.get(id(inst.operands[1]))
        if root is None or root in self.escaped:
            return False
        old = self.stored[root]
        new = old.join(self.of(inst.operands[0]))
        if new == old:
            return False
        self.stored[root] = new if self.passes < PASSES else anything(inst.operands[0].type)
        return True

    def _load(self, inst) -> Interval:
        root = self.roots.get(id(inst.operands[0]))
        if root is None or root in self.escaped:
            return anything(inst.type)
        got = self.stored[root]
        return got if not _is_aggregate(inst.type) else anything(inst.type)

    # -- one instruction -------------------------------------------------------------------
    def _eval(self, inst) -> Interval | None:
        op = inst.opname
        if op == "store":
            self.moved = self._store(inst) or self.moved
            return None
        if op in ("br", "ret", "switch", "unreachable", "alloca", "getelementptr") or \
                isinstance(inst.type, ir.VoidType):
            return None
        summary = self.summaries.get(id(inst))
        if summary is not None:
            return summary(self)
        if _is_aggregate(inst.type) or isinstance(inst.type, ir.PointerType):
            return None if isinstance(inst.type, ir.PointerType) else anything(inst.type)
        rule = _RULES.get(op)
        return rule(self, inst) if rule is not None else anything(inst.type)


def branch_facts(function) -> dict[int, tuple]:
    """Per block (by id): the fcmp conditions, with their truth, that every path from the entry
    to it took (a conditional branch's edge gives its condition, through ``and``/``or``/``not``;
    a block joins what all its predecessors' paths share)."""
    blocks = function.blocks
    edges: dict[int, list] = {id(b): [] for b in blocks}  # block -> [(predecessor, facts of the edge)]
    for b in blocks:
        term = b.instructions[-1] if b.instructions else None
        if term is None or term.opname != "br":  # ret, unreachable; a switch's edges say nothing
            targets = [] if term is None or term.opname != "switch" else \
                [term.default] + [target for _, target in term.cases]
            for target in targets:
                edges[id(target)].append((b, ()))
            continue
        if len(term.operands) == 1:
            edges[id(term.operands[0])].append((b, ()))
            continue
        cond, yes, no = term.operands
        if yes is no:
            edges[id(yes)].append((b, ()))
            continue
        edges[id(yes)].append((b, tuple(_conditions(cond, True))))
        edges[id(no)].append((b, tuple(_conditions(cond, False))))
    known: dict[int, dict | None] = {id(b): None for b in blocks}  # None: not reached yet (every fact)
    known[id(blocks[0])] = {}
    changed = True
    while changed:
        changed = False
        for b in blocks[1:]:
            shared: dict | None = None
            for pred, facts in edges[id(b)]:
                before = known[id(pred)]
                if before is None:
                    continue
                here = {**before, **{(id(c), t): (c, t) for c, t in facts}}
                shared = here if shared is None else {k: v for k, v in shared.items() if k in here}
            before_b = known[id(b)]
            if shared is not None and (before_b is None or shared.keys() != before_b.keys()):
                known[id(b)] = shared
                changed = True
    return {k: tuple(v.values()) for k, v in known.items() if v}


def _conditions(cond, truth: bool) -> list:
    """The (fcmp, truth) pairs that ``cond`` being ``truth`` implies."""
    op = getattr(cond, "opname", None)
    if op == "fcmp":
        return [(cond, truth)]
    if op in ("and", "or") and isinstance(cond.type, ir.IntType) and cond.type.width == 1:
        if (op == "and") == truth:  # both sides hold (and true) or both fail (or false)
            return _conditions(cond.operands[0], truth) + _conditions(cond.operands[1], truth)
        return []
    if op == "xor" and isinstance(cond.type, ir.IntType) and cond.type.width == 1:
        for k in (0, 1):
            c = cond.operands[1 - k]
            if isinstance(c, ir.Constant) and c.constant in (1, True, -1):
                return _conditions(cond.operands[k], not truth)
    if op == "select" and isinstance(cond.type, ir.IntType) and cond.type.width == 1:
        test, yes, no = cond.operands
        if truth and isinstance(no, ir.Constant) and no.constant in (0, False):  # test && yes
            return _conditions(test, True) + _conditions(yes, True)
        if not truth and isinstance(yes, ir.Constant) and yes.constant in (1, True, -1):  # test || no
            return _conditions(test, False) + _conditions(no, False)
    return []


def _is_aggregate(t) -> bool:
    return isinstance(t, (ir.LiteralStructType, ir.ArrayType))


def _constant(c) -> Interval:
    v = c.constant
    if isinstance(v, (list, tuple)):
        parts = [_constant(x) if isinstance(x, ir.Constant) else _number(x, c.type) for x in v]
        out = NONE
        for p in parts:
            out = out.join(p)
        return out
    return _number(v, c.type)


def _number(v, t) -> Interval:
    if v is ir.Undefined:  # a vector's lanes before they are set (the DSL builds vectors lane by
        return NONE        # lane into undef and never reads an unset lane)
    if v is None:  # zeroinitializer
        v = 0
    if isinstance(v, bool):
        return Interval(float(v), float(v))
    if isinstance(v, (int, float)):
        x = float(v)
        if math.isnan(x):
            return Interval(INF, -INF, True)
        if _kind(t) == "i" and _scalar(t).width == 1:
            return Interval(float(bool(v)), float(bool(v)))
        if _kind(t) == "i":  # signless: both readings (signed below, unsigned above) are kept
            bits = _scalar(t).width
            signed = x - 2 ** bits if x >= 2 ** (bits - 1) else x
            return Interval(signed, signed)
        kind = _kind(t)
        if kind in _NP:  # llvmlite keeps the Python number; the constant is its nearest of the type
            with np.errstate(over="ignore"):
                x = float(_NP[kind](x))
        return Interval(x, x)
    return anything(t)


# -- the rules, per opcode -------------------------------------------------------------------------

def _k(inst) -> str:
    return _kind(inst.type)


def _binary(fn):
    return lambda a, inst: fn(a.of(inst.operands[0]), a.of(inst.operands[1]), _k(inst))


def _select(a: Analysis, inst) -> Interval:
    """The chosen side where the condition is decided, else the join of both; a side that is an
    operand of the fcmp deciding it is narrowed by what the choice says of it (``Min(v, 1.0)``,
    ``v < 1 ? v : 1``, is at most 1)."""
    cond_value = inst.operands[0]
    cond = a.of(cond_value)
    yes = _given(a, cond_value, inst.operands[1], True)
    no = _given(a, cond_value, inst.operands[2], False)
    if cond.lo == cond.hi == 1.0:
        return yes
    if cond.lo == cond.hi == 0.0:
        return no
    return yes.join(no)


_NEGATED = {"<": ">=", "<=": ">", ">": "<=", ">=": "<", "==": "!=", "!=": "=="}


def _given(a: Analysis, cond, value, truth: bool) -> Interval:
    """The interval of ``value`` where the fcmp ``cond`` is ``truth`` (where ``value`` is one
    of its operands; else its interval)."""
    return narrowed(a, a.of(value), cond, value, truth)


def narrowed(a: Analysis, v: Interval, cond, value, truth: bool) -> Interval:
    """``v``, the interval of ``value``, narrowed by the fcmp ``cond`` being ``truth`` (``v``
    where ``value`` is not one of its operands). The other operand's interval is taken as the
    analysis has it, unnarrowed."""
    if getattr(cond, "opname", None) != "fcmp" or not any(value is x for x in cond.operands[:2]):
        return v
    pred = _PREDICATES.get(cond.op[1:])
    if pred is None or cond.op[0] not in "ou" or v.lo > v.hi:
        return v
    p, q = cond.operands[0], cond.operands[1]
    ordered = cond.op[0] == "o"
    relation, nan_allowed = (pred, not ordered) if truth else (_NEGATED[pred], ordered)
    if value is q:  # the relation read from q's side
        relation = {"<": ">", "<=": ">=", ">": "<", ">=": "<="}.get(relation, relation)
    other = a.raw(p if value is q else q)
    if nan_allowed and other.nan:
        return v  # an unordered pair takes this side whatever value holds
    lo, hi = v.lo, v.hi
    if relation in ("<", "<="):
        hi = min(hi, other.hi)
    elif relation in (">", ">="):
        lo = max(lo, other.lo)
    elif relation == "==":
        lo, hi = max(lo, other.lo), min(hi, other.hi)
    return Interval(lo, hi, v.nan and nan_allowed)


def _phi(a: Analysis, inst) -> Interval:
    out = NONE
    for value, _ in inst.incomings:
        out = out.join(a.of(value))
    return out


_PREDICATES = {"lt": "<", "le": "<=", "gt": ">", "ge": ">=", "eq": "==", "ne": "!="}


def _fcmp(a: Analysis, inst) -> Interval:
    """``olt`` ... ``une``: decided where the operands' intervals settle it."""
    pred = _PREDICATES.get(inst.op[1:])
    if pred is None or inst.op[0] not in "ou":  # ord, uno, true, false
        return BOOL
    return compare(pred, a.of(inst.operands[0]), a.of(inst.operands[1]), inst.op[0] == "o")


def _icmp(a: Analysis, inst) -> Interval:
    """``eq``, ``ne`` and the signed orders are decided where the intervals settle them (intervals
    of integers are their signed reading); unsigned orders are not followed."""
    pred = _PREDICATES.get(inst.op if inst.op in ("eq", "ne") else inst.op[1:])
    if pred is None or inst.op[0] == "u":
        return BOOL
    return compare(pred, a.of(inst.operands[0]), a.of(inst.operands[1]), True)


def _cast(a: Analysis, inst) -> Interval:
    op, src = inst.opname, a.of(inst.operands[0])
    if op in ("sitofp", "uitofp"):
        bits = _scalar(inst.operands[0].type).width
        if op == "uitofp" and (src.lo < 0 or bits == 1):
            src = Interval(0.0, float(2 ** bits - 1)) if bits > 1 else BOOL
        return _out(src.lo, src.hi, False, _k(inst))
    if op in ("fpext",):
        return src
    if op == "fptrunc":
        return _out(src.lo, src.hi, src.nan, _k(inst))
    if op in ("fptosi", "fptoui"):
        return anything(inst.type)  # out-of-range and NaN inputs give poison: not followed
    if op == "zext":
        bits = _scalar(inst.operands[0].type).width
        if src.lo >= 0:
            return src
        return Interval(0.0, float(2 ** bits - 1)) if bits > 1 else BOOL
    if op == "sext":
        if _scalar(inst.operands[0].type).width == 1:
            return Interval(-src.hi, -src.lo)
        return src
    if op == "bitcast" and _kind(inst.type) == _kind(inst.operands[0].type) != "i":
        return src
    return anything(inst.type)


def _lanes(a: Analysis, inst) -> Interval:
    """insertelement, shufflevector: the hull of what goes in; extractelement: the vector's."""
    op = inst.opname
    if op == "extractelement":
        return a.of(inst.operands[0])
    if op == "insertelement":
        return a.of(inst.operands[0]).join(a.of(inst.operands[1]))
    return a.of(inst.operands[0]).join(a.of(inst.operands[1]))


def _bool_logic(a: Analysis, inst) -> Interval:
    if _kind(inst.type) != "i" or _scalar(inst.type).width != 1:
        return anything(inst.type)
    x, y = a.of(inst.operands[0]), a.of(inst.operands[1])
    op = inst.opname
    if op == "and":
        if x.hi == 0.0 or y.hi == 0.0:
            return Interval(0.0, 0.0)
        if x.lo == 1.0 and y.lo == 1.0:
            return Interval(1.0, 1.0)
    elif op == "or":
        if x.lo == 1.0 or y.lo == 1.0:
            return Interval(1.0, 1.0)
        if x.hi == 0.0 and y.hi == 0.0:
            return Interval(0.0, 0.0)
    return BOOL


def _int_arith(a: Analysis, inst) -> Interval:
    if _kind(inst.type) != "i":
        return anything(inst.type)
    x, y = a.of(inst.operands[0]), a.of(inst.operands[1])
    top = anything(inst.type)
    if x.lo > x.hi or y.lo > y.hi:
        return Interval(INF, -INF)
    ends = {"add": (x.lo + y.lo, x.hi + y.hi), "sub": (x.lo - y.hi, x.hi - y.lo)}.get(inst.opname)
    if ends is None:
        p = [x.lo * y.lo, x.lo * y.hi, x.hi * y.lo, x.hi * y.hi]
        ends = (min(p), max(p))
    if ends[0] < top.lo or ends[1] > top.hi:  # it may wrap
        return top
    return Interval(*ends)


def _call(a: Analysis, inst) -> Interval:
    name = getattr(inst.callee, "name", "")
    args = [a.of(x) for x in inst.args]
    kind = _k(inst)
    base = name.split(".")[1] if name.startswith("llvm.") and name.count(".") >= 1 else ""
    if base in ("fma", "fmuladd") and len(args) == 3:
        return fma(args[0], args[1], args[2], kind, same=inst.args[0] is inst.args[1])
    if base == "sqrt":
        return sqrt(args[0], kind)
    if base == "fabs":
        return fabs(args[0])
    if base in ("minnum", "maxnum", "minimum", "maximum"):
        pick = minimum if base.startswith("min") else maximum
        return pick(args[0], args[1], base.endswith("num"))
    if base in ("floor", "ceil", "trunc"):
        return rounded(args[0], base)
    if base in ("roundeven", "rint", "nearbyint", "round"):  # to a neighbour: one of floor, ceil
        r = args[0]
        return r if r.lo > r.hi else Interval(rounded(r, "floor").lo, rounded(r, "ceil").hi, r.nan)
    if base == "copysign":
        m = fabs(args[0])
        return Interval(-m.hi, m.hi, m.nan) if not m.empty else m
    return anything(inst.type)


_RULES: dict[str, typing.Callable[[Analysis, typing.Any], Interval]] = {
    "fadd": _binary(add),
    "fsub": _binary(lambda x, y, k: add(x, neg(y), k)),
    "fmul": lambda a, inst: square(a.of(inst.operands[0]), _k(inst)) if inst.operands[0] is inst.operands[1]
    else mul(a.of(inst.operands[0]), a.of(inst.operands[1]), _k(inst)),
    "fdiv": _binary(div),
    "fneg": lambda a, inst: neg(a.of(inst.operands[0])),
    "select": _select,
    "phi": _phi,
    "fcmp": _fcmp,
    "icmp": _icmp,
    "sitofp": _cast, "uitofp": _cast, "fpext": _cast, "fptrunc": _cast, "fptosi": _cast,
    "fptoui": _cast, "zext": _cast, "sext": _cast, "bitcast": _cast, "trunc": lambda a, i: anything(i.type),
    "extractelement": _lanes, "insertelement": _lanes, "shufflevector": _lanes,
    "and": _bool_logic, "or": _bool_logic,
    "add": _int_arith, "sub": _int_arith, "mul": _int_arith,
    "call": _call,
    "load": lambda a, inst: a._load(inst),
}


def analyse(function, params: dict[int, Interval], summaries: dict[int, Summary] | None = None) -> Analysis:
    """The intervals of ``function``'s values (``Analysis.of``) when its argument k lies in
    ``params[k]`` (others: anything); ``summaries``: value id -> the interval of that value,
    computed from the analysis so far (a routine's result from its operands)."""
    return Analysis(function, params, summaries).run()
