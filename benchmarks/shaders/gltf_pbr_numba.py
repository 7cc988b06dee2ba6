"""examples/shaders/gltf_pbr.py (glTF single-light GGX) for numba: a scalar function per pixel, float32
throughout (every constant a float32, as a GLSL float), over the covered pixels with ``prange``."""
import math

import numba as nb
import numpy as np

F = np.float32
LIGHT = (F(4.0), F(6.0), F(10.0))
CAMERA = (F(0.0), F(0.0), F(12.0))
U_METALLIC = F(0.0)
PI = F(3.141592653589793)


@nb.njit(inline="always")
def _normalize(x, y, z):
    inv = F(1.0) / math.sqrt(x * x + y * y + z * z)
    return x * inv, y * inv, z * inv


@nb.njit(parallel=True, fastmath=False, error_model="numpy")
def _shade(px, py, pz, nx, ny, nz, tx, ty, tz, br, bg, bb, mr, mg, mb, metal, rough, out):
    for i in nb.prange(px.size):
        n0, n1, n2 = _normalize(nx[i], ny[i], nz[i])
        t0, t1, t2 = _normalize(tx[i], ty[i], tz[i])
        b0, b1, b2 = n1 * t2 - t1 * n2, n2 * t0 - t2 * n0, n0 * t1 - t0 * n1
        m0, m1, m2 = _normalize(mr[i] * F(2.0) - F(1.0), mg[i] * F(2.0) - F(1.0), mb[i] * F(2.0) - F(1.0))
        n0, n1, n2 = _normalize(t0 * m0 + b0 * m1 + n0 * m2, t1 * m0 + b1 * m1 + n1 * m2,
                                t2 * m0 + b2 * m1 + n2 * m2)
        l0, l1, l2 = _normalize(LIGHT[0] - px[i], LIGHT[1] - py[i], LIGHT[2] - pz[i])
        v0, v1, v2 = _normalize(CAMERA[0] - px[i], CAMERA[1] - py[i], CAMERA[2] - pz[i])
        h0, h1, h2 = _normalize(l0 + v0, l1 + v1, l2 + v2)
        n_v = max(F(0.0), n0 * v0 + n1 * v1 + n2 * v2)
        n_l = max(F(0.0), n0 * l0 + n1 * l1 + n2 * l2)
        n_h = max(F(0.0), n0 * h0 + n1 * h1 + n2 * h2)
        v_h = max(F(0.0), v0 * h0 + v1 * h1 + v2 * h2)
        m = metal[i]
        s5 = math.pow(F(1.0) - v_h, F(5.0))
        r = rough[i]
        a = r * r
        k = (r + F(1.0)) * (r + F(1.0)) / F(8.0)
        g = n_l / (n_l * (F(1.0) - k) + k) * (n_v / (n_v * (F(1.0) - k) + k))
        a2 = a * a
        q = n_h * n_h * (a2 - F(1.0)) + F(1.0)
        d = a2 / (PI * q * q)
        den = F(4.0) * n_l * n_v
        diffuse_scale = F(1.0) - max(F(0.5), U_METALLIC)
        base = (br[i], bg[i], bb[i])
        for c in range(3):
            sc = base[c] * m + F(0.04) * (F(1.0) - m)
            fr = sc + (F(1.0) - sc) * s5
            spec = d * fr * g / den            # IEEE (error_model="numpy"): 0/0 is NaN, as in GLSL
            x = base[c] * diffuse_scale * n_l + sc * spec
            out[c, i] = min(max(x, F(0.0)), F(1.0)) if x == x else F(0.0)


def render(*args):
    """The 17 input arrays -> (r, g, b) float32."""
    out = np.empty((3, args[0].size), np.float32)
    _shade(*args, out)
    return out[0], out[1], out[2]
