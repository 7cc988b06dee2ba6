"""Calls that are safe under Ctrl-C, signal handlers that raise, and fork.

A split call runs in native threads with no Python inside: a signal arriving
during it is taken when the ufunc returns, after every thread has finished
writing; no thread outlives the call, so children made by fork compute
correctly. The signal tests run in a subprocess (they signal the process)."""
from __future__ import annotations

import multiprocessing
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import reactor

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

SCRIPT = textwrap.dedent('''
    import os, signal, sys, threading, time
    import numpy as np
    import reactor
    from reactor import Float, For, Variable, kernel

    @kernel(name="slow")
    def slow(x: Float) -> Float:
        v = Variable(x)
        with For(0, 400):
            v.set(v * 0.999 + 0.5)   # a dependent chain: ~1,600 cycles per vector
        return v

    n = 1 << 19
    x = np.linspace(0, 1, n, dtype=np.float32)
    reactor.configure_threads(threads=1)
    want = slow(x)
    reactor.configure_threads(threads=2, threshold=1, min_work=0)
    mode = sys.argv[1]
    if mode == "alarm":
        class Alarm(Exception):
            pass
        def on_alarm(signum, frame):
            raise Alarm()
        signal.signal(signal.SIGALRM, on_alarm)
        caught = Alarm
    else:
        caught = KeyboardInterrupt
    taken = complete = 0
    for run in range(int(sys.argv[2])):
        out = np.full(n, np.nan, np.float32)
        try:  # on a loaded machine the signal may come before the call starts (even in Timer.start)
            if mode == "alarm":
                signal.setitimer(signal.ITIMER_REAL, 0.002)
            else:
                threading.Timer(0.002, os.kill, (os.getpid(), signal.SIGINT)).start()
            slow(x, out=out)
            for _ in range(10000):  # the signal may come after a fast call (or a loaded machine): wait
                time.sleep(0.001)
        except caught:
            taken += 1
        done = np.array_equal(out.view(np.uint32), want.view(np.uint32))
        assert done or np.isnan(out).all(), f"run {run}: output partly written"  # never half a call
        complete += done
        r = slow(x)  # a result freed right after: no thread may still write to it
        del r
    print("complete", complete, "taken", taken)
''')


def _run(mode: str, runs: int):
    proc = subprocess.run([sys.executable, "-c", SCRIPT, mode, str(runs)], capture_output=True, text=True,
                          timeout=300, cwd=ROOT, env=dict(os.environ, PYTHONPATH=ROOT))
    assert proc.returncode == 0, proc.stderr[-3000:]
    words = proc.stdout.split()
    return int(words[-3]), int(words[-1])


@pytest.mark.parametrize("mode", ["sigint", "alarm"])
def test_signal_during_split_call_is_taken_after_complete_output(mode):
    complete, taken = _run(mode, 12)
    assert taken == 12  # every signal arrived as an exception, once
    assert complete >= 6  # and most calls ran to the end first (the rest never started)


def _child(queue):
    from reactor import Float, kernel
    k = kernel(lambda x: x * 2.0 + 1.0, args=[Float], returns=Float, name="forked")
    x = np.arange(1 << 21, dtype=np.float32)
    queue.put(bool(np.array_equal(k(x), x * 2 + 1)))


@pytest.mark.parametrize("method", ["fork", "spawn", "forkserver"])
def test_children_compute_after_parallel_calls(method):
    if method not in multiprocessing.get_all_start_methods():
        pytest.skip(f"no {method} here")
    saved = reactor.thread_settings()
    reactor.configure_threads(threads=2, threshold=1, min_work=0)
    try:
        k = reactor.kernel(lambda x: x * 2.0 + 1.0, args=[reactor.Float], returns=reactor.Float, name="parent")
        x = np.arange(1 << 21, dtype=np.float32)
        assert np.array_equal(k(x), x * 2 + 1)  # a split call in the parent first
        ctx = multiprocessing.get_context(method)
        queue = ctx.Queue()
        proc = ctx.Process(target=_child, args=(queue,))
        proc.start()
        proc.join(120)
        assert proc.exitcode == 0 and queue.get(timeout=5) is True
    finally:
        reactor.configure_threads(**saved._asdict())
