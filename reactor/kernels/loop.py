"""A kernel's code: its body, traced once per width, and the loop NumPy calls.

The user's body is traced twice: at the build's width W into an internal
function ``<name>.body(x0, x1, ...) -> result(s)`` and at width 1 into
``<name>.body1`` (the same code on scalars: every lane of the vector body
computes what the scalar body computes, bit for bit).

``void <name>.loop(char **args, npy_intp *dims, npy_intp *steps, void *data)``
is NumPy's ufunc loop signature. For ``n = dims[0]`` elements it runs:

* the **vector loop**, W elements per iteration, with the vector body inlined,
  when every output is contiguous and every input is contiguous or a
  broadcast scalar (stride 0: its value is splatted into a W-element buffer
  once, so one loop serves every mix of the two, as in ``pow(x, 2.2)``), and
  no output starts inside an input ahead of it (``ufunc.accumulate`` passes
  ``out[i-1]`` as input ``i``);
* then the **scalar loop** for whatever is left: the last ``n % W`` elements
  of the vector loop, or every element when an operand is strided or the
  operands overlap, one element at a time in order (so accumulations see each
  result before the next element reads it), at any strides.

So the body is compiled twice (once per width) however many inputs and
layouts the kernel has; every element of the vector loop holds real data.

Floating-point exception flags are saved on entry and restored on exit: the
routines' special-value paths compute on values whose flags mean nothing,
so kernels report no floating-point warnings through NumPy's ``errstate``.
"""
from __future__ import annotations

from ..dsl.control import final_results
from ..dsl.values import to_ir, value_class
from ..errors import DSLTypeError, at_return_of
from ..ir import emitter as _em
from ..ir import ops, x86
from ..ir import types as T
from ..ir.types import INDEX, KINDS, VType
from ..dsl.limits import STATUS, messages_of
from .parallel import CYCLES_SCALE

BOOL = KINDS["Bool"]
LOOP_PARAMS = [T.BYTES_ARRAY, T.PointerType(INDEX), T.PointerType(INDEX), T.BYTES]
LOOP_NAMES = ["args", "dims", "steps", "data"]
#: The runtime's settings and a kernel's LoopConfig (reactor.kernels.parallel), as the IR sees them.
SETTINGS = T.StructType((INDEX, INDEX, INDEX, T.BYTES, T.BYTES, T.BYTES, T.BYTES, T.BYTES, T.BYTES))
_CONFIG = T.StructType((T.Address(SETTINGS), INDEX, INDEX, T.BYTES_ARRAY))
#: i64 reactor_prepare(args, dims, steps, nin, nargs, sizes, width, srcs, incs, splats)
PREPARE_PARAMS = [T.BYTES_ARRAY, T.PointerType(INDEX), T.PointerType(INDEX), INDEX, INDEX, T.PointerType(INDEX),
                  INDEX, T.BYTES_ARRAY, T.PointerType(INDEX), T.BYTES]


def _idx(v: int):
    return T.const(INDEX, v)


class KernelBody:
    """Stands in for the function being built: a kernel body gives its results with Python
    ``return``, or per lane with ``Return(...)`` (see ``reactor.dsl.control``)."""

    returns = None
    is_kernel = True

    def __init__(self, name, outputs):
        self.name, self.outputs = name, outputs


def emit_body(module, name: str, body, in_kinds, out_kinds, width: int):
    """The internal function ``<name>.body`` (or ``.body1`` at width 1): the user's body traced at ``width``."""
    from ..dsl.control import check_python_returns

    check_python_returns(body)
    outs = [VType(k, width) for k in out_kinds]
    ret = outs[0] if len(outs) == 1 else T.StructType(tuple(outs))
    params = [VType(k, width) for k in in_kinds]
    fname = f"{name}.body" if width > 1 or module.build.width == 1 else f"{name}.body1"
    em = _em.FunctionEmitter(module, fname, ret, params, [f"x{k}" for k in range(len(in_kinds))],
                             width=width, internal=True)
    em.dsl_function = KernelBody(name, outs)
    with em:
        inputs = [value_class(p)._wrap(a, em) for p, a in zip(params, em.params)]
        result = body(*inputs)
        if result is not None and not isinstance(result, tuple):
            result = (result,)
        with at_return_of(body):
            result = final_results(em, em.dsl_function, result)
            irs: list | None = None
            if result is not None:
                if len(result) != len(outs):
                    raise DSLTypeError(f"kernel body returned {len(result)} value(s); its signature declares "
                                       f"{len(outs)} output(s)")
                irs = [to_ir(r, vt) for r, vt in zip(result, outs)]
            open_blocks = em.finish()
            if open_blocks and irs is None:
                raise DSLTypeError("kernel body can reach its end without a result: end it with "
                                   "'return value' (or Return(...) on every path)")
        for block in open_blocks:
            assert irs is not None
            em.position_at(block)
            em.ret(irs[0] if isinstance(ret, VType) else em.pack(ret, irs))
        em.finish()
    return em.function


class LoopEmitter:
    """Emits ``<name>.loop`` around the body functions of a kernel (``vector`` at the
    build's width, None when it is 1; ``scalar`` at width 1)."""

    def __init__(self, module, name: str, vector, scalar, in_kinds, out_kinds, width: int):
        self.vector_fn, self.scalar_fn = vector, scalar
        self.ins, self.outs, self.width = in_kinds, out_kinds, width
        self.kinds = list(in_kinds) + list(out_kinds)
        # Out of line: the dispatcher calls it, and inlining it there would double the machine code.
        self.em = _em.FunctionEmitter(module, name, None, LOOP_PARAMS, LOOP_NAMES, width=width, inline="never")

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
            for k in range(len(self.kinds)):
                self.ptrs.append(em.load(em.address(args, k), name=f"arg{k}"))
                self.steps.append(em.load(em.address(steps, k), name=f"step{k}"))
            status = x86.save_fp_status(em)
            self.i = em.alloca(INDEX, "i")
            em.store(_idx(0), self.i)
            scalar = em.new_block("scalar")
            if self.vector_fn is not None:
                self._vector_loop(args, dims, steps, data, scalar)
            else:
                em.branch(scalar)
            em.goto(scalar)
            self._scalar_loop()
            x86.restore_fp_status(em, status)
            em.ret(None)
            em.finish()
        return em.function

    # -- the vector loop -------------------------------------------------------------
    def _vector_loop(self, args, dims, steps, data, exit_block):
        """W elements per iteration, from where ``reactor_prepare`` (the shared runtime) says:
        each operand's start (an input's array, or a buffer holding its broadcast value W
        times) and step, and how many elements the layout lets this loop do (0: none)."""
        em, W, nargs = self.em, self.width, len(self.kinds)
        sizes = em.alloca(INDEX, "sizes", count=nargs)
        for k, kind in enumerate(self.kinds):
            em.store(_idx(kind.mem_bytes), em.address(sizes, k))
        srcs = em.alloca(T.BYTES, "srcs", count=nargs)
        incs = em.alloca(INDEX, "incs", count=nargs)
        splats = em.alloca(VType(T.BYTE_KIND, 16), "splats", count=max(1, len(self.ins) * W // 2))  # 8 bytes a lane
        settings = em.load(em.field(em.cast_pointer(data, _CONFIG), 0), name="settings")
        prepare = em.load(em.field(settings, 4), name="prepare")
        n_fast = em.call_pointer(prepare, INDEX, PREPARE_PARAMS,
                                 [args, dims, steps, _idx(len(self.ins)), _idx(nargs), sizes, _idx(W), srcs, incs,
                                  em.cast_pointer(splats, T.BYTE)], name="n.fast")
        slots = [em.alloca(T.BYTES, f"p{k}") for k in range(nargs)]
        step_of = [em.load(em.address(incs, k), name=f"inc{k}") for k in range(nargs)]
        for k, slot in enumerate(slots):
            em.store(em.load(em.address(srcs, k), name=f"src{k}"), slot)
        head, body = em.new_block("vec.cond"), em.new_block("vec.body")
        em.branch(head)
        em.goto(head)
        i = em.load(self.i, name="i")
        em.cbranch(self._cmp("lt", i, n_fast), body, exit_block)
        em.goto(body)
        i = em.load(self.i, name="i")
        ptrs = [em.load(slot, name=f"p{k}") for k, slot in enumerate(slots)]
        xs = [ops.load(em, VType(kind, W), ptrs[k], name=f"x{k}") for k, kind in enumerate(self.ins)]
        results = self._call(self.vector_fn, xs, inline="always")
        for j, (kind, value) in enumerate(zip(self.outs, results)):
            ops.store(em, VType(kind, W), value, ptrs[len(self.ins) + j])
        for k, (slot, p) in enumerate(zip(slots, ptrs)):
            em.store(em.address(p, step_of[k], name=f"p{k}.next"), slot)
        em.store(self._add(i, _idx(W)), self.i)
        em.branch(head)

    def _call(self, fn, xs, inline):
        em = self.em
        result = em.call(fn, xs, name="r", inline=inline)
        return [result] if len(self.outs) == 1 else em.unpack(result, len(self.outs))

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
        addrs = [em.address(p, self._mul(i, self.steps[k]), name=f"e{k}") for k, p in enumerate(self.ptrs)]
        xs = [ops.from_memory(em, VType(kind, 1), em.load(em.cast_pointer(addrs[k], T.memory(VType(kind, 1))),
                                                          align=1, name=f"in{k}"), name=f"x{k}")
              for k, kind in enumerate(self.ins)]
        results = self._call(self.scalar_fn, xs, inline="always")
        for j, (kind, value) in enumerate(zip(self.outs, results)):
            vt = VType(kind, 1)
            em.store(ops.to_memory(em, vt, value), em.cast_pointer(addrs[len(self.ins) + j], T.memory(vt)), align=1)
        em.store(self._add(i, _idx(1)), self.i)
        em.branch(head)
        em.goto(done)


def estimated_cycles(body_fn, width: int) -> float:
    """A rough cost of one element: the body's instructions (as built) over the width, at
    two vector instructions per cycle, plus the loop's own. It only decides whether a call
    is worth splitting across threads."""
    return _em.ModuleEmitter.instruction_count(body_fn) / width / 2 + 0.25


def _raise_runaway(em, data) -> None:
    """If a loop of the body ran out of iterations, set Python's error (GIL taken): NumPy
    reports it when the call returns. Emitted in the dispatcher, on the caller's thread, after
    every chunk of a split call has finished (an error set on a worker thread would be lost)."""
    i32 = VType(KINDS["Int"], 1)
    old = em.atomic_swap(em.module.counter(STATUS), T.const(i32, 0), name="runaway")
    report, done = em.new_block("runaway"), em.new_block("return")
    em.cbranch(ops.compare(em, i32, "ne", old, T.const(i32, 0)), report, done)
    em.goto(report)
    cfg = em.cast_pointer(data, _CONFIG, name="config")
    settings = em.load(em.field(cfg, 0), name="settings")
    message = em.load(em.address(em.load(em.field(cfg, 3), name="messages"),
                                 ops.convert(em, i32, INDEX, ops.binary(em, "sub", i32, old, T.const(i32, 1)))),
                      name="message")
    ensure, set_error, release, exc = (em.load(em.field(settings, k), name=n) for k, n in
                                       ((5, "gil.ensure"), (6, "err.set"), (7, "gil.release"), (8, "exc")))
    state = em.call_pointer(ensure, i32, [], [], name="gil")
    em.call_pointer(set_error, None, [T.BYTES, T.BYTES], [exc, message])
    em.call_pointer(release, None, [i32], [state])
    em.branch(done)
    em.goto(done)


def emit_dispatcher(module, name: str, serial) -> object:
    """``<name>.ufunc``: the loop NumPy calls. ``data`` points to the kernel's
    ``parallel.LoopConfig``; a call worth splitting (see ``parallel``) goes to the
    native ``reactor_parallel_for``, every other one straight to ``serial``."""
    em = _em.FunctionEmitter(module, name, None, LOOP_PARAMS, LOOP_NAMES)
    with em:
        args, dims, steps, data = em.params
        cfg = em.cast_pointer(data, _CONFIG, name="config")
        settings = em.load(em.field(cfg, 0), name="settings")
        nargs, cycles = (em.load(em.field(cfg, k), name=n) for k, n in ((1, "nargs"), (2, "cycles")))
        threads, threshold, min_work = (em.load(em.field(settings, k), name=n)
                                        for k, n in enumerate(("threads", "threshold", "min_work")))
        n = em.load(dims, name="n")
        work = ops.binary(em, "mul", INDEX, n, cycles)
        budget = ops.binary(em, "mul", INDEX, min_work, _idx(CYCLES_SCALE))
        split = []
        for cond in (("gt", threads, _idx(1)), ("ge", n, threshold), ("ge", work, budget)):
            split.append(ops.compare(em, INDEX, *cond))
        bool1 = VType(BOOL, 1)
        worth = ops.binary(em, "and", bool1, ops.binary(em, "and", bool1, split[0], split[1]), split[2])
        parallel, serial_block = em.new_block("parallel"), em.new_block("serial")
        em.cbranch(worth, parallel, serial_block)
        em.goto(parallel)
        parallel_for = em.load(em.field(settings, 3), name="parallel_for")
        em.call_pointer(parallel_for, None, [T.BYTES] + LOOP_PARAMS + [INDEX, INDEX],
                        [em.function_address(serial, name="serial"), args, dims, steps, data, nargs, threads])
        done = em.new_block("done")
        em.branch(done)
        em.goto(serial_block)
        em.call(serial, [args, dims, steps, data])
        em.branch(done)
        em.goto(done)
        if messages_of(module):
            _raise_runaway(em, data)
        em.ret(None)
        em.finish()
    return em.function
