"""reactor: a typed SIMD DSL in Python that emits LLVM IR and JIT-compiles it.

Layers (one package each): ``dsl`` (types, values, control flow, functions)
-> ``ir`` (the IR emitter and the operation table) -> ``jit`` (targets, LLVM
optimization, caches) -> ``kernels`` (compiled code as NumPy ufuncs).
"""
from .dsl.external import External
from .dsl.control import Elif, Else, For, If, Return, While
from .dsl.function import Function, Library, Module, Routine, function
from .dsl.intrinsics import (
    Abs, All, Any, As, Ceil, CopySign, Exponent, Extract, Floor, Fma, Fract, Insert, IsFinite,
    IsInf, IsNan, LaneIndex, Max, MaxNum, Min, MinNum, MulAdd, RcpApprox, Round, RsqrtApprox, Select, Significand,
    ShiftRightArithmetic, ShiftRightLogical, Sqrt, ToInt, Trunc, fma_mode, target_features,
)
from .dsl.signature import SIMD, Pointer
from .dsl.types import KINDS, WIDTHS
from .dsl.values import Value, vector_type
from .dsl.variables import Variable
from .errors import (
    ArgumentError, ArityError, CompileError, ControlFlowError, DSLTypeError, FmaDisabledError,
    MissingReturnError, ReactorError, ScopeError, WidthMismatchError,
)
from .kernels.kernel import Kernel, kernel, kernel_of
from .options import BuildOptions, options

# Value types: Float, Float4, Float8, Float16, Int, Int4, ..., Bool16 (masks).
for _kind in KINDS:
    for _w in WIDTHS:
        _cls = vector_type(_kind, _w)
        globals()[_cls.__name__] = _cls
del _kind, _w, _cls

__version__ = "0.1.0"
