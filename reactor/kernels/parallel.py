"""Multi-core kernels: large calls split across threads in native code, no Python inside.

Every kernel's ufunc loop is the runtime's one dispatcher (``reactor_dispatch``: a
kernel compiles only its own loop, ``<name>.loop``, which saves a fifth of a small
kernel's code generation). NumPy passes it the ``data`` pointer registered with the
loop, which points to the kernel's ``LoopConfig``: its code (the loop, and the
status its limited loops leave; one pointer, which a tiered kernel's optimized code
replaces whole), its operand count, the estimated cost of one element
(``cycles_per_element``, from the size of its vector body) and the
process-wide ``Settings``. A call is split when there is more than one thread,
at least ``threshold`` elements and an estimated ``n * cycles_per_element`` of
at least ``min_work`` cycles: splitting is decided by work, so a shader of
8,192 pixels is split and a copy of 8,192 floats is not.

A split call goes to ``reactor_parallel_for``, JIT-compiled once per process
from IR (``runtime()``). It hands the call to a pool of persistent worker
threads (``abi.POOL``, one per process): started on the first split call that
needs them (``pthread_create``, every signal blocked in them) and kept; they
run only native code (no Python, no GIL), under the calling thread's
floating-point controls (rounding, flush to zero: MXCSR or FPCR, copied for
each call), so a split call has the serial bits. A call publishes its task with one
*seat* per worker it wants (``threads - 1``, at most those there are; workers
beyond stay idle), bumps the pool's generation and wakes the workers that
sleep on it (a futex, Linux's ``syscall(SYS_futex)``); the calling thread and
every worker that takes a seat take chunks of the index space from the task's
atomic counter (multiples of 64 elements, shrinking: each thread's first is
``1 / (2 * threads)`` of the call, the last ones ``1 / (16 * threads)`` or 256
elements, so a busy core takes fewer and little is left to wait for), and the
call returns when every chunk is done: the output is complete when the ufunc
returns. The caller closes the seats nobody took, so it never waits for a
worker that is asleep or descheduled, only for chunks being run. After a job a
worker spins ``spin_ns`` (100 us; ``set_spin``) before it sleeps, so NumPy's next
buffer of a broadcast call (8,192 elements each, each a split call) or a
loop's next call finds it awake: a split costs about a microsecond, not a
thread's start and join. One split call uses the pool at a time: a call from
another Python thread meanwhile runs serially on its own thread, as do calls
when no worker could be started (a thread that cannot be created leaves its
share to the others; a later call tries again). A call whose elements depend
on each other runs serially too: ``ufunc.accumulate`` and ``ufunc.reduce``,
whose output overlaps an input other than in place (see ``_independent``).

No Python runs during the call and the workers block every signal, so a signal
(Ctrl-C, an alarm whose handler raises) goes to a Python thread and is taken
when the call returns, as for NumPy's own long calls. A child of ``fork``
(``multiprocessing`` with ``fork``) has no workers: ``os.register_at_fork``
resets the pool in the child, which starts its own on its first split call; a
child forked without Python's hooks sees another process's pool (its pid) and
runs every call serially. At interpreter exit the workers are told to leave and
joined (``reactor_pool_stop``, after a call in flight), before the runtime's
code is unloaded; calls after that run serially.

``configure(threads=..., threshold=..., min_work=...)`` changes the settings for
every kernel; ``REACTOR_THREADS`` sets the default thread count (default: the
CPUs this process may run on).
"""
from __future__ import annotations

import atexit
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
#: The chunks of a split call shrink: each thread's first is ``1 / (2 * threads)`` of the call, the
#: next ones half as large, down to the last ones of ``1 / (FINAL_CHUNKS * threads)`` of the call
#: or ``MIN_CHUNK`` elements (the larger): few chunks, and little left to wait for at the end; a
#: core slowed by other work takes fewer of them.
FINAL_CHUNKS = 16
MIN_CHUNK = 4 * ALIGN
#: At most this many threads per call.
MAX_THREADS = 256
#: Entries of NumPy's ``dims`` a loop may read: the loop size and a gufunc's core dimensions.
MAX_DIMS = 64
DEFAULT_THRESHOLD = 4096
#: Estimated cycles a call must cost before it is split: waking the pool's workers and
#: handing out chunks costs about a microsecond, and on two free cores the split pays from
#: about 3 us of work; 16,000 cycles (about 4 us) splits a copy from ~47,000 floats, exp2
#: from ~26,000 and a shader from a few thousand pixels (benchmarks/bench_parallel.py).
DEFAULT_MIN_WORK = 16_000
#: How long an idle worker, and a caller waiting for its workers' last chunks, spin before they
#: sleep on a futex: NumPy's next buffer of a broadcast call, or the next call of a loop, then
#: finds the workers awake. Longer than one of NumPy's buffers takes a shader on one core (about
#: 80 us for the noise example), so that a worker that woke too late for one buffer (a halted
#: vCPU can take that long) is awake for the next (benchmarks/bench_parallel.py).
DEFAULT_SPIN_NS = 100_000
SettingsStruct, LoopConfig, ErrorLoop = abi.SETTINGS.ctype, abi.LOOP_CONFIG.ctype, abi.ERROR_LOOP.ctype
CodeBlock = abi.CODE.ctype
PoolStruct = abi.POOL.ctype


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
#: The process's worker threads (``abi.POOL``), filled by the native runtime. Workers hold its
#: address while they live: they are stopped at exit (``_stop_pool``) before modules are torn down.
_tids = (ctypes.c_int64 * MAX_THREADS)()
_pool = PoolStruct(pid=os.getpid(), spin_ns=DEFAULT_SPIN_NS, tids=ctypes.cast(_tids, ctypes.POINTER(ctypes.c_int64)))
_settings.pool = ctypes.pointer(_pool)


class PoolState(NamedTuple):
    """The thread pool as this process sees it: ``workers`` started and kept (0 before the first
    split call, in a fork's child until its first, and after exit's stop), the ``pid`` they
    belong to, whether the pool is ``stopped`` (calls run serially), and ``spin_ns``."""

    workers: int
    pid: int
    stopped: bool
    spin_ns: int


def pool_state() -> PoolState:
    """The thread pool's state (see :class:`PoolState`)."""
    return PoolState(_pool.workers, _pool.pid, bool(_pool.quit), _pool.spin_ns)


def set_spin(ns: int) -> int:
    """Set how long an idle worker (and a caller waiting for the last chunks) spins before it
    sleeps, in nanoseconds (0: sleep at once); the previous value."""
    if not isinstance(ns, int) or isinstance(ns, bool) or ns < 0:
        raise ValueError(f"spin must be an int >= 0 nanoseconds, not {ns!r}")
    before, _pool.spin_ns = _pool.spin_ns, ns
    return before


def _reset_pool_in_child() -> None:
    """After ``os.fork`` in the child (its only thread): the parent's workers do not exist here,
    and a parent thread's call may have held the pool. The child starts its own on its first
    split call."""
    for name in ("gen", "sleepers", "seats", "remaining", "waiting", "busy", "workers", "quit"):
        setattr(_pool, name, 0)
    _pool.task = None
    _pool.pid = os.getpid()


def _stop_pool() -> None:
    """At interpreter exit: tell this process's workers to leave and join them, before the
    runtime's code is unloaded (later calls, from daemon threads, run serially)."""
    if _pool.workers and _pool.pid == os.getpid() and _settings.parallel_for:
        stop = ctypes.CFUNCTYPE(None, ctypes.c_void_p)(runtime().address(abi.POOL_STOP.name))
        stop(ctypes.addressof(_pool))


os.register_at_fork(after_in_child=_reset_pool_in_child)
atexit.register(_stop_pool)


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


def make_config(nargs: int, cycles_per_element: float, messages=(), ndims: int = 1, loop: int = 0,
                status: int = 0) -> ctypes.Structure:
    """The ``data`` block for one kernel loop (keep it alive as long as the ufunc): ``messages``
    are the errors of its loops that run out of iterations; ``ndims`` the entries of NumPy's
    ``dims`` its loop reads (1 + a gufunc's distinct core dimensions); ``loop`` its code's
    ``<name>.loop`` and ``status`` its module's status counter (0: none), as ``set_code``."""
    if ndims > MAX_DIMS:
        raise ValueError(f"a kernel may have at most {MAX_DIMS - 1} core dimensions, not {ndims - 1}")
    _runtime_addresses()
    cycles = max(1, int(round(cycles_per_element * abi.CYCLES_SCALE)))
    table = (ctypes.c_char_p * max(1, len(messages)))(*[m.encode() for m in messages])
    config = LoopConfig(settings=ctypes.pointer(_settings), nargs=nargs, cycles_per_element=cycles, messages=table,
                        ndims=ndims)
    config._keep = [table]  # the strings (and every code block) live as long as the config
    set_code(config, loop, status)
    return config


def set_code(config: ctypes.Structure, loop: int, status: int) -> None:
    """Make the dispatcher run ``loop`` (reporting through ``status``) for ``config``'s kernel from
    its next call: one pointer written whole, the code blocks before it kept (a call still running
    the code it read is never cut)."""
    code = CodeBlock(loop=loop or None, status=status or None)
    config._keep.append(code)
    config.code = ctypes.pointer(code)


def dispatcher() -> int:
    """The address of ``reactor_dispatch``: every kernel's ufunc loop."""
    return runtime().address(abi.DISPATCH.name)


def _runtime_addresses() -> None:
    if _settings.parallel_for is None:
        _settings.parallel_for = runtime().address("reactor_parallel_for")
        _settings.prepare = runtime().address("reactor_prepare")
        _settings.move = runtime().address("reactor_move")


# -- the native runtime ------------------------------------------------------------------------

RUNTIME_EXPORTS = (abi.PARALLEL_FOR.name, abi.PREPARE.name, abi.RAISE.name, abi.MOVE.name, abi.POOL_STOP.name,
                   abi.DISPATCH.name)


_runtimes: dict[str, CompiledCode] = {}
_runtime_lock = threading.Lock()  # one build per target: every kernel's config points into it


def runtime(target: str = "host") -> CompiledCode:
    """The compiled runtime (built once per process and target, cached on disk):
    ``reactor_parallel_for`` and ``reactor_prepare`` (every kernel's layout decisions, kept out
    of each kernel's code). The host's is loaded into this process; another target's is object
    code to link elsewhere (``reactor.kernels.qemu``). Thread-safe: the import's warm-up
    (:func:`warm_up`) and a first build may ask at once."""
    code = _runtimes.get(target)
    if code is None:
        with _runtime_lock:
            code = _runtimes.get(target)
            if code is None:
                code = _runtimes[target] = _load_runtime(target)
    return code


def _load_runtime(target: str) -> CompiledCode:
    build = BuildOptions(target=target, width=1).resolved()

    def ir_text() -> str:
        module = _em.ModuleEmitter("reactor.parallel", build)
        _emit_runtime(module)
        _emit_prepare(module)
        _emit_raise(module)
        _emit_move(module)
        _emit_dispatch(module)
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


_warm_up: threading.Thread | None = None


def warm_up() -> None:
    """Start the process's one-time JIT start-up (LLVM's native target, the JIT, the runtime
    from the disk cache: ~4-5 ms) on a background thread, so that it overlaps the rest of the
    import and the caller's own work, and the first kernel pays only its own build. LLVM runs
    with the interpreter lock released. A fork or the interpreter's exit waits for it first
    (``REACTOR_WARMUP=0``: no thread, the first build pays the start-up)."""
    global _warm_up
    if _warm_up is not None or os.environ.get("REACTOR_WARMUP", "1") == "0":
        return
    _warm_up = threading.Thread(target=_start_up, name="reactor-warm-up", daemon=True)
    _warm_up.start()


def _start_up() -> None:
    try:
        with cache.quietly():
            _runtime_addresses()
    except Exception:  # noqa: BLE001 - the first build meets the same error and reports it
        pass


def _join_warm_up() -> None:
    if _warm_up is not None and _warm_up is not threading.current_thread():
        _warm_up.join()


os.register_at_fork(before=_join_warm_up)
atexit.register(_join_warm_up)


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


def _emit_dispatch(module) -> None:
    """``void reactor_dispatch(args, dims, steps, data)``: every kernel's ufunc loop. ``data`` is
    the kernel's ``LoopConfig``; its ``code`` gives the kernel's loop, which a call worth
    splitting (by work: see the module docstring) runs through ``reactor_parallel_for`` and any
    other runs straight. After the call, if the kernel's status says a loop ran out of
    iterations, it sets Python's error with that loop's message (on the caller's thread, after
    every chunk: an error set on a worker thread would be lost)."""
    em = _em.FunctionEmitter(module, abi.DISPATCH.name, None, abi.DISPATCH.params, abi.DISPATCH.names, width=1)
    with em:
        args, dims, steps, data = em.params
        cfg = abi.LOOP_CONFIG.of(em, data)
        settings, nargs, cycles, ndims, code = abi.LOOP_CONFIG.load(em, cfg, "settings", "nargs",
                                                                    "cycles_per_element", "ndims", "code")
        loop, status = abi.CODE.load(em, code, "loop", "status")  # read once: one code for the whole call
        threads, threshold, min_work = abi.SETTINGS.load(em, settings, "threads", "threshold", "min_work")
        n = em.load(dims, name="n")
        work = ops.binary(em, "mul", INDEX, n, cycles)
        budget = ops.binary(em, "mul", INDEX, min_work, _idx(abi.CYCLES_SCALE))
        bool1 = VType(KINDS["Bool"], 1)
        worth = T.const(bool1, 1)
        for cond in (("gt", threads, _idx(1)), ("ge", n, threshold), ("ge", work, budget)):
            worth = ops.binary(em, "and", bool1, worth, ops.compare(em, INDEX, *cond))
        with em.if_else(worth, name="split") as (split, serial):
            with split:
                em.call_pointer(abi.SETTINGS.load(em, settings, "parallel_for"), None, abi.PARALLEL_FOR.params,
                                [loop, args, dims, steps, data, nargs, threads, ndims])
            with serial:
                em.call_pointer(loop, None, abi.LOOP.params, [args, dims, steps, data])
        null = ops.compare(em, INDEX, "eq", em.convert("ptrtoint", status, INDEX, name="status"), _idx(0))
        with em.if_then(ops.binary(em, "xor", bool1, null, T.const(bool1, 1)), name="counted"):
            old = em.atomic_swap(em.cast_pointer(status, _I32), T.const(_I32, 0), name="runaway")
            with em.if_then(ops.compare(em, _I32, "ne", old, T.const(_I32, 0)), name="runaway"):
                messages = abi.LOOP_CONFIG.load(em, cfg, "messages")
                which = ops.convert(em, _I32, INDEX, ops.binary(em, "sub", _I32, old, T.const(_I32, 1)))
                message = em.load(em.address(messages, which), name="message")
                abi.raise_python_error(em, settings, abi.SETTINGS.load(em, settings, "runtime_error"), message)
        em.ret(None)
        em.finish()


def _idx(v: int):
    return T.const(INDEX, v)


#: futex(2)'s system call number by architecture (called through libc's ``syscall``).
SYS_FUTEX = {"x86_64": 202, "aarch64": 98}
FUTEX_WAIT_PRIVATE, FUTEX_WAKE_PRIVATE = 128, 129
#: pthread_sigmask's SIG_SETMASK, and the bytes of glibc's sigset_t (both Linux targets).
SIG_SETMASK, SIGSET_BYTES = 2, 128
CLOCK_MONOTONIC = 1
#: The processor's hint inside a spin loop, and a full memory fence, by architecture: both are
#: intrinsics that LLVM must assume touch memory, so they also order the compiler's loads and stores.
_PAUSE = {"x86_64": ("llvm.x86.sse2.pause", None), "aarch64": ("llvm.aarch64.hint", 1)}
_FENCE = {"x86_64": ("llvm.x86.sse2.mfence", None), "aarch64": ("llvm.aarch64.dmb", 11)}
_I32 = VType(KINDS["Int"], 1)


class _Native:
    """What the pool's functions need from the processor and from libc, for one function
    (``em``): atomic reads, fences, spin hints, a clock, futexes, the process id.

    The emitter's atomics are monotonic; every publication of plain memory (the task, the
    outputs) is ordered by a :meth:`fence` on each side."""

    def __init__(self, em) -> None:
        self.em = em
        arch = em.settings.target.arch
        if arch not in SYS_FUTEX:  # reactor's targets are Linux on x86-64 and AArch64
            raise NotImplementedError(f"the thread pool knows no futex system call for architecture {arch}")
        self.arch, module = arch, em.module
        i8p = T.BYTES
        self._syscall = module.declare("syscall", INDEX, [INDEX, i8p, INDEX, INDEX, i8p, i8p, INDEX])
        self._clock = module.declare("clock_gettime", _I32, [_I32, T.PointerType(INDEX)])
        self._getpid = module.declare("getpid", _I32, [])
        self._now = em.alloca(INDEX, "timespec", count=2)

    def read(self, ptr, name: str = "v"):
        """An atomic read of ``*ptr`` (an i64: never hoisted out of a loop)."""
        return self.em.atomic_add(ptr, _idx(0), name=name)

    def _hint(self, table) -> None:
        name, arg = table[self.arch]
        fn = self.em.intrinsic(name, None, [] if arg is None else [_I32])
        self.em.call(fn, [] if arg is None else [T.const(_I32, arg)])

    def fence(self) -> None:
        """A full memory fence, for the processor and for the compiler."""
        self._hint(_FENCE)

    def pause(self) -> None:
        """The spin-loop hint (``pause``, ``yield``)."""
        self._hint(_PAUSE)

    def now(self):
        """CLOCK_MONOTONIC in nanoseconds (i64)."""
        em = self.em
        em.call(self._clock, [T.const(_I32, CLOCK_MONOTONIC), self._now])
        sec, nsec = em.load(self._now, name="sec"), em.load(em.address(self._now, 1), name="nsec")
        return ops.binary(em, "add", INDEX, ops.binary(em, "mul", INDEX, sec, _idx(1_000_000_000)), nsec)

    def controls(self):
        """The calling thread's floating-point controls (rounding, flush to zero: MXCSR on x86,
        FPCR on AArch64) as an i64."""
        em = self.em
        if self.arch == "x86_64":
            slot = em.alloca(_I32, "mxcsr")
            em.call(em.intrinsic("llvm.x86.sse.stmxcsr", None, [T.BYTES]), [em.cast_pointer(slot, T.BYTE)])
            return em.convert("zext", em.load(slot, name="mxcsr"), INDEX, name="controls")
        return em.call(em.intrinsic("llvm.aarch64.get.fpcr", INDEX, []), [], name="controls")

    def set_controls(self, value) -> None:
        """Make ``value`` (from :meth:`controls`) this thread's floating-point controls."""
        em = self.em
        if self.arch == "x86_64":
            slot = em.alloca(_I32, "mxcsr.new")
            em.store(em.convert("trunc", value, _I32, name="mxcsr"), slot)
            em.call(em.intrinsic("llvm.x86.sse.ldmxcsr", None, [T.BYTES]), [em.cast_pointer(slot, T.BYTE)])
        else:
            em.call(em.intrinsic("llvm.aarch64.set.fpcr", None, [INDEX]), [value])

    def pid(self):
        """getpid() as an i64."""
        return ops.convert(self.em, _I32, INDEX, self.em.call(self._getpid, [], name="pid"))

    def _futex(self, word, op: int, value) -> None:
        em = self.em
        em.call(self._syscall, [_idx(SYS_FUTEX[self.arch]), em.cast_pointer(word, T.BYTE), _idx(op), value,
                                T.null(T.BYTES), T.null(T.BYTES), _idx(0)])

    def wait(self, word, expected) -> None:
        """Sleep while the low 32 bits of ``*word`` equal those of ``expected`` (returns at once
        if they differ; may return spuriously or on a signal: callers loop)."""
        low = ops.binary(self.em, "and", INDEX, expected, _idx(0xFFFF_FFFF))
        self._futex(word, FUTEX_WAIT_PRIVATE, low)

    def wake(self, word, count) -> None:
        """Wake up to ``count`` threads sleeping on ``word``."""
        self._futex(word, FUTEX_WAKE_PRIVATE, count)

    def spin_until(self, pool, ready, name: str) -> None:
        """Emit a loop that spins (pause) until ``ready()`` (an i1, re-evaluated each turn) holds or
        the pool's ``spin_ns`` have passed; the code after it runs in either case."""
        em = self.em
        deadline = ops.binary(em, "add", INDEX, self.now(), abi.POOL.load(em, pool, "spin_ns"))
        head, turn, done = em.new_block(f"{name}.spin"), em.new_block(f"{name}.turn"), em.new_block(f"{name}.done")
        em.branch(head)
        em.goto(head)
        em.cbranch(ready(), done, turn)
        em.goto(turn)
        self.pause()
        em.cbranch(ops.compare(em, INDEX, "lt", self.now(), deadline), head, done)
        em.goto(done)


def _emit_runtime(module) -> None:
    """``reactor_parallel_for``, the pool's worker threads and ``reactor_pool_stop``."""
    chunks = _emit_take_chunks(module)
    worker = _emit_pool_worker(module, chunks)
    _emit_parallel_for(module, chunks, worker)
    _emit_pool_stop(module)


def _emit_take_chunks(module):
    """``void reactor_take_chunks(struct task *)``: take chunks of the index space by their index
    (the task's atomic counter ``next``, see :func:`_chunk_bounds`) and run the loop on each,
    until none is left."""
    em = _em.FunctionEmitter(module, "reactor_take_chunks", None, [T.BYTES], ["task"], width=1)
    with em:
        task = abi.TASK.of(em, em.params[0])
        loop, args, steps, data, nargs, n, last, dims, ndims, parts = abi.TASK.load(
            em, task, "loop", "args", "steps", "data", "nargs", "n", "chunk", "dims", "ndims", "parts")
        sub_args = em.alloca(T.BYTES, "sub_args", count=64)  # NumPy ufuncs have at most 64 operands
        sub_n = em.alloca(INDEX, "sub_n", count=MAX_DIMS)  # the chunk's size, then the core dimensions
        with em.counting(1, ndims, "dims") as d:
            em.store(em.load(em.address(dims, d), name="dim"), em.address(sub_n, d))
        head, body, done = em.new_block("take"), em.new_block("chunk"), em.new_block("done")
        em.branch(head)
        em.goto(head)
        index = em.atomic_add(abi.TASK.field(em, task, "next"), _idx(1), name="index")
        lo, hi = _chunk_bounds(em, index, n, parts, last)
        em.cbranch(ops.compare(em, INDEX, "lt", lo, n), body, done)
        em.goto(body)
        em.store(ops.binary(em, "sub", INDEX, hi, lo), sub_n)
        with em.counting(0, nargs, "args") as k:
            base, step = em.load(em.address(args, k), name="base"), em.load(em.address(steps, k), name="step")
            em.store(em.address(base, ops.binary(em, "mul", INDEX, lo, step)), em.address(sub_args, k))
        em.call_pointer(loop, None, abi.LOOP.params, [sub_args, sub_n, steps, data])
        em.branch(head)
        em.goto(done)
        em.ret(None)
        em.finish()
    return em.function


def _align_up(em, v):
    return ops.binary(em, "and", INDEX, ops.binary(em, "add", INDEX, v, _idx(ALIGN - 1)), _idx(-ALIGN))


def _chunk_bounds(em, index, n, parts, last):
    """Emit: the elements ``[lo, hi)`` of chunk number ``index`` (``lo >= n``: none). Level by
    level, ``parts`` chunks of ``(n - lo) / (2 * parts)`` elements (rounded up to ``ALIGN``) cover
    about half of what is left, until that size is at most ``last``: from there on, chunks of
    ``last`` elements. Chunks follow each other in the order of their index, without gaps."""
    def add(a, b):
        return ops.binary(em, "add", INDEX, a, b)

    def mul(a, b):
        return ops.binary(em, "mul", INDEX, a, b)

    lo_slot, i_slot, size_slot = em.alloca(INDEX, "lo"), em.alloca(INDEX, "i"), em.alloca(INDEX, "size")
    em.store(_idx(0), lo_slot)
    em.store(index, i_slot)
    head, level, deeper, done = (em.new_block(b) for b in ("level", "in_level", "deeper", "bounds"))
    em.branch(head)
    em.goto(head)
    lo, i = em.load(lo_slot, name="lo"), em.load(i_slot, name="i")
    rest = ops.binary(em, "max", INDEX, ops.binary(em, "sub", INDEX, n, lo), _idx(0))
    twice = mul(parts, _idx(2))
    size = _align_up(em, ops.binary(em, "div", INDEX, add(rest, ops.binary(em, "sub", INDEX, twice, _idx(1))), twice))
    final = ops.compare(em, INDEX, "le", size, last)
    size = em.select(final, last, size, name="size")
    em.store(size, size_slot)
    # the chunk is in this level (the last level holds every remaining index)
    em.cbranch(ops.binary(em, "or", VType(KINDS["Bool"], 1), final, ops.compare(em, INDEX, "lt", i, parts)),
               level, deeper)
    em.goto(deeper)
    em.store(add(lo, mul(parts, size)), lo_slot)
    em.store(ops.binary(em, "sub", INDEX, i, parts), i_slot)
    em.branch(head)
    em.goto(level)
    em.branch(done)
    em.goto(done)
    lo = add(em.load(lo_slot, name="lo"), mul(em.load(i_slot, name="i"), em.load(size_slot, name="size")))
    hi = add(lo, em.load(size_slot, name="size"))
    return lo, em.select(ops.compare(em, INDEX, "lt", hi, n), hi, n, name="hi")


def _emit_pool_worker(module, chunks):
    """``void *reactor_pool_worker(struct pool *)``: a worker thread's life. It waits for a new
    generation (spinning ``spin_ns``, then asleep on the futex), leaves if the pool is stopped,
    else takes one of the job's ``seats`` if any is left: then it takes chunks like the caller,
    under the caller's floating-point controls (rounding, flush to zero: the serial bits), and
    counts itself out of ``remaining`` (waking the caller if it sleeps and this was the last).

    A seat is only open while its job's task is published and its caller waits, so a worker
    that takes one reads a whole task; the caller closes the seats nobody took (a worker
    asleep or descheduled is never waited for)."""
    em = _em.FunctionEmitter(module, "reactor_pool_worker", T.BYTES, [T.BYTES], ["pool"], width=1)
    with em:
        nat = _Native(em)
        pool = abi.POOL.of(em, em.params[0])
        field = functools.partial(abi.POOL.field, em, pool)
        seen = em.alloca(INDEX, "seen")
        em.store(_idx(-1), seen)  # a new worker looks for an open seat at once
        head = em.new_block("next_job")
        em.branch(head)
        em.goto(head)
        old = em.load(seen, name="seen")
        gen = _wait_for_change(em, nat, pool, old)
        em.store(gen, seen)
        nat.fence()
        with em.if_then(ops.compare(em, INDEX, "ne", nat.read(field("quit"), "quit"), _idx(0)), "quit"):
            em.ret(T.null(T.BYTES))
        seat = em.atomic_add(field("seats"), _idx(-1), name="seat")
        with em.if_then(ops.compare(em, INDEX, "gt", seat, _idx(0)), "seated"):
            nat.fence()
            task = abi.POOL.load(em, pool, "task")
            own = nat.controls()  # the caller's rounding and flushing, so that the bits are the serial ones
            nat.set_controls(abi.TASK.load(em, abi.TASK.of(em, task), "fpcr"))
            em.call(chunks, [task])
            nat.set_controls(own)
            nat.fence()
            left = em.atomic_add(field("remaining"), _idx(-1), name="left")
            nat.fence()
            last = ops.compare(em, INDEX, "eq", left, _idx(1))
            with em.if_then(last, "last"):
                with em.if_then(ops.compare(em, INDEX, "ne", nat.read(field("waiting"), "waiting"), _idx(0)),
                                "caller_sleeps"):
                    nat.wake(field("remaining"), _idx(1))
        em.branch(head)
        em.finish()
    return em.function


def _wait_for_change(em, nat, pool, seen):
    """Emit: wait until the pool's generation differs from ``seen`` (spin, then sleep counted in
    ``sleepers``); the new generation."""
    gen_word = abi.POOL.field(em, pool, "gen")
    nat.spin_until(pool, lambda: ops.compare(em, INDEX, "ne", nat.read(gen_word, "gen"), seen), "idle")
    head, sleep, done = em.new_block("asleep?"), em.new_block("sleep"), em.new_block("woken")
    em.branch(head)
    em.goto(head)
    em.cbranch(ops.compare(em, INDEX, "ne", nat.read(gen_word, "gen"), seen), done, sleep)
    em.goto(sleep)
    sleepers = abi.POOL.field(em, pool, "sleepers")
    em.atomic_add(sleepers, _idx(1))
    nat.fence()  # counted before the futex compares the generation: a publisher sees us, or we see it
    nat.wait(gen_word, seen)
    em.atomic_add(sleepers, _idx(-1))
    em.branch(head)
    em.goto(done)
    return nat.read(gen_word, "gen")


def _emit_parallel_for(module, chunks, worker) -> None:
    """``void reactor_parallel_for(loop, args, dims, steps, data, nargs, threads, ndims)``: split
    the call into chunks (shrinking, see ``FINAL_CHUNKS``; multiples of ``ALIGN``) taken by
    the calling thread and up to ``threads - 1`` of the pool's workers (started on first need,
    kept), and return when every chunk is done. ``data`` is the kernel's ``LOOP_CONFIG``: the pool
    is its settings'. The call runs serially (one ``loop`` call) when its elements depend on each
    other (an accumulation or a reduction, see ``_independent``), when the pool is missing, stopped,
    another process's (a fork's child whose pool was not reset), or busy with another thread's call,
    or when no worker could be started."""
    sig = abi.PARALLEL_FOR
    em = _em.FunctionEmitter(module, sig.name, None, sig.params, sig.names, width=1)
    with em:
        loop, args, dims, steps, data, nargs, threads, ndims = em.params
        nat = _Native(em)
        serial = em.new_block("serial")
        settings = abi.LOOP_CONFIG.load(em, abi.LOOP_CONFIG.of(em, data), "settings")
        pool_p = abi.SETTINGS.load(em, settings, "pool")
        pool = abi.POOL.of(em, em.cast_pointer(pool_p, T.BYTE))
        field = functools.partial(abi.POOL.field, em, pool)
        _leave_unless(em, ops.compare(em, INDEX, "ne", em.convert("ptrtoint", pool_p, INDEX), _idx(0)), serial)
        _leave_unless(em, _independent(em, args, steps, em.load(dims, name="n"), nargs), serial)
        _leave_unless(em, ops.compare(em, INDEX, "eq", abi.POOL.load(em, pool, "pid"), nat.pid()), serial)
        _leave_unless(em, ops.compare(em, INDEX, "eq", em.atomic_swap(field("busy"), _idx(1)), _idx(0)), serial)
        nat.fence()
        release = em.new_block("release")
        _leave_unless(em, ops.compare(em, INDEX, "eq", nat.read(field("quit"), "quit"), _idx(0)), release)
        want = ops.binary(em, "sub", INDEX, threads, _idx(1))
        _grow_pool(em, nat, pool, want, worker)
        active = ops.binary(em, "min", INDEX, abi.POOL.load(em, pool, "workers"), want)
        _leave_unless(em, ops.compare(em, INDEX, "gt", active, _idx(0)), release)
        task = _publish(em, nat, pool, active, loop, args, dims, steps, data, nargs, ndims)
        em.call(chunks, [task])  # the calling thread works too
        _finish_job(em, nat, pool)
        nat.fence()
        em.atomic_swap(field("busy"), _idx(0))
        em.ret(None)
        em.goto(release)  # the pool taken but not used
        em.atomic_swap(field("busy"), _idx(0))
        em.branch(serial)
        em.goto(serial)
        em.call_pointer(loop, None, abi.LOOP.params, [args, dims, steps, data])
        em.ret(None)
        em.finish()


def _independent(em, args, steps, n, nargs):
    """Emit: whether the call's elements may be computed in any order (an i1): no two operands
    share bytes over the call unless they are one array in one place with one nonzero step (an
    output written over an input). ``ufunc.accumulate`` (an output that is an input shifted by one
    element) and ``ufunc.reduce`` (an accumulator of step 0, read and written) are not: they run
    serially. An operand's extent counts ``|step|`` bytes an element (1 for step 0); two inputs
    that overlap (``x[1:]`` and ``x[:-1]``) also run serially, which is safe."""
    bool1 = VType(KINDS["Bool"], 1)
    ok = em.alloca(bool1, "independent")
    em.store(T.const(bool1, 1), ok)

    def extent(k, name):
        start = em.convert("ptrtoint", em.load(em.address(args, k), name=f"{name}.p"), INDEX, name=name)
        step = em.load(em.address(steps, k), name=f"{name}.step")
        span = ops.binary(em, "mul", INDEX, ops.binary(em, "sub", INDEX, n, _idx(1)), step)
        size = ops.binary(em, "max", INDEX, ops.unary(em, "abs", INDEX, step), _idx(1))
        lo = ops.binary(em, "add", INDEX, start, ops.binary(em, "min", INDEX, span, _idx(0)))
        hi = ops.binary(em, "add", INDEX, ops.binary(em, "add", INDEX, start, ops.binary(em, "max", INDEX, span,
                                                                                            _idx(0))), size)
        return start, step, lo, hi

    with em.counting(0, nargs, "first") as a:
        start_a, step_a, lo_a, hi_a = extent(a, "a")
        with em.counting(ops.binary(em, "add", INDEX, a, _idx(1)), nargs, "second") as b:
            start_b, step_b, lo_b, hi_b = extent(b, "b")
            meet = ops.binary(em, "and", bool1, ops.compare(em, INDEX, "lt", lo_a, hi_b),
                              ops.compare(em, INDEX, "lt", lo_b, hi_a))
            same = ops.binary(em, "and", bool1, ops.compare(em, INDEX, "eq", start_a, start_b), ops.binary(
                em, "and", bool1, ops.compare(em, INDEX, "eq", step_a, step_b),
                ops.compare(em, INDEX, "ne", step_a, _idx(0))))
            clash = ops.binary(em, "and", bool1, meet, ops.unary(em, "invert", bool1, same))
            em.store(ops.binary(em, "and", bool1, em.load(ok, name="ok"), ops.unary(em, "invert", bool1, clash)), ok)
    return em.load(ok, name="independent")


def _leave_unless(em, cond, otherwise) -> None:
    """Emit: go on where ``cond`` holds, else branch to ``otherwise``."""
    go = em.new_block("go")
    em.cbranch(cond, go, otherwise)
    em.goto(go)


def _grow_pool(em, nat, pool, want, worker) -> None:
    """Emit: start workers until the pool has ``want`` (the pool is held), every signal blocked in
    them (a signal is taken by Python's threads; the mask is the creator's during
    ``pthread_create``). The first thread that cannot be created ends the attempt: the call runs
    on those there are, and a later call tries again."""
    create = em.module.declare("pthread_create", _I32, [T.PointerType(INDEX), T.BYTES, T.BYTES, T.BYTES])
    fill = em.module.declare("sigfillset", _I32, [T.BYTES])
    mask = em.module.declare("pthread_sigmask", _I32, [_I32, T.BYTES, T.BYTES])
    workers = abi.POOL.field(em, pool, "workers")
    with em.if_then(ops.compare(em, INDEX, "lt", em.load(workers, name="have"), want), "grow"):
        blocked, saved = em.alloca(T.BYTE, "blocked", count=SIGSET_BYTES), em.alloca(T.BYTE, "saved",
                                                                                       count=SIGSET_BYTES)
        em.call(fill, [blocked])
        em.call(mask, [T.const(_I32, SIG_SETMASK), blocked, saved])
        head, make, done = em.new_block("start?"), em.new_block("start"), em.new_block("started")
        em.branch(head)
        em.goto(head)
        have = em.load(workers, name="have")
        em.cbranch(ops.compare(em, INDEX, "lt", have, want), make, done)
        em.goto(make)
        tid = em.address(abi.POOL.load(em, pool, "tids"), have, name="tid")
        rc = em.call(create, [tid, T.null(T.BYTES), em.function_address(worker, name="worker"),
                              em.cast_pointer(pool, T.BYTE)], name="rc")
        ok = em.new_block("made")
        em.cbranch(ops.compare(em, _I32, "eq", rc, T.const(_I32, 0)), ok, done)
        em.goto(ok)
        em.store(ops.binary(em, "add", INDEX, have, _idx(1)), workers)
        em.branch(head)
        em.goto(done)
        em.call(mask, [T.const(_I32, SIG_SETMASK), saved, T.null(T.BYTES)])


def _publish(em, nat, pool, active, loop, args, dims, steps, data, nargs, ndims):
    """Emit: the call's task (on the caller's stack, with its floating-point controls) published
    with ``active`` seats, a new generation, and the sleeping workers woken if there are any; the
    task as a byte pointer."""
    field = functools.partial(abi.POOL.field, em, pool)
    n = em.load(dims, name="n")
    parts = ops.binary(em, "add", INDEX, active, _idx(1))
    last = _align_up(em, ops.binary(em, "div", INDEX, n, ops.binary(em, "mul", INDEX, parts, _idx(FINAL_CHUNKS))))
    last = ops.binary(em, "max", INDEX, last, _idx(MIN_CHUNK))
    task = em.alloca(abi.TASK.ir, "task")
    abi.TASK.store(em, task, loop=loop, args=args, steps=steps, data=data, nargs=nargs, n=n, chunk=last,
                   next=_idx(0), dims=dims, ndims=ndims, parts=parts, fpcr=nat.controls())
    task_p = em.cast_pointer(task, T.BYTE, name="task.p")
    abi.POOL.store(em, pool, task=task_p)
    em.atomic_swap(field("remaining"), active)
    nat.fence()  # the task and the count before any seat opens
    em.atomic_swap(field("seats"), active)
    nat.fence()
    em.atomic_add(field("gen"), _idx(1))
    nat.fence()  # the generation before the sleepers are counted (see _wait_for_change)
    with em.if_then(ops.compare(em, INDEX, "ne", nat.read(field("sleepers"), "sleepers"), _idx(0)), "wake"):
        nat.wake(field("gen"), active)
    return task_p


def _finish_job(em, nat, pool) -> None:
    """Emit: close the seats no worker took, then wait (spin, then sleep on ``remaining``) until
    every worker that took one has finished its chunks."""
    field = functools.partial(abi.POOL.field, em, pool)
    unused = em.atomic_swap(field("seats"), _idx(0), name="unused")
    with em.if_then(ops.compare(em, INDEX, "gt", unused, _idx(0)), "close"):
        em.atomic_add(field("remaining"), ops.unary(em, "neg", INDEX, unused))
    nat.fence()
    remaining = field("remaining")
    nat.spin_until(pool, lambda: ops.compare(em, INDEX, "eq", nat.read(remaining, "left"), _idx(0)), "join")
    em.atomic_swap(field("waiting"), _idx(1))
    nat.fence()  # waiting set before remaining is read: the last worker sees it, or we see 0
    head, sleep, done = em.new_block("done?"), em.new_block("sleep"), em.new_block("all_done")
    em.branch(head)
    em.goto(head)
    left = nat.read(remaining, "left")
    em.cbranch(ops.compare(em, INDEX, "eq", left, _idx(0)), done, sleep)
    em.goto(sleep)
    nat.wait(remaining, left)
    em.branch(head)
    em.goto(done)
    em.atomic_swap(field("waiting"), _idx(0))


def _emit_pool_stop(module) -> None:
    """``void reactor_pool_stop(struct pool *)``: at exit, stop this process's workers: mark the
    pool stopped (later calls run serially), wait for a call that uses it, wake every worker
    (they see ``quit`` and return) and join them. Another process's pool is left alone."""
    em = _em.FunctionEmitter(module, abi.POOL_STOP.name, None, abi.POOL_STOP.params, abi.POOL_STOP.names, width=1)
    join = module.declare("pthread_join", _I32, [INDEX, T.BYTES])
    pause = module.declare("sched_yield", _I32, [])
    with em:
        nat = _Native(em)
        pool = abi.POOL.of(em, em.params[0])
        field = functools.partial(abi.POOL.field, em, pool)
        with em.if_then(ops.compare(em, INDEX, "ne", abi.POOL.load(em, pool, "pid"), nat.pid()), "foreign"):
            em.ret(None)
        em.atomic_swap(field("quit"), _idx(1))
        nat.fence()
        head, wait, done = em.new_block("held?"), em.new_block("yield"), em.new_block("held")
        em.branch(head)
        em.goto(head)
        em.cbranch(ops.compare(em, INDEX, "eq", em.atomic_swap(field("busy"), _idx(1)), _idx(0)), done, wait)
        em.goto(wait)
        em.call(pause, [])
        em.branch(head)
        em.goto(done)
        nat.fence()
        em.atomic_add(field("gen"), _idx(1))
        nat.fence()
        nat.wake(field("gen"), _idx(2 ** 31 - 1))
        tids = abi.POOL.load(em, pool, "tids")
        with em.counting(0, abi.POOL.load(em, pool, "workers"), "join") as t:
            em.call(join, [em.load(em.address(tids, t), name="tid"), T.null(T.BYTES)])
        abi.POOL.store(em, pool, workers=_idx(0))
        nat.fence()
        em.atomic_swap(field("busy"), _idx(0))
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
