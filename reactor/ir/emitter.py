"""The only module that drives llvmlite's ``IRBuilder``.

A ``ModuleEmitter`` owns one ``ir.Module``; a ``FunctionEmitter`` owns one
function being built: its blocks, its entry-block stack slots (so mem2reg
turns variables into SSA values, as Reactor does), its scopes (which values
are still visible), and the instruction cursor. The DSL layers above never see
an ``IRBuilder``; they call the methods here.

The emitter of the function being built is thread-local: each thread builds
with its own emitter stack, so building is thread-safe.
"""
from __future__ import annotations

import itertools
import threading

from llvmlite import ir

from ..errors import ControlFlowError, ScopeError

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


class ModuleEmitter:
    """One LLVM module: a compilation unit holding several functions."""

    _ids = itertools.count()

    def __init__(self, name: str, options):
        self.options = options  # resolved BuildOptions
        self.module = ir.Module(name=name)
        from ..jit.target import get_target

        target = get_target(options.target)
        self.module.triple = target.triple
        self.module.data_layout = str(target.machine.target_data)
        self.functions: dict[object, ir.Function] = {}
        self.imports: dict[str, int] = {}  # external symbol -> address (see dsl/external.py)
        self.written: dict[object, frozenset] = {}  # (Function, width) -> pointer parameters it stores to

    def unique_name(self, base: str) -> str:
        names = {g.name for g in self.module.global_values}
        if base not in names:
            return base
        for i in itertools.count(1):
            if f"{base}.{i}" not in names:
                return f"{base}.{i}"

    def declare(self, name: str, ret: ir.Type, args: list[ir.Type]) -> ir.Function:
        """Declare an external or intrinsic function once per module."""
        try:
            return self.module.get_global(name)
        except KeyError:
            return ir.Function(self.module, ir.FunctionType(ret, args), name=name)


class FunctionEmitter:
    """Builds the body of one LLVM function."""

    def __init__(self, module: ModuleEmitter, name: str, ret: ir.Type, args: list[ir.Type],
                 arg_names: list[str], *, internal: bool = False, width: int | None = None):
        self.module = module
        self.options = module.options
        self.width = width or module.options.width
        self.fma = module.options.fma  # what MulAdd emits; see reactor.fma_mode
        fnty = ir.FunctionType(ret, args)
        self.function = ir.Function(module.module, fnty, name=name)
        for arg, argname in zip(self.function.args, arg_names):
            arg.name = argname
        if internal:
            self.function.linkage = "internal"
            self.function.attributes.add("alwaysinline")
        self.function.attributes.add("nounwind")
        self._entry = self.function.append_basic_block("entry")
        body = self.function.append_basic_block("body")
        self._b = ir.IRBuilder(self._entry)
        self._b.branch(body)
        self._b.position_at_end(body)
        self.scope = Scope(None, "function")
        self.root_scope = self.scope
        self.ret_type = ret
        self.pending_chain = None  # (else_block, merge_block, mark) after an If/Elif
        self.dsl_function = None  # the reactor Function being built (set by its builder)
        self.unentered: list = []  # blocks (If, For, ...) created but not yet entered with `with`

    # -- activation -----------------------------------------------------
    def __enter__(self):
        _stack().append(self)
        return self

    def __exit__(self, *exc):
        popped = _stack().pop()
        assert popped is self

    # -- raw emission ---------------------------------------------------
    def emit(self, method: str, *args, **kwargs):
        """Call ``IRBuilder.<method>`` at the cursor (e.g. ``emit("fadd", a, b)``)."""
        return getattr(self._b, method)(*args, **kwargs)

    def call(self, fn: ir.Function, args, name: str = ""):
        return self._b.call(fn, args, name=name)

    def intrinsic(self, name: str, ret: ir.Type, args: list[ir.Type]) -> ir.Function:
        return self.module.declare(name, ret, args)

    def freeze(self, value, name: str = ""):
        """``freeze``: turn a possibly-poison value into an arbitrary fixed one."""
        instr = ir.instructions.Instruction(self._b.block, value.type, "freeze", [value], name=name)
        self._b._insert(instr)
        return instr

    def alloca(self, ty: ir.Type, name: str):
        """A stack slot in the entry block (promoted to registers by mem2reg)."""
        with self._b.goto_block(self._entry):
            self._b.position_at_start(self._entry)
            return self._b.alloca(ty, name=name)

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

    def branch_to(self, target: ir.Block) -> None:
        """Branch to ``target`` unless the current block already ended (e.g. Return)."""
        if not self._b.block.is_terminated:
            self._b.branch(target)

    def cbranch(self, cond, then_block: ir.Block, else_block: ir.Block) -> None:
        self._b.cbranch(cond, then_block, else_block)

    def ret(self, value) -> None:
        if value is None:
            self._b.ret_void()
        else:
            self._b.ret(value)
        # Code written after a Return in the same block is unreachable; give it
        # a block of its own so emission can continue.
        self._b.position_at_end(self.new_block("after.return"))

    # -- If-chain bookkeeping (see control.py) ----------------------------
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

    # -- scopes -----------------------------------------------------------
    def in_chain(self, value) -> bool:
        """Whether ``value``, if claim_since_chain moved it into an If chain's else
        block, may be used here: in that block or in a body of the same chain."""
        merge = getattr(value, "reactor_chain", None)
        if merge is None or value.parent is self._b.block:
            return True
        scope = self.scope
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
        self.scope = scope.parent

    # -- finishing ----------------------------------------------------------
    def finish(self) -> list[ir.Block]:
        """Close the body: blocks unreachable from the entry get ``unreachable``;
        return the reachable blocks that still lack a terminator (they fall off
        the end of the function)."""
        if self.unentered:
            blk = self.unentered[0]
            name = type(blk).__name__
            raise ControlFlowError(f"{name}(...) was created but never entered, so it has no effect: "
                                   f"write 'with {name}(...):'", location=getattr(blk, "_created", None))
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
        return open_blocks

    def position_at(self, block: ir.Block) -> None:
        self._b.position_at_end(block)
