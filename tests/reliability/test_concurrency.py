"""Threads: building, compiling and calling different routines at once for several
seconds (no crash, every result correct), and kernel execution without the GIL."""
import ctypes
import math
import threading
import time

import numpy as np
import pytest

import reactor

import routines
from fuzz import check, program_for
from reactor import DSLTypeError, Float, For, Function, Int, MulAdd, Pointer, Select, Variable, kernel

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
def spin(n: Int, x: Float, trace: Pointer[Float, "n"]) -> Float:
    """About n * 8 dependent float operations, each step's value written to trace[i] as it
    goes: a long-running call with scalar arguments whose progress another thread can see."""
    acc = Variable(Float, x)
    with For(0, n) as i:
        for _ in range(8):
            acc.set(MulAdd(acc, 0.999, 0.001))
        trace[i] = acc
    return acc


@kernel(name="gil_heavy")
def heavy(x: Float) -> Float:
    acc = Variable(x)
    with For(0, 64):
        acc.set(Select(acc > 2.0, acc * 0.5, MulAdd(acc, acc, 0.25)))
    return acc


def _seen_midway(call, written: np.ndarray, tries: int = 20) -> int:
    """In how many of up to ``tries`` calls (stopping after the third) a pure-Python thread
    saw ``written`` (which the call writes from first to last) half written: it can look only
    while it holds the GIL, so seeing that proves the call released the GIL. No clock: each
    call starts once the watcher is looking, and the watcher stops when the call is over."""
    seen = 0
    for _ in range(tries):
        written.fill(np.nan)
        looking, over, saw = threading.Event(), threading.Event(), []

        def watch():
            looking.set()
            while not over.is_set():
                # first, then last, each read holding the GIL (no NumPy loop: those may let go of
                # it): the first element written and, later, the last not yet means the call was
                # running, without the GIL, when this thread read the first
                if not math.isnan(written[0]) and math.isnan(written[-1]):
                    saw.append(True)
                    return

        th = threading.Thread(target=watch)
        th.start()
        looking.wait(60)
        call()
        over.set()
        th.join(60)
        assert not np.isnan(written).any()  # the call wrote everything
        seen += bool(saw)
        if seen == 3:
            break
    return seen


@pytest.fixture
def one_thread_kernels():
    saved = reactor.thread_settings()
    reactor.configure_threads(threads=1)
    yield
    reactor.configure_threads(**saved._asdict())


def test_kernel_and_routine_calls_release_the_gil(one_thread_kernels, capsys):
    """While one thread runs compiled code, a pure-Python thread runs too: it sees the call's
    output half written. The control: the same machine code called through
    ctypes.PYFUNCTYPE, which keeps the GIL, is never seen midway."""
    x = np.linspace(-1, 1, 1 << 20, dtype=np.float32)
    out = np.empty_like(x)
    n = 1 << 20
    trace = np.empty(n, np.float32)
    routine = spin.compile()
    n_val, x_val, ret = ctypes.c_int32(n), ctypes.c_float(0.5), ctypes.c_float()
    # argv: where each argument is (a pointer argument: its data)
    argv = (ctypes.c_void_p * 3)(ctypes.addressof(n_val), ctypes.addressof(x_val), trace.ctypes.data)
    holding = ctypes.PYFUNCTYPE(None, ctypes.c_void_p, ctypes.c_void_p)(routine.address)

    kernel_seen = _seen_midway(lambda: heavy(x, out=out), out)
    routine_seen = _seen_midway(lambda: spin(n, 0.5, trace), trace)
    held_seen = _seen_midway(lambda: holding(ctypes.addressof(argv), ctypes.addressof(ret)), trace, tries=3)

    # two threads running the kernel at once vs one after the other (shown, not asserted: a timing)
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
        print(f"\nGIL: a Python thread saw the output half written in {kernel_seen} kernel calls, {routine_seen} "
              f"routine calls and {held_seen} of 3 GIL-holding control calls; 2 kernel calls in 2 threads "
              f"{serial / parallel_time:.2f}x faster than one after the other")
    assert held_seen == 0  # the watcher cannot look while the GIL is held
    assert kernel_seen >= 1 and routine_seen >= 1


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0
