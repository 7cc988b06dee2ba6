"""Value-noise fbm with the ``fract(sin(dot(...)) * 43758.5453)`` hash and a rotating mat2: glsl-fbm's 2d.glsl.

    python examples/shaders/noise.py [--out DIR] [--size 512] [--repeat 5]

Source: yiwenl/glsl-fbm, ``2d.glsl`` (commit b74844523a7c0d5e4e51965579bc93b3b547e5c3), MIT licence
(package.json "license": "MIT"; the repository ships no LICENSE file). The original is 32 lines, 26 of
code (blank and comment-only lines not counted); all of it is ported. It is a glslify module (``rand``,
``noise``, ``fbm``); the kernel's ``main_image`` (gray = ``fbm(6 * gl_FragCoord.xy / height)``) is ours.

The hash is the famous one and it is chaotic on purpose: at octave 5 its argument
``dot(ip, vec2(12.9898, 4.1414))`` is about 2e4, where one float32 rounding of that dot product
(ulp 2^-9) moves ``sin`` by 2e-3 and the hash by 2e-3 * 43758 = 85, i.e. to another random value. So the
pattern itself depends on float32 arithmetic: the float64 reference computes that dot product as
float32 does (the products and the sum rounded to float32; ``ip`` is an exact integer), and everything
else in float64. A pure float64 evaluation is a different (equally random) texture: reported apart.
The same goes for relaxed precision: relaxed ``sin`` is within 2^-11 of sin, which the hash multiplies
by 43758, so mediump destroys this hash (a known failure of this hash on mobile GPUs). The fix a shader
author applies, ``highp float rand(highp vec2 n)``, is ``with reactor.precision("full"):`` around the
hash in a relaxed kernel: measured as "relaxed, highp hash".
"""
from __future__ import annotations

import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from shader_common import (  # noqa: E402
    best_time, compare, difference_panel, format_report, fragcoords, port_lines, shader_main, timed_build,
    to_codes,
)

import reactor  # noqa: E402
from reactor import Float, mat2, vec2  # noqa: E402
from routines import glsl as gl  # noqa: E402

GLSL_LINES = 26
SCALE = 6.0

# --- DSL port begin
NUM_OCTAVES = 5


def rand(n):
    return gl.fract(gl.sin(gl.dot(n, vec2(12.9898, 4.1414))) * 43758.5453)


def rand_highp(n):   # the mediump fix: `highp float rand(highp vec2 n)`
    with reactor.precision("full"):
        return rand(n)


def noise(p, rand=rand):
    ip = gl.floor(p)
    u = gl.fract(p)
    u = u * u * (3.0 - 2.0 * u)

    res = gl.mix(
        gl.mix(rand(ip), rand(ip + vec2(1.0, 0.0)), u.x),
        gl.mix(rand(ip + vec2(0.0, 1.0)), rand(ip + vec2(1.0, 1.0)), u.x), u.y)
    return res * res


def fbm(x, rand=rand):
    v = 0.0
    a = 0.5
    shift = vec2(100)
    # Rotate to reduce axial bias
    rot = mat2(gl.cos(0.5), gl.sin(0.5), -gl.sin(0.5), gl.cos(0.50))
    for i in range(NUM_OCTAVES):          # a constant loop: unrolled at build time
        v += a * noise(x, rand)
        x = rot @ x * 2.0 + shift
        a *= 0.5
    return v


def main_image(frag_x: Float, frag_y: Float, height: Float) -> Float:
    return fbm(vec2(frag_x, frag_y) / height * SCALE)


def main_image_highp_hash(frag_x: Float, frag_y: Float, height: Float) -> Float:
    return fbm(vec2(frag_x, frag_y) / height * SCALE, rand_highp)
# --- DSL port end


def build(precision: str = "full", highp_hash: bool = False, **options):
    body = main_image_highp_hash if highp_hash else main_image
    name = f"fbm_{precision}" + ("_highp_hash" if highp_hash else "")
    return reactor.kernel(body, name=name, precision=precision, cache=False, **options)


# -- the independent NumPy port ----------------------------------------------------------------------

def numpy_shader(frag_x, frag_y, height, hash_argument_f32: bool = True):
    """fbm in the inputs' precision (float32 or float64). In float64, the hash's dot product is rounded
    as float32 computes it when ``hash_argument_f32`` (see the module docstring)."""
    F = np.result_type(frag_x, frag_y).type
    x = np.broadcast_to(frag_x / F(height) * F(SCALE), np.broadcast_shapes(frag_x.shape, frag_y.shape))
    y = np.broadcast_to(frag_y / F(height) * F(SCALE), x.shape)
    c, s = F(math.cos(0.5)), F(math.sin(0.5))

    def rand(ix, iy):
        if F is np.float64 and hash_argument_f32:
            f32 = np.float32
            arg = (ix.astype(f32) * f32(12.9898) + iy.astype(f32) * f32(4.1414)).astype(np.float64)
        else:
            arg = ix * F(12.9898) + iy * F(4.1414)
        h = np.sin(arg) * F(43758.5453)
        return h - np.floor(h)

    def noise(px, py):
        ix, iy = np.floor(px), np.floor(py)
        ux, uy = px - ix, py - iy
        ux, uy = ux * ux * (F(3) - F(2) * ux), uy * uy * (F(3) - F(2) * uy)
        a, b = rand(ix, iy), rand(ix + F(1), iy)
        cc, d = rand(ix, iy + F(1)), rand(ix + F(1), iy + F(1))
        top = a * (F(1) - ux) + b * ux
        bot = cc * (F(1) - ux) + d * ux
        res = top * (F(1) - uy) + bot * uy
        return res * res

    v, a = np.zeros(x.shape, F), F(0.5)
    for _ in range(NUM_OCTAVES):
        v = v + a * noise(x, y)
        x, y = (c * x - s * y) * F(2) + F(100), (s * x + c * y) * F(2) + F(100)
        a = a * F(0.5)
    return v


def inputs(size: int = 512):
    """The kernel's arguments: gl_FragCoord.x (a row), .y (a column), the height (a scalar)."""
    fx, fy = fragcoords(size, size)
    return fx, fy, np.float32(size)


def reference(args):
    fx, fy, height = args
    return (numpy_shader(fx.astype(np.float64), fy.astype(np.float64), float(height)),)


def run(size: int = 512, repeat: int = 5) -> dict:
    fx, fy, height = inputs(size)
    kernels, build_ms = {}, {}
    for name, args in {"full": ("full", False), "relaxed": ("relaxed", False),
                       "relaxed_highp_hash": ("relaxed", True)}.items():
        kernels[name], build_ms[name] = timed_build(build, *args)
    renders = {name: (k(fx, fy, height),) for name, k in kernels.items()}
    renders["numpy_f32"] = (numpy_shader(fx, fy, height),)
    f64 = fx.astype(np.float64), fy.astype(np.float64), float(size)
    ref = (numpy_shader(*f64),)
    pure = (numpy_shader(*f64, hash_argument_f32=False),)
    ms = {name: best_time(k, fx, fy, height, repeat=repeat) for name, k in kernels.items()}
    ms["numpy_f32"] = best_time(numpy_shader, fx, fy, height, repeat=repeat)
    accuracy = {name: compare(r, ref) for name, r in renders.items()}
    gray = {k: np.repeat(to_codes(v), 3, axis=-1) for k, v in (("full", renders["full"]),
                                                                ("relaxed", renders["relaxed"]), ("ref", ref))}
    panels = [gray["full"], gray["relaxed"], difference_panel(gray["full"], gray["ref"])]
    return {"shader": "noise", "shape": (size, size), "accuracy": accuracy, "ms": ms, "build_ms": build_ms,
            "pure_float64": {"full": compare(renders["full"], pure), "reference": compare(ref, pure)},
            "lines": {"dsl": port_lines(__file__), "glsl": GLSL_LINES}, "panels": panels}


def report(r: dict) -> str:
    h, w = r["shape"]
    text = format_report(f"glsl-fbm 2d (5 octaves of sin-hash value noise), {w} x {h} gray; 8-bit codes "
                         "against float64 (hash argument rounded as float32 does):", r)
    p = r["pure_float64"]["full"]
    return text + (f"\n  against float64 everywhere (hash argument too): full differs in "
                   f"{p['codes_differing']:,} codes (max {p['max_code_diff']}): another texture")


def main(argv=None) -> dict:
    return shader_main(argv, __doc__, "noise", run, report)


if __name__ == "__main__":
    main()
