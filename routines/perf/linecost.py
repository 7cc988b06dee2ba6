"""The dataflow model's cost of each instruction of a kernel's vector loop, for ``reactor.explain``.

Registered as the entry point ``reactor.explain_costs`` (pyproject.toml), so
``reactor.explain`` and ``python -m reactor explain`` show, per source line, the
operations by class (pipe), its share of the iteration's pipe time (slots times the
cycles each keeps its pipe busy: a divide weighs more than an add) and
whether the line is on the critical path: the longest latency chain through one
iteration (``routines.perf.model``, the same model as the report's).
"""
from __future__ import annotations

import llvmlite.binding as llvm

from . import model


def line_costs(optimized_ir: str, function: str, width: int, machine=None):
    """(per instruction: (its text, {class, slots, critical}), the iteration's summary) for the
    vector loop of ``function`` in ``optimized_ir`` (one iteration: ``model.iteration``)."""
    machine = machine or model.ZEN4
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
        finish[key] = start + (machine[cls].latency if cls else 0.0)
        came_from[key] = pred if start > 0 else None
        rows.append((key, str(instr).strip(), cls, model._slots(instr) if cls else 0))
    critical: set[int] = set()
    node = max(finish, key=finish.get) if finish else None
    while node is not None:
        critical.add(node)
        node = came_from.get(node)
    prediction = model.predict(optimized_ir, function, width, machine)
    per_instruction = [(text.split(", !dbg")[0],
                        {"class": cls, "slots": slots, "busy": slots * machine[cls].busy if cls else 0.0,
                         "critical": key in critical})
                       for key, text, cls, slots in rows]
    summary = {"machine": "Zen 4 table" if machine is model.ZEN4 else "given table",
               "ops": sum(prediction.counts.values()), "slots": sum(prediction.slots.values()),
               "busy": sum(c["busy"] for _, c in per_instruction),
               "bound": prediction.throughput_bound, "bottleneck": prediction.bottleneck,
               "critical_path": prediction.critical_path}
    return per_instruction, summary
