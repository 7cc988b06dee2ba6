"""examples/shaders/noise.py (glsl-fbm 2d: sin-hash value noise, 5 octaves, mat2 rotation) for numba:
a scalar function per pixel in float32, rows in parallel with ``prange``."""
import math

import numba as nb
import numpy as np

F = np.float32
C, S = F(math.cos(0.5)), F(math.sin(0.5))
SCALE = F(6.0)


@nb.njit(inline="always")
def _fract(x):
    return x - np.floor(x)   # np.floor keeps float32 (math.floor gives an int64)


@nb.njit(inline="always")
def _rand(x, y):
    return _fract(math.sin(x * F(12.9898) + y * F(4.1414)) * F(43758.5453))


@nb.njit(inline="always")
def _noise(px, py):
    ix, iy = np.floor(px), np.floor(py)
    ux, uy = px - ix, py - iy
    ux, uy = ux * ux * (F(3.0) - F(2.0) * ux), uy * uy * (F(3.0) - F(2.0) * uy)
    a, b = _rand(ix, iy), _rand(ix + F(1.0), iy)
    c, d = _rand(ix, iy + F(1.0)), _rand(ix + F(1.0), iy + F(1.0))
    top = a * (F(1.0) - ux) + b * ux
    bot = c * (F(1.0) - ux) + d * ux
    res = top * (F(1.0) - uy) + bot * uy
    return res * res


@nb.njit(parallel=True, fastmath=False)
def _fbm(fx, fy, height, out):
    for j in nb.prange(fy.size):
        for i in range(fx.size):
            x, y = fx[i] / height * SCALE, fy[j] / height * SCALE
            v, a = F(0.0), F(0.5)
            for _ in range(5):
                v += a * _noise(x, y)
                x, y = (C * x - S * y) * F(2.0) + F(100.0), (S * x + C * y) * F(2.0) + F(100.0)
                a *= F(0.5)
            out[j, i] = v


def render(fx, fy, height):
    """gl_FragCoord.x (a row), .y (a column), the height -> (gray,) float32."""
    fx, fy = np.ascontiguousarray(fx.ravel(), np.float32), np.ascontiguousarray(fy.ravel(), np.float32)
    out = np.empty((fy.size, fx.size), np.float32)
    _fbm(fx, fy, F(height), out)
    return (out,)
