"""Threads: building, compiling and calling different routines at once for several
seconds (no crash, every result correct), and kernel execution without the GIL."""
import ctypes
import sys
import threading
import time

import numpy as np
import pytest

import reactor

import routines
from fuzz import check, program_for
from reactor import DSLTypeError, Float, For, Function, Int, MulAdd, Select, Variable, kernel

DURATION = 4.0  # seconds of concurrent work


def test_threads_build_compile_and_call_for_seconds():
    shared = {name: routines.jit(name) for name in ("exp2", "log2", "pow")}
    x = np.linspace(0.01, 20, 4099, dtype=np.float32)
    want = {name: (u(x, x[::-1].copy()) if name == "pow" else u(x)) for name, u in shared.items()}
    n_threads = 4
    barrier = threading.Barrier(n_threads)
    errors, done = [], [0] * n_threads

    def work(t):
        try:
            barrier.wait()
            deadline = time.perf_counter() + DURATION
            k = 0
            while time.perf_counter() < deadline or k < 3:
                k += 1
                c = np.float32(t * 1000 + k + 0.5)

                def body(a: Float, b: Float) -> Float:
                    return a * float(c) + b
                f = Function(body, name=f"thr{t}_{k}", cache=False)          # a fresh compile
                assert f(2.0, 1.0) == float(np.float32(2) * c + np.float32(1))
                if k % 3 == 0:                                                # a fresh ufunc
                    u = kernel(body, name=f"thrk{t}_{k}", width=(4, 8, 16)[k % 3], fma=bool(k % 2),
                               cache=False)
                    got = u(x, x)
                    assert np.array_equal(got, x * c + x)
                name = ("exp2", "log2", "pow")[(t + k) % 3]                    # shared routines
                if name == "pow":
                    got = shared[name](x[::-1], x)[::-1]
                    assert np.array_equal(got, want[name])
                else:
                    assert np.array_equal(shared[name](x[::-2]), want[name][::-2])
                if k % 7 == 0:                                                # a failing build
                    def broken(a: Float, i: Int) -> Float:
                        return a + i
                    with pytest.raises(DSLTypeError):
                        Function(broken, name=f"bad{t}_{k}").compile()
                if k % 11 == 0:                                               # a fuzz program
                    res = check(program_for("threads", t * 100 + k), seed=[t, k], widths=(1, 8))
                    assert res.status == "ok", res.summary() + res.error
                done[t] = k
        except BaseException as exc:  # noqa: BLE001 - reported below
            errors.append((t, exc))

    threads = [threading.Thread(target=work, args=(t,)) for t in range(n_threads)]
    for th in threads:
        th.start()
    for th in threads:
        th.join(timeout=DURATION + 120)
    assert not any(th.is_alive() for th in threads)
    assert not errors, errors
    assert sum(done) >= 4 * n_threads, done


@Function
def spin(n: Int, x: Float) -> Float:
    """About n * 8 dependent float operations: a long-running call with scalar arguments."""
    acc = Variable(Float, x)
    with For(0, n):
        for _ in range(8):
            acc.set(MulAdd(acc, 0.999, 0.001))
    return acc


@kernel(name="gil_heavy")
def heavy(x: Float) -> Float:
    acc = Variable(x)
    with For(0, 64):
        acc.set(Select(acc > 2.0, acc * 0.5, MulAdd(acc, acc, 0.25)))
    return acc


class _Counter:
    """A pure-Python thread that counts as fast as it can (it needs the GIL to count)
    and notes the time every 256 counts."""

    STEP = 256

    def __enter__(self):
        self.stop, self.count, self.times = threading.Event(), 0, []
        self.interval = sys.getswitchinterval()
        sys.setswitchinterval(1e-4)  # hand-offs of the GIL around each call stay short
        self.thread = threading.Thread(target=self._run)
        self.thread.start()
        time.sleep(0.02)
        return self

    def _run(self):
        while not self.stop.is_set():
            self.count += 1
            if self.count % self.STEP == 0:
                self.times.append(time.perf_counter())

    def __exit__(self, *exc):
        self.stop.set()
        self.thread.join()
        sys.setswitchinterval(self.interval)

    def rate(self, seconds=0.3) -> float:
        """Counts per second while this thread sleeps."""
        c0, t0 = self.count, time.perf_counter()
        time.sleep(seconds)
        return (self.count - c0) / (time.perf_counter() - t0)

    def share_during(self, call, rate: float, repeat: int = 7) -> float:
        """The counting done in the middle half of each call (away from the hand-offs of
        the GIL at its ends), as a share of the solo rate: near 1 if the call releases the
        GIL and a core is free, about 0.5 if the two threads share one core, exactly 0 if
        the call holds the GIL. The median over ``repeat`` calls."""
        shares = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            call()
            t1 = time.perf_counter()
            lo, hi = t0 + (t1 - t0) / 4, t1 - (t1 - t0) / 4
            stamps = np.asarray(self.times[-200_000:])
            inside = np.count_nonzero((stamps > lo) & (stamps < hi))
            shares.append(inside * self.STEP / (rate * (hi - lo)))
        return float(np.median(shares))


@pytest.fixture
def one_thread_kernels():
    saved = reactor.thread_settings()
    reactor.configure_threads(threads=1)
    yield
    reactor.configure_threads(**saved._asdict())


def test_kernel_and_routine_calls_release_the_gil(one_thread_kernels, capsys):
    """While one thread runs compiled code, a pure-Python thread keeps counting: the
    GIL is released for the call (as a control, the same machine code called through
    ctypes.PYFUNCTYPE, which keeps the GIL, stops the counter)."""
    x = np.linspace(-1, 1, 1 << 20, dtype=np.float32)
    heavy(x[:64])
    t0 = time.perf_counter()
    spin(1_000_000, 0.5)
    n = int(1_000_000 * 0.08 / max(time.perf_counter() - t0, 1e-4))  # calls of ~80 ms
    routine = spin.compile()
    n_val, x_val, ret = ctypes.c_int32(n), ctypes.c_float(0.5), ctypes.c_float()
    argv = (ctypes.c_void_p * 2)(ctypes.addressof(n_val), ctypes.addressof(x_val))
    holding = ctypes.PYFUNCTYPE(None, ctypes.c_void_p, ctypes.c_void_p)(routine.address)

    t0 = time.perf_counter()
    heavy(x)
    kernel_call = time.perf_counter() - t0
    t0 = time.perf_counter()
    spin(n, 0.5)
    routine_call = time.perf_counter() - t0
    assert kernel_call > 0.005 and routine_call > 0.02  # long enough to measure

    with _Counter() as counter:
        base = counter.rate()
        kernel_share = counter.share_during(lambda: heavy(x), base)
        routine_share = counter.share_during(lambda: spin(n, 0.5), base)
        held_share = counter.share_during(lambda: holding(ctypes.addressof(argv), ctypes.addressof(ret)), base)

    # two threads running the kernel at once vs one after the other
    def run_twice_serial():
        heavy(x)
        heavy(x)

    def run_twice_parallel():
        th = threading.Thread(target=heavy, args=(x,))
        th.start()
        heavy(x)
        th.join()

    serial = min(_timed(run_twice_serial) for _ in range(3))
    parallel_time = min(_timed(run_twice_parallel) for _ in range(3))
    with capsys.disabled():
        print(f"\nGIL: a Python thread's share of its solo counting rate during one call: kernel "
              f"({kernel_call * 1e3:.0f} ms) {kernel_share:.0%}, routine ({routine_call * 1e3:.0f} ms) "
              f"{routine_share:.0%}, GIL-holding control {held_share:.0%}; 2 kernel calls in 2 threads "
              f"{serial / parallel_time:.2f}x faster than one after the other")
    assert held_share < 0.02  # the measurement sees a held GIL
    assert kernel_share > 0.15
    assert routine_share > 0.15


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0
