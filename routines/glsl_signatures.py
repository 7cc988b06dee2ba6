"""GLSL's signatures of its built-in functions (GLSL 4.50, section 8; the names of the types as there:
``genType`` is float, vec2, vec3 or vec4, ``genDType`` their double forms, ``genIType`` int and ivec,
``genUType`` uint and uvec, ``genBType`` bool and bvec), and one sentence of meaning for the rows of
``routines.glsl``'s tables, from which its docstrings are made (``help(routines.glsl.mix)``)."""
from __future__ import annotations

import inspect
import typing

_F, _D, _I, _U = "genType", "genDType", "genIType", "genUType"


def _forms(pattern: str, *types: str) -> tuple[str, ...]:
    """``pattern`` with ``{T}`` replaced by each type (``"{T} abs({T} x)"`` for genType, genIType ...)."""
    return tuple(pattern.format(T=t) for t in types)


def _scalar_too(pattern: str, *types: tuple[str, str]) -> tuple[str, ...]:
    """For each ``(genType, scalar)`` pair, ``pattern`` with ``{S}`` the vector type, then with ``{S}``
    its scalar: ``{T} min({T} x, {S} y)`` gives ``genType min(genType x, genType y)`` and
    ``genType min(genType x, float y)``."""
    return tuple(pattern.format(T=gen, S=s) for gen, one in types for s in (gen, one))


#: GLSL name -> its GLSL signatures.
SIGNATURES: dict[str, tuple[str, ...]] = {
    # 8.1 angle and trigonometry
    "radians": (f"{_F} radians({_F} degrees)",),
    "degrees": (f"{_F} degrees({_F} radians)",),
    **{name: (f"{_F} {name}({_F} angle)",) for name in ("sin", "cos", "tan")},
    **{name: (f"{_F} {name}({_F} x)",) for name in ("asin", "acos", "sinh", "cosh", "tanh")},
    "atan": (f"{_F} atan({_F} y, {_F} x)", f"{_F} atan({_F} y_over_x)"),
    "atan2": (f"{_F} atan({_F} y, {_F} x)",),
    # 8.2 exponential
    "pow": (f"{_F} pow({_F} x, {_F} y)",),
    **{name: (f"{_F} {name}({_F} x)",) for name in ("exp", "log", "exp2", "log2")},
    "sqrt": _forms("{T} sqrt({T} x)", _F, _D),
    "inversesqrt": _forms("{T} inversesqrt({T} x)", _F, _D),
    # 8.3 common
    "abs": _forms("{T} abs({T} x)", _F, _I, _D),
    "sign": _forms("{T} sign({T} x)", _F, _I, _D),
    **{name: _forms(f"{{T}} {name}({{T}} x)", _F, _D) for name in ("floor", "trunc", "round", "roundEven", "ceil",
                                                            "fract")},
    "mod": _scalar_too("{T} mod({T} x, {S} y)", (_F, "float"), (_D, "double")),
    "min": _scalar_too("{T} min({T} x, {S} y)", (_F, "float"), (_D, "double"), (_I, "int"), (_U, "uint")),
    "max": _scalar_too("{T} max({T} x, {S} y)", (_F, "float"), (_D, "double"), (_I, "int"), (_U, "uint")),
    "clamp": _scalar_too("{T} clamp({T} x, {S} minVal, {S} maxVal)", (_F, "float"), (_D, "double"), (_I, "int"),
                         (_U, "uint")),
    "mix": (*_scalar_too("{T} mix({T} x, {T} y, {S} a)", (_F, "float"), (_D, "double")),
            *_forms("{T} mix({T} x, {T} y, genBType a)", _F, _D, _I, _U, "genBType")),
    "step": _scalar_too("{T} step({S} edge, {T} x)", (_F, "float"), (_D, "double")),
    "smoothstep": _scalar_too("{T} smoothstep({S} edge0, {S} edge1, {T} x)", (_F, "float"), (_D, "double")),
    "isnan": _forms("genBType isnan({T} x)", _F, _D),
    "isinf": _forms("genBType isinf({T} x)", _F, _D),
    "floatBitsToInt": (f"{_I} floatBitsToInt({_F} value)",),
    "floatBitsToUint": (f"{_U} floatBitsToUint({_F} value)",),
    "intBitsToFloat": (f"{_F} intBitsToFloat({_I} value)",),
    "uintBitsToFloat": (f"{_F} uintBitsToFloat({_U} value)",),
    "fma": _forms("{T} fma({T} a, {T} b, {T} c)", _F, _D),
    # 8.4 floating-point pack and unpack
    "packUnorm2x16": ("uint packUnorm2x16(vec2 v)",),
    "packSnorm2x16": ("uint packSnorm2x16(vec2 v)",),
    "packUnorm4x8": ("uint packUnorm4x8(vec4 v)",),
    "packSnorm4x8": ("uint packSnorm4x8(vec4 v)",),
    "unpackUnorm2x16": ("vec2 unpackUnorm2x16(uint p)",),
    "unpackSnorm2x16": ("vec2 unpackSnorm2x16(uint p)",),
    "unpackUnorm4x8": ("vec4 unpackUnorm4x8(uint p)",),
    "unpackSnorm4x8": ("vec4 unpackSnorm4x8(uint p)",),
    "packHalf2x16": ("uint packHalf2x16(vec2 v)",),
    "unpackHalf2x16": ("vec2 unpackHalf2x16(uint v)",),
    # 8.5 geometric
    "length": ("float length(genType x)", "double length(genDType x)"),
    "distance": ("float distance(genType p0, genType p1)", "double distance(genDType p0, genDType p1)"),
    "dot": ("float dot(genType x, genType y)", "double dot(genDType x, genDType y)"),
    "cross": ("vec3 cross(vec3 x, vec3 y)", "dvec3 cross(dvec3 x, dvec3 y)"),
    "normalize": _forms("{T} normalize({T} x)", _F, _D),
    "faceforward": _forms("{T} faceforward({T} N, {T} I, {T} Nref)", _F, _D),
    "reflect": _forms("{T} reflect({T} I, {T} N)", _F, _D),
    "refract": (f"{_F} refract({_F} I, {_F} N, float eta)", f"{_D} refract({_D} I, {_D} N, double eta)"),
    # 8.6 matrix (square forms: reactor's matrices are mat2, mat3, mat4)
    "matrixCompMult": ("mat matrixCompMult(mat x, mat y)",),
    "outerProduct": tuple(f"mat{n} outerProduct(vec{n} c, vec{n} r)" for n in (2, 3, 4)),
    "transpose": tuple(f"mat{n} transpose(mat{n} m)" for n in (2, 3, 4)),
    "determinant": tuple(f"float determinant(mat{n} m)" for n in (2, 3, 4)),
    "inverse": tuple(f"mat{n} inverse(mat{n} m)" for n in (2, 3, 4)),
    # 8.7 vector relational
    **{name: _forms(f"bvec {name}({{T}} x, {{T}} y)", "vec", "ivec", "uvec")
       for name in ("lessThan", "lessThanEqual", "greaterThan", "greaterThanEqual")},
    **{name: _forms(f"bvec {name}({{T}} x, {{T}} y)", "vec", "ivec", "uvec", "bvec") for name in ("equal", "notEqual")},
    "any": ("bool any(bvec x)",),
    "all": ("bool all(bvec x)",),
    "not_": ("bvec not(bvec x)",),
}

#: GLSL name -> what it computes, for the built-ins made from a table row (the others say it in
#: their own docstrings).
MEANINGS: dict[str, str] = {
    "radians": "Degrees to radians: degrees * pi / 180.",
    "degrees": "Radians to degrees: radians * 180 / pi.",
    "sin": "The sine of an angle in radians.",
    "cos": "The cosine of an angle in radians.",
    "tan": "The tangent of an angle in radians.",
    "asin": "The arc sine, in [-pi/2, pi/2]; NaN for |x| > 1.",
    "acos": "The arc cosine, in [0, pi]; NaN for |x| > 1.",
    "sinh": "The hyperbolic sine, (e^x - e^-x) / 2.",
    "cosh": "The hyperbolic cosine, (e^x + e^-x) / 2.",
    "tanh": "The hyperbolic tangent, sinh(x) / cosh(x).",
    "pow": "x raised to the power y (GLSL leaves x < 0, and x = 0 with y <= 0, undefined).",
    "exp": "The natural exponentiation, e^x.",
    "log": "The natural logarithm; NaN for x < 0, -inf for 0.",
    "exp2": "2 raised to the power x.",
    "log2": "The base-2 logarithm; NaN for x < 0, -inf for 0.",
    "sqrt": "The square root; NaN for x < 0.",
    "inversesqrt": "1 / sqrt(x); +inf for +0, NaN for x < 0.",
    "abs": "The absolute value.",
    "sign": "1.0 if x > 0, -1.0 if x < 0, else x (0 keeps its sign, NaN stays NaN); for ints 1, -1 or 0.",
    "floor": "The nearest whole number less than or equal to x.",
    "ceil": "The nearest whole number greater than or equal to x.",
    "trunc": "The nearest whole number whose magnitude is not larger than x's (toward zero).",
    "round": "The nearest whole number; halves away from zero (GLSL lets the implementation choose).",
    "roundEven": "The nearest whole number; halves to the even one.",
    "fract": "x - floor(x), rounded to nearest (so fract(-1e-9) is 1.0).",
    "mod": "x - y * floor(x / y).",
    "min": "y if y < x, else x (a NaN x gives y; GLSL leaves NaN undefined).",
    "max": "y if x < y, else x (a NaN x gives y; GLSL leaves NaN undefined).",
    "clamp": "min(max(x, minVal), maxVal).",
    "mix": "x * (1 - a) + y * a, the linear blend; with a Boolean a, y where a is true and x elsewhere.",
    "step": "0.0 where x < edge, else 1.0.",
    "smoothstep": "The Hermite interpolation t * t * (3 - 2 t), t = clamp((x - edge0) / (edge1 - edge0), 0, 1).",
    "isnan": "True where x is a NaN.",
    "isinf": "True where x is an infinity of either sign.",
    "floatBitsToInt": "The bits of a float as a signed int (no conversion).",
    "floatBitsToUint": "The bits of a float as an unsigned int (no conversion).",
    "intBitsToFloat": "The bits of an int as a float (no conversion).",
    "uintBitsToFloat": "The bits of a uint as a float (no conversion).",
    "fma": "a * b + c; GLSL lets it round once or twice, unless its result is consumed by a precise variable.",
    "lessThan": "x < y, per component.",
    "lessThanEqual": "x <= y, per component.",
    "greaterThan": "x > y, per component.",
    "greaterThanEqual": "x >= y, per component.",
    "equal": "x == y, per component.",
    "notEqual": "x != y, per component (true with a NaN).",
    "any": "True if any component of x is true (per lane).",
    "all": "True only if every component of x is true (per lane).",
}

ROUTINE_NOTE = ("Precision: the precision in scope (reactor.precision, a kernel's precision=; GLSL's highp is "
                "'full', mediump 'relaxed'), or precision= on the call; fma=None follows the build's FMA "
                "option, fma=True/False sets it for the call.")
FMA_NOTE = ("Fused (one rounding) if and only if the build's FMA option is on (fma=, reactor.fma_mode): "
            "reactor.MulAdd, the FMA toggle; reactor.Fma always fuses.")
EXACT_NOTE = "Exact, or a few correctly rounded steps: no precision= option."


def docstring(name: str, fn: typing.Callable[..., typing.Any], routine: bool) -> str:
    """The docstring of GLSL built-in ``name``: GLSL's signatures, its meaning (the table's, else
    ``fn``'s own docstring), and how precision and FMA apply. A name GLSL lacks is a KeyError."""
    signatures = SIGNATURES[name]
    own = inspect.cleandoc(fn.__doc__ or "")
    meaning = MEANINGS.get(name) or own
    if name in MEANINGS and own and not own.startswith("GLSL"):
        meaning += "\n\n" + own
    per_component = getattr(fn, "kind", None) == "componentwise"
    lines = ["GLSL: " + signatures[0]] + ["      " + s for s in signatures[1:]]
    note = FMA_NOTE if name == "fma" else ROUTINE_NOTE if routine else EXACT_NOTE
    where = "Per component on vectors; scalars broadcast against vectors.\n\n" if per_component else ""
    return "\n".join(lines) + "\n\n" + meaning + "\n\n" + where + note
