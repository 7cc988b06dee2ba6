"""benchmarks/shaders/pbr.py for Dr.Jit's LLVM backend (``drjit.llvm``): the same arithmetic."""
import drjit as dr

LIGHTS = ((0.3, 0.8, 0.5, 4.0), (-0.6, 0.4, 0.7, 2.0), (0.1, -0.2, 0.97, 1.5), (0.9, 0.1, 0.4, 3.0))


def d_ggx(nh, a2):
    d = nh * nh * (a2 - 1.0) + 1.0
    return a2 / (3.14159265 * d * d)


def pbr(nx, ny, nz, vx, vy, vz, rough, metal):
    color = nx * 0.0
    for lx, ly, lz, power in LIGHTS:
        hx, hy, hz = lx + vx, ly + vy, lz + vz
        inv = dr.rsqrt(hx * hx + hy * hy + hz * hz)
        nh = dr.maximum((nx * hx + ny * hy + nz * hz) * inv, 0.0)
        nl = dr.maximum(nx * lx + ny * ly + nz * lz, 0.0)
        a = rough * rough
        d = d_ggx(nh, a * a)
        f0 = dr.fma(metal, 0.96, 0.04)
        fresnel = f0 + (1.0 - f0) * dr.power(dr.maximum(1.0 - nh, 0.0), 5.0)
        spec = d * fresnel * 0.25
        color = color + (spec + (1.0 - metal) * 0.318) * nl * power
    return dr.power(dr.clip(color, 0.0, 1.0), 1.0 / 2.2)
