"""DSL values: one Python class per value type (``Float``, ``Float4``, ``Int16``, ``Bool8`` ...).

A value wraps an SSA value of the function being built. Python numbers
broadcast as constants; a scalar value broadcasts against a vector; vectors of
different widths, or of different kinds (Float + Int), are errors. Operators
come from the table in ``reactor.ir.ops`` and are attached to the base class
once, for every kind and width.

Constructors convert: ``Float4(1.5)`` is a constant, ``Float4(1, 2, 3, 4)``
one per lane, ``Float4(x)`` broadcasts a scalar ``Float`` or converts an
``Int4`` (``Int(x)`` truncates toward zero and saturates; NaN gives 0; a Bool
converts to 0/1).
"""
from __future__ import annotations

from . import builtins as _numpy

import functools
import numbers
import typing

from ..errors import DSLTypeError, ScopeError, WidthMismatchError
from ..ir import emitter as _em
from ..ir import ops
from ..ir import types as T
from ..ir.types import KINDS, WIDTHS, Kind, VType
from .context import is_kernel_body


#: What an operator of a DSL value accepts on its other side.
Operand = typing.Union["Value", int, float, bool]


class Value:
    """Base class of every DSL value type; see the module docstring."""

    vtype: VType  # set on each concrete subclass
    __slots__ = ("_ir", "_emitter", "_scope")
    _ir: typing.Any
    _emitter: typing.Any
    _scope: typing.Any

    if typing.TYPE_CHECKING:  # attached from the operation table below (_install_operators)
        def __add__(self, other: Operand) -> Value: ...
        def __radd__(self, other: Operand) -> Value: ...
        def __sub__(self, other: Operand) -> Value: ...
        def __rsub__(self, other: Operand) -> Value: ...
        def __mul__(self, other: Operand) -> Value: ...
        def __rmul__(self, other: Operand) -> Value: ...
        def __truediv__(self, other: Operand) -> Value: ...
        def __rtruediv__(self, other: Operand) -> Value: ...
        def __mod__(self, other: Operand) -> Value: ...
        def __rmod__(self, other: Operand) -> Value: ...
        def __and__(self, other: Operand) -> Value: ...
        def __rand__(self, other: Operand) -> Value: ...
        def __or__(self, other: Operand) -> Value: ...
        def __ror__(self, other: Operand) -> Value: ...
        def __xor__(self, other: Operand) -> Value: ...
        def __rxor__(self, other: Operand) -> Value: ...
        def __lshift__(self, other: Operand) -> Value: ...
        def __rlshift__(self, other: Operand) -> Value: ...
        def __rshift__(self, other: Operand) -> Value: ...
        def __rrshift__(self, other: Operand) -> Value: ...
        def __lt__(self, other: Operand) -> Value: ...
        def __le__(self, other: Operand) -> Value: ...
        def __gt__(self, other: Operand) -> Value: ...
        def __ge__(self, other: Operand) -> Value: ...
        def __eq__(self, other: object) -> Value: ...  # type: ignore[override]
        def __ne__(self, other: object) -> Value: ...  # type: ignore[override]
        def __pow__(self, other: Operand) -> Value: ...
        def __rpow__(self, other: Operand) -> Value: ...
        def __neg__(self) -> Value: ...
        def __pos__(self) -> Value: ...
        def __invert__(self) -> Value: ...
        def __abs__(self) -> Value: ...

    # -- construction ---------------------------------------------------
    def __new__(cls, *args):
        if not hasattr(cls, "vtype"):
            raise DSLTypeError("Value is abstract; use a concrete type such as Float or Int4")
        em = _em.current()
        vt = cls.vtype
        if len(args) == 1:
            arg = args[0]
            if vt.width == 1 and isinstance(arg, Value) and arg.width > 1:
                # Float(i) of an Int16 is a Float16: a scalar type converts lane by lane
                cls, vt = value_class(vt.with_width(arg.width)), vt.with_width(arg.width)
            return cls._wrap(to_ir(arg, vt, convert=True), em)
        if len(args) == vt.width and vt.width > 1:
            vec = T.undefined(vt)
            for lane, arg in enumerate(args):
                vec = em.insert(vec, to_ir(arg, vt.with_width(1), convert=True), lane, name="lanes")
            return cls._wrap(vec, em)
        raise DSLTypeError(
            f"{shown(vt)}(...) takes one value (broadcast or converted) or {vt.width} lane values, "
            f"not {len(args)}"
        )

    @classmethod
    def _wrap(cls, value, em=None):
        """Wrap an IR value produced in the current scope."""
        self = object.__new__(cls)
        em = em or _em.current()
        self._ir, self._emitter, self._scope = value, em, em.scope
        return self

    # -- access ---------------------------------------------------------
    @property
    def ir(self):
        """The IR value, after checking it is visible where it is used."""
        em = _em.current()
        if self._emitter is not em:
            raise ScopeError(
                f"a {shown(self.vtype)} value from function '{self._emitter.function.name}' "
                f"used while building '{em.function.name}'; pass it as an argument instead"
            )
        if self._scope.closed:
            raise ScopeError(
                f"a {shown(self.vtype)} value defined inside a '{self._scope.what}' block is used "
                f"after that block ended; declare a Variable before the block and assign it inside"
            )
        if not em.in_chain(self._ir):
            raise ScopeError(
                f"a {shown(self.vtype)} value computed between the blocks of an If/Elif chain belongs "
                f"to the next Elif's condition and is only valid in that chain's Elif/Else blocks; "
                f"compute it before the If (or keep it in a Variable)"
            )
        return self._ir

    @property
    def width(self) -> int:
        return self.vtype.width

    @property
    def kind(self) -> Kind:
        return self.vtype.kind

    def named(self, name: str) -> "Value":
        """Give the IR value a readable name (shown in IR dumps); returns self."""
        _em.FunctionEmitter.set_name(self._ir, name)
        return self

    def __repr__(self) -> str:
        return f"<{shown(self.vtype)} value>"

    def __bool__(self):
        raise DSLTypeError(
            f"a {shown(self.vtype)} value has no Python truth value at build time: use "
            f"If(...)/While(...) for run-time branches, Select(...) for lane-wise choice (Python's "
            f"max, min, abs, 'and', 'or' and 'if' need one: use routines.glsl's max/min/abs or reactor.Max ...)"
        )

    def __index__(self):
        raise DSLTypeError(f"a {shown(self.vtype)} value cannot index a Python list or tuple, or count a range "
                           f"(it holds a value per lane): read per lane from a ConstantTable(values, Float) or a "
                           f"Table parameter, and loop with reactor.For")

    def __float__(self):
        raise DSLTypeError(f"a {shown(self.vtype)} value cannot be used as a Python number "
                           f"(math.* and Python's built-ins take numbers: use routines.glsl's cos, floor ... "
                           f"or reactor's Floor, Sqrt ... on DSL values)")

    __int__ = __complex__ = __float__  # math.cos(x) asks for one of these

    # np.sin(x) on a DSL value is GLSL's sin, np.clip its clamp; anything else a clear error
    __array_ufunc__ = _numpy.array_ufunc
    __array_function__ = _numpy.array_function

    def set(self, value: Operand) -> "Value":
        raise DSLTypeError(f"a {shown(self.vtype)} value (an argument, constant or result) cannot be assigned "
                           f"to: declare v = Variable({shown(self.vtype)}, ...) and use v.set(...)")

    def __setitem__(self, index, value):
        raise DSLTypeError(f"a {shown(self.vtype)} value cannot be changed in place: Insert(v, x, {index!r}) "
                           f"gives a copy with lane {index!r} replaced")

    __hash__ = object.__hash__


def shown(vtype: VType) -> str:
    """A type's name as the user wrote it, for messages: in a kernel body, ``Float`` for its lane
    type (``Float16`` in a 16-lane kernel); elsewhere, and for other widths, ``Float4``."""
    if vtype.width > 1 and _em.building() and is_kernel_body() and vtype.width == _em.current().settings.width:
        return vtype.kind.name
    return vtype.name


@functools.cache
def value_class(vtype: VType) -> type[Value]:
    """The Python class for ``vtype`` (e.g. ``VType(Float, 4)`` -> ``Float4``)."""
    return type(vtype.name, (Value,), {"vtype": vtype, "__slots__": (), "__module__": "reactor",
                                       "__doc__": type_doc(vtype)})


_ELEMENTS = {"float": "an IEEE binary{bits} float", "int": "a signed {bits}-bit integer (wrapping)",
             "uint": "an unsigned {bits}-bit integer (wrapping)", "bool": "a mask lane (what comparisons give)"}


def type_doc(vtype: VType) -> str:
    """The docstring of the value class of ``vtype``: its element, lanes and constructors."""
    kind, width = vtype.kind, vtype.width
    element = _ELEMENTS[kind.category].format(bits=kind.bits) + f", NumPy {kind.dtype.name}"
    example = {"float": "1.5", "bool": "True"}.get(kind.category, "3")
    if width == 1:
        return (f"{vtype.name}: a DSL value, {element}; in a kernel's body, one per lane of the "
                f"body's width.\n\n{vtype.name}({example}) is a constant, {vtype.name}(x) converts a value of "
                f"another kind lane by lane (Int of a float truncates toward zero and saturates; a mask "
                f"gives 0/1).")
    return (f"{vtype.name}: a DSL vector of {width} lanes, each {element}.\n\n{vtype.name}({example}) "
            f"broadcasts a constant, {vtype.name}(a, b, ...) takes {width} lane values, {vtype.name}(x) "
            f"broadcasts a scalar {kind.name} or converts a value of another kind, lane by lane.")


def vector_type(kind: "str | type[Value]", width: int) -> type[Value]:
    """``vector_type(Float, 8)`` -> ``Float8``; width 1 gives the scalar type."""
    kind_obj = KINDS[kind] if isinstance(kind, str) else kind.vtype.kind
    if width not in WIDTHS:
        raise DSLTypeError(f"vector width must be one of {WIDTHS}, not {width!r}")
    return value_class(VType(kind_obj, width))


# -- coercion ----------------------------------------------------------------

def _python_constant(x, vt: VType):
    kind = vt.kind
    if isinstance(x, bool) or (hasattr(x, "dtype") and getattr(x, "dtype", None) == bool):
        if kind.category != "bool":
            raise DSLTypeError(f"Python bool {x!r} used where a {shown(vt)} is expected")
        return T.const(vt, int(bool(x)))
    if kind.category == "bool":
        raise DSLTypeError(f"number {x!r} used where a {shown(vt)} (mask) is expected; use True/False")
    if kind.is_float:
        if not isinstance(x, numbers.Real):
            raise DSLTypeError(f"{type(x).__name__} {x!r} cannot be a {shown(vt)} constant")
        return T.const(vt, float(kind.dtype.type(x)) if kind.bits < 32 else float(x))  # Half: rounded once
    if isinstance(x, numbers.Integral):
        x, bits = int(x), kind.bits
        if not -(2 ** (bits - 1)) <= x < 2 ** bits:
            raise DSLTypeError(f"integer constant {x} does not fit in {bits} bits ({shown(vt)})")
        return T.const(vt, x - 2 ** bits if x >= 2 ** (bits - 1) else x)
    raise DSLTypeError(f"{type(x).__name__} {x!r} used where an integer {shown(vt)} is expected")


def to_ir(x, vt: VType, *, convert: bool = False):
    """IR for ``x`` as type ``vt``: constants broadcast, scalars splat.

    With ``convert`` (constructors) a value of another kind is converted
    numerically; otherwise a kind mismatch is an error.
    """
    if not isinstance(x, Value):
        return _python_constant(x, vt)
    xt = x.vtype
    val = x.ir
    if xt.kind != vt.kind:
        if not convert:
            raise DSLTypeError(f"expected {shown(vt)}, got {shown(xt)}")
        val = ops.convert(_em.current(), xt, xt.with_kind(vt.kind), val)
        xt = xt.with_kind(vt.kind)
    if xt.width == vt.width:
        return val
    if xt.width == 1:
        named = getattr(val, "name", "") and not T.is_constant(val)
        return _em.current().splat(val, vt.width, name=f"{val.name}.splat" if named else "splat")
    raise width_mismatch(f"a {shown(xt)} cannot become a {shown(vt)}: widths {xt.width} and {vt.width}")


def width_mismatch(message: str) -> WidthMismatchError:
    """The error for values of different widths; in a kernel's body, with how to write it there."""
    if _em.building():
        em = _em.current()
        if is_kernel_body(em):
            message += (f"; a kernel's body is traced at width {em.settings.width} and at width 1 (the tail): "
                        f"write the scalar types (Float, Int, Bool ...), which take the body's width, not "
                        f"Float4 or Float16")
    return WidthMismatchError(message)


def common_type(*args, what: str) -> VType:
    """The value type of an operation on ``args`` (at least one must be a Value)."""
    vts = [a.vtype for a in args if isinstance(a, Value)]
    if not vts:
        raise DSLTypeError(f"{what} needs at least one DSL value (all operands are Python constants)")
    kinds = {vt.kind for vt in vts}
    if len(kinds) > 1:
        names = " and ".join(shown(vt) for vt in vts)
        raise DSLTypeError(f"{what}: operands of different types ({names}); convert one explicitly, "
                           f"e.g. Float(i) or Int(x)")
    widths = {vt.width for vt in vts} - {1}
    if len(widths) > 1:
        names = " and ".join(shown(vt) for vt in vts)
        raise width_mismatch(f"{what}: vector widths differ ({names})")
    return VType(vts[0].kind, widths.pop() if widths else 1)


def _lookup(table: dict, name: str, vt: VType, what: str):
    recipe = ops.lookup(table, name, vt)
    if recipe is None:
        kinds = sorted({k.name for k in KINDS.values() if k.category in table[name]})
        hint = ""
        if name in ("and", "or", "xor") and vt.kind.is_float:
            hint = ("; in Python '&', '|' and '^' bind tighter than comparisons: write (a < b) & (c < d), "
                    "with the parentheses")
        raise DSLTypeError(f"{what} is not defined for {shown(vt)} (only for {', '.join(kinds)}){hint}")
    return recipe


def binary(name: str, a, b, what: str | None = None) -> Value:
    """Apply the binary operation ``name`` of ``ops.BINARY``."""
    what = what or name
    vt = common_type(a, b, what=what)
    recipe = _lookup(ops.BINARY, name, vt, what)
    em = _em.current()
    return value_class(vt)._wrap(ops.apply(recipe, em, vt, to_ir(a, vt), to_ir(b, vt), name=name), em)


def unary(name: str, a, what: str | None = None) -> Value:
    what = what or name
    vt = common_type(a, what=what)
    recipe = _lookup(ops.UNARY, name, vt, what)
    em = _em.current()
    return value_class(vt)._wrap(ops.apply(recipe, em, vt, to_ir(a, vt), name=name), em)


def comparison(name: str, a, b) -> Value:
    vt = common_type(a, b, what=f"comparison '{ops.COMPARE[name]}'")
    if vt.kind.category == "bool" and name not in ("eq", "ne"):
        raise DSLTypeError(f"ordering comparison '{ops.COMPARE[name]}' of masks ({shown(vt)})")
    em = _em.current()
    result = ops.compare(em, vt, name, to_ir(a, vt), to_ir(b, vt))
    return value_class(vt.with_kind("Bool"))._wrap(result, em)


# -- operators, attached once for every type ----------------------------------

_BINARY_DUNDERS = {
    "add": ("__add__", "__radd__", "+"), "sub": ("__sub__", "__rsub__", "-"),
    "mul": ("__mul__", "__rmul__", "*"), "div": ("__truediv__", "__rtruediv__", "/"),
    "rem": ("__mod__", "__rmod__", "%"), "and": ("__and__", "__rand__", "&"),
    "or": ("__or__", "__ror__", "|"), "xor": ("__xor__", "__rxor__", "^"),
    "shl": ("__lshift__", "__rlshift__", "<<"), "shr": ("__rshift__", "__rrshift__", ">>"),
}


def _foreign(x) -> bool:
    """An operand that handles the operation itself (a GLSL vector or matrix): Python then asks it."""
    return getattr(type(x), "dsl_composite", False)


_power_function = None


def set_power(fn) -> None:
    """Install what ``x ** y`` computes for a non-integer ``y`` (a routine library's pow)."""
    global _power_function
    _power_function = fn


def power(a, b):
    """``a ** b``: a chain of multiplications for a whole-number constant ``|b| <= 16`` (``2`` or
    ``2.0``), else the installed pow (``routines`` installs its ``pow``, which follows the build's precision)."""
    if isinstance(b, float) and b.is_integer() and abs(b) <= 16:
        b = int(b)  # x ** 2.0 is x * x, as in Python and NumPy (pow would be NaN for x < 0)
    if isinstance(b, int) and not isinstance(b, bool) and abs(b) <= 16 and isinstance(a, Value):
        if not a.kind.is_float:
            raise DSLTypeError(f"operator '**' is defined for Float and Double, not {shown(a.vtype)}")
        result, base, n = None, a, abs(b)
        while n:
            if n & 1:
                result = base if result is None else result * base
            n >>= 1
            if n:
                base = base * base
        result = value_class(a.vtype)(1.0) if result is None else result
        return 1.0 / result if b < 0 else result
    if _power_function is None:
        raise DSLTypeError("x ** y with a y other than a small integer constant needs pow: import routines "
                           "(or reactor.set_power(your_pow))")
    return _power_function(a, b)


def _install_operators() -> None:
    for name, (fwd, rev, sym) in _BINARY_DUNDERS.items():
        what = f"operator '{sym}'"
        setattr(Value, fwd, lambda a, b, _n=name, _w=what: NotImplemented if _foreign(b) else binary(_n, a, b, _w))
        setattr(Value, rev, lambda a, b, _n=name, _w=what: NotImplemented if _foreign(b) else binary(_n, b, a, _w))
    for name, dunder in {"lt": "__lt__", "le": "__le__", "gt": "__gt__", "ge": "__ge__",
                         "eq": "__eq__", "ne": "__ne__"}.items():
        setattr(Value, dunder, lambda a, b, _n=name: NotImplemented if _foreign(b) else comparison(_n, a, b))
    setattr(Value, "__pow__", lambda a, b: NotImplemented if _foreign(b) else power(a, b))
    setattr(Value, "__rpow__", lambda a, b: NotImplemented if _foreign(b) else power(b, a))
    setattr(Value, "__neg__", lambda a: unary("neg", a, "negation"))
    setattr(Value, "__pos__", lambda a: a)
    setattr(Value, "__invert__", lambda a: unary("invert", a, "operator '~'"))
    setattr(Value, "__abs__", lambda a: unary("abs", a, "abs"))


_install_operators()
