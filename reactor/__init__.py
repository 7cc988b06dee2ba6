"""reactor: a typed SIMD DSL in Python that emits LLVM IR and JIT-compiles it.

Layers (docs/architecture.md): ``build``/``targets`` (settings, resolved once
per build) -> ``ir`` (value types, the one emitter that speaks llvmlite, the
operation table) -> ``dsl`` (values, intrinsics, control flow, function
definitions) -> ``jit`` (LLVM optimization, caches) -> ``runtime`` (compiled
functions called from Python) and ``kernels`` (compiled loops as NumPy ufuncs).
"""
from .build import Build, BuildOptions, Precision, options
from .dsl.control import Elif, Else, For, If, Return, While
from .dsl.external import External
from .dsl.intrinsics import (
    Abs, All, Any, As, Ceil, CopySign, Exponent, Extract, Floor, Fma, Fract, Insert, IsFinite,
    IsInf, IsNan, LaneIndex, LRint, Max, MaxNum, Min, MinNum, MulAdd, RcpApprox, ReduceNearest, Round,
    RsqrtApprox, ScaleF, Select, Significand, ShiftRightArithmetic, ShiftRightLogical, Sqrt, ToInt, Trunc,
    build_settings, fma_mode, precision, target_features,
)
from .dsl.signature import SIMD, Pointer
from .dsl.values import Value, vector_type
from .dsl.variables import Variable, is_variable
from .errors import (
    ArgumentError, ArityError, CompileError, ControlFlowError, DSLTypeError, FmaDisabledError,
    MissingReturnError, ReactorError, ScopeError, WidthMismatchError, hide_frames_of,
)
from .ir.types import KINDS, WIDTHS
from .kernels.kernel import Kernel, kernel, kernel_of
from .kernels.parallel import configure as configure_threads, settings as thread_settings
from .runtime.function import Function, Library, Module, Routine, function
from .targets import TARGETS, Target, get_target

# Value types: Float, Float4, Float8, Float16, Int, Int4, ..., Bool16 (masks).
for _kind in KINDS:
    for _w in WIDTHS:
        _cls = vector_type(_kind, _w)
        globals()[_cls.__name__] = _cls
del _kind, _w, _cls

__version__ = "0.1.0"
