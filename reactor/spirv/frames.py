"""One function's translation (:class:`Frame`): its structured control flow on the core's per-lane
blocks (selections, switches, loops with break and continue, returns), its values and variables."""
from __future__ import annotations

import dataclasses
import typing

from ..dsl import flow
from ..dsl.control import Return
from ..dsl.values import value_class
from ..ir.types import KINDS, VType
from ..errors import ReactorError
from .binary import Instruction, SpirvError
from .cells import Cell, _dsl, new_cell, to_vec
from .declarations import Block, Function, Type

if typing.TYPE_CHECKING:
    from .translate import Translator


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
        self.cells: dict[int, typing.Any] = {}  # Cell or DynamicCell  # id -> variable (OpVariable, access chains, spilled ids, phis)
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

    def pointer(self, id_: int) -> typing.Any:  # a Cell or DynamicCell
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
        seen: set = set()
        while label not in stop:
            if label in seen:
                raise SpirvError(f"unstructured control flow: block %{label} is reached again without a loop "
                                 f"(OpLoopMerge)")
            seen.add(label)
            block = self.fn.blocks[label]
            if block.loop is not None:
                label = self.loop(block, ctx)
                continue
            self.values = {}
            for ins in block.body:
                self.translate(ins)
            self._phi_stores(label)
            nxt = self.terminate(block, ctx)
            if nxt is None:
                return
            label = nxt

    def translate(self, ins: Instruction) -> None:
        """One instruction; a mistake it raises is reported at the shader's line where there is one."""
        try:
            self.tr.instruction(self, ins)
        except ReactorError as exc:
            where = self.tr.location
            if where is None or exc.location == where:
                raise
            problem = exc.problem if ins.op in exc.problem else f"{exc.problem} ({ins.op})"
            raise SpirvError(problem, location=where) from None

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
            self.tr.discard()
            if self.tr.entry is self.fn and ctx.depth == 0:
                self.result = self.tr.outputs_now()
            else:
                flow.return_value(self.tr.outputs_now())  # from the shader, wherever it is
            return None
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
            self.translate(ins)
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
                    self.translate(ins)
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
