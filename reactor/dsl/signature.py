"""Signatures: argument and return types of DSL functions and kernels.

Types are written as annotations (``def f(x: Float, p: Pointer[Float, "n"], n: Int) -> Float``)
or given explicitly. ``SIMD.Float`` (and ``SIMD.Int`` ...) is width-generic: it
becomes ``Float16``/``Float8``/``Float4`` according to the build's width.

Several results are a tuple of types: ``-> tuple[Float, Bool]`` (what type checkers accept;
``typing.Tuple[...]`` too) or ``-> (Float, Bool)``; both become the same plain tuple here.
"""
from __future__ import annotations

import dataclasses
import inspect
import weakref
import typing

from ..errors import DSLTypeError
from ..ir import emitter as _em
from ..ir.types import KINDS, PointerType, VType
from .values import Value, value_class


class GenericType:
    """A kind whose width is the build's SIMD width (``SIMD.Float``)."""

    def __init__(self, kind: str):
        self.kind = KINDS[kind]

    def at(self, width: int) -> type[Value]:
        return value_class(VType(self.kind, width))

    def __call__(self, *args):
        """Construct a value at the width of the function being built."""
        return self.at(_em.current().width)(*args)

    def __repr__(self):
        return f"SIMD.{self.kind.name}"


class _SIMD:
    """Width-generic types, like SwiftShader's ``SIMD::Float`` with a build-time width."""

    Float = GenericType("Float")
    Double = GenericType("Double")
    Int = GenericType("Int")
    UInt = GenericType("UInt")
    Bool = GenericType("Bool")

    @property
    def width(self) -> int:
        """The SIMD width of the function being built."""
        return _em.current().width


SIMD = _SIMD()


if typing.TYPE_CHECKING:
    from typing_extensions import TypeVar as _TypeVar

    _Pointee = _TypeVar("_Pointee")
    _Length = _TypeVar("_Length", default=None)

    class Pointer(typing.Generic[_Pointee, _Length]):
        """What a type checker sees: ``Pointer[Float]`` or ``Pointer[Float, Literal["n"]]``; an
        element read is of the pointee's type (``p[i]`` of a ``Pointer[Float4]`` is a ``Float4``)."""

        def __getitem__(self, index: int | Value) -> _Pointee: ...
        def __setitem__(self, index: int | Value, value: typing.Any) -> None: ...
        def load(self, index: int | Value, width: int) -> Value: ...
        def store(self, index: int | Value, value: Value) -> None: ...
else:
    class Pointer:
        """``Pointer[Float]``, ``Pointer[Float4]``, ``Pointer[Float, 64]`` or
        ``Pointer[Float, "n"]`` (at least ``n`` elements, ``n`` an Int argument). Under
        a type checker write the length as ``Literal[64]`` or ``Literal["n"]``."""

        def __class_getitem__(cls, item):
            pointee, length = (item if isinstance(item, tuple) else (item, None))
            args = typing.get_args(length) if typing.get_origin(length) is typing.Literal else ()
            return _PointerSpec(pointee, args[0] if args else length)


@dataclasses.dataclass(frozen=True)
class _PointerSpec:
    pointee: object
    length: int | str | None


def resolve(spec, width: int, what: str):
    """A concrete VType or PointerType for an annotation at a build width."""
    if isinstance(spec, GenericType):
        return spec.at(width).vtype
    if isinstance(spec, type) and issubclass(spec, Value) and hasattr(spec, "vtype"):
        return spec.vtype
    if isinstance(spec, _PointerSpec):
        pointee = resolve(spec.pointee, width, what)
        if not isinstance(pointee, VType):
            raise DSLTypeError(f"{what}: a pointer must point to a value type, not {spec.pointee!r}")
        return PointerType(pointee, spec.length)
    if isinstance(spec, (VType, PointerType)):
        return spec
    raise DSLTypeError(f"{what}: {spec!r} is not a DSL type (use Float, Int4, SIMD.Float, Pointer[Float] ...)")


def _is_type_spec(spec) -> bool:
    """Whether ``spec`` can name one result: a DSL class, a width-generic, pointer, texture or IR type.
    (Which of these a function or a kernel takes is checked where it is resolved.)"""
    if typing.get_origin(spec) is not None or spec is None or spec is Ellipsis:
        return False  # tuple[...], list[...], Optional[...]: not one type
    if isinstance(spec, type):
        from .vectors import Mat, Vec
        return issubclass(spec, (Value, Vec, Mat))
    return not isinstance(spec, (tuple, list, str, int, float, typing.ForwardRef))


def results_of(returns, name: str):
    """The result spec of a return annotation: ``tuple[Float, Bool]`` and ``typing.Tuple[Float, Bool]``
    become the plain tuple ``(Float, Bool)`` (what ``-> (Float, Bool)`` gives); a tuple of no fixed
    length, an empty one or one holding a non-DSL type is a DSLTypeError naming the problem."""
    if typing.get_origin(returns) is tuple:
        items, written = typing.get_args(returns), _spelled(returns)
    elif isinstance(returns, tuple):
        items, written = returns, "(" + ", ".join(map(_spelled, returns)) + ")"
    else:
        return returns
    if Ellipsis in items:
        problem = "a tuple of results needs one type per result (e.g. tuple[Float, Float]), not '...'"
    elif not items:
        problem = "an empty tuple of results (write no return annotation for none)"
    else:
        bad = [i for i, item in enumerate(items) if not _is_type_spec(item)]
        if not bad:
            return tuple(items)
        problem = (f"result {bad[0] + 1} of {len(items)} is {_spelled(items[bad[0]])}, not a DSL type "
                   f"(Float, Int, Bool, vec3 ...)")
    raise DSLTypeError(f"'{name}' returns {written}: {problem}")


def _spelled(spec) -> str:
    """An annotation as it is written (``tuple[Float, Float]``, ``int``)."""
    if typing.get_origin(spec) is tuple:
        return "tuple[" + ", ".join(_spelled(a) for a in typing.get_args(spec)) + "]"
    if isinstance(spec, type) and typing.get_origin(spec) is None:
        return spec.__name__
    return "..." if spec is Ellipsis else repr(spec)


_HINTS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def _names_and_hints(body):
    """A function's parameter names and evaluated annotations, remembered while its code and its
    annotations stay the same (string annotations are evaluated once, not at every kernel call)."""
    raw = getattr(body, "__annotations__", None)
    try:
        key = (getattr(body, "__code__", None), tuple(raw.items()) if isinstance(raw, dict) else None)
        hash(key)
        known = _HINTS.get(body)
    except TypeError:  # an unhashable annotation, or a callable that takes no weak reference
        key, known = None, None
    if known is not None and known[0] == key:
        return known[1], known[2]
    names = tuple(inspect.signature(body).parameters)
    try:
        hints = inspect.get_annotations(body, eval_str=True)
    except NameError as exc:  # e.g. a local type under `from __future__ import annotations`
        raise DSLTypeError(f"'{body.__name__}': cannot evaluate its type annotations ({exc}); "
                           f"string annotations can only name module-level types, so give "
                           f"args=[...]/returns=... explicitly") from None
    if key is not None:
        try:
            _HINTS[body] = (key, names, hints)
        except TypeError:
            pass
    return names, hints


@dataclasses.dataclass(frozen=True)
class Signature:
    """Parameter names, parameter type specs and the return type spec (None: void)."""

    names: tuple[str, ...]
    params: tuple[object, ...]
    returns: object

    @classmethod
    def from_function(cls, body, args=None, returns=inspect.Parameter.empty) -> "Signature":
        names, hints = _names_and_hints(body)
        if args is None:
            missing = [n for n in names if n not in hints]
            if missing:
                raise DSLTypeError(f"'{body.__name__}': parameter(s) {', '.join(missing)} need a type "
                                   f"annotation (e.g. x: Float) or an explicit args=[...] list")
            args = [hints[n] for n in names]
        elif len(args) != len(names):
            raise DSLTypeError(f"'{body.__name__}' has {len(names)} parameter(s) but {len(args)} "
                               f"argument type(s) were given")
        if returns is inspect.Parameter.empty:
            returns = hints.get("return")
        return cls(names, tuple(args), results_of(returns, getattr(body, "__name__", "function")))

    def resolved(self, width: int, where: str):
        params = tuple(resolve(p, width, f"{where} parameter '{n}'") for n, p in zip(self.names, self.params))
        if self.returns is None:
            returns = None
        elif isinstance(self.returns, tuple):
            returns = tuple(resolve(r, width, f"{where} result") for r in self.returns)
        else:
            returns = resolve(self.returns, width, f"{where} result")
        for name, p in zip(self.names, params):
            if isinstance(p, PointerType) and isinstance(p.length, str):
                idx = self.names.index(p.length) if p.length in self.names else -1
                if idx < 0 or not isinstance(params[idx], VType) or not params[idx].kind.is_integer \
                        or params[idx].width != 1:
                    raise DSLTypeError(f"{where}: pointer '{name}' has length '{p.length}', which must "
                                       f"name a scalar Int/UInt parameter")
        return params, returns
