"""three.js's ACES Filmic and AgX tone mappers, then its sRGB OETF, on an HDR exposure chart.

    python examples/shaders/tonemap.py [--out DIR] [--size 512] [--repeat 5]

Source: mrdoob/three.js, ``src/renderers/shaders/ShaderChunk/tonemapping_pars_fragment.glsl.js``
(commit 0ac1f6ab583e183ba7ed865b092b033be85dc790: ``RRTAndODTFit``, ``ACESFilmicToneMapping``,
``agxDefaultContrastApprox``, ``AgXToneMapping``) and ``colorspace_pars_fragment.glsl.js`` (commit
1fcc38baed30e9d15f844a1a8ef72b6fe2cc7567: ``sRGBTransferOETF``), MIT licence. The ported part is
131 lines, 75 of code (blank and comment-only lines not counted); the chunks' other operators
(Linear, Reinhard, Cineon, the unused ``agx``/``agxEotf``, the P3 matrices) are not ported.

What three.js's ``tonemapping_fragment`` and ``colorspace_fragment`` do with a fragment: tone map its
linear colour (``toneMappingExposure`` = 1), then encode with the sRGB OETF. The kernel does it for
both operators and returns six channels (ACES rgb, AgX rgb). The input is an HDR chart: hue across,
exposure from 2^-8 to 2^+8 down, a gray strip on the left; float32, as a half-float render target
would be read. AgX's output is not clamped: its small negative values make ``pow`` in the OETF NaN
(``mix`` then keeps the NaN, in GLSL as here); NaN counts as code 0, as a GPU's clamp gives.
The constant matrices (``transpose``, ``inverse`` of constants) fold at build time, in float32.
"""
from __future__ import annotations

import colorsys
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from shader_common import (  # noqa: E402
    best_time, compare, difference_panel, format_report, port_lines, shader_main, timed_build, to_codes,
)

import reactor  # noqa: E402
from reactor import Float, mat3, vec3, vec4  # noqa: E402
from routines import glsl as gl  # noqa: E402

GLSL_LINES = 75

# --- DSL port begin
toneMappingExposure = 1.0


def saturate(a):
    return gl.clamp(a, 0.0, 1.0)


# source: https://github.com/selfshadow/ltc_code/blob/master/webgl/shaders/ltc/ltc_blit.fs
def RRTAndODTFit(v):
    a = v * (v + 0.0245786) - 0.000090537
    b = v * (0.983729 * v + 0.4329510) + 0.238081
    return a / b


# this implementation of ACES is modified to accommodate a brighter viewing environment.
# the scale factor of 1/0.6 is subjective. see discussion in #19621.
def ACESFilmicToneMapping(color):
    # sRGB => XYZ => D65_2_D60 => AP1 => RRT_SAT
    ACESInputMat = mat3(
        vec3(0.59719, 0.07600, 0.02840),  # transposed from source
        vec3(0.35458, 0.90834, 0.13383),
        vec3(0.04823, 0.01566, 0.83777)
    )
    # ODT_SAT => XYZ => D60_2_D65 => sRGB
    ACESOutputMat = mat3(
        vec3(1.60475, -0.10208, -0.00327),  # transposed from source
        vec3(-0.53108, 1.10813, -0.07276),
        vec3(-0.07367, -0.00605, 1.07602)
    )
    color *= toneMappingExposure / 0.6
    color = ACESInputMat @ color
    # Apply RRT and ODT
    color = RRTAndODTFit(color)
    color = ACESOutputMat @ color
    # Clamp to [0, 1]
    return saturate(color)


# AGX Tone Mapping implementation from
# https://iolite-engine.com/blog_posts/minimal_agx_implementation
# Mean error^2: 3.6705141e-06
def agxDefaultContrastApprox(x):
    x2 = x * x
    x4 = x2 * x2
    return (+ 15.5 * x4 * x2
            - 40.14 * x4 * x
            + 31.96 * x4
            - 6.868 * x2 * x
            + 0.4298 * x2
            + 0.1191 * x
            - 0.00232)


# Input and output encoded as Linear-sRGB.
def AgXToneMapping(color):
    # https://www.itu.int/pub/R-REP-BT.2407-2017
    # matrix provided in row-major order so we transpose
    LINEAR_REC2020_TO_LINEAR_SRGB = gl.transpose(mat3(
        vec3(1.6605, - 0.5876, - 0.0728),
        vec3(- 0.1246, 1.1329, - 0.0083),
        vec3(- 0.0182, - 0.1006, 1.1187)
    ))
    LINEAR_SRGB_TO_LINEAR_REC2020 = gl.inverse(LINEAR_REC2020_TO_LINEAR_SRGB)
    AgXInsetMatrix = mat3(
        vec3(0.856627153315983, 0.137318972929847, 0.11189821299995),
        vec3(0.0951212405381588, 0.761241990602591, 0.0767994186031903),
        vec3(0.0482516061458583, 0.101439036467562, 0.811302368396859)
    )
    AgXOutsetMatrixInv = mat3(
        vec3(0.899796955911611, 0.11142098895748, 0.11142098895748),
        vec3(0.0871996192028351, 0.875575586156966, 0.0871996192028349),
        vec3(0.013003424885555, 0.0130034248855548, 0.801379391839686)
    )
    AgXOutsetMatrix = gl.inverse(AgXOutsetMatrixInv)
    AgxMinEv = - 12.47393  # log2(pow(2, LOG2_MIN) * MIDDLE_GRAY)
    AgxMaxEv = 4.026069    # log2(pow(2, LOG2_MAX) * MIDDLE_GRAY)

    v = color
    v = LINEAR_SRGB_TO_LINEAR_REC2020 @ v
    v = gl.max(vec3(0.0), v)
    v *= toneMappingExposure
    v = AgXInsetMatrix @ v
    # Log2 encoding
    v = gl.max(v, 1e-10)  # avoid 0 or negative numbers for log2
    v = gl.log2(v)
    v = (v - AgxMinEv) / (AgxMaxEv - AgxMinEv)
    v = gl.clamp(v, 0.0, 1.0)
    # Apply sigmoid
    v = agxDefaultContrastApprox(v)
    # Apply AgX look
    # v = agxLook(v, look);
    v = AgXOutsetMatrix @ v
    # Linearize
    v = gl.pow(gl.max(vec3(0.0), v), vec3(2.2))
    v = LINEAR_REC2020_TO_LINEAR_SRGB @ v
    return v


def sRGBTransferOETF(value):
    return vec4(gl.mix(gl.pow(value.rgb, vec3(0.41666)) * 1.055 - vec3(0.055), value.rgb * 12.92,
                       vec3(gl.lessThanEqual(value.rgb, vec3(0.0031308)))), value.a)


def main_image(r: Float, g: Float, b: Float) -> (Float, Float, Float, Float, Float, Float):
    color = vec3(r, g, b)
    aces = sRGBTransferOETF(vec4(ACESFilmicToneMapping(color), 1.0))
    agx = sRGBTransferOETF(vec4(AgXToneMapping(color), 1.0))
    return aces.r, aces.g, aces.b, agx.r, agx.g, agx.b
# --- DSL port end


def build(precision: str = "full", **options):
    return reactor.kernel(main_image, name=f"tonemap_{precision}", precision=precision, cache=False, **options)


# -- the independent NumPy port ----------------------------------------------------------------------

def _m(*columns):
    """A matrix from GLSL column vectors (mat3(c0, c1, c2) is column-major)."""
    return np.array(columns, dtype=np.float64).T


ACES_IN = _m((0.59719, 0.07600, 0.02840), (0.35458, 0.90834, 0.13383), (0.04823, 0.01566, 0.83777))
ACES_OUT = _m((1.60475, -0.10208, -0.00327), (-0.53108, 1.10813, -0.07276), (-0.07367, -0.00605, 1.07602))
REC2020_TO_SRGB = _m((1.6605, -0.5876, -0.0728), (-0.1246, 1.1329, -0.0083), (-0.0182, -0.1006, 1.1187)).T
SRGB_TO_REC2020 = np.linalg.inv(REC2020_TO_SRGB)
AGX_INSET = _m((0.856627153315983, 0.137318972929847, 0.11189821299995),
               (0.0951212405381588, 0.761241990602591, 0.0767994186031903),
               (0.0482516061458583, 0.101439036467562, 0.811302368396859))
AGX_OUTSET = np.linalg.inv(_m((0.899796955911611, 0.11142098895748, 0.11142098895748),
                              (0.0871996192028351, 0.875575586156966, 0.0871996192028349),
                              (0.013003424885555, 0.0130034248855548, 0.801379391839686)))


def numpy_shader(r, g, b):
    """Both operators and the OETF in NumPy, in the inputs' precision; six channels."""
    F = r.dtype.type

    def mul(m, v):                       # m @ v for a 3 x N stack of colours
        m = m.astype(F)
        return np.stack([m[i, 0] * v[0] + m[i, 1] * v[1] + m[i, 2] * v[2] for i in range(3)])

    def oetf(v):
        with np.errstate(invalid="ignore"):
            curve = np.power(v, F(0.41666)) * F(1.055) - F(0.055)
        low = (v <= F(0.0031308)).astype(F)
        return curve * (F(1) - low) + v * F(12.92) * low        # GLSL mix: a NaN curve stays NaN

    c = np.stack([r, g, b])
    x = mul(ACES_IN, c * F(toneMappingExposure / 0.6))
    x = (x * (x + F(0.0245786)) - F(0.000090537)) / (x * (F(0.983729) * x + F(0.4329510)) + F(0.238081))
    aces = oetf(np.clip(mul(ACES_OUT, x), F(0), F(1)))
    v = np.maximum(mul(SRGB_TO_REC2020, c), F(0)) * F(toneMappingExposure)
    v = np.log2(np.maximum(mul(AGX_INSET, v), F(1e-10)))
    v = np.clip((v - F(-12.47393)) / F(4.026069 - -12.47393), F(0), F(1))
    x2 = v * v
    x4 = x2 * x2
    v = (F(15.5) * x4 * x2 - F(40.14) * x4 * v + F(31.96) * x4 - F(6.868) * x2 * v + F(0.4298) * x2
         + F(0.1191) * v - F(0.00232))
    v = np.power(np.maximum(mul(AGX_OUTSET, v), F(0)), F(2.2))
    agx = oetf(mul(REC2020_TO_SRGB, v))
    return (*aces, *agx)


def chart(size: int):
    """An HDR chart, float32 r, g, b: hue across (a gray strip first), exposure 2^+8 (top) to 2^-8."""
    h, w = size // 2, size
    hue = (np.arange(w) + 0.5) / w
    rgb = np.array([colorsys.hsv_to_rgb(t, 0.85, 1.0) for t in hue]).T        # 3 x w, linear
    rgb[:, : w // 10] = 0.18 / 0.18 * 1.0                                      # a neutral strip
    ev = 8.0 - 16.0 * (np.arange(h) + 0.5) / h
    hdr = 0.18 * rgb[:, None, :] * np.exp2(ev)[None, :, None]
    return [np.ascontiguousarray(c, dtype=np.float32) for c in hdr]


def inputs(size: int = 512):
    """The kernel's arguments: the HDR chart's r, g, b."""
    return chart(size)


def reference(args):
    with np.errstate(invalid="ignore"):
        return numpy_shader(*(np.asarray(c, np.float64) for c in args))


def run(size: int = 512, repeat: int = 5) -> dict:
    hdr = inputs(size)
    full, build_full = timed_build(build, "full")
    relaxed, build_relaxed = timed_build(build, "relaxed")
    with np.errstate(invalid="ignore"):
        renders = {"full": full(*hdr), "relaxed": relaxed(*hdr), "numpy_f32": numpy_shader(*hdr)}
        ref = reference(hdr)
        ms = {"full": best_time(full, *hdr, repeat=repeat), "relaxed": best_time(relaxed, *hdr, repeat=repeat),
              "numpy_f32": best_time(numpy_shader, *hdr, repeat=repeat)}
    accuracy = {name: compare(r, ref) for name, r in renders.items()}
    per_operator = {op: {name: compare(r[k:k + 3], ref[k:k + 3]) for name, r in renders.items()}
                    for op, k in (("aces", 0), ("agx", 3))}

    def picture(r):
        return np.concatenate([to_codes(r[:3]), np.full((6, size, 3), 255, np.uint8), to_codes(r[3:])])
    panels = [picture(renders["full"]), picture(renders["relaxed"]),
              difference_panel(picture(renders["relaxed"]), picture(ref))]
    return {"shader": "tonemap", "shape": hdr[0].shape, "accuracy": accuracy, "per_operator": per_operator,
            "ms": ms, "build_ms": {"full": build_full, "relaxed": build_relaxed},
            "lines": {"dsl": port_lines(__file__), "glsl": GLSL_LINES}, "panels": panels}


def report(r: dict) -> str:
    h, w = r["shape"]
    text = format_report(f"three.js ACES Filmic + AgX + sRGB OETF, {w} x {h} HDR chart x 6 channels; "
                         "8-bit codes against float64:", r)
    ops = "; ".join(f"{op}: relaxed {d['relaxed']['codes_differing']:,} codes (max {d['relaxed']['max_code_diff']})"
                    for op, d in r["per_operator"].items())
    return text + "\n  " + ops


def main(argv=None) -> dict:
    return shader_main(argv, __doc__, "tonemap", run, report)


if __name__ == "__main__":
    main()
