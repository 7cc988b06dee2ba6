"""``python -m routines accuracy FUNCTION [--precision P] [--fma on|off] [--exhaustive] [--json F]``

Measures one routine variant on its compiled kernel against the float64
reference (audited by mpmath, see docs/accuracy.md): max ULP-32 and ULP-16
with the input where each occurs, the max Vulkan margin (error / tolerance),
non-conforming inputs, special-value mismatches, flushes to zero and the 10
worst inputs.

Default: a quick sample (every hard region plus ``--samples`` random inputs).
``--exhaustive``: all 2^32 float32 inputs across both cores (~40-60 s), or for
pow the stratified sweep of >= 2^30 pairs (routines/lab/pairs.py).
"""
from __future__ import annotations

import argparse
import json
import sys

from reactor import WIDTHS

from .. import NAMES, jit
from ..base import PRECISIONS
from ..lab import evaluate, sample_inputs, sweep
from ..lab.pairs import stratified_pow


def measure(name: str, precision: str, fma: bool, *, width=None, exhaustive=False, samples=2 ** 20,
            workers=2, progress=True):
    """The SweepResult of one variant (see the module docstring)."""
    ufunc = jit(name, precision, fma, width)
    if not exhaustive:
        return evaluate(ufunc, name, precision, *sample_inputs(name, samples))
    if name == "pow":
        return stratified_pow(ufunc, precision, workers=workers, progress=progress)
    return sweep(ufunc, name, precision, workers=workers, progress=progress)


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m routines accuracy", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("function", choices=NAMES)
    parser.add_argument("--precision", choices=PRECISIONS, default="full")
    parser.add_argument("--fma", choices=("on", "off"), default="on")
    parser.add_argument("--width", type=int, choices=WIDTHS)
    parser.add_argument("--exhaustive", action="store_true")
    parser.add_argument("--samples", type=int, default=2 ** 20, help="random inputs in quick mode")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--json", metavar="FILE", help="also write the figures as JSON ('-': stdout)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    args = parser.parse_args(argv)
    result = measure(args.function, args.precision, args.fma == "on", width=args.width,
                     exhaustive=args.exhaustive, samples=args.samples, workers=args.workers,
                     progress=not args.quiet)
    print(f"{args.function} {args.precision} fma={args.fma}" + (f" width={args.width}" if args.width else ""))
    print(result.table())
    if args.json:
        data = dict(result.to_json(), fma=args.fma == "on", width=args.width, exhaustive=args.exhaustive)
        if args.json == "-":
            json.dump(data, sys.stdout, indent=1)
        else:
            with open(args.json, "w") as f:
                json.dump(data, f, indent=1)
    return 0 if result.conforming else 1
