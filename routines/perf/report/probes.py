"""Floors and probes: what the data movement and the core deliver during the run.

Contract: :func:`floor_kernels` and :func:`probe_kernels` build reactor
kernels (returned as entries for :func:`~routines.perf.report.speed.measure_speed`,
timed in the same rounds as everything else); :func:`machine_state` turns
the two probes' timings at one size into the FP pipe share and the
effective FP window the run saw there.
"""
from __future__ import annotations

from .bounds import FP_SCHEDULER, window_bound
from .speed import cycles_per_element as _cy
from .variants import WIDTHS


def floor_kernels(functions) -> list[dict]:
    """Reactor kernels that only move data, at widths 4/8/16: ``out = x``
    (timed on the first unary function's inputs) and ``out = x + y`` (on the
    first two-operand function's: pow's, or atan2's): the memory and loop floor
    of the harness at each size and width."""
    import reactor
    from reactor import Float

    def copy(x):
        return x

    def add(x, y):
        return x + y

    out = []
    unary = [f for f in functions if f not in ("pow", "atan2")]
    binary = [f for f in functions if f in ("pow", "atan2")]
    for width in WIDTHS:
        if unary:
            out.append({"key": f"floor copy w{width}", "func": unary[0], "kind": "floor", "family": "floor",
                        "width": width, "label": "out = x (one input stream)",
                        "ufunc": reactor.kernel(copy, name=f"perf_floor_copy_w{width}", args=[Float],
                                                returns=Float, width=width)})
        if binary:
            out.append({"key": f"floor add w{width}", "func": binary[0], "kind": "floor", "family": "floor",
                        "width": width, "label": "out = x + y (two input streams)",
                        "ufunc": reactor.kernel(add, name=f"perf_floor_add_w{width}", args=[Float, Float],
                                                returns=Float, width=width)})
    return out


def probe_kernels() -> list[dict]:
    """Two reactor kernels timed in the same rounds as everything else, to see
    what the machine delivers during the run (a shared core's pipes and window
    shrink when its sibling is busy):

    * ``probe pipes`` (width 16): 8 independent chains of 4 FMAs per element,
      summed: FP0/FP1-bound (model: 32 cycles/vector, window ~7);
    * ``probe window`` (width 8): one dependent chain of 32 FMAs per element:
      window-bound (pipes 16 cycles/vector, window ~33 at ``FP_SCHEDULER`` = 64 entries).

    ``pipe factor`` = model bound / measured (1 = all of the FMA pipes),
    ``window`` = the probe's scheduler occupancy / measured cycles per vector
    (the effective scheduler entries: ``FP_SCHEDULER`` on a quiet core of the model's kind)."""
    import reactor
    from reactor import Float, MulAdd

    def pipes(x):
        chains = [MulAdd(MulAdd(MulAdd(MulAdd(x + float(k), 0.999, 0.001), 0.999, 0.001), 0.999, 0.001),
                         0.999, 0.001) for k in range(8)]
        total = chains[0]
        for c in chains[1:]:
            total = total + c
        return total

    def window(x):
        v = x
        for _ in range(32):
            v = MulAdd(v, 0.999, 0.001)
        return v

    out = []
    for key, body, width in (("probe pipes", pipes, 16), ("probe window", window, 8)):
        u = reactor.kernel(body, name=f"perf_{key.replace(' ', '_')}", args=[Float], returns=Float,
                           width=width, fma=True)
        out.append({"key": key, "func": "exp2", "kind": "probe", "family": "probe", "width": width,
                    "ufunc": u, "wait_op_cycles": window_bound(u)["wait_op_cycles"]})
    from reactor.cost import predict_kernel
    out[0]["model_cycles_per_vector"] = predict_kernel(out[0]["ufunc"]).throughput_bound
    return out


def machine_state(probes, size) -> dict:
    """(pipe factor, effective window) at ``size`` from the probes' timings."""
    pp, pw = probes
    cv_p = _cy(pp, size) * pp["width"]
    cv_w = _cy(pw, size) * pw["width"]
    factor = min(1.0, pp["model_cycles_per_vector"] / cv_p) if cv_p > 0 else 1.0
    window = min(float(FP_SCHEDULER), pw["wait_op_cycles"] / cv_w) if cv_w > 0 else float(FP_SCHEDULER)
    return {"pipe_factor": factor, "window": window, "pipe_probe_cycles_per_vector": cv_p,
            "window_probe_cycles_per_vector": cv_w}
