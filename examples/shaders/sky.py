"""The Preetham daylight sky (acos, cos, exp, pow with negative and fractional exponents): three.js's Sky.

    python examples/shaders/sky.py [--out DIR] [--size 512] [--repeat 5]

Source: mrdoob/three.js, ``examples/jsm/objects/Sky.js`` (commit
0255e15dd1d46b5f00e51398b5052d88720eba9a): ``SkyShader``'s vertex and fragment shaders, "based on
A Practical Analytic Model for Daylight (Preetham), first implemented by Simon Wallner, improved by
Martin Upitis, three.js integration by zz85", MIT licence (three.js). The two shaders are 153 lines,
91 of code (blank and comment-only lines not counted); all of it is ported except the vertex
shader's two position transforms (the rasterizer's business) and the fragment's final
``#include <tonemapping_fragment>`` / ``<colorspace_fragment>`` (three.js's default renderer: no tone
mapping; examples/shaders/tonemap.py ports those chunks).

Parameters of three.js's ``webgl_shaders_sky`` example: turbidity 10, rayleigh 3, mie coefficient
0.005, mie directional g 0.7, the sun 2 degrees above the horizon. The vertex shader's outputs are
the same for every vertex but the position, so it runs once, as a kernel of its own on one element;
its varyings reach the fragment kernel as broadcast scalars (as flat varyings would), with the view
direction of each pixel (``vWorldPosition``, the camera at the origin) as three float32 arrays.
"""
from __future__ import annotations

import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from shader_common import (  # noqa: E402
    best_time, compare, difference_panel, format_report, port_lines, shader_main, timed_build, to_codes,
)

import reactor  # noqa: E402
from reactor import Float, vec2, vec3  # noqa: E402
from routines import glsl as gl  # noqa: E402

GLSL_LINES = 91
ELEVATION, AZIMUTH = 2.0, 180.0          # degrees, as three.js's sky example

# --- DSL port begin
# uniforms (Python constants, three.js's webgl_shaders_sky values)
rayleigh, turbidity, mieCoefficient, mieDirectionalG = 3.0, 10.0, 0.005, 0.7
up = (0.0, 1.0, 0.0)
cameraPosition = (0.0, 0.0, 0.0)

# vertex shader: constants for atmospheric scattering
e = 2.71828182845904523536028747135266249775724709369995957
pi = 3.141592653589793238462643383279502884197169

# wavelength of used primaries, according to preetham
lambda_ = (680E-9, 550E-9, 450E-9)
# this pre-calcuation replaces older TotalRayleigh(vec3 lambda) function:
totalRayleigh = (5.804542996261093E-6, 1.3562911419845635E-5, 3.0265902468824876E-5)

# mie stuff
# K coefficient for the primaries
v = 4.0
K = (0.686, 0.678, 0.666)
# MieConst = pi * pow( ( 2.0 * pi ) / lambda, vec3( v - 2.0 ) ) * K
MieConst = (1.8399918514433978E14, 2.7798023919660528E14, 4.0790479543861094E14)

# earth shadow hack
# cutoffAngle = pi / 1.95;
cutoffAngle = 1.6110731556870734
steepness = 1.5
EE = 1000.0


def sunIntensity(zenithAngleCos):
    zenithAngleCos = gl.clamp(zenithAngleCos, -1.0, 1.0)
    return EE * gl.max(0.0, 1.0 - gl.pow(e, -((cutoffAngle - gl.acos(zenithAngleCos)) / steepness)))


def totalMie(T):
    c = (0.2 * T) * 10E-18
    return 0.434 * c * vec3(*MieConst)


def vertex_main(sun_x: Float, sun_y: Float, sun_z: Float) -> (Float, Float, Float, Float, Float, Float, Float,
                                                               Float, Float, Float, Float):
    sunPosition = vec3(sun_x, sun_y, sun_z)
    vSunDirection = gl.normalize(sunPosition)
    vSunE = sunIntensity(gl.dot(vSunDirection, vec3(*up)))
    vSunfade = 1.0 - gl.clamp(1.0 - gl.exp((sunPosition.y / 450000.0)), 0.0, 1.0)
    rayleighCoefficient = rayleigh - (1.0 * (1.0 - vSunfade))
    # extinction (absorbtion + out scattering)
    # rayleigh coefficients
    vBetaR = vec3(*totalRayleigh) * rayleighCoefficient
    # mie coefficients
    vBetaM = totalMie(turbidity) * mieCoefficient
    return (*vSunDirection, vSunfade, *vBetaR, *vBetaM, vSunE)


# fragment shader: constants for atmospheric scattering
n = 1.0003  # refractive index of air
N = 2.545E25  # number of molecules per unit volume for air at 288.15K and 1013mb (sea level -45 celsius)

# optical length at zenith for molecules
rayleighZenithLength = 8.4E3
mieZenithLength = 1.25E3
# 66 arc seconds -> degrees, and the cosine of that
sunAngularDiameterCos = 0.999956676946448443553574619906976478926848692873900859324

# 3.0 / ( 16.0 * pi )
THREE_OVER_SIXTEENPI = 0.05968310365946075
# 1.0 / ( 4.0 * pi )
ONE_OVER_FOURPI = 0.07957747154594767


def rayleighPhase(cosTheta):
    return THREE_OVER_SIXTEENPI * (1.0 + gl.pow(cosTheta, 2.0))


def hgPhase(cosTheta, g):
    g2 = gl.pow(g, 2.0)
    inverse = 1.0 / gl.pow(1.0 - 2.0 * g * cosTheta + g2, 1.5)
    return ONE_OVER_FOURPI * ((1.0 - g2) * inverse)


def main_image(wx: Float, wy: Float, wz: Float, sdx: Float, sdy: Float, sdz: Float, vSunfade: Float,
               brx: Float, bry: Float, brz: Float, bmx: Float, bmy: Float, bmz: Float,
               vSunE: Float) -> (Float, Float, Float):
    vWorldPosition, vSunDirection = vec3(wx, wy, wz), vec3(sdx, sdy, sdz)
    vBetaR, vBetaM = vec3(brx, bry, brz), vec3(bmx, bmy, bmz)

    direction = gl.normalize(vWorldPosition - vec3(*cameraPosition))

    # optical length
    # cutoff angle at 90 to avoid singularity in next formula.
    zenithAngle = gl.acos(gl.max(0.0, gl.dot(vec3(*up), direction)))
    inverse = 1.0 / (gl.cos(zenithAngle) + 0.15 * gl.pow(93.885 - ((zenithAngle * 180.0) / pi), -1.253))
    sR = rayleighZenithLength * inverse
    sM = mieZenithLength * inverse

    # combined extinction factor
    Fex = gl.exp(-(vBetaR * sR + vBetaM * sM))

    # in scattering
    cosTheta = gl.dot(direction, vSunDirection)

    rPhase = rayleighPhase(cosTheta * 0.5 + 0.5)
    betaRTheta = vBetaR * rPhase

    mPhase = hgPhase(cosTheta, mieDirectionalG)
    betaMTheta = vBetaM * mPhase

    Lin = gl.pow(vSunE * ((betaRTheta + betaMTheta) / (vBetaR + vBetaM)) * (1.0 - Fex), vec3(1.5))
    Lin *= gl.mix(vec3(1.0), gl.pow(vSunE * ((betaRTheta + betaMTheta) / (vBetaR + vBetaM)) * Fex,
                                    vec3(1.0 / 2.0)),
                  gl.clamp(gl.pow(1.0 - gl.dot(vec3(*up), vSunDirection), 5.0), 0.0, 1.0))

    # nightsky
    theta = gl.acos(direction.y)  # elevation --> y-axis, [-pi/2, pi/2]
    phi = gl.atan(direction.z, direction.x)  # azimuth --> x-axis [-pi/2, pi/2]
    uv = vec2(phi, theta) / vec2(2.0 * pi, pi) + vec2(0.5, 0.0)  # noqa: F841 (unused, as in the original)
    L0 = vec3(0.1) * Fex

    # composition + solar disc
    sundisk = gl.smoothstep(sunAngularDiameterCos, sunAngularDiameterCos + 0.00002, cosTheta)
    L0 += (vSunE * 19000.0 * Fex) * sundisk

    texColor = (Lin + L0) * 0.04 + vec3(0.0, 0.0003, 0.00075)

    retColor = gl.pow(texColor, vec3(1.0 / (1.2 + (1.2 * vSunfade))))
    return retColor.r, retColor.g, retColor.b
# --- DSL port end


def build(precision: str = "full", **options):
    return reactor.kernel(main_image, name=f"sky_{precision}", precision=precision, cache=False, **options)


def build_vertex(precision: str = "full", **options):
    return reactor.kernel(vertex_main, name=f"sky_vertex_{precision}", precision=precision, cache=False,
                          **options)


# -- the independent NumPy port ----------------------------------------------------------------------

def numpy_vertex(sun, F=np.float64):
    """The vertex stage's varyings (sun direction, sunfade, betaR, betaM, sunE) in precision F."""
    sun = np.asarray(sun, F)
    sun_dir = sun / np.sqrt((sun * sun).sum())
    zc = np.clip(sun_dir[1], F(-1), F(1))
    sun_e = F(EE) * max(F(0), F(1) - F(e) ** (-((F(cutoffAngle) - np.arccos(zc)) / F(steepness))))
    sunfade = F(1) - np.clip(F(1) - np.exp(sun[1] / F(450000)), F(0), F(1))
    beta_r = np.array(totalRayleigh, F) * (F(rayleigh) - (F(1) - sunfade))
    beta_m = F(0.434) * (F(0.2) * F(turbidity) * F(10E-18)) * np.array(MieConst, F) * F(mieCoefficient)
    return (*sun_dir, sunfade, *beta_r, *beta_m, sun_e)


def numpy_shader(wx, wy, wz, sdx, sdy, sdz, sunfade, brx, bry, brz, bmx, bmy, bmz, sun_e):
    """The fragment stage in NumPy, in the dtype of ``wx``."""
    F = wx.dtype.type
    d = np.stack([wx, wy, wz])
    d = d / np.sqrt((d * d).sum(0))
    sun_dir = np.array([sdx, sdy, sdz], F).reshape(3, 1, 1)
    beta_r, beta_m = np.array([brx, bry, brz], F).reshape(3, 1, 1), np.array([bmx, bmy, bmz], F).reshape(3, 1, 1)
    zenith = np.arccos(np.maximum(F(0), d[1]))
    inverse = F(1) / (np.cos(zenith) + F(0.15) * (F(93.885) - zenith * F(180) / F(pi)) ** F(-1.253))
    fex = np.exp(-(beta_r * (F(rayleighZenithLength) * inverse) + beta_m * (F(mieZenithLength) * inverse)))
    cos_theta = (d * sun_dir).sum(0)
    r_phase = F(THREE_OVER_SIXTEENPI) * (F(1) + (cos_theta * F(0.5) + F(0.5)) ** F(2))
    g = F(mieDirectionalG)
    m_phase = F(ONE_OVER_FOURPI) * ((F(1) - g * g) / (F(1) - F(2) * g * cos_theta + g * g) ** F(1.5))
    ratio = F(sun_e) * ((beta_r * r_phase + beta_m * m_phase) / (beta_r + beta_m))
    lin = (ratio * (F(1) - fex)) ** F(1.5)
    w = np.clip((F(1) - F(sdy)) ** F(5), F(0), F(1))
    lin = lin * (F(1) * (F(1) - w) + (ratio * fex) ** F(0.5) * w)
    t = np.clip((cos_theta - F(sunAngularDiameterCos)) / F(0.00002), F(0), F(1))
    sundisk = t * t * (F(3) - F(2) * t)
    l0 = F(0.1) * fex + F(sun_e) * F(19000) * fex * sundisk
    tex = (lin + l0) * F(0.04) + np.array([0.0, 0.0003, 0.00075], F).reshape(3, 1, 1)
    ret = tex ** (F(1) / (F(1.2) + F(1.2) * F(sunfade)))
    return ret[0], ret[1], ret[2]


def view(size: int):
    """Per-pixel view directions (vWorldPosition, camera at the origin) of a 2:1 image looking at
    the sun's azimuth, 70 degrees wide, the horizon a third up from the bottom."""
    w, h = size, size // 2
    fov = math.radians(70.0)
    x = (np.arange(w) + 0.5) / w * 2.0 - 1.0
    y = 1.0 - (np.arange(h) + 0.5) / h * 2.0
    tx, ty = math.tan(fov / 2), math.tan(fov / 2) * h / w
    pitch = math.radians(10.0)
    dx = np.broadcast_to(x[None, :] * tx, (h, w))
    dy0 = np.broadcast_to(y[:, None] * ty, (h, w))
    dz0 = -np.ones((h, w))
    dy = dy0 * math.cos(pitch) - dz0 * math.sin(pitch)      # pitched up about x
    dz = dy0 * math.sin(pitch) + dz0 * math.cos(pitch)
    return [np.ascontiguousarray(c, dtype=np.float32) for c in (dx, dy, dz)]


def sun_position():
    phi, theta = math.radians(90.0 - ELEVATION), math.radians(AZIMUTH)   # setFromSphericalCoords
    return (math.sin(phi) * math.sin(theta), math.cos(phi), math.sin(phi) * math.cos(theta))


def inputs(size: int = 512):
    """The fragment kernel's arguments: the view directions and the vertex stage's varyings (float32
    scalars, from the NumPy vertex stage in float32)."""
    return (*view(size), *numpy_vertex(np.array(sun_position(), np.float32), np.float32))


def reference(args):
    """float64: the view directions upcast, the vertex stage recomputed in float64."""
    return numpy_shader(*(np.asarray(c, np.float64) for c in args[:3]),
                        *numpy_vertex(np.array(sun_position(), np.float32).astype(np.float64)))


def run(size: int = 512, repeat: int = 5) -> dict:
    world = view(size)
    sun = np.array(sun_position(), np.float32)
    full, build_full = timed_build(build, "full")
    relaxed, build_relaxed = timed_build(build, "relaxed")
    varyings = {p: [np.float32(x[0]) for x in build_vertex(p)(*(np.array([c]) for c in sun))]
                for p in ("full", "relaxed")}
    ref_varyings = numpy_vertex(sun.astype(np.float64))
    renders = {"full": full(*world, *varyings["full"]), "relaxed": relaxed(*world, *varyings["relaxed"]),
               "numpy_f32": numpy_shader(*world, *numpy_vertex(sun, np.float32))}
    ref = numpy_shader(*(c.astype(np.float64) for c in world), *ref_varyings)
    ms = {"full": best_time(full, *world, *varyings["full"], repeat=repeat),
          "relaxed": best_time(relaxed, *world, *varyings["relaxed"], repeat=repeat),
          "numpy_f32": best_time(numpy_shader, *world, *numpy_vertex(sun, np.float32), repeat=repeat)}
    accuracy = {name: compare(r, ref) for name, r in renders.items()}
    vertex_error = max(abs(float(a) - float(b)) / max(abs(float(b)), 1e-30)
                       for a, b in zip(varyings["full"], ref_varyings))
    codes = {k: to_codes(v) for k, v in (("full", renders["full"]), ("relaxed", renders["relaxed"]), ("ref", ref))}
    panels = [codes["full"], codes["relaxed"], difference_panel(codes["relaxed"], codes["ref"])]
    return {"shader": "sky", "shape": world[0].shape, "accuracy": accuracy, "ms": ms,
            "build_ms": {"full": build_full, "relaxed": build_relaxed},
            "vertex_max_relative_error": vertex_error,
            "lines": {"dsl": port_lines(__file__), "glsl": GLSL_LINES}, "panels": panels}


def report(r: dict) -> str:
    h, w = r["shape"]
    return format_report(f"three.js Sky (Preetham), {w} x {h}, sun 2 degrees up; 8-bit codes against float64 "
                         f"(vertex stage within {r['vertex_max_relative_error']:.1e} relative):", r)


def main(argv=None) -> dict:
    return shader_main(argv, __doc__, "sky", run, report)


if __name__ == "__main__":
    main()
