"""Pixel formats against exact references: unorm/snorm codes, RGB10A2, float16, the GLSL packing
functions, and the sRGB8 encode proved on every float32 of [0, 1]."""
import mpmath
import numpy as np
import pytest

import reactor
from reactor import Float, Half, UByte, UInt, UShort, kernel, vec2, vec4
from routines import glsl as gl
from routines import pixels as px

SPECIALS = np.float32([0, -0.0, 1, -1, 0.5, -0.5, np.nan, np.inf, -np.inf, 2, 1e-30, -1e-30,
                       127.5 / 255, 128.5 / 255, 0.5 / 255, 254.5 / 255])


def _inputs(n=1 << 16, seed=0):
    rng = np.random.default_rng(seed)
    return np.concatenate([SPECIALS, rng.uniform(-1.5, 1.5, n).astype(np.float32),
                           (rng.integers(0, 256, n) / 255 + rng.choice([-1, 0, 1], n) * 2.0 ** -26).astype(
                               np.float32)])


def _exact_codes(x, scale, signed):
    """Round-half-even of clamp(x) * scale computed exactly (float64 holds the product)."""
    lo = -1.0 if signed else 0.0
    c = np.clip(np.nan_to_num(x.astype(np.float64), nan=0.0), lo, 1.0)
    return np.rint(c * scale).astype(np.int64)


@pytest.mark.parametrize("fmt", sorted(px.FORMATS))
def test_encode_is_the_correctly_rounded_code_and_decode_divides(fmt):
    kind, scale, signed = px.FORMATS[fmt]

    @kernel
    def roundtrip(x: Float) -> (kind, Float):
        code = px.encode(x, fmt)
        return code, px.decode(code, fmt)

    x = _inputs()
    code, back = roundtrip(x)
    want = _exact_codes(x, scale, signed)
    bits = kind.vtype.kind.bits
    np.testing.assert_array_equal(code.astype(np.int64), np.mod(want, 1 << bits))
    dec = (want.astype(np.float32) / np.float32(scale)).astype(np.float32)
    np.testing.assert_array_equal(back, np.maximum(dec, np.float32(-1)) if signed else dec)


def test_rgb10a2_packs_red_lowest():
    @kernel
    def pack(r: Float, g: Float, b: Float, a: Float) -> (UInt, vec4):
        u = px.pack_rgb10a2(vec4(r, g, b, a))
        return u, px.unpack_rgb10a2(u)

    rng = np.random.default_rng(3)
    r, g, b, a = (rng.uniform(-0.2, 1.2, 999).astype(np.float32) for _ in range(4))
    u, back = pack(r, g, b, a)
    codes = [_exact_codes(c, m, False) for c, m in ((r, 1023), (g, 1023), (b, 1023), (a, 3))]
    want = codes[0] | codes[1] << 10 | codes[2] << 20 | codes[3] << 30
    np.testing.assert_array_equal(u.astype(np.int64), want)
    np.testing.assert_array_equal(back[:, 3], (codes[3] / np.float32(3)).astype(np.float32))


def test_half_conversion_is_correctly_rounded_with_nan_and_inf_kept():
    @kernel
    def to_half(x: Float) -> (Half, Float):
        h = Half(x)
        return h, Float(h)

    rng = np.random.default_rng(5)
    bits = rng.integers(0, 2 ** 32, 1 << 22, dtype=np.uint64).astype(np.uint32)
    x = np.concatenate([SPECIALS, bits.view(np.float32), np.float32([65504, 65519.99, 65520, 5.96e-8, 2.98e-8])])
    with np.errstate(over="ignore"):
        want = x.astype(np.float16)
    h, back = to_half(x)
    same = (h.view(np.uint16) == want.view(np.uint16)) | (np.isnan(h) & np.isnan(want))
    assert same.all(), x[~same][:5]
    np.testing.assert_array_equal(back, want.astype(np.float32))
    asm = reactor.kernel_of(to_half).assembly
    if "f16c" in reactor.get_target("host").feature_set or "avx512f" in reactor.get_target("host").feature_set:
        assert "vcvtps2ph" in asm and "vcvtph2ps" in asm  # the hardware conversion, not a library call


def test_glsl_packing_functions():
    @kernel
    def pack(x: Float, y: Float) -> (UInt, UInt, UInt, vec2, vec2):
        u8 = gl.packUnorm4x8(vec4(x, y, 0.5, 1.0))
        s16 = gl.packSnorm2x16(vec2(x, y))
        h = gl.packHalf2x16(vec2(x, y))
        return u8, s16, h, gl.unpackSnorm2x16(s16), gl.unpackHalf2x16(h)

    rng = np.random.default_rng(7)
    x, y = rng.uniform(-1.2, 1.2, 500).astype(np.float32), rng.uniform(-1.2, 1.2, 500).astype(np.float32)
    u8, s16, h, s_back, h_back = pack(x, y)
    cx, cy = _exact_codes(x, 255, False), _exact_codes(y, 255, False)
    np.testing.assert_array_equal(u8.astype(np.int64), cx | cy << 8 | 128 << 16 | 255 << 24)
    sx, sy = _exact_codes(x, 32767, True), _exact_codes(y, 32767, True)
    np.testing.assert_array_equal(s16.astype(np.int64), np.mod(sx, 65536) | np.mod(sy, 65536) << 16)
    np.testing.assert_array_equal(s_back[:, 1], (sy / np.float32(32767)).astype(np.float32))
    hx, hy = x.astype(np.float16).view(np.uint16), y.astype(np.float16).view(np.uint16)
    np.testing.assert_array_equal(h.astype(np.int64), hx.astype(np.int64) | hy.astype(np.int64) << 16)
    np.testing.assert_array_equal(h_back[:, 0], x.astype(np.float16).astype(np.float32))


def test_srgb8_thresholds_are_the_first_float_of_each_code():
    """Checked independently of how they were found: at 80 digits, T[k] encodes to k + 1 and the
    float32 just below it to k."""
    thresholds = px.srgb8_thresholds()
    assert np.all(np.diff(thresholds) > 0)
    with mpmath.workdps(80):
        for k, t in enumerate(thresholds):
            below = np.nextafter(t, np.float32(-1))
            assert px.exact_code(float(t), mpmath.mp) == k + 1
            assert px.exact_code(float(below), mpmath.mp) == k


def test_srgb8_encode_is_exact_on_every_float32_in_0_1():
    """All 1,065,353,217 inputs (about 10 s): the compiled encode steps by one code exactly at
    each threshold. Also python -m routines pixels --exhaustive."""
    result = px.check_srgb8()
    assert result == {"checked": 0x3F800001, "mismatched": 0, "thresholds": 255}


def test_srgb8_encode_outside_0_1_and_decode_is_correctly_rounded():
    @kernel
    def enc(x: Float) -> UByte:
        return px.srgb8_encode(x)

    @kernel
    def dec(b: UByte) -> Float:
        return px.srgb8_decode(b)

    np.testing.assert_array_equal(enc(np.float32([np.nan, -1, -0.0, 1.5, np.inf, -np.inf])), [0, 0, 0, 255, 255, 0])
    got = dec(np.arange(256, dtype=np.uint8))
    with mpmath.workdps(60):
        for k, v in enumerate(got):
            exact = px.srgb_decode_exact(mpmath.mpf(k) / 255, mpmath.mp)
            lo, hi = np.nextafter(v, np.float32(-1)), np.nextafter(v, np.float32(2))
            err = abs(mpmath.mpf(float(v)) - exact)
            assert err <= abs(mpmath.mpf(float(lo)) - exact) and err <= abs(mpmath.mpf(float(hi)) - exact), k
