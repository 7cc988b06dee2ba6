"""The cost of the execution mask: per-lane control flow against the same computation with Select.

``python benchmarks/bench_masks.py [--json F] [--n N]`` prints, same run, one thread, best of N,
the time per element of pairs of kernels that compute the same result, one written with per-lane
``If``/``Else`` (or ``While``/``Break``) and one with ``Select`` (or a hand-masked loop):

1. ``If``/``Elif``/``Else`` assigning a Variable, against nested ``Select`` (target <= 1.1x), and a
   lighting-like ``If``/``Else`` (diffuse and specular on the lit side, a rim term on the other);
2. an ``If`` guarding an expensive branch that few lanes take (``pow``), against ``Select`` that
   computes it everywhere: the mask skips blocks no lane enters, so this ratio is below 1;
3. a ``While`` whose lanes leave at different steps, against the hand-written form (an active
   mask, ``Select`` on every loop-carried variable and ``While(Any(...))``).
Each pair is checked to give the same bits before it is timed.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import numpy as np  # noqa: E402

import reactor  # noqa: E402
import routines  # noqa: E402
from reactor import Any, Elif, Else, Float, If, Select, Variable, While, kernel  # noqa: E402


def best(fn, reps):
    t = float("inf")
    for _ in range(reps):
        t0 = time.perf_counter()
        fn()
        t = min(t, time.perf_counter() - t0)
    return t


@kernel
def branches_if(x: Float) -> Float:
    y = Variable(Float, 0.0)
    with If(x < 0.25):
        y.set(x * x + 1.0)
    with Elif(x < 0.75):
        y.set(x * 0.5 - 2.0)
    with Else():
        y.set(3.0 - x)
    return y


@kernel
def branches_select(x: Float) -> Float:
    return Select(x < 0.25, x * x + 1.0, Select(x < 0.75, x * 0.5 - 2.0, 3.0 - x))


@kernel
def shading_if(x: Float, y: Float) -> Float:
    c = Variable(Float, 0.05)  # ambient
    nl = x * 0.6 + y * 0.8
    with If(nl > 0.0):  # lit side: diffuse and a specular lobe
        h = routines.rsqrt(x * x + y * y + 1.0)
        spec = (nl * h) * (nl * h)
        spec = spec * spec * spec
        c += nl * 0.7 + spec * 0.25
    with Else():  # back side: a rim term
        c += (1.0 + nl) * 0.1
    return c


@kernel
def shading_select(x: Float, y: Float) -> Float:
    nl = x * 0.6 + y * 0.8
    h = routines.rsqrt(x * x + y * y + 1.0)
    spec = (nl * h) * (nl * h)
    spec = spec * spec * spec
    return Select(nl > 0.0, 0.05 + (nl * 0.7 + spec * 0.25), 0.05 + (1.0 + nl) * 0.1)


@kernel
def rare_if(x: Float) -> Float:
    y = Variable(x)
    with If(x > 0.999):
        y.set(routines.pow(x, 7.5) + routines.exp2(x) * routines.log2(x))
    return y


@kernel
def rare_select(x: Float) -> Float:
    return Select(x > 0.999, routines.pow(x, 7.5) + routines.exp2(x) * routines.log2(x), x)


@kernel
def steps_while(x: Float) -> Float:
    v = Variable(x)
    n = Variable(Float, 0.0)
    with While(lambda: v > 1.0):
        v.set(v * 0.75)
        n += 1.0
    return n


@kernel
def steps_masked(x: Float) -> Float:
    v = Variable(x)
    n = Variable(Float, 0.0)
    with While(lambda: Any(v > 1.0)):
        active = v > 1.0
        v.set(Select(active, v * 0.75, v))
        n.set(Select(active, n + 1.0, n))
    return n


PAIRS = [
    ("If/Elif/Else vs nested Select", branches_if, branches_select, lambda r: r.uniform(0, 1, R.n)),
    ("shading If/Else vs Select", shading_if, shading_select, lambda r: r.uniform(-1, 1, (2, R.n))),
    ("rare If (0.1% of lanes) vs Select", rare_if, rare_select, lambda r: r.uniform(0, 1, R.n)),
    ("While per lane vs hand-masked", steps_while, steps_masked, lambda r: r.uniform(0, 64, R.n)),
]


class R:
    n = 1 << 20


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--json")
    parser.add_argument("--n", type=int, default=1 << 20)
    parser.add_argument("--reps", type=int, default=30)
    args = parser.parse_args(argv)
    R.n = args.n
    saved = reactor.thread_settings()
    reactor.configure_threads(threads=1)
    rng = np.random.default_rng(1)
    rows = []
    try:
        print(f"{R.n} elements, one thread, best of {args.reps} (ns per element)")
        print(f"{'pair':<36} {'per-lane':>9} {'Select':>9} {'ratio':>7}")
        for label, masked, selected, data in PAIRS:
            x = data(rng).astype(np.float32)
            ops = list(x) if x.ndim == 2 else [x]
            a, b = masked(*ops), selected(*ops)
            assert np.array_equal(a.view(np.uint32), b.view(np.uint32)), f"{label}: results differ"
            out = np.empty_like(ops[0])
            ta = tb = float("inf")
            for _ in range(3):  # interleaved rounds: the ratio is of the same moments
                ta = min(ta, best(lambda: masked(*ops, out=out), args.reps // 3))
                tb = min(tb, best(lambda: selected(*ops, out=out), args.reps // 3))
            rows.append({"pair": label, "per_lane_ns": ta / R.n * 1e9, "select_ns": tb / R.n * 1e9,
                         "ratio": ta / tb})
            print(f"{label:<36} {ta / R.n * 1e9:9.3f} {tb / R.n * 1e9:9.3f} {ta / tb:7.3f}")
    finally:
        reactor.configure_threads(**saved._asdict())
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)
    return rows


if __name__ == "__main__":
    main()
