"""``python -m routines ladder``: the faithful and correct tiers, proved on the compiled code.

Each variant (function x tier x FMA on/off) runs on float32 inputs against a correctly
rounded reference, computed once per input for all the variants of a function (``routines.lab.rounding``): results not correctly rounded, max ULP-32,
subnormal results. By default every 256th bit pattern (2^24 inputs, every binade and sign);
``--exhaustive``: all 2^32. pow and atan2 run the stratified 2^30-pair sweep (every 16th
stratum by default) plus their hard pairs. Exit status 1 if a correct variant misrounds any
input or a faithful one errs by 1 ULP or more.
"""
from __future__ import annotations

import json
import pathlib

from . import add_quiet, choice_of
from . import parser as command_parser

FUNCS = ("exp2", "exp", "log2", "log", "rcp", "rsqrt", "sqrt", "pow", "sin", "cos", "tan", "asin", "acos",
         "atan", "atan2", "sinh", "cosh", "tanh")
PAIRS = ("pow", "atan2")


def main(argv: list[str]) -> int:
    p = command_parser("ladder", __doc__, ("exp2 log2 --exhaustive", "pow", "--fma on --precisions correct"))
    p.add_argument("functions", nargs="*", type=choice_of(FUNCS), metavar="F",
                   help=f"any of {', '.join(FUNCS)} (default: all)")
    p.add_argument("--precisions", nargs="+", choices=("faithful", "correct"), default=["faithful", "correct"])
    p.add_argument("--fma", nargs="+", choices=("on", "off"), default=["on", "off"])
    p.add_argument("--exhaustive", action="store_true", help="all 2^32 inputs (pow, atan2: all 256 strata)")
    p.add_argument("--json", default="out/ladder.json", help="where to write the results (default %(default)s)")
    p.add_argument("--table", action="store_true",
                   help="print the exhaustive results of --json as a Markdown table (no sweep)")
    add_quiet(p)
    args = p.parse_args(argv)
    if args.table:
        print(table(json.loads(pathlib.Path(args.json).read_text()), args.functions or FUNCS))
        return 0

    from tqdm import tqdm

    from .. import jit
    from ..base import tiers
    from ..lab import rounding as ladder

    failed = False
    results = []
    for func in args.functions or FUNCS:
        variants = {f"{precision} fma {fma}": jit(func, precision, fma=fma == "on")
                    for precision in args.precisions if precision in tiers(func) for fma in args.fma}
        if not variants:
            continue
        step = 1 if args.exhaustive else (16 if func in PAIRS else 256)
        total = (2 ** 30 if func in PAIRS else 2 ** 32) // step
        with tqdm(total=total, unit="in", unit_scale=True, disable=None if not args.quiet else True,
                  desc=f"{func} ({len(variants)} variants)", leave=False) as bar:
            swept = ladder.sweep_many(variants, func, step=step, progress=bar.update)
        for variant, r in swept.items():
            print(r.line(), flush=True)
            bad = r.misrounded if variant.startswith("correct") else int(r.max_ulp >= 1.0)
            failed |= bool(bad)
            results.append({**vars(r), "exhaustive": args.exhaustive, "step": step})
    out = pathlib.Path(args.json)
    out.parent.mkdir(parents=True, exist_ok=True)
    old = json.loads(out.read_text()) if out.exists() else []
    keep = [o for o in old if (o["func"], o["variant"], o["exhaustive"]) not in
            {(r["func"], r["variant"], r["exhaustive"]) for r in results}]
    out.write_text(json.dumps(keep + results, indent=1, default=str))
    return 1 if failed else 0


def table(rows: list[dict], functions) -> str:
    """The exhaustive rows of ``functions`` (in that order) as docs/accuracy-ladder.md's table."""
    head = ("| function | tier | FMA | inputs | not correctly rounded | max ULP-32 (at x) | "
            "subnormal results (wrong) | decided by mpmath | seconds (the variants swept together) |\n|---|---|---|---|---|---|---|---|---|")
    lines = [head]
    for func in functions:
        for r in sorted((r for r in rows if r["func"] == func and r["exhaustive"]), key=lambda r: r["variant"]):
            tier, _, fma = r["variant"].split()
            lines.append(f"| {func} | {tier} | {fma} | {r['inputs']:,d} | {r['misrounded']:,d} | "
                         f"{r['max_ulp']:.4f} ({r['max_ulp_at']:.9g}) | {r['subnormal_results']:,d} "
                         f"({r['subnormal_misrounded']:,d}) | {r['decided_by_mpmath']:,d} | {r['seconds']:.1f} |")
    return "\n".join(lines)
