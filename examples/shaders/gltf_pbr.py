"""Cook-Torrance GGX with Schlick's Fresnel ``pow(1 - v.h, 5)``: the glTF sample viewer's single-light shader.

    python examples/shaders/gltf_pbr.py [--out DIR] [--size 512] [--repeat 5]

Source: KhronosGroup/glTF-Sample-Viewer, ``shaders/single-light-pbr-frag.glsl`` (commit
ce1705e488ec2f05501805cd54648a4f85431b34, from the glTF-WebGL-PBR days of the repository), MIT
licence (LICENSE.md of that time: "Copyright (c) 2016-2017 Mohamad Moneimne and Contributors").
The original is 71 lines, 55 of code (blank and comment-only lines not counted); all of it is ported.
It declares ``precision mediump float;``: relaxed precision is the author's own choice here.

The fragment shader reads varyings (position, normal, tangent) and four textures (base colour, normal
map, metallic, roughness). The rasterizer and the texture units are the harness's part: a grid of
spheres (roughness across, metallic down, a hue per sphere, an 8-bit ripple normal map), and every
covered pixel's varyings and texels arrive as the kernel's inputs (17 float32 arrays). Uniforms
(light, camera, ``u_Metallic``) are Python constants. The port keeps the original's quirks: the
specular term is multiplied by ``specularColor`` twice, and ``specBRDF`` is 0/0 = NaN where
``n.l`` or ``n.v`` is 0 (the clamp of ``diffuse + specular`` then gives 0, as the float64 reference's).
"""
from __future__ import annotations

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

GLSL_LINES = 55

# --- DSL port begin
M_PI = 3.141592653589793
u_LightPosition = (4.0, 6.0, 10.0)   # uniforms (Python constants)
u_Camera = (0.0, 0.0, 12.0)
u_Metallic = 0.0


def main_image(px: Float, py: Float, pz: Float, nx: Float, ny: Float, nz: Float, tx: Float, ty: Float,
               tz: Float, base_r: Float, base_g: Float, base_b: Float, map_r: Float, map_g: Float,
               map_b: Float, metal_texel: Float, rough_texel: Float) -> (Float, Float, Float):
    v_Position, v_Normal, v_Tangent = vec3(px, py, pz), vec3(nx, ny, nz), vec3(tx, ty, tz)
    baseColor = vec4(base_r, base_g, base_b, 1.0)          # texture2D(u_BaseColorSampler, v_UV)

    # Normal Map
    n = gl.normalize(v_Normal)
    t = gl.normalize(v_Tangent)
    b = gl.cross(n, t)
    tbn = mat3(t, b, n)
    n = vec3(map_r, map_g, map_b)                           # texture2D(u_NormalSampler, v_UV).rgb
    n = gl.normalize(n * 2.0 - 1.0)
    n = gl.normalize(tbn @ n)

    l = gl.normalize(vec3(*u_LightPosition) - v_Position)
    v = gl.normalize(vec3(*u_Camera) - v_Position)
    h = gl.normalize(l + v)
    nDotV = gl.max(0.0, gl.dot(n, v))
    nDotL = gl.max(0.0, gl.dot(n, l))
    nDotH = gl.max(0.0, gl.dot(n, h))
    vDotH = gl.max(0.0, gl.dot(v, h))

    # Fresnel Term: Schlick's Approximation
    metallic = metal_texel                                  # texture2D(u_MetallicSampler, v_UV).x
    specularColor = (baseColor.rgb * metallic) + (vec3(0.04) * (1.0 - metallic))
    f = specularColor + ((1.0 - specularColor) * gl.pow(1.0 - vDotH, 5.0))

    # Geometric Attenuation Term: Schlick-Beckmann
    roughness = rough_texel                                 # texture2D(u_RoughnessSampler, v_UV).x
    a = roughness * roughness  # UE4 definition
    k = ((roughness + 1.0) * (roughness + 1.0)) / 8.0
    g1L = nDotL / ((nDotL * (1.0 - k)) + k)
    g1V = nDotV / ((nDotV * (1.0 - k)) + k)
    g = g1L * g1V

    # Normal Distribution Function: GGX (Trowbridge-Reitz)
    a2 = a * a
    nDotH2 = nDotH * nDotH
    denom = M_PI * (nDotH2 * (a2 - 1.0) + 1.0) * (nDotH2 * (a2 - 1.0) + 1.0)
    d = a2 / denom

    # Specular BRDF
    specBRDF = (d * f * g) / (4.0 * nDotL * nDotV)

    metallic = gl.max(0.5, u_Metallic)  # Hack to look good before environment maps
    diffuseColor = baseColor.rgb * (1.0 - metallic)
    diffuse = vec4(diffuseColor * nDotL, 1.0)
    specular = vec4(specularColor * specBRDF, 1.0)
    gl_FragColor = gl.clamp(diffuse + specular, 0.0, 1.0)
    return gl_FragColor.r, gl_FragColor.g, gl_FragColor.b
# --- DSL port end


def build(precision: str = "full", **options):
    """The port as a ufunc, built at ``precision`` ("full" = highp, "relaxed" = mediump)."""
    return reactor.kernel(main_image, name=f"gltf_pbr_{precision}", precision=precision, cache=False, **options)


# -- the independent float64 (or float32) NumPy port ------------------------------------------------

def numpy_shader(px, py, pz, nx, ny, nz, tx, ty, tz, base_r, base_g, base_b, map_r, map_g, map_b,
                 metal_texel, rough_texel):
    """The same shader in NumPy, vectorized over the pixels, in the inputs' precision."""
    F = px.dtype.type

    def normalize(v):
        return v / np.sqrt((v * v).sum(axis=0))

    pos = np.stack([px, py, pz])
    base = np.stack([base_r, base_g, base_b])
    n = normalize(np.stack([nx, ny, nz]))
    t = normalize(np.stack([tx, ty, tz]))
    b = np.cross(n, t, axis=0)
    tn = normalize(np.stack([map_r, map_g, map_b]) * F(2) - F(1))
    n = normalize(t * tn[0] + b * tn[1] + n * tn[2])               # tbn * n, tbn = (t, b, n) columns
    light = np.array(u_LightPosition, dtype=F)[:, None]
    eye = np.array(u_Camera, dtype=F)[:, None]
    l, v = normalize(light - pos), normalize(eye - pos)
    h = normalize(l + v)
    n_v, n_l = np.maximum((n * v).sum(0), F(0)), np.maximum((n * l).sum(0), F(0))
    n_h, v_h = np.maximum((n * h).sum(0), F(0)), np.maximum((v * h).sum(0), F(0))
    metal, rough = metal_texel, rough_texel
    spec_color = base * metal + F(0.04) * (F(1) - metal)
    fres = spec_color + (F(1) - spec_color) * (F(1) - v_h) ** F(5)
    a = rough * rough
    k = (rough + F(1)) * (rough + F(1)) / F(8)
    g = n_l / (n_l * (F(1) - k) + k) * (n_v / (n_v * (F(1) - k) + k))
    a2 = a * a
    q = n_h * n_h * (a2 - F(1)) + F(1)
    d = a2 / (F(M_PI) * q * q)
    with np.errstate(invalid="ignore", divide="ignore"):
        spec = d * fres * g / (F(4) * n_l * n_v)
    diffuse = base * (F(1) - F(max(0.5, u_Metallic))) * n_l
    out = np.fmin(np.fmax(diffuse + spec_color * spec, F(0)), F(1))   # clamp; NaN -> 0 as the DSL's
    return out[0], out[1], out[2]


# -- the scene: what the rasterizer and the texture units would deliver ------------------------------

COLS, ROWS = 5, 3   # roughness across, metallic down


def scene(size: int):
    """(inputs: 17 float32 arrays over the covered pixels, mask: H x W bool) for a ``size`` wide image."""
    cell = size // COLS
    h, w = cell * ROWS, cell * COLS
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float64)
    col, row = (xx // cell).astype(int), (yy // cell).astype(int)
    u = ((xx % cell) + 0.5) / cell * 2.0 - 1.0
    v = 1.0 - ((yy % cell) + 0.5) / cell * 2.0
    u, v = u * 1.08, v * 1.08                                       # a margin around each sphere
    r2 = u * u + v * v
    mask = r2 < 1.0
    u, v, r2, col, row = u[mask], v[mask], r2[mask], col[mask], row[mask]
    nzc = np.sqrt(1.0 - r2)
    cx, cy = (col - (COLS - 1) / 2) * 2.2, ((ROWS - 1) / 2 - row) * 2.2
    px, py, pz = cx + u, cy + v, nzc
    tx, ty, tz = nzc, np.zeros_like(nzc), -u                         # cross(up, n), unnormalized
    hue = (col * ROWS + row) / (COLS * ROWS)
    base = 0.5 + 0.45 * np.cos(2 * np.pi * (hue[None, :] + np.array([0.0, 0.33, 0.67])[:, None]))
    bump = np.stack([0.15 * np.sin(22.0 * u), 0.15 * np.sin(22.0 * v), np.ones_like(u)])
    bump /= np.sqrt((bump * bump).sum(0))
    texel = np.rint((bump * 0.5 + 0.5) * 255.0) / 255.0             # an 8-bit normal map
    metal = row / (ROWS - 1)
    rough = 0.12 + 0.8 * col / (COLS - 1)
    arrays = [px, py, pz, u, v, nzc, tx, ty, tz, *base, *texel, metal, rough]
    return [np.ascontiguousarray(a, dtype=np.float32) for a in arrays], mask


def image(channels, mask, background=(0.08, 0.08, 0.09)):
    out = np.empty(mask.shape + (3,), np.float64)
    out[...] = background
    for i, c in enumerate(channels):
        out[..., i][mask] = c
    return to_codes([out[..., 0], out[..., 1], out[..., 2]])


def inputs(size: int = 512):
    """The kernel's arguments for a ``size`` wide image (the covered pixels' varyings and texels)."""
    return scene(size)[0]


def reference(args):
    """The float64 render of ``args`` (the NumPy port on float64 copies)."""
    return numpy_shader(*(np.asarray(a, np.float64) for a in args))


def run(size: int = 512, repeat: int = 5) -> dict:
    inputs, mask = scene(size)
    full, build_full = timed_build(build, "full")
    relaxed, build_relaxed = timed_build(build, "relaxed")
    renders = {"full": full(*inputs), "relaxed": relaxed(*inputs),
               "numpy_f32": numpy_shader(*inputs)}
    ref = numpy_shader(*(a.astype(np.float64) for a in inputs))
    ms = {"full": best_time(full, *inputs, repeat=repeat), "relaxed": best_time(relaxed, *inputs, repeat=repeat),
          "numpy_f32": best_time(numpy_shader, *inputs, repeat=repeat)}
    accuracy = {name: compare(r, ref) for name, r in renders.items()}
    panels = [image(renders["full"], mask), image(renders["relaxed"], mask),
              difference_panel(image(renders["relaxed"], mask), image(ref, mask))]
    return {"shader": "gltf_pbr", "pixels": int(mask.sum()), "shape": mask.shape, "accuracy": accuracy, "ms": ms,
            "build_ms": {"full": build_full, "relaxed": build_relaxed},
            "lines": {"dsl": port_lines(__file__), "glsl": GLSL_LINES}, "panels": panels}


def report(r: dict) -> str:
    h, w = r["shape"]
    return format_report(f"glTF single-light GGX, {w} x {h}, {r['pixels']:,} shaded pixels x 3 channels; "
                         "8-bit codes against float64:", r)


def main(argv=None) -> dict:
    return shader_main(argv, __doc__, "gltf_pbr", run, report)


if __name__ == "__main__":
    main()
