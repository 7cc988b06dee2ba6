"""examples/shaders/raymarch.py (three.js raymarching: 64-step march, 50-step soft shadow, 3 bounces)
for numba: scalar code per pixel in float32 with the GLSL loops and early exits as they are, rows in
parallel with ``prange``. ``error_model="numpy"``: ``h * 16 / c`` at c = 0 is inf, as in GLSL (numba's
default raises ZeroDivisionError)."""
import math

import numba as nb
import numpy as np

F = np.float32
EPS = F(0.01)
OFFSET = F(1.0)
LX, LY, LZ = F(-0.48666426339228763), F(0.8111071056538127), F(-0.3244428422615251)
MOUSE = (0.5, 0.5)
TIME = 0.0


@nb.njit(inline="always")
def _mod(x, y):
    return x - y * np.floor(x / y)


@nb.njit(inline="always")
def _sphere(x, y, z):
    qx, qz = _mod(x, F(3.0)) - F(1.5), _mod(z, F(3.0)) - F(1.5)
    return math.sqrt(qx * qx + y * y + qz * qz) - F(1.0)


@nb.njit(inline="always")
def _scene(x, y, z):
    return min(_sphere(x, y, z), y + F(1.0))


@nb.njit(inline="always")
def _normalize(x, y, z):
    inv = F(1.0) / math.sqrt(x * x + y * y + z * z)
    return x * inv, y * inv, z * inv


@nb.njit(inline="always")
def _color(x, y, z):
    if _sphere(x, y, z) < y + F(1.0):
        h = (z + x) / F(9.0)
        out = []
        for k in (F(1.0), F(2.0 / 3.0), F(1.0 / 3.0)):
            f = (h + k) - np.floor(h + k)
            out.append(min(max(abs(f * F(6.0) - F(3.0)) - F(1.0), F(0.0)), F(1.0)))
        return out[0], out[1], out[2]
    u = F(1.0) - np.floor(_mod(x, F(2.0)))
    v = F(1.0) - np.floor(_mod(z, F(2.0)))
    c = F(0.2) if (u == F(1.0) and v < F(1.0)) or (u < F(1.0) and v == F(1.0)) else F(1.0)
    return F(0.5) * c, F(0.5) * c, F(0.5) * c


@nb.njit(inline="always")
def _shadow(x, y, z):
    c, r = F(0.0), F(1.0)
    for _ in range(50):
        h = _scene(x + LX * c, y + LY * c, z + LZ * c)
        if h < EPS:
            return F(0.5)
        r = min(r, h * F(16.0) / c)
        c += h
    return F(1.0) - F(0.5) + r * F(0.5)


@nb.njit(inline="always")
def _ray_color(ox, oy, oz, rx, ry, rz):
    dist, depth = F(0.0), F(0.0)
    px, py, pz = ox, oy, oz
    for _ in range(64):
        dist = _scene(px, py, pz)
        depth += dist
        px, py, pz = ox + depth * rx, oy + depth * ry, oz + depth * rz
        if abs(dist) < EPS:
            break
    cr = cg = cb = F(0.0)
    nx = ny = nz = F(0.0)
    hit = False
    if abs(dist) < EPS:
        e = EPS
        nx, ny, nz = _normalize(_scene(px + e, py, pz) - _scene(px - e, py, pz),
                                _scene(px, py + e, pz) - _scene(px, py - e, pz),
                                _scene(px, py, pz + e) - _scene(px, py, pz - e))
        diffuse = min(max(LX * nx + LY * ny + LZ * nz, F(0.1)), F(1.0))
        d2 = F(2.0) * (nx * LX + ny * LY + nz * LZ)
        sx, sy, sz = LX - d2 * nx, LY - d2 * ny, LZ - d2 * nz
        specular = math.pow(min(max(sx * rx + sy * ry + sz * rz, F(0.0)), F(1.0)), F(10.0))
        shadow = _shadow(px + nx * OFFSET, py + ny * OFFSET, pz + nz * OFFSET)
        mr, mg, mb = _color(px, py, pz)
        k = max(F(0.5), shadow)
        cr = (mr * diffuse + F(0.8) * specular) * k
        cg = (mg * diffuse + F(0.8) * specular) * k
        cb = (mb * diffuse + F(0.8) * specular) * k
        hit = True
    fog = math.pow(min(max(F(0.05) * depth, F(0.0)), F(0.6)), F(2.0))
    return cr - fog, cg - fog, cb - fog, px, py, pz, nx, ny, nz, hit


@nb.njit(parallel=True, fastmath=False, error_model="numpy")
def _render(fx, fy, res_x, res_y, out):
    m = min(res_x, res_y)
    dx, dy, dz = _normalize(F(0.0), F(-0.3), F(1.0))
    ux, uy, uz = F(0.0), dz, -dy                       # cross(cDir, (1, 0, 0))
    sx, sy, sz = dy * uz - dz * uy, dz * ux - dx * uz, dx * uy - dy * ux
    for j in nb.prange(fy.size):
        for i in range(fx.size):
            qx, qy = (fx[i] * F(2.0) - res_x) / m, (fy[j] * F(2.0) - res_y) / m
            rx, ry, rz = _normalize(sx * qx + ux * qy + dx * F(1.3), sy * qx + uy * qy + dy * F(1.3),
                                    sz * qx + uz * qy + dz * F(1.3))
            cx, cy, cz = F(MOUSE[0] - 0.5), F(MOUSE[1] * 4.0 - 0.2), F(TIME)
            r = g = b = F(0.0)
            alpha = F(1.0)
            for _ in range(3):
                cr, cg, cb, px, py, pz, nx, ny, nz, hit = _ray_color(cx, cy, cz, rx, ry, rz)
                r += alpha * cr
                g += alpha * cg
                b += alpha * cb
                alpha *= F(0.3)
                d2 = F(2.0) * (nx * rx + ny * ry + nz * rz)
                rx, ry, rz = _normalize(rx - d2 * nx, ry - d2 * ny, rz - d2 * nz)
                cx, cy, cz = px + nx * OFFSET, py + ny * OFFSET, pz + nz * OFFSET
                if not hit:
                    break
            out[0, j, i], out[1, j, i], out[2, j, i] = r, g, b


def render(fx, fy, res_x, res_y):
    fx, fy = np.ascontiguousarray(fx.ravel(), np.float32), np.ascontiguousarray(fy.ravel(), np.float32)
    out = np.empty((3, fy.size, fx.size), np.float32)
    _render(fx, fy, F(res_x), F(res_y), out)
    return out[0], out[1], out[2]
