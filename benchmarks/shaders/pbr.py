"""A GGX/PBR fragment shader of the size real ones have (8 inputs, four lights, 4 pow, 4 rsqrt,
~60 DSL lines): the compile-time benchmark's reference kernel. benchmarks/shaders/pbr_drjit.py is the
same shader for Dr.Jit."""
import routines
from reactor import Float, Max, Min, MulAdd, kernel

LIGHTS = ((0.3, 0.8, 0.5, 4.0), (-0.6, 0.4, 0.7, 2.0), (0.1, -0.2, 0.97, 1.5), (0.9, 0.1, 0.4, 3.0))


def d_ggx(nh, a2):
    d = nh * nh * (a2 - 1.0) + 1.0
    return a2 / (3.14159265 * d * d)


@kernel
def pbr(nx: Float, ny: Float, nz: Float, vx: Float, vy: Float, vz: Float, rough: Float, metal: Float) -> Float:
    color = nx * 0.0
    for lx, ly, lz, power in LIGHTS:
        hx, hy, hz = lx + vx, ly + vy, lz + vz
        inv = routines.rsqrt(hx * hx + hy * hy + hz * hz)
        nh = Max((nx * hx + ny * hy + nz * hz) * inv, 0.0)
        nl = Max(nx * lx + ny * ly + nz * lz, 0.0)
        a = rough * rough
        d = d_ggx(nh, a * a)
        f0 = MulAdd(metal, 0.96, 0.04)
        fresnel = f0 + (1.0 - f0) * routines.pow(Max(1.0 - nh, 0.0), 5.0)
        spec = d * fresnel * 0.25
        color = color + (spec + (1.0 - metal) * 0.318) * nl * power
    return routines.pow(Min(Max(color, 0.0), 1.0), 1.0 / 2.2)
