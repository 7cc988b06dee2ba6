"""examples/shaders/sky.py (three.js Sky, Preetham) fragment stage for Dr.Jit's LLVM backend, float32,
``dr.freeze``d; the varyings are Dr.Jit scalars (literals broadcast to every lane)."""
import drjit as dr
import numpy as np
from drjit.llvm import Array3f, Float

PI = 3.141592653589793
SUN_COS = 0.999956676946448443553574619906976478926848692873900859324


def shade(wx, wy, wz, sun_dir, sunfade, beta_r, beta_m, sun_e):
    d = dr.normalize(Array3f(wx, wy, wz))
    zenith = dr.acos(dr.maximum(0.0, d.y))
    inverse = 1.0 / (dr.cos(zenith) + 0.15 * dr.power(93.885 - zenith * 180.0 / PI, -1.253))
    fex = dr.exp(-(beta_r * (8.4e3 * inverse) + beta_m * (1.25e3 * inverse)))
    cos_theta = dr.dot(d, sun_dir)
    r_phase = 0.05968310365946075 * (1.0 + dr.power(cos_theta * 0.5 + 0.5, 2.0))
    g = 0.7
    m_phase = 0.07957747154594767 * ((1.0 - g * g) / dr.power(1.0 - 2.0 * g * cos_theta + g * g, 1.5))
    ratio = sun_e * ((beta_r * r_phase + beta_m * m_phase) / (beta_r + beta_m))
    lin = dr.power(ratio * (1.0 - fex), 1.5)
    lin *= dr.lerp(Array3f(1.0), dr.power(ratio * fex, 0.5), dr.clip(dr.power(1.0 - sun_dir.y, 5.0), 0.0, 1.0))
    t = dr.clip((cos_theta - SUN_COS) / 0.00002, 0.0, 1.0)          # smoothstep (Dr.Jit has none)
    sundisk = t * t * (3.0 - 2.0 * t)
    l0 = 0.1 * fex + (sun_e * 19000.0 * fex) * sundisk
    tex = (lin + l0) * 0.04 + Array3f(0.0, 0.0003, 0.00075)
    return dr.power(tex, 1.0 / (1.2 + 1.2 * sunfade))


_frozen = dr.freeze(shade)


def prepare(wx, wy, wz, sdx, sdy, sdz, sunfade, brx, bry, brz, bmx, bmy, bmz, sun_e):
    arrays = tuple(Float(np.ascontiguousarray(c.ravel(), np.float32)) for c in (wx, wy, wz))
    return arrays + (Array3f(float(sdx), float(sdy), float(sdz)), Float(float(sunfade)),
                     Array3f(float(brx), float(bry), float(brz)), Array3f(float(bmx), float(bmy), float(bmz)),
                     Float(float(sun_e)), wx.shape)


def run(*prepared):
    out = _frozen(*prepared[:8])
    dr.eval(out)
    return out


def render(*args):
    p = prepare(*args)
    out = run(*p)
    return tuple(np.array(c).reshape(p[-1]) for c in (out.x, out.y, out.z))
