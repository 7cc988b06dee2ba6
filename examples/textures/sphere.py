"""Ray-cast spheres, texture-mapped and normal-mapped with a photograph, lit with Blinn-Phong.

    python examples/textures/sphere.py [--out DIR] [--size 512] [--repeat 5]

Two kernels. ``normal_map`` turns the photograph (matplotlib's Grace Hopper, an RGBA8
``Texture2D[u8vec4, "repeat"]``) into a tangent-space normal map: the height is the Rec.709 luma
of the sRGB codes, its central differences come from ``fetch`` at the four neighbours (wrapping:
the map tiles seamlessly), the normal ``normalize(-s dh/dx, -s dh/dy, 1)`` is stored as RGBA8 codes
with ``routines.pixels.encode(n * 0.5 + 0.5, "unorm8")`` and the height in alpha. x follows the
texture's u (columns), y its v (rows, downwards): the map's own convention, matched by the tangent
frame below.

``render`` is the fragment shader, per pixel: a primary ray from a pinhole camera, the nearest of
three spheres (a Python loop over them at build time: one ``Select`` chain), the hit's normal,
spherical UVs (``u = atan(n.z, n.x) / 2 pi``, ``v = acos(n.y) / pi``; each sphere has its own
tiling, 2 x 1 for the large one, 4 x 2 for the small ones: the ``"repeat"`` wrap mode at work, and
seamless at the ``atan`` cut), the photo sampled bilinearly as an RGBA8
``Texture2D[u8vec4, "repeat", "linear"]`` (filtered in its sRGB codes, as a GL_RGBA8 texture is,
then decoded with the sRGB formula: the DSL has no sRGB texture format), the normal map sampled the
same way and moved to world space by the tangent frame (T along u, B = n x T along v, n),
Blinn-Phong (``gl.pow(n.h, 40)``) under a key light and a sky/ground ambient, and
``srgb8_encode`` into a ``u8vec4``: the PNG is the (H, W, 4) uint8 array the kernel returns.

The NumPy reference is the same scene written with NumPy arrays (``np.arctan2``, ``np.arccos``,
its own bilinear filter with ``np.mod`` for the wrap) in float64 and on float32 arrays. Pixels on a
sphere's silhouette are chaotic in any float32 evaluation (a ray grazing a sphere hits in one
precision and misses in the other), so a few codes differ there by a lot, as they do for NumPy
float32.
"""
from __future__ import annotations

import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from textures_common import (  # noqa: E402
    best_time, code_lines, compare, format_report, load_photo, numpy_codes_f32, reference_codes, scene_main,
    timed_build, with_alpha,
)

import reactor  # noqa: E402
from reactor import Float, Int, Select, Texture2D, u8vec4, vec3  # noqa: E402
from routines import glsl as gl  # noqa: E402
from routines.pixels import encode, srgb8_encode  # noqa: E402

#: (centre, radius, uv tiling, u offset): the photo's centre faces the camera on the large sphere
SPHERES = [((0.0, 0.0, 0.0), 1.25, (2.0, 1.0), 0.5),
           ((-2.05, -0.6, 0.8), 0.65, (4.0, 2.0), 0.125),
           ((2.05, -0.6, 0.8), 0.65, (4.0, 2.0), 0.125)]
EYE = (0.0, 0.0, -4.0)
FOCAL = 2.0              # the image plane at z = 2 in front of the eye, the image 2 units high
LIGHT = (-0.8, 0.55, -0.4)
LIGHT_COLOUR = (1.25, 1.15, 1.0)
SKY, GROUND = (0.16, 0.19, 0.26), (0.05, 0.04, 0.03)
SHININESS, SPECULAR = 40.0, 0.5
BUMP = 4.0               # normal-map strength: height units per texel
LUMA = (0.2126, 0.7152, 0.0722)
ASPECT = 0.625           # image height / width


def _unit(v):
    n = math.sqrt(sum(c * c for c in v))
    return tuple(c / n for c in v)


L_DIR = _unit(LIGHT)


# --- DSL begin
def height(photo, x, y):
    return gl.dot(photo.fetch(x, y).rgb, vec3(*LUMA))


def normal_map(x: Int, y: Int, photo: Texture2D[u8vec4, "repeat"]) -> u8vec4:
    dx = (height(photo, x + 1, y) - height(photo, x - 1, y)) * 0.5
    dy = (height(photo, x, y + 1) - height(photo, x, y - 1)) * 0.5
    n = gl.normalize(vec3(-BUMP * dx, -BUMP * dy, 1.0)) * 0.5 + 0.5
    return u8vec4(encode(n.x, "unorm8"), encode(n.y, "unorm8"), encode(n.z, "unorm8"),
                  encode(height(photo, x, y), "unorm8"))


def srgb_to_linear(c):
    return Select(c <= 0.04045, c / 12.92, gl.pow((c + 0.055) / 1.055, 2.4))


def shade(sx, sy, photo, nmap, highp_normalize=False):
    """The linear colour of the pixel at image-plane coordinates (sx, sy) (``highp_normalize``:
    full-precision normalize in a relaxed kernel)."""
    hp = {"precision": "full"} if highp_normalize else {}
    eye = vec3(*EYE)
    rd = gl.normalize(vec3(sx, sy, FOCAL), **hp)
    t, hit = Float(1e30), Int(-1)
    for k, (centre, radius, _, _) in enumerate(SPHERES):     # the nearest sphere, unrolled
        oc = eye - vec3(*centre)
        b = gl.dot(oc, rd)
        h = b * b - (gl.dot(oc, oc) - radius * radius)
        tk = -b - gl.sqrt(gl.max(h, 0.0))
        closer = (h > 0.0) & (tk > 0.0) & (tk < t)
        t, hit = Select(closer, tk, t), Select(closer, k, hit)

    def pick(values):                                           # a per-sphere constant, per lane
        out = values[0]
        for k in range(1, len(values)):
            out = Select(hit == k, values[k], out)
        return out
    centre = vec3(*(pick([s[0][i] for s in SPHERES]) for i in range(3)))
    n = (eye + rd * t - centre) / pick([s[1] for s in SPHERES])
    u = (gl.atan(n.z, n.x) * (0.5 / math.pi) + pick([s[3] for s in SPHERES])) * pick([s[2][0] for s in SPHERES])
    v = gl.acos(gl.clamp(n.y, -1.0, 1.0)) * (1.0 / math.pi) * pick([s[2][1] for s in SPHERES])

    tangent = vec3(-n.z, 0.0, n.x) * gl.inversesqrt(gl.max(n.x * n.x + n.z * n.z, 1e-20))   # along u
    bitangent = gl.cross(n, tangent)                                                          # along v
    m = nmap.sample(u, v).xyz * 2.0 - 1.0
    nn = gl.normalize(tangent * m.x + bitangent * m.y + n * m.z, **hp)
    albedo = srgb_to_linear(photo.sample(u, v).rgb)

    light, view = vec3(*L_DIR), -rd
    half = gl.normalize(light + view, **hp)
    diffuse = gl.max(gl.dot(nn, light), 0.0)
    specular = SPECULAR * gl.pow(gl.max(gl.dot(nn, half), 0.0), SHININESS) * Select(diffuse > 0.0, 1.0, 0.0)
    ambient = gl.mix(vec3(*GROUND), vec3(*SKY), nn.y * 0.5 + 0.5)
    lit = albedo * (ambient + vec3(*LIGHT_COLOUR) * diffuse) + vec3(*LIGHT_COLOUR) * specular
    background = gl.mix(vec3(0.02, 0.025, 0.04), vec3(0.10, 0.13, 0.20), gl.clamp(sy * 0.5 + 0.5, 0.0, 1.0))
    return Select(hit >= 0, lit, background)


# "repeat" costs half of this kernel's time: the wrap is an integer remainder, which x86 has no
# vector instruction for (16 scalar idivs per coordinate; with "clamp" the kernel takes 5.5 ms, not
# 10.2). Kept: the tiling across the atan seam is what the scene shows.
def render(sx: Float, sy: Float, photo: Texture2D[u8vec4, "repeat", "linear"],
           nmap: Texture2D[u8vec4, "repeat", "linear"]) -> u8vec4:
    c = shade(sx, sy, photo, nmap)
    return u8vec4(srgb8_encode(c.r), srgb8_encode(c.g), srgb8_encode(c.b), 255)


def render_linear(sx: Float, sy: Float, photo: Texture2D[u8vec4, "repeat", "linear"],
                  nmap: Texture2D[u8vec4, "repeat", "linear"]) -> vec3:
    return shade(sx, sy, photo, nmap)
# --- DSL end


def render_hp_normalize(sx: Float, sy: Float, photo: Texture2D[u8vec4, "repeat", "linear"],
                        nmap: Texture2D[u8vec4, "repeat", "linear"]) -> u8vec4:
    """``render`` with full-precision ``normalize`` (built relaxed: the rest stays relaxed)."""
    c = shade(sx, sy, photo, nmap, highp_normalize=True)
    return u8vec4(srgb8_encode(c.r), srgb8_encode(c.g), srgb8_encode(c.b), 255)


def render_linear_hp_normalize(sx: Float, sy: Float, photo: Texture2D[u8vec4, "repeat", "linear"],
                               nmap: Texture2D[u8vec4, "repeat", "linear"]) -> vec3:
    return shade(sx, sy, photo, nmap, highp_normalize=True)


def build(body, precision="full"):
    return reactor.kernel(body, cache=False, precision=precision, name=f"{body.__name__}_{precision}")


# --- NumPy begin
def np_normal_map(photo):
    """(H, W, 4) uint8 -> the normal map's float values in [0, 1] (before quantization), float64."""
    h = (photo[..., :3] / 255.0) @ np.array(LUMA)
    dx = (np.roll(h, -1, axis=1) - np.roll(h, 1, axis=1)) * 0.5
    dy = (np.roll(h, -1, axis=0) - np.roll(h, 1, axis=0)) * 0.5
    n = np.stack([-BUMP * dx, -BUMP * dy, np.ones_like(h)], -1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return np.concatenate([n * 0.5 + 0.5, h[..., None]], -1)


def np_bilinear(tex, u, v):
    """GL_LINEAR with GL_REPEAT: ``tex`` (H, W, C) uint8 read as unorm, at (u, v) in u's dtype."""
    F = u.dtype.type
    th, tw = tex.shape[:2]
    x, y = u * F(tw) - F(0.5), v * F(th) - F(0.5)
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    xi, yi = x0.astype(np.int64), y0.astype(np.int64)
    t = tex.astype(F) / F(255)

    def at(dx, dy):
        return t[np.mod(yi + dy, th), np.mod(xi + dx, tw)]
    return ((at(0, 0) * (F(1) - fx) + at(1, 0) * fx) * (F(1) - fy)
            + (at(0, 1) * (F(1) - fx) + at(1, 1) * fx) * fy)


def np_shade(sx, sy, photo, nmap):
    """Linear RGB (H, W, 3) of the scene, in the dtype of ``sx``."""
    F = sx.dtype.type

    def vec(c):
        return np.array(c, F)

    def dot(a, b):
        return (a * b).sum(-1, dtype=F)
    sx, sy = np.broadcast_arrays(sx, sy)
    rd = np.stack([sx, sy, np.full(sx.shape, F(FOCAL))], -1)
    rd = rd / np.sqrt(dot(rd, rd))[..., None]
    best = np.full(sx.shape, np.inf, F)
    hit = np.full(sx.shape, -1)
    for k, (centre, radius, _, _) in enumerate(SPHERES):
        oc = vec(EYE) - vec(centre)
        b = rd @ oc
        h = b * b - (oc @ oc - F(radius) ** 2)
        with np.errstate(invalid="ignore"):
            tk = -b - np.sqrt(h)
        closer = (h > 0) & (tk > 0) & (tk < best)
        best, hit = np.where(closer, tk, best), np.where(closer, k, hit)
    on = hit >= 0
    sphere = np.array([list(c) + [r, tile[0], tile[1], off] for c, r, tile, off in SPHERES], F)[np.maximum(hit, 0)]
    t = np.where(on, best, F(0))[..., None]
    n = (vec(EYE) + rd * t - sphere[..., :3]) / sphere[..., 3:4]
    u = (np.arctan2(n[..., 2], n[..., 0]) / F(2 * np.pi) + sphere[..., 6]) * sphere[..., 4]
    v = np.arccos(np.clip(n[..., 1], F(-1), F(1))) / F(np.pi) * sphere[..., 5]
    tangent = np.stack([-n[..., 2], np.zeros_like(u), n[..., 0]], -1)
    tangent /= np.sqrt(np.maximum(n[..., 0] ** 2 + n[..., 2] ** 2, F(1e-20)))[..., None]
    bitangent = np.cross(n, tangent)
    m = np_bilinear(nmap, u, v)[..., :3] * F(2) - F(1)
    nn = tangent * m[..., :1] + bitangent * m[..., 1:2] + n * m[..., 2:3]
    nn /= np.sqrt(dot(nn, nn))[..., None]
    c = np_bilinear(photo, u, v)[..., :3]
    albedo = np.where(c <= F(0.04045), c / F(12.92), ((c + F(0.055)) / F(1.055)) ** F(2.4))
    view = -rd
    half = vec(L_DIR) + view
    half /= np.sqrt(dot(half, half))[..., None]
    diffuse = np.maximum(nn @ vec(L_DIR), F(0))[..., None]
    specular = F(SPECULAR) * np.maximum(dot(nn, half), F(0))[..., None] ** F(SHININESS) * (diffuse > 0)
    ambient = vec(GROUND) + (vec(SKY) - vec(GROUND)) * (nn[..., 1:2] * F(0.5) + F(0.5))
    lit = albedo * (ambient + vec(LIGHT_COLOUR) * diffuse) + vec(LIGHT_COLOUR) * specular
    s = np.clip(sy * F(0.5) + F(0.5), F(0), F(1))[..., None]
    background = vec((0.02, 0.025, 0.04)) * (F(1) - s) + vec((0.10, 0.13, 0.20)) * s
    return np.where(on[..., None], lit, background)
# --- NumPy end


def numpy_rgba8(sx, sy, photo, nmap):
    """The NumPy float32 render, through to RGBA8 codes (what is timed against the kernel)."""
    return with_alpha(numpy_codes_f32(np_shade(sx, sy, photo, nmap)))


def inputs(size: int):
    """Image-plane coordinates of the pixel centres (the image 2 units high, y up): a (1, W) row and
    an (H, 1) column, float32; the photo as RGBA8."""
    w, h = size, max(1, round(size * ASPECT))
    sx = ((2.0 * (np.arange(w) + 0.5) - w) / h).astype(np.float32)[None, :]
    sy = ((h - 2.0 * (np.arange(h) + 0.5)) / h).astype(np.float32)[:, None]
    return sx, sy


def run(size: int = 512, repeat: int = 5) -> dict:
    sx, sy = inputs(size)
    photo = with_alpha(load_photo())                  # the texture keeps the photograph's 512 x 600
    nm_kernel, build_nm = timed_build(build, normal_map)
    rgba8, build_u8 = timed_build(build, render)
    linear, build_f = timed_build(build, render_linear)
    relaxed, build_r = timed_build(build, render, "relaxed")
    relaxed_linear = build(render_linear, "relaxed")
    hp_normalize = build(render_hp_normalize, "relaxed")
    hp_normalize_linear = build(render_linear_hp_normalize, "relaxed")

    th, tw = photo.shape[:2]
    xs, ys = np.arange(tw, dtype=np.int32)[None, :], np.arange(th, dtype=np.int32)[:, None]
    nmap = nm_kernel(xs, ys, photo)
    nm_ref = np_normal_map(photo)
    nm_diff = np.abs(nmap.astype(np.int16) - np.rint(nm_ref * 255).astype(np.int16))

    image = rgba8(sx, sy, photo, nmap)
    ref_lin = np_shade(sx.astype(np.float64), sy.astype(np.float64), photo, nmap)
    ref = reference_codes(ref_lin)
    np_lin = np_shade(sx, sy, photo, nmap)
    renders = {"reactor": (image, linear(sx, sy, photo, nmap)),
               "relaxed": (relaxed(sx, sy, photo, nmap), relaxed_linear(sx, sy, photo, nmap)),
               "relaxed_hp_norm": (hp_normalize(sx, sy, photo, nmap), hp_normalize_linear(sx, sy, photo, nmap)),
               "numpy_f32": (numpy_rgba8(sx, sy, photo, nmap), np_lin)}
    accuracy = {name: compare(codes, ref, lin, ref_lin) for name, (codes, lin) in renders.items()}
    ms = {"reactor": best_time(rgba8, sx, sy, photo, nmap, repeat=repeat),
          "relaxed": best_time(relaxed, sx, sy, photo, nmap, repeat=repeat),
          "relaxed_hp_norm": best_time(hp_normalize, sx, sy, photo, nmap, repeat=repeat),
          "numpy_f32": best_time(numpy_rgba8, sx, sy, photo, nmap, repeat=repeat),
          "normal_map": best_time(nm_kernel, xs, ys, photo, repeat=repeat),
          "normal_map_numpy_f64": best_time(np_normal_map, photo, repeat=repeat)}
    silhouette = _silhouette(sx, sy)
    off = np.abs(image[..., :3].astype(np.int16) - ref[..., :3].astype(np.int16)).max(-1) > 1
    return {
        "scene": "sphere", "shape": image.shape, "rgba": image, "accuracy": accuracy, "ms": ms,
        "build_ms": {"rgba8": build_u8, "linear": build_f, "relaxed": build_r, "normal_map": build_nm},
        "lines": {"dsl": code_lines(__file__, "DSL"), "numpy": code_lines(__file__, "NumPy")},
        "u8_vs_linear_kernel": int(np.count_nonzero(image[..., :3] != reference_codes(renders["reactor"][1]))),
        "normal_map": {"codes": int(nm_diff.size), "codes_differing": int(np.count_nonzero(nm_diff)),
                       "max_code_diff": int(nm_diff.max())},
        "coverage": float(np.mean(silhouette["hit"])),
        "over_1_off_silhouette": int(np.count_nonzero(off & ~silhouette["edge"])),
    }


def _silhouette(sx, sy):
    """Which pixels' rays hit a sphere (float64), and the pixels next to a change of sphere or of
    hit/miss (where float32 may pick another sphere)."""
    F = np.float64
    sxb, syb = np.broadcast_arrays(sx.astype(F), sy.astype(F))
    rd = np.stack([sxb, syb, np.full(sxb.shape, FOCAL)], -1)
    rd /= np.linalg.norm(rd, axis=-1, keepdims=True)
    best, ids = np.full(sxb.shape, np.inf), np.full(sxb.shape, -1)
    for k, (centre, radius, _, _) in enumerate(SPHERES):
        oc = np.array(EYE) - np.array(centre)
        b = rd @ oc
        h = b * b - (oc @ oc - radius ** 2)
        tk = -b - np.sqrt(np.maximum(h, 0.0))
        closer = (h > 0) & (tk > 0) & (tk < best)
        best, ids = np.where(closer, tk, best), np.where(closer, k, ids)
    hit = ids >= 0
    edge = np.zeros_like(hit)
    for axis in (0, 1):
        for step in (1, -1):
            edge |= np.roll(ids, step, axis=axis) != ids
    return {"hit": hit, "edge": edge}


def report(r: dict) -> str:
    h, w, _ = r["shape"]
    text = format_report(f"three photo-textured, normal-mapped spheres, {w} x {h} RGBA8; 8-bit codes against "
                         "float64:", r)
    nm = r["normal_map"]
    return (text + f"\n  normal map kernel {r['ms']['normal_map']:.2f} ms (NumPy float64 "
            f"{r['ms']['normal_map_numpy_f64']:.2f} ms): {nm['codes_differing']} of {nm['codes']:,} codes differ "
            f"from NumPy's (max {nm['max_code_diff']})\n  codes more than 1 off away from silhouettes (full): "
            f"{r['over_1_off_silhouette']}; u8 kernel vs exact encode of the linear kernel: "
            f"{r['u8_vs_linear_kernel']} codes differ")


def main(argv=None) -> dict:
    return scene_main(argv, __doc__, "sphere", run, report)


if __name__ == "__main__":
    main()
