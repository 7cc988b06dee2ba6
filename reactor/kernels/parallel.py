"""Multi-core kernels: large calls split across threads in native code, no Python inside.

Every kernel's ufunc loop is a small dispatcher (``<name>.ufunc``). NumPy passes
it the ``data`` pointer registered with the loop, which points to the kernel's
``LoopConfig``: its operand count, the estimated cost of one element
(``cycles_per_element``, from the size of its vector body) and the
process-wide ``Settings``. A call is split when there is more than one thread,
at least ``threshold`` elements and an estimated ``n * cycles_per_element`` of
at least ``min_work`` cycles: splitting is decided by work, so a shader of a
million pixels is split and a copy of a million floats is not.

A split call goes to ``reactor_parallel_for``, JIT-compiled once per process
from IR (``runtime()``): it starts ``threads - 1`` POSIX threads for this call
(``pthread_create``), which with the calling thread take chunks of the index
space from an atomic counter (aligned to 64 elements, about four per thread,
so a busy core takes fewer), and returns only after ``pthread_join`` of every
thread: the output is complete when the ufunc returns. No Python runs during
the call, so a signal (Ctrl-C, an alarm whose handler raises) is taken when
the call returns, as for NumPy's own long calls; no thread outlives a call, so
a process forked afterwards (``multiprocessing`` with ``fork``) has nothing to
reset. A thread that cannot be created leaves its share to the others.

``configure(threads=..., threshold=..., min_work=...)`` changes the settings for
every kernel; ``REACTOR_THREADS`` sets the default thread count (default: the
CPUs this process may run on).
"""
from __future__ import annotations

import ctypes
import functools
import os
import threading
from typing import NamedTuple

from ..build import BuildOptions
from ..errors import LoopLimitError
from ..ir import emitter as _em
from ..ir import ops
from ..ir import types as T
from ..ir.types import INDEX, KINDS, VType
from ..jit.compiler import CompiledCode

#: Chunks are multiples of this many elements, so vector loops stay whole.
ALIGN = 64
#: Chunks per thread: a core slowed by other work takes fewer of them.
CHUNKS_PER_THREAD = 4
#: At most this many threads per call.
MAX_THREADS = 256
#: Entries of NumPy's ``dims`` a loop may read: the loop size and a gufunc's core dimensions.
MAX_DIMS = 64
DEFAULT_THRESHOLD = 4096
#: Estimated cycles a call must cost before it is split: starting and joining a
#: thread costs ~15-40 us, so the split pays from a few hundred microseconds
#: (benchmarks/bench_parallel.py measures it).
DEFAULT_MIN_WORK = 600_000
CYCLES_SCALE = 256  # LoopConfig.cycles_per_element is fixed point, 1/256 cycle


class SettingsStruct(ctypes.Structure):
    """What every dispatcher reads at each call (one per process)."""

    _fields_ = [("threads", ctypes.c_int64), ("threshold", ctypes.c_int64), ("min_work", ctypes.c_int64),
                ("parallel_for", ctypes.c_void_p), ("prepare", ctypes.c_void_p),
                # how a kernel's loop raises a Python error (a loop out of iterations)
                ("gil_ensure", ctypes.c_void_p), ("err_set", ctypes.c_void_p), ("gil_release", ctypes.c_void_p),
                ("runtime_error", ctypes.c_void_p),
                ("move", ctypes.c_void_p)]  # reactor_move: a kernel's elements in and out of its vector body


class LoopConfig(ctypes.Structure):
    """What a kernel's dispatcher reads through NumPy's per-loop ``data`` pointer."""

    _fields_ = [("settings", ctypes.POINTER(SettingsStruct)), ("nargs", ctypes.c_int64),
                ("cycles_per_element", ctypes.c_int64), ("messages", ctypes.POINTER(ctypes.c_char_p)),
                ("ndims", ctypes.c_int64)]  # entries of NumPy's dims: 1 + a gufunc's core dimensions


class ErrorLoop(ctypes.Structure):
    """The ``data`` of a loop that only raises (``reactor_raise``): NumPy picked it for operands a
    kernel refuses (a texture of another dtype, which NumPy would convert silently)."""

    _fields_ = [("settings", ctypes.POINTER(SettingsStruct)), ("message", ctypes.c_char_p),
                ("exception", ctypes.c_void_p)]


def error_loop(message: str, exception: type) -> tuple[int, ErrorLoop]:
    """(address of ``reactor_raise``, its data) for a loop that raises ``exception(message)``;
    keep the data alive as long as the ufunc."""
    _runtime_addresses()
    data = ErrorLoop(ctypes.pointer(_settings), message.encode(), id(exception))
    data._keep = exception
    return runtime().address("reactor_raise"), data


class Settings(NamedTuple):
    """The thread settings: ``threads``, and when a call is split (``threshold`` elements
    and ``min_work`` estimated cycles, both needed)."""

    threads: int
    threshold: int
    min_work: int


def _default_threads() -> int:
    env = os.environ.get("REACTOR_THREADS")
    if env:
        return max(1, int(env))
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def _c_function(name: str) -> int:
    address = ctypes.cast(getattr(ctypes.pythonapi, name), ctypes.c_void_p).value
    if not address:
        raise RuntimeError(f"the Python C API function {name} has no address")
    return address


_settings = SettingsStruct(min(_default_threads(), MAX_THREADS), DEFAULT_THRESHOLD, DEFAULT_MIN_WORK, None, None,
                           _c_function("PyGILState_Ensure"), _c_function("PyErr_SetString"),
                           _c_function("PyGILState_Release"), id(LoopLimitError))
_lock = threading.Lock()


def configure(threads: int | None = None, threshold: int | None = None, min_work: int | None = None) -> Settings:
    """Set the thread count, the minimum elements and the minimum estimated cycles of a split call."""
    with _lock:
        for name, value, low in (("threads", threads, 1), ("threshold", threshold, 1), ("min_work", min_work, 0)):
            if value is not None:
                if not isinstance(value, int) or isinstance(value, bool) or value < low:
                    raise ValueError(f"{name} must be an int >= {low}, not {value!r}")
                setattr(_settings, name, min(value, MAX_THREADS) if name == "threads" else value)
        return settings()


def settings() -> Settings:
    """The current thread settings."""
    return Settings(_settings.threads, _settings.threshold, _settings.min_work)


def make_config(nargs: int, cycles_per_element: float, messages=(), ndims: int = 1) -> LoopConfig:
    """The ``data`` block for one kernel loop (keep it alive as long as the ufunc): ``messages``
    are the errors of its loops that run out of iterations; ``ndims`` the entries of NumPy's
    ``dims`` its loop reads (1 + a gufunc's distinct core dimensions)."""
    if ndims > MAX_DIMS:
        raise ValueError(f"a kernel may have at most {MAX_DIMS - 1} core dimensions, not {ndims - 1}")
    _runtime_addresses()
    cycles = max(1, int(round(cycles_per_element * CYCLES_SCALE)))
    table = (ctypes.c_char_p * max(1, len(messages)))(*[m.encode() for m in messages])
    config = LoopConfig(ctypes.pointer(_settings), nargs, cycles, table, ndims)
    config._keep = table  # the strings live as long as the config
    return config


def _runtime_addresses() -> None:
    if _settings.parallel_for is None:
        _settings.parallel_for = runtime().address("reactor_parallel_for")
        _settings.prepare = runtime().address("reactor_prepare")
        _settings.move = runtime().address("reactor_move")


# -- the native runtime ------------------------------------------------------------------------

RUNTIME_EXPORTS = ("reactor_parallel_for", "reactor_prepare", "reactor_raise", "reactor_move")


@functools.cache
def runtime(target: str = "host") -> CompiledCode:
    """The compiled runtime (built once per process and target, cached on disk):
    ``reactor_parallel_for`` and ``reactor_prepare`` (every kernel's layout decisions, kept out
    of each kernel's code). The host's is loaded into this process; another target's is object
    code to link elsewhere (``reactor.kernels.emulated``)."""
    build = BuildOptions(target=target, width=1).resolved()
    module = _em.ModuleEmitter("reactor.parallel", build)
    _emit_runtime(module)
    _emit_prepare(module)
    _emit_raise(module)
    _emit_move(module)
    return CompiledCode(module.text, build.target, build.opt, RUNTIME_EXPORTS, build.cache)


def _emit_raise(module) -> None:
    """``void reactor_raise(args, dims, steps, data)``: a ufunc loop that sets Python's error from
    its ``ErrorLoop`` (GIL taken) and touches no operand."""
    from .loop import LOOP_NAMES, LOOP_PARAMS, SETTINGS

    i32 = VType(KINDS["Int"], 1)
    error_t = T.StructType((T.Address(SETTINGS), T.BYTES, T.BYTES))
    em = _em.FunctionEmitter(module, "reactor_raise", None, LOOP_PARAMS, LOOP_NAMES, width=1)
    with em:
        data = em.cast_pointer(em.params[3], error_t, name="error")
        settings = em.load(em.field(data, 0), name="settings")
        message, exc = em.load(em.field(data, 1), name="message"), em.load(em.field(data, 2), name="exc")
        ensure, set_error, release = (em.load(em.field(settings, k), name=n) for k, n in
                                      ((5, "gil.ensure"), (6, "err.set"), (7, "gil.release")))
        state = em.call_pointer(ensure, i32, [], [], name="gil")
        em.call_pointer(set_error, None, [T.BYTES, T.BYTES], [exc, message])
        em.call_pointer(release, None, [i32], [state])
        em.ret(None)
        em.finish()


def _emit_runtime(module) -> None:
    from .loop import LOOP_PARAMS  # loop.py imports this module

    bool1, i32 = VType(KINDS["Bool"], 1), VType(KINDS["Int"], 1)
    idx = lambda v: T.const(INDEX, v)  # noqa: E731
    # struct Task { loop, args, steps, data, nargs, n, chunk, next, dims, ndims }
    task_t = T.StructType((T.BYTES, T.BYTES_ARRAY, T.PointerType(INDEX), T.BYTES, INDEX, INDEX, INDEX, INDEX,
                           T.PointerType(INDEX), INDEX))
    create = module.declare("pthread_create", i32, [T.PointerType(INDEX), T.BYTES, T.BYTES, T.BYTES])
    join = module.declare("pthread_join", i32, [INDEX, T.BYTES])

    def add(em, a, b):
        return ops.binary(em, "add", INDEX, a, b)

    # void *reactor_parallel_worker(void *task): take chunks until none is left.
    worker = _em.FunctionEmitter(module, "reactor_parallel_worker", T.BYTES, [T.BYTES], ["task"], width=1)
    with worker as em:
        task = em.cast_pointer(em.params[0], task_t, name="t")
        f = [em.load(em.field(task, k), name=name) for k, name in
             enumerate(("loop", "args", "steps", "data", "nargs", "n", "chunk"))]
        loop, args, steps, data, nargs, n, chunk = f
        dims, ndims = em.load(em.field(task, 8), name="dims"), em.load(em.field(task, 9), name="ndims")
        sub_args = em.alloca(T.BYTES, "sub_args", count=64)  # NumPy ufuncs have at most 64 operands
        sub_n = em.alloca(INDEX, "sub_n", count=MAX_DIMS)  # the chunk's size, then the core dimensions
        d_slot = em.alloca(INDEX, "d")
        em.store(idx(1), d_slot)
        d_head, d_each, d_done = em.new_block("dims"), em.new_block("dims.each"), em.new_block("dims.done")
        em.branch(d_head)
        em.goto(d_head)
        d = em.load(d_slot, name="d")
        em.cbranch(ops.compare(em, INDEX, "lt", d, ndims), d_each, d_done)
        em.goto(d_each)
        em.store(em.load(em.address(dims, d), name="dim"), em.address(sub_n, d))
        em.store(add(em, d, idx(1)), d_slot)
        em.branch(d_head)
        em.goto(d_done)
        head, body, copy, call, done = (em.new_block(b) for b in ("take", "chunk", "args", "run", "done"))
        em.branch(head)
        em.goto(head)
        lo = em.atomic_add(em.field(task, 7), chunk, name="lo")
        em.cbranch(ops.compare(em, INDEX, "lt", lo, n), body, done)
        em.goto(body)
        hi = add(em, lo, chunk)
        hi = em.select(ops.compare(em, INDEX, "lt", hi, n), hi, n, name="hi")
        em.store(ops.binary(em, "sub", INDEX, hi, lo), sub_n)
        k_slot = em.alloca(INDEX, "k")
        em.store(idx(0), k_slot)
        em.branch(copy)
        em.goto(copy)
        k = em.load(k_slot, name="k")
        more, each = em.new_block("args.more"), em.new_block("args.each")
        em.cbranch(ops.compare(em, INDEX, "lt", k, nargs), each, call)
        em.goto(each)
        base = em.load(em.address(args, k), name="base")
        step = em.load(em.address(steps, k), name="step")
        em.store(em.address(base, ops.binary(em, "mul", INDEX, lo, step)), em.address(sub_args, k))
        em.store(add(em, k, idx(1)), k_slot)
        em.branch(more)
        em.goto(more)
        em.branch(copy)
        em.goto(call)
        em.call_pointer(loop, None, LOOP_PARAMS, [sub_args, sub_n, steps, data])
        em.branch(head)
        em.goto(done)
        em.ret(T.null(T.BYTES))
        em.finish()

    # void reactor_parallel_for(loop, args, dims, steps, data, nargs, threads, ndims)
    params = [T.BYTES] + LOOP_PARAMS + [INDEX, INDEX, INDEX]
    names = ["loop", "args", "dims", "steps", "data", "nargs", "threads", "ndims"]
    pf = _em.FunctionEmitter(module, "reactor_parallel_for", None, params, names, width=1)
    with pf as em:
        loop, args, dims, steps, data, nargs, threads, ndims = em.params
        n = em.load(dims, name="n")
        per = ops.binary(em, "mul", INDEX, threads, idx(CHUNKS_PER_THREAD))
        chunk = ops.binary(em, "div", INDEX, add(em, n, ops.binary(em, "sub", INDEX, per, idx(1))), per)
        chunk = ops.binary(em, "and", INDEX, add(em, chunk, idx(ALIGN - 1)), idx(-ALIGN))
        task = em.alloca(task_t, "task")
        for k, v in enumerate((loop, args, steps, data, nargs, n, chunk, idx(0), dims, ndims)):
            em.store(v, em.field(task, k))
        tids = em.alloca(INDEX, "tids", count=MAX_THREADS)
        made = em.alloca(T.BYTE, "made", count=MAX_THREADS)
        task_p = em.cast_pointer(task, T.BYTE, name="task.p")
        worker_p = em.function_address(worker.function, name="worker")
        t_slot = em.alloca(INDEX, "t")
        # start threads 1 .. threads-1
        em.store(idx(1), t_slot)
        start_head, start_body, start_done = em.new_block("start"), em.new_block("start.one"), em.new_block("run")
        em.branch(start_head)
        em.goto(start_head)
        t = em.load(t_slot, name="t")
        em.cbranch(ops.compare(em, INDEX, "lt", t, threads), start_body, start_done)
        em.goto(start_body)
        rc = em.call(create, [em.address(tids, t), T.null(T.BYTES), worker_p, task_p], name="rc")
        ok = ops.compare(em, i32, "eq", rc, T.const(i32, 0))
        em.store(ops.to_memory(em, bool1, ok), em.address(made, t))
        em.store(add(em, t, idx(1)), t_slot)
        em.branch(start_head)
        em.goto(start_done)
        em.call(worker.function, [task_p])  # the calling thread works too
        # join every thread that was started
        em.store(idx(1), t_slot)
        join_head, join_body, join_one, join_next, end = (em.new_block(b) for b in
                                                          ("join", "join.test", "join.one", "join.next", "end"))
        em.branch(join_head)
        em.goto(join_head)
        t = em.load(t_slot, name="t")
        em.cbranch(ops.compare(em, INDEX, "lt", t, threads), join_body, end)
        em.goto(join_body)
        was_made = ops.from_memory(em, bool1, em.load(em.address(made, t), name="made"))
        em.cbranch(was_made, join_one, join_next)
        em.goto(join_one)
        em.call(join, [em.load(em.address(tids, t), name="tid"), T.null(T.BYTES)])
        em.branch(join_next)
        em.goto(join_next)
        em.store(add(em, t, idx(1)), t_slot)
        em.branch(join_head)
        em.goto(end)
        em.ret(None)
        em.finish()


def counted_loop(em, start, stop, body, name: str) -> None:
    """Emit ``for j in range(start, stop): body(j)`` (i64 values) in the runtime's functions."""
    slot = em.alloca(INDEX, f"{name}.j")
    em.store(start, slot)
    head, each, done = em.new_block(f"{name}.cond"), em.new_block(f"{name}.each"), em.new_block(f"{name}.done")
    em.branch(head)
    em.goto(head)
    em.cbranch(ops.compare(em, INDEX, "lt", em.load(slot, name="j"), stop), each, done)
    em.goto(each)
    body(em.load(slot, name="j"))
    em.store(ops.binary(em, "add", INDEX, em.load(slot, name="j"), T.const(INDEX, 1)), slot)
    em.branch(head)
    em.goto(done)


def _emit_prepare(module) -> None:
    """``i64 reactor_prepare(args, dims, steps, nin, nargs, sizes, width, srcs, incs, splats, lane_bytes)``: whether
    a kernel's vector loop may run on this call's layout and from where. It may when every output is
    contiguous, every input contiguous or broadcast (stride 0), and no output starts inside an
    input's extent ahead of the input (``ufunc.accumulate`` passes ``out[i-1]`` as input ``i``; for
    ordinary calls NumPy copies overlapping operands). Then it sets each operand's start
    (``srcs``: the array, or for a broadcast input its value repeated ``width`` times in
    ``splats``, ``lane_bytes`` a lane) and step in bytes (``incs``), and returns ``n`` rounded down to a
    multiple of ``width``; otherwise 0."""
    from .loop import PREPARE_PARAMS

    bool1 = VType(KINDS["Bool"], 1)
    idx = lambda v: T.const(INDEX, v)  # noqa: E731
    names = ["args", "dims", "steps", "nin", "nargs", "sizes", "width", "srcs", "incs", "splats", "lane_bytes"]
    em = _em.FunctionEmitter(module, "reactor_prepare", INDEX, PREPARE_PARAMS, names, width=1)

    def loop(count, body, name):
        """``for k in range(count): body(k)`` (``count`` an i64 value)."""
        counted_loop(em, idx(0), count, body, name)

    with em:
        args, dims, steps, nin, nargs, sizes, width, srcs, incs, splats, lane_bytes = em.params
        n = em.load(dims, name="n")
        short, long_ = em.new_block("short"), em.new_block("long")
        em.cbranch(ops.compare(em, INDEX, "lt", n, width), short, long_)  # no whole vector: read nothing
        em.goto(short)
        em.ret(idx(0))
        em.goto(long_)
        ok = em.alloca(bool1, "ok")
        em.store(T.const(bool1, 1), ok)

        def need(cond):
            em.store(ops.binary(em, "and", bool1, em.load(ok, name="ok"), cond), ok)

        def layout(k):
            step, size = em.load(em.address(steps, k), name="step"), em.load(em.address(sizes, k), name="size")
            contiguous = ops.compare(em, INDEX, "eq", step, size)
            is_input = ops.compare(em, INDEX, "lt", k, nin)
            broadcast = ops.binary(em, "and", bool1, is_input, ops.compare(em, INDEX, "eq", step, idx(0)))
            need(ops.binary(em, "or", bool1, contiguous, broadcast))
        loop(nargs, layout, "layout")

        def apart(a):
            start_a = em.convert("ptrtoint", em.load(em.address(args, a), name="in"), INDEX, name="a")
            size_a = em.load(em.address(sizes, a), name="size")
            last = ops.binary(em, "sub", INDEX, ops.binary(em, "mul", INDEX, n, size_a), idx(1))

            def against(j):
                b = ops.binary(em, "add", INDEX, j, nin)
                start_b = em.convert("ptrtoint", em.load(em.address(args, b), name="out"), INDEX, name="b")
                ahead = ops.binary(em, "sub", INDEX, ops.binary(em, "sub", INDEX, start_b, start_a), idx(1))
                need(ops.compare(em, T.UINDEX, "ge", ahead, last))
            loop(ops.binary(em, "sub", INDEX, nargs, nin), against, "outputs")
        loop(nin, apart, "inputs")

        fits, none = em.new_block("fits"), em.new_block("none")
        em.cbranch(em.load(ok, name="ok"), fits, none)
        em.goto(none)
        em.ret(idx(0))
        em.goto(fits)

        def where(k):
            step, size = em.load(em.address(steps, k), name="step"), em.load(em.address(sizes, k), name="size")
            arg = em.load(em.address(args, k), name="arg")
            buffer = em.address(splats, ops.binary(em, "mul", INDEX, k, ops.binary(em, "mul", INDEX, width,
                                                                                      lane_bytes)), name="buf")
            broadcast, contiguous_b, done = em.new_block("bcast"), em.new_block("contig"), em.new_block("set")
            em.cbranch(ops.binary(em, "and", bool1, ops.compare(em, INDEX, "lt", k, nin),
                                  ops.compare(em, INDEX, "eq", step, idx(0))), broadcast, contiguous_b)
            em.goto(broadcast)

            def byte(j):  # buffer[j] = arg[j % size]
                src = em.address(arg, ops.binary(em, "rem", INDEX, j, size))
                em.store(em.load(src, name="byte"), em.address(buffer, j))
            loop(ops.binary(em, "mul", INDEX, width, size), byte, "splat")
            em.store(buffer, em.address(srcs, k))
            em.store(idx(0), em.address(incs, k))
            em.branch(done)
            em.goto(contiguous_b)
            em.store(arg, em.address(srcs, k))
            em.store(ops.binary(em, "mul", INDEX, width, size), em.address(incs, k))
            em.branch(done)
            em.goto(done)
        loop(nargs, where, "where")
        em.ret(ops.binary(em, "and", INDEX, n, ops.unary(em, "neg", INDEX, width)))
        em.finish()


#: i64 reactor_move(scatter, ptrs, steps, cstrides, channels, kbytes, ncols, nin, i, n, k, width, buf, slot_bytes)
MOVE_PARAMS = [INDEX, T.BYTES_ARRAY] + [T.PointerType(INDEX)] * 4 + [INDEX] * 6 + [T.BYTES, INDEX]


def _emit_move(module) -> None:
    """``i64 reactor_move(scatter, ptrs, steps, cstrides, channels, kbytes, ncols, nin, i, n, k, width, buf,
    slot_bytes)``: how a kernel's one vector body serves the elements its vector loop cannot read in
    place (the tail of fewer than ``width`` elements, strided operands, accumulations).

    ``scatter`` 0 (gather): copies elements ``i ..`` of each input column ``c < nin`` into
    ``buf + c * slot_bytes``, lane after lane, channels interleaved as in memory, a column's element
    ``e`` at ``ptrs[c] + e * steps[c] + channel * cstrides[c]`` (``kbytes[c]`` bytes a channel); lanes
    past the last element repeat it (so Any/All over the vector see only real elements). It returns how
    many elements the vector holds: ``min(width, n - i)``, or 1 where an output's remaining elements
    overlap an input's other than in place (``ufunc.accumulate`` reads ``out[i-1]`` as input ``i``, and
    ``reduce`` reads and writes one element, step 0: such elements must be computed one after the other). ``scatter`` 1 copies the first ``k`` lanes of each
    output column ``c >= nin`` back to memory and returns ``k``."""
    idx = lambda v: T.const(INDEX, v)  # noqa: E731
    bool1 = VType(KINDS["Bool"], 1)
    names = ["scatter", "ptrs", "steps", "cstrides", "channels", "kbytes", "ncols", "nin", "i", "n", "k", "width",
             "buf", "slot_bytes"]
    em = _em.FunctionEmitter(module, "reactor_move", INDEX, MOVE_PARAMS, names, width=1)

    def add(a, b):
        return ops.binary(em, "add", INDEX, a, b)

    def mul(a, b):
        return ops.binary(em, "mul", INDEX, a, b)

    def loop(start, count, body, name):
        """``for j in range(start, count): body(j)``."""
        counted_loop(em, start, count, body, name)

    def column(c, name):
        return [em.load(em.address(p, c), name=f"{name}.{what}") for p, what in
                ((ptrs, "ptr"), (steps, "step"), (cstrides, "cstride"), (channels, "channels"), (kbytes, "kbytes"))]

    def copy(dst, src, size):
        """``size`` (1, 2, 4 or 8) bytes from ``src`` to ``dst``, as one load and store."""
        blocks = {b: em.new_block(f"copy{b}") for b in (1, 2, 4, 8)}
        done = em.new_block("copied")
        for bytes_, block in blocks.items():
            nxt = em.new_block(f"not{bytes_}") if bytes_ != 8 else None
            em.cbranch(ops.compare(em, INDEX, "eq", size, idx(bytes_)), block, nxt or done)
            em.goto(block)
            t = VType(KINDS["UByte"] if bytes_ == 1 else KINDS["UShort"] if bytes_ == 2 else
                      KINDS["Int"] if bytes_ == 4 else T.INDEX_KIND, 1)
            value = em.load(em.cast_pointer(src, t.mem_ir), align=1, name="v")
            em.store(value, em.cast_pointer(dst, t.mem_ir), align=1)
            em.branch(done)
            if nxt is not None:
                em.goto(nxt)
        em.goto(done)

    with em:
        scatter, ptrs, steps, cstrides, channels, kbytes, ncols, nin, i, n, k_in, width, buf, slot_bytes = em.params
        gather_b, scatter_b = em.new_block("gather"), em.new_block("scatter")
        em.cbranch(ops.compare(em, INDEX, "eq", scatter, idx(0)), gather_b, scatter_b)

        def extent(c):
            """[lo, hi) of the bytes column ``c`` occupies from element ``i`` to ``n - 1``."""
            ptr, step, cstride, chans, kb = column(c, "x")
            first = add(em.convert("ptrtoint", ptr, INDEX, name="base"), mul(i, step))
            span = mul(ops.binary(em, "sub", INDEX, ops.binary(em, "sub", INDEX, n, i), idx(1)), step)
            inner = mul(ops.binary(em, "sub", INDEX, chans, idx(1)), cstride)
            lo = add(add(first, ops.binary(em, "min", INDEX, span, idx(0))), ops.binary(em, "min", INDEX, inner, idx(0)))
            hi = add(add(add(first, ops.binary(em, "max", INDEX, span, idx(0))),
                         ops.binary(em, "max", INDEX, inner, idx(0))), kb)
            return first, step, lo, hi

        em.goto(gather_b)
        left = ops.binary(em, "sub", INDEX, n, i)
        k_slot = em.alloca(INDEX, "k")
        em.store(ops.binary(em, "min", INDEX, width, left), k_slot)

        def against_inputs(a):
            fa, sa, lo_a, hi_a = extent(a)

            def against_outputs(b):
                fb, sb, lo_b, hi_b = extent(b)
                same = ops.binary(em, "and", bool1, ops.compare(em, INDEX, "eq", fa, fb),  # in place, moving
                                  ops.binary(em, "and", bool1, ops.compare(em, INDEX, "eq", sa, sb),
                                             ops.compare(em, INDEX, "ne", sa, idx(0))))
                meet = ops.binary(em, "and", bool1, ops.compare(em, INDEX, "lt", lo_b, hi_a),
                                  ops.compare(em, INDEX, "lt", lo_a, hi_b))
                overlap = ops.binary(em, "and", bool1, meet, ops.unary(em, "invert", bool1, same))
                em.store(em.select(overlap, idx(1), em.load(k_slot, name="k"), name="k"), k_slot)
            loop(nin, ncols, against_outputs, "outs")
        loop(idx(0), nin, against_inputs, "ins")
        k = em.load(k_slot, name="k")
        last = ops.binary(em, "sub", INDEX, k, idx(1))

        def gather_column(c):
            ptr, step, cstride, chans, kb = column(c, "in")
            base = em.address(buf, mul(c, slot_bytes), name="slot")

            def lane(j):
                e = add(i, ops.binary(em, "min", INDEX, j, last))
                src = em.address(ptr, mul(e, step), name="src")
                dst = em.address(base, mul(mul(j, chans), kb), name="dst")
                loop(idx(0), chans, lambda ch: copy(em.address(dst, mul(ch, kb)), em.address(src, mul(ch, cstride)),
                                                   kb), "ch")
            loop(idx(0), width, lane, "lane")
        loop(idx(0), nin, gather_column, "gather")
        em.ret(em.load(k_slot, name="k"))

        em.goto(scatter_b)

        def scatter_column(c):
            ptr, step, cstride, chans, kb = column(c, "out")
            base = em.address(buf, mul(c, slot_bytes), name="slot")

            def lane(j):
                dst = em.address(ptr, mul(add(i, j), step), name="dst")
                src = em.address(base, mul(mul(j, chans), kb), name="src")
                loop(idx(0), chans, lambda ch: copy(em.address(dst, mul(ch, cstride)), em.address(src, mul(ch, kb)),
                                                   kb), "ch")
            loop(idx(0), k_in, lane, "lane")
        loop(nin, ncols, scatter_column, "scatter")
        em.ret(k_in)
        em.finish()
