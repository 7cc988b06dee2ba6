"""A sphere tracer with soft shadows and three reflection bounces: three.js's raymarching example.

    python examples/shaders/raymarch.py [--out DIR] [--size 512] [--repeat 5]

Source: mrdoob/three.js, ``examples/webgl_raymarching_reflect.html`` (commit
012f3897179d6374659a9a2a9878cf1631ffbac9), the fragment shader by gam0022, MIT licence (three.js).
The fragment shader is 184 lines, 110 of code (blank and comment-only lines not counted); all of it
is ported. Uniforms: ``resolution`` arrives as two broadcast scalars, ``mouse`` = (0.5, 0.5) and
``time`` = 0 are constants.

Every pixel marches at most 64 steps, leaves the loop when ``abs(dist) < EPS`` (per lane: the loop
runs while any lane of the vector is still marching), then a shadow ray of at most 50 steps that
returns early where it hits, then up to two reflections that stop per pixel when a ray misses. So the
vector's lanes end their loops at different steps: reactor's execution mask (a loop runs while any
lane is in it; ``break`` and ``return`` act per lane) does what a GPU's does.

The port is written as the GLSL is, in plain Python: ``for`` loops with ``break``, ``if``/``else``,
``getShadow``'s early ``return`` inside its loop, ``a ? b : c`` as ``b if a else c``; on per-lane values
each acts per pixel (``reactor.syntax``: a loop that can leave early runs at run time). What it spells
differently: the ``out`` parameters of ``getRayColor`` become a returned tuple, and GLSL constants of
vector type are tuples at module level (``vec3`` needs a build). The original reads ``hit``
uninitialized when a ray misses (an ``out bool`` never written): the port takes the evident intent,
``hit = false``, as does the float64 reference.
"""
from __future__ import annotations

import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from shader_common import (  # noqa: E402
    best_time, compare, difference_panel, format_report, fragcoords, port_lines, shader_main, timed_build,
    timed_call, to_codes,
)

import reactor  # noqa: E402
from reactor import Float, vec2, vec3, vec4  # noqa: E402
from routines import glsl as gl  # noqa: E402

GLSL_LINES = 110
MOUSE = (0.5, 0.5)
TIME = 0.0

# --- DSL port begin
EPS = 0.01
OFFSET = EPS * 100.0
lightDir = (-0.48666426339228763, 0.8111071056538127, -0.3244428422615251)


# distance functions
def onRep(p, interval):
    q = gl.mod(p.xz, interval) - interval * 0.5
    return vec3(q.x, p.y, q.y)


def sphereDist(p, r):
    return gl.length(onRep(p, 3.0)) - r


def floorDist(p):
    return gl.dot(p, vec3(0.0, 1.0, 0.0)) + 1.0


def minVec4(a, b):
    return a if a.a < b.a else b


def checkeredPattern(p):
    u = 1.0 - gl.floor(gl.mod(p.x, 2.0))
    v = 1.0 - gl.floor(gl.mod(p.z, 2.0))
    return 0.2 if (u == 1.0 and v < 1.0) or (u < 1.0 and v == 1.0) else 1.0


def hsv2rgb(c):
    K = vec4(1.0, 2.0 / 3.0, 1.0 / 3.0, 3.0)
    p = gl.abs(gl.fract(c.xxx + K.xyz) * 6.0 - K.www)
    return c.z * gl.mix(K.xxx, gl.clamp(p - K.xxx, 0.0, 1.0), c.y)


def sceneDist(p):
    return gl.min(
        sphereDist(p, 1.0),
        floorDist(p)
    )


def sceneColor(p):
    return minVec4(
        # 3 * 6 / 2 = 9
        vec4(hsv2rgb(vec3((p.z + p.x) / 9.0, 1.0, 1.0)), sphereDist(p, 1.0)),
        vec4(vec3(0.5) * checkeredPattern(p), floorDist(p))
    )


def getNormal(p):
    return gl.normalize(vec3(
        sceneDist(p + vec3(EPS, 0.0, 0.0)) - sceneDist(p + vec3(-EPS, 0.0, 0.0)),
        sceneDist(p + vec3(0.0, EPS, 0.0)) - sceneDist(p + vec3(0.0, -EPS, 0.0)),
        sceneDist(p + vec3(0.0, 0.0, EPS)) - sceneDist(p + vec3(0.0, 0.0, -EPS))
    ))


def getShadow(ro, rd):
    h = 0.0
    c = 0.0
    r = 1.0
    shadowCoef = 0.5
    for t in range(50):
        h = sceneDist(ro + rd * c)
        if h < EPS:
            return shadowCoef
        r = gl.min(r, h * 16.0 / c)
        c += h
    return 1.0 - shadowCoef + r * shadowCoef


def getRayColor(origin, ray):             # -> color, out p, out normal, out hit
    # marching loop
    dist = 0.0
    depth = 0.0
    p = origin
    for i in range(64):
        dist = sceneDist(p)
        depth += dist
        p = origin + depth * ray
        if gl.abs(dist) < EPS:
            break

    # hit check and calc color
    color = vec3(0.0)
    normal = vec3(0.0)
    hit = False
    if gl.abs(dist) < EPS:
        normal = getNormal(p)
        diffuse = gl.clamp(gl.dot(vec3(*lightDir), normal), 0.1, 1.0)
        specular = gl.pow(gl.clamp(gl.dot(gl.reflect(vec3(*lightDir), normal), ray), 0.0, 1.0), 10.0)
        shadow = getShadow(p + normal * OFFSET, vec3(*lightDir))
        color = (sceneColor(p).rgb * diffuse + vec3(0.8) * specular) * gl.max(0.5, shadow)
        hit = True
    else:
        color = vec3(0.0)
    return color - gl.pow(gl.clamp(0.05 * depth, 0.0, 0.6), 2.0), p, normal, hit


def main_image(frag_x: Float, frag_y: Float, res_x: Float, res_y: Float) -> (Float, Float, Float):
    resolution = vec2(res_x, res_y)
    mouse = vec2(*MOUSE)
    time = TIME
    # fragment position
    p = (vec2(frag_x, frag_y) * 2.0 - resolution) / gl.min(resolution.x, resolution.y)

    # camera and ray
    cPos = vec3(mouse.x - 0.5, mouse.y * 4.0 - 0.2, time)
    cDir = gl.normalize(vec3(0.0, -0.3, 1.0))
    cUp = gl.cross(cDir, vec3(1.0, 0.0, 0.0))
    cSide = gl.cross(cDir, cUp)
    targetDepth = 1.3
    ray = gl.normalize(cSide * p.x + cUp * p.y + cDir * targetDepth)

    color = vec3(0.0)
    alpha = 1.0
    for i in range(3):
        c, q, normal, hit = getRayColor(cPos, ray)
        color += alpha * c
        alpha *= 0.3
        ray = gl.normalize(gl.reflect(ray, normal))
        cPos = q + normal * OFFSET
        if not hit:
            break
    return color.r, color.g, color.b
# --- DSL port end


def build(precision: str = "full", **options):
    return reactor.kernel(main_image, name=f"raymarch_{precision}", precision=precision, cache=False, **options)


# -- the independent NumPy port: the same loops over masks of pixels ----------------------------------

def numpy_shader(frag_x, frag_y, res_x, res_y, steps: dict | None = None):
    """The shader over whole images in NumPy, in the inputs' precision: each loop runs on the pixels
    still in it (their indices), as the GPU's lanes do. ``steps`` collects march-loop iteration counts."""
    F = np.result_type(frag_x, frag_y).type
    fx, fy = np.broadcast_arrays(frag_x, frag_y)
    shape = fx.shape
    fx, fy = fx.ravel().astype(F), fy.ravel().astype(F)
    n = fx.size
    eps, offset = F(EPS), F(OFFSET)
    light = np.array(lightDir, F)[:, None]

    def mod(x, y):
        return x - F(y) * np.floor(x / F(y))

    def sphere_dist(p):
        qx, qz = mod(p[0], 3.0) - F(1.5), mod(p[2], 3.0) - F(1.5)
        return np.sqrt(qx * qx + p[1] * p[1] + qz * qz) - F(1)

    def scene_dist(p):
        return np.minimum(sphere_dist(p), p[1] + F(1))

    def normalize(v):
        return v / np.sqrt((v * v).sum(0))

    def reflect(i, nn):
        return i - F(2) * (nn * i).sum(0) * nn

    def scene_color(p):
        hue = (p[2] + p[0]) / F(9)
        k = np.array([1.0, 2.0 / 3.0, 1.0 / 3.0], F)[:, None]
        frac = (hue + k) - np.floor(hue + k)
        hsv = np.clip(np.abs(frac * F(6) - F(3)) - F(1), F(0), F(1))
        u = F(1) - np.floor(mod(p[0], 2.0))
        v = F(1) - np.floor(mod(p[2], 2.0))
        checker = np.where(((u == 1) & (v < 1)) | ((u < 1) & (v == 1)), F(0.2), F(1.0))
        return np.where(sphere_dist(p) < p[1] + F(1), hsv, F(0.5) * checker)

    def normal_at(p):
        e = [np.array(v, F)[:, None] * eps for v in ((1, 0, 0), (0, 1, 0), (0, 0, 1))]
        return normalize(np.stack([scene_dist(p + d) - scene_dist(p - d) for d in e]))

    def shadow(ro):
        m = ro.shape[1]
        c, r = np.zeros(m, F), np.ones(m, F)
        result = np.full(m, F(-1))
        live = np.arange(m)
        for _ in range(50):
            h = scene_dist(ro[:, live] + light * c[live])
            early = h < eps
            result[live[early]] = F(0.5)
            live, h = live[~early], h[~early]
            with np.errstate(divide="ignore"):
                r[live] = np.minimum(r[live], h * F(16) / c[live])
            c[live] += h
            if not live.size:
                break
        return np.where(result >= 0, result, F(1) - F(0.5) + r * F(0.5))

    def ray_color(origin, ray):
        m = origin.shape[1]
        depth, dist = np.zeros(m, F), np.zeros(m, F)
        p = origin.copy()
        live = np.arange(m)
        count = np.zeros(m, np.int32)
        for _ in range(64):
            d = scene_dist(p[:, live])
            dist[live] = d
            depth[live] += d
            p[:, live] = origin[:, live] + depth[live] * ray[:, live]
            count[live] += 1
            live = live[~(np.abs(d) < eps)]
            if not live.size:
                break
        if steps is not None:
            steps.setdefault("march", []).append(count)
        hit = np.abs(dist) < eps
        color, normal = np.zeros((3, m), F), np.zeros((3, m), F)
        if hit.any():
            ph, rh = p[:, hit], ray[:, hit]
            nn = normal_at(ph)
            diffuse = np.clip((light * nn).sum(0), F(0.1), F(1))
            specular = np.clip((reflect(light, nn) * rh).sum(0), F(0), F(1)) ** F(10)
            sh = shadow(ph + nn * offset)
            color[:, hit] = (scene_color(ph) * diffuse + F(0.8) * specular) * np.maximum(F(0.5), sh)
            normal[:, hit] = nn
        return color - np.clip(F(0.05) * depth, F(0), F(0.6)) ** F(2), p, normal, hit

    rx, ry = F(res_x), F(res_y)
    px, py = (fx * F(2) - rx) / min(rx, ry), (fy * F(2) - ry) / min(rx, ry)
    c_dir = normalize(np.array([0.0, -0.3, 1.0], F)[:, None])
    c_up = np.cross(c_dir, np.array([1.0, 0.0, 0.0], F)[:, None], axis=0)
    c_side = np.cross(c_dir, c_up, axis=0)
    ray = normalize(c_side * px + c_up * py + c_dir * F(1.3))
    c_pos = np.repeat(np.array([MOUSE[0] - 0.5, MOUSE[1] * 4.0 - 0.2, TIME], F)[:, None], n, axis=1)
    color, alpha = np.zeros((3, n), F), np.ones(n, F)
    live = np.arange(n)
    for _ in range(3):
        c, q, nn, hit = ray_color(c_pos[:, live], ray[:, live])
        color[:, live] += alpha[live] * c
        alpha[live] *= F(0.3)
        ray[:, live] = normalize(reflect(ray[:, live], nn))
        c_pos[:, live] = q + nn * offset
        live = live[hit]
        if not live.size:
            break
    return tuple(ch.reshape(shape) for ch in color)


def inputs(size: int = 512):
    """The kernel's arguments: gl_FragCoord.x (a row), .y (a column), resolution (two scalars)."""
    fx, fy = fragcoords(size, size)
    return fx, fy, np.float32(size), np.float32(size)


def reference(args, steps: dict | None = None):
    fx, fy, rx, ry = args
    return numpy_shader(fx.astype(np.float64), fy.astype(np.float64), float(rx), float(ry), steps)


def run(size: int = 512, repeat: int = 5) -> dict:
    fx, fy, *res = inputs(size)
    full, build_full = timed_build(build, "full")
    relaxed, build_relaxed = timed_build(build, "relaxed")
    steps: dict = {}
    numpy_f32, numpy_ms = timed_call(numpy_shader, fx, fy, *res)     # ~1 s: timed once
    renders = {"full": full(fx, fy, *res), "relaxed": relaxed(fx, fy, *res), "numpy_f32": numpy_f32}
    ref = reference((fx, fy, *res), steps)
    ms = {"full": best_time(full, fx, fy, *res, repeat=repeat),
          "relaxed": best_time(relaxed, fx, fy, *res, repeat=repeat), "numpy_f32": numpy_ms}
    accuracy = {name: compare(r, ref) for name, r in renders.items()}
    first = steps["march"][0]
    codes = {k: to_codes(v) for k, v in (("full", renders["full"]), ("relaxed", renders["relaxed"]), ("ref", ref))}
    panels = [codes["full"], codes["relaxed"], difference_panel(codes["full"], codes["ref"])]
    return {"shader": "raymarch", "shape": (size, size), "accuracy": accuracy, "ms": ms,
            "build_ms": {"full": build_full, "relaxed": build_relaxed},
            "march_steps": {"min": int(first.min()), "max": int(first.max()), "mean": float(first.mean())},
            "lines": {"dsl": port_lines(__file__), "glsl": GLSL_LINES}, "panels": panels}


def report(r: dict) -> str:
    h, w = r["shape"]
    s = r["march_steps"]
    return format_report(f"three.js raymarching (64-step march, 50-step soft shadow, 3 bounces), {w} x {h}; "
                         f"primary rays take {s['min']} to {s['max']} steps (mean {s['mean']:.1f}); "
                         "8-bit codes against float64:", r)


def main(argv=None) -> dict:
    return shader_main(argv, __doc__, "raymarch", run, report)


if __name__ == "__main__":
    main()
