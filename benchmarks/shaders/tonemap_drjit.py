"""examples/shaders/tonemap.py (three.js ACES Filmic + AgX + sRGB OETF) for Dr.Jit's LLVM backend,
float32, ``dr.freeze``d; matrices as ``Matrix3f`` (the AgX inverses by ``dr.rcp``)."""
import drjit as dr
import numpy as np
from drjit.llvm import Array3f, Float, Matrix3f


def _cols(*c):                      # GLSL mat3(c0, c1, c2): columns
    return Matrix3f(*[[c[j][i] for j in range(3)] for i in range(3)])


ACES_IN = _cols((0.59719, 0.07600, 0.02840), (0.35458, 0.90834, 0.13383), (0.04823, 0.01566, 0.83777))
ACES_OUT = _cols((1.60475, -0.10208, -0.00327), (-0.53108, 1.10813, -0.07276), (-0.07367, -0.00605, 1.07602))
TO_SRGB = _cols((1.6605, -0.5876, -0.0728), (-0.1246, 1.1329, -0.0083), (-0.0182, -0.1006, 1.1187)).T
TO_2020 = dr.rcp(TO_SRGB)
INSET = _cols((0.856627153315983, 0.137318972929847, 0.11189821299995),
              (0.0951212405381588, 0.761241990602591, 0.0767994186031903),
              (0.0482516061458583, 0.101439036467562, 0.811302368396859))
OUTSET = dr.rcp(_cols((0.899796955911611, 0.11142098895748, 0.11142098895748),
                          (0.0871996192028351, 0.875575586156966, 0.0871996192028349),
                          (0.013003424885555, 0.0130034248855548, 0.801379391839686)))


def oetf(v):
    return dr.lerp(dr.power(v, 0.41666) * 1.055 - 0.055, v * 12.92, dr.select(v <= 0.0031308, 1.0, 0.0))


def rrt(v):
    return (v * (v + 0.0245786) - 0.000090537) / (v * (0.983729 * v + 0.4329510) + 0.238081)


def sigmoid(x):
    x2 = x * x
    x4 = x2 * x2
    return 15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x - 0.00232


def shade(r, g, b):
    c = Array3f(r, g, b)
    aces = oetf(dr.clip(ACES_OUT @ rrt(ACES_IN @ (c * (1.0 / 0.6))), 0.0, 1.0))
    v = INSET @ dr.maximum(0.0, TO_2020 @ c)
    v = dr.clip((dr.log2(dr.maximum(v, 1e-10)) + 12.47393) / (4.026069 + 12.47393), 0.0, 1.0)
    v = dr.power(dr.maximum(0.0, OUTSET @ sigmoid(v)), 2.2)
    agx = oetf(TO_SRGB @ v)
    return aces, agx


_frozen = dr.freeze(shade)


def prepare(r, g, b):
    return tuple(Float(np.ascontiguousarray(c.ravel(), np.float32)) for c in (r, g, b)) + (r.shape,)


def run(r, g, b, shape=None):
    out = _frozen(r, g, b)
    dr.eval(out)
    return out


def render(r, g, b):
    *p, shape = prepare(r, g, b)
    aces, agx = run(*p)
    return tuple(np.array(c).reshape(shape) for c in (aces.x, aces.y, aces.z, agx.x, agx.y, agx.z))
