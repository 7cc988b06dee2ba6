"""Tiered compilation: a kernel's first code quickly, its optimized code swapped in when ready.

With tiering on (``configure(True)``, or ``REACTOR_TIERED=1`` in the environment), a kernel that
is traced (not found in a cache) is first emitted at LLVM's quickest code generation (about a
fifth of the time; its machine code is slower) and its ufunc runs that code at once. A
background thread then compiles the same optimized IR at full code generation, stores it in the
caches, and swaps the ufunc's loop pointer to it: the ufunc is the same object, and its results
are the same bits (one IR, two instruction selections). ``finish()`` waits for the swaps (a
benchmark calls it before timing).

Safe across fork and exit: a fork waits for the compile in flight and the child, which has no
thread, starts its own for what is still queued; at exit the queue is dropped and the thread
joined after its current compile (no thread runs LLVM while the interpreter is torn down). The
quick code of a kernel is kept as long as the kernel, so a call still running it is never cut.
"""
from __future__ import annotations

import atexit
import collections
import os
import threading
import time
import typing
import warnings

_enabled = os.environ.get("REACTOR_TIERED", "") not in ("", "0")
#: Seconds the thread waits before a compile: the end of the build that queued it would otherwise
#: take turns with it for the interpreter lock (3-4 ms added to a 8 ms build)
START_DELAY = 0.002
_jobs: "collections.deque[typing.Callable[[], None]]" = collections.deque()
_lock = threading.Lock()  # the queue, the worker and the counters
_working = threading.Lock()  # held while a job runs (a fork waits for it)
_idle = threading.Condition(_lock)
_worker: threading.Thread | None = None
_stopping = False
_running = 0


def configure(enabled: bool) -> None:
    """Tier the kernels traced from now on (True) or compile them fully before returning (False)."""
    global _enabled
    _enabled = bool(enabled)


def enabled() -> bool:
    return _enabled


def submit(job: typing.Callable[[], None]) -> None:
    """Run ``job`` (a kernel's full compile and swap) on the background thread."""
    global _worker
    with _lock:
        if _stopping:
            return
        _jobs.append(job)
        if _worker is None or not _worker.is_alive():
            _worker = threading.Thread(target=_work, name="reactor-tiers", daemon=True)
            _worker.start()


def finish(timeout: float | None = None) -> bool:
    """Wait until every queued kernel runs its optimized code; False if ``timeout`` passed first."""
    with _idle:
        return _idle.wait_for(lambda: not _jobs and not _running, timeout)


def pending() -> int:
    """Kernels still running their quick code (queued or compiling)."""
    with _lock:
        return len(_jobs) + _running


def _work() -> None:
    """Run the queued jobs one at a time; a job is taken and run while ``_working`` is held, so a
    fork (which takes it first) never copies a job that left the queue but did not run."""
    global _running
    while True:
        time.sleep(START_DELAY)  # let the build that queued the job return without sharing the GIL
        with _working:
            with _lock:
                if _stopping or not _jobs:
                    _idle.notify_all()
                    return
                job = _jobs.popleft()
                _running += 1
            try:
                job()
            except Exception as exc:  # the quick code stays: correct, only slower
                warnings.warn(f"reactor: a kernel keeps its quick code: its full compile failed ({exc})",
                              RuntimeWarning, stacklevel=1)
            finally:
                with _lock:
                    _running -= 1
                    _idle.notify_all()


@atexit.register
def _stop() -> None:
    """At exit: drop the queue, let the current compile end, join the thread."""
    global _stopping
    with _lock:
        _stopping = True
        _jobs.clear()
        worker = _worker
    if worker is not None and worker is not threading.current_thread():
        worker.join()


def _before_fork() -> None:
    _working.acquire()  # no compile in flight while the process is copied
    _lock.acquire()


def _after_in_parent() -> None:
    _lock.release()
    _working.release()


def _after_in_child() -> None:
    """The child has no worker thread: fresh locks, and a thread of its own for what is queued."""
    global _lock, _working, _idle, _worker, _running
    _lock, _working = threading.Lock(), threading.Lock()
    _idle = threading.Condition(_lock)
    _worker, _running = None, 0
    if _jobs and not _stopping:
        submit(_jobs.popleft())


os.register_at_fork(before=_before_fork, after_in_parent=_after_in_parent, after_in_child=_after_in_child)
