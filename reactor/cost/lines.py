"""The dataflow model's cost of each instruction of a kernel's vector loop, for ``reactor.explain``.

``reactor.explain`` and ``python -m reactor explain`` show, per source line, the
operations by class (pipe), its share of the vector iteration's pipe time (slots times the
cycles each keeps its pipe busy: a divide weighs more than an add, each times how often
it runs) and whether the line is on the critical path: the longest latency chain through one
pass (``reactor.cost.model``, the same model as the report's). The machine is the
host's table (``model.host_machine``) unless one is given; the summary names it.

**How often a line runs.** The model's pass (``model.iteration``) runs every block of the
vector iteration once. A loop inside the body (a run-time ``while``/``for``) runs its blocks
many times per vector, so every block gets a *weight*, its executions per vector iteration
(:func:`block_weights`):

* **measured**: given ``counts`` (each block's executions on sample inputs, from an
  instrumented build: ``reactor.explain``'s ``inputs=``), a block's weight is its count over
  the count of ``vec.body``; a loop's trip count is its header's;
* **estimated**: a loop whose exit compares a counter with a constant (``for i in range(8)``
  with a ``break``, ``while n < 64``) is taken to run to that bound (the most it can run);
  any other loop is assumed to run :data:`ASSUMED_TRIPS` times. Blocks outside loops that not
  every iteration runs weigh 0, as in the model's pass.

Each loop is reported with its trip count and which of the two it is.
"""
from __future__ import annotations

import dataclasses
import re

import llvmlite.binding as llvm

from . import model

#: Iterations assumed for a loop whose trip count is not known when it is built: LLVM's own
#: default (BranchProbabilityInfo weighs a loop's back edge 124 to 4 against its exit: 32).
ASSUMED_TRIPS = 32
_MAX_BOUND = 1 << 20


@dataclasses.dataclass
class Loop:
    """A loop inside a kernel's vector iteration: its header block, its blocks, and its trip
    count per vector iteration, ``how`` it is known ("measured" or "estimated") and why."""

    header: str
    blocks: list[str]
    latches: list[str]
    trips: float = 0.0
    how: str = "estimated"
    detail: str = ""
    parent: str | None = None  # the header of the loop this one is inside


def region(fn, start: str = "vec.body") -> tuple[list[str], dict[str, list[str]]]:
    """(the blocks of one vector iteration in function order, successors within them): ``start``
    and every block on a path from it back to it (not the ``tail.*`` gathering blocks)."""
    blocks = {b.name: b for b in fn.blocks}
    if start not in blocks:
        raise ValueError(f"{fn.name} has no vector loop (block {start})")
    succ = model.loop_successors(blocks)
    inside = {n for n in blocks if n != start and model._reaches(succ, start, n) and model._reaches(succ, n, start)}
    names = [b.name for b in fn.blocks if b.name == start or b.name in inside]
    keep = set(names)
    return names, {n: [m for m in succ[n] if m in keep] for n in names}


def _dominators(names: list[str], succ: dict[str, list[str]], start: str) -> dict[str, set[str]]:
    """Each block's dominators in the iteration's graph (edges back into ``start`` cut)."""
    preds: dict[str, list[str]] = {n: [] for n in names}
    for n in names:
        for m in succ[n]:
            if m != start:
                preds[m].append(n)
    dom = {n: set(names) for n in names}
    dom[start] = {start}
    changed = True
    while changed:
        changed = False
        for n in names:
            if n == start:
                continue
            new = set.intersection(*(dom[p] for p in preds[n])) if preds[n] else set()
            new = new | {n}
            if new != dom[n]:
                dom[n], changed = new, True
    return dom


def find_loops(fn, start: str = "vec.body") -> list[Loop]:
    """The natural loops inside the vector iteration of ``fn`` (outer loops first), from its back
    edges: an edge to a block that dominates its source."""
    names, succ = region(fn, start)
    dom = _dominators(names, succ, start)
    latches: dict[str, list[str]] = {}
    for n in names:
        for m in succ[n]:
            if m != start and m in dom[n]:
                latches.setdefault(m, []).append(n)
    preds: dict[str, list[str]] = {n: [m for m in names if n in succ[m]] for n in names}
    loops = []
    for header, tails in latches.items():
        body, todo = {header}, list(tails)
        while todo:
            n = todo.pop()
            if n not in body:
                body.add(n)
                todo += preds[n]
        loops.append(Loop(header, [n for n in names if n in body], tails))
    loops.sort(key=lambda lp: -len(lp.blocks))
    for k, lp in enumerate(loops):
        outer = [o for o in loops[:k] if lp.header in o.blocks and o is not lp]
        lp.parent = outer[-1].header if outer else None
    return loops


_PHI = re.compile(r"^%(\S+) = phi (.+?) \[ (.+?), %(\S+) \], \[ (.+?), %(\S+) \]$")
_ADD = re.compile(r"^%(\S+) = add (?:nuw |nsw )*(.+?) %(\S+), (.+)$")
_ICMP = re.compile(r"^%(\S+) = icmp (\w+) (.+?) %(\S+), (.+)$")
_ZEXT = re.compile(r"^%(\S+) = zext <\d+ x i1> %\S+ to ")


def _integer(text: str) -> int | None:
    """The value of an integer constant of IR (``7``, ``zeroinitializer``, ``splat (i32 7)``,
    a vector of equal elements), else None."""
    text = text.strip()
    if text == "zeroinitializer":
        return 0
    m = re.fullmatch(r"-?\d+", text) or re.fullmatch(r"splat \(i\d+ (-?\d+)\)", text)
    if m:
        return int(m.group(1) if m.groups() else m.group(0))
    values = re.findall(r"i\d+ (-?\d+)", text) if text.startswith("<") else []
    return int(values[0]) if values and len(set(values)) == 1 else None


def _trips(start: int, step: int, predicate: str, bound: int, on_next: bool) -> int | None:
    """Iterations of a loop whose counter starts at ``start`` and grows by ``step``, compared with
    ``bound`` at the end of each iteration (the counter after the step if ``on_next``): the first
    iteration whose answer differs from the first one's ends it. None if none does within
    ``_MAX_BOUND`` iterations or the predicate is not an ordering."""
    ops = {"slt": int.__lt__, "ult": int.__lt__, "sle": int.__le__, "ule": int.__le__, "sgt": int.__gt__,
           "ugt": int.__gt__, "sge": int.__ge__, "uge": int.__ge__, "ne": int.__ne__, "eq": int.__eq__}
    if predicate not in ops or step <= 0:
        return None
    test = ops[predicate]

    def value(k: int) -> int:
        return start + (k if on_next else k - 1) * step
    first = test(value(1), bound)
    k = next((k for k in range(2, _MAX_BOUND) if test(value(k), bound) != first), None)
    return k


def constant_bound(fn, lp: Loop) -> tuple[int, str] | None:
    """(the most iterations, how it was found) for a loop whose counter (a phi of the header that
    starts at a constant and grows by a constant, or by at most 1 per lane) is compared with a
    constant inside the loop; None if there is no such counter."""
    instrs = {b.name: [str(i).split(", !dbg")[0].strip() for i in b.instructions] for b in fn.blocks}
    inside = [t for n in lp.blocks for t in instrs[n]]
    adds = {m.group(1): m for m in map(_ADD.match, inside) if m}
    zexts = {m.group(1) for m in map(_ZEXT.match, inside) if m}
    compares = [m for m in map(_ICMP.match, inside) if m]
    best: tuple[int, str] | None = None
    for text in instrs[lp.header]:
        phi = _PHI.match(text)
        if not phi:
            continue
        name, init, nxt = phi.group(1), None, None
        for value, block in ((phi.group(3), phi.group(4)), (phi.group(5), phi.group(6))):
            if block in lp.blocks:
                nxt = value.lstrip("%")
            else:
                init = _integer(value)
        add = adds.get(nxt or "")
        if init is None or add is None or add.group(3) != name:
            continue
        step = 1 if add.group(4).lstrip("%") in zexts else _integer(add.group(4))
        if step is None:
            continue
        for cmp in compares:
            bound = _integer(cmp.group(5))
            if bound is None or cmp.group(4) not in (name, nxt):
                continue
            trips = _trips(init, step, cmp.group(2), bound, cmp.group(4) == nxt)
            if trips is not None and (best is None or trips < best[0]):
                lanes = " (per lane)" if add.group(4).lstrip("%") in zexts else ""
                best = (trips, f"a counter from {init} by {step}{lanes} against {bound}, known when built; "
                               f"at most {trips}, taken as {trips}")
    return best


def block_weights(fn, counts: dict[str, int] | None = None, start: str = "vec.body"
                  ) -> tuple[dict[str, float], list[Loop]]:
    """(each block's executions per vector iteration, the loops inside it with their trip counts):
    measured from ``counts`` (a block's executions on sample inputs) when given, else estimated
    (see the module docstring)."""
    names, succ = region(fn, start)
    loops = find_loops(fn, start)
    if counts is not None and counts.get(start):
        total = counts[start]
        for lp in loops:
            lp.trips, lp.how = counts.get(lp.header, 0) / total, "measured"
            lp.detail = f"measured: {counts.get(lp.header, 0)} passes in {total} vector iterations"
        return {n: counts.get(n, 0) / total for n in names}, loops
    for lp in loops:
        found = constant_bound(fn, lp)
        lp.trips, lp.detail = (float(found[0]), found[1]) if found else (
            float(ASSUMED_TRIPS), f"unknown when built; assumed {ASSUMED_TRIPS} (LLVM's default for a loop of "
                                  f"unknown count); explain with inputs to measure it")
    by_header = {lp.header: lp for lp in loops}
    weights = {}
    for n in names:
        inner = [lp for lp in loops if n in lp.blocks]
        home = inner[-1] if inner else None  # the innermost (loops are sorted outer first)
        factor = 1.0
        for lp in inner:
            factor *= lp.trips
        weights[n] = factor if _every(n, home, succ, start, by_header) else 0.0
    return weights, loops


def _every(block: str, home: Loop | None, succ: dict[str, list[str]], start: str, loops: dict[str, Loop]) -> bool:
    """Whether every pass through ``home`` (a loop; None: the vector iteration) runs ``block``:
    no path from the loop's header back to it avoids ``block`` (a loop nested inside counts
    as run: its own header decides)."""
    head = home.header if home else start
    if block == head:
        return True
    inner = [lp for lp in loops.values() if block in lp.blocks and lp is not home and
             (home is None or lp.header in home.blocks)]
    if inner and block != inner[0].header:
        return _every(block, inner[-1], succ, start, loops) and _every(inner[0].header, home, succ, start, loops)
    allowed = set(home.blocks) if home else set(succ)
    seen, todo = set(), [m for m in succ[head] if m in allowed or m == head]
    while todo:
        n = todo.pop()
        if n == head:
            return False
        if n in seen or n == block or n not in allowed:
            continue
        seen.add(n)
        todo += succ[n]
    return True


def line_costs(optimized_ir: str, function: str, width: int, machine=None, counts: dict[str, int] | None = None):
    """(per instruction: (its text, {class, slots, busy, weight, block, critical}), the iteration's
    summary) for the vector loop of ``function`` in ``optimized_ir`` on ``machine`` (a
    ``model.Machine``, a table name, or None: the host's table). ``busy`` is the pipe time of one
    execution times ``weight``, the executions per vector iteration (:func:`block_weights`, measured
    from ``counts`` when given); the critical path is that of one pass (``model.iteration``)."""
    machine = model.as_machine(machine)
    mod = llvm.parse_assembly(optimized_ir)
    fn = mod.get_function(function)
    weights, loops = block_weights(fn, counts)
    passed, _skipped = model.iteration(fn)
    on_pass = {model._key(i) for i in passed}
    body = [i for b in fn.blocks if b.name in weights for i in b.instructions]
    minmax = model._minmax_selects(body)
    folded = set(minmax.values())
    finish: dict[int, float] = {}
    came_from: dict[int, int | None] = {}
    rows = []
    demand: dict[str, float] = {}
    fp_slots = 0.0
    for instr in body:
        cls = model.classify(instr)
        key = model._key(instr)
        if key in folded:
            cls = None
        elif key in minmax:
            cls = "fminmax"
        cost = machine.cost(cls, model._bits(instr)) if cls else None
        weight = weights[instr.block.name]
        if key in on_pass:
            preds = [(finish.get(model._key(op), 0.0), model._key(op)) for op in instr.operands]
            begin, pred = max(preds, default=(0.0, None))
            finish[key] = begin + (cost[1].latency if cost else 0.0)
            came_from[key] = pred if begin > 0 else None
        if cost and weight:
            demand[cost[0]] = demand.get(cost[0], 0.0) + cost[2] * weight
            fp_slots += 0 if cls in ("load", "store") else cost[2] * weight
        rows.append((key, str(instr).strip(), cls, cost, weight, instr.block.name))
    critical: set[int] = set()
    node = max(finish, key=lambda k: finish[k]) if finish else None
    while node is not None:
        critical.add(node)
        node = came_from.get(node)
    prediction = model.predict(optimized_ir, function, width, machine)
    busy = [cost[2] * cost[1].busy * weight if cost else 0.0 for _, _, _, cost, weight, _ in rows]
    per_instruction = [(text.split(", !dbg")[0],
                        {"class": cls if weight else None, "slots": cost[2] if cost else 0, "busy": b,
                         "weight": weight, "block": block, "critical": key in critical})
                       for (key, text, cls, cost, weight, block), b in zip(rows, busy)]
    bounds = {"issue width": fp_slots / machine.issue_width}
    bounds.update(model._pipe_bounds(demand, machine) if demand else {})
    weighted = max(bounds, key=lambda k: bounds[k])
    summary = {"machine": machine.label, "table": machine.name,
               "ops": sum(prediction.counts.values()), "slots": sum(prediction.slots.values()),
               "busy": sum(busy),
               "bound": prediction.throughput_bound, "bottleneck": prediction.bottleneck,
               "critical_path": prediction.critical_path,
               "loops": [dataclasses.asdict(lp) for lp in loops],
               "weighted_bound": bounds[weighted], "weighted_bottleneck": weighted}
    return per_instruction, summary


def summary_text(summary: dict) -> str:
    """One line for the summary ``line_costs`` returns (two when the iteration has loops: the
    bound of one pass through every block, and with each block weighted by how often it runs)."""
    line = (f"model ({summary.get('machine', '?')}): {summary.get('ops', 0)} operations a vector, throughput bound "
            f"{summary.get('bound', 0):.2f} cycles a vector ({summary.get('bottleneck', '?')}), critical path "
            f"{summary.get('critical_path', 0):.0f} cycles")
    if summary.get("loops"):
        line += (f"\n  (the blocks every iteration runs, once); with each line weighted by how often it runs "
                 f"(the loops below): {summary.get('weighted_bound', 0):.2f} cycles a vector "
                 f"({summary.get('weighted_bottleneck', '?')})")
    return line


def region_blocks(optimized_ir: str, function: str) -> list[str]:
    """The names of the blocks of one vector iteration of ``function`` (:func:`region`)."""
    return region(llvm.parse_assembly(optimized_ir).get_function(function))[0]


def runs_text(cost: dict) -> str:
    """", run 64.0 times a vector" for a line's cost inside a loop (nothing for a line run once)."""
    runs = cost.get("runs", 1.0)
    return "" if abs(runs - 1.0) < 1e-9 else f", run {runs:.1f} times a vector"
