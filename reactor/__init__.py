"""reactor: a typed SIMD DSL in Python that emits LLVM IR and JIT-compiles it.

Layers (docs/architecture.md): ``build``/``targets`` (settings, resolved once
per build) -> ``ir`` (value types, the one emitter that speaks llvmlite, the
operation table) -> ``dsl`` (values, intrinsics, control flow, function
definitions) -> ``jit`` (LLVM optimization, caches) -> ``runtime`` (compiled
functions called from Python) and ``kernels`` (compiled loops as NumPy ufuncs).

Value types: ``Float``, ``Int``, ``UInt``, ``Bool`` (masks), ``Double``, ``UByte``, ``UShort``, ``Half``,
each at widths 1, 4, 8 and 16 (``Float4`` ...), and GLSL's vectors and matrices (``vec3``, ``ivec2``,
``mat4`` ...); each class's docstring says what it holds. The constants:

- ``WIDTHS``: the SIMD widths of the DSL, ``(1, 4, 8, 16)`` (1 is scalar).
- ``KINDS``: the element kinds by name (``"Float"`` -> its category, bits and NumPy dtype).
- ``TARGETS``: the code-generation target names ``get_target`` takes (``"host"``, ``"avx2"`` ...).
- ``SHADER_TIERS``: the precision tiers every math built-in has, least accurate first
  (``("relaxed", "full")``, Vulkan's mediump and highp).
"""
import typing as _typing

from .build import SHADER_TIERS, Build, BuildOptions, Precision, Site, options, register_variants, split_precision
from .kernels import parallel as _parallel

_parallel.warm_up()  # the JIT's one-time start-up on a thread, beside the rest of the import
from .dsl.control import Break, Continue, Elif, Else, For, If, Return, While
from .dsl.external import External
from .dsl.intrinsics import (
    Abs, All, Any, As, Ceil, CopySign, Exponent, Extract, Floor, Fma, Fract, Insert, IsFinite,
    IsInf, IsNan, LaneIndex, Lookup, LRint, Max, MaxNum, Min, MinNum, MulAdd, RcpApprox, ReduceDown, ReduceNearest, Round,
    RsqrtApprox, ScaleF, Select, Significand, ShiftRightArithmetic, ShiftRightLogical, Sqrt, ToInt, Trunc,
    build_settings, fma_mode, precision, target_features,
)
from .dsl import flow  # the control-flow core as plain calls, for front ends
from .dsl.syntax import hint, inline, syntax
from .spirv import from_glsl, from_spirv
from .spirv import set_builtins as set_glsl_builtins
from .dsl.calls import RoutineCall, pure_call, routine_call, site_choice, site_probe
from .dsl.signature import SIMD, Pointer
from .dsl.textures import ConstantTable, Table, Texture2D, Texture3D
from .dsl.values import Value, set_power, vector_type
from .dsl.vectors import Mat, Vec, mat_type, vec_type
from .dsl.vectors import (bvec2, bvec3, bvec4, dvec2, dvec3, dvec4, f16vec2, f16vec3, f16vec4,  # noqa: F401
                          ivec2, ivec3, ivec4, mat2, mat3, mat4, u8vec2, u8vec3, u8vec4, u16vec2, u16vec3,
                          u16vec4, uvec2, uvec3, uvec4, vec2, vec3, vec4)
from .dsl.variables import Variable, is_variable
from .errors import (
    ArgumentError, ArityError, CompileError, ControlFlowError, DSLTypeError, FmaDisabledError, LoopLimitError,
    MissingDependencyError, MissingReturnError, ReactorError, ScopeError, WidthMismatchError, hide_frames_of, require,
)
from .ir.types import KINDS, WIDTHS
from .kernels.kernel import Kernel, kernel, kernel_of
from .kernels.chunks import map_blocks
from .kernels.qemu import Emulator, missing as emulator_missing, run as run_emulated
from .kernels.pickling import travels_as  # also registers how reactor ufuncs pickle
from .explain import explain
from .planner import Plan, PlanStaleError, Range, Rows, plan
from .kernels.parallel import configure as configure_threads, settings as thread_settings
from .kernels.tiers import configure as configure_tiers, finish as finish_tiers
from .runtime.function import CompiledModule, Function, Library, Module, Routine, function
from .targets import TARGETS, Target, get_target

# Value types: Float, Float4, Float8, Float16, Int, Int4, ..., Bool16 (masks).
if _typing.TYPE_CHECKING:  # the classes the loop below makes, with their operators' types (generated)
    from .dsl.value_types import *  # noqa: F401,F403 - python tools/value_types.py writes it
for _kind in KINDS:
    for _w in WIDTHS:
        _cls = vector_type(_kind, _w)
        globals()[_cls.__name__] = _cls
del _kind, _w, _cls

__version__ = "0.2.0.dev0"  # CHANGELOG.md; the package's version (pyproject reads it)

__all__ = [
    # build settings and targets
    "Build", "BuildOptions", "Precision", "SHADER_TIERS", "Site", "options", "build_settings", "fma_mode", "precision", "target_features",
    "Target", "TARGETS", "get_target", "Emulator", "emulator_missing", "run_emulated", "WIDTHS", "KINDS",
    # values, types, variables, pointers
    "Value", "vector_type", "SIMD", "Pointer", "Variable", "is_variable", "set_power",
    "Table", "Texture2D", "Texture3D", "ConstantTable",
    "Vec", "Mat", "vec_type", "mat_type", "vec2", "vec3", "vec4", "dvec2", "dvec3", "dvec4", "ivec2", "ivec3",
    "ivec4", "uvec2", "uvec3", "uvec4", "bvec2", "bvec3", "bvec4", "mat2", "mat3", "mat4",
    "u8vec2", "u8vec3", "u8vec4", "u16vec2", "u16vec3", "u16vec4", "f16vec2", "f16vec3", "f16vec4",
    *(f"{kind}{'' if w == 1 else w}" for kind in ("Float", "Double", "Int", "UInt", "Bool", "UByte", "UShort",
                                                  "Half") for w in WIDTHS),
    # control flow
    "If", "Elif", "Else", "While", "For", "Return", "Break", "Continue", "inline",
    # intrinsics
    "Abs", "All", "Any", "As", "Ceil", "CopySign", "Exponent", "Extract", "Floor", "Fma", "Fract", "Insert",
    "IsFinite", "IsInf", "IsNan", "LaneIndex", "Lookup", "LRint", "Max", "MaxNum", "Min", "MinNum", "MulAdd", "RcpApprox",
    "ReduceDown", "ReduceNearest", "Round", "RsqrtApprox", "ScaleF", "Select", "Significand", "ShiftRightArithmetic",
    "ShiftRightLogical", "Sqrt", "ToInt", "Trunc", "External",
    # functions, kernels, threads
    "Function", "function", "Module", "CompiledModule", "Library", "Routine", "Kernel", "kernel", "kernel_of", "travels_as", "map_blocks",
    "configure_threads", "thread_settings", "configure_tiers", "finish_tiers", "RoutineCall", "routine_call", "pure_call", "site_choice", "site_probe", "explain",
    "plan", "Plan", "PlanStaleError", "Range", "Rows", "register_variants", "split_precision", "flow", "hint", "syntax", "from_glsl", "from_spirv", "set_glsl_builtins",
    # errors
    "ReactorError", "DSLTypeError", "WidthMismatchError", "ScopeError", "ControlFlowError", "LoopLimitError",
    "MissingReturnError", "ArityError", "ArgumentError", "FmaDisabledError", "CompileError", "hide_frames_of",
    "MissingDependencyError", "require",
]
