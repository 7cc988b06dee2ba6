"""``python -m routines pixels``: prove the sRGB8 encode exact and time it beside a pow-based one.

Without ``--exhaustive`` the check runs on 2^24 float32 inputs spread over [0, 1];
with it, on every float32 in [0, 1] (1,065,353,217 inputs, ~10 s). The timing
compares, on 2^22 inputs of [0, 1], the exact encode (relaxed pow + a threshold
correction), the table-free encode with the full-precision pow (not always the
nearest code), and NumPy float32. Exit status 1 if any code differs.
"""
from __future__ import annotations

import time

import numpy as np

from . import add_quiet
from . import parser as command_parser


def _best(fn, reps=7):
    best = float("inf")
    for _ in range(reps):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main(argv: list[str]) -> int:
    p = command_parser("pixels", __doc__, ("", "--exhaustive"))
    p.add_argument("--exhaustive", action="store_true", help="every float32 in [0, 1]")
    add_quiet(p)
    args = p.parse_args(argv)

    import reactor
    from reactor import Float, UByte
    from .. import pixels

    stop = 0x3F800001
    if args.exhaustive:
        result = pixels.check_srgb8()
    else:  # 2^24 inputs: every 64th bit pattern, then the last chunk whole
        result = {"checked": 0, "mismatched": 0, "thresholds": 255}
        for lo in range(0, stop, 64 * (1 << 18)):
            part = pixels.check_srgb8(lo, min(lo + (1 << 18), stop))
            result["checked"] += part["checked"]
            result["mismatched"] += part["mismatched"]
    print(f"sRGB8 encode: {result['checked']:,} float32 inputs in [0, 1] checked against the "
          f"{result['thresholds']} mpmath thresholds: {result['mismatched']} codes differ")

    x = np.random.default_rng(1).random(1 << 22).astype(np.float32)
    exact = reactor.kernel(lambda v: pixels.srgb8_encode(v), args=[Float], returns=UByte, name="srgb8_exact")
    with_pow = reactor.kernel(lambda v: pixels.srgb8_encode_pow(v), args=[Float], returns=UByte, name="srgb8_pow")
    out = np.empty(x.shape, np.uint8)

    def numpy_encode():
        y = np.where(x <= 0.0031308, x * np.float32(12.92),
                     np.float32(1.055) * np.power(x, np.float32(1 / 2.4)) - np.float32(0.055))
        return np.rint(y * np.float32(255)).astype(np.uint8)

    rows = [("exact (relaxed pow + thresholds)", _best(lambda: exact(x, out=out))),
            ("full pow, no table", _best(lambda: with_pow(x, out=out))),
            ("NumPy float32", _best(numpy_encode, 3))]
    ref = np.searchsorted(pixels.srgb8_thresholds(), x, side="right")
    misses = {"exact (relaxed pow + thresholds)": int(np.count_nonzero(exact(x) != ref)),
              "full pow, no table": int(np.count_nonzero(with_pow(x) != ref)),
              "NumPy float32": int(np.count_nonzero(numpy_encode() != ref))}
    print(f"\n{len(x):,} random inputs of [0, 1], one call, best of 7 (3 for NumPy):")
    print(f"{'encode':<36} {'ns/value':>9} {'codes off':>10}")
    for name, t in rows:
        print(f"{name:<36} {t / len(x) * 1e9:9.3f} {misses[name]:>10,}")
    return 1 if result["mismatched"] else 0
