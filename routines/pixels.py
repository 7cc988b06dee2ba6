"""Pixel formats: unorm/snorm 8- and 16-bit channels, RGB10A2, and an exact sRGB8 encode/decode.

Encoding a Float channel (GLSL's ``packUnorm``/``packSnorm`` semantics) clamps it
to [0, 1] (or [-1, 1]), scales it by the format's maximum code and rounds to
nearest even: here the rounding is of the **exact** product (computed in double
lanes, where ``x * 255`` has no error), so every code is the correctly rounded
one; NaN encodes as 0. Decoding divides by the maximum (correctly rounded float
division; snorm clamps -128/127 to -1 as GLSL does)::

    FORMATS: unorm8 -> UByte (255), snorm8 -> UByte holding an int8 (127),
             unorm16 -> UShort (65535), snorm16 -> UShort holding an int16 (32767)

``pack_rgb10a2(v)`` / ``unpack_rgb10a2(u)``: three unorm10 channels and a unorm2
alpha in a UInt (red in the low bits, as Vulkan's A2B10G10R10_UNORM_PACK32).

**sRGB8**: ``srgb8_encode(x)`` gives the UByte nearest to 255 * sRGB(x), where
sRGB(x) = 12.92 x for x <= 0.0031308 and 1.055 x^(1/2.4) - 0.055 above (IEC
61966-2-1), evaluated exactly: a relaxed ``pow`` gives a code within one of the
answer, and one comparison with each neighbouring threshold of a 257-entry table
corrects it (the thresholds are the smallest float32 inputs of every code,
found with mpmath at 60 digits and checked on both sides). Proved on every
float32 in [0, 1]: ``python -m routines pixels --exhaustive``. ``srgb8_decode(b)``
reads the correctly rounded float32 of sRGB^-1(b / 255) from a 256-entry table.
``srgb8_encode_pow(x)``: the same formula with the full-precision pow and no
correction (no table; not always the nearest code) for comparison.
"""
from __future__ import annotations

import functools
import typing

import numpy as np

import reactor
from reactor import ConstantTable, DSLTypeError, Float, Max, Min, Round, Select, UByte, UShort

from .base import float_value
from .constants import SRGB8_DECODE_BITS, SRGB8_THRESHOLD_BITS
from .power import pow as _pow

#: name: (storage kind, maximum code, signed)
FORMATS: dict[str, tuple[typing.Any, int, bool]] = {
    "unorm8": (UByte, 255, False),
    "snorm8": (UByte, 127, True),
    "unorm16": (UShort, 65535, False),
    "snorm16": (UShort, 32767, True),
}


def _format(name: str):
    try:
        return FORMATS[name]
    except KeyError:
        raise DSLTypeError(f"unknown pixel format {name!r} (one of {', '.join(FORMATS)})") from None


def _double_of(x):
    return reactor.vector_type("Double", x.width)(x)


def encode(x, fmt: str):
    """``x`` (Float) as the format's code: clamp, scale, round the exact product to nearest even."""
    kind, scale, signed = _format(fmt)
    x = float_value(x, f"encode {fmt}")
    low = -1.0 if signed else 0.0
    clamped = Min(Max(x, low), 1.0)  # NaN -> low, then 0 after scaling for unorm (snorm: see below)
    if signed:
        clamped = Select(reactor.IsNan(x), 0.0, clamped)
    code = reactor.ToInt(Round(_double_of(clamped) * float(scale)))  # exact product, rounded to even
    store = reactor.vector_type(kind.vtype.kind.name, x.width)
    return store(code)  # an int in range: truncating to 8/16 bits keeps it (two's complement for snorm)


def decode(code, fmt: str):
    """A format's code as Float: over the maximum (correctly rounded); snorm clamps to -1."""
    kind, scale, signed = _format(fmt)
    if not isinstance(code, reactor.Value) or code.kind.name != kind.vtype.kind.name:
        raise DSLTypeError(f"decode {fmt} takes a {kind.vtype.kind.name} value, not {code!r}")
    f32 = reactor.vector_type("Float", code.width)
    i32 = reactor.vector_type("Int", code.width)
    n = i32(code)
    if signed:
        bits = 8 if kind is UByte else 16
        n = (n << (32 - bits)) >> (32 - bits)  # sign-extend the stored two's complement
        return Max(f32(n) / float(scale), -1.0)
    return f32(n) / float(scale)


def pack_rgb10a2(v):
    """A vec4 as A2B10G10R10: red bits 0-9, green 10-19, blue 20-29, alpha 30-31 (unorm each)."""
    comps = list(v) if isinstance(v, reactor.Vec) else None
    if comps is None or len(comps) != 4:
        raise DSLTypeError(f"pack_rgb10a2 takes a vec4, not {v!r}")
    out = None
    for c, (bits, shift) in zip(comps, ((10, 0), (10, 10), (10, 20), (2, 30))):
        c = float_value(c, "pack_rgb10a2")
        u32 = reactor.vector_type("UInt", c.width)
        code = u32(reactor.ToInt(Round(_double_of(Min(Max(c, 0.0), 1.0)) * float((1 << bits) - 1)))) << shift
        out = code if out is None else out | code
    return out


def unpack_rgb10a2(u):
    """The vec4 of an A2B10G10R10 UInt."""
    if not isinstance(u, reactor.Value) or u.kind.name != "UInt":
        raise DSLTypeError(f"unpack_rgb10a2 takes a UInt, not {u!r}")
    f32 = reactor.vector_type("Float", u.width)
    comps = [f32((u >> shift) & ((1 << bits) - 1)) / float((1 << bits) - 1)
             for bits, shift in ((10, 0), (10, 10), (10, 20), (2, 30))]
    return reactor.vec4(*comps)


# -- sRGB8 ----------------------------------------------------------------------------------------

LINEAR_LIMIT = 0.0031308


def srgb_exact(x, mp):
    """IEC 61966-2-1's encode of ``x`` in [0, 1] at mpmath's precision."""
    x = mp.mpf(x)
    if x <= mp.mpf(LINEAR_LIMIT):
        return mp.mpf("12.92") * x
    return mp.mpf("1.055") * x ** (mp.mpf(1) / mp.mpf("2.4")) - mp.mpf("0.055")


def srgb_decode_exact(y, mp):
    y = mp.mpf(y)
    if y <= mp.mpf("12.92") * mp.mpf(LINEAR_LIMIT):
        return y / mp.mpf("12.92")
    return ((y + mp.mpf("0.055")) / mp.mpf("1.055")) ** mp.mpf("2.4")


def exact_code(x: float, mp) -> int:
    """The nearest integer to 255 * sRGB(x) (no float32 input is a tie: checked)."""
    v = 255 * srgb_exact(x, mp)
    k = int(mp.floor(v + mp.mpf("0.5")))
    if v - k == mp.mpf("0.5") or k - v == mp.mpf("0.5"):
        raise ArithmeticError(f"sRGB8 tie at {x!r}")
    return k


@functools.lru_cache(maxsize=1)
def srgb8_thresholds() -> np.ndarray:
    """T[k] (k = 0..254): the smallest float32 whose sRGB8 code is k + 1 (mpmath, 60 digits):
    code(T[k]) = k + 1 and code(prevfloat(T[k])) = k, both checked (``routines.constants``;
    ``python -m routines.lab.constants`` recomputes it)."""
    return np.array(SRGB8_THRESHOLD_BITS, np.uint32).view(np.float32)


@functools.lru_cache(maxsize=1)
def _encode_table() -> ConstantTable:
    bounds = np.concatenate([[-np.inf], srgb8_thresholds(), [np.inf]]).astype(np.float32)
    return ConstantTable(bounds, Float)


@functools.lru_cache(maxsize=1)
def srgb8_decode_table() -> np.ndarray:
    """The correctly rounded float32 of sRGB^-1(k / 255), k = 0..255 (mpmath, 60 digits;
    ``routines.constants``)."""
    return np.array(SRGB8_DECODE_BITS, np.uint32).view(np.float32)


@functools.lru_cache(maxsize=1)
def _decode_table() -> ConstantTable:
    return ConstantTable(srgb8_decode_table(), Float)


def srgb8_encode(x):
    """The sRGB8 code nearest to 255 * sRGB(x) (x clamped to [0, 1]; NaN gives 0), exactly."""
    x = float_value(x, "srgb8_encode")
    x = Min(Max(x, 0.0), 1.0)  # NaN -> 0
    approx = Select(x <= LINEAR_LIMIT, x * (12.92 * 255.0),
                    _pow(x, 1.0 / 2.4, precision="relaxed") * (1.055 * 255.0) - 0.055 * 255.0)
    guess = Min(Max(reactor.ToInt(approx, "nearest"), 0), 255)  # within one code of the answer
    bounds = _encode_table()
    up = Select(x >= bounds[guess + 1], 1, 0)
    down = Select(x < bounds[guess], 1, 0)
    code = guess + up - down
    return reactor.vector_type("UByte", x.width)(code)


def srgb8_decode(code):
    """The linear value of an sRGB8 code: correctly rounded float32 (a table read)."""
    if not isinstance(code, reactor.Value) or code.kind.name != "UByte":
        raise DSLTypeError(f"srgb8_decode takes a UByte value, not {code!r}")
    return _decode_table()[reactor.vector_type("Int", code.width)(code)]


def srgb8_encode_pow(x):
    """The formula with the full-precision pow, rounded once: no table, not always the nearest code."""
    x = float_value(x, "srgb8_encode_pow")
    x = Min(Max(x, 0.0), 1.0)
    y = Select(x <= LINEAR_LIMIT, x * 12.92, _pow(x, 1.0 / 2.4, precision="full") * 1.055 - 0.055)
    return reactor.vector_type("UByte", x.width)(reactor.ToInt(y * 255.0, "nearest"))


__all__ = ["FORMATS", "encode", "decode", "pack_rgb10a2", "unpack_rgb10a2", "srgb8_encode", "srgb8_decode",
           "srgb8_encode_pow", "srgb8_thresholds", "srgb8_decode_table"]


def check_srgb8(start_bits: int = 0, stop_bits: int = 0x3F800001, chunk: int = 1 << 24,
                progress=None) -> dict:
    """Run the compiled ``srgb8_encode`` on every float32 whose bits are in [start, stop) (all of
    [0, 1] by default) and compare it with the thresholds: the codes must start right and step by
    one exactly at each threshold (float32 order is bit order there). Returns the counts."""
    T = srgb8_thresholds()
    tbits = T.view(np.uint32).astype(np.int64)
    encode_kernel = _encode_kernel()
    checked = mismatched = 0
    for lo in range(start_bits, stop_bits, chunk):
        hi = min(lo + chunk, stop_bits)
        x = np.arange(lo, hi, dtype=np.uint32).view(np.float32)
        got = encode_kernel(x).astype(np.int64)
        first = int(np.searchsorted(tbits, lo, side="right"))
        steps = np.flatnonzero(np.diff(got)) + 1 + lo
        want_steps = tbits[(tbits > lo) & (tbits < hi)]
        ok = got[0] == first and np.array_equal(steps, want_steps) and bool(np.all(np.diff(got) >= 0)) \
            and bool(np.all(np.diff(got) <= 1))
        if not ok:  # find the inputs that differ
            want = np.searchsorted(tbits, np.arange(lo, hi, dtype=np.int64), side="right")
            mismatched += int(np.count_nonzero(got != want))
        checked += hi - lo
        if progress is not None:
            progress(hi - lo)
    return {"checked": checked, "mismatched": mismatched, "thresholds": len(T)}


@functools.lru_cache(maxsize=1)
def _encode_kernel():
    return reactor.kernel(lambda x: srgb8_encode(x), args=[Float], returns=UByte, name="srgb8_encode")
