"""Uniform work out of the vector loop (reactor.ir.hoist), measured: each kernel built with its
uniform work split off and without (``reactor.kernels.loop.UNIFORM_WORK``), same run, one thread.

    python benchmarks/bench_uniform.py [--n 65536] [--shaders 1024]

Kernels ``x * f(t)`` with ``t`` a broadcast scalar: time over ``x * c`` (the floor: one multiply),
without and with the split, and with ``t`` an array (the split's cost when nothing is broadcast).
With ``--shaders N``: the example shaders (examples/shaders) at N x N, without over with, as the
examples call them (their uniforms are scalars), and whether the bits are the same.
"""
from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

import reactor
from reactor import Float
from reactor.kernels import kernel as kernel_module
from reactor.kernels import loop
from routines import glsl as gl

HERE = os.path.dirname(os.path.abspath(__file__))
CASES = {
    "x * exp2(t * 0.3)": lambda x, t: x * gl.exp2(t * 0.3),
    "x * log2(t) + pow(t, 1.7)": lambda x, t: x * gl.log2(t) + gl.pow(t, 1.7),
    "x * normalize(vec3(t, 1, 2)).y": lambda x, t: x * gl.normalize(reactor.vec3(t, 1.0, 2.0)).y,
    "x * cos(t * 0.3)": lambda x, t: x * gl.cos(t * 0.3),
}


def both(build):
    """``build()`` with the uniform work split off and without: {True: kernel, False: kernel}."""
    made = {}
    for flag in (False, True):
        previous, loop.UNIFORM_WORK = loop.UNIFORM_WORK, flag
        try:
            kernel_module._memo.clear()
            made[flag] = build()
        finally:
            loop.UNIFORM_WORK = previous
    return made


def best_ms(fn, args, repeat: int) -> float:
    fn(*args)
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn(*args)
        times.append(time.perf_counter() - start)
    return min(times) * 1e3


def kernels(n: int, repeat: int) -> None:
    x = np.random.default_rng(1).random(n, dtype=np.float32)
    t, ts = np.float32(0.7), np.random.default_rng(2).random(n, dtype=np.float32) + 0.5
    floor = reactor.kernel(lambda a, c: a * c, args=[Float, Float], returns=Float, cache=False)
    print(f"{n:,} float32, one thread; times over x * c (the floor)")
    print(f"{'kernel':34} {'without':>8} {'with':>8} {'t an array: with/without':>26}")
    for name, body in CASES.items():
        made = both(lambda: reactor.kernel(body, args=[Float, Float], returns=Float, cache=False))
        assert np.array_equal(made[True](x, t), made[False](x, t), equal_nan=True)
        base = best_ms(floor, (x, t), repeat)
        off, on = (best_ms(made[f], (x, t), repeat) / base for f in (False, True))
        arrays = best_ms(made[True], (x, ts), repeat) / best_ms(made[False], (x, ts), repeat)
        print(f"{name:34} {off:7.2f}x {on:7.2f}x {arrays:25.2f}x")


def shaders(size: int, repeat: int) -> None:
    sys.path.insert(0, HERE)
    import bench_shaders
    print(f"\nexample shaders at {size} x {size}, one thread: without / with (above 1: the split is faster)")
    for name in bench_shaders.NAMES:
        example = bench_shaders.load_example(name)
        args = example.inputs(size)
        made = both(example.build)
        outs = [made[f](*args) for f in (False, True)]
        outs = [o if isinstance(o, tuple) else (o,) for o in outs]
        same = all(np.array_equal(a, b, equal_nan=True) for a, b in zip(*outs))
        off, on = (best_ms(made[f], args, repeat) for f in (False, True))
        print(f"  {name:9} {off:8.2f} ms {on:8.2f} ms  {off / on:.2f}x  same bits: {same}")


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=int, default=1 << 16)
    p.add_argument("--repeat", type=int, default=200)
    p.add_argument("--shaders", type=int, default=0, metavar="N", help="also the example shaders at N x N")
    args = p.parse_args(argv)
    reactor.configure_threads(threads=1)  # this script's own process: one thread throughout
    kernels(args.n, args.repeat)
    if args.shaders:
        shaders(args.shaders, max(3, args.repeat // 40))


if __name__ == "__main__":
    main()
