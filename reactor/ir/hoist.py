"""Uniform work out of a kernel's vector loop, as a GPU driver does it once per draw.

A kernel's vector body is traced once, for any mix of array and broadcast operands. After
tracing, ``split`` sorts its side-effect-free instructions by the kernel inputs they depend on
(their *group*: ``t * 0.3`` and ``cos`` of it depend on ``t`` alone). Every group that does not
depend on all the inputs moves to a function of its own, ``<body>.pre<k>``, which computes the
group and stores the values that other instructions read into a slot structure; the body reads
them from the slots instead. The loop then calls each group's function once before the vector
loop when every input of the group is broadcast in this call (stride 0), and at the top of each
iteration otherwise. Inlined, the slots become registers (SROA), so a call with every operand an
array runs the same instructions as before, and ``x * cos(t * 0.3)`` with a scalar ``t`` computes
the cosine once per call.

What moves: arithmetic, comparisons, selects, conversions, lane shuffles and LLVM's intrinsics
without memory effects, whose operands are constants, inputs or moved values. Loads, stores,
calls of other functions, phis, integer division (undefined for a zero divisor, which the moved
code would compute unconditionally) and anything on pointers stay in the body.
"""
from __future__ import annotations

import copy as _copy
import dataclasses

from llvmlite import ir

from . import emitter as _em

#: Instructions with no effect but their result, defined for every operand value.
PURE = frozenset({
    "fadd", "fsub", "fmul", "fdiv", "frem", "fneg", "add", "sub", "mul", "shl", "lshr", "ashr", "and", "or", "xor",
    "icmp", "fcmp", "select", "trunc", "zext", "sext", "fptrunc", "fpext", "fptoui", "fptosi", "uitofp", "sitofp",
    "bitcast", "extractelement", "insertelement", "shufflevector", "extractvalue", "insertvalue", "freeze",
})
#: Words naming LLVM intrinsics that touch memory or machine state (they stay in the body).
IMPURE_INTRINSIC = ("masked", "gather", "scatter", "mem", "csr", "prefetch", "lifetime", "assume", "experimental",
                    "invariant", "rdtsc", "trap", "stack", "load", "store", "va_")


@dataclasses.dataclass
class Group:
    """The moved instructions that depend on exactly these kernel ``inputs`` (indices), and the
    function computing them: the body's parameters, its slots last; returns nothing."""

    inputs: frozenset
    function: ir.Function


@dataclasses.dataclass
class Hoisted:
    """A body's uniform work: its groups, smallest first (a group reads the slots of groups of
    fewer inputs, so they run first), and the slot structure (an LLVM type) they fill."""

    groups: list[Group]
    slots: ir.LiteralStructType
    #: the body's instructions that only computed the groups (left, unused, to dead-code elimination)
    dead: int = 0


def _operands(instruction) -> list:
    if isinstance(instruction, ir.PhiInstr):
        return [value for value, _ in instruction.incomings]
    return list(instruction.operands)


def _replace(instruction, old, new) -> None:
    """``instruction`` reads ``new`` where it read ``old`` (llvmlite's insertvalue and extractvalue
    print fields of their own beside their operands)."""
    instruction.replace_usage(old, new)
    for field in ("aggregate", "value"):
        if isinstance(instruction, (ir.InsertValue, ir.ExtractValue)) and getattr(instruction, field, None) is old:
            setattr(instruction, field, new)
            instruction._clear_string_cache()


def _distinct(values: list) -> list:
    """``values`` without repeats (by identity: LLVM constants compare by value)."""
    return list({id(v): v for v in values}.values())


def _is_pointer(t) -> bool:
    return isinstance(t, ir.PointerType) or (isinstance(t, ir.VectorType) and isinstance(t.element, ir.PointerType))


def _movable(instruction) -> bool:
    """Whether ``instruction`` has no effect but its result and is defined for every operand."""
    if isinstance(instruction.type, ir.VoidType) or _is_pointer(instruction.type):
        return False
    if instruction.opname == "call":
        callee = instruction.operands[0]
        name = getattr(callee, "name", "")
        return (isinstance(callee, ir.Function) and name.startswith("llvm.")
                and not any(word in name for word in IMPURE_INTRINSIC))
    return instruction.opname in PURE and not isinstance(instruction, ir.PhiInstr)


def _dependence(instruction, deps: dict):
    """The inputs ``instruction`` depends on (a frozenset), or None if it must stay in the body."""
    if not _movable(instruction):
        return None
    found: frozenset = frozenset()
    operands = _operands(instruction)
    for op in operands[1:] if instruction.opname == "call" else operands:
        if isinstance(op, ir.Constant) and not _is_pointer(op.type):
            continue
        d = deps.get(id(op))
        if d is None:
            return None
        found |= d
    return found


#: A group is split off only when it holds at least this many instructions (less saves less than
#: the branch its loop takes per iteration when the group's inputs are arrays) ...
MIN_GROUP = 6
#: ... and at most this many groups per body, those of the fewest inputs first ...
MAX_GROUPS = 2
#: ... and at least this many instructions for each result the body reads from the group (each is
#: a register held through the loop: the tone mappers' per-channel products are not worth one)
PER_RESULT = 8
#: ... and at most this many results in all: they are registers the loop holds whether or not the
#: groups' inputs are broadcast (more cost a PBR shader on per-pixel arrays 3-9% in spills)
MAX_RESULTS = 4


def split(module: "_em.ModuleEmitter", em: "_em.FunctionEmitter", param_inputs: list) -> Hoisted | None:
    """Split the uniform work of the finished body ``em`` (its last parameter the slots pointer;
    ``param_inputs[k]``: the kernel input of parameter ``k``, None for one that varies per element
    whatever the call) into group functions: None (and the body unchanged) when no group is worth it.
    The groups' instructions are copied into their functions; the body reads their results from the
    slots, and its own copies, unused, are left to LLVM's dead-code elimination."""
    body = em.function
    params = list(body.args)
    deps: dict = {id(p): (None if i is None else frozenset([i])) for p, i in zip(params[:-1], param_inputs)}
    every = frozenset(i for i in param_inputs if i is not None)
    position: dict = {}
    always = _always_run(body)
    for block in body.blocks:
        for instruction in block.instructions:
            # work behind a branch (a routine's rare path) is never computed where it was not
            deps[id(instruction)] = _dependence(instruction, deps) if block.name in always else None
            position[id(instruction)] = len(position)
    kept = _worth_splitting(body, deps, every, always)
    if not kept:
        return None
    crossing = _crossing(body, deps, kept, always)
    slot_of = {id(v): k for k, v in enumerate(crossing)}
    slots = ir.LiteralStructType([v.type for v in crossing])
    made = [Group(d, _group_function(module, em, k, d, [v for v in crossing if deps[id(v)] == d], deps, kept,
                                     slot_of, slots, position))
            for k, d in enumerate(kept)]
    _read_slots(em, crossing, slots)
    _recompute_where_rare(em, deps, kept, always, position)
    dead = sum(1 for block in body.blocks for i in block.instructions if deps.get(id(i)) in set(kept))
    return Hoisted(made, slots, dead)


def _always_run(body: ir.Function) -> set:
    """The names of the blocks every run of ``body`` passes through: those that dominate each
    block that returns (iterative dominators; bodies have tens of blocks)."""
    blocks = body.blocks
    succ = {b.name: [op.name for op in b.terminator.operands if isinstance(op, ir.Block)] if b.is_terminated else []
            for b in blocks}
    pred: dict = {b.name: [] for b in blocks}
    for name, targets in succ.items():
        for t in targets:
            pred[t].append(name)
    names = [b.name for b in blocks]
    dom = {n: set(names) for n in names}
    dom[names[0]] = {names[0]}
    changed = True
    while changed:
        changed = False
        for n in names[1:]:
            ps = [dom[p] for p in pred[n]]
            new = (set.intersection(*ps) if ps else set()) | {n}
            if new != dom[n]:
                dom[n], changed = new, True
    exits = [b.name for b in blocks if b.is_terminated and b.terminator.opname == "ret"]
    return set.intersection(*(dom[e] for e in exits)) if exits else {names[0]}


def _worth_splitting(body: ir.Function, deps: dict, every: frozenset, always: set) -> list:
    """The input sets whose groups are split off: at least ``MIN_GROUP`` instructions, and
    ``PER_RESULT`` per result the body reads, on at most a third of the inputs (or one; a group of
    more is rarely all broadcast while others are arrays, and its branch in the loop costs the sky
    shader 4% when they are arrays); at most ``MAX_GROUPS`` of them (fewest inputs, then most
    instructions, first), smallest first."""
    sizes: dict = {}
    for block in body.blocks:
        for instruction in block.instructions:
            d = deps[id(instruction)]
            if d and d != every:
                sizes[d] = sizes.get(d, 0) + 1
    big = [d for d, n in sizes.items() if n >= MIN_GROUP and len(d) <= max(1, len(every) // 3)]
    outputs: dict = {}
    for value in _crossing(body, deps, big, always):
        outputs[deps[id(value)]] = outputs.get(deps[id(value)], 0) + 1
    # each result the body reads from a group is a register its loop keeps: worth it for real work
    big = sorted((d for d in big if sizes[d] >= PER_RESULT * outputs.get(d, 0)),
                 key=lambda d: (len(d), -sizes[d], sorted(d)))
    kept: list = []
    for d in big[:MAX_GROUPS]:
        if sum(outputs.get(k, 0) for k in kept) + outputs.get(d, 0) <= MAX_RESULTS:
            kept.append(d)
    return sorted(kept, key=lambda d: (len(d), sorted(d)))


def _crossing(body: ir.Function, deps: dict, kept: list, always: set) -> list:
    """The values of kept groups that an instruction outside their group reads where every run
    passes (or a phi), in order: the slots. Those read only on a rare path are computed again
    there (``_recompute_where_rare``)."""
    kept_set = set(kept)
    crossing: set = set()
    for block in body.blocks:
        for instruction in block.instructions:
            if block.name not in always and not isinstance(instruction, ir.PhiInstr):
                continue
            own = deps.get(id(instruction))
            for op in _operands(instruction):
                d = deps.get(id(op))
                if d in kept_set and d != own:
                    crossing.add(id(op))
    return [i for block in body.blocks for i in block.instructions if id(i) in crossing]


def _recompute_where_rare(em, deps: dict, kept: list, always: set, position: dict) -> None:
    """Each block off the common path computes again, at its start, the groups' values it reads
    that have no slot, so the body's own copies are left unused."""
    kept_set = set(kept)
    for block in list(em.function.blocks):
        if block.name in always:
            continue
        wanted = {id(op): op for i in block.instructions if not isinstance(i, ir.PhiInstr)
                  for op in _operands(i) if isinstance(op, ir.Instruction) and deps.get(id(op)) in kept_set}
        if not wanted:
            continue
        needed: dict = {}
        todo = list(wanted.values())
        while todo:
            value = todo.pop()
            if id(value) not in needed:
                needed[id(value)] = value
                todo += [op for op in _operands(value)
                         if isinstance(op, ir.Instruction) and deps.get(id(op)) in kept_set]
        copies: dict = {}
        with em.block_start(block):
            for value in sorted(needed.values(), key=lambda i: position[id(i)]):
                copy = _clone(value)
                for op in _distinct(_operands(value)):
                    if id(op) in copies:
                        _replace(copy, op, copies[id(op)])
                em.adopt(copy)
                copies[id(value)] = copy
        for instruction in block.instructions:
            for op in _distinct(_operands(instruction)):
                if id(op) in copies:
                    _replace(instruction, op, copies[id(op)])


def _clone(instruction):
    """A copy of ``instruction`` belonging to no block yet (operands still the original's)."""
    copy = _copy.copy(instruction)
    copy.operands = list(instruction.operands)
    copy.flags = list(instruction.flags)
    copy.metadata = dict(instruction.metadata)
    copy._clear_string_cache()
    return copy


def _group_function(module, em, k: int, inputs: frozenset, outputs: list, deps: dict, kept: list, slot_of: dict,
                    slots, position: dict) -> ir.Function:
    """``<body>.pre<k>``: copies of what the group's ``outputs`` are computed from, which it stores
    in their slots; the values of smaller groups it reads from theirs."""
    body = em.function
    pre = _em.FunctionEmitter(module, f"{body.name}.pre{k}", None, [p.type for p in body.args],
                              [f"x{j}" for j in range(len(body.args))], width=em.width, internal=True,
                              inline="always")
    needed = _closure(outputs, deps, inputs, kept)
    with pre:
        slot_ptr = pre.cast_pointer(pre.params[-1], slots, name="slots")
        copies: dict = {id(p): q for p, q in zip(body.args, pre.params)}
        for instruction in sorted(needed.values(), key=lambda i: position[id(i)]):
            copy = _clone(instruction)
            for op in _distinct(_operands(instruction)):
                if id(op) in copies:
                    _replace(copy, op, copies[id(op)])
                elif deps.get(id(op)) in kept:  # a smaller group's value: from its slot
                    copies[id(op)] = pre.load(pre.field(slot_ptr, slot_of[id(op)]), name="slot")
                    _replace(copy, op, copies[id(op)])
            pre.adopt(copy)
            copies[id(instruction)] = copy
        for value in outputs:
            pre.store(copies[id(value)], pre.field(slot_ptr, slot_of[id(value)]))
        pre.ret(None)
        pre.finish()
    return pre.function


def _closure(outputs: list, deps: dict, inputs: frozenset, kept: list) -> dict:
    """The instructions a group copies: its outputs and, recursively, their operands that are
    instructions not of another kept group (those it reads from their slots)."""
    needed: dict = {}
    todo = list(outputs)
    while todo:
        instruction = todo.pop()
        if id(instruction) in needed:
            continue
        needed[id(instruction)] = instruction
        for op in _operands(instruction):
            d = deps.get(id(op))
            if isinstance(op, ir.Instruction) and d is not None and (d == inputs or d not in kept):
                todo.append(op)
    return needed


def _read_slots(em, crossing: list, slots) -> None:
    """The body reads the crossing values from the slots, loaded in its entry block."""
    body = em.function
    with em.entry_cursor():
        slot_ptr = em.cast_pointer(body.args[-1], slots, name="slots")
        loaded = {id(v): em.load(em.field(slot_ptr, k), name="uniform") for k, v in enumerate(crossing)}
    for block in body.blocks:
        for instruction in block.instructions:
            for op in _distinct(_operands(instruction)):
                if id(op) in loaded:
                    _replace(instruction, op, loaded[id(op)])
