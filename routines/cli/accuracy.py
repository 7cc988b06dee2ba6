"""``python -m routines accuracy FUNCTION [--precision P] [--fma on|off] [--exhaustive] [--json F]``

Measures one routine variant on its compiled kernel against the float64
reference (audited by mpmath, see docs/accuracy.md): max ULP-32 and ULP-16
with the input where each occurs, the max Vulkan margin (error / tolerance),
non-conforming inputs, special-value mismatches, flushes to zero and the 10
worst inputs.

Default: a quick sample (every hard region plus ``--samples`` random inputs).
``--exhaustive``: all 2^32 float32 inputs across both cores (~40-60 s; sin,
cos and tan ~2 min: the float64 reference is glibc's), or for pow and atan2
the stratified sweep of >= 2^30 pairs (routines/lab/pairs.py; atan2(y, x)
takes y first). For sin, cos and tan the errors inside and outside [-pi, pi]
are reported apart (Vulkan bounds only the inside). ``--scheduler ADDRESS``
spreads the exhaustive sweep over a dask cluster (``dask scheduler`` and
``dask worker ADDRESS`` on any machines with this package; the distributed
extra) and gives the same figures as the local run.
"""
from __future__ import annotations

import json
import os
import sys

from reactor import WIDTHS

from .. import NAMES, jit
from ..base import PRECISIONS
from ..lab import evaluate, sample_inputs, sweep
from ..lab.pairs import STRATA_OF, stratified
from . import add_quiet, parser as command_parser, positive_int


def measure(name: str, precision: str, fma: bool, *, width=None, exhaustive=False, samples=2 ** 20,
            workers=2, progress=True, scheduler=None):
    """The SweepResult of one variant (see the module docstring); ``scheduler``: a dask
    cluster to spread the exhaustive sweep over."""
    ufunc = jit(name, precision, fma, width)
    if not exhaustive:
        return evaluate(ufunc, name, precision, *sample_inputs(name, samples))
    if name in STRATA_OF:
        return stratified(ufunc, name, precision, workers=workers, progress=progress, scheduler=scheduler)
    return sweep(ufunc, name, precision, workers=workers, progress=progress, scheduler=scheduler)


def main(argv: list[str]) -> int:
    parser = command_parser("accuracy", __doc__, (
        "exp2 --precision relaxed --fma off",
        "log2 --exhaustive --json out/accuracy/log2_full_fma.json",
        "pow --samples 100000 --width 8", "sin --precision full --fma on --exhaustive",
        "exp2 --exhaustive --scheduler tcp://127.0.0.1:8786"))
    parser.add_argument("function", choices=NAMES)
    parser.add_argument("--precision", choices=PRECISIONS, default="full")
    parser.add_argument("--fma", choices=("on", "off"), default="on")
    parser.add_argument("--width", type=int, choices=WIDTHS, help="SIMD lanes (default: the target's)")
    parser.add_argument("--exhaustive", action="store_true",
                        help="every float32 input (pow, atan2: >= 2^30 pairs)")
    parser.add_argument("--samples", type=positive_int, metavar="N", default=2 ** 20,
                        help="random inputs in quick mode (default 2^20)")
    parser.add_argument("--workers", type=positive_int, metavar="N", default=2,
                        help="processes of the exhaustive sweep (default 2)")
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="spread the exhaustive sweep over this dask cluster (the distributed extra)")
    parser.add_argument("--json", metavar="FILE", help="also write the figures as JSON ('-': stdout)")
    add_quiet(parser, "no progress bar (it is shown only on a terminal anyway)")
    args = parser.parse_args(argv)
    if args.json and args.json != "-":  # before the measurement, not after a minute of it
        os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
    result = measure(args.function, args.precision, args.fma == "on", width=args.width,
                     exhaustive=args.exhaustive, samples=args.samples, workers=args.workers,
                     progress=not args.quiet, scheduler=args.scheduler)
    print(f"{args.function} {args.precision} fma={args.fma}" + (f" width={args.width}" if args.width else ""))
    print(result.table())
    if args.json:
        data = dict(result.to_json(), fma=args.fma == "on", width=args.width, exhaustive=args.exhaustive)
        if args.json == "-":
            json.dump(data, sys.stdout, indent=1)
            print()
        else:
            with open(args.json, "w") as f:
                json.dump(data, f, indent=1)
    return 0 if result.conforming else 1
