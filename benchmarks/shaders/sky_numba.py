"""examples/shaders/sky.py (three.js Sky, Preetham) fragment stage for numba: scalar float32 code per
pixel; the vertex stage's varyings arrive as float32 scalars, as for the DSL kernel."""
import math

import numba as nb
import numpy as np

F = np.float32
PI = F(3.141592653589793)
SUN_COS = F(0.999956676946448443553574619906976478926848692873900859324)


@nb.njit(parallel=True, fastmath=False, error_model="numpy")
def _sky(wx, wy, wz, sdx, sdy, sdz, sunfade, br, bm, sun_e, out):
    g = F(0.7)
    w = min(max(math.pow(F(1.0) - sdy, F(5.0)), F(0.0)), F(1.0))
    expo = F(1.0) / (F(1.2) + F(1.2) * sunfade)
    for i in nb.prange(wx.size):
        inv = F(1.0) / math.sqrt(wx[i] * wx[i] + wy[i] * wy[i] + wz[i] * wz[i])
        dx, dy, dz = wx[i] * inv, wy[i] * inv, wz[i] * inv
        zenith = math.acos(max(F(0.0), dy))
        inverse = F(1.0) / (math.cos(zenith) + F(0.15) * math.pow(F(93.885) - zenith * F(180.0) / PI, F(-1.253)))
        s_r, s_m = F(8.4e3) * inverse, F(1.25e3) * inverse
        cos_theta = dx * sdx + dy * sdy + dz * sdz
        r_phase = F(0.05968310365946075) * (F(1.0) + math.pow(cos_theta * F(0.5) + F(0.5), F(2.0)))
        m_phase = F(0.07957747154594767) * ((F(1.0) - g * g)
                                            / math.pow(F(1.0) - F(2.0) * g * cos_theta + g * g, F(1.5)))
        t = min(max((cos_theta - SUN_COS) / F(0.00002), F(0.0)), F(1.0))
        sundisk = t * t * (F(3.0) - F(2.0) * t)
        for c in range(3):
            fex = math.exp(-(br[c] * s_r + bm[c] * s_m))
            ratio = sun_e * ((br[c] * r_phase + bm[c] * m_phase) / (br[c] + bm[c]))
            lin = math.pow(ratio * (F(1.0) - fex), F(1.5))
            lin *= F(1.0) * (F(1.0) - w) + math.pow(ratio * fex, F(0.5)) * w
            l0 = F(0.1) * fex + sun_e * F(19000.0) * fex * sundisk
            tint = F(0.0) if c == 0 else (F(0.0003) if c == 1 else F(0.00075))
            out[c, i] = math.pow((lin + l0) * F(0.04) + tint, expo)


def render(wx, wy, wz, sdx, sdy, sdz, sunfade, brx, bry, brz, bmx, bmy, bmz, sun_e):
    shape = wx.shape
    out = np.empty((3, wx.size), np.float32)
    _sky(*(np.ascontiguousarray(c.ravel(), np.float32) for c in (wx, wy, wz)), F(sdx), F(sdy), F(sdz), F(sunfade),
         np.array([brx, bry, brz], np.float32), np.array([bmx, bmy, bmz], np.float32), F(sun_e), out)
    return tuple(c.reshape(shape) for c in out)
