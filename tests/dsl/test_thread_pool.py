"""The thread split's persistent pool: same bits as one thread at every size, calls in a row and from
several Python threads at once, configure() changes, a fork's child, interpreter exit, signals.

No timing here: speed is measured by benchmarks/bench_parallel.py."""
import multiprocessing
import os
import subprocess
import sys
import textwrap
import threading

import numpy as np
import pytest

import reactor
import routines
from reactor import Float, MulAdd, kernel
from reactor.kernels import parallel
from dsl_helpers import serial

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


@kernel
def pool_fused(x: Float, y: Float) -> (Float, Float):
    return MulAdd(x, y, 1.0), x - y


@pytest.fixture
def split_everything():
    """Two threads, every call of more than one element split; the settings and spin restored."""
    saved, spin = reactor.thread_settings(), parallel.pool_state().spin_ns
    reactor.configure_threads(threads=2, threshold=1, min_work=0)
    yield
    reactor.configure_threads(**saved._asdict())
    parallel.set_spin(spin)


def _operands(n, seed=0):
    rng = np.random.default_rng(seed)
    return rng.normal(size=n).astype(np.float32), rng.normal(size=n).astype(np.float32)


@pytest.mark.parametrize("n", [1, 63, 64, 65, 255, 256, 257, 1000, 4095, 4096, 4097, 8195, 100_003, 2 ** 20 + 7])
def test_every_element_written_once_with_the_serial_bits(split_everything, n):
    x, y = _operands(n, n)
    want = serial(pool_fused, x, y)
    got = (np.full(n, np.nan, np.float32), np.full(n, np.nan, np.float32))
    pool_fused(x, y, out=got)
    for g, w in zip(got, want):
        assert np.array_equal(g, w)


def test_broadcast_operands_split_in_numpys_buffers(split_everything):
    row, col = _operands(1024, 7)
    got = pool_fused(row[None, :], col[:, None])
    want = serial(pool_fused, row[None, :], col[:, None])
    assert all(np.array_equal(g, w) for g, w in zip(got, want))


@pytest.mark.parametrize("spin", [0, 20_000])
def test_many_small_and_large_calls_in_a_row(split_everything, spin):
    parallel.set_spin(spin)  # 0: every worker sleeps on the futex between calls
    cases = [_operands(n, n) for n in (4096, 300, 70_001, 1, 9000)]
    wants = [serial(pool_fused, x, y) for x, y in cases]
    for i in range(600):
        (x, y), want = cases[i % len(cases)], wants[i % len(cases)]
        got = pool_fused(x, y)
        assert all(np.array_equal(g, w) for g, w in zip(got, want)), i
    assert parallel.pool_state().workers >= 1


def test_calls_from_several_python_threads_at_once(split_everything):
    cases = [_operands(n, n) for n in (5000, 33_333, 200_000, 4096)]
    wants = [serial(pool_fused, x, y) for x, y in cases]
    exp2 = routines.jit("exp2")
    wants_exp2 = [serial(exp2, x) for x, _ in cases]
    errors = []

    def caller(k):
        try:
            for i in range(150):
                j = (i + k) % len(cases)
                got = pool_fused(*cases[j])
                if not all(np.array_equal(g, w) for g, w in zip(got, wants[j])):
                    errors.append((k, i, "fused"))
                if not np.array_equal(exp2(cases[j][0]), wants_exp2[j]):
                    errors.append((k, i, "exp2"))
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append((k, repr(e)))

    threads = [threading.Thread(target=caller, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    assert not any(t.is_alive() for t in threads), "a caller is stuck"
    assert errors == []


def test_configure_grows_the_pool_and_idles_the_rest(split_everything):
    x, y = _operands(50_000, 3)
    want = serial(pool_fused, x, y)
    before = parallel.pool_state().workers  # other tests may have asked for more threads
    for threads in (4, 2, 1, 3, 4):
        reactor.configure_threads(threads=threads)
        got = pool_fused(x, y)
        assert all(np.array_equal(g, w) for g, w in zip(got, want)), threads
        if threads > 1:
            assert parallel.pool_state().workers >= threads - 1
    assert parallel.pool_state().workers == max(before, 3)  # never more than asked for, kept when fewer are


def test_spin_is_validated():
    before = parallel.pool_state().spin_ns
    for bad in (-1, 1.5, True):
        with pytest.raises(ValueError):
            parallel.set_spin(bad)
    assert parallel.pool_state().spin_ns == before


def _child_work(n):
    """In a fork's child: the pool as inherited, then a split call and the pool after it."""
    inherited = parallel.pool_state()
    reactor.configure_threads(threads=2, threshold=1, min_work=0)
    x, y = _operands(n, 11)
    got = pool_fused(x, y)
    return inherited, parallel.pool_state(), os.getpid(), got


def test_a_forked_child_starts_its_own_workers(split_everything):
    x, y = _operands(100_000, 11)
    pool_fused(x, y)  # the parent's workers exist, and sleep or spin
    assert parallel.pool_state().workers >= 1
    want = serial(pool_fused, x, y)
    with multiprocessing.get_context("fork").Pool(2, maxtasksperchild=1) as processes:
        results = processes.map(_child_work, [100_000] * 4)
    for inherited, after, pid, got in results:
        assert inherited.workers == 0 and inherited.pid == pid and not inherited.stopped
        assert after.workers >= 1 and after.pid == pid
        assert all(np.array_equal(g, w) for g, w in zip(got, want))


def _run(code: str, timeout: float = 120) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                          timeout=timeout, env=env, cwd=ROOT)


PRELUDE = """
    import os, sys, threading
    import numpy as np
    import reactor
    from reactor import Float, kernel
    from reactor.kernels import parallel
    k = kernel(lambda x: x * 3.0 + 1.0, args=[Float], returns=Float, name="pool_exit_probe")
    reactor.configure_threads(threads=2, threshold=1, min_work=0)
    x = np.arange(200_000, dtype=np.float32)
    assert np.array_equal(k(x), x * 3 + 1)
    assert parallel.pool_state().workers >= 1
"""


@pytest.mark.parametrize("spin", [0, 10 ** 9])
def test_exit_with_workers_asleep_or_spinning(spin):
    """Exit right after a split call: workers asleep (spin 0) or spinning (1 s): no hang, no crash."""
    done = _run(PRELUDE + f"""
    parallel.set_spin({spin})
    assert np.array_equal(k(x), x * 3 + 1)
    print("ok")
    """)
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr


def test_exit_while_a_daemon_thread_splits_calls():
    done = _run(PRELUDE + """
    def forever():
        while True:
            k(x)
    threading.Thread(target=forever, daemon=True).start()
    import time; time.sleep(0.2)
    print("ok")
    """)
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr


def test_after_the_pool_stops_calls_run_serially():
    done = _run(PRELUDE + """
    parallel._stop_pool()
    state = parallel.pool_state()
    assert state.stopped and state.workers == 0, state
    assert np.array_equal(k(x), x * 3 + 1)
    assert parallel.pool_state().workers == 0
    print("ok")
    """)
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr


def test_fork_after_use_then_exit_in_a_fresh_process():
    """multiprocessing's fork after the pool was used, kernels split in the children, then exit."""
    done = _run(PRELUDE + """
    import multiprocessing
    def child(seed):
        y = np.random.default_rng(seed).normal(size=300_000).astype(np.float32)
        return parallel.pool_state().workers, bool(np.array_equal(k(y), y * 3 + 1)), parallel.pool_state().workers
    if __name__ == "__main__":
        with multiprocessing.get_context("fork").Pool(2, maxtasksperchild=1) as p:
            print(p.map(child, range(4)))
    """)
    assert done.returncode == 0, done.stderr
    results = eval(done.stdout.strip())
    assert all(before == 0 and ok and after >= 1 for before, ok, after in results), results


def test_workers_block_every_signal_and_a_signal_waits_for_the_call():
    """Workers block signals, so Python's threads take them; an alarm during a long split call
    raises once the call has returned, its output complete (parallel.py's docstring)."""
    done = _run(PRELUDE + """
    import signal
    before = set(os.listdir("/proc/self/task"))  # Python's threads and one worker so far
    reactor.configure_threads(threads=3)
    k(x)  # two more workers
    def blocked(tid):
        with open(f"/proc/self/task/{tid}/status") as f:
            mask = int(next(l for l in f if l.startswith("SigBlk")).split()[1], 16)
        return all(mask >> (s - 1) & 1 for s in (signal.SIGINT, signal.SIGALRM, signal.SIGTERM))
    new = set(os.listdir("/proc/self/task")) - before  # the second worker
    assert len(new) == 1 and all(blocked(t) for t in new), new
    assert sum(blocked(t) for t in os.listdir("/proc/self/task")) >= 2  # both workers
    assert not blocked(str(threading.get_native_id()))
    class Alarm(Exception):
        pass
    def ring(*_):
        raise Alarm
    signal.signal(signal.SIGALRM, ring)
    import routines
    big = np.random.default_rng(0).uniform(0.5, 2, 2 ** 23).astype(np.float32)
    want = np.empty_like(big)
    pow_ = routines.jit("pow")  # bound before the loop: no Python frame between the alarm and the call
    reactor.configure_threads(threads=1)
    pow_(big, big, out=want)
    reactor.configure_threads(threads=3)
    out = np.full_like(big, np.nan)
    rang = 0
    for _ in range(20):
        out[:] = np.nan
        called = False
        try:
            try:
                signal.setitimer(signal.ITIMER_REAL, 0.002)  # rings during the call, or just after it
                called = True
                pow_(big, big, out=out)
            finally:
                signal.setitimer(signal.ITIMER_REAL, 0)
        except Alarm:  # a fast host may finish first: the alarm then rings here, not in the call
            rang += 1
        if called:
            assert np.array_equal(out, want)
    print("ok", rang)
    """)
    assert done.returncode == 0 and done.stdout.startswith("ok"), done.stderr


def test_workers_take_the_callers_rounding_mode():
    """A worker runs its chunks under the calling thread's floating-point controls, set after the
    workers were started: the same bits as one thread under that mode."""
    done = _run(PRELUDE + """
    import ctypes
    libm = ctypes.CDLL("libm.so.6")
    FE_TONEAREST, FE_UPWARD = (0, 0x800) if os.uname().machine == "x86_64" else (0, 0x400000)
    r = kernel(lambda a, b: a / b + a * b, args=[Float, Float], returns=Float, name="pool_rounding_probe")
    a = np.random.default_rng(5).normal(size=100_000).astype(np.float32)
    b = np.random.default_rng(6).normal(size=100_000).astype(np.float32) + np.float32(3)
    nearest = r(a, b)
    assert libm.fesetround(FE_UPWARD) == 0
    try:
        split = r(a, b)
        reactor.configure_threads(threads=1)
        serial = r(a, b)
    finally:
        libm.fesetround(FE_TONEAREST)
    assert np.array_equal(split, serial)
    assert not np.array_equal(split, nearest)  # the mode matters for these values
    print("ok")
    """)
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr


@pytest.mark.parametrize("n", [5000, 300_000])
def test_accumulate_reduce_and_in_place_calls_keep_the_serial_bits(split_everything, n):
    """``accumulate`` reads the element it wrote last and ``reduce`` one accumulator: such calls run
    serially; an output written over its input (``out=x``) still splits."""
    step = kernel(lambda a, b: a * 0.5 + b * 1.0001, args=[Float, Float], returns=Float, name="pool_acc_probe")
    x = np.random.default_rng(n).uniform(0, 1, n).astype(np.float32)
    assert np.array_equal(step.accumulate(x), serial(step.accumulate, x))
    assert step.reduce(x) == serial(step.reduce, x)
    assert np.array_equal(step.reduce(x.reshape(50, -1), axis=1), serial(step.reduce, x.reshape(50, -1), axis=1))
    y, want = x.copy(), serial(step, x, x[::-1])
    step(y, x[::-1], out=y)
    assert np.array_equal(y, want)
