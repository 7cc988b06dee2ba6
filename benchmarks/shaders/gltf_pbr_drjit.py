"""examples/shaders/gltf_pbr.py (glTF single-light GGX) for Dr.Jit's LLVM backend: the same
arithmetic on ``drjit.llvm`` arrays (float32), traced once and replayed with ``dr.freeze``."""
import drjit as dr
import numpy as np
from drjit.llvm import Array3f, Float

LIGHT = (4.0, 6.0, 10.0)
CAMERA = (0.0, 0.0, 12.0)
U_METALLIC = 0.0
PI = 3.141592653589793


def shade(px, py, pz, nx, ny, nz, tx, ty, tz, br, bg, bb, mr, mg, mb, metal, rough):
    pos, base = Array3f(px, py, pz), Array3f(br, bg, bb)
    n = dr.normalize(Array3f(nx, ny, nz))
    t = dr.normalize(Array3f(tx, ty, tz))
    b = dr.cross(n, t)
    m = dr.normalize(Array3f(mr, mg, mb) * 2.0 - 1.0)
    n = dr.normalize(t * m.x + b * m.y + n * m.z)
    l = dr.normalize(Array3f(*LIGHT) - pos)
    v = dr.normalize(Array3f(*CAMERA) - pos)
    h = dr.normalize(l + v)
    n_v, n_l = dr.maximum(0.0, dr.dot(n, v)), dr.maximum(0.0, dr.dot(n, l))
    n_h, v_h = dr.maximum(0.0, dr.dot(n, h)), dr.maximum(0.0, dr.dot(v, h))
    spec_color = base * metal + 0.04 * (1.0 - metal)
    f = spec_color + (1.0 - spec_color) * dr.power(1.0 - v_h, 5.0)
    a = rough * rough
    k = (rough + 1.0) * (rough + 1.0) / 8.0
    g = n_l / (n_l * (1.0 - k) + k) * (n_v / (n_v * (1.0 - k) + k))
    a2 = a * a
    q = n_h * n_h * (a2 - 1.0) + 1.0
    d = a2 / (PI * q * q)
    spec = d * f * g / (4.0 * n_l * n_v)
    color = base * (1.0 - max(0.5, U_METALLIC)) * n_l + spec_color * spec
    return dr.clip(color, 0.0, 1.0)


_frozen = dr.freeze(shade)


def prepare(*args):
    return tuple(Float(np.ascontiguousarray(a, np.float32)) for a in args)


def run(*prepared):
    out = _frozen(*prepared)
    dr.eval(out)
    return out


def to_numpy(out):
    return tuple(np.array(c) for c in (out.x, out.y, out.z))


def render(*args):
    return to_numpy(run(*prepare(*args)))
