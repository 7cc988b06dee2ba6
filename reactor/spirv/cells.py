"""Flattened values and variables: a scalar is a DSL value (or a Python number for what is known
while building), a vector a tuple of scalars, a matrix a tuple of columns, a struct or an array a
tuple of members; a variable (:class:`Cell`) has that shape with a per-lane Variable, or a
:class:`Lazy` scalar known while building, at each leaf."""
from __future__ import annotations

import typing

from ..dsl.lanes import lanes_of
from ..dsl.values import Value, value_class
from ..dsl.variables import is_variable, per_lane
from ..dsl.vectors import Vec, vec_type
from ..ir.types import KINDS, VType
from .binary import SpirvError
from .declarations import _KIND, Type, zero


# -- flattened values -----------------------------------------------------------------------------

def leaves(value) -> list:
    return [x for v in value for x in leaves(v)] if isinstance(value, tuple) else [value]


def rebuild(shape, flat: list):
    """``flat`` (leaves) in the nesting of ``shape``."""
    it = iter(flat)

    def build(s):
        return tuple(build(x) for x in s) if isinstance(s, tuple) else next(it)
    return build(shape)


def componentwise(fn, *args):
    """``fn`` on each component (a scalar argument is used with every component)."""
    size = next((len(a) for a in args if isinstance(a, tuple)), None)
    if size is None:
        return fn(*args)
    return tuple(componentwise(fn, *[a[k] if isinstance(a, tuple) else a for a in args]) for k in range(size))


def _dsl(v, kind: str = "Float"):
    """A DSL value for ``v`` (a Python number becomes a constant of ``kind``)."""
    if isinstance(v, Value):
        return v
    return value_class(VType(KINDS[kind], 1))(v)


def to_vec(v):
    """A flattened vector as the DSL's vector (for the built-ins); scalars as they are."""
    if not isinstance(v, tuple):
        return v
    kind = next((x.kind.name for x in v if isinstance(x, Value)), "Bool" if isinstance(v[0], bool) else "Float")
    return vec_type(kind, len(v))(*v)


def from_vec(v):
    return tuple(v._c) if isinstance(v, Vec) else v


# -- variables ------------------------------------------------------------------------------------

class Cell:
    """A variable: the flattened shape of its type with a per-lane DSL Variable at each scalar,
    or fixed values (an input, a uniform). ``path`` selects a part of it (an access chain)."""

    def __init__(self, slots, path: tuple = ()) -> None:
        self.slots, self.path = slots, path

    def part(self, indices) -> "Cell | DynamicCell":
        """The part an access chain selects; an index known only at run time (a DSL Int) gives a
        :class:`DynamicCell`."""
        for k, index in enumerate(indices):
            if isinstance(index, Value):
                return DynamicCell(Cell(self.slots, self.path + tuple(indices[:k])), index, tuple(indices[k + 1:]))
        return Cell(self.slots, self.path + tuple(indices))

    def _at(self):
        node = self.slots
        for k in self.path:
            node = node[k]
        return node

    def materialize(self) -> None:
        """Make every scalar of the variable a per-lane Variable (before a run-time construct
        stores into it)."""
        def walk(node):
            if isinstance(node, tuple):
                for x in node:
                    walk(x)
            elif isinstance(node, Lazy):
                node.materialize()
        walk(self.slots)

    def load(self):
        def read(node):
            if isinstance(node, tuple):
                return tuple(read(x) for x in node)
            if isinstance(node, Lazy):
                return node.load()
            return node.value if is_variable(node) else node
        return read(self._at())

    def store(self, value) -> None:
        def write(node, v):
            if isinstance(node, tuple):
                for n, x in zip(node, v):
                    write(n, x)
            elif isinstance(node, Lazy):
                node.store(v)
            elif is_variable(node):
                node.set(v)
            else:
                raise SpirvError("a store to an input or a uniform")
        write(self._at(), value)


class _Invocation:
    """``gl_GlobalInvocationID.x``: each lane's element. It is the index of its own element in the
    buffers, and it is below the length of each (``.length()``): so a bounds check holds. Anything
    else done with it is refused."""

    def _refuse(self, *args):
        raise SpirvError("gl_GlobalInvocationID.x is supported as the index of a buffer's element (one "
                         "invocation per element) and in a bounds check against a buffer's length(); "
                         "arithmetic on it, or another comparison, is not yet")

    __int__ = __index__ = __float__ = __bool__ = __add__ = __radd__ = __sub__ = __mul__ = _refuse
    __lt__ = __le__ = __gt__ = __ge__ = _refuse

    def __repr__(self) -> str:
        return "gl_GlobalInvocationID.x"


class _Length(_Invocation):
    """A buffer's ``length()``: more than any invocation's index."""

    def __repr__(self) -> str:
        return "length()"


INVOCATION, LENGTH = _Invocation(), _Length()


def invocation_compare(fn, xs):
    """A comparison of the invocation's index with a buffer's length, known while building (the
    index is below the length: 0 and 1 stand for them)."""
    if sorted(map(repr, xs)) != sorted(["gl_GlobalInvocationID.x", "length()"]):
        INVOCATION._refuse()
    return bool(fn(*[0 if x is INVOCATION else 1 for x in xs]))


class DynamicCell:
    """``cell[index][rest...]`` with ``index`` a per-lane Int: loads pick, stores go to the element
    each lane's index names (a select over the elements, as GLSL compilers lower it)."""

    def __init__(self, cell: Cell, index, rest: tuple) -> None:
        self.cell, self.index, self.rest = cell, index, rest

    def _elements(self) -> list:
        return [self.cell.part((k,) + self.rest) for k in range(len(self.cell._at()))]

    def part(self, indices) -> "DynamicCell":
        return DynamicCell(self.cell, self.index, self.rest + tuple(indices))

    def load(self):
        return pick([e.load() for e in self._elements()], self.index)

    def store(self, value) -> None:
        from ..dsl.intrinsics import Select
        for k, element in enumerate(self._elements()):
            hit = self.index == k
            element.store(componentwise(lambda v, old: Select(hit, _dsl(v, _kind_of(old)), old), value,
                                        element.load()))

    def materialize(self) -> None:
        self.cell.materialize()


def pick(items: list, index):
    """``items[index]`` for a per-lane Int ``index`` (a select chain; an index out of range gives
    the last item, as no GLSL program may rely on it)."""
    from ..dsl.intrinsics import Select
    result = items[-1]
    for k in range(len(items) - 2, -1, -1):
        hit = index == k
        result = componentwise(lambda a, b: Select(hit, _dsl(a, _kind_of(b)), b), items[k], result)
    return result


def _kind_of(v) -> str:
    if isinstance(v, Value):
        return v.kind.name
    return "Bool" if isinstance(v, bool) else "Int" if isinstance(v, int) else "Float"


class Lazy:
    """A scalar of a local variable known while building (a Python number) until a DSL value or
    a store under run-time control flow makes it a per-lane Variable (declared at the entry)."""

    __slots__ = ("value", "var", "vtype", "name", "depth")

    def __init__(self, value, vtype, name: str) -> None:
        self.value, self.vtype, self.name = value, vtype, name
        self.var: typing.Any = None  # the per-lane Variable, once made
        self.depth = len(lanes_of().calls)  # the inline depth of the function it is a local of

    def load(self):
        return self.value if self.var is None else self.var.value

    def store(self, value) -> None:
        from ..dsl.context import active_mask
        # lanes that returned from its function (or one around it) never read it again: after an
        # early per-lane return, a loop counter stays known while building (the loop unrolls)
        if self.var is None and not isinstance(value, Value) and (
                active_mask() is None or lanes_of().returns_only(self.depth)):
            self.value = value
            return
        self.materialize()
        self.var.set(value)

    def materialize(self) -> None:
        if self.var is None:
            self.var = lanes_of().entry_variable(self.vtype, False if self.vtype.kind.category == "bool" else 0,
                                                 self.name)
            self.var.set_all(self.value)


def new_cell(typ: Type, init, name: str, lazy: bool = False) -> Cell:
    """A variable of ``typ`` declared at the function's entry (it exists on every path);
    ``lazy``: known while building until it cannot be (:class:`Lazy`)."""
    lanes = lanes_of()

    def make(t: Type, v):
        if t.scalar and lazy:
            vt = per_lane(VType(KINDS[_KIND[t.kind]], 1))
            leaf = Lazy(zero(t), vt, name)
            if v is not None:
                leaf.store(v)
            return leaf
        if t.scalar:
            vt = per_lane(VType(KINDS[_KIND[t.kind]], 1))
            var = lanes.entry_variable(vt, False if t.kind == "bool" else 0, name)
            if v is not None:
                var.set(v)
            return var
        parts = t.members if t.kind == "struct" else [t.elem] * t.count
        return tuple(make(p, None if v is None else v[k]) for k, p in enumerate(parts))
    return Cell(make(typ, init))
