"""Fingerprints of the compiled routines: a SHA-256 of every variant's output bits.

A refactor, a new target or a new pipeline must not change what a routine
computes. ``fingerprints()`` runs every variant (function x precision x FMA x
width) on the same 2^24 inputs (every 256th float32 bit pattern with a moving
offset, so every binade and both signs are covered, with the special values and
thresholds first) and hashes the output bits, NaN payloads included. Two runs
agree iff every output bit agrees. ``pow`` (and ``atan2``) pairs these x with y drawn from
small integers, halves, specials and a wide sweep.

    python -m routines fingerprint [--json FILE] [--compare FILE] [--target T]
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import sys

import numpy as np

from ..base import PRECISIONS
from .reference import BINARY

N = 2 ** 24

_SPECIAL_BITS = [
    0x00000000, 0x80000000, 0x7F800000, 0xFF800000, 0x7FC00000, 0xFFC00000, 0x7F800001, 0xFF800001,
    0x7FBFFFFF, 0x7FC00001, 0x00000001, 0x80000001, 0x007FFFFF, 0x807FFFFF, 0x00800000, 0x80800000,
    0x7F7FFFFF, 0xFF7FFFFF, 0x3F800000, 0xBF800000, 0x3F7FFFFF, 0x3F800001,
]
_SPECIAL_VALUES = ([float(k) for k in range(-160, 161)] + [k + 0.5 for k in range(-160, 160)]
                   + [127.99999, 128.00002, -126.00001, -149.5, 88.72283, 88.72284, -87.33655, -103.97208,
                      1e-45, 1e-38, 3.4e38, 0.5, 2.0, 4.0, 0.25])


def unary_inputs(n: int = N) -> np.ndarray:
    """``n`` float32 inputs: the specials, then every (2^32/n)-th bit pattern with a moving offset."""
    step = 2 ** 32 // n
    k = np.arange(n, dtype=np.uint64)
    bits = (k * step + (k * 97) % step).astype(np.uint32)
    head = np.concatenate([np.array(_SPECIAL_BITS, np.uint32),
                           np.array(_SPECIAL_VALUES, np.float32).view(np.uint32)])
    bits[:head.size] = head
    return bits.view(np.float32)


def pow_inputs(n: int = N) -> tuple[np.ndarray, np.ndarray]:
    """(x, y) pairs: x as :func:`unary_inputs`, y cycling through integers, halves,
    specials and a sweep of [-300, 300]."""
    x = unary_inputs(n)
    rng = np.random.default_rng(2024)
    small = np.array([0.0, -0.0, 1.0, -1.0, 2.0, -2.0, 3.0, 0.5, -0.5, 1 / 2.2, 2.2, 127.0, -149.0,
                      np.inf, -np.inf, np.nan], np.float32)
    y = rng.uniform(-300, 300, n).astype(np.float32)
    y[::4] = rng.integers(-40, 40, y[::4].size).astype(np.float32)
    y[1::8] = (rng.integers(-80, 80, y[1::8].size) / 2).astype(np.float32)
    y[: small.size * 64] = np.tile(small, 64)
    return x, y


def variants(functions=None, widths=(16, 8, 4), target=None):
    """(name, precision, fma, width) for every variant."""
    import routines
    for name in functions or routines.NAMES:
        for precision in PRECISIONS:
            for fma in (True, False):
                for width in widths:
                    yield name, precision, fma, width


def fingerprint(name: str, precision: str, fma: bool, width: int, target: str | None = None,
                n: int = N) -> str:
    """SHA-256 of the output bits of one variant on the fingerprint inputs, contiguous and strided."""
    import routines
    fn = routines.jit(name, precision=precision, fma=fma, width=width, target=target)
    args = pow_inputs(n) if name in BINARY else (unary_inputs(n),)  # atan2: the same pairs
    h = hashlib.sha256()
    h.update(fn(*args).view(np.uint32).tobytes())
    strided = tuple(a[: n // 64 * 2: 2] for a in args)  # the strided path of the same kernel
    h.update(fn(*strided).view(np.uint32).tobytes())
    return h.hexdigest()


def fingerprints(functions=None, widths=(16, 8, 4), target=None, n: int = N, progress=None) -> dict:
    out = {}
    for name, precision, fma, width in variants(functions, widths, target):
        key = f"{name} {precision} {'fma' if fma else 'nofma'} w{width}"
        out[key] = fingerprint(name, precision, fma, width, target, n)
        if progress:
            progress(key, out[key])
    return out


def main(argv=None) -> int:
    from reactor import TARGETS, WIDTHS

    from .. import NAMES
    from ..cli import CommandError, add_quiet, parser as command_parser

    parser = command_parser("fingerprint", __doc__, (
        "--json out/fingerprints.json", "--compare out/fingerprints.json --quiet",
        "--functions exp2 pow --widths 16 --target avx2"))
    parser.add_argument("--json", metavar="FILE", help="write the fingerprints to this file")
    parser.add_argument("--compare", metavar="FILE",
                        help="compare with fingerprints written earlier; exit 1 on a difference")
    parser.add_argument("--target", choices=TARGETS, help="code-generation target (default: host)")
    parser.add_argument("--functions", nargs="+", choices=NAMES, metavar="F",
                        help=f"only these functions (default all: {' '.join(NAMES)})")
    parser.add_argument("--widths", type=int, nargs="+", choices=WIDTHS, default=[16, 8, 4], metavar="W",
                        help=f"SIMD widths, from {', '.join(map(str, WIDTHS))} (default 16 8 4)")
    add_quiet(parser, "no line per variant (with --json or --compare)")
    args = parser.parse_args(argv if argv is not None else sys.argv[1:])
    old = None
    if args.compare:  # read before the long run, not after it
        with open(args.compare) as f:
            try:
                old = json.load(f)
            except ValueError as exc:
                raise CommandError(f"{args.compare} is not a fingerprint JSON: {exc}") from None
    if args.json:
        os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
    fps = fingerprints(args.functions, tuple(args.widths), args.target,
                       progress=None if args.quiet else lambda k, v: print(f"{k:32s} {v[:16]}", flush=True))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(fps, f, indent=1)
    if old is not None:
        diff = [k for k in fps if k in old and old[k] != fps[k]]
        missing = [k for k in fps if k not in old]
        print(f"{len(fps) - len(diff) - len(missing)} identical, {len(diff)} different, "
              f"{len(missing)} not in {args.compare}")
        for k in diff:
            print(f"  DIFFERENT: {k}")
        return 1 if diff else 0
    return 0


if __name__ == "__main__":
    from ..cli import run

    sys.exit(run(main))
