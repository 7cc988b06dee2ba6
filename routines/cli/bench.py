"""``python -m routines bench [--size N] [--rounds R] [--json F]``

Times every routine variant (function x precision x FMA) against NumPy's
float32 ``exp2``/``log2``/``power`` (and ``exp``/``log``/``sqrt``/``1/x``) on the
same inputs, in one process, interleaving the candidates round by round and
keeping each one's best round, so a noisy shared machine slows all of them
alike. Prints ns/element and the speed-up over NumPy.
"""
from __future__ import annotations

import json
import os
import time

import numpy as np

from .. import jit
from ..base import PRECISIONS
from . import parser as command_parser, positive_int

NUMPY = {
    "exp2": lambda x, out: np.exp2(x, out=out), "exp": lambda x, out: np.exp(x, out=out),
    "log2": lambda x, out: np.log2(x, out=out), "log": lambda x, out: np.log(x, out=out),
    "pow": lambda x, y, out: np.power(x, y, out=out), "sqrt": lambda x, out: np.sqrt(x, out=out),
    "rcp": lambda x, out: np.divide(1.0, x, out=out),
    "rsqrt": lambda x, out: np.divide(1.0, np.sqrt(x, out=out), out=out),
}
DEFAULT_FUNCTIONS = ("exp2", "log2", "pow", "exp", "log", "rcp", "rsqrt", "sqrt")


def inputs(name: str, n: int, seed: int = 1):
    """Typical arguments: exp inputs in [-10, 10], log/pow bases in (0, 100]."""
    rng = np.random.default_rng(seed)
    x = rng.uniform(-10, 10, n).astype(np.float32)
    pos = rng.uniform(1e-3, 100, n).astype(np.float32)
    return {"exp2": (x,), "exp": (x,), "pow": (pos, x)}.get(name, (pos,))


def time_all(candidates: dict, n: int, rounds: int) -> dict[str, float]:
    """Best ns/element of each ``name -> (callable, args, out)`` over interleaved rounds."""
    reps = max(1, 2 ** 23 // n)
    best = {k: float("inf") for k in candidates}
    for _ in range(rounds):
        for key, (fn, args, out) in candidates.items():
            fn(*args, out=out)
            t0 = time.perf_counter()
            for _ in range(reps):
                fn(*args, out=out)
            best[key] = min(best[key], (time.perf_counter() - t0) / reps / n * 1e9)
    return best


def run(functions=DEFAULT_FUNCTIONS, size: int = 65536, rounds: int = 7):
    rows = []
    for name in functions:
        args = inputs(name, size)
        out = np.empty(size, np.float32)
        cands = {"numpy": (NUMPY[name], args, out)}
        for precision in PRECISIONS:
            for fma in (True, False):
                cands[f"{precision} fma={'on' if fma else 'off'}"] = (jit(name, precision, fma), args, out)
        with np.errstate(all="ignore"):
            best = time_all(cands, size, rounds)
        for key, ns in best.items():
            rows.append({"function": name, "variant": key, "ns_per_element": ns,
                         "speedup_vs_numpy": best["numpy"] / ns})
    return rows


def main(argv: list[str]) -> int:
    parser = command_parser("bench", __doc__, ("", "--functions exp2 pow --size 4096 --rounds 3",
                                               "--json out/bench.json"))
    parser.add_argument("--size", type=positive_int, metavar="N", default=65536,
                        help="elements per call (default 64K)")
    parser.add_argument("--rounds", type=positive_int, metavar="N", default=7,
                        help="interleaved rounds; each candidate keeps its best (default 7)")
    parser.add_argument("--functions", nargs="+", default=list(DEFAULT_FUNCTIONS), choices=DEFAULT_FUNCTIONS,
                        metavar="F", help=f"functions to time (default all: {' '.join(DEFAULT_FUNCTIONS)})")
    parser.add_argument("--json", metavar="FILE", help="also write the rows as JSON")
    args = parser.parse_args(argv)
    if args.json:
        os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
    rows = run(args.functions, args.size, args.rounds)
    print(f"{'function':8s} {'variant':20s} {'ns/elem':>9s} {'vs numpy':>9s}")
    for r in rows:
        print(f"{r['function']:8s} {r['variant']:20s} {r['ns_per_element']:9.4f} {r['speedup_vs_numpy']:8.2f}x")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"size": args.size, "rows": rows}, f, indent=1)
    return 0
