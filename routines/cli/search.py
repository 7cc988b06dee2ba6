"""``python -m routines search``: the variant search (docs/search.md).

For a function and a precision target, generates candidate variants (form,
polynomial degree, Remez weight, evaluation order, conversion, FMA), builds
each as a routine, measures its error on the compiled code and its cost (the
dataflow model, plus a measured ns/element), and prints the Pareto set of
cost vs maximum Vulkan margin.

    python -m routines search exp2 --precision full [--quick] [--json out/search/exp2_full.json]

The JSON is a list of points (one per candidate) with the keys function,
precision, name, description, fma, cost_cycles_per_element, ns_per_element,
max_ulp32, max_margin, conforming, pareto and measured (how the error was
measured), and more (see docs/search.md).
"""
from __future__ import annotations

import json
import os
import sys
import time

from ..base import PRECISIONS
from . import ArgumentParser, add_quiet, parser as command_parser, positive_int


def _parser() -> ArgumentParser:
    p = command_parser("search", __doc__, ("exp2 --precision full --quick",
                                          "log2 --precision relaxed --json out/search/log2_relaxed.json",
                                          "all --precision all --workers 2 --retune"))
    p.add_argument("function", choices=("exp2", "log2", "all"))
    p.add_argument("--precision", choices=PRECISIONS + ("all",), default="full")
    p.add_argument("--quick", action="store_true",
                   help="fewer candidates, sampled errors only (~30 s); default: exhaustive "
                        "sweeps of the finalists and the Pareto set")
    p.add_argument("--retune", action="store_true",
                   help="also retune the best candidates' coefficients against the compiled "
                        "error (adds ~1-2 min per function and precision)")
    p.add_argument("--json", metavar="F", help="write the points as a JSON list to F")
    p.add_argument("--markdown", action="store_true", help="print the table as Markdown")
    p.add_argument("--all-points", action="store_true",
                   help="print every point, not just the Pareto set and production")
    p.add_argument("--workers", type=positive_int, metavar="N", default=1,
                   help="processes for exhaustive sweeps (default 1)")
    p.add_argument("--no-time", action="store_true", help="skip the ns/element timing")
    add_quiet(p, "no progress log on stderr")
    return p


def _f(v, digits: int) -> str:
    return f"{float(v):.{digits}f}" if isinstance(v, (int, float)) else str(v)


def _fmt_row(d: dict) -> list[str]:
    ns = "-" if d["ns_per_element"] is None else f"{d['ns_per_element']:.3f}"
    return [d["name"], "on" if d["fma"] else "off", f"{d['cost_cycles_per_element']:.4f}", ns,
            _f(d["max_ulp32"], 3), _f(d["max_margin"], 4),
            ("yes" if d["admissible"] else "yes, " + ", ".join(
                SHORT.get(k, k) for k, v in d["properties"].items() if not v))
            if d["conforming"] else "NO", "exh" if d["exhaustive"] else "sample",
            "*" if d["pareto"] else ""]


SHORT = {"monotone_on_random_adjacent_pairs_in_[-1,1)": "not monotone",
         "exact_at_integers": "not exact at integers",
         "exact_at_powers_of_two": "not exact at 2^k",
         "sign_correct_on_[1/2,2]": "wrong sign near 1"}
HEADER = ["variant", "FMA", "cycles/elem", "ns/elem", "max ULP-32", "max margin", "conforms",
          "error", "Pareto"]


def table(points: list[dict], markdown: bool = False) -> str:
    rows = [_fmt_row(d) for d in points]
    if markdown:
        out = ["| " + " | ".join(HEADER) + " |", "|" + "---|" * len(HEADER)]
        out += ["| " + " | ".join(r) + " |" for r in rows]
        return "\n".join(out)
    rows = [HEADER] + rows
    w = [max(len(r[i]) for r in rows) for i in range(len(HEADER))]
    lines = ["  ".join(c.ljust(w[i]) for i, c in enumerate(r)).rstrip() for r in rows]
    lines.insert(1, "-" * len(lines[0]))
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    args = _parser().parse_args(argv)
    from ..search.run import ULP_DOMAIN, CORE_LABEL, search

    funcs = ("exp2", "log2") if args.function == "all" else (args.function,)
    precs = PRECISIONS if args.precision == "all" else (args.precision,)
    log = (lambda s: None) if args.quiet else (lambda s: print(s, file=sys.stderr, flush=True))
    if args.json:  # before the search, not after it
        os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
    everything = []
    t_all = time.perf_counter()
    for func in funcs:
        for prec in precs:
            t0 = time.perf_counter()
            log(f"search {func} {prec}{' (quick)' if args.quick else ''}:")
            pts = search(func, prec, quick=args.quick, retune=args.retune, workers=args.workers,
                         time_it=not args.no_time, log=log)
            dicts = sorted((p.to_json() for p in pts),
                           key=lambda d: (d["cost_cycles_per_element"], float(d["max_margin"])))
            everything += dicts
            secs = time.perf_counter() - t0
            shown = dicts if args.all_points else [d for d in dicts if d["pareto"] or d["baseline"]]
            print(f"\n{func} ({prec}): {len(dicts)} candidates, {secs:.1f} s; "
                  f"{'every point' if args.all_points else 'Pareto set and production'}; "
                  f"max ULP-32 over {ULP_DOMAIN[func]}, margin over all inputs "
                  f"(core {CORE_LABEL[func]} {'sampled' if args.quick else 'exhaustive for these'})")
            print(table(shown, args.markdown))
            prod = next((d for d in dicts if d["baseline"] and d["fma"]), None)
            same = [d for d in dicts if d["admissible"] and not d["baseline"] and prod
                    and d["cost_cycles_per_element"] <= prod["cost_cycles_per_element"] + 1e-9]
            if prod and same:
                best = min(same, key=lambda d: float(d["max_margin"]))
                print(f"best at production's cost ({prod['cost_cycles_per_element']:.4f} c/e): "
                      f"{best['name']}: margin {best['max_margin']:.4f}, ULP-32 {best['max_ulp32']:.3f} "
                      f"(production {prod['max_margin']:.4f}, {prod['max_ulp32']:.3f}); coefficients "
                      f"{', '.join(best['candidate']['coefficients'])}")
    print(f"\n{len(everything)} points in {time.perf_counter() - t_all:.1f} s")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(everything, f, indent=1)
    return 0
