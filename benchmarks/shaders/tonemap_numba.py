"""examples/shaders/tonemap.py (three.js ACES Filmic + AgX + sRGB OETF) for numba: scalar float32
code per pixel; the constant matrices (the AgX inverses computed in float64 by NumPy, then rounded)
are float32 tuples."""
import math

import numba as nb
import numpy as np

F = np.float32


def _m(*columns):
    return np.array(columns, dtype=np.float64).T


_ACES_IN = _m((0.59719, 0.07600, 0.02840), (0.35458, 0.90834, 0.13383), (0.04823, 0.01566, 0.83777))
_ACES_OUT = _m((1.60475, -0.10208, -0.00327), (-0.53108, 1.10813, -0.07276), (-0.07367, -0.00605, 1.07602))
_REC2020_TO_SRGB = _m((1.6605, -0.5876, -0.0728), (-0.1246, 1.1329, -0.0083), (-0.0182, -0.1006, 1.1187)).T
_SRGB_TO_REC2020 = np.linalg.inv(_REC2020_TO_SRGB)
_INSET = _m((0.856627153315983, 0.137318972929847, 0.11189821299995),
            (0.0951212405381588, 0.761241990602591, 0.0767994186031903),
            (0.0482516061458583, 0.101439036467562, 0.811302368396859))
_OUTSET = np.linalg.inv(_m((0.899796955911611, 0.11142098895748, 0.11142098895748),
                           (0.0871996192028351, 0.875575586156966, 0.0871996192028349),
                           (0.013003424885555, 0.0130034248855548, 0.801379391839686)))
MATS = tuple(np.ascontiguousarray(m, np.float32) for m in (_ACES_IN, _ACES_OUT, _SRGB_TO_REC2020, _INSET, _OUTSET,
                                                             _REC2020_TO_SRGB))


@nb.njit(inline="always")
def _mul(m, x, y, z):
    return (m[0, 0] * x + m[0, 1] * y + m[0, 2] * z, m[1, 0] * x + m[1, 1] * y + m[1, 2] * z,
            m[2, 0] * x + m[2, 1] * y + m[2, 2] * z)


@nb.njit(inline="always")
def _oetf(v):
    if v <= F(0.0031308):
        return v * F(12.92) if v >= F(0.0) else F(np.nan)      # GLSL's mix keeps pow's NaN
    return math.pow(v, F(0.41666)) * F(1.055) - F(0.055)


@nb.njit(inline="always")
def _rrt(v):
    return (v * (v + F(0.0245786)) - F(0.000090537)) / (v * (F(0.983729) * v + F(0.4329510)) + F(0.238081))


@nb.njit(inline="always")
def _sigmoid(x):
    x2 = x * x
    x4 = x2 * x2
    return (F(15.5) * x4 * x2 - F(40.14) * x4 * x + F(31.96) * x4 - F(6.868) * x2 * x + F(0.4298) * x2
            + F(0.1191) * x - F(0.00232))


@nb.njit(inline="always")
def _agx_in(v):
    v = max(v, F(1e-10))
    v = (math.log2(v) - F(-12.47393)) / F(4.026069 - -12.47393)
    return _sigmoid(min(max(v, F(0.0)), F(1.0)))


@nb.njit(parallel=True, fastmath=False, error_model="numpy")
def _tonemap(r, g, b, aces_in, aces_out, to2020, inset, outset, to_srgb, out):
    for i in nb.prange(r.size):
        s = F(1.0 / 0.6)
        x, y, z = _mul(aces_in, r[i] * s, g[i] * s, b[i] * s)
        x, y, z = _mul(aces_out, _rrt(x), _rrt(y), _rrt(z))
        out[0, i] = _oetf(min(max(x, F(0.0)), F(1.0)))
        out[1, i] = _oetf(min(max(y, F(0.0)), F(1.0)))
        out[2, i] = _oetf(min(max(z, F(0.0)), F(1.0)))
        x, y, z = _mul(to2020, r[i], g[i], b[i])
        x, y, z = _mul(inset, max(F(0.0), x), max(F(0.0), y), max(F(0.0), z))
        x, y, z = _mul(outset, _agx_in(x), _agx_in(y), _agx_in(z))
        x, y, z = (math.pow(max(F(0.0), x), F(2.2)), math.pow(max(F(0.0), y), F(2.2)),
                   math.pow(max(F(0.0), z), F(2.2)))
        x, y, z = _mul(to_srgb, x, y, z)
        out[3, i], out[4, i], out[5, i] = _oetf(x), _oetf(y), _oetf(z)


def render(r, g, b):
    shape = r.shape
    out = np.empty((6, r.size), np.float32)
    _tonemap(*(np.ascontiguousarray(c.ravel(), np.float32) for c in (r, g, b)), *MATS, out)
    return tuple(c.reshape(shape) for c in out)
