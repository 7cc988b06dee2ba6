"""SPIR-V to a reactor kernel, through the DSL and its control-flow core (``reactor.dsl.flow``): no
second code generator. A fragment shader becomes a NumPy ufunc (a gufunc where vectors are
involved): its ``in`` variables, by location, are the inputs (``gl_FragCoord`` too where it is read),
its ``out`` variables the outputs, the members of its uniform blocks either build-time constants
(``uniforms={"name": value}``) or arguments after the inputs, in declaration order.

Values are *flattened*: a scalar is a DSL value (or a Python number for a constant), a vector a
tuple of scalars, a matrix a tuple of columns, a struct or array a tuple of members. A variable is
the same shape with a per-lane DSL Variable at each scalar. Structured control flow (selection and
loop merges) becomes the core's if/else and loops on per-lane masks; ``break``, ``continue`` and
``return`` act per lane; an id used outside the block that makes it, and every ``OpPhi``, lives in
a variable. GLSL.std.450 instructions call the built-ins installed with :func:`set_builtins`
(``import routines`` installs ``routines.glsl``'s)."""
from __future__ import annotations

import dataclasses
import inspect
import struct
import typing

import numpy as np

from ..dsl import flow
from ..dsl.control import Return
from ..dsl.inline import inline
from ..dsl.lanes import lanes_of
from ..dsl.values import Value, value_class
from ..dsl.variables import is_variable, per_lane
from ..dsl.vectors import Vec, vec_type
from ..ir.types import KINDS, VType
from .binary import Instruction, Module, SpirvError

_BUILTINS: dict[str, typing.Callable] = {}


def set_builtins(table: dict[str, typing.Callable]) -> None:
    """Install the GLSL built-ins (GLSL name -> function over DSL scalars and vectors) that
    GLSL.std.450 instructions call; ``routines`` installs ``routines.glsl``'s when imported."""
    _BUILTINS.update(table)


def builtins_table() -> dict[str, typing.Callable]:
    """The GLSL built-ins installed; if none yet, those a package declares under the entry point
    group ``reactor.glsl_builtins`` (``routines`` declares its own), loaded."""
    if not _BUILTINS:
        from importlib.metadata import entry_points
        for point in entry_points(group="reactor.glsl_builtins"):
            set_builtins(point.load())
    return _BUILTINS


# -- types ----------------------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class Type:
    kind: str  # void bool int float vector matrix struct array pointer function
    width: int = 32
    signed: bool = True
    count: int = 0  # vector size, matrix columns, array length
    elem: typing.Any = None  # a Type: vector/matrix/array element, pointer's pointee
    members: tuple = ()
    storage: str = ""

    @property
    def scalar(self) -> bool:
        return self.kind in ("bool", "int", "float")

    def dsl(self):
        """The DSL class of a scalar or vector type (kernel arguments and results)."""
        if self.scalar:
            return value_class(VType(KINDS[_KIND[self.kind]], 1))
        if self.kind == "vector" and self.elem is not None and self.elem.scalar:
            return vec_type(_KIND[self.elem.kind], self.count)
        raise SpirvError(f"a shader interface of type {self.kind} is not supported (scalars and vectors are)")


_KIND = {"float": "Float", "int": "Int", "bool": "Bool"}


# -- the module's declarations --------------------------------------------------------------------

@dataclasses.dataclass
class Block:
    label: int
    body: list
    terminator: Instruction
    selection_merge: int | None = None
    loop: tuple[int, int] | None = None  # (merge, continue target)


@dataclasses.dataclass
class Function:
    id: int
    type: int
    params: list
    blocks: dict
    entry: int


class Declarations:
    """What a module declares: names, decorations, types, constants, global variables, functions."""

    def __init__(self, module: Module) -> None:
        self.names: dict[int, str] = {}
        self.member_names: dict[tuple[int, int], str] = {}
        self.decorations: dict[int, dict[str, list]] = {}
        self.types: dict[int, Type] = {}
        self.pointee: dict[int, int] = {}  # pointer type id -> its pointee's type id
        self.constants: dict[int, typing.Any] = {}
        self.globals: dict[int, Instruction] = {}
        self.functions: dict[int, Function] = {}
        self.imports: dict[int, str] = {}
        self.entry: Instruction | None = None
        self.capabilities: list[str] = []
        current: list[Instruction] | None = None
        for ins in module.instructions:
            if current is not None:
                current.append(ins)
                if ins.op == "OpFunctionEnd":
                    self._function(current)
                    current = None
                continue
            if ins.op == "OpFunction":
                current = [ins]
            else:
                self._declare(ins)
        if self.entry is None:
            raise SpirvError("the SPIR-V module has no OpEntryPoint")

    def _declare(self, ins: Instruction) -> None:
        op, a = ins.op, ins.args
        if op == "OpName":
            self.names[a[0]] = a[1]
        elif op == "OpMemberName":
            self.member_names[a[0], a[1]] = a[2]
        elif op == "OpDecorate":
            self.decorations.setdefault(a[0], {})[a[1]] = a[2:]
        elif op == "OpEntryPoint":
            self.entry = self.entry or ins
        elif op == "OpExtInstImport":
            self.imports[ins.id] = a[0]
        elif op == "OpCapability":
            self.capabilities.append(a[0])
        elif op.startswith("OpType"):
            self.types[ins.id] = self._type(ins)
        elif op in ("OpConstant", "OpSpecConstant"):
            self.constants[ins.id] = self._number(self.types[ins.type], a)
        elif op in ("OpConstantTrue", "OpSpecConstantTrue"):
            self.constants[ins.id] = True
        elif op in ("OpConstantFalse", "OpSpecConstantFalse"):
            self.constants[ins.id] = False
        elif op in ("OpConstantComposite", "OpSpecConstantComposite"):
            self.constants[ins.id] = tuple(self.constants[c] for c in a)
        elif op == "OpConstantNull":
            self.constants[ins.id] = zero(self.types[ins.type])
        elif op == "OpVariable":
            self.globals[ins.id] = ins
        elif op in ("OpMemberDecorate", "OpSource", "OpSourceExtension", "OpSourceContinued", "OpString",
                    "OpLine", "OpNoLine", "OpExtension", "OpMemoryModel", "OpExecutionMode", "OpModuleProcessed",
                    "OpExecutionModeId", "OpDecorateString", "OpMemberDecorateString"):
            pass
        else:
            raise SpirvError(f"{op} (SPIR-V word {ins.word}) is not supported outside functions")

    def _type(self, ins: Instruction) -> Type:
        op, a, t = ins.op, ins.args, self.types
        if op == "OpTypeVoid":
            return Type("void")
        if op == "OpTypeBool":
            return Type("bool")
        if op == "OpTypeInt":
            if a[0] != 32:
                raise SpirvError(f"{a[0]}-bit integers are not supported (32-bit are)")
            return Type("int", 32, bool(a[1]))
        if op == "OpTypeFloat":
            if a[0] != 32:
                raise SpirvError(f"{a[0]}-bit floats are not supported (32-bit are)")
            return Type("float", 32)
        if op == "OpTypeVector":
            return Type("vector", count=a[1], elem=t[a[0]])
        if op == "OpTypeMatrix":
            return Type("matrix", count=a[1], elem=t[a[0]])
        if op == "OpTypeStruct":
            return Type("struct", members=tuple(t[m] for m in a))
        if op == "OpTypeArray":
            return Type("array", count=int(self.constants[a[1]]), elem=t[a[0]])
        if op == "OpTypePointer":
            self.pointee[ins.id] = a[1]
            return Type("pointer", storage=a[0], elem=t[a[1]])
        if op == "OpTypeFunction":
            return Type("function")
        raise SpirvError(f"{op} (SPIR-V word {ins.word}) is not supported")

    @staticmethod
    def _number(typ: Type, words: list):
        if typ.kind == "float":
            return struct.unpack("<f", struct.pack("<I", words[0]))[0]
        if typ.kind == "int":
            v = words[0]
            return v - (1 << 32) if typ.signed and v >= 1 << 31 else v
        raise SpirvError(f"a constant of type {typ.kind} is not supported")

    def _function(self, instructions: list[Instruction]) -> None:
        head = instructions[0]
        params = [i for i in instructions if i.op == "OpFunctionParameter"]
        blocks: dict[int, Block] = {}
        label: int | None = None
        body: list[Instruction] = []
        entry = 0
        for ins in instructions[1:]:
            if ins.op == "OpLabel":
                label, body = ins.id, []
                entry = entry or label
            elif ins.op in ("OpBranch", "OpBranchConditional", "OpReturn", "OpReturnValue", "OpKill",
                            "OpUnreachable", "OpSwitch", "OpTerminateInvocation") and label is not None:
                block = Block(label, body, ins)
                for m in body:
                    if m.op == "OpSelectionMerge":
                        block.selection_merge = m.args[0]
                    elif m.op == "OpLoopMerge":
                        block.loop = (m.args[0], m.args[1])
                block.body = [m for m in body if m.op not in ("OpSelectionMerge", "OpLoopMerge")]
                blocks[label] = block
                label = None
            elif label is not None:
                body.append(ins)
        self.functions[head.id] = Function(head.id, head.type, params, blocks, entry)

    def name(self, id_: int, default: str = "") -> str:
        return self.names.get(id_, default or f"%{id_}")


def zero(typ: Type):
    """The flattened zero of ``typ``."""
    if typ.kind == "bool":
        return False
    if typ.kind == "int":
        return 0
    if typ.kind == "float":
        return 0.0
    if typ.kind in ("vector", "matrix", "array"):
        return tuple(zero(typ.elem) for _ in range(typ.count))
    if typ.kind == "struct":
        return tuple(zero(m) for m in typ.members)
    raise SpirvError(f"no value of type {typ.kind}")


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

    def part(self, indices) -> "Cell":
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


class Lazy:
    """A scalar of a local variable known while building (a Python number) until a DSL value or
    a store under run-time control flow makes it a per-lane Variable (declared at the entry)."""

    __slots__ = ("value", "var", "vtype", "name")

    def __init__(self, value, vtype, name: str) -> None:
        self.value, self.vtype, self.name = value, vtype, name
        self.var: typing.Any = None  # the per-lane Variable, once made

    def load(self):
        return self.value if self.var is None else self.var.value

    def store(self, value) -> None:
        from ..dsl.context import active_mask
        if self.var is None and not isinstance(value, Value) and active_mask() is None:
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


# -- functions and control flow -------------------------------------------------------------------

@dataclasses.dataclass
class Context:
    """Where a region is: the innermost loop's merge and continue targets, its header (the back
    edge), and how many constructs are open (a return at depth 0 is the function's own)."""

    merge: int | None = None
    cont: int | None = None
    header: int | None = None
    depth: int = 0
    flag: Cell | None = None  # a loop wrapped for its continues: lanes that broke out of it
    wrapped: bool = False

    def exits(self) -> set:
        """The labels a region of this loop leaves by (never walked into)."""
        return {x for x in (self.merge, self.cont, self.header) if x is not None}


class Frame:
    """The translation of one function call (the entry point's too)."""

    def __init__(self, tr: "Translator", fn: Function) -> None:
        self.tr, self.fn = tr, fn
        self.values: dict[int, typing.Any] = {}  # id -> flattened value (this block's)
        self.cells: dict[int, Cell] = {}  # id -> variable (OpVariable, access chains, spilled ids, phis)
        self.spilled = self._crossing()
        self.base = {ins.id: ins.args[0] for b in fn.blocks.values() for ins in b.body
                     if ins.op in ("OpAccessChain", "OpInBoundsAccessChain")}
        self.phis: dict[int, list] = {}  # predecessor label -> [(phi id, incoming id)]
        for block in fn.blocks.values():
            for ins in block.body:
                if ins.op == "OpPhi":
                    for k in range(0, len(ins.args), 2):
                        self.phis.setdefault(ins.args[k + 1], []).append((ins.id, ins.args[k]))
        self.result = None

    def _crossing(self) -> set[int]:
        """The ids used in a block other than the one that makes them (they live in variables)."""
        home: dict[int, int] = {}
        for label, block in self.fn.blocks.items():
            for ins in block.body:
                if ins.id and ins.op not in ("OpVariable", "OpAccessChain", "OpInBoundsAccessChain"):
                    home[ins.id] = label  # (a pointer is the same in every block)
        crossing = set()
        for label, block in self.fn.blocks.items():
            for ins in block.body + [block.terminator]:
                for a in ins.args:
                    if isinstance(a, int) and a in home and home[a] != label:
                        crossing.add(a)
        return crossing

    # values --------------------------------------------------------------------------------------

    def get(self, id_: int):
        if id_ in self.values:
            return self.values[id_]
        if id_ in self.tr.decl.constants:
            return self.tr.decl.constants[id_]
        if id_ in self.cells and id_ in self.spilled:
            return self.cells[id_].load()
        raise SpirvError(f"SPIR-V id %{id_} ({self.tr.decl.name(id_)}) is used where it has no value")

    def put(self, ins: Instruction, value) -> None:
        self.values[ins.id] = value
        if ins.id in self.spilled:
            if ins.id not in self.cells:
                self.cells[ins.id] = new_cell(self.tr.decl.types[ins.type], None, self.tr.decl.name(ins.id, "v"))
            self.cells[ins.id].store(value)

    def pointer(self, id_: int) -> Cell:
        if id_ in self.cells and id_ not in self.spilled:
            return self.cells[id_]
        if id_ in self.tr.global_cells:
            return self.tr.global_cells[id_]
        value = self.get(id_) if id_ in self.spilled else None
        if isinstance(value, Cell):
            return value
        raise SpirvError(f"SPIR-V id %{id_} ({self.tr.decl.name(id_)}) is not a pointer this front end knows")

    # regions -------------------------------------------------------------------------------------

    def run(self):
        """Translate the function; its result (None for void)."""
        self.region(self.fn.entry, set(), Context())
        return self.result

    def region(self, label: int, stop: set, ctx: Context) -> None:
        """Emit the blocks from ``label`` until a label of ``stop`` (or the path ends)."""
        while label not in stop:
            block = self.fn.blocks[label]
            if block.loop is not None:
                label = self.loop(block, ctx)
                continue
            self.values = {}
            for ins in block.body:
                self.tr.instruction(self, ins)
            self._phi_stores(label)
            nxt = self.terminate(block, ctx)
            if nxt is None:
                return
            label = nxt

    def _phi_stores(self, label: int) -> None:
        for phi, incoming in self.phis.get(label, ()):
            if phi not in self.cells:
                ins = self.tr.phi_types[phi]
                self.cells[phi] = new_cell(self.tr.decl.types[ins], None, self.tr.decl.name(phi, "phi"))
            self.cells[phi].store(self.get(incoming))

    def jump(self, target: int, ctx: Context) -> int | None:
        """A branch to ``target``: a loop exit or continue per lane, or the next block."""
        if target == ctx.merge:
            if ctx.flag is not None:
                ctx.flag.store(True)
            flow.loop_break()
            return None
        if target == ctx.cont and ctx.wrapped:
            flow.loop_break()  # out of the wrapper: on to the continue block
            return None
        return target

    def terminate(self, block: Block, ctx: Context) -> int | None:
        t = block.terminator
        if t.op == "OpBranch":
            return self.jump(t.args[0], ctx)
        if t.op == "OpBranchConditional":
            cond, yes, no = self.get(t.args[0]), t.args[1], t.args[2]
            merge = block.selection_merge
            if merge is None:  # a loop's test or an exit: one side leaves
                return self.exit_or_go(cond, yes, no, ctx)
            self.select(cond, yes, no, merge, ctx)
            return merge
        if t.op in ("OpReturn", "OpReturnValue"):
            self.leave(self.get(t.args[0]) if t.op == "OpReturnValue" else None, ctx)
            return None
        if t.op in ("OpKill", "OpTerminateInvocation"):
            raise SpirvError("discard (OpKill) is not supported yet")
        if t.op == "OpUnreachable":
            return None
        if t.op == "OpSwitch":
            return self.switch(block, ctx)
        raise SpirvError(f"{t.op} is not supported")

    def exit_or_go(self, cond, yes: int, no: int, ctx: Context) -> int | None:
        leaving = {ctx.merge, ctx.cont if ctx.wrapped else None} - {None}
        if yes in leaving and no not in leaving:
            cond, leave, go = cond, yes, no
        elif no in leaving and yes not in leaving:
            cond, leave, go = _not(cond), no, yes
        elif yes == no:
            return self.jump(yes, ctx)
        else:
            raise SpirvError("a conditional branch without a merge that neither leaves a loop nor continues it")
        if isinstance(cond, bool):
            return self.jump(leave, ctx) if cond else go
        block = flow.if_begin(cond)
        self.jump(leave, ctx)
        flow.end(block)
        return go

    def select(self, cond, yes: int, no: int, merge: int, ctx: Context) -> None:
        inner = dataclasses.replace(ctx, depth=ctx.depth + 1)
        if isinstance(cond, bool):  # a constant condition: one side
            side = yes if cond else no
            if side != merge:
                self.region(side, {merge}, inner)
            return
        self.materialize_stores(self.blocks_of([yes, no], {merge} | ctx.exits()))
        block: typing.Any = flow.if_begin(cond)
        if yes != merge:
            self.region(yes, {merge}, inner)
        flow.end(block)
        if no != merge:
            block = flow.else_begin()
            self.region(no, {merge}, inner)
            flow.end(block)

    def switch(self, block: Block, ctx: Context) -> int:
        t = block.terminator
        selector, default, pairs = self.get(t.args[0]), t.args[1], t.args[2:]
        merge = typing.cast(int, block.selection_merge)
        cases = [(pairs[k], pairs[k + 1]) for k in range(0, len(pairs), 2)]
        targets = {target for _, target in cases} | {default}
        if any(target != merge and self._falls_through(target, targets, merge) for target in targets):
            raise SpirvError("a switch case that falls through to another is not supported")
        inner = dataclasses.replace(ctx, depth=ctx.depth + 1)
        self.materialize_stores(self.blocks_of(list(targets), {merge} | ctx.exits()))
        opened = 0
        for k, (literal, target) in enumerate(cases):
            test = _dsl(selector, "Int") == literal
            blk: typing.Any = flow.if_begin(test) if k == 0 else flow.elif_begin(test)
            if target != merge:
                self.region(target, {merge}, inner)
            flow.end(blk)
            opened += 1
        if opened:
            blk = flow.else_begin()
            if default != merge:
                self.region(default, {merge}, inner)
            flow.end(blk)
        elif default != merge:
            self.region(default, {merge}, inner)
        return merge

    def _falls_through(self, label: int, targets: set, merge: int) -> bool:
        t = self.fn.blocks[label].terminator
        return t.op == "OpBranch" and t.args[0] in targets and t.args[0] != label and t.args[0] != merge

    def leave(self, value, ctx: Context) -> None:
        if self.tr.entry is self.fn:  # the shader's main: per lane, its outputs as they are
            outputs = self.tr.outputs_now()
            if ctx.depth == 0:
                self.result = outputs
            else:
                flow.return_value(outputs)
            return
        if ctx.depth == 0:
            self.result = value
        else:
            Return(to_result(value))

    def loop(self, header: Block, ctx: Context) -> int:
        """A structured loop: its body runs while any lane is in it; exits and continues per lane."""
        assert header.loop is not None
        merge, cont = header.loop
        test = self._test_block(header, merge, cont)
        if test is not None and self._unroll(header, test, merge, cont, ctx):
            return merge
        self.materialize_stores(self.blocks_of([header.label], {merge}))
        wrapped = self._continues_inside(header, cont)
        flag = new_cell(Type("bool"), False, "broke") if wrapped else None
        inner = Context(merge, cont, header.label, ctx.depth + 1, flag, wrapped)
        outer_loop = flow.while_begin(lambda: value_class(VType(KINDS["Bool"], 1))(True), lane_exits=True)
        if flag is not None:
            flag.store(False)
            wrapper, _ = flow.for_begin(0, 1, lane_exits=True)  # a continue leaves it for the continue block
        # the header's own instructions, then the body up to the continue target
        self.values = {}
        for ins in header.body:
            self.tr.instruction(self, ins)
        self._phi_stores(header.label)
        nxt = self.terminate_header(header, inner)
        if nxt is not None and nxt != cont:
            self.region(nxt, {cont, header.label}, inner)
        if flag is not None:
            flow.end(wrapper)
            after = flow.if_begin(flag.load())
            flow.loop_break()
            flow.end(after)
        if cont != header.label:
            self.region(cont, {header.label}, Context(merge, None, header.label, ctx.depth + 1))
        flow.end(outer_loop)
        return merge

    UNROLL = 64  # iterations a loop whose test is known while building is unrolled, at most

    def _test_block(self, header: Block, merge: int, cont: int) -> Block | None:
        """The block that tests a loop that can be unrolled: reached from the header by plain
        branches, its branch leaves to ``merge`` or goes on; and a body that has no exit of its own
        (no break, continue or return). None for any other loop."""
        block, chain = header, []  # type: Block, list[Block]
        while block.terminator.op == "OpBranch" and block.selection_merge is None and len(chain) < 8:
            chain.append(block)
            block = self.fn.blocks[block.terminator.args[0]]
            if block.loop is not None or block.label in (merge, cont):
                return None
        t = block.terminator
        if t.op != "OpBranchConditional" or block.selection_merge is not None or merge not in t.args[1:3]:
            return None
        body = self.blocks_of([x for x in t.args[1:3] if x != merge], {merge, cont, header.label})
        for b in body:
            bt = b.terminator
            if bt.op in ("OpReturn", "OpReturnValue", "OpKill", "OpTerminateInvocation", "OpUnreachable"):
                return None
            if bt.op in ("OpBranch", "OpBranchConditional", "OpSwitch") and merge in bt.args[1:] + bt.args[:1]:
                return None
        if self._continues_inside(header, cont):
            return None
        return block

    def _unroll(self, header: Block, test: Block, merge: int, cont: int, ctx: Context) -> bool:
        """Run the loop while building while its test is a Python value (a counter known while
        building): each iteration's body emitted in turn. False where the test is a DSL value or
        the loop is still running after ``UNROLL`` iterations: the rest runs as a run-time loop."""
        inner = Context(merge, cont, header.label, ctx.depth)
        for _ in range(self.UNROLL):
            block = header
            while True:
                self.values = {}
                for ins in block.body:
                    self.tr.instruction(self, ins)
                self._phi_stores(block.label)
                if block is test:
                    break
                block = self.fn.blocks[block.terminator.args[0]]
            cond = self.get(test.terminator.args[0])
            if not isinstance(cond, bool):
                return False
            yes, no = test.terminator.args[1:3]
            go = yes if cond else no
            if go == merge:
                return True
            if go != cont:
                self.region(go, {cont, header.label}, inner)
            if cont != header.label:
                self.region(cont, {header.label}, inner)
        return False

    def blocks_of(self, starts, stops: set) -> list[Block]:
        """The blocks reachable from ``starts`` without entering ``stops``."""
        seen: set = set()
        todo, out = list(starts), []
        while todo:
            label = todo.pop()
            if label in seen or label in stops:
                continue
            seen.add(label)
            block = self.fn.blocks[label]
            out.append(block)
            t = block.terminator
            if t.op == "OpBranch":
                todo.append(t.args[0])
            elif t.op == "OpBranchConditional":
                todo += t.args[1:3]
            elif t.op == "OpSwitch":
                todo += [t.args[1]] + t.args[3::2]
        return out

    def materialize_stores(self, blocks: list[Block]) -> None:
        """Make per-lane Variables of the locals these blocks store into (or pass by pointer),
        before a run-time branch or loop runs them."""
        for block in blocks:
            for ins in block.body:
                if ins.op == "OpStore":
                    targets = [ins.args[0]]
                elif ins.op == "OpFunctionCall":
                    targets = list(ins.args[1:])
                else:
                    continue
                for target in targets:
                    while target in self.base:
                        target = self.base[target]
                    cell = self.cells.get(target) or self.tr.global_cells.get(target)
                    if cell is not None:
                        cell.materialize()

    def terminate_header(self, header: Block, inner: Context) -> int | None:
        t = header.terminator
        if t.op == "OpBranch":
            return self.jump(t.args[0], inner)
        if t.op == "OpBranchConditional":
            return self.exit_or_go(self.get(t.args[0]), t.args[1], t.args[2], inner)
        return self.terminate(header, inner)

    def _continues_inside(self, header: Block, cont: int) -> bool:
        """Whether more than one block of the loop branches to its continue target (a continue
        statement inside the body, not only its end)."""
        count = 0
        for label, block in self.fn.blocks.items():
            t = block.terminator
            if label != cont and t.op in ("OpBranch", "OpBranchConditional") and cont in t.args[1:] + t.args[:1]:
                count += 1
        return count > 1


def to_result(value):
    """A flattened value as a DSL result (vectors as the DSL's vectors)."""
    if isinstance(value, tuple) and value and not isinstance(value[0], tuple):
        return to_vec(value)
    return value


def _not(cond):
    if isinstance(cond, bool):
        return not cond
    return ~cond


# -- instructions ---------------------------------------------------------------------------------

def _arith(fn):
    return lambda fr, ins: fr.put(ins, componentwise(fn, *[fr.get(a) for a in ins.args]))


def _fl(fn, py=None):
    """A float operation: on DSL values per lane; on Python numbers while building, in float32
    (as the shader's constant folding would)."""
    return _arith(_float_op(fn, py))


def _float_op(fn, py=None):
    def op(*xs):
        if any(isinstance(x, Value) for x in xs):
            return fn(*[_dsl(x) if not isinstance(x, Value) else x for x in xs])
        return _python((py or fn)(*[np.float32(x) for x in xs]))
    return op


def _int(fn, py=None):
    """An integer operation: per lane, or while building with int32 wrap-around."""
    def op(*xs):
        if any(isinstance(x, Value) for x in xs):
            return fn(*[_dsl(x, "Int") if not isinstance(x, Value) else x for x in xs])
        return _python((py or fn)(*[int(x) for x in xs]))
    return _arith(op)


def _bool(fn, py):
    def op(*xs):
        if any(isinstance(x, Value) for x in xs):
            return fn(*[_dsl(x, "Bool") if not isinstance(x, Value) else x for x in xs])
        return bool(py(*[bool(x) for x in xs]))
    return _arith(op)


def _python(r):
    """A result computed while building, as a Python number (ints wrapped to int32)."""
    if isinstance(r, (bool, np.bool_)):
        return bool(r)
    if isinstance(r, (int, np.integer)):
        r = int(r)
        return (r + (1 << 31)) % (1 << 32) - (1 << 31)
    return float(np.float32(r))


def _tdiv(a: int, b: int) -> int:
    q = abs(a) // abs(b)
    return q if (a < 0) == (b < 0) else -q


def _fmul(a, b):
    return _float_op(lambda x, y: x * y)(a, b)


def _fadd(a, b):
    return _float_op(lambda x, y: x + y)(a, b)


def _convert(kind: str):
    from ..dsl.intrinsics import ToInt

    def convert(x):
        if not isinstance(x, Value):
            return float(np.float32(x)) if kind == "Float" else int(x)
        if kind == "Int" and x.kind.is_float:
            return ToInt(x)
        return value_class(VType(KINDS[kind], x.width))(x)
    return _arith(convert)


def _select(fr, ins):
    from ..dsl.intrinsics import Select
    cond, a, b = (fr.get(x) for x in ins.args)
    if isinstance(cond, bool):
        fr.put(ins, a if cond else b)
        return
    fr.put(ins, componentwise(lambda c, x, y: Select(c, x, y), cond, a, b))


def _fmod(x, y):
    from ..dsl.intrinsics import Floor
    return x - y * Floor(x / y)


OPS: dict[str, typing.Callable] = {
    "OpFAdd": _fl(lambda a, b: a + b), "OpFSub": _fl(lambda a, b: a - b), "OpFMul": _fl(lambda a, b: a * b),
    "OpFDiv": _fl(lambda a, b: a / b), "OpFNegate": _fl(lambda a: -a),
    "OpFMod": _fl(_fmod, lambda a, b: a - b * np.floor(a / b)),
    "OpIAdd": _int(lambda a, b: a + b), "OpISub": _int(lambda a, b: a - b), "OpIMul": _int(lambda a, b: a * b),
    "OpSNegate": _int(lambda a: -a), "OpSDiv": _int(lambda a, b: a // b, _tdiv),
    "OpSRem": _int(lambda a, b: a % b, lambda a, b: a - b * _tdiv(a, b)), "OpSMod": _int(lambda a, b: a % b),
    "OpBitwiseAnd": _int(lambda a, b: a & b), "OpBitwiseOr": _int(lambda a, b: a | b),
    "OpBitwiseXor": _int(lambda a, b: a ^ b), "OpNot": _int(lambda a: ~a),
    "OpShiftLeftLogical": _int(lambda a, b: a << b), "OpShiftRightArithmetic": _int(lambda a, b: a >> b),
    "OpFOrdEqual": _fl(lambda a, b: a == b),
    "OpFOrdNotEqual": _fl(lambda a, b: (a != b) & (a == a) & (b == b)),
    "OpFUnordNotEqual": _fl(lambda a, b: a != b),
    "OpFOrdLessThan": _fl(lambda a, b: a < b), "OpFOrdGreaterThan": _fl(lambda a, b: a > b),
    "OpFOrdLessThanEqual": _fl(lambda a, b: a <= b), "OpFOrdGreaterThanEqual": _fl(lambda a, b: a >= b),
    "OpIEqual": _int(lambda a, b: a == b), "OpINotEqual": _int(lambda a, b: a != b),
    "OpSLessThan": _int(lambda a, b: a < b), "OpSGreaterThan": _int(lambda a, b: a > b),
    "OpSLessThanEqual": _int(lambda a, b: a <= b), "OpSGreaterThanEqual": _int(lambda a, b: a >= b),
    "OpLogicalAnd": _bool(lambda a, b: a & b, lambda a, b: a and b),
    "OpLogicalOr": _bool(lambda a, b: a | b, lambda a, b: a or b),
    "OpLogicalNot": _bool(lambda a: ~a, lambda a: not a),
    "OpLogicalEqual": _bool(lambda a, b: ~(a ^ b), lambda a, b: a == b),
    "OpLogicalNotEqual": _bool(lambda a, b: a ^ b, lambda a, b: a != b),
    "OpConvertSToF": _convert("Float"), "OpConvertFToS": _convert("Int"),
    "OpSelect": _select,
}


class Translator:
    """One module's translation into a kernel body (see the module docstring)."""

    def __init__(self, module: Module, uniforms: dict | None = None) -> None:
        self.decl = Declarations(module)
        self.uniforms = dict(uniforms or {})
        entry = typing.cast(Instruction, self.decl.entry)
        self.model, fn_id, self.entry_name, interface = entry.args[0], entry.args[1], entry.args[2], entry.args[3:]
        if self.model != "Fragment":
            raise SpirvError(f"a {self.model} shader: only fragment shaders are supported so far")
        self.entry = self.decl.functions[fn_id]
        self.phi_types = {ins.id: ins.type for f in self.decl.functions.values()
                          for b in f.blocks.values() for ins in b.body if ins.op == "OpPhi"}
        self.inputs, self.outputs, self.uniform_args = self._interface(interface)
        self.global_cells: dict[int, Cell] = {}
        self.output_cells: list[Cell] = []

    def _interface(self, interface):
        d = self.decl
        inputs, outputs = [], []
        for vid in interface:
            var = d.globals[vid]
            storage, typ = var.args[0], d.types[var.type].elem
            deco = d.decorations.get(vid, {})
            if "BuiltIn" in deco:
                if deco["BuiltIn"][0] != "FragCoord" or storage != "Input":
                    raise SpirvError(f"built-in {deco['BuiltIn'][0]} is not supported (gl_FragCoord is)")
                inputs.append((1 << 30, vid, "gl_FragCoord", typ))
            elif storage == "Input":
                inputs.append((deco.get("Location", [0])[0], vid, d.name(vid), typ))
            elif storage == "Output":
                outputs.append((deco.get("Location", [0])[0], vid, d.name(vid), typ))
        uniform_args = []
        for vid, var in d.globals.items():
            if var.args[0] != "Uniform":
                continue
            block = d.types[var.type].elem
            if block.kind != "struct":
                raise SpirvError(f"uniform {d.name(vid)} of type {block.kind}: only uniform blocks are supported")
            for k, member in enumerate(block.members):
                name = d.member_names.get((d.pointee[var.type], k), f"{d.name(vid)}.{k}")
                if name not in self.uniforms:
                    uniform_args.append((vid, k, name, member))
        return sorted(inputs), sorted(outputs), uniform_args

    # the kernel ----------------------------------------------------------------------------------

    def signature(self):
        """(parameter names, annotations, result annotation) of the kernel body."""
        names, annotations = [], {}
        for _, vid, name, typ in self.inputs:
            names.append(_identifier(name, names))
            annotations[names[-1]] = typ.dsl()
        for _, _, name, typ in self.uniform_args:
            names.append(_identifier(name, names))
            annotations[names[-1]] = typ.dsl()
        outs = [typ.dsl() for *_, typ in self.outputs]
        if not outs:
            raise SpirvError("the shader has no output (an 'out' variable with a location)")
        return names, annotations, outs[0] if len(outs) == 1 else tuple(outs)

    def body(self, *args):
        """The kernel's body: bind inputs, uniforms and outputs, translate main."""
        d = self.decl
        self.global_cells = {}
        args = list(args)
        for _, vid, _, typ in self.inputs:
            self.global_cells[vid] = Cell(_flatten(args.pop(0)))
        uniform_values: dict[tuple[int, int], typing.Any] = {
            (vid, k): _flatten(args.pop(0)) for vid, k, _, _ in self.uniform_args}
        for vid, var in d.globals.items():
            storage, typ = var.args[0], d.types[var.type].elem
            if storage == "Uniform":
                sid = d.pointee[var.type]
                members = []
                for k, member in enumerate(typ.members):
                    name = d.member_names.get((sid, k), f"{d.name(vid)}.{k}")
                    members.append(uniform_values[vid, k] if (vid, k) in uniform_values
                                   else _constant(self.uniforms[name], member))
                self.global_cells[vid] = Cell(tuple(members))
            elif storage in ("Output", "Private"):
                init = d.constants[var.args[1]] if len(var.args) > 1 else zero(typ)
                self.global_cells[vid] = new_cell(typ, init, d.name(vid))
            elif storage != "Input":
                raise SpirvError(f"{storage} variables ({d.name(vid)}) are not supported yet")
        self.output_cells = [self.global_cells[vid] for _, vid, _, _ in self.outputs]
        result = Frame(self, self.entry).run()
        return result if result is not None else self.outputs_now()

    def outputs_now(self):
        values = [to_result(c.load()) for c in self.output_cells]
        return values[0] if len(values) == 1 else tuple(values)

    # one instruction -----------------------------------------------------------------------------

    def instruction(self, fr: Frame, ins: Instruction) -> None:
        op = ins.op
        if op in OPS:
            OPS[op](fr, ins)
        elif op == "OpVariable":
            typ = self.decl.types[ins.type].elem
            init = fr.get(ins.args[1]) if len(ins.args) > 1 else None
            fr.cells[ins.id] = new_cell(typ, init, self.decl.name(ins.id, "var"), lazy=True)
        elif op == "OpLoad":
            fr.put(ins, fr.pointer(ins.args[0]).load())
        elif op == "OpStore":
            fr.pointer(ins.args[0]).store(fr.get(ins.args[1]))
        elif op in ("OpAccessChain", "OpInBoundsAccessChain"):
            indices = [fr.get(a) for a in ins.args[1:]]
            if not all(isinstance(i, int) for i in indices):
                raise SpirvError("an access chain with an index computed at run time is not supported yet")
            cell = fr.pointer(ins.args[0]).part(indices)
            fr.cells[ins.id] = cell
        elif op == "OpCompositeConstruct":
            typ = self.decl.types[ins.type]
            parts = [fr.get(a) for a in ins.args]
            if typ.kind == "vector":  # vectors of vectors and scalars concatenate
                parts = [x for p in parts for x in (p if isinstance(p, tuple) else (p,))]
            fr.put(ins, tuple(parts))
        elif op == "OpCompositeExtract":
            value = fr.get(ins.args[0])
            for k in ins.args[1:]:
                value = value[k]
            fr.put(ins, value)
        elif op == "OpCompositeInsert":
            fr.put(ins, _insert(fr.get(ins.args[1]), ins.args[2:], fr.get(ins.args[0])))
        elif op == "OpVectorShuffle":
            a, b = fr.get(ins.args[0]), fr.get(ins.args[1])
            both = list(a) + list(b)
            fr.put(ins, tuple(both[k] for k in ins.args[2:]))
        elif op == "OpVectorTimesScalar" or op == "OpMatrixTimesScalar":
            fr.put(ins, componentwise(_fmul, fr.get(ins.args[0]), fr.get(ins.args[1])))
        elif op == "OpDot":
            a, b = fr.get(ins.args[0]), fr.get(ins.args[1])
            fr.put(ins, _dot(a, b))
        elif op == "OpMatrixTimesVector":
            m, v = fr.get(ins.args[0]), fr.get(ins.args[1])
            fr.put(ins, tuple(_dot(tuple(col[r] for col in m), v) for r in range(len(m[0]))))
        elif op == "OpVectorTimesMatrix":
            v, m = fr.get(ins.args[0]), fr.get(ins.args[1])
            fr.put(ins, tuple(_dot(v, col) for col in m))
        elif op == "OpMatrixTimesMatrix":
            a, b = fr.get(ins.args[0]), fr.get(ins.args[1])
            fr.put(ins, tuple(tuple(_dot(tuple(col[r] for col in a), bc) for r in range(len(a[0]))) for bc in b))
        elif op == "OpTranspose":
            m = fr.get(ins.args[0])
            fr.put(ins, tuple(tuple(col[r] for col in m) for r in range(len(m[0]))))
        elif op == "OpExtInst":
            fr.put(ins, self.extended(ins, [fr.get(a) for a in ins.args[2:]]))
        elif op == "OpFunctionCall":
            fr.put(ins, self.call(fr, ins))
        elif op == "OpPhi":
            fr.values[ins.id] = fr.cells[ins.id].load() if ins.id in fr.cells else fr.get(ins.args[0])
        elif op in ("OpLine", "OpNoLine", "OpNop", "OpFunctionParameter"):
            pass
        else:
            raise SpirvError(f"{op} (SPIR-V word {ins.word}) is not supported yet")

    def extended(self, ins: Instruction, args):
        from .grammar import grammar
        set_name = self.decl.imports.get(ins.args[0], "")
        instructions = grammar().extended(set_name)
        if set_name != "GLSL.std.450" or instructions is None:
            raise SpirvError(f"extended instruction set {set_name!r} is not supported (GLSL.std.450 is)")
        name = instructions.by_code[ins.args[1]][0]
        glsl = _GLSL_NAMES.get(name)
        table = builtins_table()
        if glsl is None or glsl not in table:
            if not table:
                raise SpirvError("GLSL.std.450 instructions need the GLSL built-ins: import routines")
            raise SpirvError(f"GLSL.std.450 {name} is not supported yet")
        options = {"precision": "relaxed"} if "RelaxedPrecision" in self.decl.decorations.get(ins.id, {}) \
            and glsl in _ROUTINES else {}
        return from_vec(table[glsl](*[to_vec(_dsl(a) if isinstance(a, float) else a) for a in args], **options))

    def call(self, fr: Frame, ins: Instruction):
        fn = self.decl.functions[ins.args[0]]
        args = []
        for param, a in zip(fn.params, ins.args[1:]):
            if self.decl.types[param.type].kind == "pointer":
                args.append(fr.pointer(a))
            else:
                args.append(fr.get(a))

        def helper(*values):
            callee = Frame(self, fn)
            for param, v in zip(fn.params, values):
                if isinstance(v, Cell):
                    callee.cells[param.id] = v
                else:
                    callee.values[param.id] = v
                    callee.spilled.discard(param.id)
                    callee.cells[param.id] = Cell(v)
            return to_result(callee.run())
        helper.__name__ = _identifier(self.decl.name(fn.id).split("(")[0], [])
        result = inline(helper)(*args)
        return from_vec(result) if result is not None else None


_GLSL_NAMES = {
    "Round": "round", "RoundEven": "roundEven", "Trunc": "trunc", "FAbs": "abs", "SAbs": "abs", "FSign": "sign",
    "SSign": "sign", "Floor": "floor", "Ceil": "ceil", "Fract": "fract", "Radians": "radians", "Degrees": "degrees",
    "Sin": "sin", "Cos": "cos", "Tan": "tan", "Asin": "asin", "Acos": "acos", "Atan": "atan", "Sinh": "sinh",
    "Cosh": "cosh", "Tanh": "tanh", "Atan2": "atan", "Pow": "pow", "Exp": "exp", "Log": "log", "Exp2": "exp2",
    "Log2": "log2", "Sqrt": "sqrt", "InverseSqrt": "inversesqrt", "FMin": "min", "UMin": "min", "SMin": "min",
    "FMax": "max", "UMax": "max", "SMax": "max", "FClamp": "clamp", "UClamp": "clamp", "SClamp": "clamp",
    "FMix": "mix", "Step": "step", "SmoothStep": "smoothstep", "Fma": "fma", "Length": "length",
    "Distance": "distance", "Cross": "cross", "Normalize": "normalize", "FaceForward": "faceforward",
    "Reflect": "reflect", "Refract": "refract", "NMin": "min", "NMax": "max", "NClamp": "clamp",
}
_ROUTINES = {"sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "pow", "exp", "log", "exp2",
             "log2", "sqrt", "inversesqrt"}


def _dot(a, b):
    total = None
    for x, y in zip(a, b):
        term = _fmul(x, y)
        total = term if total is None else _fadd(total, term)
    return total


def _insert(value, path, composite):
    k, rest = path[0], path[1:]
    parts = list(composite)
    parts[k] = _insert(value, rest, parts[k]) if rest else value
    return tuple(parts)


def _flatten(arg):
    return tuple(arg._c) if isinstance(arg, Vec) else arg


def _constant(value, typ: Type):
    """A uniform given at build time, flattened to its type."""
    if typ.scalar:
        return float(value) if typ.kind == "float" else bool(value) if typ.kind == "bool" else int(value)
    seq = list(value)
    if len(seq) != typ.count:
        raise SpirvError(f"a uniform of {typ.count} components was given {len(seq)}")
    return tuple(_constant(v, typ.elem) for v in seq)


def _identifier(name: str, taken: list) -> str:
    base = "".join(c if c.isalnum() or c == "_" else "_" for c in name) or "arg"
    if base[0].isdigit() or base in taken or base in ("lambda", "class", "def", "in", "out", "return"):
        base = f"{base}_{len(taken)}"
    return base


def kernel_body(spirv: bytes, uniforms: dict | None = None):
    """A Python function with the shader's kernel signature that translates it (what
    ``reactor.kernel`` traces). It holds only the SPIR-V bytes and the uniforms given, so the disk
    cache keys a build by them (a warm build does not translate); marked as already written, so the
    Python rewrite leaves it alone."""
    from .binary import decode

    translator = Translator(decode(spirv), uniforms)
    names, annotations, result = translator.signature()
    given = tuple(sorted((k, _frozen(v)) for k, v in (uniforms or {}).items()))

    def body(*args):
        return run_translation(spirv, given, args)
    setattr(body, "__signature__", inspect.Signature([  # noqa: B010 - what inspect.signature reads
        inspect.Parameter(n, inspect.Parameter.POSITIONAL_OR_KEYWORD) for n in names]))
    body.__annotations__ = dict(annotations, **{"return": result})
    body.__name__ = translator.entry_name
    setattr(body, "__reactor_syntax__", True)  # noqa: B010 - already as written: not rewritten
    return body, translator


def run_translation(spirv: bytes, given: tuple, args: tuple):
    """Translate ``spirv`` (with the uniforms ``given``) into the body being built, on ``args``."""
    from .binary import decode
    return Translator(decode(spirv), dict(given)).body(*args)


def _frozen(value):
    """A uniform's value as numbers and tuples (what the build's key can state)."""
    if isinstance(value, (bool, int, float)):
        return value
    if isinstance(value, np.generic):
        return value.item()
    return tuple(_frozen(v) for v in value)
