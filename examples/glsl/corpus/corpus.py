"""The GLSL corpus: public shaders with permissive licences, each file as its package holds it
(``fetch.py`` re-creates and checks them; ``SOURCES.md`` gives provenance and licences), with
what each takes to run: its stage, its uniforms, its pixel inputs (the same affine function of the
pixel on reactor and in llvmpipe's vertex shader) and an independent float64 evaluation of the same
shader in NumPy, written from the GLSL here. ``benchmarks/bench_glsl.py`` runs every shader on
reactor and on llvmpipe; ``tests/examples/test_glsl_corpus.py`` checks each against its float64
evaluation.

Three source conventions are resolved here, as their own tools would: glslify's ``#pragma glslify:
name = require(module)`` (the module's text inlined once; a renamed export becomes a ``#define``),
three.js's ``#include <chunk>`` (its ShaderChunk) and manim's ``#INSERT file.glsl`` (the file from
``inserts/``).
"""
from __future__ import annotations

import dataclasses
import pathlib
import re
import typing

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
F = np.float32


@dataclasses.dataclass(frozen=True)
class Varying:
    """A fragment shader's interpolated input: GLSL's ``name = expr`` over the quad's corner ``pos``
    in [-1, 1]^2 (llvmpipe's vertex shader; ``{w}``, ``{h}``: the image size), and the same in NumPy
    over pixel centres."""
    name: str
    glsl_type: str
    expr: str
    numpy: typing.Callable[[np.ndarray, np.ndarray, int, int], np.ndarray]  # pos x, pos y (float64), w, h

    def glsl(self, width: int, height: int) -> str:
        return self.expr.format(w=f"{width:.1f}", h=f"{height:.1f}")


@dataclasses.dataclass(frozen=True)
class Shader:
    """One corpus shader: ``path`` (relative to this folder), how it is compiled and run, and its
    float64 evaluation ``reference(inputs, texture)`` giving (H, W, 4) for a fragment shader (the
    rows from the bottom, as OpenGL stores a framebuffer)."""
    name: str
    path: str
    stage: str  # "webgl", "fragment" or "shadertoy"
    uniforms: dict
    reference: typing.Callable  # (list of the pixel inputs, texture, uniforms) -> (H, W, 4) float64
    varyings: tuple = ()
    frag_coord: bool = False
    texture: bool = False
    features: str = ""
    public: bool = True
    licence: str = ""  # the licence file beside the shader's package (relative to this folder)

    def source(self) -> str:
        return assemble(HERE / self.path)

    def inputs(self, width: int, height: int) -> list[np.ndarray]:
        """The kernel's pixel inputs (float64): the varyings, then ``gl_FragCoord`` if it reads it
        (a Shadertoy shader: ``fragCoord``)."""
        x, y = quad_positions(width, height)
        out = [v.numpy(x, y, width, height) for v in self.varyings]
        if self.frag_coord:
            out.append(frag_coord(width, height).astype(float)[..., :2 if self.stage == "shadertoy" else 4])
        return out

    def uniforms_for(self, width: int, height: int) -> dict:
        """The uniforms at this image size (a callable value is called with the size)."""
        return {k: v(width, height) if callable(v) else v for k, v in self.uniforms.items()}


# ---- sources -----------------------------------------------------------------------------------

REQUIRE = re.compile(r"^#pragma glslify:\s*(\w+)\s*=\s*require\(([^)]+)\)\s*$", re.M)
EXPORT = re.compile(r"^#pragma glslify:\s*export\((\w+)\)\s*$", re.M)
INSERT = re.compile(r"^#INSERT (\S+\.glsl)\s*$", re.M)
CHUNK = re.compile(r"^[ \t]*#include <(\w+)>[ \t]*$", re.M)


def assemble(path: pathlib.Path, seen: set | None = None) -> str:
    """A shader's text with its glslify requires and manim inserts resolved."""
    seen = set() if seen is None else seen
    text = path.read_text(encoding="utf-8")

    def require(m: re.Match) -> str:
        name, module = m.group(1), m.group(2).strip()
        found = _module(path.parent, module)
        if found in seen:
            return ""
        seen.add(found)
        body = assemble(found, seen)
        exported = EXPORT.search(body)
        if exported is None:
            raise ValueError(f"{found} exports nothing")
        alias = "" if exported.group(1) == name else f"#define {name} {exported.group(1)}\n"
        return EXPORT.sub("", body) + alias  # glslify renames the export to the local name

    text = REQUIRE.sub(require, text)
    text = CHUNK.sub(lambda m: (HERE / "three.js" / f"{m.group(1)}.glsl").read_text(encoding="utf-8"), text)
    return INSERT.sub(lambda m: (HERE / "manimgl" / "inserts" / m.group(1)).read_text(encoding="utf-8"), text)


def _module(folder: pathlib.Path, module: str) -> pathlib.Path:
    if module.startswith("."):
        base = (folder / module).resolve()
        return base if base.suffix == ".glsl" else base.with_suffix(".glsl") if base.with_suffix(".glsl").is_file() \
            else base / "index.glsl"
    return HERE / module / "index.glsl"  # a package: its index.glsl, beside the others here


# ---- inputs ------------------------------------------------------------------------------------

def quad_positions(width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """The quad's ``pos`` at each pixel centre, rows from the bottom (float64, (H, W) each)."""
    x = (2.0 * (np.arange(width) + 0.5) / width - 1.0)[None, :].repeat(height, 0)
    y = (2.0 * (np.arange(height) + 0.5) / height - 1.0)[:, None].repeat(width, 1)
    return x, y


def frag_coord(width: int, height: int) -> np.ndarray:
    """``gl_FragCoord`` at each pixel, rows from the bottom: (x + 0.5, y + 0.5, 0.5, 1)."""
    x, y = np.meshgrid(np.arange(width) + 0.5, np.arange(height) + 0.5)
    return np.stack([x, y, np.full_like(x, 0.5), np.ones_like(x)], -1).astype(F)


def test_image(width: int, height: int) -> np.ndarray:
    """The texture the post-processing shaders read: smooth colour waves and a hard edge, float32
    RGBA in [0, 1], one texel per pixel (row 0 is ``v = 0``, as OpenGL uploads it)."""
    v, u = np.meshgrid((np.arange(height) + 0.5) / height, (np.arange(width) + 0.5) / width, indexing="ij")
    r = 0.5 + 0.5 * np.sin(9.0 * u + 2.0 * v)
    g = 0.5 + 0.5 * np.cos(7.0 * v - 3.0 * u * v)
    b = np.where((u - 0.6) ** 2 + (v - 0.4) ** 2 < 0.05, 0.9, 0.2 + 0.3 * u)
    return np.stack([r, g, b, 0.5 + 0.5 * u], -1).astype(F)


def sample(image: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """``texture(image, uv)``, bilinear with clamp to edge, in float64."""
    h, w = image.shape[:2]
    img = image.astype(float)
    x = np.clip(uv[..., 0] * w - 0.5, 0, w - 1)
    y = np.clip(uv[..., 1] * h - 0.5, 0, h - 1)
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    x1, y1 = np.minimum(x0 + 1, w - 1), np.minimum(y0 + 1, h - 1)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    top = img[y0, x0] * (1 - fx) + img[y0, x1] * fx
    bottom = img[y1, x0] * (1 - fx) + img[y1, x1] * fx
    return top * (1 - fy) + bottom * fy


UV = Varying("vUv", "vec2", "pos * 0.5 + 0.5", lambda x, y, w, h: np.stack([x * 0.5 + 0.5, y * 0.5 + 0.5], -1))


def rgba(rgb: np.ndarray, a) -> np.ndarray:
    return np.concatenate([rgb, np.broadcast_to(np.asarray(a, float)[..., None] if np.ndim(a) else a,
                                                rgb.shape[:-1] + (1,))], -1)


# ---- float64 evaluations, one per shader -------------------------------------------------------

def aces(inputs, image, u):
    uv = inputs[0]
    tex = sample(image, uv)
    color = tex[..., :3] * (u["exposure"] / 0.6)
    into = np.array([[0.59719, 0.07600, 0.02840], [0.35458, 0.90834, 0.13383], [0.04823, 0.01566, 0.83777]])
    out = np.array([[1.60475, -0.10208, -0.00327], [-0.53108, 1.10813, -0.07276], [-0.07367, -0.00605, 1.07602]])
    color = color @ into  # mat3(columns) * v, the columns as rows here
    a = color * (color + 0.0245786) - 0.000090537
    b = color * (0.983729 * color + 0.4329510) + 0.238081
    return rgba(np.clip((a / b) @ out, 0.0, 1.0), tex[..., 3])


def color_correction(inputs, image, u):
    uv = inputs[0]
    tex = sample(image, uv)
    return rgba(np.array(u["mulRGB"]) * (tex[..., :3] + np.array(u["addRGB"])) ** np.array(u["powRGB"]), tex[..., 3])


def dot_screen(inputs, image, u):
    uv = inputs[0]
    tex = sample(image, uv)
    s, c = np.sin(u["angle"]), np.cos(u["angle"])
    t = uv * np.array(u["tSize"]) - np.array(u["center"])
    px, py = (c * t[..., 0] - s * t[..., 1]) * u["scale"], (s * t[..., 0] + c * t[..., 1]) * u["scale"]
    average = tex[..., :3].sum(-1) / 3.0
    value = average * 10.0 - 5.0 + np.sin(px) * np.sin(py) * 4.0
    return rgba(np.repeat(value[..., None], 3, -1), tex[..., 3])


def hue_saturation(inputs, image, u):
    uv = inputs[0]
    tex = sample(image, uv)
    angle = u["hue"] * 3.14159265
    s, c = np.sin(angle), np.cos(angle)
    w = (np.array([2.0 * c, -np.sqrt(3.0) * s - c, np.sqrt(3.0) * s - c]) + 1.0) / 3.0
    rgb = tex[..., :3]
    rgb = np.stack([rgb @ w, rgb @ w[[2, 0, 1]], rgb @ w[[1, 2, 0]]], -1)
    average = rgb.sum(-1, keepdims=True) / 3.0
    sat = u["saturation"]
    factor = 1.0 - 1.0 / (1.001 - sat) if sat > 0 else -sat
    return rgba(rgb + (average - rgb) * factor, tex[..., 3])


def sepia(inputs, image, u):
    uv = inputs[0]
    tex = sample(image, uv)
    a, c = u["amount"], tex[..., :3]
    m = np.array([[1.0 - 0.607 * a, 0.769 * a, 0.189 * a], [0.349 * a, 1.0 - 0.314 * a, 0.168 * a],
                  [0.272 * a, 0.534 * a, 1.0 - 0.869 * a]])
    return rgba(np.minimum(1.0, c @ m.T), tex[..., 3])


def sobel(inputs, image, u):
    uv = inputs[0]
    texel = 1.0 / np.array(u["resolution"])
    t = {(i, j): sample(image, uv + texel * np.array([i, j]))[..., 0] for i in (-1, 0, 1) for j in (-1, 0, 1)}
    gx = -t[-1, -1] - 2 * t[-1, 0] - t[-1, 1] + t[1, -1] + 2 * t[1, 0] + t[1, 1]
    gy = -t[-1, -1] - 2 * t[0, -1] - t[1, -1] + t[-1, 1] + 2 * t[0, 1] + t[1, 1]
    g = np.sqrt(gx * gx + gy * gy)
    return rgba(np.repeat(g[..., None], 3, -1), 1.0)


def technicolor(inputs, image, u):
    uv = inputs[0]
    tex = sample(image, uv)
    gb = (tex[..., 1] + tex[..., 2]) * 0.5
    return np.stack([tex[..., 0], gb, gb, np.ones_like(gb)], -1)


def vignette(inputs, image, u):
    uv = inputs[0]
    tex = sample(image, uv)
    p = (uv - 0.5) * u["offset"]
    t = (p * p).sum(-1, keepdims=True)
    return rgba(tex[..., :3] * (1 - t) + (1.0 - u["darkness"]) * t, tex[..., 3])


def agx(inputs, image, u):
    """three.js's AgX (rec 2020 inset, log2 encoding, contrast polynomial, outset, 2.2 power),
    then its sRGB OETF."""
    tex = sample(image, inputs[0])
    srgb_to_2020 = np.array([[0.6274, 0.0691, 0.0164], [0.3293, 0.9195, 0.0880], [0.0433, 0.0113, 0.8956]])
    rec2020_to_srgb = np.array([[1.6605, -0.1246, -0.0182], [-0.5876, 1.1329, -0.1006], [-0.0728, -0.0083, 1.1187]])
    inset = np.array([[0.856627153315983, 0.137318972929847, 0.11189821299995],
                      [0.0951212405381588, 0.761241990602591, 0.0767994186031903],
                      [0.0482516061458583, 0.101439036467562, 0.811302368396859]])
    outset = np.array([[1.1271005818144368, -0.1413297634984383, -0.14132976349843826],
                       [-0.11060664309660323, 1.157823702216272, -0.11060664309660294],
                       [-0.016493938717834573, -0.016493938717834257, 1.2519364065950405]])
    lo, hi = -12.47393, 4.026069
    c = tex[..., :3] * u["toneMappingExposure"]
    c = c @ srgb_to_2020 @ inset  # mat3(columns) * v is v times the columns as rows
    c = np.clip((np.log2(np.maximum(c, 1e-10)) - lo) / (hi - lo), 0.0, 1.0)
    c = 15.5 * c ** 6 - 40.14 * c ** 5 + 31.96 * c ** 4 - 6.868 * c ** 3 + 0.4298 * c ** 2 + 0.1191 * c - 0.00232
    c = np.maximum(0.0, c @ outset) ** 2.2
    c = np.clip(c @ rec2020_to_srgb, 0.0, 1.0)
    c = np.where(c <= 0.0031308, c * 12.92, c ** 0.41666 * 1.055 - 0.055)
    return rgba(c, tex[..., 3])


def rsi(r0, rd, sr):
    a = (rd * rd).sum(-1)
    b = 2.0 * (rd * r0).sum(-1)
    c = (r0 * r0).sum(-1) - sr * sr
    d = b * b - 4.0 * a * c
    root = np.sqrt(np.maximum(d, 0.0))
    return np.where(d < 0, 1e5, (-b - root) / (2.0 * a)), np.where(d < 0, -1e5, (-b + root) / (2.0 * a))


def atmosphere(inputs, _image, u):
    """glsl-atmosphere's example: 16 primary and 8 secondary samples, an early return where the ray
    misses the atmosphere, then the example's exposure."""
    position = inputs[0]
    r = position / np.linalg.norm(position, axis=-1, keepdims=True)
    r0 = np.array([0.0, 6372e3, 0.0])
    p_sun = np.array(u["uSunPos"], float)
    p_sun = p_sun / np.linalg.norm(p_sun)
    i_sun, r_planet, r_atmos = 22.0, 6371e3, 6471e3
    k_rlh, k_mie, sh_rlh, sh_mie, g = np.array([5.5e-6, 13.0e-6, 22.4e-6]), 21e-6, 8e3, 1.2e3, 0.758
    r0s = np.broadcast_to(r0, r.shape)
    px, py = rsi(r0s, r, r_atmos)
    miss = px > py
    py = np.minimum(py, rsi(r0s, r, r_planet)[0])
    i_step = (py - px) / 16.0
    total_rlh, total_mie = np.zeros(r.shape), np.zeros(r.shape)
    i_od_rlh, i_od_mie = np.zeros(r.shape[:-1]), np.zeros(r.shape[:-1])
    mu = r @ p_sun
    pi = 3.141592
    p_rlh = 3.0 / (16.0 * pi) * (1.0 + mu * mu)
    p_mie = 3.0 / (8.0 * pi) * ((1.0 - g * g) * (mu * mu + 1.0)) / ((1.0 + g * g - 2.0 * mu * g) ** 1.5 * (2.0 + g * g))
    i_time = np.zeros(r.shape[:-1])
    for _ in range(16):
        i_pos = r0 + r * (i_time + i_step * 0.5)[..., None]
        height = np.linalg.norm(i_pos, axis=-1) - r_planet
        od_rlh, od_mie = np.exp(-height / sh_rlh) * i_step, np.exp(-height / sh_mie) * i_step
        i_od_rlh, i_od_mie = i_od_rlh + od_rlh, i_od_mie + od_mie
        j_step = rsi(i_pos, np.broadcast_to(p_sun, i_pos.shape), r_atmos)[1] / 8.0
        j_time = np.zeros(r.shape[:-1])
        j_od_rlh, j_od_mie = np.zeros(r.shape[:-1]), np.zeros(r.shape[:-1])
        for _ in range(8):
            j_pos = i_pos + p_sun * (j_time + j_step * 0.5)[..., None]
            j_height = np.linalg.norm(j_pos, axis=-1) - r_planet
            j_od_rlh = j_od_rlh + np.exp(-j_height / sh_rlh) * j_step
            j_od_mie = j_od_mie + np.exp(-j_height / sh_mie) * j_step
            j_time = j_time + j_step
        attn = np.exp(-(k_mie * (i_od_mie + j_od_mie)[..., None] + k_rlh * (i_od_rlh + j_od_rlh)[..., None]))
        total_rlh = total_rlh + od_rlh[..., None] * attn
        total_mie = total_mie + od_mie[..., None] * attn
        i_time = i_time + i_step
    color = i_sun * (p_rlh[..., None] * k_rlh * total_rlh + (p_mie * k_mie)[..., None] * total_mie)
    color = np.where(miss[..., None], 0.0, color)
    return rgba(1.0 - np.exp(-1.0 * color), 1.0)


BAYER8 = np.array([0, 32, 8, 40, 2, 34, 10, 42, 48, 16, 56, 24, 50, 18, 58, 26, 12, 44, 4, 36, 14, 46, 6, 38,
                   60, 28, 52, 20, 62, 30, 54, 22, 3, 35, 11, 43, 1, 33, 9, 41, 51, 19, 59, 27, 49, 17, 57, 25,
                   15, 47, 7, 39, 13, 45, 5, 37, 63, 31, 55, 23, 61, 29, 53, 21])


def dither(inputs, image, u):
    """glsl-dither's example: an 8x8 Bayer threshold on the luma of the texture, times two."""
    uv, coord = inputs
    tex = sample(image, uv)
    x = np.mod(coord[..., 0], 8.0).astype(int)
    y = np.mod(coord[..., 1], 8.0).astype(int)
    limit = (BAYER8[x + y * 8] + 1.0) / 64.0
    luma = tex[..., :3] @ np.array([0.299, 0.587, 0.114])
    keep = np.where(luma < limit, 0.0, 1.0)
    return rgba(tex[..., :3] * keep[..., None], 1.0) * 2.0


#: manim's own palette (its default_config.yml), 8-bit colours as a scene passes them: on code
#: values, so a flat region is no tie between two codes
MANIM_COLORS = [tuple(int(h[k:k + 2], 16) / 255 for k in (1, 3, 5)) for h in (
    "#1C758A", "#29ABCA", "#58C4DD", "#9CDCEB", "#C7E9F1", "#FFF1B6", "#F4D345", "#E1A158", "#C78D46")]


def mandelbrot(inputs, _image, u):
    """manimgl's Mandelbrot: escape time with a smooth count, mapped through a 9-colour map."""
    xyz = inputs[0]
    c = xyz[..., 0] + 1j * xyz[..., 1]
    z = np.zeros_like(c)
    n_escape = np.full(c.shape, -1.0)
    for n in range(int(u["n_steps"])):
        z = np.where(n_escape < 0, z * z + c, z)
        out = (np.abs(z) > 2.0) & (n_escape < 0)
        n_escape = np.where(out, n + np.log(2.0) / np.log(np.abs(z)) + 0.5 * np.abs(c), n_escape)
    colors = np.array(MANIM_COLORS)
    alpha = np.clip((np.sqrt(np.maximum(n_escape, 0.0)) - 1.5) / (8.0 - 1.5), 0.0, 1.0)
    k = np.minimum((alpha * 8).astype(int), 7)
    t = (8.0 * alpha - k)[..., None]
    color = colors[k] * (1 - t) + colors[k + 1] * t
    color = np.where((n_escape < 0)[..., None], 0.0, color)
    return rgba(color, u["opacity"])


def fbm(inputs, _image, u):
    """glsl-fbm's 2d fbm: five octaves of a sin-hash value noise, rotated. ``fract(sin(a) * 43758.5)``
    magnifies the rounding of ``a`` 43758 times, so the hash's argument is rounded to float32 as the
    shader computes it (a float64 argument gives a different, equally random texture)."""
    x, y = inputs[0] / u["height"] * 6.0, inputs[1] / u["height"] * 6.0
    c, s = np.cos(0.5), np.sin(0.5)

    def rand(ix, iy):
        a = (ix.astype(F) * F(12.9898) + iy.astype(F) * F(4.1414)).astype(float)
        h = np.sin(a) * 43758.5453
        return h - np.floor(h)

    def noise(px, py):
        ix, iy = np.floor(px), np.floor(py)
        ux, uy = px - ix, py - iy
        ux, uy = ux * ux * (3 - 2 * ux), uy * uy * (3 - 2 * uy)
        top = rand(ix, iy) * (1 - ux) + rand(ix + 1, iy) * ux
        bottom = rand(ix, iy + 1) * (1 - ux) + rand(ix + 1, iy + 1) * ux
        res = top * (1 - uy) + bottom * uy
        return res * res

    v, a = np.zeros(x.shape), 0.5
    for _ in range(5):
        v = v + a * noise(x, y)
        x, y = (c * x - s * y) * 2.0 + 100.0, (s * x + c * y) * 2.0 + 100.0
        a *= 0.5
    return v


def rings(inputs, _image, u):
    """examples/glsl/rings.frag (ours): rings drifting with time."""
    width, height = u["iResolution"][:2]
    p = (2.0 * inputs[0] - np.array([width, height])) / height
    r = np.hypot(p[..., 0], p[..., 1])
    k = ((0.5 + 0.5 * np.cos(24.0 * r - 3.0 * u["iTime"])) * np.exp(-1.5 * r))[..., None]
    col = np.array([0.08, 0.1, 0.2]) * (1 - k) + np.array([1.0, 0.75, 0.3]) * k
    col = np.where((r < 0.1)[..., None], 1.0, col)
    return rgba(col ** (1.0 / 2.2), 1.0)


def op_mult(arrays, _u):
    lhs, rhs, _ = arrays
    return [lhs.astype(float) * rhs.astype(float)]


def logistic_regression(arrays, u):
    """One gradient step of Kompute's logistic regression: the four buffers it writes."""
    xi, xj, y, win, _, _, bin_, _, _ = [a.astype(float) for a in arrays]
    z = win[0] * xi + win[1] * xj + bin_[0]
    y_hat = 1.0 / (1.0 + np.exp(-z))
    dz = y_hat - y
    m = u["m"]
    loss = -(y * np.log(y_hat) + (1.0 - y) * np.log(1.0 - y_hat))
    return [(1.0 / m) * xi * dz, (1.0 / m) * xj * dz, (1.0 / m) * dz, loss]


def op_mult_arrays(n: int, rng) -> list[np.ndarray]:
    return [rng.uniform(-2, 2, n).astype(F), rng.uniform(-2, 2, n).astype(F), np.zeros(n, F)]


def logistic_arrays(n: int, rng) -> list[np.ndarray]:
    """Kompute's test data, at scale: two features, labels 0/1, weights and bias, outputs zeroed."""
    xi, xj = rng.uniform(0, 1, n).astype(F), rng.uniform(0, 1, n).astype(F)
    y = (xi + xj + rng.normal(0, 0.3, n) > 1.0).astype(F)
    zero = np.zeros(n, F)
    return [xi, xj, y, np.array([0.3, -0.2], F), zero, zero, np.array([0.1], F), zero, zero]


@dataclasses.dataclass(frozen=True)
class ComputeShader:
    """A compute shader: its buffers in binding order (``arrays(n, rng)``), the bindings it writes,
    and its float64 evaluation of those (``reference(arrays, uniforms)``)."""
    name: str
    path: str
    uniforms: dict
    arrays: typing.Callable
    written: tuple
    reference: typing.Callable
    features: str = ""
    public: bool = True
    licence: str = ""

    def source(self) -> str:
        return assemble(HERE / self.path)


# ---- the corpus --------------------------------------------------------------------------------

THREE = "three.js/{}.frag"


def _post(name: str, file: str, uniforms: dict, reference, features: str) -> Shader:
    return Shader(name, THREE.format(file), "webgl", uniforms, reference, varyings=(UV,), texture=True,
                  features=features, licence="three.js/LICENSE")


CORPUS: list[Shader] = [
    _post("aces", "ACESFilmicToneMappingShader", {"exposure": 1.5}, aces, "mat3 constants, helpers, #define"),
    _post("color_correction", "ColorCorrectionShader",
          {"powRGB": (1.8, 2.0, 2.2), "mulRGB": (1.1, 1.0, 0.9), "addRGB": (0.05, 0.0, 0.02)},
          color_correction, "pow of vectors"),
    _post("dot_screen", "DotScreenShader", {"center": (0.5, 0.5), "angle": 1.57, "scale": 1.0,
                                            "tSize": (256.0, 256.0)}, dot_screen, "sin, cos, a helper"),
    _post("hue_saturation", "HueSaturationShader", {"hue": 0.3, "saturation": 0.4}, hue_saturation,
          "swizzles, a branch on a uniform, writes to gl_FragColor.rgb"),
    _post("sepia", "SepiaShader", {"amount": 1.0}, sepia, "component writes"),
    _post("sobel", "SobelOperatorShader", {"resolution": lambda w, h: (float(w), float(h))}, sobel,
          "nine texture taps, const mat3 indexed"),
    _post("technicolor", "TechnicolorShader", {}, technicolor, "texture"),
    _post("vignette", "VignetteShader", {"offset": 1.0, "darkness": 1.0}, vignette, "mix"),
    Shader("atmosphere", "glsl-atmosphere/example/example.frag", "webgl", {"uSunPos": (0.0, 0.1, -1.0)},
           atmosphere, varyings=(Varying("vPosition", "vec3", "vec3(pos, -1.0)",
                                         lambda x, y, w, h: np.stack([x, y, -np.ones_like(x)], -1)),),
           features="nested loops (16 x 8), early return from a helper, exp, pow, glslify",
           licence="glsl-atmosphere/LICENSE"),
    Shader("dither", "glsl-dither/example/index.frag", "webgl", {}, dither, texture=True, frag_coord=True,
           varyings=(Varying("vUv", "vec2", "vec2((pos.x + 1.0) / 2.0, 1.0 - (pos.y + 1.0) / 2.0)",
                             lambda x, y, w, h: np.stack([(x + 1.0) / 2.0, 1.0 - (y + 1.0) / 2.0], -1)),),
           features="mediump, integer arithmetic, 64 branches, gl_FragCoord, glslify (two modules)",
           licence="glsl-dither/LICENSE.md"),
    Shader("mandelbrot", "manimgl/mandelbrot_fractal/frag.glsl", "fragment",
           {"parameter": (0.0, 0.0), "opacity": 1.0, "n_steps": 30.0, "mandelbrot": 1.0,
            "shading": (0.0, 0.0, 0.0), "light_position": (0.0, 0.0, 10.0), "camera_position": (0.0, 0.0, 10.0),
            **{f"color{k}": c for k, c in enumerate(MANIM_COLORS)}},
           mandelbrot, varyings=(Varying("xyz_coords", "vec3", "vec3(pos.x * 1.5 - 0.5, pos.y * 1.5, 0.0)",
                                         lambda x, y, w, h: np.stack([x * 1.5 - 0.5, y * 1.5, np.zeros_like(x)], -1)),),
           features="a loop with break on a uniform bound, arrays indexed per pixel, log, #INSERT",
           licence="manimgl/LICENSE.md"),
]

CORPUS += [
    Shader("fbm", "../fbm2d.frag", "fragment", {"height": lambda w, h: float(h)}, fbm,
           varyings=(Varying("frag_x", "float", "(pos.x * 0.5 + 0.5) * {w}", lambda x, y, w, h: (x * 0.5 + 0.5) * w),
                     Varying("frag_y", "float", "(pos.y * 0.5 + 0.5) * {h}", lambda x, y, w, h: (y * 0.5 + 0.5) * h)),
           features="a loop of 5 octaves, a sin hash, mat2 rotation (the noise example's GLSL; our main)",
           licence="../fbm2d.frag"),  # MIT, named in the file's header
    Shader("agx", "../agx_output.frag", "webgl", {"toneMappingExposure": 2.0}, agx, varyings=(UV,), texture=True,
           features="three.js's AgX and sRGB chunks, unchanged (the tonemap example's GLSL; our main): "
                    "log2, pow, const mat3 products, #include <chunk>", licence="three.js/LICENSE"),
    Shader("rings", "../rings.frag", "shadertoy", {"iResolution": lambda w, h: (float(w), float(h), 1.0),
                                                   "iTime": 1.0}, rings, frag_coord=True,
           features="Shadertoy's mainImage (ours, not counted as public)", public=False),
]

COMPUTE: list[ComputeShader] = [
    ComputeShader("op_mult", "kompute/ShaderOpMult.comp", {}, op_mult_arrays, (2,), op_mult,
                  "three buffers, specialization constants", licence="kompute/LICENSE"),
    ComputeShader("logistic_regression", "kompute/ShaderLogisticRegression.comp", {"m": 4.0}, logistic_arrays,
                  (4, 5, 7, 8), logistic_regression,
                  "nine buffers, weights read at constant indices, exp, log, a specialization constant",
                  licence="kompute/LICENSE"),
]
