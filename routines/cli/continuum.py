"""``python -m routines continuum``: the precision continuum's variants, measured on the compiled code.

For exp2, exp, log2, log, pow, sin, cos, tan, atan, asin, acos, sinh, cosh and tanh, each variant of ``routines.continuum`` between relaxed and full
(and both tiers, for comparison) is built with ``routines.jit`` and measured, same run:

* **error** against float64 NumPy on a stated domain, every float32 in it: exp2 and exp, ULP of
  the float32 result for 1/2 <= |x| < 8; sinh, cosh and tanh, ULP for every 7th float32 of 2^-20
  <= |x| <= 10; log2 and log, the largest absolute error for 1/16 <= x
  < 16 (their error is absolute near their zero) and ULP where |result| >= 1; pow, ULP for every
  16th float32 x in [1/16, 16) and y in {2.2, 1/2.2, 2.4, 1/2.4}; sin and cos, the largest absolute
  error (Vulkan's bound for them is absolute) and tan the largest relative error, for every 7th float32
  of 2^-20 <= |x| <= pi; atan, asin and acos, ULP for every 7th float32 of 2^-20 <= |x| <= 4 (atan) or
  1;
* **modelled cost**: cycles per element of the vector loop (``reactor.cost``, this host's table);
* **time**: ns per element on 65,536 elements, one thread, median of ``--rounds`` calls
  interleaved across the variants, and the ratio to full.

``--markdown`` prints the table as Markdown (docs/plan.md has this host's).
"""
from __future__ import annotations

import time

import numpy as np

from . import add_quiet, choice_of
from . import parser as command_parser

FUNCS = ("exp2", "exp", "log2", "log", "pow", "sin", "cos", "tan", "atan", "asin", "acos", "sinh", "cosh", "tanh")
POW_Y = (2.2, 1 / 2.2, 2.4, 1 / 2.4)


def _floats(lo: float, hi: float, step: int = 1) -> np.ndarray:
    """Every ``step``-th float32 in [lo, hi) (lo, hi > 0)."""
    a, b = np.float32(lo).view(np.int32), np.float32(hi).view(np.int32)
    return np.arange(a, b, step, dtype=np.int32).view(np.float32)


def _ulp(got: np.ndarray, want: np.ndarray) -> float:
    """The largest error in float32 ULP (of the exact result's binade)."""
    want = want.astype(np.float64)
    ulp = np.ldexp(1.0, np.frexp(np.abs(want))[1] - 24)
    return float(np.max(np.abs(got.astype(np.float64) - want) / ulp))


def error(name: str, u) -> str:
    """The error of ufunc ``u`` computing ``name`` on its stated domain (module docstring)."""
    with np.errstate(all="ignore"):
        if name in ("exp2", "exp"):
            pos = _floats(0.5, 8.0)
            x = np.concatenate([pos, -pos])
            want = np.exp2(x.astype(np.float64)) if name == "exp2" else np.exp(x.astype(np.float64))
            return f"{_ulp(u(x), want):.3g} ULP"
        if name in ("log2", "log"):
            x = _floats(1 / 16, 16.0)
            want = np.log2(x.astype(np.float64)) if name == "log2" else np.log(x.astype(np.float64))
            got = u(x).astype(np.float64)
            big = np.abs(want) >= 1
            return f"{np.max(np.abs(got - want)):.2g} abs, {_ulp(got[big], want[big]):.3g} ULP"
        if name in ("sin", "cos", "tan"):
            half = _floats(2.0 ** -20, float(np.float32(np.pi)), 7)
            x = np.concatenate([half, -half])
            want = getattr(np, name)(x.astype(np.float64))
            err = np.abs(u(x).astype(np.float64) - want)
            if name == "tan":
                return f"{np.max(err / np.abs(want)):.3g} relative"
            return f"{np.max(err):.3g} abs"
        if name in ("atan", "asin", "acos", "sinh", "cosh", "tanh"):
            half = _floats(2.0 ** -20, {"atan": 4.0, "asin": 1.0, "acos": 1.0}.get(name, 10.0), 7)
            x = np.concatenate([half, -half])
            fn = getattr(np, name if name.endswith("h") else "arc" + name[1:])
            return f"{_ulp(u(x), fn(x.astype(np.float64))):.3g} ULP"
        x = _floats(1 / 16, 16.0, 16)
        worst = 0.0
        for y in POW_Y:
            yy = np.full_like(x, y)
            worst = max(worst, _ulp(u(x, yy), np.power(x.astype(np.float64), float(np.float32(y)))))
        return f"{worst:.3g} ULP"


def rows(name: str, rounds: int) -> list[dict]:
    """Every variant of ``name`` (relaxed, the continuum, full), measured (module docstring)."""
    import reactor
    import routines
    from reactor.cost import kernel_cycles
    from routines import continuum

    names = ["relaxed", *continuum.VARIANTS[name], "full"]
    ufuncs = {p: routines.jit(name, precision=p) for p in names}
    reactor.configure_threads(threads=1)
    rng = np.random.default_rng(7)
    x = rng.uniform(0.05, 0.95 if name in ("asin", "acos") else 4.0, 1 << 16).astype(np.float32)
    args = (x, np.full_like(x, 2.2)) if name == "pow" else (x,)
    out = np.empty_like(x)
    times: dict[str, list[float]] = {p: [] for p in names}
    for _ in range(rounds):
        for p, u in ufuncs.items():
            t0 = time.perf_counter()
            u(*args, out=out)
            times[p].append(time.perf_counter() - t0)
    full_ns = np.median(times["full"]) / x.size * 1e9
    found = []
    for p, u in ufuncs.items():
        ns = float(np.median(times[p]) / x.size * 1e9)
        found.append({"function": name, "variant": p, "error": error(name, u),
                      "cycles": float(kernel_cycles(reactor.kernel_of(u))), "ns": ns, "vs_full": ns / full_ns})
    return found


def markdown(found: list[dict]) -> str:
    lines = ["| function | variant | error (stated domain) | modelled cycles/element | ns/element | time / full |",
             "|---|---|---|---|---|---|"]
    lines += [f"| {r['function']} | {r['variant']} | {r['error']} | {r['cycles']:.2f} | {r['ns']:.3f} | "
              f"{r['vs_full']:.2f} |" for r in found]
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    p = command_parser("continuum", __doc__, ("exp2 log2", "pow --markdown"))
    p.add_argument("functions", nargs="*", type=choice_of(FUNCS), metavar="F",
                   help=f"any of {', '.join(FUNCS)} (default: all)")
    p.add_argument("--rounds", type=int, default=21, help="timed calls per variant (default %(default)s)")
    p.add_argument("--markdown", action="store_true", help="print a Markdown table")
    add_quiet(p)
    args = p.parse_args(argv)
    found = []
    for name in args.functions or FUNCS:
        found += rows(name, args.rounds)
        if not args.markdown:
            for r in (r for r in found if r["function"] == name):
                print(f"{r['function']:5s} {r['variant']:11s} {r['error']:28s} {r['cycles']:6.2f} cycles "
                      f"{r['ns']:7.3f} ns/element  x{r['vs_full']:.2f}", flush=True)
    if args.markdown:
        print(markdown(found))
    return 0
