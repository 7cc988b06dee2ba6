"""``python -m routines.lab.constants``: recompute the literals of ``routines/constants.py``.

The routines need a few constants beyond float64 (series coefficients as double-double pairs)
and two float32 tables found by search (the sRGB8 encode's thresholds, its decode table). They
are computed here with mpmath at 60 digits and stored as literals, so that building a routine
needs no mpmath: this command prints the module (``> routines/constants.py`` rewrites it), and
``tests/routines/test_constants.py`` checks that the stored literals are what it computes.
"""
from __future__ import annotations

import sys

import mpmath
import numpy as np

from .. import doubled as dd
from .. import pixels

HEADER = '''"""Constants of the routines, stored as literals: do not edit by hand.

Written by ``python -m routines.lab.constants > routines/constants.py`` (mpmath, 60 digits; see
that module for how each is obtained); ``tests/routines/test_constants.py`` recomputes them.
"""
'''


def exp2_series() -> tuple[list[float], list[tuple[float, float]]]:
    """2^r = sum (ln 2)^n / n! r^n, n <= 18, highest first: r^18..r^9 in float64, the rest
    (r^8..r^0) as double-double pairs."""
    with mpmath.workdps(60):
        c = [mpmath.log(2) ** n / mpmath.factorial(n) for n in range(19)][::-1]
        return [float(v) for v in c[:10]], [dd.constant(v) for v in c[10:]]


def log2_series() -> tuple[list[float], list[tuple[float, float]]]:
    """2 atanh(s) / (s ln 2) = sum 2 / ((2n+1) ln 2) z^n, n <= 17, highest first: z^17..z^6 in
    float64, the rest as double-double pairs."""
    with mpmath.workdps(60):
        c = [2 / ((2 * n + 1) * mpmath.log(2)) for n in range(18)][::-1]
        return [float(v) for v in c[:12]], [dd.constant(v) for v in c[12:]]


def atan_series() -> list[tuple[float, float]]:
    """atan(d) / d = sum (-1)^n z^n / (2n+1), z = d^2, n <= 8 (remainder < 2^-110 for |d| <= 1/64),
    highest power first, as double-double pairs."""
    with mpmath.workdps(60):
        return [dd.constant(mpmath.mpf((-1) ** n) / (2 * n + 1)) for n in range(9)][::-1]


def atan_table() -> list[tuple[float, float]]:
    """atan(k / 32), k = 0..32, as double-double pairs."""
    with mpmath.workdps(60):
        return [dd.constant(mpmath.atan(mpmath.mpf(k) / 32)) for k in range(33)]


def srgb8_thresholds() -> np.ndarray:
    """T[k] (k = 0..254): the smallest float32 whose sRGB8 code is k + 1: code(T[k]) = k + 1 and
    code(prevfloat(T[k])) = k, both checked at 60 digits."""
    with mpmath.workdps(60):
        out = np.empty(255, np.float32)
        for k in range(255):
            t = pixels.srgb_decode_exact(mpmath.mpf(k) / 255 + mpmath.mpf(1) / 510, mpmath.mp)
            x = np.float32(float(t))
            while pixels.exact_code(float(x), mpmath.mp) < k + 1:
                x = np.nextafter(x, np.float32(2))
            while pixels.exact_code(float(np.nextafter(x, np.float32(-1))), mpmath.mp) >= k + 1:
                x = np.nextafter(x, np.float32(-1))
            out[k] = x
    return out


def srgb8_decode() -> np.ndarray:
    """The correctly rounded float32 of sRGB^-1(k / 255), k = 0..255 (60 digits to float64, then
    to float32: correctly rounded, as no such value lies within 2^-60 of a float32 midpoint)."""
    with mpmath.workdps(60):
        return np.array([float(pixels.srgb_decode_exact(mpmath.mpf(k) / 255, mpmath.mp)) for k in range(256)],
                        np.float64).astype(np.float32)


def _tuple(values) -> str:
    return "(\n" + "".join(f"    {v!r},\n" for v in values) + ")"


def _bits(table: np.ndarray) -> str:
    words = [f"0x{int(b):08x}" for b in table.view(np.uint32)]
    rows = [", ".join(words[i:i + 8]) for i in range(0, len(words), 8)]
    return "(\n" + "".join(f"    {r},\n" for r in rows) + ")"


def module_text() -> str:
    """The text of ``routines/constants.py``."""
    e_hi, e_lo = exp2_series()
    l_hi, l_lo = log2_series()
    return (HEADER + "\n"
            + "#: 2^r's series, highest power first: float64 terms, then double-double (hi, lo) pairs\n"
            + f"EXP2_SERIES_HIGH = {_tuple(e_hi)}\nEXP2_SERIES_LOW = {_tuple(e_lo)}\n\n"
            + "#: 2 atanh(s) / (s ln 2)'s series in z = s^2, highest power first, the same way\n"
            + f"LOG2_SERIES_HIGH = {_tuple(l_hi)}\nLOG2_SERIES_LOW = {_tuple(l_lo)}\n\n"
            + "#: atan(d) / d's series in z = d^2 (|d| <= 1/64), highest power first, double-double pairs\n"
            + f"ATAN_SERIES = {_tuple(atan_series())}\n"
            + "#: atan(k / 32), k = 0..32, double-double pairs\n"
            + f"ATAN_TABLE = {_tuple(atan_table())}\n\n"
            + "#: float32 bits: the smallest float32 of each sRGB8 code 1..255\n"
            + f"SRGB8_THRESHOLD_BITS = {_bits(srgb8_thresholds())}\n\n"
            + "#: float32 bits: sRGB^-1(k / 255) correctly rounded, k = 0..255\n"
            + f"SRGB8_DECODE_BITS = {_bits(srgb8_decode())}\n")


if __name__ == "__main__":
    sys.stdout.write(module_text())
