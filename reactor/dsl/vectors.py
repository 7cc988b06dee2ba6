"""GLSL vectors and matrices: structures of per-lane DSL values.

A ``vec3`` holds three DSL values of one kind and width (one SIMD value per
component, as SwiftShader's SPIR-V backend holds them), so a kernel's
``vec3`` is three ``Float16`` in registers::

    n = vec3(nx, ny, nz)                 # components: numbers, scalars or lanes
    l = vec3(0.3, 0.8, 0.5)
    c = vec4(n.zyx * 0.5 + 0.5, 1.0)     # swizzles, constructors as in GLSL
    v = Variable(vec3, 0.0)              # mutable (per lane), v.xy = ..., v.set(...)
    m = mat3(c0, c1, c2)                 # column-major; m @ v, v @ m, m @ m

Kinds and sizes are a table (``VECTORS``): ``vec2..4`` (Float), ``dvec``
(Double), ``ivec`` (Int), ``uvec`` (UInt), ``bvec`` (Bool), ``u8vec``,
``u16vec``, ``f16vec`` (UByte, UShort, Half: pixels and texels); ``mat2..4``
(Float, square). Operators act per component, with Python numbers, DSL
scalars and vectors of the same size on either side; ``%`` is GLSL's
``mod`` and ``**`` is ``pow``. Comparisons give a ``bvec`` per component
(NumPy's convention: GLSL's ``equal``/``lessThan``); ``any``/``all`` reduce
a bvec. ``Select(mask, a, b)`` takes vectors too. Matrix products are
``@`` (a ``*`` between a matrix and a vector is an error naming ``@``).
"""
from __future__ import annotations

from . import builtins as _numpy

import typing

from ..errors import DSLTypeError, ScopeError
from ..ir import emitter as _em
from ..ir.types import KINDS, Kind, VType
from .intrinsics import SELECT_FORMS, Select
from .values import Value, binary, comparison, shown, unary, value_class
from .variables import VARIABLE_FORMS, Variable, per_lane

_SWIZZLE_SETS = ("xyzw", "rgba", "stpq")
_OPERATORS = {
    "add": ("__add__", "__radd__"), "sub": ("__sub__", "__rsub__"), "mul": ("__mul__", "__rmul__"),
    "div": ("__truediv__", "__rtruediv__"), "rem": ("__mod__", "__rmod__"),
    "and": ("__and__", "__rand__"), "or": ("__or__", "__ror__"), "xor": ("__xor__", "__rxor__"),
    "shl": ("__lshift__", "__rlshift__"), "shr": ("__rshift__", "__rrshift__"),
}
_COMPARISONS = {"lt": "__lt__", "le": "__le__", "gt": "__gt__", "ge": "__ge__", "eq": "__eq__", "ne": "__ne__"}


def _scalar_kind(x) -> Kind | None:
    if isinstance(x, Value):
        return x.kind
    return None


def _as_value(x, kind: Kind) -> typing.Any:
    """A component: a DSL value of ``kind`` (numbers become constants; other kinds convert)."""
    if isinstance(x, Value):
        return x if x.kind == kind else value_class(VType(kind, x.width))(x)
    if not _em.building():  # a constant vector made at module level: numbers until used in a build
        if isinstance(x, bool) or isinstance(x, (int, float)) and kind.category != "bool":
            return (bool(x) if kind.category == "bool" else float(x) if kind.is_float else
                    _integer_component(x, kind))
        raise DSLTypeError(f"{x!r} cannot be a component of a {kind.name} vector made outside a build "
                           f"(only numbers: a constant vector)")
    if isinstance(x, bool) or (kind.category != "bool" and isinstance(x, (int, float))):
        return value_class(VType(kind, 1))(x)
    if hasattr(x, "dtype") and getattr(x, "shape", None) == ():  # a NumPy scalar
        return _as_value(x.item(), kind)
    raise DSLTypeError(f"{x!r} cannot be a component of a {kind.name} vector")


def _integer_component(x, kind: Kind) -> int:
    if isinstance(x, float) and not x.is_integer():
        raise DSLTypeError(f"{x!r} is not a whole number: it cannot be a {kind.name} component")
    return int(x)


def _swizzle(name: str) -> list[int] | None:
    for letters in _SWIZZLE_SETS:
        if all(ch in letters for ch in name):
            return [letters.index(ch) for ch in name]
    return None


def _per_lane_pick(items: list, index: Value) -> Value:
    """``items[index]`` with an Int index that may differ per lane (GLSL's dynamic indexing of a
    vector or matrix): a select per item. An index outside the items gives the first (GLSL leaves
    it undefined)."""
    picked = items[0]
    for k in range(1, len(items)):
        picked = Select(index == k, items[k], picked)
    return picked


class Vec:
    """Base class of the vector types (``vec3`` ...): ``size`` components of one ``kind``."""

    kind: Kind
    size: int
    dsl_composite = True  # DSL scalars defer their operators to it
    __slots__ = ("_comps", "_scope")
    # np.sin(v) on a vector is GLSL's sin per component, np.clip its clamp; anything else an error
    __array_ufunc__ = _numpy.array_ufunc
    __array_function__ = _numpy.array_function

    if typing.TYPE_CHECKING:  # installed from a table (_install_vector_operators); declared for type checkers
        def __add__(self, other: typing.Any) -> typing.Any: ...
        def __radd__(self, other: typing.Any) -> typing.Any: ...
        def __sub__(self, other: typing.Any) -> typing.Any: ...
        def __rsub__(self, other: typing.Any) -> typing.Any: ...
        def __mul__(self, other: typing.Any) -> typing.Any: ...
        def __rmul__(self, other: typing.Any) -> typing.Any: ...
        def __truediv__(self, other: typing.Any) -> typing.Any: ...
        def __rtruediv__(self, other: typing.Any) -> typing.Any: ...
        def __mod__(self, other: typing.Any) -> typing.Any: ...
        def __rmod__(self, other: typing.Any) -> typing.Any: ...
        def __lt__(self, other: typing.Any) -> typing.Any: ...
        def __le__(self, other: typing.Any) -> typing.Any: ...
        def __gt__(self, other: typing.Any) -> typing.Any: ...
        def __ge__(self, other: typing.Any) -> typing.Any: ...

    def __init__(self, *args):
        if type(self) is Vec:
            raise DSLTypeError("Vec is abstract; use vec2, vec3, vec4, ivec3 ...")
        comps = self._components(args)
        object.__setattr__(self, "_comps", tuple(comps))
        object.__setattr__(self, "_scope", _em.current().scope if _em.building() else None)

    @property
    def _c(self) -> tuple[typing.Any, ...]:
        """The components as DSL values (a vector made outside any build, as GLSL's ``const vec3``
        at module level, holds numbers until it is first used in one)."""
        comps = self._comps
        if _em.building() and not all(isinstance(c, Value) for c in comps):
            return tuple(_as_value(c, self.kind) for c in comps)
        return comps

    @classmethod
    def _components(cls, args) -> list[typing.Any]:
        n, kind = cls.size, cls.kind
        if not args:
            raise DSLTypeError(f"{cls.__name__}() needs components: a scalar to fill it, or {n} values")
        if len(args) == 1 and not isinstance(args[0], (Vec, Mat)):
            return [_as_value(args[0], kind)] * n
        if len(args) == 1 and isinstance(args[0], Vec):
            if args[0].size < n:
                raise DSLTypeError(f"{cls.__name__}({type(args[0]).__name__}) needs more components "
                                   f"({args[0].size} given, {n} needed)")
            return [_as_value(c, kind) for c in args[0]._c[:n]]  # GLSL: a longer vector is truncated
        flat: list = []
        for a in args:
            flat.extend(a._c if isinstance(a, Vec) else [a])
        if len(flat) != n:
            raise DSLTypeError(f"{cls.__name__}(...) takes {n} components, got {len(flat)}")
        return [_as_value(c, kind) for c in flat]

    @classmethod
    def _of(cls, comps):
        """A vector of this class holding the values ``comps`` as they are."""
        v = object.__new__(cls)
        object.__setattr__(v, "_comps", tuple(comps))
        object.__setattr__(v, "_scope", _em.current().scope if _em.building() else None)
        return v

    # -- components and swizzles ------------------------------------------------------
    def __len__(self) -> int:
        return self.size

    def __iter__(self):
        return iter(self._c)

    def __getitem__(self, i: int | Value) -> Value:
        if isinstance(i, Value) and i.kind.name in ("Int", "UInt"):
            return _per_lane_pick(list(self._c), i)
        if not isinstance(i, int) or not -self.size <= i < self.size:
            raise DSLTypeError(f"{type(self).__name__} index must be an int in [0, {self.size}) or an Int value, "
                               f"not {i!r}")
        return self._c[i]

    def __getattr__(self, name: str):
        lanes = _swizzle(name) if name and len(name) <= 4 else None
        if lanes is None or max(lanes) >= self.size:
            raise AttributeError(f"{type(self).__name__} has no component or swizzle {name!r}")
        if len(lanes) == 1:
            return self._c[lanes[0]]
        return vec_type(self.kind, len(lanes))._of([self._c[i] for i in lanes])

    def __setattr__(self, name: str, value) -> None:
        lanes = _swizzle(name)
        if lanes is None or max(lanes) >= self.size:
            raise AttributeError(f"{type(self).__name__} has no component or swizzle {name!r}")
        if len(set(lanes)) != len(lanes):
            raise DSLTypeError(f"swizzle {name!r} names a component twice; it cannot be assigned")
        values = value._c if isinstance(value, Vec) else [value] * len(lanes)
        if len(values) != len(lanes):
            raise DSLTypeError(f"assigning {len(values)} components to swizzle {name!r}")
        self._assign(lanes, values)

    def _assign(self, lanes, values) -> None:
        if _em.building() and _em.current().scope is not self._scope:
            raise ScopeError(f"a {type(self).__name__} value made outside this block cannot be changed in it "
                             f"(the change would not follow the block's condition): declare it with "
                             f"Variable({type(self).__name__}, ...) and assign that")
        comps = list(self._c)
        for i, v in zip(lanes, values):
            comps[i] = _as_value(v, self.kind)
        object.__setattr__(self, "_comps", tuple(comps))

    def set(self, value) -> "Vec":
        raise DSLTypeError(f"a {type(self).__name__} value cannot be assigned: declare "
                           f"v = Variable({type(self).__name__}, ...) and use v.set(...)")

    @property
    def width(self) -> int:
        """The SIMD width of the components (1: uniform)."""
        return max(c.width for c in self._c)

    def __bool__(self):
        raise DSLTypeError(f"a {type(self).__name__} has no Python truth value: use any(...)/all(...) and "
                           f"If(...) for run-time branches")

    def __repr__(self) -> str:
        first = self._comps[0]
        if not isinstance(first, Value):
            return f"{type(self).__name__}({', '.join(repr(c) for c in self._comps)})"
        return f"<{type(self).__name__} of {shown(first.vtype)}>"

    __hash__ = object.__hash__

    # -- arithmetic ---------------------------------------------------------------------
    def _map(self, other, fn, what: str, kind: Kind | None = None, reverse: bool = False):
        if isinstance(other, Mat):
            return NotImplemented
        if isinstance(other, Vec):
            if other.size != self.size:
                raise DSLTypeError(f"{what}: {type(self).__name__} and {type(other).__name__} differ in size")
            pairs: typing.Iterable[tuple[typing.Any, typing.Any]] = zip(self._c, other._c)
        elif isinstance(other, (Value, int, float, bool)) or hasattr(other, "dtype"):
            pairs = ((c, other) for c in self._c)
        else:
            return NotImplemented
        out = [fn(b, a) if reverse else fn(a, b) for a, b in pairs]
        return vec_type(kind or out[0].kind, self.size)._of(out)

    def __neg__(self):
        return type(self)._of([unary("neg", c, "negation") for c in self._c])

    def __pos__(self):
        return self

    def __invert__(self):
        return type(self)._of([unary("invert", c, "operator '~'") for c in self._c])

    def __abs__(self):
        return type(self)._of([unary("abs", c, "abs") for c in self._c])

    def __pow__(self, other):
        from .values import power
        return self._map(other, power, "operator '**'")

    def __rpow__(self, other):
        from .values import power
        return self._map(other, power, "operator '**'", reverse=True)

    def __matmul__(self, other):
        if isinstance(other, Mat):  # row vector times matrix: (m^T v)
            return other.transpose() @ self
        return NotImplemented


def _install_vector_operators() -> None:
    for op, (fwd, rev) in _OPERATORS.items():
        what = f"operator '{fwd}'"
        setattr(Vec, fwd, lambda a, b, _op=op, _w=what: a._map(b, lambda x, y: binary(_op, x, y, _w), _w))
        setattr(Vec, rev, lambda a, b, _op=op, _w=what: a._map(b, lambda x, y: binary(_op, x, y, _w), _w,
                                                               reverse=True))
    for op, dunder in _COMPARISONS.items():
        setattr(Vec, dunder, lambda a, b, _op=op: a._map(b, lambda x, y: comparison(_op, x, y), "comparison",
                                                         kind=KINDS["Bool"]))


_install_vector_operators()

#: The vector and matrix type names: (kind name, name prefix).
VECTORS = (("Float", "vec"), ("Double", "dvec"), ("Int", "ivec"), ("UInt", "uvec"), ("Bool", "bvec"),
           # GL_EXT_shader_explicit_arithmetic_types' names: pixels and texels
           ("UByte", "u8vec"), ("UShort", "u16vec"), ("Half", "f16vec"))
SIZES = (2, 3, 4)
_VEC_TYPES: dict[tuple[str, int], type[Vec]] = {}


def vec_type(kind: Kind | str, size: int) -> type[Vec]:
    """The vector class of ``size`` components of ``kind`` (``vec_type("Float", 3)`` is ``vec3``)."""
    name = kind if isinstance(kind, str) else kind.name
    try:
        return _VEC_TYPES[name, size]
    except KeyError:
        raise DSLTypeError(f"no vector of {size} {name} components (sizes 2, 3, 4)") from None


def vec_doc(kind: str, size: int) -> str:
    """The docstring of the vector class of ``size`` components of ``kind``."""
    name = f"{dict(VECTORS)[kind]}{size}"
    return (f"{name}: GLSL's {name}, {size} {kind} components, each a DSL value (one per lane in a kernel's "
            f"body).\n\n{name}(s) fills it with a scalar, {name}(a, b, ...) takes components and shorter "
            f"vectors, {name}(v) truncates a longer vector; swizzles as in GLSL (v.x, v.yx); operators act per "
            f"component, comparisons give a bvec{size}.")


def mat_doc(size: int) -> str:
    """The docstring of the square Float matrix class of ``size`` columns."""
    return (f"mat{size}: GLSL's mat{size}, {size} columns of vec{size} (Float components, column-major)."
            f"\n\nmat{size}(2.0) is 2 on the diagonal, mat{size}(c0, ...) takes {size} columns or {size * size} components, "
            f"mat{size}(m) another matrix's upper-left part; m @ v, v @ m and m @ m are the linear-algebra "
            f"products, m[i] is column i.")


for _kind, _prefix in VECTORS:
    for _n in SIZES:
        _VEC_TYPES[_kind, _n] = type(f"{_prefix}{_n}", (Vec,), {"kind": KINDS[_kind], "size": _n,
                                                                 "__slots__": (), "__module__": "reactor",
                                                                 "__doc__": vec_doc(_kind, _n)})


# -- matrices --------------------------------------------------------------------------------

class Mat:
    """Base class of the square Float matrices ``mat2``, ``mat3``, ``mat4``: ``size`` columns.

    ``mat3(2.0)`` is 2 on the diagonal; ``mat3(c0, c1, c2)`` takes columns; ``mat3(a, b, ...)``
    nine scalars in column-major order; ``mat3(m4)`` the upper-left part. ``m[i]`` is column i."""

    size: int
    _cols: tuple[Vec, ...]
    dsl_composite = True
    __slots__ = ("_cols",)

    def __init__(self, *args):
        n = self.size
        column = vec_type("Float", n)
        if len(args) == 1 and isinstance(args[0], Mat):
            src = args[0]
            cols = []
            for j in range(n):
                comps = [src._cols[j]._c[i] if j < src.size and i < src.size else (1.0 if i == j else 0.0)
                         for i in range(n)]
                cols.append(column(*comps))
        elif len(args) == 1:
            d = _as_value(args[0], KINDS["Float"])
            cols = [column(*[d if i == j else 0.0 for i in range(n)]) for j in range(n)]
        elif len(args) == n and all(isinstance(a, Vec) and a.size == n for a in args):
            cols = [column(a) for a in args]
        else:
            flat: list = []
            for a in args:
                flat.extend(a._c if isinstance(a, Vec) else [a])
            if len(flat) != n * n:
                raise DSLTypeError(f"{type(self).__name__}(...) takes one scalar, {n} columns or {n * n} "
                                   f"components, got {len(flat)}")
            cols = [column(*flat[j * n:(j + 1) * n]) for j in range(n)]
        object.__setattr__(self, "_cols", tuple(cols))

    @classmethod
    def _of(cls, cols):
        m = object.__new__(cls)
        object.__setattr__(m, "_cols", tuple(cols))
        return m

    def __iter__(self) -> typing.Iterator[Vec]:
        return iter(self._cols)

    def __getitem__(self, j: int | Value) -> Vec:
        if isinstance(j, Value) and j.kind.name in ("Int", "UInt"):
            n = self.size
            return vec_type("Float", n)._of([_per_lane_pick([c._c[r] for c in self._cols], j) for r in range(n)])
        if not isinstance(j, int) or not -self.size <= j < self.size:
            raise DSLTypeError(f"{type(self).__name__} column index must be an int in [0, {self.size}) or an Int "
                               f"value, not {j!r}")
        return self._cols[j]

    def __len__(self) -> int:
        return self.size

    def transpose(self) -> "Mat":
        n = self.size
        return type(self)._of([vec_type("Float", n)._of([self._cols[j]._c[i] for j in range(n)])
                               for i in range(n)])

    def __matmul__(self, other):
        n = self.size
        if isinstance(other, Vec):
            if other.size != n:
                raise DSLTypeError(f"{type(self).__name__} @ {type(other).__name__}: sizes differ")
            acc = self._cols[0] * other._c[0]
            for j in range(1, n):
                acc = acc + self._cols[j] * other._c[j]
            return acc
        if isinstance(other, Mat):
            if other.size != n:
                raise DSLTypeError(f"{type(self).__name__} @ {type(other).__name__}: sizes differ")
            return type(self)._of([self @ col for col in other._cols])
        return NotImplemented

    def _map(self, other, fn, product: str | None = None):
        if product is not None and isinstance(other, (Mat, Vec)):
            raise DSLTypeError(f"{product}: GLSL's '*' between matrices and vectors is the linear-algebra "
                               f"product, written with '@' here (matrixCompMult for per component)")
        if isinstance(other, Mat) and other.size == self.size:
            return type(self)._of([fn(a, b) for a, b in zip(self._cols, other._cols)])
        if isinstance(other, Vec):
            raise DSLTypeError(f"{type(self).__name__} and {type(other).__name__}: a matrix and a vector "
                               f"combine only with '@'")
        if isinstance(other, (Value, int, float)) or hasattr(other, "dtype"):
            return type(self)._of([fn(a, other) for a in self._cols])
        return NotImplemented

    def __add__(self, other):
        return self._map(other, lambda a, b: a + b)

    def __sub__(self, other):
        return self._map(other, lambda a, b: a - b)

    def __mul__(self, other):
        return self._map(other, lambda a, b: a * b, f"{type(self).__name__} * {type(other).__name__}")

    def __truediv__(self, other):
        return self._map(other, lambda a, b: a / b)

    def __radd__(self, other):
        return self._map(other, lambda a, b: b + a)

    def __rsub__(self, other):
        return self._map(other, lambda a, b: b - a)

    def __rmul__(self, other):
        return self._map(other, lambda a, b: b * a, f"{type(other).__name__} * {type(self).__name__}")

    def __neg__(self):
        return type(self)._of([-c for c in self._cols])

    def __repr__(self) -> str:
        return f"<{type(self).__name__}>"


_MAT_TYPES = {n: type(f"mat{n}", (Mat,), {"size": n, "__slots__": (), "__module__": "reactor",
                                          "__doc__": mat_doc(n)}) for n in SIZES}


def mat_type(size: int) -> type[Mat]:
    """The square Float matrix class of ``size`` columns (``mat_type(3)`` is ``mat3``)."""
    return _MAT_TYPES[size]


if typing.TYPE_CHECKING:  # the classes with their operators' types: python tools/value_types.py
    from .value_types import (bvec2, bvec3, bvec4, dvec2, dvec3, dvec4, f16vec2, f16vec3, f16vec4, ivec2, ivec3,
                              ivec4, mat2, mat3, mat4, u8vec2, u8vec3, u8vec4, u16vec2, u16vec3, u16vec4, uvec2,
                              uvec3, uvec4, vec2, vec3, vec4)
else:
    globals().update({cls.__name__: cls for cls in _VEC_TYPES.values()})
    globals().update({cls.__name__: cls for cls in _MAT_TYPES.values()})


def select(mask, a, b):
    """``Select`` for vectors: per component (``mask`` a Bool value, or a bvec of the same size)."""
    size = next(v.size for v in (a, b) if isinstance(v, Vec))
    kind = next(v.kind for v in (a, b) if isinstance(v, Vec))
    masks = mask._c if isinstance(mask, Vec) else [mask] * size

    def comps(v):
        if isinstance(v, Vec):
            if v.size != size:
                raise DSLTypeError("Select: the vectors differ in size")
            return v._c
        return [v] * size
    return vec_type(kind, size)._of([Select(m, x, y) for m, x, y in zip(masks, comps(a), comps(b))])


# -- vector variables --------------------------------------------------------------------------

class _VecVariable:
    """What a vector Variable adds: its components are Variables; reading a swizzle gives a
    snapshot, assigning one (or ``set``) stores (under the lanes a per-lane block runs)."""

    __slots__ = ()

    def __getattr__(self, name: str):
        got = Vec.__getattr__(typing.cast(Vec, self), name)
        if isinstance(got, Vec):
            return type(got)._of([c.value for c in got._c])
        return got.value

    def _assign(self, lanes, values) -> None:
        for i, v in zip(lanes, values):
            self._c[i].set(v)

    def set(self, value):
        values = value._c if isinstance(value, Vec) else [value] * self.size
        if len(values) != self.size:
            raise DSLTypeError(f"{type(self).__name__}.set: {len(values)} components for {self.size}")
        for var, v in zip(self._c, values):
            var.set(v)
        return self

    @property
    def value(self) -> Vec:
        """An immutable snapshot of the current value."""
        return vec_type(self.kind, self.size)._of([c.value for c in self._c])

    # ``v += x`` stores into the variable (without these, Python would rebind ``v`` to a new value)
    def __iadd__(self, other):
        return self.set(self.value + other)

    def __isub__(self, other):
        return self.set(self.value - other)

    def __imul__(self, other):
        return self.set(self.value * other)

    def __itruediv__(self, other):
        return self.set(self.value / other)

    def __imod__(self, other):
        return self.set(self.value % other)

    def __imatmul__(self, other):
        return self.set(self.value @ other)


_VAR_TYPES: dict[type, type[Vec]] = {}


def vector_variable(type_or_value, init=None, name: str = "var"):
    """``Variable(vec3, 0.0)``, ``Variable(vec3)`` (zeros) or ``Variable(v)`` for a vector ``v``."""
    if isinstance(type_or_value, Vec):
        cls, init = type(type_or_value), type_or_value
    else:
        cls = type_or_value
    if isinstance(cls, type) and issubclass(cls, _VecVariable):
        cls = cls.__mro__[2]  # Variable of a Variable: the vector type underneath
    base = per_lane(VType(cls.kind, 1))
    start = cls(init if init is not None else (False if cls.kind.category == "bool" else 0)) \
        if not isinstance(init, Vec) else init
    if isinstance(start, Vec) and start.size != cls.size:
        raise DSLTypeError(f"Variable({cls.__name__}, ...): the initial value has {start.size} components")
    width = max([base.width] + [c.width for c in start._c])  # one width for every component
    comps = [Variable(value_class(base.with_width(width)), c, name=f"{name}.{'xyzw'[i]}")
             for i, c in enumerate(start._c)]
    return _variable_class(cls)._of(comps)


def _variable_class(cls):
    """The Variable class of the vector type ``cls``."""
    var_cls = _VAR_TYPES.get(cls)
    if var_cls is None:
        var_cls = _VAR_TYPES[cls] = type(f"Variable[{cls.__name__}]", (_VecVariable, cls),
                                         {"__slots__": (), "__module__": "reactor"})
    return var_cls


def entry_vector_variable(cls, name: str = "var"):
    """A vector Variable of type ``cls`` (per lane) declared at the function's entry, zeros there
    (it exists on every path, wherever it is first assigned)."""
    from .lanes import lanes_of
    if isinstance(cls, type) and issubclass(cls, _VecVariable):
        cls = cls.__mro__[2]
    base = per_lane(VType(cls.kind, 1))
    zero = False if cls.kind.category == "bool" else 0
    comps = [lanes_of().entry_variable(base, zero, f"{name}.{'xyzw'[i]}") for i in range(cls.size)]
    return _variable_class(cls)._of(comps)


SELECT_FORMS[Vec] = select  # Select and Variable of GLSL vectors: per component
VARIABLE_FORMS[Vec] = vector_variable
