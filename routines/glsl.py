"""The GLSL built-in functions (GLSL.std.450 and GLSL's vector relational set), over DSL values.

Use them as a shader does, on scalars, GLSL vectors (``vec3`` ...) and matrices::

    from routines import glsl as gl
    from reactor import vec3, kernel, Float

    @kernel(precision="relaxed")                       # precision mediump float;
    def shade(x: Float, y: Float) -> Float:
        n = gl.normalize(vec3(x, y, 1.0))
        h = gl.fract(gl.sin(gl.dot(n.xy, vec2(12.9898, 78.233))) * 43758.5453)
        with reactor.precision("full"):                # highp for this block
            spec = gl.pow(gl.max(gl.dot(n, vec3(0.0, 0.0, 1.0)), 0.0), 32.0)
        return gl.mix(h, spec, 0.5)

Every function is a row of a table: ``COMPONENTWISE`` (applied to each
component, scalars broadcasting against vectors as in GLSL: ``clamp(v, 0.0,
1.0)``, ``mix(a, b, 0.5)``, ``step(0.5, v)``), ``GEOMETRIC`` (whole vectors:
``dot``, ``cross``, ``normalize`` ...), ``RELATIONAL`` (``lessThan`` ... giving
``bvec``; ``any``, ``all``, ``not_``) and ``MATRIX``. ``BUILTINS`` has them all.
The routines (``exp2 ... pow``, ``sqrt``, ``inversesqrt``, trigonometry) follow
the precision in scope (``reactor.precision``, the kernel's ``precision=``
option; GLSL's ``highp``/``mediump`` are accepted names) and take a per-call
``precision=`` override; the others are exact or a few correctly rounded steps.

Semantics where GLSL leaves a choice: ``round`` rounds halves away from zero
(``roundEven`` to even); ``min``/``max``/``clamp`` give the second operand of a
comparison with NaN (GLSL leaves it undefined); ``sign`` keeps ``±0`` and NaN;
``fract(x) = x - floor(x)`` rounded to nearest (``fract(-1e-9) = 1.0``); ``mod(x,
y) = x - y * floor(x / y)``; ``normalize(v) = v * inversesqrt(dot(v, v))``. GLSL's
``not`` is ``not_`` (``not`` is a Python keyword). Importing ``*`` from here
shadows Python's ``abs``, ``min``, ``max``, ``round``, ``pow``, ``any`` and ``all``
with these, as in a shader.
"""
from __future__ import annotations

import builtins
import inspect
import math
import typing

import reactor
from reactor import (
    Abs, As, Ceil, CopySign, DSLTypeError, Float, Floor, Fract, IsInf, IsNan, Mat, Max, Min, MulAdd, Round, Select,
    Trunc, Value, Vec, mat_type, vec_type,
)

from . import trig
from . import exponential, logarithm, power, reciprocal
from . import glsl_signatures as _signatures

Scalar = typing.Union[Value, float, int, bool]
Operand = typing.Union[Scalar, Vec]


# -- applying a scalar function to each component ------------------------------------------------

def _size(name: str, args) -> int | None:
    """The common size of the vector arguments (None: all scalars)."""
    sizes = {a.size for a in args if isinstance(a, Vec)}
    if len(sizes) > 1:
        raise DSLTypeError(f"{name}: vector arguments of different sizes ({', '.join(map(str, sorted(sizes)))})")
    if builtins.any(isinstance(a, Mat) for a in args):
        raise DSLTypeError(f"{name} takes scalars and vectors, not matrices (matrixCompMult ... for those)")
    return sizes.pop() if sizes else None


def _per_component(name: str, fn: typing.Callable[..., Value], args) -> typing.Any:
    n = _size(name, args)
    if n is None:
        return fn(*args)
    comps = [fn(*(a[i] if isinstance(a, Vec) else a for a in args)) for i in range(n)]
    return vec_type(comps[0].kind, n)._of(comps)


class Builtin:
    """One GLSL built-in: ``name(args...)`` on scalars and vectors; ``routine`` ones take
    ``precision=`` (and ``fma=``) like the routines they call."""

    def __init__(self, name: str, arity: int, scalar: typing.Callable[..., typing.Any], kind: str,
                 routine: bool = False, doc: str = "") -> None:
        self.name, self.arity, self.scalar, self.kind, self.routine = name, arity, scalar, kind, routine
        self.__name__ = self.__qualname__ = name
        self.__doc__ = doc

    def __call__(self, *args: typing.Any, **options: typing.Any) -> typing.Any:
        if len(args) != self.arity:
            raise reactor.ArityError(f"{self.name} takes {self.arity} argument(s), got {len(args)}")
        if options and not self.routine:
            raise DSLTypeError(f"{self.name} takes no options ({', '.join(options)}): it is exact or correctly "
                               f"rounded at every precision")
        fn = self.scalar
        if options:
            def fn(*a, _f=self.scalar):
                return _f(*a, **options)
        if self.kind == "componentwise":
            return _per_component(self.name, fn, args)
        return fn(*args)

    def __repr__(self) -> str:
        return f"<GLSL built-in {self.name}>"


# -- scalar definitions ------------------------------------------------------------------------

def _value(x, like=None) -> Value:
    """``x`` as a DSL value (a Python number: a Float constant, or an Int one next to Int values)."""
    if isinstance(x, Value):
        return x
    if isinstance(x, bool):
        return reactor.Bool(x)
    if isinstance(like, Value) and like.kind.is_integer and isinstance(x, int):
        return type(like)(x) if like.width == 1 else reactor.vector_type(like.kind.name, 1)(x)
    return Float(float(x))


def _sign(x):
    x = _value(x)
    one = 1 if x.kind.is_integer else 1.0
    return Select(x > 0, one, Select(x < 0, -one, x))


def _round_half_away(x):
    x = _value(x)
    t = Trunc(x)
    return Select(Abs(x - t) >= 0.5, t + CopySign(1.0, x), t)


def _mod(x, y):
    return _value(x) % y


def _clamp(x, lo, hi):
    return Min(Max(x, lo), hi)


def _mix(x, y, a):
    if isinstance(a, Value) and a.kind.category == "bool" or isinstance(a, bool):
        return Select(_value(a), y, x)
    return x * (1.0 - a) + y * a


def _step(edge, x):
    return Select(_value(x) < edge, 0.0, 1.0)


def _smoothstep(e0, e1, x):
    t = _clamp((_value(x) - e0) / (_value(e1) - e0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def _radians(x):
    return _value(x) * (math.pi / 180.0)


def _degrees(x):
    return _value(x) * (180.0 / math.pi)


def _atan(y, x=None, **options):
    return trig.atan(y, **options) if x is None else trig.atan2(y, x, **options)


def _bits(kind):
    def convert(x):
        x = _value(x)
        return As(reactor.vector_type(kind, x.width), x)
    return convert


def _float_of_bits(x):
    x = _value(x)
    return As(reactor.vector_type("Float", x.width), x)


# name: (arity, scalar implementation, a routine that follows the precision)
_COMPONENTWISE_ROWS: dict[str, tuple[int, typing.Callable[..., typing.Any], bool]] = {
    "abs": (1, lambda x: Abs(_value(x)), False),
    "sign": (1, _sign, False),
    "floor": (1, lambda x: Floor(_value(x)), False),
    "ceil": (1, lambda x: Ceil(_value(x)), False),
    "trunc": (1, lambda x: Trunc(_value(x)), False),
    "round": (1, _round_half_away, False),
    "roundEven": (1, lambda x: Round(_value(x)), False),
    "fract": (1, lambda x: Fract(_value(x)), False),
    "mod": (2, _mod, False),
    "min": (2, lambda a, b: Min(_value(a, b), b), False),
    "max": (2, lambda a, b: Max(_value(a, b), b), False),
    "clamp": (3, lambda x, lo, hi: _clamp(_value(x, lo), lo, hi), False),
    "mix": (3, _mix, False),
    "step": (2, _step, False),
    "smoothstep": (3, _smoothstep, False),
    "fma": (3, lambda a, b, c: MulAdd(_value(a), b, c), False),
    "radians": (1, _radians, False),
    "degrees": (1, _degrees, False),
    "isnan": (1, lambda x: IsNan(_value(x)), False),
    "isinf": (1, lambda x: IsInf(_value(x)), False),
    "floatBitsToInt": (1, _bits("Int"), False),
    "floatBitsToUint": (1, _bits("UInt"), False),
    "intBitsToFloat": (1, _float_of_bits, False),
    "uintBitsToFloat": (1, _float_of_bits, False),
    "sqrt": (1, reciprocal.sqrt, True),
    "inversesqrt": (1, reciprocal.rsqrt, True),
    "exp": (1, exponential.exp, True),
    "exp2": (1, exponential.exp2, True),
    "log": (1, logarithm.log, True),
    "log2": (1, logarithm.log2, True),
    "pow": (2, power.pow, True),
    "sin": (1, trig.sin, True),
    "cos": (1, trig.cos, True),
    "tan": (1, trig.tan, True),
    "asin": (1, trig.asin, True),
    "acos": (1, trig.acos, True),
    "atan": (1, _atan, True),  # atan(y_over_x); atan(y, x) is the two-argument row below
    "sinh": (1, trig.sinh, True),
    "cosh": (1, trig.cosh, True),
    "tanh": (1, trig.tanh, True),
}

COMPONENTWISE = {name: Builtin(name, arity, fn, "componentwise", routine, f"GLSL {name}, per component.")
                 for name, (arity, fn, routine) in _COMPONENTWISE_ROWS.items()}
_atan2 = Builtin("atan", 2, _atan, "componentwise", True, "GLSL atan(y, x), per component.")


def atan(y: Operand, x: Operand | None = None, **options: typing.Any) -> typing.Any:
    """GLSL ``atan(y_over_x)`` in [-pi/2, pi/2], or ``atan(y, x)`` in [-pi, pi] by the signs of both."""
    return COMPONENTWISE["atan"](y, **options) if x is None else _atan2(y, x, **options)


# -- geometric functions: whole vectors --------------------------------------------------------

def _components(v) -> list:
    return list(v) if isinstance(v, Vec) else [v]


def dot(x: Operand, y: Operand) -> Value:
    """The sum of the products of the components (``x * y`` for scalars)."""
    a, b = _components(x), _components(y)
    if len(a) != len(b):
        raise DSLTypeError(f"dot: vectors of different sizes ({len(a)} and {len(b)})")
    acc = _value(a[0]) * b[0]
    for u, v in zip(a[1:], b[1:]):
        acc = acc + u * v
    return acc


def length(x: Operand, **options: typing.Any) -> Value:
    """``sqrt(dot(x, x))``; ``abs(x)`` for a scalar."""
    if not isinstance(x, Vec):
        return Abs(_value(x))
    return reciprocal.sqrt(dot(x, x), **options)


def distance(p0: Operand, p1: Operand, **options: typing.Any) -> Value:
    """``length(p0 - p1)``."""
    return length(p0 - p1, **options)


def cross(x: Vec, y: Vec) -> Vec:
    """The cross product of two ``vec3``."""
    if not (isinstance(x, Vec) and isinstance(y, Vec) and x.size == y.size == 3):
        raise DSLTypeError("cross takes two vec3")
    return vec_type(x.kind, 3)(x.y * y.z - y.y * x.z, x.z * y.x - y.z * x.x, x.x * y.y - y.x * x.y)


def normalize(x: Operand, **options: typing.Any) -> typing.Any:
    """``x`` scaled to length 1 (``x * inversesqrt(dot(x, x))``): ±1 for a scalar, NaN for zero."""
    if not isinstance(x, Vec):
        return _value(x) * reciprocal.rsqrt(_value(x) * x, **options)
    return x * reciprocal.rsqrt(dot(x, x), **options)


def faceforward(n: Operand, i: Operand, nref: Operand) -> typing.Any:
    """``n`` if ``dot(nref, i) < 0``, else ``-n``."""
    return reactor.Select(dot(nref, i) < 0.0, n, -n)


def reflect(i: Operand, n: Operand) -> typing.Any:
    """The reflection of incident ``i`` about the (normalized) normal ``n``: ``i - 2 dot(n, i) n``."""
    return i - 2.0 * dot(n, i) * n


def refract(i: Operand, n: Operand, eta: Scalar, **options: typing.Any) -> typing.Any:
    """The refraction of ``i`` through a surface of normal ``n`` with ratio ``eta`` (zero on total
    internal reflection); ``i`` and ``n`` normalized."""
    d = dot(n, i)
    k = 1.0 - eta * eta * (1.0 - d * d)
    out = eta * i - (eta * d + reciprocal.sqrt(Max(k, 0.0), **options)) * n
    return reactor.Select(k < 0.0, out * 0.0 if not isinstance(out, Vec) else type(out)(0.0), out)


GEOMETRIC = {f.__name__: f for f in (dot, length, distance, cross, normalize, faceforward, reflect, refract)}


# -- vector relational functions ---------------------------------------------------------------

def _relation(name: str, op: str) -> Builtin:
    compare = {"lt": lambda a, b: _value(a, b) < b, "le": lambda a, b: _value(a, b) <= b,
               "gt": lambda a, b: _value(a, b) > b, "ge": lambda a, b: _value(a, b) >= b,
               "eq": lambda a, b: _value(a, b) == b, "ne": lambda a, b: _value(a, b) != b}[op]
    return Builtin(name, 2, compare, "componentwise", doc=f"GLSL {name}: a bvec, per component.")


def _reduce_components(name: str, combine) -> typing.Callable[[typing.Any], Value]:
    def reduce(v):
        if not isinstance(v, Vec) or v.kind.category != "bool":
            raise DSLTypeError(f"{name} takes a bvec (as lessThan(...) gives), not {v!r}")
        acc = v[0]
        for c in list(v)[1:]:
            acc = combine(acc, c)
        return acc
    reduce.__name__ = name
    reduce.__doc__ = f"GLSL {name}: the components of a bvec, combined (per lane)."
    return reduce


def not_(v: Vec) -> Vec:
    """GLSL ``not``: each component of a bvec negated."""
    if not isinstance(v, Vec) or v.kind.category != "bool":
        raise DSLTypeError(f"not_ takes a bvec, not {v!r}")
    return ~v


RELATIONAL: dict[str, typing.Callable[..., typing.Any]] = {
    **{name: _relation(name, op) for name, op in (("lessThan", "lt"), ("lessThanEqual", "le"),
                                                  ("greaterThan", "gt"), ("greaterThanEqual", "ge"),
                                                  ("equal", "eq"), ("notEqual", "ne"))},
    "any": _reduce_components("any", lambda a, b: a | b),
    "all": _reduce_components("all", lambda a, b: a & b),
    "not_": not_,
}


# -- matrix functions --------------------------------------------------------------------------

def transpose(m: Mat) -> Mat:
    """The transposed matrix."""
    return m.transpose()


def matrixCompMult(a: Mat, b: Mat) -> Mat:  # noqa: N802 - GLSL's name
    """The product of corresponding components (GLSL's ``*`` is the linear-algebra product)."""
    if not (isinstance(a, Mat) and isinstance(b, Mat) and a.size == b.size):
        raise DSLTypeError("matrixCompMult takes two matrices of one size")
    return type(a)._of([x * y for x, y in zip(a, b)])


def outerProduct(c: Vec, r: Vec) -> Mat:  # noqa: N802 - GLSL's name
    """The matrix ``c r^T`` (square: ``c`` and ``r`` of one size)."""
    if not (isinstance(c, Vec) and isinstance(r, Vec) and c.size == r.size):
        raise DSLTypeError("outerProduct takes two vectors of one size (square matrices only)")
    return mat_type(c.size)._of([c * r[j] for j in range(r.size)])


def determinant(m: Mat) -> Value:
    """The determinant (cofactor expansion along the first column)."""
    n = m.size
    if n == 2:
        return m[0][0] * m[1][1] - m[1][0] * m[0][1]
    cols = list(m)
    total: typing.Any = None
    for i in range(n):
        minor = mat_type(n - 1)._of([vec_type("Float", n - 1)._of([cols[j][r] for r in range(n) if r != i])
                                     for j in range(1, n)])
        term = cols[0][i] * determinant(minor)
        total = term if total is None else (total + term if i % 2 == 0 else total - term)
    return total


def inverse(m: Mat) -> Mat:
    """The inverse (adjugate over determinant; undefined for a singular matrix, as in GLSL)."""
    n = m.size
    cols = list(m)
    rcp = 1.0 / determinant(m)
    out_cols = []
    for j in range(n):  # column j, row i of the inverse: the cofactor of row j, column i of m
        comps = []
        for i in range(n):
            sign = 1.0 if (i + j) % 2 == 0 else -1.0
            if n == 2:
                minor_det = cols[1 - i][1 - j]
            else:
                minor_det = determinant(mat_type(n - 1)._of(
                    [vec_type("Float", n - 1)._of([cols[c][r] for r in range(n) if r != j])
                     for c in range(n) if c != i]))
            comps.append(sign * minor_det * rcp)
        out_cols.append(vec_type("Float", n)._of(comps))
    return mat_type(n)._of(out_cols)


MATRIX = {f.__name__: f for f in (transpose, matrixCompMult, outerProduct, determinant, inverse)}


# -- packing: channels in a uint (GLSL's packUnorm4x8 ...; routines.pixels has the formats) -----------

def _packer(fmt: str, count: int, bits: int):
    from . import pixels

    def pack(v):
        comps = list(v) if isinstance(v, Vec) else None
        if comps is None or len(comps) != count:
            raise DSLTypeError(f"pack{fmt.title()}{count}x{bits} takes a vec{count}, not {v!r}")
        out = None
        for k, c in enumerate(comps):
            code = pixels.encode(c, f"{fmt}{bits}")
            u32 = reactor.vector_type("UInt", code.width)
            part = u32(code) << (bits * k)
            out = part if out is None else out | part
        return out

    def unpack(u):
        if not isinstance(u, Value) or u.kind.name != "UInt":
            raise DSLTypeError(f"unpack{fmt.title()}{count}x{bits} takes a uint, not {u!r}")
        kind = "UByte" if bits == 8 else "UShort"
        comps = [pixels.decode(reactor.vector_type(kind, u.width)((u >> (bits * k)) & ((1 << bits) - 1)),
                               f"{fmt}{bits}") for k in range(count)]
        return vec_type("Float", count)._of(comps)
    return pack, unpack


def packHalf2x16(v: Vec) -> Value:  # noqa: N802 - GLSL's name
    """Two float16 (rounded to nearest even, NaN and inf kept) in a uint, x in the low half."""
    if not isinstance(v, Vec) or v.size != 2:
        raise DSLTypeError(f"packHalf2x16 takes a vec2, not {v!r}")
    halves = [reactor.As(reactor.vector_type("UShort", c.width), reactor.vector_type("Half", c.width)(c))
              for c in v]
    u32 = reactor.vector_type("UInt", halves[0].width)
    return u32(halves[0]) | (u32(halves[1]) << 16)


def unpackHalf2x16(u: Value) -> Vec:  # noqa: N802 - GLSL's name
    """The vec2 of two float16 in a uint (exact)."""
    if not isinstance(u, Value) or u.kind.name != "UInt":
        raise DSLTypeError(f"unpackHalf2x16 takes a uint, not {u!r}")
    comps = [reactor.vector_type("Float", u.width)(reactor.As(reactor.vector_type("Half", u.width),
                                                              reactor.vector_type("UShort", u.width)(part)))
             for part in (u & 0xFFFF, u >> 16)]
    return vec_type("Float", 2)._of(comps)


PACKING: dict[str, typing.Callable[..., typing.Any]] = {"packHalf2x16": packHalf2x16,
                                                        "unpackHalf2x16": unpackHalf2x16}
for _fmt, _lanes, _width in (("unorm", 4, 8), ("snorm", 4, 8), ("unorm", 2, 16), ("snorm", 2, 16)):
    _pack, _unpack = _packer(_fmt, _lanes, _width)
    _pack.__name__ = f"pack{_fmt.title()}{_lanes}x{_width}"
    _unpack.__name__ = f"unpack{_fmt.title()}{_lanes}x{_width}"
    _pack.__doc__ = f"GLSL's {_pack.__name__}: {_lanes} channels as {_fmt}{_width} codes in a uint, first lowest."
    _unpack.__doc__ = f"GLSL's {_unpack.__name__}: the vec{_lanes} of a uint of {_fmt}{_width} codes."
    PACKING[_pack.__name__], PACKING[_unpack.__name__] = _pack, _unpack

def atan2(y: Operand, x: Operand, **options: typing.Any) -> typing.Any:
    """``atan(y, x)`` under the name of C, HLSL and ``routines.atan2`` (GLSL spells it ``atan``)."""
    return _atan2(y, x, **options)


BUILTINS: dict[str, typing.Callable[..., typing.Any]] = {
    **COMPONENTWISE, "atan": atan, "atan2": atan2, **GEOMETRIC, **RELATIONAL, **MATRIX, **PACKING}


def _takes_precision(fn: typing.Callable[..., typing.Any]) -> bool:
    """Whether a built-in follows the precision (a routine row, or a function passing options on)."""
    if isinstance(fn, Builtin):
        return fn.routine
    return any(p.kind is p.VAR_KEYWORD for p in inspect.signature(fn).parameters.values())


for _name, _builtin in BUILTINS.items():  # docstrings: GLSL's signatures, meaning, precision and FMA
    _builtin.__doc__ = _signatures.docstring(_name, _builtin, _takes_precision(_builtin))
del _name, _builtin

globals().update(BUILTINS)

__all__ = sorted(BUILTINS)
