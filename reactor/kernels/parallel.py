"""Multi-core kernels: large ufunc calls are split across threads.

Every kernel's ufunc loop is a small JIT dispatcher (``<name>.ufunc``). NumPy
passes it the ``data`` pointer registered with the loop, which points to a
``LoopConfig``: the address of the serial loop, of this module's hook, and of
the process-wide threshold. When ``n >= threshold`` the dispatcher calls the
hook, which cuts ``[0, n)`` into one contiguous chunk per thread (aligned to
64 elements so vector loops stay whole), runs all but the first on a thread
pool and the first itself, and returns when all are done. The serial loop is
called through ctypes, which releases the GIL, so the chunks really run in
parallel. Below the threshold the dispatcher calls the serial loop directly:
small calls pay nothing.

``configure(threads=..., threshold=...)`` changes both for every kernel;
``REACTOR_THREADS`` sets the default thread count (default: the CPUs this
process may run on).
"""
from __future__ import annotations

import concurrent.futures
import ctypes
import os
import threading

LOOP = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p)

#: Elements below which a call stays on one thread. Handing chunks to the pool
#: costs ~40-60 us here; measured break-even is near 2^19 elements for exp2, so
#: 2^20 keeps every parallel call clearly ahead (benchmarks/bench_parallel.py).
DEFAULT_THRESHOLD = 2 ** 20
_NEVER = 2 ** 62
ALIGN = 64


class LoopConfig(ctypes.Structure):
    """What a kernel's dispatcher reads through NumPy's per-loop ``data`` pointer."""

    _fields_ = [("serial", ctypes.c_void_p), ("hook", ctypes.c_void_p),
                ("threshold", ctypes.POINTER(ctypes.c_int64)), ("nargs", ctypes.c_int64)]


def _default_threads() -> int:
    env = os.environ.get("REACTOR_THREADS")
    if env:
        return max(1, int(env))
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


_threads = _default_threads()
_threshold = ctypes.c_int64(DEFAULT_THRESHOLD if _threads > 1 else _NEVER)
_pool: concurrent.futures.ThreadPoolExecutor | None = None
_pool_lock = threading.Lock()


def configure(threads: int | None = None, threshold: int | None = None) -> tuple[int, int]:
    """Set the thread count and/or the parallel threshold; returns the new (threads, threshold)."""
    global _threads, _pool
    with _pool_lock:
        if threads is not None:
            if threads < 1:
                raise ValueError("threads must be >= 1")
            _threads = threads
            if _pool is not None:
                _pool.shutdown(wait=True)
                _pool = None
        if threshold is not None:
            if threshold < 1:
                raise ValueError("threshold must be >= 1")
            _threshold.value = threshold
        elif threads is not None:
            _threshold.value = DEFAULT_THRESHOLD if _threads > 1 else _NEVER
        if _threads == 1:
            _threshold.value = _NEVER
        return _threads, _threshold.value


def settings() -> tuple[int, int]:
    """The current (threads, threshold)."""
    return _threads, _threshold.value


def _executor():
    global _pool
    with _pool_lock:
        if _pool is None:
            _pool = concurrent.futures.ThreadPoolExecutor(max(1, _threads - 1), thread_name_prefix="reactor")
        return _pool


def _split(n: int, parts: int) -> list[tuple[int, int]]:
    step = -(-n // parts)
    step = -(-step // ALIGN) * ALIGN
    return [(lo, min(lo + step, n)) for lo in range(0, n, step)]


def _run(args, dims, steps, data):
    """The hook: run the serial loop on one chunk per thread (called with the GIL)."""
    cfg = LoopConfig.from_address(data)
    nargs = cfg.nargs
    n = ctypes.c_int64.from_address(dims).value
    argv = (ctypes.c_void_p * nargs).from_address(args)
    stepv = (ctypes.c_int64 * nargs).from_address(steps)
    serial = LOOP(cfg.serial)
    calls = []
    for lo, hi in _split(n, _threads):
        sub_args = (ctypes.c_void_p * nargs)(*[(argv[k] or 0) + lo * stepv[k] for k in range(nargs)])
        sub_dims = (ctypes.c_int64 * 1)(hi - lo)
        calls.append((sub_args, sub_dims))
    pending = [_executor().submit(serial, a, d, steps, data) for a, d in calls[1:]]
    serial(calls[0][0], calls[0][1], steps, data)
    for f in pending:
        f.result()


HOOK = LOOP(_run)


def make_config(serial_address: int, nargs: int) -> LoopConfig:
    """The ``data`` block for one kernel loop (keep it alive as long as the ufunc)."""
    return LoopConfig(serial_address, ctypes.cast(HOOK, ctypes.c_void_p).value,
                      ctypes.pointer(_threshold), nargs)
