"""The only module that drives llvmlite's ``IRBuilder``: reactor's seam to LLVM.

A ``ModuleEmitter`` owns one ``ir.Module`` and the ``Build`` (settings) it is
built with; a ``FunctionEmitter`` owns one function being built: its blocks,
its entry-block stack slots (so mem2reg turns variables into SSA values, as
Reactor does), its scopes (which values are still visible), the settings in
effect (a stack of immutable ``Build`` objects for ``fma_mode``/``precision``
blocks) and the instruction cursor.

The layers above never see an ``IRBuilder`` or an llvmlite type: they call the
named, typed operations here (the vocabulary of SwiftShader's Nucleus and of
IRBuilder: ``fadd``, ``icmp``, ``load``, ``address`` ...), name types with
``reactor.ir.types`` and semantic operations with ``reactor.ir.ops``.

The emitter of the function being built is thread-local: each thread builds
with its own emitter stack, so building is thread-safe.
"""
from __future__ import annotations

import contextlib
import threading
import typing

from llvmlite import ir

from ..errors import ControlFlowError, ReactorError, ScopeError
from . import types as T

_tls = threading.local()


def _stack() -> list["FunctionEmitter"]:
    stack = getattr(_tls, "stack", None)
    if stack is None:
        stack = _tls.stack = []
    return stack


def current() -> "FunctionEmitter":
    """The emitter of the innermost function being built on this thread."""
    stack = _stack()
    if not stack:
        raise ScopeError(
            "DSL operation outside a function being built: wrap this code in a "
            "reactor.Function, @reactor.function or @reactor.kernel body"
        )
    return stack[-1]


def building() -> bool:
    return bool(_stack())


class Scope:
    """A lexical region (function body, branch, loop body) whose values die at its end."""

    __slots__ = ("parent", "what", "closed", "chain", "where")

    def __init__(self, parent: "Scope | None", what: str):
        self.parent, self.what, self.closed = parent, what, False
        self.chain = None  # for Elif/Else bodies: the merge block of their If chain
        self.where = None  # (file, line) of the user's code that opened it


_ARCH_INTRINSICS = {"x86_64": "llvm.x86.", "aarch64": "llvm.aarch64."}


def _check_architecture(name: str, target) -> None:
    """Refuse an intrinsic of another architecture (``llvm.x86.*`` in AArch64 code): LLVM would
    fail on it much later, with an assertion instead of a message."""
    for arch, prefix in _ARCH_INTRINSICS.items():
        if name.startswith(prefix) and target.arch != arch:
            raise ReactorError(f"{name} is an {arch} instruction and cannot be emitted for target "
                               f"'{target.name}' ({target.arch}); use a portable operation there")


class ModuleEmitter:
    """One LLVM module: a compilation unit holding several functions, built with one ``Build``.

    With ``lines`` every instruction carries the user's source line as a debug location
    (``!dbg``), which survives optimization and reaches the assembly as ``.loc`` directives
    (``reactor.explain`` reads them); the code is otherwise the same."""

    def __init__(self, name: str, build, lines: bool = False):
        self.build = build
        self.module = ir.Module(name=name)
        self.module.triple = build.target.triple
        self.module.data_layout = build.target.data_layout
        self.lines = _SourceLines(self.module) if lines else None
        self.routine_name: str | None = None  # the outermost routine being emitted (for lines)
        self.functions: dict[object, ir.Function] = {}
        self.imports: dict[str, int] = {}  # external symbol -> address (see dsl/external.py)
        self.import_libraries: dict[str, str | None] = {}  # external symbol -> its library
        self._text: str | None = None
        self.written: dict[object, frozenset] = {}  # (Function, width) -> pointer parameters it stores to
        # what the DSL notes for the caller (reactor.dsl.calls, reactor.dsl.limits):
        self.routine_calls: list = []  # RoutineCall, in order of first use
        self.routine_depth = 0  # > 0 while a routine emits (its inner routines are its own)
        self.runaway_messages: list[str] = []  # of loops with max_iterations, by status - 1

    def counter(self, name: str):
        """A module-level 32-bit integer variable initialized to 0 (made once per name), visible
        to the JIT by ``name`` (for a status its code leaves for the caller)."""
        try:
            return self.module.get_global(name)
        except KeyError:
            g = ir.GlobalVariable(self.module, ir.IntType(32), name=name)
            g.initializer = ir.Constant(ir.IntType(32), 0)
            return g

    def constant_array(self, key, vt: "T.VType", values, name: str):
        """A module-level constant array of ``values`` (of ``vt``'s kind, in memory form), made
        once per ``key``; returns its address as a byte pointer value."""
        cache = self.__dict__.setdefault("_constant_arrays", {})
        g = cache.get(key)
        if g is None:
            elem = _llvm(T.memory(vt.with_width(1)))
            array = ir.ArrayType(elem, len(values))
            g = ir.GlobalVariable(self.module, array, name=self.unique_name(name))
            g.global_constant = True
            g.linkage = "internal"
            g.initializer = ir.Constant(array, [ir.Constant(elem, v) for v in values])
            g.align = 64
            cache[key] = g
        return g

    def unique_name(self, base: str) -> str:
        names = {g.name for g in self.module.global_values}
        i = 0
        name = base
        while name in names:
            i += 1
            name = f"{base}.{i}"
        return name

    def declare(self, name: str, ret, args) -> ir.Function:
        """Declare an external or intrinsic function once per module (types: reactor
        types or, inside ``reactor.ir``, LLVM types)."""
        try:
            return self.module.get_global(name)
        except KeyError:
            _check_architecture(name, self.build.target)
            fnty = ir.FunctionType(_llvm(ret), [_llvm(a) for a in args])
            return ir.Function(self.module, fnty, name=name)

    @property
    def text(self) -> str:
        """The module's IR as text (serialized once, when first asked for)."""
        if self._text is None:
            self._text = str(self.module)
        return self._text

    @staticmethod
    def instruction_count(fn) -> int:
        """How many instructions function ``fn`` of this module holds (as built)."""
        return sum(len(block.instructions) for block in fn.blocks)


def _llvm(t) -> ir.Type:
    if t is None:
        return ir.VoidType()
    return t if isinstance(t, ir.Type) else t.ir


def _same_type(what: str, *values) -> None:
    first = values[0].type
    if all(v.type is first for v in values[1:]):
        return
    types = {str(v.type) for v in values}
    if len(types) > 1:
        raise TypeError(f"{what}: operand types differ ({', '.join(sorted(types))})")


# Binary instructions: emitter method -> (IRBuilder method, operand category).
_BINARY = {
    "add": ("add", "int"), "sub": ("sub", "int"), "mul": ("mul", "int"),
    "sdiv": ("sdiv", "int"), "udiv": ("udiv", "int"), "srem": ("srem", "int"), "urem": ("urem", "int"),
    "and_": ("and_", "int"), "or_": ("or_", "int"), "xor": ("xor", "int"),
    "shl": ("shl", "int"), "ashr": ("ashr", "int"), "lshr": ("lshr", "int"),
    "fadd": ("fadd", "float"), "fsub": ("fsub", "float"), "fmul": ("fmul", "float"), "fdiv": ("fdiv", "float"),
}
# Conversions: emitter method -> IRBuilder method.
_CASTS = ("fptosi", "fptoui", "sitofp", "uitofp", "fpext", "fptrunc", "zext", "sext", "trunc",
          "bitcast", "ptrtoint")


def _element(t: ir.Type) -> ir.Type:
    return t.element if isinstance(t, ir.VectorType) else t


#: A location's column is its group (0: the user's own code, k: the k-th routine emitted there),
#: plus this for a kernel's width-1 tail body (so its copy of a line is told from the vector one's).
TAIL_COLUMN = 100


class _SourceLines:
    """The debug metadata of a module built with lines: files, subprograms and locations. A
    location's column is its group: 0 for the user's own code, k for the k-th routine (exp2,
    pow ...) emitted there (``groups``), plus ``TAIL_COLUMN`` in a kernel's tail body."""

    def __init__(self, module: ir.Module) -> None:
        self.module = module
        self.files: dict[str, typing.Any] = {}
        self.groups: list[str] = [""]
        self._locations: dict[tuple, typing.Any] = {}
        self._scopes: dict[tuple, typing.Any] = {}
        i32 = ir.IntType(32)
        module.add_named_metadata("llvm.module.flags", module.add_metadata([i32(2), "Debug Info Version", i32(3)]))
        module.add_named_metadata("llvm.module.flags", module.add_metadata([i32(2), "Dwarf Version", i32(4)]))
        self.unit = module.add_debug_info("DICompileUnit", {
            "language": ir.DIToken("DW_LANG_C99"), "file": self.file("<reactor>"), "producer": "reactor",
            "runtimeVersion": 0, "isOptimized": True, "emissionKind": ir.DIToken("FullDebug")}, is_distinct=True)
        module.add_named_metadata("llvm.dbg.cu", self.unit)
        self.signature = module.add_debug_info("DISubroutineType", {"types": module.add_metadata([])})

    def file(self, path: str):
        found = self.files.get(path)
        if found is None:
            import os
            found = self.files[path] = self.module.add_debug_info(
                "DIFile", {"filename": os.path.basename(path), "directory": os.path.dirname(path) or "."})
        return found

    def subprogram(self, name: str):
        return self.module.add_debug_info("DISubprogram", {
            "name": name, "file": self.file("<reactor>"), "line": 0, "type": self.signature, "unit": self.unit,
            "spFlags": ir.DIToken("DISPFlagDefinition | DISPFlagOptimized"), "scopeLine": 0}, is_distinct=True)

    def group(self, routine: str | None) -> int:
        name = routine or ""
        if name not in self.groups:
            self.groups.append(name)
        return self.groups.index(name)

    def relocate(self, location, subprogram):
        """``location`` (a DILocation of another function) in ``subprogram``: same file, line, group."""
        fields = dict(location.operands)
        scope = dict(fields["scope"].operands) if fields["scope"].kind == "DILexicalBlockFile" else {}
        paths = {id(f): p for p, f in self.files.items()}
        path = paths.get(id(scope["file"])) if "file" in scope else None
        return self.location(subprogram, path, fields["line"], fields["column"])

    def location(self, subprogram, path: str | None, line: int, group: int):
        key = (id(subprogram), path, line, group)
        loc = self._locations.get(key)
        if loc is None:
            scope = subprogram
            if path is not None:
                skey = (id(subprogram), path)
                scope = self._scopes.get(skey)
                if scope is None:
                    scope = self._scopes[skey] = self.module.add_debug_info(
                        "DILexicalBlockFile", {"scope": subprogram, "file": self.file(path), "discriminator": 0})
            loc = self._locations[key] = self.module.add_debug_info(
                "DILocation", {"line": line, "column": group, "scope": scope})
        return loc


class _LocatingBuilder:
    """An ``ir.IRBuilder`` that gives every instruction it makes the current source location."""

    _PLAIN = frozenset({"position_at_end", "position_at_start", "position_before", "position_after",
                        "goto_block", "goto_entry_block", "block", "function", "module"})

    def __init__(self, builder: ir.IRBuilder, emitter: "FunctionEmitter") -> None:
        self.__dict__["_builder"], self.__dict__["_emitter"] = builder, emitter

    def __getattr__(self, name: str):
        attr = getattr(self._builder, name)
        if name in self._PLAIN or not callable(attr):
            return attr

        def located(*args, **kwargs):
            self._builder.debug_metadata = self._emitter.source_location()
            return attr(*args, **kwargs)
        return located

    def __setattr__(self, name: str, value) -> None:
        setattr(self._builder, name, value)


def _category(t: ir.Type) -> str:
    e = _element(t)
    return "float" if isinstance(e, (ir.FloatType, ir.DoubleType, ir.HalfType)) else "int"


class FunctionEmitter:
    """Builds the body of one LLVM function at one SIMD ``width``.

    ``params``/``ret`` are reactor types (``VType``, ``PointerType``,
    ``StructType``; ``ret=None`` is void). ``internal`` functions are private
    to the module; ``inline`` is "always", "never" or None (LLVM decides).
    """

    def __init__(self, module: ModuleEmitter, name: str, ret, params, param_names, *,
                 width: int | None = None, internal: bool = False, inline: str | None = None):
        self.module = module
        self.width = width or module.build.width
        self._settings = [module.build]
        self.front: object = None  # the front end's state of this function (opaque here: reactor.dsl.context)
        #: the source-location provider the front end installs: the user's (file, line) now, or None
        self.locate: typing.Callable[[], tuple[str, int] | None] | None = None
        self.tail_body = False  # a kernel's width-1 body beside its vector body (a column of its own)
        self._at_finish: list[typing.Callable[[set], None]] = []  # given the ids of the values used
        self.pure_calls: dict = {}  # pure calls emitted (dsl.calls.reuse): key -> (result, operands)
        fnty = ir.FunctionType(_llvm(ret), [_llvm(p) for p in params])
        self.function = ir.Function(module.module, fnty, name=name)
        for arg, argname in zip(self.function.args, param_names):
            arg.name = argname
        if internal:
            self.function.linkage = "internal"
        if inline == "always":
            self.function.attributes.add("alwaysinline")
        elif inline == "never":
            self.function.attributes.add("noinline")
        self.function.attributes.add("nounwind")
        self._entry = self.function.append_basic_block("entry")
        body = self.function.append_basic_block("body")
        self._b = ir.IRBuilder(self._entry)
        self._subprogram = None
        if module.lines is not None:
            self._subprogram = module.lines.subprogram(name)
            self.function.set_metadata("dbg", self._subprogram)
            self._b = typing.cast(ir.IRBuilder, _LocatingBuilder(self._b, self))
        self._b.branch(body)
        self._b.position_at_end(body)
        self.scope: Scope = Scope(None, "function")
        self.root_scope = self.scope
        self.ret_type = ret
        self.pending_chain = None  # (else_block, merge_block, mark) after an If/Elif

    def source_location(self):
        """The debug location of the instruction being made: the user's line while a body is
        traced (its routine's group inside a routine), line 0 for reactor's own plumbing."""
        lines = self.module.lines
        where = self.locate() if self.locate is not None else None
        if where is None:
            return lines.location(self._subprogram, None, 0, 0)
        column = lines.group(self.module.routine_name) + (TAIL_COLUMN if self.tail_body else 0)
        return lines.location(self._subprogram, where[0], where[1], column)

    @property
    def name(self) -> str:
        return self.function.name

    @property
    def params(self) -> list:
        """The function's parameters (IR values)."""
        return list(self.function.args)

    # -- activation -----------------------------------------------------
    def __enter__(self):
        _stack().append(self)
        return self

    def __exit__(self, *exc):
        popped = _stack().pop()
        assert popped is self

    # -- settings -------------------------------------------------------------
    @property
    def settings(self):
        """The ``Build`` in effect at the cursor (the module's, or a block's override)."""
        return self._settings[-1]

    @contextlib.contextmanager
    def overriding(self, **changes):
        """Emit the block with some settings changed (e.g. ``fma=False``)."""
        self._settings.append(self.settings.replace(**changes))
        try:
            yield self.settings
        finally:
            self._settings.pop()

    # -- arithmetic and logic ----------------------------------------------------
    def _binary(self, op: str, a, b, name: str):
        method, category = _BINARY[op]
        _same_type(op, a, b)
        if _category(a.type) != category:
            raise TypeError(f"{op} needs {category} operands, not {a.type}")
        return getattr(self._b, method)(a, b, name=name or op.rstrip("_"))

    def neg(self, a, name="neg"):
        return self._b.neg(a, name=name)

    def fneg(self, a, name="fneg"):
        return self._b.fneg(a, name=name)

    def icmp(self, pred: str, a, b, *, signed: bool, name: str = "cmp"):
        """Integer comparison (``pred`` one of < <= > >= == !=)."""
        _same_type("icmp", a, b)
        return (self._b.icmp_signed if signed else self._b.icmp_unsigned)(pred, a, b, name=name)

    def fcmp(self, pred: str, a, b, *, ordered: bool = True, name: str = "cmp"):
        """Float comparison: ordered (false on NaN) or unordered (true on NaN); ``pred``
        one of < <= > >= == != or "uno"/"ord"."""
        _same_type("fcmp", a, b)
        return (self._b.fcmp_ordered if ordered else self._b.fcmp_unordered)(pred, a, b, name=name)

    def select(self, cond, a, b, name: str = "select"):
        _same_type("select", a, b)
        return self._b.select(cond, a, b, name=name)

    def convert(self, op: str, value, to, name: str = "conv"):
        """A conversion instruction (``op`` one of fptosi fptoui sitofp uitofp fpext
        fptrunc zext sext trunc bitcast ptrtoint) to reactor type ``to``."""
        if op not in _CASTS:
            raise ValueError(f"unknown conversion {op!r}")
        return getattr(self._b, op)(value, _llvm(to), name=name)

    def bitcast(self, value, to, name: str = "cast"):
        return self._b.bitcast(value, _llvm(to), name=name)

    def freeze(self, value, name: str = ""):
        """``freeze``: turn a possibly-poison value into an arbitrary fixed one."""
        instr = ir.instructions.Instruction(self._b.block, value.type, "freeze", [value], name=name)
        self._b._insert(instr)
        return instr

    # -- vectors ----------------------------------------------------------------------
    def extract(self, vector, index, name: str = "lane"):
        """Lane ``index`` (an int or an i32 value) of ``vector``."""
        return self._b.extract_element(vector, _i32(index), name=name)

    def insert(self, vector, scalar, index, name: str = "insert"):
        return self._b.insert_element(vector, scalar, _i32(index), name=name)

    def shuffle(self, a, b, lanes, name: str = "shuffle"):
        """Lanes of the concatenation ``a ++ b`` picked by the Python ints ``lanes``."""
        mask = ir.Constant(ir.VectorType(ir.IntType(32), len(lanes)), [ir.Constant(ir.IntType(32), i)
                                                                       for i in lanes])
        return self._b.shuffle_vector(a, b, mask, name=name)

    def splat(self, scalar, width: int, name: str = "splat"):
        """Broadcast a scalar to ``width`` lanes (width 1: unchanged)."""
        if width == 1:
            return scalar
        undef = ir.Constant(ir.VectorType(scalar.type, width), ir.Undefined)
        one = self._b.insert_element(undef, scalar, ir.Constant(ir.IntType(32), 0), name=name)
        return self.shuffle(one, undef, [0] * width, name=name)

    def pack(self, struct: "T.StructType", values, name: str = "results"):
        """A struct value holding ``values``."""
        agg = ir.Constant(struct.ir, ir.Undefined)
        for i, v in enumerate(values):
            agg = self._b.insert_value(agg, v, i, name=name)
        return agg

    def unpack(self, value, count: int, name: str = "result"):
        return [self._b.extract_value(value, i, name=f"{name}{i}") for i in range(count)]

    # -- memory -------------------------------------------------------------------------
    def alloca(self, t, name: str, count: int = 1):
        """A stack slot (``count`` elements) in the entry block (promoted to registers by mem2reg)."""
        with self._b.goto_block(self._entry):
            self._b.position_at_start(self._entry)
            size = None if count == 1 else ir.Constant(ir.IntType(64), count)
            return self._b.alloca(_llvm(t), size=size, name=name)

    def store_at_entry(self, value, ptr):
        """Store ``value`` to ``ptr`` in the entry block (an initial value that dominates every use)."""
        with self._b.goto_block(self._entry):
            self._b.position_before(self._entry.terminator)
            return self._b.store(value, ptr)

    @contextlib.contextmanager
    def block_start(self, block):
        """A context in which what is emitted goes to the start of ``block`` (after its phis)."""
        phis = [i for i in block.instructions if isinstance(i, ir.PhiInstr)]
        with self._b.goto_block(block):
            if phis:
                self._b.position_after(phis[-1])
            else:
                self._b.position_at_start(block)
            yield

    def entry_cursor(self):
        """A context in which what is emitted goes to the end of the entry block."""
        return _at_entry(self)

    def adopt(self, instruction) -> None:
        """Move ``instruction`` (of another function of this module) to the cursor, unchanged but
        for its debug location: the same line, in this function's scope."""
        where = instruction.metadata.pop("dbg", None)
        if where is not None and self._subprogram is not None and self.module.lines is not None:
            instruction.metadata["dbg"] = self.module.lines.relocate(where, self._subprogram)
        instruction.parent = self._b.block
        instruction.name = instruction.name  # registered in this function's names
        self._b._insert(instruction)

    def load(self, ptr, *, align: int | None = None, name: str = "load"):
        return self._b.load(ptr, name=name, align=align)

    def store(self, value, ptr, *, align: int | None = None):
        return self._b.store(value, ptr, align=align)

    def address(self, ptr, index, name: str = "addr"):
        """``&ptr[index]`` (in elements of the pointee; ``index`` an int or an i64 value)."""
        idx = ir.Constant(ir.IntType(64), index) if isinstance(index, int) else index
        return self._b.gep(ptr, [idx], inbounds=True, name=name)

    def gather(self, vt: "T.VType", base, offsets, mask=None, name: str = "gather"):
        """Lanes of ``vt`` (in its memory form) read from ``base + offsets[lane]`` bytes: ``base``
        a pointer, ``offsets`` an i64 value of ``vt``'s width. Lanes off in ``mask`` read nothing
        and give 0. One ``llvm.masked.gather`` (a gather instruction where the target has a
        fast one), a plain load at width 1."""
        mem = T.memory(vt)
        elem = _llvm(mem.with_width(1))
        if vt.width == 1:
            ptr = self._b.bitcast(self._b.gep(self._b.bitcast(base, ir.IntType(8).as_pointer()), [offsets]),
                                  elem.as_pointer())
            if mask is None:
                return self._b.load(ptr, name=name, align=vt.kind.mem_bytes)
            read, done, here = self.new_block(f"{name}.read"), self.new_block(f"{name}.done"), self._b.block
            self._b.cbranch(mask, read, done)
            self._b.position_at_end(read)
            got = self._b.load(ptr, name=name, align=vt.kind.mem_bytes)
            self._b.branch(done)
            self._b.position_at_end(done)
            phi = self._b.phi(elem, name=name)
            phi.add_incoming(ir.Constant(elem, 0), here)
            phi.add_incoming(got, read)
            return phi
        ptrs = self._lane_pointers(base, offsets, elem, vt.width, name)
        mask = mask if mask is not None else ir.Constant(ir.VectorType(ir.IntType(1), vt.width), [1] * vt.width)
        vec = _llvm(mem)
        fn = self.intrinsic(f"llvm.masked.gather.{T.mangle(vec)}.v{vt.width}p0", vec,
                            [ptrs.type, ir.IntType(32), mask.type, vec])
        return self._b.call(fn, [ptrs, ir.Constant(ir.IntType(32), vt.kind.mem_bytes), mask,
                                 ir.Constant(vec, None)], name=name)

    def scatter(self, vt: "T.VType", value, base, offsets, mask=None) -> None:
        """Store the lanes of ``value`` (memory form of ``vt``) at ``base + offsets[lane]`` bytes,
        the lanes on in ``mask`` only (lanes writing one address: the highest lane wins)."""
        mem = T.memory(vt)
        elem = _llvm(mem.with_width(1))
        if vt.width == 1:
            ptr = self._b.bitcast(self._b.gep(self._b.bitcast(base, ir.IntType(8).as_pointer()), [offsets]),
                                  elem.as_pointer())
            if mask is None:
                self._b.store(value, ptr, align=vt.kind.mem_bytes)
                return
            write, done = self.new_block("scatter.write"), self.new_block("scatter.done")
            self._b.cbranch(mask, write, done)
            self._b.position_at_end(write)
            self._b.store(value, ptr, align=vt.kind.mem_bytes)
            self._b.branch(done)
            self._b.position_at_end(done)
            return
        ptrs = self._lane_pointers(base, offsets, elem, vt.width, "scatter")
        mask = mask if mask is not None else ir.Constant(ir.VectorType(ir.IntType(1), vt.width), [1] * vt.width)
        fn = self.intrinsic(f"llvm.masked.scatter.{T.mangle(value.type)}.v{vt.width}p0", ir.VoidType(),
                            [value.type, ptrs.type, ir.IntType(32), mask.type])
        self._b.call(fn, [value, ptrs, ir.Constant(ir.IntType(32), vt.kind.mem_bytes), mask])

    def load_rows(self, vt: "T.VType", base, offsets, count: int, name: str = "row"):
        """For each lane, ``count`` consecutive elements of ``vt``'s kind (in memory form) at
        ``base + offsets[lane]`` bytes, read with one vector load per lane, given back as ``count``
        values of ``vt`` (element k of every lane: a transpose by shuffles). Every lane reads, so
        the caller makes each offset valid. Where gathers are slow (AMD, AArch64), this costs
        less than ``count`` gathers."""
        return self.ungroup(self.row_groups(vt, base, offsets, count, name), count, name)

    def row_groups(self, vt: "T.VType", base, offsets, count: int, name: str = "row") -> list:
        """The rows of :meth:`load_rows` as they lie in memory: ``count`` vectors of ``vt``'s width,
        the k-th holding lanes k*g .. k*g + g - 1 (g = width // count) side by side."""
        row = ir.VectorType(_llvm(T.memory(vt).with_width(1)), count)
        bytes_ = self._b.bitcast(base, ir.IntType(8).as_pointer())
        rows = [self._b.load(self._b.bitcast(self._b.gep(bytes_, [self.extract(offsets, lane, name=f"{name}.at")]),
                                             row.as_pointer()), name=name, align=vt.kind.mem_bytes)
                for lane in range(vt.width)]
        while rows[0].type.count < vt.width:  # concatenate pairwise
            n = rows[0].type.count
            rows = [self.shuffle(rows[i], rows[i + 1], list(range(2 * n)), name=f"{name}s")
                    for i in range(0, len(rows), 2)]
        return rows

    def ungroup(self, groups: list, count: int, name: str = "row") -> list:
        """``count`` vectors of lane values side by side (as :meth:`row_groups` gives them) as
        ``count`` vectors of one element each (a transpose by shuffles)."""
        while len(groups) > 1:
            n = groups[0].type.count
            groups = [self.shuffle(groups[i], groups[i + 1], list(range(2 * n)), name=f"{name}s")
                      for i in range(0, len(groups), 2)]
        whole, width = groups[0], groups[0].type.count // count
        return [self.shuffle(whole, whole, [lane * count + k for lane in range(width)], name=f"{name}.{k}")
                for k in range(count)]

    def _lane_pointers(self, base, offsets, elem, width: int, name: str):
        """A vector of ``width`` pointers ``base + offsets[lane]`` (llvmlite's GEP takes no vectors)."""
        i64 = ir.IntType(64)
        start = self.splat(self._b.ptrtoint(base, i64, name=f"{name}.base"), width, name=f"{name}.base")
        return self._b.inttoptr(self._b.add(start, offsets, name=f"{name}.addr"),
                                ir.VectorType(elem.as_pointer(), width), name=f"{name}.ptrs")

    def field(self, ptr, index: int, name: str = "field"):
        """``&ptr->field[index]`` of a pointer to a struct."""
        return self._b.gep(ptr, [ir.Constant(ir.IntType(32), 0), ir.Constant(ir.IntType(32), index)], name=name)

    def cast_pointer(self, ptr, pointee, name: str = "p"):
        """``ptr`` seen as a pointer to ``pointee`` (a reactor type)."""
        target = _llvm(pointee).as_pointer()
        return ptr if ptr.type == target else self._b.bitcast(ptr, target, name=name)

    # -- calls ---------------------------------------------------------------------------
    def call(self, fn, args, name: str = "", inline: str | None = None):
        """Call ``fn``; ``inline`` "always"/"never" marks this call site only."""
        instr = self._b.call(fn, args, name=name)
        if inline == "always":
            instr.attributes.add("alwaysinline")
        elif inline == "never":
            instr.attributes.add("noinline")
        return instr

    def call_pointer(self, ptr, ret, params, args, name: str = ""):
        """Call the function at address ``ptr`` (any pointer) of type ``ret(params...)`` (reactor types)."""
        fnty = ir.FunctionType(_llvm(ret), [_llvm(p) for p in params])
        fn = self._b.bitcast(ptr, fnty.as_pointer(), name="fnptr")
        return self._b.call(fn, args, name=name)

    def function_address(self, fn, name: str = "fn"):
        """The address of function ``fn`` of this module, as a byte pointer."""
        return self._b.bitcast(fn, ir.IntType(8).as_pointer(), name=name)

    def atomic_add(self, ptr, value, name: str = "old"):
        """Atomically add ``value`` to ``*ptr`` (monotonic order); the value before."""
        return self._b.atomic_rmw("add", ptr, value, "monotonic", name=name)

    def atomic_swap(self, ptr, value, name: str = "old"):
        """Atomically replace ``*ptr`` by ``value``; the value before."""
        return self._b.atomic_rmw("xchg", ptr, value, "monotonic", name=name)

    def intrinsic(self, name: str, ret, args) -> ir.Function:
        return self.module.declare(name, ret, args)

    # -- names ----------------------------------------------------------------------------
    @staticmethod
    def set_name(value, name: str) -> None:
        """Give an instruction a readable name (shown in IR dumps); constants keep none."""
        if hasattr(value, "name") and not isinstance(value, ir.Constant):
            value.name = name

    # -- blocks ----------------------------------------------------------
    @property
    def block(self) -> ir.Block:
        return self._b.block

    def new_block(self, name: str) -> ir.Block:
        return self.function.append_basic_block(name)

    def terminated(self) -> bool:
        return self._b.block.is_terminated

    def goto(self, block: ir.Block) -> None:
        self._b.position_at_end(block)

    position_at = goto

    def branch(self, target: ir.Block) -> None:
        self._b.branch(target)

    def branch_to(self, target: ir.Block) -> None:
        """Branch to ``target`` unless the current block already ended (e.g. Return)."""
        if not self._b.block.is_terminated:
            self._b.branch(target)

    def cbranch(self, cond, then_block: ir.Block, else_block: ir.Block):
        return self._b.cbranch(cond, then_block, else_block)

    # -- structured control for plumbing code (llvmlite's if_then/if_else are the model) ----
    @contextlib.contextmanager
    def if_then(self, cond, name: str = "if"):
        """``with em.if_then(cond):`` the block's code runs where ``cond`` (an i1) holds; after
        the block, code continues where both paths meet."""
        then, merge = self.new_block(f"{name}.then"), self.new_block(f"{name}.end")
        self.cbranch(cond, then, merge)
        self.goto(then)
        yield
        self.branch_to(merge)
        self.goto(merge)

    @contextlib.contextmanager
    def if_else(self, cond, name: str = "if"):
        """``with em.if_else(cond) as (then, otherwise):`` then ``with then: ...`` and ``with
        otherwise: ...``; after the block, code continues where the paths meet."""
        then, other, merge = self.new_block(f"{name}.then"), self.new_block(f"{name}.else"), self.new_block(f"{name}.end")
        self.cbranch(cond, then, other)

        @contextlib.contextmanager
        def arm(block):
            self.goto(block)
            yield
            self.branch_to(merge)

        yield arm(then), arm(other)
        self.goto(merge)

    @contextlib.contextmanager
    def counting(self, start, stop, name: str = "for"):
        """``with em.counting(start, stop) as j:`` the block runs for j = start, start + 1, ...
        while j < stop (signed i64 values, or Python ints)."""
        start, stop = (T.const(T.INDEX, v) if isinstance(v, int) else v for v in (start, stop))
        slot = self.alloca(T.INDEX, f"{name}.j")
        self.store(start, slot)
        head, each, done = self.new_block(f"{name}.cond"), self.new_block(f"{name}.each"), self.new_block(f"{name}.done")
        self.branch(head)
        self.goto(head)
        self.cbranch(self.icmp("<", self.load(slot, name="j"), stop, signed=True), each, done)
        self.goto(each)
        j = self.load(slot, name="j")
        yield j
        self.store(self._binary("add", j, T.const(T.INDEX, 1), "next"), slot)
        self.branch(head)
        self.goto(done)

    def always_take(self, branch) -> None:
        """Make a conditional branch (from ``cbranch``) always go to its first target (LLVM then
        drops the test and the other edge)."""
        branch.operands[0] = ir.Constant(ir.IntType(1), 1)

    @staticmethod
    def straight_and_cheap(block: ir.Block, limit: int) -> bool:
        """Whether ``block`` is at most ``limit`` instructions of arithmetic, comparisons, selects,
        lane moves and pure intrinsics, besides accesses to local variables (which registers
        replace): safe and cheap to run for no lane at all (no memory but allocas, no calls but
        ``llvm.*``, no control flow)."""
        work = 0
        for inst in block.instructions:
            op = inst.opname
            if op in ("load", "store"):
                ptr = inst.operands[0] if op == "load" else inst.operands[1]
                if not isinstance(ptr, ir.AllocaInstr):
                    return False
                continue
            work += 1
            if work > limit:
                return False
            if op == "call":
                callee_name = str(getattr(getattr(inst, "callee", None), "name", ""))
                if not callee_name.startswith("llvm.") or "mxcsr" in callee_name or "fpsr" in callee_name:
                    return False
            elif op in ("br", "ret", "switch", "unreachable", "alloca", "phi", "atomicrmw", "cmpxchg",
                        "getelementptr"):
                return False
        return True

    def phi(self, t, incoming, name: str = "phi"):
        """A phi node of reactor type ``t`` with ``[(value, block), ...]``."""
        node = self._b.phi(_llvm(t), name=name)
        for value, block in incoming:
            node.add_incoming(value, block)
        return node

    def ret(self, value) -> None:
        if value is None:
            self._b.ret_void()
        else:
            self._b.ret(value)
        # Code written after a Return in the same block is unreachable; give it
        # a block of its own so emission can continue.
        self._b.position_at_end(self.new_block("after.return"))

    # -- If-chain bookkeeping (see dsl/control.py) ----------------------------
    def claim_since_chain(self, else_block: ir.Block, merge: ir.Block, mark: int) -> None:
        """Move instructions emitted into ``merge`` since ``mark`` to ``else_block``.

        Used by Elif: its condition is computed (by Python) after the previous
        branch closed, so it landed in the merge block; it belongs to the path
        where the previous conditions were false.
        """
        moved = merge.instructions[mark:]
        del merge.instructions[mark:]
        at = len(else_block.instructions) - (1 if else_block.is_terminated else 0)
        for instr in moved:
            instr.parent = else_block
            instr.reactor_chain = merge  # now only valid inside this chain (see in_chain)
        else_block.instructions[at:at] = moved

    def reopen(self, block: ir.Block) -> None:
        """Remove ``block``'s terminator and continue emitting at its end."""
        if block.is_terminated:
            block.instructions.remove(block.terminator)
            block.terminator = None
        self._b.position_at_end(block)

    def mark(self) -> int:
        """How many instructions the current block holds (for ``claim_since_chain``)."""
        return len(self._b.block.instructions)

    # -- scopes -----------------------------------------------------------
    def in_chain(self, value) -> bool:
        """Whether ``value``, if claim_since_chain moved it into an If chain's else
        block, may be used here: in that block or in a body of the same chain."""
        merge = getattr(value, "reactor_chain", None)
        if merge is None or value.parent is self._b.block:
            return True
        scope: Scope | None = self.scope
        while scope is not None and scope.chain is not merge:
            scope = scope.parent
        return scope is not None

    def push_scope(self, what: str) -> Scope:
        self.scope = Scope(self.scope, what)
        return self.scope

    def pop_scope(self, scope: Scope) -> None:
        if self.scope is not scope:
            def at(sc):
                return f" (opened at line {sc.where[1]})" if sc.where else ""
            raise ControlFlowError(
                f"blocks closed out of order: the innermost open block is "
                f"'{self.scope.what}'{at(self.scope)}, not '{scope.what}'{at(scope)}"
            )
        scope.closed = True
        self.scope = scope.parent or self.root_scope

    # -- finishing ----------------------------------------------------------
    def at_finish(self, decide: typing.Callable[[set], None]) -> None:
        """Call ``decide(used)`` when the body is complete (``finish`` finds every path ended):
        ``used`` holds the ``id`` of every value an instruction reads (a choice that depends on
        what the rest of the body needs). Never called, the choice is not made."""
        self._at_finish.append(decide)

    def never_take(self, branch) -> None:
        """Make a conditional branch always go to its second target."""
        branch.operands[0] = ir.Constant(ir.IntType(1), 0)

    def finish(self) -> list[ir.Block]:
        """Close the body: blocks unreachable from the entry get ``unreachable``;
        return the reachable blocks that still lack a terminator (they fall off
        the end of the function)."""
        if self.scope is not self.root_scope:
            raise ControlFlowError(f"'{self.scope.what}' block entered but never closed: use it in a "
                                   f"'with' statement", location=self.scope.where)
        reachable, todo = set(), [self._entry]
        while todo:
            block = todo.pop()
            if block.name in reachable:
                continue
            reachable.add(block.name)
            if block.is_terminated:
                todo.extend(op for op in block.terminator.operands if isinstance(op, ir.Block))
        targets = {op.name for block in self.function.blocks if block.is_terminated
                   for op in block.terminator.operands if isinstance(op, ir.Block)}
        open_blocks = []
        for block in list(self.function.blocks):
            if block.is_terminated:
                continue
            if block.name in reachable:
                open_blocks.append(block)
            elif not block.instructions and block.name not in targets:
                self.function.blocks.remove(block)  # e.g. the empty block after a final Return
            else:
                self._b.position_at_end(block)
                self._b.unreachable()
        if self._at_finish and not open_blocks:  # complete: every path ends (a caller may add the returns)
            used = {id(op) for block in self.function.blocks for ins in block.instructions for op in ins.operands}
            for decide in self._at_finish:
                decide(used)
            self._at_finish.clear()
        return open_blocks


@contextlib.contextmanager
def _at_entry(em: "FunctionEmitter"):
    with em._b.goto_block(em._entry):
        em._b.position_before(em._entry.terminator)
        yield


def is_constant(value) -> bool:
    """Whether an IR value is a constant (LLVM folds what is computed from constants only)."""
    return isinstance(value, ir.Constant)


def _i32(index):
    return ir.Constant(ir.IntType(32), index) if isinstance(index, int) else index


def _install_binary() -> None:
    for op in _BINARY:
        def method(self, a, b, name: str = "", _op=op):
            return self._binary(_op, a, b, name)
        method.__name__ = op
        method.__doc__ = f"``{_BINARY[op][0].rstrip('_')}`` of two {_BINARY[op][1]} operands of one type."
        setattr(FunctionEmitter, op, method)


_install_binary()
