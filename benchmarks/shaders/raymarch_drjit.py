"""examples/shaders/raymarch.py (three.js raymarching) for Dr.Jit's LLVM backend, float32: the GLSL
loops become symbolic loops (``@dr.syntax`` turns ``while``/``if`` on Jit masks into
``dr.while_loop``/``dr.if_stmt``), so one kernel marches every lane until its own exit, as the
DSL's execution mask does; the whole shader is ``dr.freeze``d."""
import drjit as dr
import numpy as np
from drjit.llvm import Array2f, Array3f, Bool, Float, UInt32

EPS = 0.01
OFFSET = EPS * 100.0
LIGHT = (-0.48666426339228763, 0.8111071056538127, -0.3244428422615251)
MOUSE = (0.5, 0.5)
TIME = 0.0


def mod(x, y):
    return x - y * dr.floor(x / y)


def sphere_dist(p):
    q = Array2f(mod(p.x, 3.0), mod(p.z, 3.0)) - 1.5
    return dr.sqrt(q.x * q.x + p.y * p.y + q.y * q.y) - 1.0


def scene_dist(p):
    return dr.minimum(sphere_dist(p), p.y + 1.0)


def fract(x):
    return x - dr.floor(x)


def hsv2rgb(c):
    p = dr.abs(Array3f(fract(c.x + 1.0), fract(c.x + 2.0 / 3.0), fract(c.x + 1.0 / 3.0)) * 6.0 - 3.0)
    return c.z * dr.lerp(Array3f(1.0), dr.clip(p - 1.0, 0.0, 1.0), c.y)


def scene_color(p):
    u = 1.0 - dr.floor(mod(p.x, 2.0))
    v = 1.0 - dr.floor(mod(p.z, 2.0))
    checker = dr.select(((u == 1.0) & (v < 1.0)) | ((u < 1.0) & (v == 1.0)), 0.2, 1.0)
    sphere = hsv2rgb(Array3f((p.z + p.x) / 9.0, 1.0, 1.0))
    return dr.select(sphere_dist(p) < p.y + 1.0, sphere, Array3f(0.5) * checker)


def get_normal(p):
    return dr.normalize(Array3f(
        scene_dist(p + Array3f(EPS, 0.0, 0.0)) - scene_dist(p + Array3f(-EPS, 0.0, 0.0)),
        scene_dist(p + Array3f(0.0, EPS, 0.0)) - scene_dist(p + Array3f(0.0, -EPS, 0.0)),
        scene_dist(p + Array3f(0.0, 0.0, EPS)) - scene_dist(p + Array3f(0.0, 0.0, -EPS))))


@dr.syntax
def get_shadow(ro, rd):
    c, r = Float(0.0), Float(1.0)
    early = Bool(False)
    i = UInt32(0)
    while (i < 50) & ~early:
        h = scene_dist(ro + rd * c)
        if h < EPS:
            early = Bool(True)
        else:
            r = dr.minimum(r, h * 16.0 / c)
            c += h
        i += 1
    return dr.select(early, 0.5, 1.0 - 0.5 + r * 0.5)


@dr.syntax
def ray_color(origin, ray):
    dist, depth = Float(0.0), Float(0.0)
    p = Array3f(origin)
    i = UInt32(0)
    done = Bool(False)
    while (i < 64) & ~done:
        dist = scene_dist(p)
        depth += dist
        p = origin + depth * ray
        done = dr.abs(dist) < EPS
        i += 1
    hit = dr.abs(dist) < EPS
    color, normal = Array3f(0.0), Array3f(0.0)
    if hit:
        light = Array3f(*LIGHT)
        normal = get_normal(p)
        diffuse = dr.clip(dr.dot(light, normal), 0.1, 1.0)
        refl = light - 2.0 * dr.dot(normal, light) * normal
        specular = dr.power(dr.clip(dr.dot(refl, ray), 0.0, 1.0), 10.0)
        shadow = get_shadow(p + normal * OFFSET, light)
        color = (scene_color(p) * diffuse + Array3f(0.8) * specular) * dr.maximum(0.5, shadow)
    return color - dr.square(dr.clip(0.05 * depth, 0.0, 0.6)), p, normal, hit


@dr.syntax
def shade(fx, fy, res_x, res_y):
    p = (Array2f(fx, fy) * 2.0 - Array2f(res_x, res_y)) / dr.minimum(res_x, res_y)
    c_dir = dr.normalize(Array3f(0.0, -0.3, 1.0))
    c_up = dr.cross(c_dir, Array3f(1.0, 0.0, 0.0))
    c_side = dr.cross(c_dir, c_up)
    ray = dr.normalize(c_side * p.x + c_up * p.y + c_dir * 1.3)
    c_pos = Array3f(Float(MOUSE[0] - 0.5), MOUSE[1] * 4.0 - 0.2, TIME) + 0.0 * fx
    color = Array3f(0.0)
    alpha = Float(1.0)
    bounce = UInt32(0)
    active = Bool(True)
    while (bounce < 3) & active:
        c, q, normal, hit = ray_color(c_pos, ray)
        color += alpha * c
        alpha *= 0.3
        ray = dr.normalize(ray - 2.0 * dr.dot(normal, ray) * normal)
        c_pos = q + normal * OFFSET
        active = hit
        bounce += 1
    return color


_frozen = dr.freeze(shade)


def prepare(fx, fy, res_x, res_y):
    gx, gy = np.broadcast_arrays(fx, fy)
    return (Float(np.ascontiguousarray(gx.ravel(), np.float32)), Float(np.ascontiguousarray(gy.ravel(), np.float32)),
            Float(float(res_x)), Float(float(res_y)), gx.shape)


def run(fx, fy, res_x, res_y, shape=None):
    out = _frozen(fx, fy, res_x, res_y)
    dr.eval(out)
    return out


def render(fx, fy, res_x, res_y):
    *p, shape = prepare(fx, fy, res_x, res_y)
    out = run(*p)
    return tuple(np.array(c).reshape(shape) for c in (out.x, out.y, out.z))
