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
    import os, signal, sys, threading
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
    mode, runs, wanted = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    signum = signal.SIGALRM if mode == "alarm" else signal.SIGINT
    if mode == "alarm":
        class Alarm(Exception):
            pass
        def on_alarm(signum, frame):
            raise Alarm()
        signal.signal(signal.SIGALRM, on_alarm)
        caught = Alarm
    else:
        caught = KeyboardInterrupt

    def signal_once_written(out, sent, during):
        """Send the signal once the call has written some output (so it has started, whatever the
        machine's load), and note whether the call was still writing then."""
        while np.isnan(out[::4096]).all():
            pass
        os.kill(os.getpid(), signum)
        during.append(bool(np.isnan(out).any()))
        sent.set()

    taken = complete = 0
    during = []
    for run in range(runs):
        out = np.full(n, np.nan, np.float32)
        sent = threading.Event()
        watcher = threading.Thread(target=signal_once_written, args=(out, sent, during), daemon=True)
        watcher.start()
        try:
            slow(x, out=out)
            if not sent.wait(60):  # bounded: the watcher runs once the call has written
                raise SystemExit("the signal was never sent")
            for _ in range(1000):  # the handler runs at the main thread's next check
                sent.wait(0.001)
            raise SystemExit(f"run {run}: the signal was never taken")
        except caught:
            taken += 1
        watcher.join(60)
        assert np.array_equal(out.view(np.uint32), want.view(np.uint32)), f"run {run}: output partly written"
        complete += 1
        r = slow(x)  # a result freed right after: no thread may still write to it
        del r
        if run + 1 >= wanted and sum(during) >= 1:
            break
    print("complete", complete, "taken", taken, "during", sum(during), "runs", run + 1)
''')


def _run(mode: str, runs: int, wanted: int):
    proc = subprocess.run([sys.executable, "-c", SCRIPT, mode, str(runs), str(wanted)], capture_output=True,
                          text=True, timeout=600, cwd=ROOT, env=dict(os.environ, PYTHONPATH=ROOT))
    assert proc.returncode == 0, proc.stderr[-3000:]
    words = proc.stdout.split()
    return {words[k]: int(words[k + 1]) for k in range(0, len(words), 2)}


@pytest.mark.parametrize("mode", ["sigint", "alarm"])
def test_signal_during_split_call_is_taken_after_complete_output(mode):
    """Each signal is sent once the call has begun writing (a watcher thread sees output), never
    by a clock: every call completes its output, then the signal arrives as an exception, once.
    Runs go on (up to 60) until at least one signal was sent while the call was still writing."""
    r = _run(mode, 60, 8)
    assert r["complete"] == r["taken"] == r["runs"] >= 8
    assert r["during"] >= 1  # the signal did arrive in the middle of a call


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
