"""``python -m routines bench [--functions F ...] [--size N] [--rounds R] [--json F]``

Times every routine variant (function x precision x FMA, the natural SIMD
width) against NumPy's float32 ufunc (``np.exp2``, ``np.power``, ``np.sin``,
``np.arctan2``, ...) and, where installed, glibc libmvec's vector functions
at the host's widest level (``_ZGVeN16v_sinf`` with AVX-512, ``_ZGVdN8v_sinf``
with AVX2, ...) and SLEEF's (``Sleef_sinf16_u10``, ``Sleef_sinf8_u10``, ...),
on the same inputs, in one process, interleaving the candidates round by
round and keeping each one's best round, so a noisy shared machine slows all
of them alike. Prints ns/element and the speed-up over NumPy; a peer whose
library or symbol is missing is listed as absent. The full comparison,
accuracy included, is ``python -m routines report``.
"""
from __future__ import annotations

import json
import os
import time

import numpy as np

from .. import jit
from ..base import PRECISIONS
from ..perf import peers as peers_mod, timing
from . import parser as command_parser, positive_int

NUMPY = {
    "exp2": lambda x, out: np.exp2(x, out=out), "exp": lambda x, out: np.exp(x, out=out),
    "log2": lambda x, out: np.log2(x, out=out), "log": lambda x, out: np.log(x, out=out),
    "pow": lambda x, y, out: np.power(x, y, out=out), "sqrt": lambda x, out: np.sqrt(x, out=out),
    "rcp": lambda x, out: np.divide(1.0, x, out=out),
    "rsqrt": lambda x, out: np.divide(1.0, np.sqrt(x, out=out), out=out),
    "sin": np.sin, "cos": np.cos, "tan": np.tan, "asin": np.arcsin, "acos": np.arccos,
    "atan": np.arctan, "atan2": np.arctan2, "sinh": np.sinh, "cosh": np.cosh, "tanh": np.tanh,
}
#: Every routine: exp2 log2 pow exp log rcp rsqrt sqrt, then sin ... tanh and atan2.
DEFAULT_FUNCTIONS = ("exp2", "log2", "pow", "exp", "log", "rcp", "rsqrt", "sqrt",
                     "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh")
#: Names that stand for several functions in ``--functions`` (the report's too).
GROUPS = {"trig": peers_mod.TRIG, "all": DEFAULT_FUNCTIONS}


def expand(names, groups=None) -> list[str]:
    """``--functions`` with the groups (default :data:`GROUPS`) replaced by their functions,
    in order, each once."""
    groups = GROUPS if groups is None else groups
    out: list[str] = []
    for name in names:
        for f in groups.get(name, (name,)):
            if f not in out:
                out.append(f)
    return out


#: The peer families timed beside NumPy (numba is in the report only: its JIT is slow to build).
PEER_FAMILIES = ("libmvec", "sleef")


def inputs(name: str, n: int, seed: int = 1):
    """Typical arguments (the report's, :func:`routines.perf.timing.inputs`): exp inputs and
    the angles of sin/cos/tan/atan/sinh/cosh/tanh in [-10, 10], log/pow bases in (0, 100],
    asin/acos in [-1, 1], atan2's y and x in [-10, 10]."""
    return timing.inputs(name, n, seed)


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


def run(functions=DEFAULT_FUNCTIONS, size: int = 65536, rounds: int = 7, libraries: dict | None = None):
    """One row per candidate: our variants, NumPy, and the libmvec/SLEEF peers (absent ones
    with ``ns_per_element`` None and the reason). ``libraries`` overrides peer library names."""
    rows = []
    for name in functions:
        args = inputs(name, size)
        out = np.empty(size, np.float32)
        cands = {"numpy": (NUMPY[name], args, out)}
        family = {"numpy": "numpy"}
        for precision in PRECISIONS:
            for fma in (True, False):
                key = f"{precision} fma={'on' if fma else 'off'}"
                cands[key], family[key] = (jit(name, precision, fma), args, out), f"ours {precision}"
        absent = []
        for p in peers_mod.peers([name], libraries, families=PEER_FAMILIES):
            key = " ".join(w for w in p.key.split() if w != name)  # "libmvec", "sleef u10", "sleef fastsin u3500"
            if p.present:
                cands[key], family[key] = (p.fn, args, out), p.family
            else:
                absent.append({"function": name, "variant": key, "family": p.family, "label": p.label,
                               "ns_per_element": None, "speedup_vs_numpy": None, "absent": p.reason})
        with np.errstate(all="ignore"):
            best = time_all(cands, size, rounds)
        for key, ns in best.items():
            rows.append({"function": name, "variant": key, "family": family[key], "ns_per_element": ns,
                         "speedup_vs_numpy": best["numpy"] / ns})
        rows += absent
    return rows


def table(rows) -> str:
    """The rows as text: ns/element and the speed-up over NumPy, absent peers with the reason."""
    lines = [f"{'function':8s} {'variant':22s} {'ns/elem':>9s} {'vs numpy':>9s}"]
    for r in rows:
        if r.get("absent"):
            lines.append(f"{r['function']:8s} {r['variant']:22s} absent: {r['absent']}")
        else:
            lines.append(f"{r['function']:8s} {r['variant']:22s} {r['ns_per_element']:9.4f} "
                         f"{r['speedup_vs_numpy']:8.2f}x")
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    parser = command_parser("bench", __doc__, ("", "--functions exp2 pow --size 4096 --rounds 3",
                                               "--functions trig", "--json out/bench.json"))
    parser.add_argument("--size", type=positive_int, metavar="N", default=65536,
                        help="elements per call (default 64K)")
    parser.add_argument("--rounds", type=positive_int, metavar="N", default=7,
                        help="interleaved rounds; each candidate keeps its best (default 7)")
    parser.add_argument("--functions", nargs="+", default=list(DEFAULT_FUNCTIONS),
                        choices=DEFAULT_FUNCTIONS + tuple(GROUPS), metavar="F",
                        help=f"functions to time (default all: {' '.join(DEFAULT_FUNCTIONS)}; "
                             f"trig: {' '.join(GROUPS['trig'])})")
    parser.add_argument("--json", metavar="FILE", help="also write the rows as JSON")
    args = parser.parse_args(argv)
    if args.json:
        os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
    rows = run(expand(args.functions), args.size, args.rounds)
    print(table(rows))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"size": args.size, "rows": rows}, f, indent=1)
    return 0
