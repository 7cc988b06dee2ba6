"""A kernel's code: its body, traced once or twice, and the loop NumPy calls.

The user's body is traced at the build's width W into an internal function
``<name>.body(x0, x1, ...) -> result(s)``. A small body (fewer than
``kernel.ONE_BODY_MIN`` IR instructions) or one with uniform operands is traced
again at width 1 into ``<name>.body1`` (the same code on scalars: every lane of
the vector body computes what the scalar body computes, bit for bit).

``void <name>.loop(char **args, npy_intp *dims, npy_intp *steps, void *data)``
is NumPy's ufunc loop signature. For ``n = dims[0]`` elements it runs:

* the **vector loop**, W elements per iteration, with the vector body inlined,
  when every output is contiguous and every input is contiguous or a
  broadcast scalar (stride 0: its value is splatted into a W-element buffer
  once, so one loop serves every mix of the two, as in ``pow(x, 2.2)``), and
  no output starts inside an input ahead of it (``ufunc.accumulate`` passes
  ``out[i-1]`` as input ``i``);
* then whatever is left (the last ``n % W`` elements, or every element when an
  operand is strided or the operands overlap): with ``body1``, the **scalar
  loop**, one element at a time in order, at any strides; without it, **chunks**
  through the same inlined vector body, their elements copied into W-lane
  buffers and back by the runtime's ``reactor_move`` (W at a time, lanes past
  the last element repeating it, or one at a time where an output overlaps an
  input other than in place, so accumulations see each result before the next
  element reads it).

So a large body is compiled once, a small one twice, however many inputs and
layouts the kernel has.

Floating-point exception flags are saved on entry and restored on exit: the
routines' special-value paths compute on values whose flags mean nothing,
so kernels report no floating-point warnings through NumPy's ``errstate``.
"""
from __future__ import annotations

import dataclasses
import typing

from ..dsl.context import begin, check_entered
from ..dsl.control import final_results
from ..errors import DSLTypeError, at_return_of, return_location
from ..ir import emitter as _em
from ..ir import fpenv, hoist, ops
from ..ir import types as T
from ..ir.types import INDEX, KINDS, VType
from . import abi

BOOL = KINDS["Bool"]
#: Whether vector bodies split their uniform work off (``reactor.ir.hoist``); off only to measure it
#: (benchmarks/bench_uniform.py builds both ways).
UNIFORM_WORK = True
BOOL_MEM = VType(T.BYTE_KIND, 1)


def _idx(v: int):
    return T.const(INDEX, v)


class KernelBody:
    """Stands in for the function being built: a kernel body gives its results with Python
    ``return``, or per lane with ``Return(...)`` (see ``reactor.dsl.control``)."""

    returns = None
    is_kernel = True

    def __init__(self, name, outputs, operands=None):
        self.name, self.outputs = name, outputs  # outputs: one VType per component
        self.operands = operands  # the result Operands (vector results have several components)

    def split(self, values: list) -> list:
        """Results as component values: a vector result gives its components."""
        if self.operands is None or len(values) != len(self.operands):
            return values
        flat: list = []
        for o, v in zip(self.operands, values):
            flat.extend(list(v) if o.vector and hasattr(v, "size") else [v])
        return flat

    def join(self, flat: list) -> tuple:
        """Component values grouped back into the results (vectors for vector results)."""
        if self.operands is None:
            return tuple(flat)
        from ..dsl.vectors import vec_type
        out, at = [], 0
        for o in self.operands:
            comps = flat[at:at + o.channels]
            at += o.channels
            out.append(vec_type(o.kind, o.channels)._of(comps) if o.vector else comps[0])
        return tuple(out)


def emit_body(module, name: str, body, ins, outs, width: int):
    """The internal function ``<name>.body`` (or ``.body1`` at width 1): the user's body traced
    at ``width``; ``ins`` and ``outs`` are Operands (``reactor.kernels.operands``). With two
    inputs or more, a vector body's uniform work is split off (``reactor.ir.hoist``): then it
    takes the slots pointer last, and the ``Hoisted`` comes back with it (else None)."""
    from ..dsl.control import check_python_returns

    check_python_returns(body)
    out_types = [VType(o.kind, width) for o in outs for _ in range(o.channels)]
    ret = out_types[0] if len(out_types) == 1 else T.StructType(tuple(out_types))
    params: list = []
    groups: list[tuple[int, int]] = []
    param_inputs: list = []
    for k, o in enumerate(ins):
        types = o.body_params(width)
        groups.append((len(params), len(types)))
        params.extend(types)
        param_inputs.extend([None if o.uniform else k] * len(types))
    uniform_work = UNIFORM_WORK and width > 1 and len({i for i in param_inputs if i is not None}) > 1
    if uniform_work:
        params.append(T.BYTES)
    fname = f"{name}.body" if width > 1 or module.build.width == 1 else f"{name}.body1"
    em = _em.FunctionEmitter(module, fname, ret, params, [f"x{k}" for k in range(len(params))],
                             width=width, internal=True)
    state = begin(em, KernelBody(name, out_types, outs), body, is_kernel=True)  # Return belongs to body
    em.tail_body = width == 1 and module.build.width > 1
    with em:
        inputs = [o.wrap(em, em.params[at:at + count], width) for o, (at, count) in zip(ins, groups)]
        result = body(*inputs)
        if result is not None and not isinstance(result, tuple):
            result = (result,)
        with at_return_of(body):
            state.after_return = return_location(body)  # what follows belongs to the return statement
            result = final_results(em, state.function, result)
            irs: list | None = None
            if result is not None:
                if len(result) != len(outs):
                    raise DSLTypeError(f"kernel body returned {len(result)} value(s); its signature declares "
                                       f"{len(outs)} output(s){_vector_hint(outs, result)}")
                irs = [v for o, r in zip(outs, result) for v in o.flatten(r, width, f"kernel '{name}' result")]
            check_entered(em)
            open_blocks = em.finish()
            if open_blocks and irs is None:
                raise DSLTypeError("kernel body can reach its end without a result: end it with "
                                   "'return value' (or Return(...) on every path)")
        for block in open_blocks:
            assert irs is not None
            em.position_at(block)
            em.ret(irs[0] if isinstance(ret, VType) else em.pack(ret, irs))
        em.finish()
        hoisted = hoist.split(module, em, param_inputs) if uniform_work else None
    return em.function, hoisted


@dataclasses.dataclass
class _VectorRun:
    """What the pieces of a kernel's vector loop share (``LoopEmitter._vector_loop``)."""

    settings: typing.Any  # the runtime's settings (IR pointer)
    n_fast: typing.Any  # elements the vector loop reads in place
    slots: list  # per column: where its current pointer is kept
    step_of: list  # per column: its step in bytes
    uniforms: dict  # uniform input -> its body arguments
    gathered: bool  # the vector body also serves the other elements (no width-1 body)
    move: typing.Any = None  # reactor_move, and what it is called with
    columns: list = dataclasses.field(default_factory=list)
    count: typing.Any = None  # runs of the inner loop in this chunk
    moved: typing.Any = None  # elements a gathered chunk holds
    gathering: typing.Any = None  # whether this chunk was gathered
    j: typing.Any = None  # the inner loop's counter
    chunk: typing.Any = None  # blocks: the chunk loop's head, and after a chunk's runs
    done: typing.Any = None


class LoopEmitter:
    """Emits ``<name>.loop`` around the body functions of a kernel (``vector`` at the
    build's width, None when it is 1; ``scalar`` at width 1) for its Operands."""

    def __init__(self, module, name: str, vector, scalar, ins, outs, width: int, hoisted=None):
        from .operands import core_layout

        self.vector_fn, self.scalar_fn = vector, scalar
        self.hoisted: hoist.Hoisted | None = hoisted  # the vector body's uniform work (reactor.ir.hoist)
        self.uses_slots = vector is not None and len(vector.args) > sum(len(o.body_params(width)) for o in ins)
        self.ins, self.outs, self.width = list(ins), list(outs), width
        self.operands = self.ins + self.outs
        # the iterated operands (elements and vectors), inputs first: the loop's columns
        self.columns = [k for k, o in enumerate(self.operands) if not o.uniform]
        self.n_in_columns = sum(1 for o in self.ins if not o.uniform)
        self.core_dims, self.core_strides, self.ndims = core_layout(self.ins, self.outs)
        # Out of line: the dispatcher calls it, and inlining it there would double the machine code.
        self.em = _em.FunctionEmitter(module, name, None, abi.LOOP.params, abi.LOOP.names, width=width, inline="never")

    # -- index arithmetic, through the op table ---------------------------------
    def _add(self, a, b):
        return ops.binary(self.em, "add", INDEX, a, b)

    def _sub(self, a, b):
        return ops.binary(self.em, "sub", INDEX, a, b)

    def _mul(self, a, b):
        return ops.binary(self.em, "mul", INDEX, a, b)

    def _cmp(self, name, a, b, vt=INDEX):
        return ops.compare(self.em, vt, name, a, b)

    def _all(self, conds):
        bool1 = VType(BOOL, 1)
        out = T.const(bool1, 1)
        for c in conds:
            out = ops.binary(self.em, "and", bool1, out, c)
        return out

    def emit(self):
        em = self.em
        with em:
            args, dims, steps, data = em.params
            self.n = em.load(dims, name="n")
            self.ptrs, self.steps = [], []
            for k in range(len(self.operands)):
                self.ptrs.append(em.load(em.address(args, k), name=f"arg{k}"))
                self.steps.append(em.load(em.address(steps, k), name=f"step{k}"))
            # per operand: core sizes (dims) and core strides (steps), as NumPy's gufunc loop gives them
            self.sizes = [[em.load(em.address(dims, d), name=f"dim{k}.{j}") for j, d in enumerate(ds)]
                          for k, ds in enumerate(self.core_dims)]
            self.strides = [[em.load(em.address(steps, t), name=f"stride{k}.{j}") for j, t in enumerate(ts)]
                            for k, ts in enumerate(self.core_strides)]
            status = fpenv.save_status(em)
            if self.vector_fn is not None and self.uses_slots:
                self._uniform_work_once()
            self.i = em.alloca(INDEX, "i")
            em.store(_idx(0), self.i)
            scalar = em.new_block("scalar")
            if self.vector_fn is not None:
                self._vector_loop(data, scalar)
            else:
                em.branch(scalar)
            em.goto(scalar)
            if self.scalar_fn is not None:
                self._scalar_loop()
            fpenv.restore_status(em, status)
            em.ret(None)
            em.finish()
        return em.function

    def _uniform_work_once(self) -> None:
        """The slots of the body's uniform work, and each group computed here, once, when every
        input it depends on is broadcast in this call (stride 0; with at least one element)."""
        em, W = self.em, self.width
        hoisted = self.hoisted
        size = hoisted.slots if hoisted is not None else VType(T.BYTE_KIND, 1)
        self.slots = em.cast_pointer(em.alloca(size, "slots"), VType(T.BYTE_KIND, 1), name="slots.p")
        self.once = []
        if hoisted is None:
            return
        some = self._cmp("gt", self.n, _idx(0))
        self.any_once = T.const(VType(BOOL, 1), 0)
        for group in hoisted.groups:
            flag = self._all([some] + [self._cmp("eq", self.steps[k], _idx(0)) for k in sorted(group.inputs)])
            self.once.append(flag)
            self.any_once = ops.binary(em, "or", VType(BOOL, 1), self.any_once, flag)
            with em.if_then(flag, name="uniform"):
                args: list = []
                for k, o in enumerate(self.ins):
                    types = o.body_params(W)
                    if k in group.inputs:
                        for addr in self._element_addresses(k, _idx(0)):
                            one = ops.load(em, VType(o.kind, 1), addr, name=f"u{k}")
                            args.append(em.splat(one, W, name=f"u{k}.splat"))
                    else:
                        args.extend(T.undefined(t) for t in types)
                em.call(group.function, args + [self.slots], inline="always")

    def _uniform_work_per_iteration(self, xs: list) -> list:
        """The groups not computed once, computed for this iteration's ``xs``; the body's arguments."""
        if not self.uses_slots:
            return xs
        em = self.em
        if self.hoisted is not None:
            # a call with every group's inputs arrays (the usual) runs them in one straight line
            with em.if_else(self.any_once, name="uniform") as (some, none):
                with some:
                    true = T.const(VType(BOOL, 1), 1)
                    for group, once in zip(self.hoisted.groups, self.once):
                        with em.if_then(ops.binary(em, "xor", VType(BOOL, 1), once, true), name="varying"):
                            em.call(group.function, xs + [self.slots], inline="always")
                with none:
                    for group in self.hoisted.groups:
                        em.call(group.function, xs + [self.slots], inline="always")
        return xs + [self.slots]

    def _channel_stride(self, k):
        """The byte distance between the channels of a vector operand ``k``."""
        return self.strides[k][-1]

    def _uniform_args(self, k, i):
        """A uniform operand's body arguments: its base (the array of element ``i``), sizes and strides."""
        em, o = self.em, self.operands[k]
        base = em.address(self.ptrs[k], self._mul(i, self.steps[k]), name=f"u{k}")
        return [base] + list(self.sizes[k][:o.texture.ndim]) + list(self.strides[k])

    # -- the vector loop -------------------------------------------------------------
    def _vector_loop(self, data, exit_block):
        """W elements per iteration, from where ``reactor_prepare`` (the shared runtime) says:
        each column's start (an input's array, or a buffer holding its broadcast value W
        times) and step, and how many elements the layout lets this loop do (0: none). A
        vector column runs here when its channels are contiguous (then W elements are W *
        channels contiguous values, split into channels by shuffles); uniform operands must
        be the same array for every element (outer step 0). Where there is no width-1 body,
        the same vector body also serves every other element, through ``reactor_move``."""
        run = self._layout(data)
        if run.gathered:
            head, body = self._chunks(run, exit_block)
        else:
            em = self.em
            head, body = em.new_block("vec.cond"), em.new_block("vec.body")
            em.branch(head)
            em.goto(head)
            i = em.load(self.i, name="i")
            em.cbranch(self._cmp("lt", i, run.n_fast), body, exit_block)
        self._vector_body(run, body)
        if not run.gathered:
            em = self.em
            em.store(self._add(em.load(self.i, name="i"), _idx(self.width)), self.i)
            em.branch(head)
            return
        self._chunk_end(run, head)

    def _layout(self, data) -> "_VectorRun":
        """Ask ``reactor_prepare`` where each column starts and steps, and how many elements the
        vector loop reads in place (``n_fast``); the pointers' slots, the steps, the uniform
        operands' arguments."""
        em, W = self.em, self.width
        cols = self.columns
        ncol = len(cols)
        sizes = em.alloca(INDEX, "sizes", count=max(1, ncol))
        cargs = em.alloca(T.BYTES, "cargs", count=max(1, ncol))
        csteps = em.alloca(INDEX, "csteps", count=max(1, ncol))
        for c, k in enumerate(cols):
            em.store(_idx(self.operands[k].item_bytes), em.address(sizes, c))
            em.store(self.ptrs[k], em.address(cargs, c))
            em.store(self.steps[k], em.address(csteps, c))
        srcs = em.alloca(T.BYTES, "srcs", count=max(1, ncol))
        incs = em.alloca(INDEX, "incs", count=max(1, ncol))
        lane_bytes = max([8] + [self.operands[k].item_bytes for k in cols[:self.n_in_columns]])
        splats = em.alloca(VType(T.BYTE_KIND, 16), "splats",
                           count=max(1, self.n_in_columns * W * lane_bytes // 16))
        fits = []
        for k, o in enumerate(self.operands):
            if o.vector and not o.uniform:
                fits.append(self._cmp("eq", self._channel_stride(k), _idx(o.kind.mem_bytes)))
            if o.uniform:
                fits.append(self._cmp("eq", self.steps[k], _idx(0)))
        settings = abi.LOOP_CONFIG.load(em, abi.LOOP_CONFIG.of(em, data), "settings")
        prepare = abi.SETTINGS.load(em, settings, "prepare")
        dims1 = em.alloca(INDEX, "n.only")
        em.store(self.n, dims1)
        ask, skip, go = em.new_block("layout"), em.new_block("layout.no"), em.new_block("layout.done")
        em.cbranch(self._all(fits), ask, skip)
        em.goto(ask)
        asked = em.call_pointer(prepare, INDEX, abi.PREPARE.params,
                                [cargs, dims1, csteps, _idx(self.n_in_columns), _idx(ncol), sizes, _idx(W), srcs,
                                 incs, em.cast_pointer(splats, T.BYTE), _idx(lane_bytes)], name="n.fast")
        em.branch(go)
        em.goto(skip)
        em.branch(go)
        em.goto(go)
        n_fast = em.phi(INDEX, [(asked, ask), (_idx(0), skip)], name="n.fast")
        slots = [em.alloca(T.BYTES, f"p{c}") for c in range(ncol)]
        step_of = [em.load(em.address(incs, c), name=f"inc{c}") for c in range(ncol)]
        for c, slot in enumerate(slots):
            em.store(em.load(em.address(srcs, c), name=f"src{c}"), slot)
        uniforms = {k: self._uniform_args(k, _idx(0)) for k, o in enumerate(self.ins) if o.uniform}
        return _VectorRun(settings, n_fast, slots, step_of, uniforms, gathered=self.scalar_fn is None)

    def _chunks(self, run: "_VectorRun", exit_block):
        """The loop over chunks: the elements the vector loop reads in place (0 .. n.fast), then the
        others, W (or, for accumulations, 1) at a time through W-lane buffers (``reactor_move``),
        each a run of the one inner loop whose head and body this returns (the one copy of the body)."""
        em, W = self.em, self.width
        run.move = abi.SETTINGS.load(em, run.settings, "move")
        run.columns = self._move_columns(self.columns, W)
        run.count, run.moved, run.gathering = (em.alloca(INDEX, "run.count"), em.alloca(INDEX, "run.k"),
                                               em.alloca(BOOL_MEM, "run.gathered"))
        run.chunk, direct, gather, run.done = (em.new_block(b) for b in ("chunk", "chunk.direct", "chunk.gather",
                                                                         "chunk.done"))
        em.branch(run.chunk)
        em.goto(run.chunk)
        i = em.load(self.i, name="i")
        pick = em.new_block("chunk.pick")
        em.cbranch(self._cmp("lt", i, self.n), pick, exit_block)
        em.goto(pick)
        em.cbranch(self._cmp("lt", i, run.n_fast), direct, gather)
        em.goto(direct)
        em.store(ops.binary(em, "lshr", INDEX, run.n_fast, _idx(W.bit_length() - 1)), run.count)  # n.fast / W
        em.store(T.const(BOOL_MEM, 0), run.gathering)
        inner = em.new_block("run")
        em.branch(inner)
        em.goto(gather)
        k = em.call_pointer(run.move, INDEX, abi.MOVE.params, [_idx(0)] + run.columns + [i, self.n, _idx(0)] +
                            self._move_buffer, name="chunk.k")
        em.store(k, run.moved)
        em.store(_idx(1), run.count)
        em.store(T.const(BOOL_MEM, 1), run.gathering)
        for c, slot in enumerate(run.slots):
            em.store(em.address(self._move_buffer[1], _idx(c * self._slot_bytes)), slot)
        em.branch(inner)
        em.goto(inner)
        run.j = em.alloca(INDEX, "j")
        em.store(_idx(0), run.j)
        head, body = em.new_block("vec.cond"), em.new_block("vec.body")
        em.branch(head)
        em.goto(head)
        em.cbranch(self._cmp("lt", em.load(run.j, name="j"), em.load(run.count, name="runs")), body, run.done)
        return head, body

    def _vector_body(self, run: "_VectorRun", body) -> None:
        """One iteration: load W elements of each input, call the body, store the results, step."""
        em = self.em
        em.goto(body)
        ptrs = {k: em.load(run.slots[c], name=f"p{c}") for c, k in enumerate(self.columns)}
        xs: list = []
        for k, o in enumerate(self.ins):
            if o.uniform:
                xs.extend(run.uniforms[k])
            else:
                xs.extend(self._load_vector(o, ptrs[k], f"x{k}"))
        results = self._call(self.vector_fn, self._uniform_work_per_iteration(xs), inline="always")
        at = 0
        for jo, o in enumerate(self.outs):
            self._store_vector(o, results[at:at + o.channels], ptrs[len(self.ins) + jo])
            at += o.channels
        for c, k in enumerate(self.columns):
            em.store(em.address(ptrs[k], run.step_of[c], name=f"p{c}.next"), run.slots[c])

    def _chunk_end(self, run: "_VectorRun", head) -> None:
        """After a chunk's runs: a gathered chunk's results back to memory (``reactor_move``), then
        the next chunk."""
        em = self.em
        em.store(self._add(em.load(run.j, name="j"), _idx(1)), run.j)
        em.branch(head)
        em.goto(run.done)
        out, direct_done, after = em.new_block("chunk.out"), em.new_block("chunk.fast"), em.new_block("chunk.next")
        em.cbranch(em.icmp("!=", em.load(run.gathering, name="gathered"), T.const(BOOL_MEM, 0), signed=False,
                           name="gathered"), out, direct_done)
        em.goto(out)
        i = em.load(self.i, name="i")
        k = em.load(run.moved, name="k")
        em.call_pointer(run.move, INDEX, abi.MOVE.params, [_idx(1)] + run.columns + [i, self.n, k] +
                        self._move_buffer, name="moved")
        em.store(self._add(i, k), self.i)
        em.branch(after)
        em.goto(direct_done)
        em.store(run.n_fast, self.i)
        em.branch(after)
        em.goto(after)
        em.branch(run.chunk)

    def _move_columns(self, cols, W):
        """The column descriptors ``reactor_move`` reads (pointers, steps, channel strides, channels,
        bytes a channel, counts), and its buffer (set in ``self._move_buffer``)."""
        em = self.em
        n = max(1, len(cols))
        ptrs = em.alloca(T.BYTES, "mv.ptrs", count=n)
        arrays = [em.alloca(INDEX, f"mv.{what}", count=n) for what in ("steps", "cstrides", "channels", "kbytes")]
        for c, k in enumerate(cols):
            o = self.operands[k]
            cstride = self._channel_stride(k) if o.channels > 1 else _idx(o.kind.mem_bytes)
            em.store(self.ptrs[k], em.address(ptrs, c))
            for array, value in zip(arrays, (self.steps[k], cstride, _idx(o.channels), _idx(o.kind.mem_bytes))):
                em.store(value, em.address(array, c))
        slot_bytes = -(-W * max([8] + [self.operands[k].item_bytes for k in cols]) // 64) * 64
        buf = em.alloca(VType(T.BYTE_KIND, 16), "mv.buf", count=n * slot_bytes // 16)
        self._slot_bytes = slot_bytes
        self._move_buffer = [_idx(W), em.cast_pointer(buf, T.BYTE), _idx(slot_bytes)]
        return [ptrs] + arrays + [_idx(len(cols)), _idx(self.n_in_columns)]

    def _load_vector(self, o, ptr, name):
        """W elements of an iterated operand: one value, or its channels deinterleaved."""
        em, W = self.em, self.width
        if o.channels == 1:
            return [ops.load(em, VType(o.kind, W), ptr, name=name)]
        raw = ops.load(em, VType(o.kind, W * o.channels), ptr, name=name)
        return [em.shuffle(raw, raw, [lane * o.channels + c for lane in range(W)], name=f"{name}.{c}")
                for c in range(o.channels)]

    def _store_vector(self, o, values, ptr):
        em, W, g = self.em, self.width, o.channels
        if g == 1:
            ops.store(em, VType(o.kind, W), values[0], ptr)
            return
        mem = [ops.to_memory(em, VType(o.kind, W), v) for v in values]
        parts = mem + [T.undefined(T.memory(VType(o.kind, W)))] * (4 - g if g == 3 else 0)
        while len(parts) > 1:  # concatenate pairwise: W, 2W, 4W lanes
            n = parts[0].type.count
            parts = [em.shuffle(parts[a], parts[a + 1], list(range(2 * n)), name="cat")
                     for a in range(0, len(parts), 2)]
        whole = parts[0]
        interleaved = em.shuffle(whole, whole, [c * W + lane for lane in range(W) for c in range(g)], name="pixels")
        ptr = em.cast_pointer(ptr, T.memory(VType(o.kind, W * g)), name="out.p")
        em.store(interleaved, ptr, align=o.kind.mem_bytes)

    def _call(self, fn, xs, inline):
        em = self.em
        count = sum(o.channels for o in self.outs)
        result = em.call(fn, xs, name="r", inline=inline)
        return [result] if count == 1 else em.unpack(result, count)

    # -- the scalar loop --------------------------------------------------------------------
    def _scalar_loop(self):
        """Elements ``i .. n-1`` one at a time, at any strides, in order."""
        em = self.em
        head, body, done = em.new_block("strided.cond"), em.new_block("strided.body"), em.new_block("done")
        em.branch(head)
        em.goto(head)
        i = em.load(self.i, name="j")
        em.cbranch(self._cmp("lt", i, self.n), body, done)
        em.goto(body)
        i = em.load(self.i, name="j")
        xs: list = []
        for k, o in enumerate(self.ins):
            if o.uniform:
                xs.extend(self._uniform_args(k, i))
                continue
            for c, addr in enumerate(self._element_addresses(k, i)):
                vt = VType(o.kind, 1)
                raw = em.load(em.cast_pointer(addr, T.memory(vt)), align=1, name=f"in{k}.{c}")
                xs.append(ops.from_memory(em, vt, raw, name=f"x{k}.{c}"))
        results = self._call(self.scalar_fn, xs, inline="always")
        at = 0
        for j, o in enumerate(self.outs):
            vt = VType(o.kind, 1)
            for c, addr in enumerate(self._element_addresses(len(self.ins) + j, i)):
                em.store(ops.to_memory(em, vt, results[at + c]), em.cast_pointer(addr, T.memory(vt)), align=1)
            at += o.channels
        em.store(self._add(i, _idx(1)), self.i)
        em.branch(head)
        em.goto(done)

    def _element_addresses(self, k, i):
        """The addresses of element ``i``'s channels of iterated operand ``k``."""
        em, o = self.em, self.operands[k]
        start = em.address(self.ptrs[k], self._mul(i, self.steps[k]), name=f"e{k}")
        if o.channels == 1:
            return [start]
        return [start] + [em.address(start, self._mul(_idx(c), self._channel_stride(k)), name=f"e{k}.{c}")
                          for c in range(1, o.channels)]


def _vector_hint(outs, result) -> str:
    """What to write where a body returns a vector's components as several values."""
    if len(outs) == 1 and outs[0].vector and outs[0].channels == len(result):
        from ..dsl.vectors import vec_type
        name = vec_type(outs[0].kind, outs[0].channels).__name__
        return f": the result is one {name}, so write 'return {name}(...)' with its {len(result)} components"
    return ""


def estimated_cycles(instructions: int, width: int) -> float:
    """A rough cost of one element: the body's ``instructions`` (as built) over the width, at
    two vector instructions per cycle, plus the loop's own. It only decides whether a call
    is worth splitting across threads."""
    return instructions / width / 2 + 0.25
