"""Accuracy lab: measures, Vulkan tolerances, float64 reference, sweeps.

Scores float32 kernels (any float32 -> float32 callable, typically a NumPy
ufunc) for exp2, exp, log2, log, pow, rcp, rsqrt, sqrt, sin, cos, tan, asin,
acos, atan, atan2, sinh, cosh and tanh against a float64 reference, in ULP-32
and ULP-16 and as a margin against the Vulkan "full" (highp) or "relaxed"
(RelaxedPrecision / mediump) tolerance.
See docs/accuracy.md.
"""

from .measures import (CATEGORIES, abs_error, classify, margin, spec_ulp16, spec_ulp32,
                       ulp16, ulp32, ulp_error)
from .reference import ARITY, BINARY, FUNCS, AuditReport, audit, reference
from .sweep import Case, SweepResult, evaluate, sample_inputs, sweep
from .tolerance import PRECISIONS, Tolerance, tolerance

__all__ = [
    "ARITY", "BINARY", "CATEGORIES", "FUNCS", "PRECISIONS", "AuditReport", "Case", "SweepResult",
    "Tolerance", "abs_error", "audit", "classify", "evaluate", "margin", "reference",
    "sample_inputs", "spec_ulp16", "spec_ulp32", "sweep", "tolerance", "ulp16", "ulp32",
    "ulp_error",
]
