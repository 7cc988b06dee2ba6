"""Ken Perlin's improved noise (2002) with the classic permutation table read per lane, as fbm terrain.

    python examples/textures/perlin.py [--out DIR] [--size 512] [--repeat 5]

The algorithm is Perlin's reference implementation of "Improving Noise" (SIGGRAPH 2002,
https://mrl.nyu.edu/~perlin/noise/): the lattice cell's corners are hashed through the classic
256-entry permutation, doubled to 512 entries so ``p[p[X] + Y] + Z`` never leaves the table, each
hash picks one of 12 gradients (``grad``'s bit tricks), and the fade curve is 6t^5 - 15t^4 + 10t^3.
Three-dimensional noise, sliced at ``z`` (a uniform: a broadcast scalar argument), summed over six
octaves (fbm: frequency x2, amplitude x0.5, each octave shifted), then shaded through a colour
ramp: a 12-stop terrain palette (sRGB stops decoded to linear) read with linear filtering from a
1-D ``Table[vec3, "clamp", "linear"]`` (texel centres: ``u' = (t (N - 1) + 0.5) / N``), and
encoded to RGBA8 with ``routines.pixels.srgb8_encode`` in the kernel: the PNG is the (H, W, 4) uint8
array the kernel returns.

Every lane looks its hashes up in the permutation with its own index: ``perm: Table[Int]`` is a
kernel parameter (the whole 512-element int32 array for every pixel; 14 gathers per noise call, 84
per pixel). The same kernel with the table baked in as a ``ConstantTable`` is timed beside it.
The NumPy reference is written from the same description (fancy indexing for the permutation,
``np.where`` for ``grad``, a hand-written lerp for the ramp) and runs in float64 (the reference)
and on float32 arrays (the NumPy float32 figure).
"""
from __future__ import annotations

import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from textures_common import (  # noqa: E402
    best_time, code_lines, compare, format_report, numpy_codes_f32, reference_codes, scene_main,
    srgb_decode64, timed_build, with_alpha,
)

import reactor  # noqa: E402
from reactor import ConstantTable, Float, Floor, Int, Select, Table, u8vec4, vec3  # noqa: E402
from routines import glsl as gl  # noqa: E402
from routines.pixels import srgb8_encode  # noqa: E402

#: Ken Perlin's permutation of 0..255 (the reference implementation's ``permutation[]``).
PERMUTATION = [
    151, 160, 137, 91, 90, 15, 131, 13, 201, 95, 96, 53, 194, 233, 7, 225, 140, 36, 103, 30, 69, 142, 8, 99, 37,
    240, 21, 10, 23, 190, 6, 148, 247, 120, 234, 75, 0, 26, 197, 62, 94, 252, 219, 203, 117, 35, 11, 32, 57, 177,
    33, 88, 237, 149, 56, 87, 174, 20, 125, 136, 171, 168, 68, 175, 74, 165, 71, 134, 139, 48, 27, 166, 77, 146,
    158, 231, 83, 111, 229, 122, 60, 211, 133, 230, 220, 105, 92, 41, 55, 46, 245, 40, 244, 102, 143, 54, 65, 25,
    63, 161, 1, 216, 80, 73, 209, 76, 132, 187, 208, 89, 18, 169, 200, 196, 135, 130, 116, 188, 159, 86, 164, 100,
    109, 198, 173, 186, 3, 64, 52, 217, 226, 250, 124, 123, 5, 202, 38, 147, 118, 126, 255, 82, 85, 212, 207, 206,
    59, 227, 47, 16, 58, 17, 182, 189, 28, 42, 223, 183, 170, 213, 119, 248, 152, 2, 44, 154, 163, 70, 221, 153,
    101, 155, 167, 43, 172, 9, 129, 22, 39, 253, 19, 98, 108, 110, 79, 113, 224, 232, 178, 185, 112, 104, 218,
    246, 97, 228, 251, 34, 242, 193, 238, 210, 144, 12, 191, 179, 162, 241, 81, 51, 145, 235, 249, 14, 239, 107,
    49, 192, 214, 31, 181, 199, 106, 157, 184, 84, 204, 176, 115, 121, 50, 45, 127, 4, 150, 254, 138, 236, 205,
    93, 222, 114, 67, 29, 24, 72, 243, 141, 128, 195, 78, 66, 215, 61, 156, 180,
]
#: The doubled table the reference implementation indexes (p[256 + i] = p[i]).
P512 = np.array(PERMUTATION * 2, dtype=np.int32)

#: The colour ramp's stops, sRGB hex from deep water to snow (decoded to linear for the table).
RAMP_HEX = ["0a1a40", "12306e", "1f5aa0", "4a9ccc", "d9cc92", "8fb35a", "5a9438", "3a7029", "2f5a26", "6e6152",
            "a39a8c", "f4f6fa"]
OCTAVES = 6
CELLS = 6.0          # noise cells across the image at the first octave
SLICE_Z = 0.37       # the slice of 3-D noise (a uniform argument)
CONTRAST = 0.62      # t = 0.5 + CONTRAST * fbm


def ramp_table() -> np.ndarray:
    """The ramp as an (N, 3) float32 table of linear values (exact sRGB decode, rounded once)."""
    codes = np.array([[int(h[i:i + 2], 16) for i in (0, 2, 4)] for h in RAMP_HEX])
    return srgb_decode64(codes).astype(np.float32)


# --- DSL begin
def fade(t):
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


def lerp(t, a, b):
    return a + t * (b - a)


def grad(hash, x, y, z):
    h = hash & 15                                  # the low 4 bits pick one of 12 gradient directions
    u = Select(h < 8, x, y)
    v = Select(h < 4, y, Select((h == 12) | (h == 14), x, z))
    return Select((h & 1) == 0, u, -u) + Select((h & 2) == 0, v, -v)


def noise(p, x, y, z):
    fx, fy, fz = Floor(x), Floor(y), Floor(z)
    X, Y, Z = Int(fx) & 255, Int(fy) & 255, Int(fz) & 255   # the unit cube that contains the point
    x, y, z = x - fx, y - fy, z - fz                        # the point's position in the cube
    u, v, w = fade(x), fade(y), fade(z)
    A = p[X] + Y                                            # hash the 8 corners: per-lane table reads
    AA, AB = p[A] + Z, p[A + 1] + Z
    B = p[X + 1] + Y
    BA, BB = p[B] + Z, p[B + 1] + Z
    return lerp(w, lerp(v, lerp(u, grad(p[AA], x, y, z), grad(p[BA], x - 1.0, y, z)),
                        lerp(u, grad(p[AB], x, y - 1.0, z), grad(p[BB], x - 1.0, y - 1.0, z))),
                lerp(v, lerp(u, grad(p[AA + 1], x, y, z - 1.0), grad(p[BA + 1], x - 1.0, y, z - 1.0)),
                     lerp(u, grad(p[AB + 1], x, y - 1.0, z - 1.0), grad(p[BB + 1], x - 1.0, y - 1.0, z - 1.0))))


def fbm(p, x, y, z):
    total = 0.0
    for octave in range(OCTAVES):                   # a Python loop: unrolled at build time
        f, a = 2.0 ** octave, 0.5 ** octave
        total = total + a * noise(p, x * f + 1.7 * octave, y * f + 9.2 * octave, z * f + 0.37 * octave)
    return total


def terrain(x, y, z, perm, ramp):
    """The linear colour of a pixel: fbm through the colour ramp (a linearly filtered table)."""
    t = gl.clamp(0.5 + CONTRAST * fbm(perm, x, y, z), 0.0, 1.0)
    n = len(RAMP_HEX)
    return ramp.sample(t * ((n - 1) / n) + 0.5 / n)


def perlin_rgba8(x: Float, y: Float, z: Float, perm: Table[Int], ramp: Table[vec3, "clamp", "linear"]) -> u8vec4:
    c = terrain(x, y, z, perm, ramp)
    return u8vec4(srgb8_encode(c.r), srgb8_encode(c.g), srgb8_encode(c.b), 255)


def perlin_linear(x: Float, y: Float, z: Float, perm: Table[Int], ramp: Table[vec3, "clamp", "linear"]) -> vec3:
    return terrain(x, y, z, perm, ramp)
# --- DSL end


PERM_CONSTANT = ConstantTable(P512, Int)


def perlin_rgba8_constant(x: Float, y: Float, z: Float, ramp: Table[vec3, "clamp", "linear"]) -> u8vec4:
    """The same with the permutation baked into the kernel (a ConstantTable in read-only data)."""
    c = terrain(x, y, z, PERM_CONSTANT, ramp)
    return u8vec4(srgb8_encode(c.r), srgb8_encode(c.g), srgb8_encode(c.b), 255)


def build(body):
    return reactor.kernel(body, cache=False)


# --- NumPy begin
def np_fade(t):
    return t * t * t * (t * (t * 6 - 15) + 10)


def np_grad(h, x, y, z):
    h = h & 15
    u = np.where(h < 8, x, y)
    v = np.where(h < 4, y, np.where((h == 12) | (h == 14), x, z))
    return np.where(h & 1, -u, u) + np.where(h & 2, -v, v)


def np_noise(p, x, y, z):
    one = x.dtype.type(1)
    fx, fy, fz = np.floor(x), np.floor(y), np.floor(z)
    X, Y, Z = (f.astype(np.int64) & 255 for f in (fx, fy, fz))
    x, y, z = x - fx, y - fy, z - fz
    u, v, w = np_fade(x), np_fade(y), np_fade(z)
    A, B = p[X] + Y, p[X + 1] + Y
    AA, AB, BA, BB = p[A] + Z, p[A + 1] + Z, p[B] + Z, p[B + 1] + Z

    def lerp(t, a, b):
        return a + t * (b - a)
    return lerp(w, lerp(v, lerp(u, np_grad(p[AA], x, y, z), np_grad(p[BA], x - one, y, z)),
                        lerp(u, np_grad(p[AB], x, y - one, z), np_grad(p[BB], x - one, y - one, z))),
                lerp(v, lerp(u, np_grad(p[AA + 1], x, y, z - one), np_grad(p[BA + 1], x - one, y, z - one)),
                     lerp(u, np_grad(p[AB + 1], x, y - one, z - one),
                          np_grad(p[BB + 1], x - one, y - one, z - one))))


def np_terrain(x, y, z, perm, ramp):
    """Linear RGB (H, W, 3) in the dtype of ``x``: fbm, then the ramp as piecewise-linear stops."""
    F = x.dtype.type
    total = np.zeros(np.broadcast_shapes(x.shape, y.shape), F)
    for octave in range(OCTAVES):
        f, a = F(2.0 ** octave), F(0.5 ** octave)
        total += a * np_noise(perm, x * f + F(1.7 * octave), y * f + F(9.2 * octave), z * f + F(0.37 * octave))
    t = np.clip(F(0.5) + F(CONTRAST) * total, F(0), F(1)) * F(len(ramp) - 1)   # ramp position in stops
    i = np.minimum(np.floor(t).astype(np.int64), len(ramp) - 2)
    frac = (t - i.astype(F))[..., None]
    stops = ramp.astype(F)
    return stops[i] * (F(1) - frac) + stops[i + 1] * frac
# --- NumPy end


def numpy_rgba8(x, y, z, perm, ramp):
    """The NumPy float32 render, through to RGBA8 codes (what is timed against the kernel)."""
    return with_alpha(numpy_codes_f32(np_terrain(x, y, z, perm, ramp)))


def inputs(size: int):
    """Noise-space coordinates of the pixel centres: x a (1, W) row, y an (H, 1) column, float32."""
    scale = np.float32(CELLS / size)
    x = ((np.arange(size, dtype=np.float32) + np.float32(0.5)) * scale)[None, :]
    y = ((np.arange(size, dtype=np.float32) + np.float32(0.5)) * scale)[:, None]
    return x, y, np.float32(SLICE_Z)


def run(size: int = 512, repeat: int = 5) -> dict:
    x, y, z = inputs(size)
    ramp = ramp_table()
    rgba8, build_u8 = timed_build(build, perlin_rgba8)
    linear, build_f = timed_build(build, perlin_linear)
    constant, build_c = timed_build(build, perlin_rgba8_constant)

    image = rgba8(x, y, z, P512, ramp)
    lin = linear(x, y, z, P512, ramp)
    ref_lin = np_terrain(x.astype(np.float64), y.astype(np.float64), np.float64(z), P512.astype(np.int64),
                         ramp.astype(np.float64))
    ref = reference_codes(ref_lin)
    np_lin = np_terrain(x, y, z, P512.astype(np.int64), ramp)
    np_image = numpy_rgba8(x, y, z, P512.astype(np.int64), ramp)
    accuracy = {"reactor": compare(image, ref, lin, ref_lin), "numpy_f32": compare(np_image, ref, np_lin, ref_lin)}
    ms = {"reactor": best_time(rgba8, x, y, z, P512, ramp, repeat=repeat),
          "numpy_f32": best_time(numpy_rgba8, x, y, z, P512.astype(np.int64), ramp, repeat=repeat),
          "reactor_constant_table": best_time(constant, x, y, z, ramp, repeat=repeat)}
    return {
        "scene": "perlin", "shape": image.shape, "rgba": image, "accuracy": accuracy, "ms": ms,
        "build_ms": {"rgba8": build_u8, "linear": build_f, "constant_table": build_c},
        "lines": {"dsl": code_lines(__file__, "DSL"), "numpy": code_lines(__file__, "NumPy")},
        # the u8vec4 kernel's codes are the exact sRGB8 codes of the linear kernel's values
        "u8_vs_linear_kernel": int(np.count_nonzero(image[..., :3] != reference_codes(lin))),
        "constant_table_identical": bool(np.array_equal(constant(x, y, z, ramp), image)),
        "colour_range": [float(np.min(lin)), float(np.max(lin))],
    }


def report(r: dict) -> str:
    h, w, _ = r["shape"]
    text = format_report(f"Perlin improved noise, {OCTAVES}-octave fbm through a colour ramp, {w} x {h} RGBA8; "
                         "8-bit codes against float64:", r)
    return (text + f"\n  permutation as a ConstantTable: {r['ms']['reactor_constant_table']:.2f} ms "
            f"(identical image: {r['constant_table_identical']}); u8 kernel vs exact encode of the linear "
            f"kernel: {r['u8_vs_linear_kernel']} codes differ")


def main(argv=None) -> dict:
    return scene_main(argv, __doc__, "perlin", run, report)


if __name__ == "__main__":
    main()
