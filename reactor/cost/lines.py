"""The dataflow model's cost of each instruction of a kernel's vector loop, for ``reactor.explain``.

``reactor.explain`` and ``python -m reactor explain`` show, per source line, the
operations by class (pipe), its share of the iteration's pipe time (slots times the
cycles each keeps its pipe busy: a divide weighs more than an add) and
whether the line is on the critical path: the longest latency chain through one
iteration (``reactor.cost.model``, the same model as the report's). The machine is the
host's table (``model.host_machine``) unless one is given; the summary names it.
"""
from __future__ import annotations

import llvmlite.binding as llvm

from . import model


def line_costs(optimized_ir: str, function: str, width: int, machine=None):
    """(per instruction: (its text, {class, slots, critical}), the iteration's summary) for the
    vector loop of ``function`` in ``optimized_ir`` (one iteration: ``model.iteration``) on
    ``machine`` (a ``model.Machine``, a table name, or None: the host's table)."""
    machine = model.as_machine(machine)
    mod = llvm.parse_assembly(optimized_ir)
    fn = mod.get_function(function)
    body, _skipped = model.iteration(fn)
    minmax = model._minmax_selects(body)
    folded = set(minmax.values())
    finish: dict[int, float] = {}
    came_from: dict[int, int | None] = {}
    rows = []
    for instr in body:
        cls = model.classify(instr)
        key = model._key(instr)
        if key in folded:
            cls = None
        elif key in minmax:
            cls = "fminmax"
        preds = [(finish.get(model._key(op), 0.0), model._key(op)) for op in instr.operands]
        start, pred = max(preds, default=(0.0, None))
        cost = machine.cost(cls, model._bits(instr)) if cls else None
        finish[key] = start + (cost[1].latency if cost else 0.0)
        came_from[key] = pred if start > 0 else None
        rows.append((key, str(instr).strip(), cls, cost))
    critical: set[int] = set()
    node = max(finish, key=lambda k: finish[k]) if finish else None
    while node is not None:
        critical.add(node)
        node = came_from.get(node)
    prediction = model.predict(optimized_ir, function, width, machine)
    busy = [cost[2] * cost[1].busy if cost else 0.0 for _, _, _, cost in rows]
    per_instruction = [(text.split(", !dbg")[0],
                        {"class": cls, "slots": cost[2] if cost else 0, "busy": b, "critical": key in critical})
                       for (key, text, cls, cost), b in zip(rows, busy)]
    summary = {"machine": machine.label, "table": machine.name,
               "ops": sum(prediction.counts.values()), "slots": sum(prediction.slots.values()),
               "busy": sum(busy),
               "bound": prediction.throughput_bound, "bottleneck": prediction.bottleneck,
               "critical_path": prediction.critical_path}
    return per_instruction, summary


def summary_text(summary: dict) -> str:
    """One line for the summary ``line_costs`` returns."""
    return (f"model ({summary.get('machine', '?')}): {summary.get('ops', 0)} operations a vector, throughput bound "
            f"{summary.get('bound', 0):.2f} cycles a vector ({summary.get('bottleneck', '?')}), critical path "
            f"{summary.get('critical_path', 0):.0f} cycles")
