"""``python -m routines report [--quick] [--exhaustive] [--functions F ...|trig|all] [--out DIR] ...``

The README's first command: builds every variant (function x precision x FMA x SIMD width
4/8/16) of the functions (default: exp2 log2 pow exp log rcp rsqrt sqrt;
``--functions trig`` for sin cos tan asin acos atan atan2 sinh cosh tanh,
``--functions all`` for both, or any list of names) and the peers (NumPy,
glibc libmvec, SLEEF, numba where installed),
measures their accuracy (the lab's sample by default, every input with
``--exhaustive``) and their speed (L1, L2 and DRAM sizes, one thread, and two
threads at the DRAM size; the clock calibrated in the same run), models
every variant's loop, measures the accuracy ladder (``routines.perf.frontier``: every tier
of exp2, exp, log2, log and pow beside every peer, with which peer each of our points
dominates), writes ``DIR/report.json`` (every figure) and prints a one-screen summary
(per function our tiers beside NumPy and the fastest peer, the peers dominated, the absent peers in
one line, each target met or missed; ``--verbose``: every variant, peer, model gap and ladder row),
then draws ``DIR/ladder.png`` (the ladder), ``DIR/chart.png``/``.svg`` (cost vs
max ULP) and ``DIR/chart-margin.png``/``.svg`` (cost vs margin). The chart
needs matplotlib (``pip install "reactor-simd[plot]"``); without it the command
says so in one line and still succeeds. Progress goes to stderr. See
docs/performance.md.
"""
from __future__ import annotations

import json
import os
import sys

from ..perf import chart, report, timing
from ..perf.report.summary import summary
from . import add_quiet, parser as command_parser, positive_int
from .bench import expand

#: Names that stand for several functions in ``--functions``.
GROUPS = {"trig": report.TRIG, "all": report.FUNCTIONS}


def _expand(names) -> list[str]:
    """``--functions`` with the groups replaced by their functions, in order, each once."""
    return expand(names, GROUPS)


def main(argv: list[str]) -> int:
    parser = command_parser("report", __doc__, ("--quick", "", "--functions all", "--exhaustive --out out/full",
                                                "--functions exp2 log2 --sizes L1 L2 --rounds 9 --quiet",
                                                "--functions sin atan2 tanh --out out/trig"))
    parser.add_argument("--out", default="out", metavar="DIR", help="output directory (default out/)")
    parser.add_argument("--quick", action="store_true",
                        help="small sample (2^14), L2 size only, fewer rounds (under a minute)")
    parser.add_argument("--exhaustive", action="store_true",
                        help="accuracy over all 2^32 inputs (pow, atan2: the stratified pair sweep); ~40 s per variant")
    parser.add_argument("--exhaustive-peers", action="store_true", help="the same for the peers")
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="spread the exhaustive sweeps over this dask cluster (the distributed extra)")
    parser.add_argument("--functions", nargs="+", default=list(report.DEFAULT_FUNCTIONS),
                        choices=report.FUNCTIONS + tuple(GROUPS), metavar="F",
                        help=f"any of {' '.join(report.FUNCTIONS)}; trig: {' '.join(report.TRIG)}; "
                             f"all: every one (default: {' '.join(report.DEFAULT_FUNCTIONS)})")
    parser.add_argument("--sizes", nargs="+", choices=list(timing.SIZES), metavar="SIZE",
                        help=f"{' '.join(timing.SIZES)}; default: all (quick: L2)")
    parser.add_argument("--rounds", type=positive_int, metavar="N",
                        help="timing rounds per size (default 61, DRAM 9; quick 7)")
    parser.add_argument("--samples", type=positive_int, metavar="N",
                        help="random inputs of the accuracy sample (default 2^20; quick 2^14)")
    parser.add_argument("--no-threads", action="store_true", help="skip the two-thread timings")
    parser.add_argument("--verbose", action="store_true",
                        help="print every variant, peer, model gap and ladder row (default: a one-screen summary)")
    add_quiet(parser, "no progress bars (they are shown only on a terminal anyway)")
    args = parser.parse_args(argv)
    functions = _expand(args.functions)
    sizes = args.sizes or (["L2"] if args.quick else list(timing.SIZES))
    rounds = args.rounds or (7 if args.quick else None)
    samples = args.samples or (2 ** 14 if args.quick else 2 ** 20)
    result = report.run(functions, sizes={s: timing.SIZES[s] for s in sizes},
                        rounds={s: rounds for s in sizes} if rounds else None, samples=samples,
                        exhaustive=args.exhaustive, exhaustive_peers=args.exhaustive_peers,
                        threads2=not args.no_threads, progress=not args.quiet, scheduler=args.scheduler)
    result["settings"]["command"] = "python -m routines report " + " ".join(argv)
    os.makedirs(args.out, exist_ok=True)
    json_path = os.path.join(args.out, "report.json")
    result["chart"] = []
    _write_json(result, json_path)  # the figures first: the chart is optional and drawn last
    from ..perf import frontier as ladder
    points = ladder.from_json(result["ladder"])
    if not args.verbose:
        print(summary(result), flush=True)
    else:
        print(report.print_table(result), flush=True)
    if points and args.verbose:
        print("\nThe accuracy ladder (relaxed, full, faithful, correct) beside every peer: "
              "max ULP-32 on a sample of every binade, ns per element at 64K, one thread\n")
        print(ladder.table(points))
        print("\nPeers dominated (a point of ours at most their time and at most their max ULP):")
        print("\n".join("  " + line for line in ladder.statements(points)), flush=True)
    missing = chart.missing_matplotlib()
    if missing:
        print(f"{missing}; then `python -m routines chart --out {args.out} [--error margin]` "
              f"draws it from {json_path}", file=sys.stderr)
        print(f"\nwrote {json_path}", file=sys.stderr)
        return 0
    paths = []
    for error, name in (("ulp", "chart"), ("margin", "chart-margin")):
        panels = report.chart_panels(result, error, search_dir=os.path.join(args.out, "search"))
        paths += chart.draw(panels, os.path.join(args.out, name), error=error,
                            title=f"cost vs {'max ULP-32' if error == 'ulp' else 'max margin'} "
                                  f"({result['machine'].get('llvm_cpu')}, {result['clock']['ghz']:.2f} GHz)")
    if points:
        ladder.chart(points, os.path.join(args.out, "ladder.png"))
        paths.append(os.path.join(args.out, "ladder.png"))
    result["chart"] = paths
    _write_json(result, json_path)  # again, now listing the chart's files
    print(f"\nwrote {json_path}, " + ", ".join(paths), file=sys.stderr)
    return 0


def _write_json(result: dict, path: str) -> None:
    with open(path, "w") as f:
        json.dump(report.to_json(result), f, indent=1)
