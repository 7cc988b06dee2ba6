"""examples/shaders/noise.py (glsl-fbm 2d) for Dr.Jit's LLVM backend, float32, ``dr.freeze``d; the
five octaves are a Python loop (unrolled while tracing), as in the DSL port."""
import math

import drjit as dr
import numpy as np
from drjit.llvm import Array2f, Float

C, S = math.cos(0.5), math.sin(0.5)



def fract(x):
    return x - dr.floor(x)


def rand_glsl(p):
    return fract(dr.sin(p.x * 12.9898 + p.y * 4.1414) * 43758.5453)


def noise(p):
    ip = dr.floor(p)
    u = p - ip
    u = u * u * (3.0 - 2.0 * u)
    res = dr.lerp(dr.lerp(rand_glsl(ip), rand_glsl(ip + Array2f(1.0, 0.0)), u.x),
                  dr.lerp(rand_glsl(ip + Array2f(0.0, 1.0)), rand_glsl(ip + Array2f(1.0, 1.0)), u.x), u.y)
    return res * res


def fbm(x):
    v = Float(0.0)
    a = 0.5
    for _ in range(5):
        v += a * noise(x)
        x = Array2f(C * x.x - S * x.y, S * x.x + C * x.y) * 2.0 + 100.0
        a *= 0.5
    return v


def shade(fx, fy, scale):
    return fbm(Array2f(fx, fy) * scale)


_frozen = dr.freeze(shade)


def prepare(fx, fy, height):
    gx, gy = np.broadcast_arrays(fx, fy)
    return Float(np.ascontiguousarray(gx.ravel(), np.float32)), Float(np.ascontiguousarray(gy.ravel(), np.float32)), \
        Float(6.0 / float(height)), gx.shape


def run(fx, fy, scale, shape=None):
    out = _frozen(fx, fy, scale)
    dr.eval(out)
    return out


def render(fx, fy, height):
    *p, shape = prepare(fx, fy, height)
    return (np.array(run(*p)).reshape(shape),)
