"""Our variants: every function x precision x FMA x SIMD width, built and modelled.

Contract: :func:`build_variants` JIT-compiles every variant of ``functions``
(``routines.jit``) and returns one dict per variant, in the order
function, precision, FMA on/off, width, with its ``ufunc`` and its ``model``
figures (the dataflow model's throughput bound and the :func:`window_bound`);
nothing is timed or measured here.
"""
from __future__ import annotations

import reactor

from ...base import PRECISIONS
from .bounds import window_bound

#: The exponential, logarithmic and reciprocal routines: the report's default functions.
EXP_LOG = ("exp2", "log2", "pow", "exp", "log", "rcp", "rsqrt", "sqrt")
#: The trigonometric and hyperbolic routines (routines/trig.py).
TRIG = ("sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh")
#: Every function the report can measure (``--functions``).
FUNCTIONS = EXP_LOG + TRIG
#: The functions of ``python -m routines report`` without ``--functions``.
DEFAULT_FUNCTIONS = EXP_LOG
#: The SIMD widths every variant is measured at (reactor's, without scalars).
WIDTHS = tuple(w for w in reactor.WIDTHS if w > 1)
#: The variant the targets and the table's "fma w16" figures refer to: FMA on, 16 lanes
#: (``routines.jit``'s natural width on an AVX-512 target).
DEFAULT = {"fma": True, "width": 16}


def _variant_key(func, precision, fma, width):
    return f"{func} {precision} {'fma' if fma else 'nofma'} w{width}"


def build_variants(functions, progress=None) -> list[dict]:
    """Every variant of ours with its ufunc and model figures."""
    from routines import jit

    from reactor.cost import predict_kernel

    out = []
    has_fma = reactor.get_target("host").has_fma
    for func in functions:
        for precision in PRECISIONS:
            for fma in (True, False):
                for width in WIDTHS:  # FMA on: in software on a CPU without it (never a libm call)
                    u = jit(func, precision, fma if not fma or has_fma else "emulate", width)
                    pred = predict_kernel(u)
                    win = window_bound(u)
                    out.append({
                        "key": _variant_key(func, precision, fma, width), "kind": "ours",
                        "family": f"ours {precision}", "func": func, "precision": precision,
                        "fma": fma, "width": width, "ufunc": u,
                        "model": {"cycles_per_vector": pred.throughput_bound,
                                  "cycles_per_element": pred.cycles_per_element,
                                  "bottleneck": pred.bottleneck, "critical_path": pred.critical_path,
                                  "counts": dict(pred.counts), "explain": pred.explain(),
                                  "window_cycles_per_vector": win["cycles_per_vector"],
                                  "window_wait_op_cycles": win["wait_op_cycles"]},
                    })
                    if progress is not None:
                        progress.update(1)
    return out
