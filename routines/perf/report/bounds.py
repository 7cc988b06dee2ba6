"""The model's bounds and the verdict on where a variant spends.

Contract: :func:`window_bound` reads a reactor ufunc's optimized IR (nothing is
run) and returns its out-of-order window bound; :func:`gap_verdict` is a pure
function of cycles/vector figures; :func:`attach_gaps` sets ``variant["gap"]``
(the verdict at the L1 and L2 sizes, and the model table it was judged
against) on every variant that has timings. The latencies and the core
figures (``FP_SCHEDULER``, ``DISPATCH``) are those of the model's table for
this host (:func:`reactor.cost.host_machine`: Zen 3/4/5, Golden Cove,
Sunny Cove, Skylake-X, Haswell, Neoverse V1, or the stated generic
assumption), the same table the variants' predictions use.
"""
from __future__ import annotations

import math

from reactor.cost import model as M
from .speed import cycles_per_element as _cy

#: The model's table for this host: its name goes with every bound and verdict.
MACHINE = M.host_machine()
#: FP scheduler entries of the model's core (Zen 3/4: 2 x 32 macro-ops, AMD SOG for family 19h,
#: section 2.11; the other cores: ``model.MACHINES``); the effective figure of a run comes
#: from the window probe (:mod:`.probes`).
FP_SCHEDULER = MACHINE.fp_scheduler
DISPATCH = MACHINE.dispatch  # macro-ops dispatched per cycle by the model's core (Zen 3/4: AMD SOG, 2.9.8)
GAP = 1.3  # the target: measured within 1.3x of the model


def window_bound(ufunc, machine=None) -> dict:
    """The out-of-order window bound of a kernel's vector loop on ``machine`` (a
    ``model.Machine`` or table name; default the host's table, :data:`MACHINE`).

    An operation waits in the FP scheduler from dispatch until its operands are
    ready. Take one iteration of ``vec.body`` dispatched in program order at
    the machine's ``dispatch`` ops per cycle and its ASAP schedule with the
    table's latencies: the sum over FP operations of (start - dispatch) is the
    scheduler occupancy one iteration costs, in op-cycles. The scheduler
    holds ``fp_scheduler`` ops, so by Little's law an iteration cannot start
    more often than every ``sum / fp_scheduler`` cycles however many pipes are
    free. This bites long dependent chains at narrow widths (the same chain
    and op count carry half or a quarter of the elements of a zmm iteration).
    An operation on a vector wider than the machine's registers is as many
    native instructions (macro-ops) as it takes registers.
    """
    import llvmlite.binding as llvm
    from reactor import kernel_of

    m = MACHINE if machine is None else M.as_machine(machine)
    kern = kernel_of(ufunc)
    fn = llvm.parse_assembly(kern.optimized_ir).get_function(f"{kern.name}.loop")
    body, _ = M.iteration(fn)  # the blocks every iteration runs (the model's)
    minmax = M._minmax_selects(body)
    folded = set(minmax.values())
    finish: dict[int, float] = {}
    wait, fp_ops, position = 0.0, 0, 0
    for instr in body:
        cls = M.classify(instr)
        if M._key(instr) in folded:
            cls = None
        elif M._key(instr) in minmax:
            cls = "fminmax"
        start = max((finish.get(M._key(op), 0.0) for op in instr.operands), default=0.0)
        bits = M._bits(instr)
        finish[M._key(instr)] = start + (m.cost(cls, bits)[1].latency if cls else 0.0)
        ops = max(1, math.ceil(bits / m.vector_bits))  # native instructions
        if cls and cls not in ("load", "store"):
            wait += ops * max(0.0, start - position / m.dispatch)
            fp_ops += ops
        if cls:
            position += ops
    return {"wait_op_cycles": wait, "fp_ops": fp_ops, "cycles_per_vector": wait / m.fp_scheduler,
            "fp_scheduler": m.fp_scheduler, "machine": m.label}


def gap_verdict(measured_cv: float, pipe_cv: float, window_cv: float,
                floor_cv: float = float("nan"), pipe_factor: float = 1.0) -> tuple[str, str]:
    """(status, explanation) of a measured cycles/vector against the bounds.

    ``met``: within GAP of the pipe bound. ``memory``: within GAP of the
    measured memory floor (a kernel that only copies the same streams at this
    size: the model assumes L1 hits). ``window``: the window bound is the
    larger and the measurement within GAP of it. ``pipes+window``: both
    limits close to each other; their quadrature sum sqrt(p^2 + w^2) (an
    empirical combination: two nearly saturated resources queue against each
    other) is within GAP. ``pipes+memory``: the same with the copy floor
    added. ``unexplained`` otherwise. ``window_cv`` should use
    the run's effective window and ``pipe_factor`` (<= 1) is the share of the
    FP pipes the probe saw; both only enter the explanations, never ``met``."""
    if not (measured_cv > 0 and pipe_cv > 0):
        return "n/a", ""
    r = measured_cv / pipe_cv
    if r <= GAP:
        return "met", f"{r:.2f}x the pipe bound"
    nominal = pipe_cv
    pipe_cv = pipe_cv / pipe_factor if pipe_factor > 0 else pipe_cv
    derated = f" (pipes derated to {pipe_factor:.2f} by the probe)" if pipe_factor < 0.995 else ""
    if pipe_cv != nominal and measured_cv <= GAP * pipe_cv and pipe_cv >= window_cv:
        return "pipes (shared core)", (f"{measured_cv / pipe_cv:.2f}x the pipe bound {pipe_cv:.1f} c/v"
                                       + derated)
    if floor_cv > 0 and measured_cv <= GAP * floor_cv:
        return "memory", (f"{measured_cv / floor_cv:.2f}x the copy floor {floor_cv:.1f} c/v: moving the "
                          f"data at this size costs more than the arithmetic")
    hi = max(pipe_cv, window_cv)
    if window_cv > pipe_cv and measured_cv <= GAP * hi:
        return "window", (f"{measured_cv / hi:.2f}x the window bound {window_cv:.1f} c/v: the dependent "
                          f"chain keeps the FP scheduler full")
    combined = math.hypot(pipe_cv, window_cv)
    if measured_cv <= GAP * combined:
        return "pipes+window", (f"{measured_cv / combined:.2f}x sqrt(pipe^2 + window^2) = {combined:.1f} c/v: "
                                f"pipes ({pipe_cv:.1f}) and window ({window_cv:.1f}) both near saturation"
                                + derated)
    if floor_cv > 0:
        combined = math.sqrt(pipe_cv ** 2 + window_cv ** 2 + floor_cv ** 2)
        if measured_cv <= GAP * combined:
            return "pipes+memory", (f"{measured_cv / combined:.2f}x sqrt(pipe^2 + window^2 + floor^2) = "
                                    f"{combined:.1f} c/v: arithmetic ({pipe_cv:.1f}, window {window_cv:.1f}) "
                                    f"and data movement ({floor_cv:.1f}) both near saturation" + derated)
    return "unexplained", (f"{r:.2f}x the pipe bound, {measured_cv / combined:.2f}x the combined bound"
                           + (f", {measured_cv / floor_cv:.2f}x the copy floor" if floor_cv > 0 else ""))


def attach_gaps(variants, floors, state) -> None:
    """Set ``v["gap"]`` of every variant (in place): at the L1 and L2 sizes where
    it was timed, its measured cycles/vector, the copy floor of its width, the
    window bound at the run's effective window (``state``: size -> the probes'
    :func:`~routines.perf.report.probes.machine_state`; absent: a quiet core),
    the :func:`gap_verdict` and the model table (``"model"``: :data:`MACHINE`'s label)."""
    floor_of = {f["key"]: f for f in floors}
    for v in variants:  # where it spends, at the L1 and L2 sizes
        m = v["model"]
        fl = (floor_of.get(f"floor {'add' if v['func'] in ('pow', 'atan2') else 'copy'} w{v['width']}")
              or floor_of.get(f"floor copy w{v['width']}"))
        v["gap"] = {}
        for size in ("L1", "L2"):
            cv = _cy(v, size) * v["width"]
            if math.isfinite(cv):
                floor_cv = _cy(fl, size) * v["width"] if fl else float("nan")
                st = state.get(size, {"pipe_factor": 1.0, "window": float(FP_SCHEDULER)})
                window_cv = m["window_wait_op_cycles"] / st["window"]
                status, why = gap_verdict(cv, m["cycles_per_vector"], window_cv, floor_cv, st["pipe_factor"])
                v["gap"][size] = {"measured_cycles_per_vector": cv, "floor_cycles_per_vector": floor_cv,
                                  "window_cycles_per_vector": window_cv,
                                  "ratio": cv / m["cycles_per_vector"], "status": status, "why": why,
                                  "model": MACHINE.label}
