"""``python -m routines chart [--from FILE] [--error ulp|margin] [--out DIR]``

Draws the cost/error chart (one panel per function: x = cycles/element at
the L2-resident size, y = max ULP-32 on a log scale, or the max margin
against the highp tolerance with ``--error margin``; our variants and the
peers, the Pareto frontier and its lower convex hull, non-conforming points
marked) as PNG and SVG, from the JSON that ``python -m routines report``
wrote (default ``out/report.json``). Without that file it first runs the
report in its quick mode (and writes the JSON). The chart needs matplotlib
(``pip install "reactor-simd[plot]"``); without it the command says so in one
line and exits 0, without running anything. See docs/performance.md.
"""
from __future__ import annotations

import json
import os
import sys

from ..perf import chart, report, timing
from . import CommandError, add_quiet, parser as command_parser


def main(argv: list[str]) -> int:
    parser = command_parser("chart", __doc__, ("", "--error margin", "--from out/report.json --out docs/img"))
    parser.add_argument("--from", dest="source", metavar="FILE",
                        help="report JSON (default DIR/report.json)")
    parser.add_argument("--error", choices=("ulp", "margin"), default="ulp",
                        help="y axis: max ULP-32 or max margin against the tolerance (default ulp)")
    parser.add_argument("--out", default="out", metavar="DIR", help="output directory (default out/)")
    parser.add_argument("--name", help="file name without extension (default chart / chart-margin)")
    add_quiet(parser, "no progress bars while the quick report runs (shown only on a terminal anyway)")
    args = parser.parse_args(argv)
    missing = chart.missing_matplotlib()
    if missing:
        print(missing)
        return 0
    source = args.source or os.path.join(args.out, "report.json")
    if os.path.exists(source):
        with open(source) as f:
            try:
                data = json.load(f)
            except ValueError as exc:
                raise CommandError(f"{source} is not JSON written by `python -m routines report`: {exc}") from None
    else:
        if args.source:
            raise CommandError(f"no such file: {source}")
        print(f"{source} not found: running the quick report first", file=sys.stderr)
        data = report.to_json(report.run(sizes={"L2": timing.SIZES["L2"]}, rounds={"L2": 7},
                                         samples=2 ** 14, threads2=False,
                                         progress=not args.quiet))
        os.makedirs(args.out, exist_ok=True)
        with open(source, "w") as f:
            json.dump(data, f, indent=1)
    name = args.name or ("chart" if args.error == "ulp" else "chart-margin")
    panels = report.chart_panels(data, args.error, search_dir=os.path.join(args.out, "search"))
    paths = chart.draw(panels, os.path.join(args.out, name), error=args.error,
                       title=f"cost vs {'max ULP-32' if args.error == 'ulp' else 'max margin'} "
                             f"({data['machine'].get('llvm_cpu')}, {data['clock']['ghz']:.2f} GHz)")
    print("wrote " + ", ".join(paths))
    return 0
