"""``python -m routines zoo``: the reference's exp2/log2 methods, its figures beside ours.

Builds every method of the reference write-up (``routines.zoo``), measures it
on the compiled kernel with the accuracy lab (exhaustively over the domain
where the reference reads its figures, and over a wider domain for the
conformance verdict) and prints the table of docs/zoo.md.
"""
from __future__ import annotations

import fnmatch
import json
import os
import sys
import time

from . import ArgumentParser, add_quiet, parser as command_parser, positive_int


def _parser() -> ArgumentParser:
    p = command_parser("zoo", __doc__, ("", "--quick --only 'log2.*'", "--markdown --json out/zoo.json"))
    p.add_argument("--json", metavar="F", help="also write the full measurements as JSON to F")
    p.add_argument("--quick", action="store_true",
                   help="random samples instead of exhaustive sweeps (figures are lower bounds)")
    p.add_argument("--workers", type=positive_int, metavar="N", default=2, help="sweep processes (default 2)")
    p.add_argument("--only", metavar="GLOB", action="append",
                   help="measure only variants matching GLOB (e.g. 'log2.first*'); repeatable")
    p.add_argument("--markdown", action="store_true", help="print the table as Markdown")
    add_quiet(p, "no line per measured variant on stderr")
    return p


def main(argv: list[str]) -> int:
    args = _parser().parse_args(argv)
    from ..zoo import VARIANTS
    from ..zoo.table import markdown, measure_all, table, to_json

    variants = [v for v in VARIANTS
                if not args.only or any(fnmatch.fnmatch(v.name, g) for g in args.only)]
    if not variants:
        print(f"error: no zoo variant matches {' or '.join(args.only)} (e.g. 'exp2.*', 'log2.first*')",
              file=sys.stderr)
        return 2
    t0 = time.perf_counter()
    if args.json:
        os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
    ms = measure_all(variants, quick=args.quick, workers=args.workers,
                     log=None if args.quiet else (lambda s: print(s, file=sys.stderr, flush=True)))
    seconds = time.perf_counter() - t0
    print(markdown(ms) if args.markdown else table(ms))
    print(f"\n{len(ms)} variants in {seconds:.1f} s ({'quick' if args.quick else 'exhaustive'})")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(to_json(ms, quick=args.quick, seconds=round(seconds, 1)), f, indent=1)
    return 0
