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
import hashlib
import os
import threading
from typing import NamedTuple

from ..build import BuildOptions
from ..errors import LoopLimitError
from ..ir import emitter as _em
from ..ir import ops
from ..ir import types as T
from ..ir.types import INDEX, KINDS, VType
from ..jit import cache
from ..jit.compiler import CompiledCode, cached_object
from . import abi
from .recipe import library_digest

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
SettingsStruct, LoopConfig, ErrorLoop = abi.SETTINGS.ctype, abi.LOOP_CONFIG.ctype, abi.ERROR_LOOP.ctype


def error_loop(message: str, exception: type) -> tuple[int, ctypes.Structure]:
    """(address of ``reactor_raise``, its data) for a loop that raises ``exception(message)``;
    keep the data alive as long as the ufunc."""
    _runtime_addresses()
    data = ErrorLoop(settings=ctypes.pointer(_settings), message=message.encode(), exception=id(exception))
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


_settings = SettingsStruct(threads=min(_default_threads(), MAX_THREADS), threshold=DEFAULT_THRESHOLD,
                           min_work=DEFAULT_MIN_WORK, gil_ensure=_c_function("PyGILState_Ensure"),
                           err_set=_c_function("PyErr_SetString"), gil_release=_c_function("PyGILState_Release"),
                           runtime_error=id(LoopLimitError))
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


def make_config(nargs: int, cycles_per_element: float, messages=(), ndims: int = 1) -> ctypes.Structure:
    """The ``data`` block for one kernel loop (keep it alive as long as the ufunc): ``messages``
    are the errors of its loops that run out of iterations; ``ndims`` the entries of NumPy's
    ``dims`` its loop reads (1 + a gufunc's distinct core dimensions)."""
    if ndims > MAX_DIMS:
        raise ValueError(f"a kernel may have at most {MAX_DIMS - 1} core dimensions, not {ndims - 1}")
    _runtime_addresses()
    cycles = max(1, int(round(cycles_per_element * abi.CYCLES_SCALE)))
    table = (ctypes.c_char_p * max(1, len(messages)))(*[m.encode() for m in messages])
    config = LoopConfig(settings=ctypes.pointer(_settings), nargs=nargs, cycles_per_element=cycles, messages=table,
                        ndims=ndims)
    config._keep = table  # the strings live as long as the config
    return config


def _runtime_addresses() -> None:
    if _settings.parallel_for is None:
        _settings.parallel_for = runtime().address("reactor_parallel_for")
        _settings.prepare = runtime().address("reactor_prepare")
        _settings.move = runtime().address("reactor_move")


# -- the native runtime ------------------------------------------------------------------------

RUNTIME_EXPORTS = (abi.PARALLEL_FOR.name, abi.PREPARE.name, abi.RAISE.name, abi.MOVE.name)


@functools.cache
def runtime(target: str = "host") -> CompiledCode:
    """The compiled runtime (built once per process and target, cached on disk):
    ``reactor_parallel_for`` and ``reactor_prepare`` (every kernel's layout decisions, kept out
    of each kernel's code). The host's is loaded into this process; another target's is object
    code to link elsewhere (``reactor.kernels.qemu``)."""
    build = BuildOptions(target=target, width=1).resolved()

    def ir_text() -> str:
        module = _em.ModuleEmitter("reactor.parallel", build)
        _emit_runtime(module)
        _emit_prepare(module)
        _emit_raise(module)
        _emit_move(module)
        return module.text
    # its IR depends only on reactor's sources and the target: a fresh process loads it from the
    # disk cache under that recipe without building the IR (the first kernel's disk hit stays fast)
    recipe = hashlib.sha256(f"reactor runtime|{library_digest()}|{build.target.key()}|{build.opt}".encode()).hexdigest()
    found = cache.recipe_get(recipe, build.cache)
    if found:
        obj, source = cached_object(found["ir_key"], build.cache)
        if obj is not None:
            return CompiledCode(None, build.target, build.opt, RUNTIME_EXPORTS, build.cache, key=found["ir_key"],
                                obj=obj, source=source, ir_source=ir_text)
    code = CompiledCode(ir_text(), build.target, build.opt, RUNTIME_EXPORTS, build.cache)
    cache.recipe_put(recipe, {"ir_key": code.key}, build.cache)
    return code


def _emit_raise(module) -> None:
    """``void reactor_raise(args, dims, steps, data)``: a ufunc loop that sets Python's error from
    its ``ErrorLoop`` (GIL taken) and touches no operand."""
    em = _em.FunctionEmitter(module, abi.RAISE.name, None, abi.RAISE.params, abi.RAISE.names, width=1)
    with em:
        data = abi.ERROR_LOOP.of(em, em.params[3])
        settings, message, exc = abi.ERROR_LOOP.load(em, data, "settings", "message", "exception")
        abi.raise_python_error(em, settings, exc, message)
        em.ret(None)
        em.finish()


def _idx(v: int):
    return T.const(INDEX, v)


def _emit_runtime(module) -> None:
    """``reactor_parallel_for`` and the worker each of its threads runs."""
    worker = _emit_worker(module)
    _emit_parallel_for(module, worker)


def _emit_worker(module):
    """``void *reactor_parallel_worker(struct task *)``: take chunks of the index space from the
    task's atomic counter and run the loop on each, until none is left."""
    em = _em.FunctionEmitter(module, "reactor_parallel_worker", T.BYTES, [T.BYTES], ["task"], width=1)
    with em:
        task = abi.TASK.of(em, em.params[0])
        loop, args, steps, data, nargs, n, chunk, dims, ndims = abi.TASK.load(
            em, task, "loop", "args", "steps", "data", "nargs", "n", "chunk", "dims", "ndims")
        sub_args = em.alloca(T.BYTES, "sub_args", count=64)  # NumPy ufuncs have at most 64 operands
        sub_n = em.alloca(INDEX, "sub_n", count=MAX_DIMS)  # the chunk's size, then the core dimensions
        with em.counting(1, ndims, "dims") as d:
            em.store(em.load(em.address(dims, d), name="dim"), em.address(sub_n, d))
        head, body, done = em.new_block("take"), em.new_block("chunk"), em.new_block("done")
        em.branch(head)
        em.goto(head)
        lo = em.atomic_add(abi.TASK.field(em, task, "next"), chunk, name="lo")
        em.cbranch(ops.compare(em, INDEX, "lt", lo, n), body, done)
        em.goto(body)
        hi = ops.binary(em, "add", INDEX, lo, chunk)
        hi = em.select(ops.compare(em, INDEX, "lt", hi, n), hi, n, name="hi")
        em.store(ops.binary(em, "sub", INDEX, hi, lo), sub_n)
        with em.counting(0, nargs, "args") as k:
            base, step = em.load(em.address(args, k), name="base"), em.load(em.address(steps, k), name="step")
            em.store(em.address(base, ops.binary(em, "mul", INDEX, lo, step)), em.address(sub_args, k))
        em.call_pointer(loop, None, abi.LOOP.params, [sub_args, sub_n, steps, data])
        em.branch(head)
        em.goto(done)
        em.ret(T.null(T.BYTES))
        em.finish()
    return em.function


def _emit_parallel_for(module, worker) -> None:
    """``void reactor_parallel_for(loop, args, dims, steps, data, nargs, threads, ndims)``: split
    the call into chunks (about ``CHUNKS_PER_THREAD`` a thread, multiples of ``ALIGN``), start
    ``threads - 1`` threads on them, work on them too, then join every thread that started."""
    bool1, i32 = VType(KINDS["Bool"], 1), VType(KINDS["Int"], 1)
    create = module.declare("pthread_create", i32, [T.PointerType(INDEX), T.BYTES, T.BYTES, T.BYTES])
    join = module.declare("pthread_join", i32, [INDEX, T.BYTES])
    sig = abi.PARALLEL_FOR
    em = _em.FunctionEmitter(module, sig.name, None, sig.params, sig.names, width=1)
    with em:
        loop, args, dims, steps, data, nargs, threads, ndims = em.params
        n = em.load(dims, name="n")
        per = ops.binary(em, "mul", INDEX, threads, _idx(CHUNKS_PER_THREAD))
        chunk = ops.binary(em, "div", INDEX, ops.binary(em, "add", INDEX, n, ops.binary(em, "sub", INDEX, per,
                                                                                         _idx(1))), per)
        chunk = ops.binary(em, "and", INDEX, ops.binary(em, "add", INDEX, chunk, _idx(ALIGN - 1)), _idx(-ALIGN))
        task = em.alloca(abi.TASK.ir, "task")
        abi.TASK.store(em, task, loop=loop, args=args, steps=steps, data=data, nargs=nargs, n=n, chunk=chunk,
                       next=_idx(0), dims=dims, ndims=ndims)
        tids = em.alloca(INDEX, "tids", count=MAX_THREADS)
        made = em.alloca(T.BYTE, "made", count=MAX_THREADS)
        task_p = em.cast_pointer(task, T.BYTE, name="task.p")
        worker_p = em.function_address(worker, name="worker")
        with em.counting(1, threads, "start") as t:
            rc = em.call(create, [em.address(tids, t), T.null(T.BYTES), worker_p, task_p], name="rc")
            ok = ops.compare(em, i32, "eq", rc, T.const(i32, 0))
            em.store(ops.to_memory(em, bool1, ok), em.address(made, t))
        em.call(worker, [task_p])  # the calling thread works too
        with em.counting(1, threads, "join") as t:
            with em.if_then(ops.from_memory(em, bool1, em.load(em.address(made, t), name="made")), "started"):
                em.call(join, [em.load(em.address(tids, t), name="tid"), T.null(T.BYTES)])
        em.ret(None)
        em.finish()


def _emit_prepare(module) -> None:
    """``i64 reactor_prepare(args, dims, steps, nin, nargs, sizes, width, srcs, incs, splats, lane_bytes)``: whether
    a kernel's vector loop may run on this call's layout and from where. It may when every output is
    contiguous, every input contiguous or broadcast (stride 0), and no output starts inside an
    input's extent ahead of the input (``ufunc.accumulate`` passes ``out[i-1]`` as input ``i``; for
    ordinary calls NumPy copies overlapping operands). Then it sets each operand's start
    (``srcs``: the array, or for a broadcast input its value repeated ``width`` times in
    ``splats``, ``lane_bytes`` a lane) and step in bytes (``incs``), and returns ``n`` rounded down to a
    multiple of ``width``; otherwise 0."""
    em = _em.FunctionEmitter(module, abi.PREPARE.name, INDEX, abi.PREPARE.params, abi.PREPARE.names, width=1)
    with em:
        args, dims, steps, nin, nargs, sizes, width, srcs, incs, splats, lane_bytes = em.params
        n = em.load(dims, name="n")
        with em.if_then(ops.compare(em, INDEX, "lt", n, width), "short"):  # no whole vector: read nothing
            em.ret(_idx(0))
        ok = _vector_layout(em, args, steps, sizes, n, nin, nargs)
        with em.if_then(ops.unary(em, "invert", VType(KINDS["Bool"], 1), ok), "none"):
            em.ret(_idx(0))
        with em.counting(0, nargs, "where") as k:
            _operand_start(em, k, args, steps, sizes, nin, width, srcs, incs, splats, lane_bytes)
        em.ret(ops.binary(em, "and", INDEX, n, ops.unary(em, "neg", INDEX, width)))
        em.finish()


def _vector_layout(em, args, steps, sizes, n, nin, nargs):
    """Whether every operand is contiguous (or a broadcast input) and no output starts inside an
    input's extent ahead of it: an i1."""
    bool1 = VType(KINDS["Bool"], 1)
    ok = em.alloca(bool1, "ok")
    em.store(T.const(bool1, 1), ok)

    def need(cond):
        em.store(ops.binary(em, "and", bool1, em.load(ok, name="ok"), cond), ok)

    with em.counting(0, nargs, "layout") as k:
        step, size = em.load(em.address(steps, k), name="step"), em.load(em.address(sizes, k), name="size")
        contiguous = ops.compare(em, INDEX, "eq", step, size)
        broadcast = ops.binary(em, "and", bool1, ops.compare(em, INDEX, "lt", k, nin),
                               ops.compare(em, INDEX, "eq", step, _idx(0)))
        need(ops.binary(em, "or", bool1, contiguous, broadcast))
    with em.counting(0, nin, "inputs") as a:
        start_a = em.convert("ptrtoint", em.load(em.address(args, a), name="in"), INDEX, name="a")
        last = ops.binary(em, "sub", INDEX, ops.binary(em, "mul", INDEX, n, em.load(em.address(sizes, a),
                                                                                       name="size")), _idx(1))
        with em.counting(nin, nargs, "outputs") as b:
            start_b = em.convert("ptrtoint", em.load(em.address(args, b), name="out"), INDEX, name="b")
            ahead = ops.binary(em, "sub", INDEX, ops.binary(em, "sub", INDEX, start_b, start_a), _idx(1))
            need(ops.compare(em, T.UINDEX, "ge", ahead, last))
    return em.load(ok, name="ok")


def _operand_start(em, k, args, steps, sizes, nin, width, srcs, incs, splats, lane_bytes) -> None:
    """Operand ``k``'s start and step for the vector loop: a broadcast input's value repeated
    ``width`` times in its ``splats`` slot (step 0), else the array itself (step width * size)."""
    bool1 = VType(KINDS["Bool"], 1)
    step, size = em.load(em.address(steps, k), name="step"), em.load(em.address(sizes, k), name="size")
    arg = em.load(em.address(args, k), name="arg")
    broadcast = ops.binary(em, "and", bool1, ops.compare(em, INDEX, "lt", k, nin),
                           ops.compare(em, INDEX, "eq", step, _idx(0)))
    with em.if_else(broadcast, "bcast") as (then, otherwise):
        with then:
            slot = ops.binary(em, "mul", INDEX, k, ops.binary(em, "mul", INDEX, width, lane_bytes))
            buffer = em.address(splats, slot, name="buf")
            with em.counting(0, ops.binary(em, "mul", INDEX, width, size), "splat") as j:  # buffer[j] = arg[j % size]
                src = em.address(arg, ops.binary(em, "rem", INDEX, j, size))
                em.store(em.load(src, name="byte"), em.address(buffer, j))
            em.store(buffer, em.address(srcs, k))
            em.store(_idx(0), em.address(incs, k))
        with otherwise:
            em.store(arg, em.address(srcs, k))
            em.store(ops.binary(em, "mul", INDEX, width, size), em.address(incs, k))


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
    ``reduce`` reads and writes one element, step 0: such elements must be computed one after the other).
    ``scatter`` 1 copies the first ``k`` lanes of each output column ``c >= nin`` back to memory and
    returns ``k``."""
    em = _em.FunctionEmitter(module, abi.MOVE.name, INDEX, abi.MOVE.params, abi.MOVE.names, width=1)
    with em:
        mv = _Move(em, *em.params)
        with em.if_then(ops.compare(em, INDEX, "eq", mv.scatter, _idx(0)), "gather"):
            em.ret(mv.gather())
        em.ret(mv.scatter_outputs())
        em.finish()


class _Move:
    """The pieces of ``reactor_move`` (its parameters as attributes)."""

    def __init__(self, em, *params) -> None:
        self.em = em
        (self.scatter, self.ptrs, self.steps, self.cstrides, self.channels, self.kbytes, self.ncols, self.nin,
         self.i, self.n, self.k, self.width, self.buf, self.slot_bytes) = params

    def add(self, a, b):
        return ops.binary(self.em, "add", INDEX, a, b)

    def mul(self, a, b):
        return ops.binary(self.em, "mul", INDEX, a, b)

    def sub(self, a, b):
        return ops.binary(self.em, "sub", INDEX, a, b)

    def column(self, c, name):
        """Column ``c``'s (pointer, step, channel stride, channels, bytes a channel)."""
        return [self.em.load(self.em.address(p, c), name=f"{name}.{what}") for p, what in
                ((self.ptrs, "ptr"), (self.steps, "step"), (self.cstrides, "cstride"), (self.channels, "channels"),
                 (self.kbytes, "kbytes"))]

    def copy(self, dst, src, size) -> None:
        """``size`` (1, 2, 4 or 8) bytes from ``src`` to ``dst``, as one load and store."""
        em = self.em
        for bytes_, kind in ((1, KINDS["UByte"]), (2, KINDS["UShort"]), (4, KINDS["Int"]), (8, T.INDEX_KIND)):
            with em.if_then(ops.compare(em, INDEX, "eq", size, _idx(bytes_)), f"copy{bytes_}"):
                t = VType(kind, 1).mem_ir
                em.store(em.load(em.cast_pointer(src, t), align=1, name="v"), em.cast_pointer(dst, t), align=1)

    def extent(self, c):
        """(first element's address, step, lo, hi): the bytes [lo, hi) column ``c`` occupies from
        element ``i`` to ``n - 1``."""
        em = self.em
        ptr, step, cstride, chans, kb = self.column(c, "x")
        first = self.add(em.convert("ptrtoint", ptr, INDEX, name="base"), self.mul(self.i, step))
        span = self.mul(self.sub(self.sub(self.n, self.i), _idx(1)), step)
        inner = self.mul(self.sub(chans, _idx(1)), cstride)
        low = lambda v: ops.binary(em, "min", INDEX, v, _idx(0))  # noqa: E731
        high = lambda v: ops.binary(em, "max", INDEX, v, _idx(0))  # noqa: E731
        return first, step, self.add(self.add(first, low(span)), low(inner)), \
            self.add(self.add(self.add(first, high(span)), high(inner)), kb)

    def lanes_to_take(self):
        """``min(width, n - i)``, or 1 where an output's remaining elements overlap an input's
        other than in place."""
        em = self.em
        bool1 = VType(KINDS["Bool"], 1)
        k_slot = em.alloca(INDEX, "k")
        em.store(ops.binary(em, "min", INDEX, self.width, self.sub(self.n, self.i)), k_slot)
        with em.counting(0, self.nin, "ins") as a:
            fa, sa, lo_a, hi_a = self.extent(a)
            with em.counting(self.nin, self.ncols, "outs") as b:
                fb, sb, lo_b, hi_b = self.extent(b)
                same = ops.binary(em, "and", bool1, ops.compare(em, INDEX, "eq", fa, fb),  # in place, moving
                                  ops.binary(em, "and", bool1, ops.compare(em, INDEX, "eq", sa, sb),
                                             ops.compare(em, INDEX, "ne", sa, _idx(0))))
                meet = ops.binary(em, "and", bool1, ops.compare(em, INDEX, "lt", lo_b, hi_a),
                                  ops.compare(em, INDEX, "lt", lo_a, hi_b))
                overlap = ops.binary(em, "and", bool1, meet, ops.unary(em, "invert", bool1, same))
                em.store(em.select(overlap, _idx(1), em.load(k_slot, name="k"), name="k"), k_slot)
        return em.load(k_slot, name="k")

    def gather(self):
        """Inputs' elements ``i ..`` into their slots of ``buf``; the lanes taken."""
        em = self.em
        k = self.lanes_to_take()
        last = self.sub(k, _idx(1))
        with em.counting(0, self.nin, "gather") as c:
            ptr, step, cstride, chans, kb = self.column(c, "in")
            base = em.address(self.buf, self.mul(c, self.slot_bytes), name="slot")
            with em.counting(0, self.width, "lane") as j:
                src = em.address(ptr, self.mul(self.add(self.i, ops.binary(em, "min", INDEX, j, last)), step),
                                 name="src")
                dst = em.address(base, self.mul(self.mul(j, chans), kb), name="dst")
                with em.counting(0, chans, "ch") as ch:
                    self.copy(em.address(dst, self.mul(ch, kb)), em.address(src, self.mul(ch, cstride)), kb)
        return k

    def scatter_outputs(self):
        """The first ``k`` lanes of each output's slot back to memory; ``k``."""
        em = self.em
        with em.counting(self.nin, self.ncols, "scatter") as c:
            ptr, step, cstride, chans, kb = self.column(c, "out")
            base = em.address(self.buf, self.mul(c, self.slot_bytes), name="slot")
            with em.counting(0, self.k, "lane") as j:
                dst = em.address(ptr, self.mul(self.add(self.i, j), step), name="dst")
                src = em.address(base, self.mul(self.mul(j, chans), kb), name="src")
                with em.counting(0, chans, "ch") as ch:
                    self.copy(em.address(dst, self.mul(ch, cstride)), em.address(src, self.mul(ch, kb)), kb)
        return self.k
