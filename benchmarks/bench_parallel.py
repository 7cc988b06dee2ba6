"""Multi-core kernels: one thread against all, by size, for compute-bound and memory-bound kernels.

``python benchmarks/bench_parallel.py [--json F] [--quick]`` prints, same run, best of N:

1. a compute-bound shader-like kernel (two pow, exp2, log2, rsqrt per element) from 2^14 to 2^22
   elements: one thread, every thread with the split forced, and the default settings (which split
   by estimated work); the target is >= 1.8x on two idle cores once the call is large enough, and
   the default never slower than one thread;
2. the routines exp2 and pow (full) at 1M and 16M elements, which stream 8-12 bytes per element:
   bounded by memory bandwidth, compared with a plain two-thread memory copy;
3. the cost of a split itself: a trivial kernel on 64 elements, forced split against none;
4. small calls: 4,096 elements of the trivial kernel, of the shader-like one and of the noise example
   (64 x 64 pixels), one thread, the split forced and the default settings (the default must never
   be slower than one thread);
5. the example shaders (examples/shaders) at ``--size`` (1024) squared, full precision: one thread
   against every thread, with flat operands (every input materialized at the image's shape) and,
   where the example passes them so, broadcast ones (a row and a column: NumPy hands those to the
   loop in 8,192-element buffers, each a split call of its own). Target: >= 1.85x on two idle cores.

6. where a split starts to pay (``breakeven``): the trivial kernel, exp2 and the shader-like one
   from 1,024 to 65,536 elements, one thread against a forced split, beside the estimated work.

``--only small,shaders`` runs some sections (``shader``, ``routines``, ``split``, ``small``,
``breakeven``, ``shaders``); one and two threads alternate, call after call, so that a ratio is of the same run.
"""
from __future__ import annotations

import argparse
import importlib.util
import json
import os
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
# OpenBLAS's threads spin after a BLAS call (the examples' inputs use some) and take a core from the split
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

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


def interleaved(call, settings: dict, reps: int) -> dict:
    """Best time of ``call()`` under each of ``settings`` (name -> configure_threads arguments),
    the settings taking turns call after call so that a shared machine's noise hits them alike."""
    times = {name: float("inf") for name in settings}
    for name, kw in settings.items():   # warm-up: workers started, code paged in
        reactor.configure_threads(**kw)
        call()
    for _ in range(reps):
        for name, kw in settings.items():
            reactor.configure_threads(**kw)
            t0 = time.perf_counter()
            call()
            times[name] = min(times[name], time.perf_counter() - t0)
    return times


def small_calls(cores, saved, reps):
    """4,096-element calls: the trivial kernel, the shader-like one and the noise example (64 x 64),
    one thread, forced split and default settings (microseconds)."""
    rows = []
    tiny = kernel(lambda x: x + 1.0, args=[Float], returns=Float, name="bench_tiny4k")
    rng = np.random.default_rng(1)
    x = rng.uniform(0.1, 10, 4096).astype(np.float32)
    y = rng.uniform(-3, 3, 4096).astype(np.float32)
    o = np.empty_like(x)
    settings = {"one": dict(threads=1), "forced": dict(threads=cores, threshold=1, min_work=0),
                "default": dict(threads=cores, threshold=saved.threshold, min_work=saved.min_work)}
    noise = load_example("noise")
    cases = [("x + 1", tiny, (x,), dict(out=o)), ("shader", shader, (x, y), dict(out=o)),
             ("noise", noise.build("full"), flat(noise.inputs(64)), {})]  # a 64 x 64 image
    for name, ufunc, operands, kw in cases:
        t = interleaved(lambda: ufunc(*operands, **kw), settings, reps)
        row = {"kernel": name, "n": 4096, **{f"{k}_us": v * 1e6 for k, v in t.items()},
               "forced_speedup": t["one"] / t["forced"], "default_speedup": t["one"] / t["default"]}
        rows.append(row)
        print(f"n=4096 {name:7s} 1 thread {row['one_us']:8.2f} us  split {row['forced_us']:8.2f} us "
              f"(x{row['forced_speedup']:4.2f})  default {row['default_us']:8.2f} us (x{row['default_speedup']:4.2f})")
    return rows


def breakeven(cores, reps):
    """Where a split starts to pay: three kernels from 1,024 to 65,536 elements, one thread
    against a forced split, beside the call's estimated work (what ``min_work`` is compared with)."""
    rows = []
    tiny = kernel(lambda x: x + 1.0, args=[Float], returns=Float, name="bench_tiny_sweep")
    rng = np.random.default_rng(2)
    settings = {"one": dict(threads=1), "forced": dict(threads=cores, threshold=1, min_work=0)}
    for name, ufunc, arity in (("x + 1", tiny, 1), ("exp2", routines.jit("exp2"), 1), ("shader", shader, 2)):
        cycles = kernel_of(ufunc).cycles_per_element if name != "exp2" else None
        for n in [2 ** k for k in range(10, 17)]:
            operands = tuple(rng.uniform(0.1, 10, n).astype(np.float32) for _ in range(arity))
            o = np.empty(n, np.float32)
            t = interleaved(lambda: ufunc(*operands, out=o), settings, reps)
            row = dict(kernel=name, n=n, one_us=t["one"] * 1e6, forced_us=t["forced"] * 1e6,
                       speedup=t["one"] / t["forced"], estimated_cycles=None if cycles is None else n * cycles)
            rows.append(row)
            work = "" if cycles is None else f"  estimated {n * cycles:10,.0f} cycles"
            print(f"{name:7s} n={n:>6d}  1 thread {row['one_us']:9.2f} us  split {row['forced_us']:9.2f} us "
                  f"(x{row['speedup']:4.2f}){work}", flush=True)
    return rows


EXAMPLES = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "examples", "shaders")
SHADERS = ("gltf_pbr", "noise", "raymarch", "tonemap", "sky")


def load_example(name: str):
    """examples/shaders/<name>.py as a module."""
    if EXAMPLES not in sys.path:
        sys.path.insert(0, EXAMPLES)
    spec = importlib.util.spec_from_file_location(f"bench_parallel_{name}", os.path.join(EXAMPLES, f"{name}.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def flat(args):
    """The arguments with every array broadcast to the common shape and made contiguous."""
    arrays = [a for a in args if isinstance(a, np.ndarray) and a.ndim]
    shape = np.broadcast_shapes(*(a.shape for a in arrays))
    return tuple(np.ascontiguousarray(np.broadcast_to(a, shape)) if isinstance(a, np.ndarray) and a.ndim else a
                 for a in args)


def _concurrent(call, reps: int) -> float:
    """Best time of two one-thread calls run at once by two Python threads: what the machine
    gives two threads now (a shared machine's two vCPUs are not always two cores), the ceiling
    of the split's ratio."""
    reactor.configure_threads(threads=1)

    def both():
        other = threading.Thread(target=call)
        other.start()
        call()
        other.join()
    both()
    return best(both, reps)


def machine_check(reps: int = 5) -> float:
    """How much two threads get now: two one-thread calls of the shader-like kernel (2^18
    elements) at once against one, as a speedup (2.0: two free cores)."""
    rng = np.random.default_rng(3)
    x, y = (rng.uniform(0.1, 10, 2 ** 18).astype(np.float32) for _ in range(2))
    o1, o2 = np.empty_like(x), np.empty_like(x)
    reactor.configure_threads(threads=1)
    one = best(lambda: shader(x, y, out=o1), reps)
    two = _concurrent(lambda: shader(x, y, out=o2 if threading.current_thread() is threading.main_thread()
                                     else o1), reps)
    speed = 2 * one / two
    print(f"-- machine now: two one-thread calls at once run x{speed:4.2f} as fast as one after the other", flush=True)
    return speed


def pixels(args) -> int:
    """Elements of the arguments' broadcast shape."""
    return int(np.prod(np.broadcast_shapes(*(a.shape for a in args if isinstance(a, np.ndarray)))))


def shader_scaling(cores, size, reps):
    """Each example shader at ``size``: one thread against ``cores``, flat and broadcast operands."""
    rows = []
    for name in SHADERS:
        ex = load_example(name)
        k = ex.build("full")
        given = tuple(ex.inputs(size))
        layouts = {"flat": flat(given)}
        if any(isinstance(a, np.ndarray) and a.ndim and not a.flags.c_contiguous or
               isinstance(a, np.ndarray) and a.ndim and a.shape != layouts["flat"][0].shape for a in given):
            layouts["broadcast"] = given
        for layout, args in layouts.items():
            t = interleaved(lambda: k(*args), {"one": dict(threads=1), "all": dict(threads=cores)}, reps)
            two = _concurrent(lambda: k(*args), reps)
            row = dict(shader=name, layout=layout, pixels=pixels(args), one_ms=t["one"] * 1e3, all_ms=t["all"] * 1e3,
                       speedup=t["one"] / t["all"], two_calls_ms=two * 1e3, machine=2 * t["one"] / two)
            rows.append(row)
            print(f"{name:9s} {layout:9s} {row['pixels']:>8d} px  1 thread {row['one_ms']:8.3f} ms  "
                  f"{cores} threads {row['all_ms']:8.3f} ms  x{row['speedup']:4.2f}   (two 1-thread calls at once: "
                  f"x{row['machine']:4.2f})", flush=True)
    return rows


def shader_sizes(out, cores, saved, reps, rng):
    """Section 1: the shader-like kernel from 2^14 to 2^22 elements."""
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


def routine_streams(out, cores, reps, rng):
    """Section 2: exp2 and pow at 1M and 16M elements beside a two-thread memory copy."""
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


def split_cost(out, cores):
    """Section 3: a trivial kernel on 64 elements, forced split against none."""
    tiny = kernel(lambda x: x + 1.0, args=[Float], returns=Float, name="bench_tiny")
    x = np.ones(64, np.float32)
    o = np.empty_like(x)
    t = interleaved(lambda: tiny(x, out=o), {"one": dict(threads=1),
                                             "split": dict(threads=cores, threshold=1, min_work=0)}, 2000)
    out["split_cost_us"] = (t["split"] - t["one"]) * 1e6
    print(f"cost of a split (64 elements, forced): {out['split_cost_us']:.2f} us "
          f"({t['one'] * 1e6:.2f} us without)")


SECTIONS = ("shader", "routines", "split", "small", "breakeven", "shaders")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--json")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--size", type=int, default=1024, help="the example shaders' image size")
    parser.add_argument("--only", default="", help="comma-separated sections: " + ", ".join(SECTIONS))
    args = parser.parse_args(argv)
    sections = [s for s in args.only.split(",") if s] or list(SECTIONS)
    saved = reactor.thread_settings()
    cores = saved.threads
    reps = 5 if args.quick else 15
    rng = np.random.default_rng(0)
    out = {"cores": cores, "defaults": saved._asdict(), "shader": [], "routines": []}
    print(f"{cores} threads; defaults: split from {saved.threshold} elements and {saved.min_work} estimated "
          f"cycles; shader estimated {kernel_of(shader).cycles_per_element:.2f} cycles/element")
    out["machine"] = []
    try:
        out["machine"].append(machine_check())
        if "shader" in sections:
            shader_sizes(out, cores, saved, reps, rng)
        if "routines" in sections:
            routine_streams(out, cores, reps, rng)
        if "split" in sections:
            split_cost(out, cores)
        if "small" in sections:
            out["small"] = small_calls(cores, saved, 200 if args.quick else 1000)
            out["machine"].append(machine_check())
        if "breakeven" in sections:
            out["breakeven"] = breakeven(cores, 50 if args.quick else 300)
            out["machine"].append(machine_check())
        if "shaders" in sections:
            out["shaders"] = shader_scaling(cores, args.size, reps)
    finally:
        reactor.configure_threads(**saved._asdict())
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
