"""Multi-core kernels: one thread against all, by size, for compute-bound and memory-bound kernels.

``python benchmarks/bench_parallel.py [--json F] [--quick]`` prints, same run, best of N:

1. a compute-bound shader-like kernel (two pow, exp2, log2, rsqrt per element) from 2^14 to 2^22
   elements: one thread, every thread with the split forced, and the default settings (which split
   by estimated work); the target is >= 1.8x on two idle cores once the call is large enough, and
   the default never slower than one thread;
2. the routines exp2 and pow (full) at 1M and 16M elements, which stream 8-12 bytes per element:
   bounded by memory bandwidth, compared with a plain two-thread memory copy;
3. the cost of a split itself: a trivial kernel on 64 elements, forced split against none.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import numpy as np  # noqa: E402

import reactor  # noqa: E402
import routines  # noqa: E402
from reactor import Float, kernel, kernel_of  # noqa: E402


def best(fn, reps):
    t = float("inf")
    for _ in range(reps):
        t0 = time.perf_counter()
        fn()
        t = min(t, time.perf_counter() - t0)
    return t


@kernel(name="bench_shader")
def shader(x: Float, y: Float) -> Float:
    """A shader-like body: a few transcendental calls per element, compute-bound."""
    a = routines.pow(x, y)
    b = routines.exp2(a * 0.001) + routines.log2(x + 1.0)
    c = routines.pow(b, 1.7) * routines.rsqrt(x * x + 1.0)
    return a + b + c


def timed(ufunc, operands, out, reps, threads, **split):
    reactor.configure_threads(threads=threads, **split)
    ufunc(*operands, out=out)
    return best(lambda: ufunc(*operands, out=out), reps)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--json")
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args(argv)
    saved = reactor.thread_settings()
    cores = saved.threads
    reps = 5 if args.quick else 15
    rng = np.random.default_rng(0)
    out = {"cores": cores, "defaults": saved._asdict(), "shader": [], "routines": []}
    print(f"{cores} threads; defaults: split from {saved.threshold} elements and {saved.min_work} estimated "
          f"cycles; shader estimated {kernel_of(shader).cycles_per_element:.2f} cycles/element")
    try:
        for n in [2 ** k for k in range(14, 23, 2)]:
            x = rng.uniform(0.1, 10, n).astype(np.float32)
            y = rng.uniform(-3, 3, n).astype(np.float32)
            o = np.empty_like(x)
            one = timed(shader, (x, y), o, reps, 1)
            forced = timed(shader, (x, y), o, reps, cores, threshold=1, min_work=0)
            default = timed(shader, (x, y), o, reps, cores, threshold=saved.threshold, min_work=saved.min_work)
            row = dict(n=n, one_ms=one * 1e3, forced_ms=forced * 1e3, default_ms=default * 1e3,
                       forced_speedup=one / forced, default_speedup=one / default)
            out["shader"].append(row)
            print(f"shader n={n:>8d}  1 thread {one * 1e3:8.3f} ms  split {forced * 1e3:8.3f} ms (x{one / forced:4.2f})"
                  f"  default {default * 1e3:8.3f} ms (x{one / default:4.2f})")
        for name in ("exp2", "pow"):
            ufunc = routines.jit(name)
            for n in (2 ** 20, 2 ** 24):
                x = rng.uniform(0.5, 8, n).astype(np.float32)
                o = np.empty_like(x)
                operands = (x, x) if name == "pow" else (x,)
                one = timed(ufunc, operands, o, reps, 1)
                forced = timed(ufunc, operands, o, reps, cores, threshold=1, min_work=0)
                half = n // 2

                def copy2():
                    t = threading.Thread(target=np.copyto, args=(o[half:], x[half:]))
                    t.start()
                    np.copyto(o[:half], x[:half])
                    t.join()
                copy = best(lambda: np.copyto(o, x), reps) / best(copy2, reps)
                out["routines"].append(dict(function=name, n=n, one_ms=one * 1e3, split_ms=forced * 1e3,
                                            speedup=one / forced, memcpy_speedup=copy))
                print(f"{name:5s} n={n:>8d}  1 thread {one * 1e3:8.3f} ms  split {forced * 1e3:8.3f} ms "
                      f"(x{one / forced:4.2f}; a two-thread memcpy: x{copy:4.2f})")
        tiny = kernel(lambda x: x + 1.0, args=[Float], returns=Float, name="bench_tiny")
        x = np.ones(64, np.float32)
        o = np.empty_like(x)
        plain = timed(tiny, (x,), o, 200, 1)
        split = timed(tiny, (x,), o, 200, cores, threshold=1, min_work=0)
        out["split_cost_us"] = (split - plain) * 1e6
        print(f"cost of a split (threads started and joined): {(split - plain) * 1e6:.1f} us")
    finally:
        reactor.configure_threads(**saved._asdict())
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
