"""A dataflow cost model of a kernel's vector loop (shared/refs/003, "dataflow graphs").

The loop body of a kernel (from block ``vec.body`` of its optimized IR back
to it: :func:`iteration`) is a dataflow graph: each instruction a node, each
operand an edge. Iterations are independent, so an out-of-order core overlaps
them and the steady state is bounded by *throughput*: for every class of
operation, the number of such operations per vector divided by how many the
machine can start per cycle; and by the issue width over all operations.
The *critical path* (the longest latency chain through one iteration) tells
how many iterations must be in flight to reach that bound.

The machine is described by a small table (``ZEN4``; numbers from AMD's Zen 4
optimization guide and uops.info, rounded): each operation class has a latency
in cycles, a throughput in 256-bit operations per cycle and the execution
pipes it can run on. Zen 4 executes a 512-bit operation as two 256-bit halves,
so a zmm operation costs two slots; xmm and scalar operations cost one. The
FP/vector issue width is 4 slots per cycle (four 256-bit FP pipes), loads 2
and stores 1 per cycle (256-bit).

Classes share pipes (the pipe map of AMD's Software Optimization Guide for
Family 19h, pub. 57647, section 2.11.1, as encoded in LLVM's
``X86ScheduleZnver4.td``): FP0/FP1 run multiplies, FMAs, compares, min/max
and reciprocal estimates; FP2/FP3 additions, conversions and roundings; all
four integer ALU ops and logic; FP1/FP2 shifts and shuffles; FP1 the
divider/square root. The throughput bound is therefore the largest, over
every set S of pipes, of (slots of the classes that can only run on S) / |S|
(with an operation that keeps a pipe busy for several cycles counted that
many times): the exact bound of spreading the work over the pipes.
"""
from __future__ import annotations

import collections
import ctypes
import dataclasses
import re

import llvmlite.binding as llvm


@dataclasses.dataclass(frozen=True)
class OpClass:
    latency: float
    per_cycle: float  # 256-bit operations started per cycle (all pipes of the class)
    what: str
    pipes: tuple = ()  # the pipes it can use (empty: a resource of its own)

    @property
    def busy(self) -> float:
        """Cycles one 256-bit operation keeps one of its pipes busy."""
        return len(self.pipes) / self.per_cycle if self.pipes else 1 / self.per_cycle


_FP01, _FP23, _FP12, _FP0123 = ("FP0", "FP1"), ("FP2", "FP3"), ("FP1", "FP2"), ("FP0", "FP1", "FP2", "FP3")
ZEN4 = {
    "fma": OpClass(4, 2, "fused multiply-add (FP0/FP1)", _FP01),
    "fmul": OpClass(3, 2, "multiply (FP0/FP1)", _FP01),
    "fadd": OpClass(3, 2, "add/subtract (FP2/FP3)", _FP23),
    "fminmax": OpClass(2, 2, "compare-select min/max (FP0/FP1)", _FP01),
    "fcmp": OpClass(3, 2, "compare into a mask (FP0/FP1)", _FP01),
    "blend": OpClass(1, 4, "select: masked move, or folded into the producer's mask (any FP pipe)", _FP0123),
    "convert": OpClass(4, 2, "float<->int conversion (FP2/FP3)", _FP23),
    "round": OpClass(3, 2, "floor/ceil/round, VREDUCEPS, VGETEXPPS, VGETMANTPS (FP2/FP3)", _FP23),
    "estimate": OpClass(5, 2, "RCP14 estimate (FP0/FP1)", _FP01),
    "estimate_rsqrt": OpClass(5, 1, "RSQRT14 estimate (FP1)", ("FP1",)),
    "sqrt": OpClass(15, 0.2, "square root (FP1, not pipelined)", ("FP1",)),
    "divide": OpClass(11, 1 / 3, "division (FP1, not pipelined)", ("FP1",)),
    "int": OpClass(1, 4, "integer vector ALU, logic (any FP pipe)", _FP0123),
    "shift": OpClass(1, 2, "vector integer shift (FP1/FP2)", _FP12),
    "shuffle": OpClass(1, 2, "broadcast/shuffle (FP1/FP2)", _FP12),
    "call": OpClass(20, 0.1, "external call (opaque)"),
    "load": OpClass(7, 2, "vector load (L1 hit)", ("LD0", "LD1")),
    "store": OpClass(1, 1, "vector store", ("ST",)),
}
ISSUE_WIDTH = 4  # 256-bit FP/vector slots per cycle
_FREE = {"bitcast", "freeze", "phi", "getelementptr", "br", "icmp", "shl"}
_VECTOR_OPS = {"icmp": "int", "shl": "shift"}  # free on scalars (addressing, loop control), not on vectors

_INTRINSIC_CLASSES = [
    (r"llvm\.fma\.", "fma"), (r"llvm\.fmuladd", "fma"), (r"llvm\.(minnum|maxnum)", "fminmax"),
    (r"llvm\.(smin|smax|umin|umax)", "int"),  # VPMIN/VPMAX: integer ALU, any pipe
    (r"llvm\.(floor|ceil|trunc|roundeven|rint)", "round"),
    (r"x86\.avx512\.mask\.(reduce|getexp|getmant|rndscale)", "round"),
    (r"x86\.avx512\.mask\.scalef", "fma"),  # VSCALEFPS (ScaleF): FP0/FP1, latency ~4, like an FMA
    (r"rsqrt", "estimate_rsqrt"), (r"rcp", "estimate"), (r"llvm\.sqrt", "sqrt"), (r"llvm\.fabs|llvm\.copysign", "int"),
    (r"llvm\.fpto[su]i\.sat", "convert"), (r"llvm\.masked\.load", "load"), (r"llvm\.masked\.store", "store"),
    (r"llvm\.x86\.sse\.(st|ld)mxcsr", None), (r"llvm\.vector\.reduce", "shuffle"),
]
_OPCODE_CLASSES = {
    "fadd": "fadd", "fsub": "fadd", "fneg": "int", "fmul": "fmul", "fdiv": "divide",
    "fcmp": "fcmp", "select": "blend", "fptosi": "convert", "fptoui": "convert", "sitofp": "convert",
    "uitofp": "convert", "add": "int", "sub": "int", "and": "int", "or": "int", "xor": "int",
    "lshr": "shift", "ashr": "shift", "mul": "int", "insertelement": "shuffle",
    "extractelement": "shuffle", "shufflevector": "shuffle", "load": "load", "store": "store",
    "zext": "int", "sext": "int", "trunc": "int",
}


def _vector_bits(type_text: str) -> int:
    m = re.match(r"<(\d+) x (float|i32|i1|i8|double|i64)>", type_text)
    if not m:
        return 32
    bits = {"float": 32, "i32": 32, "i1": 1, "i8": 8, "double": 64, "i64": 64}[m.group(2)]
    return int(m.group(1)) * bits


def classify(instr) -> str | None:
    """The operation class of an instruction (None: free or loop bookkeeping)."""
    op = instr.opcode
    if op == "call":
        callee = list(instr.operands)[-1].name
        for pattern, cls in _INTRINSIC_CLASSES:
            if re.search(pattern, callee):
                return cls
        return "call"
    if op in _VECTOR_OPS and str(instr.type).startswith("<"):
        return _VECTOR_OPS[op]
    if op in _FREE:
        return None
    if op in ("add", "and", "or", "xor") and str(instr.type) == "i64":
        return None  # induction variable
    return _OPCODE_CLASSES.get(op, "int")


def _slots(instr) -> int:
    """256-bit slots an instruction occupies (2 for a 512-bit zmm operation)."""
    type_text = str(instr.type)
    if instr.opcode == "store":
        type_text = str(list(instr.operands)[0].type)
    if instr.opcode == "fcmp":
        type_text = str(list(instr.operands)[0].type)
    return 2 if _vector_bits(type_text) > 256 else 1


@dataclasses.dataclass
class Prediction:
    """What the model says about one vector iteration of a kernel's loop."""

    width: int
    counts: dict[str, int]
    slots: dict[str, int]
    critical_path: float
    throughput_bound: float  # cycles per vector
    bottleneck: str
    skipped: list = dataclasses.field(default_factory=list)  # conditional blocks left out

    @property
    def cycles_per_element(self) -> float:
        return self.throughput_bound / self.width

    def explain(self) -> str:
        ops = ", ".join(f"{n} {c}" for c, n in sorted(self.counts.items(), key=lambda kv: -kv[1]))
        return (f"{sum(self.counts.values())} ops/vector ({ops}); throughput bound "
                f"{self.throughput_bound:.2f} cycles/vector, limited by {self.bottleneck}; "
                f"critical path {self.critical_path:.0f} cycles"
                + (f"; not modelled (conditional): {', '.join(self.skipped)}" if self.skipped else ""))


def _key(value) -> int:
    return ctypes.cast(value._ptr, ctypes.c_void_p).value


def _minmax_selects(instructions) -> dict[int, int]:
    """select(fcmp(a, b), a, b) or select(fcmp(a, b), b, a) is one x86 MIN/MAX:
    maps each such select to its compare (``instructions``: a block or a list)."""
    instructions = list(getattr(instructions, "instructions", instructions))
    defs = {_key(i): i for i in instructions}
    out = {}
    for instr in instructions:
        if instr.opcode != "select":
            continue
        cond, a, b = list(instr.operands)
        cmp = defs.get(_key(cond))
        if cmp is not None and cmp.opcode == "fcmp" and {_key(o) for o in cmp.operands} == {_key(a), _key(b)}:
            out[_key(instr)] = _key(cmp)
    return out


def _successors(block) -> list[str]:
    term = list(block.instructions)[-1]
    return [o.name for o in term.operands if str(o.type) == "label"]


def iteration(fn, start: str = "vec.body") -> tuple[list, list[str]]:
    """(instructions, skipped blocks) of one iteration of the loop at block ``start``.

    A kernel whose body has no ``If`` is one block, ``start``, branching back to
    itself. With ``If`` blocks the iteration runs from ``start`` through
    conditional blocks to a latch that branches back to ``start``; the model
    takes the blocks that *every* iteration runs (those whose removal would cut
    every path back to ``start``), in the function's order, and leaves out the
    conditional ones -- e.g. the trigonometric routines' ``If(Any(|x| >
    limit))`` large-argument reduction, which typical arguments never enter
    (a phi's operand from a skipped block counts as ready)."""
    blocks = {b.name: b for b in fn.blocks}
    if start not in blocks:
        raise ValueError(f"{fn.name} has no vector loop (block {start})")
    succ = {name: _successors(b) for name, b in blocks.items()}

    def back_to_start(avoid: str | None) -> bool:
        seen, todo = set(), [n for n in succ[start] if n != avoid]
        while todo:
            n = todo.pop()
            if n == start:
                return True
            if n in seen:
                continue
            seen.add(n)
            todo += [m for m in succ[n] if m != avoid]
        return False

    inside, todo = set(), list(succ[start])  # blocks reachable from start before returning to it
    while todo:
        n = todo.pop()
        if n == start or n in inside:
            continue
        inside.add(n)
        todo += succ[n]
    if not back_to_start(None):
        raise ValueError(f"{fn.name}: block {start} is not a loop")
    on_path = {n for n in inside if _reaches(succ, n, start)}
    every = {start} | {n for n in on_path if not back_to_start(n)}
    instructions = [i for b in fn.blocks if b.name in every for i in b.instructions]
    skipped = [b.name for b in fn.blocks if b.name in on_path - every]
    return instructions, skipped


def _reaches(succ, a: str, b: str) -> bool:
    seen, todo = set(), [a]
    while todo:
        n = todo.pop()
        if n == b:
            return True
        if n in seen:
            continue
        seen.add(n)
        todo += succ[n]
    return False


def _pipe_bounds(slots, machine) -> dict[str, float]:
    """Cycles per vector forced by each set of pipes (see the module docstring),
    named by the classes confined to it; classes without pipes on their own."""
    bounds = {cls: n / machine[cls].per_cycle for cls, n in slots.items() if not machine[cls].pipes}
    pipes = sorted({p for cls in slots for p in machine[cls].pipes})
    for mask in range(1, 1 << len(pipes)):
        subset = {p for k, p in enumerate(pipes) if mask >> k & 1}
        inside = [cls for cls in slots if machine[cls].pipes and set(machine[cls].pipes) <= subset]
        if not inside:
            continue
        demand = sum(slots[cls] * machine[cls].busy for cls in inside)
        name = "/".join(sorted(subset)) + " (" + ", ".join(sorted(inside)) + ")"
        bounds[name] = demand / len(subset)
    return bounds


def predict(optimized_ir: str, function: str, width: int, machine=ZEN4, issue_width=ISSUE_WIDTH) -> Prediction:
    """Model one iteration of the vector loop (:func:`iteration`: from block ``vec.body``,
    the blocks every iteration runs) of ``function`` in ``optimized_ir``."""
    mod = llvm.parse_assembly(optimized_ir)
    fn = mod.get_function(function)
    body, skipped = iteration(fn)
    counts, slots = collections.Counter(), collections.Counter()
    finish: dict[int, float] = {}
    critical = 0.0
    minmax = _minmax_selects(body)
    folded = set(minmax.values())
    for instr in body:
        cls = classify(instr)
        if _key(instr) in folded:
            cls = None  # the compare of a min/max: part of one VMINPS/VMAXPS
        elif _key(instr) in minmax:
            cls = "fminmax"
        start = max((finish.get(_key(op), 0.0) for op in instr.operands), default=0.0)
        latency = machine[cls].latency if cls else 0.0
        finish[_key(instr)] = start + latency
        critical = max(critical, start + latency)
        if cls:
            counts[cls] += 1
            slots[cls] += _slots(instr)
    fp_slots = sum(n for cls, n in slots.items() if cls not in ("load", "store"))
    bounds = {"issue width": fp_slots / issue_width}  # first: named so on a tie
    bounds.update(_pipe_bounds(slots, machine))
    bottleneck = max(bounds, key=bounds.get)
    return Prediction(width, dict(counts), dict(slots), critical, bounds[bottleneck], bottleneck, skipped)


def predict_kernel(ufunc, machine=ZEN4) -> Prediction:
    """``predict`` for a reactor kernel (its ``<name>.loop`` function)."""
    from reactor import kernel_of
    kern = kernel_of(ufunc)
    return predict(kern.optimized_ir, f"{kern.name}.loop", kern.build.width, machine)


def kernel_cycles(kern, machine=ZEN4) -> float:
    """Cycles per element of a ``reactor.Kernel``'s vector loop: the cost ``reactor.plan`` ranks
    builds by (registered as the entry point ``reactor.kernel_costs``)."""
    return predict(kern.optimized_ir, f"{kern.name}.loop", kern.build.width, machine).cycles_per_element
