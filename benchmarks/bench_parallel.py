"""Multi-core scaling of a kernel: one thread against all, by array size.

``python benchmarks/bench_parallel.py [--function exp2] [--precision full] [--json F]``
prints, for sizes from 64K to 16M elements, the best time with one thread and
with every thread (the threshold forced to 1, so the split happens at every
size), the speed-up, and a plain two-thread memory copy for reference: at
16M elements the kernels stream 128-192 MB, so DRAM bandwidth bounds them.
"""
from __future__ import annotations

import argparse
import json
import threading
import time

import numpy as np

import routines
from reactor.kernels import parallel


def best(fn, reps=7):
    t = float("inf")
    for _ in range(reps):
        t0 = time.perf_counter()
        fn()
        t = min(t, time.perf_counter() - t0)
    return t


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--function", default="exp2", choices=routines.NAMES)
    parser.add_argument("--precision", default="full", choices=("full", "relaxed"))
    parser.add_argument("--json")
    args = parser.parse_args(argv)
    threads, threshold = parallel.settings()
    ufunc = routines.jit(args.function, args.precision)
    rows = []
    for n in [2 ** k for k in range(16, 25, 2)]:
        x = np.random.default_rng(n).uniform(0.5, 8, n).astype(np.float32)
        out = np.empty_like(x)
        operands = (x, x) if args.function == "pow" else (x,)
        parallel.configure(threads=1)
        one = best(lambda: ufunc(*operands, out=out))
        parallel.configure(threads=threads, threshold=1)
        many = best(lambda: ufunc(*operands, out=out))
        half = n // 2

        def copy2():
            t = threading.Thread(target=np.copyto, args=(out[half:], x[half:]))
            t.start()
            np.copyto(out[:half], x[:half])
            t.join()
        copy_one, copy_two = best(lambda: np.copyto(out, x)), best(copy2)
        rows.append(dict(n=n, one_thread_ms=one * 1e3, threads=threads, all_threads_ms=many * 1e3,
                         speedup=one / many, copy_speedup=copy_one / copy_two))
        print(f"n={n:>9d}  1 thread {one * 1e3:8.3f} ms  {threads} threads {many * 1e3:8.3f} ms  "
              f"x{one / many:4.2f}   (memcpy x{copy_one / copy_two:4.2f})")
    parallel.configure(threads=threads, threshold=threshold)
    print(f"default threshold: {threshold} elements")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
