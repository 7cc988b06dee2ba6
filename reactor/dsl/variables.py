"""Mutable variables and pointers.

A ``Variable`` is a stack slot in the function's entry block (so LLVM's mem2reg
turns it back into SSA values, as in Reactor). It behaves as a value of its
type wherever it is read, and keeps its value across branches and loops::

    acc = Variable(Float4, 0.0)
    with For(0, n) as i:
        acc += p.load(i * 4, 4)       # in-place operators store back
    acc.set(acc * 0.5)                # plain assignment

A ``Pointer`` argument indexes memory in elements of its pointee type.
"""
from __future__ import annotations

import functools
import typing

if typing.TYPE_CHECKING:
    from .vectors import Vec

from ..errors import ControlFlowError, DSLTypeError, ScopeError
from ..ir import emitter as _em
from ..ir import ops
from ..ir import types as T
from ..ir.types import PointerType, VType
from .context import active_mask, is_kernel_body
from .values import Operand, Value, binary, shown, to_ir, value_class

#: The value type a Variable holds (``Variable(Float, 0.0)`` is a ``Float``).
_V = typing.TypeVar("_V", bound=Value)


class _VariableMixin:
    """Methods shared by every Variable[T] class (T a value type)."""

    __slots__ = ()
    vtype: VType
    _name: str
    _init: typing.Any

    def _slot(self):
        slot = Value.ir.fget(self)  # checks function and scope
        if not _em.current().in_chain(self._init):
            raise ScopeError(f"Variable '{self._name}' was created between the blocks of an If/Elif "
                             f"chain, so only the path that evaluates the next Elif's condition "
                             f"initializes it; create it before the If")
        return slot

    @property
    def ir(self):
        return _em.current().load(self._slot(), name=self._name)

    @property
    def value(self) -> Value:
        """An immutable snapshot of the current value."""
        return value_class(self.vtype)._wrap(self.ir)

    def set(self, value: Operand) -> Value:
        """Store ``value`` (converted only if it is a Python constant or a broadcast scalar); under
        a per-lane condition, in the active lanes only."""
        em = _em.current()
        new = to_ir(value, self.vtype)
        mask = active_mask()
        if mask is not None:
            if self.vtype.width != mask.width:
                kernel = is_kernel_body(em)
                fix = ("declare it without uniform=True (one value per lane)" if kernel else
                       f"declare it with one value per lane (Variable({self.vtype.kind.name}{mask.width}, ...))")
                raise ControlFlowError(
                    f"Variable '{self._name}' ({shown(self.vtype)}) is assigned under a per-lane condition of "
                    f"{mask.width} lanes: which lane's value should it take? {fix[0].upper() + fix[1:]}, "
                    f"or assign it outside the condition")
            slot = self._slot()
            new = em.select(mask.ir, new, em.load(slot, name=self._name), name=f"{self._name}.masked")
            em.store(new, slot)
        else:
            em.store(new, self._slot())
        return typing.cast(Value, self)  # a Variable[T] class is both this mixin and a Value

    def set_all(self, value: Operand) -> None:
        """Store ``value`` in every lane, whatever the per-lane conditions (for the control flow's own
        masks and counters)."""
        _em.current().store(to_ir(value, self.vtype), self._slot())

    def named(self, name):
        return self


def _inplace(op):
    def method(self, other):
        return self.set(binary(op, self, other))

    return method


for _op, _dunder in {"add": "__iadd__", "sub": "__isub__", "mul": "__imul__",
                     "div": "__itruediv__", "rem": "__imod__", "and": "__iand__",
                     "or": "__ior__", "xor": "__ixor__", "shl": "__ilshift__",
                     "shr": "__irshift__"}.items():
    setattr(_VariableMixin, _dunder, _inplace(_op))


@functools.cache
def _variable_class(vtype: VType):
    return type(f"Variable[{vtype.name}]", (_VariableMixin, value_class(vtype)),
                {"__slots__": ("_name", "_init"), "__module__": "reactor"})


def per_lane(vtype: VType) -> VType:
    """The type a variable of ``vtype`` has where it is declared: in a kernel's body a scalar
    type means one value per lane (as every variable of a shader), so it takes the body's width."""
    if vtype.width == 1 and _em.building():
        em = _em.current()
        if is_kernel_body(em) and em.width > 1:
            return vtype.with_width(em.width)
    return vtype


#: Variable's forms for composite DSL types: class -> variable(type_or_value, init, name)
#: (``reactor.dsl.vectors`` registers the GLSL vectors' own at import)
VARIABLE_FORMS: dict[type, typing.Callable] = {}


@typing.overload
def Variable(type_or_value: type[Vec] | Vec, init: typing.Any = None, name: str = "var", *,
             uniform: bool = False) -> Vec: ...
@typing.overload
def Variable(type_or_value: type[_V] | _V, init: Operand | None = None, name: str = "var", *,
             uniform: bool = False) -> _V: ...
def Variable(type_or_value: typing.Any, init: typing.Any = None, name: str = "var", *,
             uniform: bool = False) -> typing.Any:
    """A mutable variable: ``Variable(Float4, 0.0)``, ``Variable(Float4)`` (zero)
    or ``Variable(x)`` (type and initial value from the value ``x``). In a kernel's
    body ``Variable(Float, 0.0)`` holds one value per lane (the body's width), unless
    ``uniform=True`` (one value for every lane, as a loop counter); ``Variable(vec3, 0.0)``
    is a vector variable (components per lane too)."""
    for cls, variable in VARIABLE_FORMS.items():
        if isinstance(type_or_value, cls) or isinstance(type_or_value, type) and issubclass(type_or_value, cls):
            return variable(type_or_value, init, name)
    if isinstance(type_or_value, Value):
        if init is not None:
            raise DSLTypeError("Variable(value) takes its initial value from the value; "
                               "use Variable(Type, init) to give both")
        vtype, init = type_or_value.vtype if uniform else per_lane(type_or_value.vtype), type_or_value
    elif isinstance(type_or_value, type) and issubclass(type_or_value, Value) and hasattr(type_or_value, "vtype"):
        vtype = type_or_value.vtype if uniform else per_lane(type_or_value.vtype)
    else:
        raise DSLTypeError(f"Variable needs a DSL type or value, not {type_or_value!r}")
    em = _em.current()
    init_ir = to_ir(0 if init is None and not vtype.kind.category == "bool" else (False if init is None else init), vtype)
    slot = em.alloca(vtype.ir, name=name)
    init_store = em.store(init_ir, slot)
    var = _variable_class(vtype)._wrap(slot, em)
    var._name, var._init = name, init_store
    return var


class PointerValue:
    """A pointer argument: ``p[i]`` loads, ``p[i] = v`` stores, in pointee elements.

    ``p.load(i, width)`` / ``p.store(i, vec)`` move ``width`` consecutive scalars
    starting at element ``i`` of a scalar pointer as one vector (unaligned).
    """

    __slots__ = ("ptype", "_ir", "_emitter", "written", "_length")

    def __init__(self, ptype: PointerType, value, em, length=None):
        self.ptype, self._ir, self._emitter = ptype, value, em
        self.written = False  # stored through (here or by a called function): needs a writeable array
        self._length = length  # the declared length (pointee elements) when known: (its type, IR value)

    def _ptr(self):
        em = _em.current()
        if self._emitter is not em:
            raise ScopeError(f"a {self.ptype.name} from function '{self._emitter.function.name}' "
                             f"used while building '{em.function.name}'")
        return em, self._ir

    def _address(self, index, vt: VType):
        """The address of scalar element ``index`` (an int or a scalar Int/UInt value)."""
        em, base = self._ptr()
        if isinstance(index, Value):
            if not index.kind.is_integer or index.width != 1:
                raise DSLTypeError(f"pointer index must be a scalar Int or UInt, not {shown(index.vtype)}")
            idx = ops.convert(em, index.vtype, T.INDEX, index.ir)
        elif isinstance(index, int) and not isinstance(index, bool):
            idx = index
        else:
            raise DSLTypeError(f"pointer index must be an int or an Int value, not {index!r}")
        elem = vt.with_width(1) if vt.kind.category != "bool" else T.BYTE
        return em, em.address(em.cast_pointer(base, elem), idx)

    def _lanes(self, index: Value, what: str):
        """Per-lane element offsets (bytes) and the mask of the lanes whose index is inside the
        declared length: a gather or scatter never touches memory outside the array."""
        em, base = self._ptr()
        if self.ptype.pointee.width != 1:
            raise DSLTypeError(f"per-lane indices are for pointers to scalars, not {self.ptype.name}")
        if self._length is None:
            raise DSLTypeError(f"{what} {self.ptype.name} with a per-lane index needs the pointer's length "
                               f"(Pointer[{self.ptype.pointee.name}, 'n'] with n an Int argument, or a number): "
                               f"lanes outside it read 0 and write nothing")
        vt = self.ptype.pointee
        w = index.width
        i64 = VType(T.INDEX.kind, w)
        idx = ops.convert(em, index.vtype, i64, index.ir)
        length = ops.convert(em, self._length[0], T.INDEX, self._length[1])
        inside = ops.compare(em, T.UINDEX.with_width(w), "lt", idx, em.splat(length, w))  # 0 <= i < n
        mask = active_mask()
        if mask is not None:
            m = mask.ir if mask.width == w else em.splat(mask.ir, w)
            inside = ops.binary(em, "and", VType(T.KINDS["Bool"], w), inside, m)
        safe = em.select(inside, idx, T.const(i64, 0), name="index")
        offsets = ops.binary(em, "mul", i64, safe, T.const(i64, vt.kind.mem_bytes))
        return em, base, offsets, inside, vt.with_width(w)

    def _load(self, index, vt: VType):
        if isinstance(index, Value) and index.width > 1 and index.kind.is_integer:
            em, base, offsets, inside, lanes_vt = self._lanes(index, "reading")
            raw = em.gather(lanes_vt, base, offsets, inside, name="gather")
            return value_class(lanes_vt)._wrap(ops.from_memory(em, lanes_vt, raw), em)
        em, addr = self._address(index, vt)
        return value_class(vt)._wrap(ops.load(em, vt, addr), em)

    def _store(self, index, value, vt: VType):
        if isinstance(index, Value) and index.width > 1 and index.kind.is_integer:
            em, base, offsets, inside, lanes_vt = self._lanes(index, "writing")
            self.written = True
            em.scatter(lanes_vt, ops.to_memory(em, lanes_vt, to_ir(value, lanes_vt)), base, offsets, inside)
            return
        if active_mask() is not None:
            raise ControlFlowError(f"a store through {self.ptype.name} under a per-lane condition: only some "
                                   f"lanes should store; compute the value with Select and store it outside")
        val = to_ir(value, vt)
        em, addr = self._address(index, vt)
        self.written = True
        ops.store(em, vt, val, addr)

    def _scaled(self, index):
        w = self.ptype.pointee.width
        return index if w == 1 else index * w

    def __getitem__(self, index):
        return self._load(self._scaled(index), self.ptype.pointee)

    def __setitem__(self, index, value):
        self._store(self._scaled(index), value, self.ptype.pointee)

    def load(self, index, width: int):
        """Load ``width`` consecutive scalars from scalar element ``index``."""
        self._require_scalar("load")
        return self._load(index, self.ptype.pointee.with_width(width))

    def store(self, index, value: Value):
        """Store the vector ``value`` to consecutive scalars from element ``index``."""
        self._require_scalar("store")
        if not isinstance(value, Value):
            raise DSLTypeError("Pointer.store needs a DSL vector value")
        self._store(index, value, self.ptype.pointee.with_width(value.width))

    def _require_scalar(self, what):
        if self.ptype.pointee.width != 1:
            raise DSLTypeError(f"{what}(i, width) is for pointers to scalars; {self.ptype.name} indexes whole vectors")

    def __repr__(self):
        return f"<{self.ptype.name}>"


def entry_variable(vtype: VType, init, name: str):
    """A Variable whose initial value is stored at the function's entry, wherever it is created
    (so it holds that value on every path that reaches its first use)."""
    em = _em.current()
    slot = em.alloca(vtype.ir, name=name)
    init_store = em.store_at_entry(to_ir(init, vtype), slot)
    var = _variable_class(vtype)._wrap(slot, em)
    var._name, var._init = name, init_store
    var._scope = em.root_scope
    return var


def is_variable(x: object) -> bool:
    """Whether ``x`` is a ``Variable`` (mutable) rather than a plain value."""
    return isinstance(x, _VariableMixin)
