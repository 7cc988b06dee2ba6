"""``python -m routines hardcases``: the correct tier's tables of hard cases (``routines.correct``).

For each function, every float32 input whose exact result lies within 2^-46 relative of a
float32 rounding boundary (``routines.correct.NEAR``), with its correctly rounded result
(mpmath at 50 digits), found by an exhaustive sweep of the correctly rounded reference
(``routines.lab.rounding``) and written to ``routines/hard_cases/<F>.npy`` as int32 pairs
(input bits, result bits). The tables depend on the function alone, not on its code: a
routine of the correct tier whose float64 evaluation is within 2^-49 needs nothing else.
"""
from __future__ import annotations

import time

from . import add_quiet, choice_of
from . import parser as command_parser

FUNCS = ("sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh")


def main(argv: list[str]) -> int:
    p = command_parser("hardcases", __doc__, ("sin cos", ""))
    p.add_argument("functions", nargs="*", type=choice_of(FUNCS), metavar="F",
                   help=f"any of {', '.join(FUNCS)} (default: all)")
    add_quiet(p)
    args = p.parse_args(argv)

    import numpy as np
    from tqdm import tqdm

    from ..correct import NEAR, TABLES
    from ..lab import rounding

    TABLES.mkdir(exist_ok=True)
    for func in args.functions or FUNCS:
        t0 = time.perf_counter()
        with tqdm(total=2 ** 32, unit="in", unit_scale=True, disable=None if not args.quiet else True,
                  desc=func, leave=False) as bar:
            pairs = rounding.sweep_hard_cases(func, NEAR, progress=bar.update)
        np.save(TABLES / f"{func}.npy", pairs, allow_pickle=False)
        print(f"{func:5s} {len(pairs):6,d} hard cases  {time.perf_counter() - t0:.1f} s  "
              f"-> {TABLES.name}/{func}.npy", flush=True)
    return 0
