"""A lit surface: normals from a height field, Blinn-Phong, full against relaxed.

    python examples/specular.py [--out out/examples]

The height field is a real one: the Jacksboro fault digital elevation model
(Tennessee, 344 x 403 samples, 3 arc-seconds) that ships with matplotlib
(``cbook.get_sample_data("jacksboro_fault_dem.npz")``), with the lake at
305 m rendered as water.

One ``@reactor.kernel`` shades a pixel from start to finish: the normal from
central differences (the four neighbours arrive as shifted views of the same
array, so NumPy's broadcasting does the stencil), the view vector from the
pixel's position (x and y arrive as a row and a column and broadcast), a
Blinn-Phong highlight ``pow(n.h, shininess)`` and an sRGB encode. Where lanes
diverge (water or land, facing the sun or not) the kernel computes both sides
and picks with ``Select`` on a mask: no branches. The same body is built with
the full and the relaxed routines (``pow``, ``rsqrt``); printed: their times,
NumPy's (the same formula in float32), and the largest difference between the
8-bit renders.
"""
from __future__ import annotations

import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # the examples' common.py, however run
from common import best_time, save_png, timed_example_main, to_codes  # noqa: E402

import reactor
import routines
from reactor import Abs, Float, Max, Min, Select

WATER_LEVEL = 305.0          # metres: the lake's surface in this model
EXAGGERATION = 3.0           # vertical exaggeration
SUN = (-0.55, 0.45, 0.70)    # towards the sun (x east, y north, z up), low in the north-west
EYE = (21_000.0, -11_500.0, 12_000.0)  # metres from the map's centre: where the lake mirrors the sun
AMBIENT = 0.06
WATER_SHININESS, WATER_GLOSS = 250.0, 1.5      # Blinn-Phong exponent and strength
LAND_SHININESS, LAND_GLOSS = 16.0, 0.25
# base colours (linear RGB)
LOW, HIGH, WATER = (0.09, 0.20, 0.05), (0.42, 0.33, 0.22), (0.010, 0.035, 0.070)


def _unit(v):
    n = math.sqrt(sum(c * c for c in v))
    return tuple(c / n for c in v)


SUN = _unit(SUN)


def make_shader(precision: str, dx: float, dy: float, rsqrt_precision: str | None = None):
    """The shading kernel with pow (and the sRGB encode) in ``precision`` and the normalizations'
    rsqrt in ``rsqrt_precision`` (default: the same); dx, dy: sample spacing in metres."""
    rsqrt_precision = rsqrt_precision or precision
    sx, sy = EXAGGERATION / (2 * dx), EXAGGERATION / (2 * dy)
    lx, ly, lz = SUN

    def normalize(x, y, z):
        inv = routines.rsqrt(x * x + y * y + z * z, precision=rsqrt_precision)
        return x * inv, y * inv, z * inv

    def encode(c):                                   # linear -> sRGB, the segment picked by mask
        c = Min(Max(c, 0.0), 1.0)
        curve = routines.pow(c, 1.0 / 2.4, precision=precision) * 1.055 - 0.055
        return Select(c <= 0.0031308, c * 12.92, curve)

    @reactor.kernel(name=f"terrain_pow_{precision}_rsqrt_{rsqrt_precision}")
    def shade(h: Float, west: Float, east: Float, south: Float, north: Float,
              x: Float, y: Float) -> (Float, Float, Float):
        water = Abs(h - WATER_LEVEL) < 0.5
        # the normal (-dh/dx, -dh/dy, 1), flat on the water
        gx = Select(water, 0.0, (east - west) * sx)
        gy = Select(water, 0.0, (north - south) * sy)
        nx, ny, nz = normalize(-gx, -gy, 1.0)
        # view vector from the surface point to the eye, half vector
        vx, vy, vz = normalize(EYE[0] - x, EYE[1] - y, EYE[2] - h * EXAGGERATION)
        hx, hy, hz = normalize(vx + lx, vy + ly, vz + lz)
        n_l = nx * lx + ny * ly + nz * lz
        n_h = Max(nx * hx + ny * hy + nz * hz, 0.0)
        facing = n_l > 0.0                            # lanes facing away get no highlight
        shininess = Select(water, Float(WATER_SHININESS), LAND_SHININESS)
        strength = Select(water, Float(WATER_GLOSS), LAND_GLOSS)
        highlight = Select(facing, routines.pow(n_h, shininess, precision=precision) * strength, 0.0)
        diffuse = Max(n_l, 0.0) + AMBIENT
        # land colour from the height (a ramp), water colour on the lake
        t = Min(Max((h - 300.0) * (1.0 / 600.0), 0.0), 1.0)
        out = []
        for lo, hi, wa in zip(LOW, HIGH, WATER):
            base = Select(water, wa, lo + (hi - lo) * t)
            out.append(encode(base * diffuse + highlight))
        return tuple(out)

    return shade


def numpy_shader(h, west, east, south, north, x, y, dx, dy):
    """The same shading in NumPy, in the inputs' precision: float32 (for timing) or float64
    (the reference the renders are measured against)."""
    f = h.dtype.type
    water = np.abs(h - f(WATER_LEVEL)) < f(0.5)
    gx = np.where(water, f(0), (east - west) * f(EXAGGERATION / (2 * dx)))
    gy = np.where(water, f(0), (north - south) * f(EXAGGERATION / (2 * dy)))

    def normalize(a, b, c):
        inv = f(1) / np.sqrt(a * a + b * b + c * c)
        return a * inv, b * inv, c * inv

    nx, ny, nz = normalize(-gx, -gy, np.ones_like(gx))
    vx, vy, vz = normalize(f(EYE[0]) - x + 0 * h, f(EYE[1]) - y + 0 * h, f(EYE[2]) - h * f(EXAGGERATION))
    lx, ly, lz = (f(c) for c in SUN)
    hx, hy, hz = normalize(vx + lx, vy + ly, vz + lz)
    n_l = nx * lx + ny * ly + nz * lz
    n_h = np.maximum(nx * hx + ny * hy + nz * hz, f(0))
    shininess = np.where(water, f(WATER_SHININESS), f(LAND_SHININESS))
    strength = np.where(water, f(WATER_GLOSS), f(LAND_GLOSS))
    highlight = np.where(n_l > 0, n_h ** shininess * strength, f(0))
    diffuse = np.maximum(n_l, f(0)) + f(AMBIENT)
    t = np.clip((h - f(300)) * f(1 / 600), 0, 1)
    out = []
    for lo, hi, wa in zip(LOW, HIGH, WATER):
        base = np.where(water, f(wa), f(lo) + f(hi - lo) * t)
        c = np.clip(base * diffuse + highlight, 0, 1)
        out.append(np.where(c <= f(0.0031308), c * f(12.92), f(1.055) * c ** f(1 / 2.4) - f(0.055)))
    return tuple(out)


def load_height_field():
    """(elevation in metres as float32, dx, dy in metres) from matplotlib's sample data."""
    from matplotlib import cbook

    dem = cbook.get_sample_data("jacksboro_fault_dem.npz")
    z = dem["elevation"].astype(np.float32)
    lat = math.radians(0.5 * (float(dem["ymin"]) + float(dem["ymax"])))
    dx = float(dem["dx"]) * 111_320.0 * math.cos(lat)
    dy = float(dem["dy"]) * 110_570.0
    return z, dx, dy


def stencil(z: np.ndarray, dx: float, dy: float):
    """The kernel's inputs: the height, its four neighbours (shifted views of the edge-padded
    field: no copies), x as a row and y as a column (metres from the centre; they broadcast)."""
    p = np.pad(z, 1, mode="edge")
    h, w = z.shape
    inner = p[1:-1, 1:-1]
    west, east = p[1:-1, :-2], p[1:-1, 2:]
    north, south = p[:-2, 1:-1], p[2:, 1:-1]      # row 0 is the northern edge
    x = ((np.arange(w, dtype=np.float32) - (w - 1) / 2) * dx)[None, :]
    y = (((h - 1) / 2 - np.arange(h, dtype=np.float32)) * dy)[:, None]
    return inner, west, east, south, north, x.astype(np.float32), y.astype(np.float32)


VARIANTS = {                     # name: (pow and encode precision, rsqrt precision)
    "full": ("full", "full"),
    "relaxed": ("relaxed", "relaxed"),
    "relaxed pow only": ("relaxed", "full"),
    "relaxed rsqrt only": ("full", "relaxed"),
}


def run(repeat: int = 5, upsample: int = 2) -> dict:
    z, dx, dy = load_height_field()
    if upsample > 1:                                   # bilinear, so the render has some size
        z = _upsample(z, upsample)
        dx, dy = dx / upsample, dy / upsample
    args = stencil(z, dx, dy)
    shaders = {name: make_shader(p, dx, dy, rsqrt_precision=q) for name, (p, q) in VARIANTS.items()}
    renders = {name: shader(*args) for name, shader in shaders.items()}
    renders["numpy"] = numpy_shader(*args, dx, dy)
    renders["float64"] = numpy_shader(*(a.astype(np.float64) for a in args), dx, dy)
    times = {name: best_time(shader, *args, repeat=repeat) for name, shader in shaders.items()}
    times["numpy"] = best_time(numpy_shader, *args, dx, dy, repeat=repeat)
    codes = {k: to_codes(v) for k, v in renders.items()}
    water = np.abs(args[0] - WATER_LEVEL) < 0.5
    ref = codes["float64"].astype(np.int16)

    def against_reference(name):
        d = np.abs(codes[name] - ref).max(axis=-1)
        return {"max_diff": int(d.max()), "max_diff_land": int(d[~water].max()),
                "max_diff_water": int(d[water].max()), "pixels": int(np.count_nonzero(d))}

    return {
        "shape": tuple(z.shape),
        "water_fraction": float(water.mean()),
        "ms": times,
        "vs_float64": {name: against_reference(name) for name in list(VARIANTS) + ["numpy"]},
        "max_diff_full_relaxed": int(np.abs(codes["full"].astype(np.int16) - codes["relaxed"]).max()),
        "finite": bool(all(np.isfinite(c).all() for r in renders.values() for c in r)),
        "codes": codes,
    }


def _upsample(z: np.ndarray, k: int) -> np.ndarray:
    h, w = z.shape
    yi = np.linspace(0, h - 1, (h - 1) * k + 1)
    xi = np.linspace(0, w - 1, (w - 1) * k + 1)
    y0 = np.minimum(yi.astype(int), h - 2)
    x0 = np.minimum(xi.astype(int), w - 2)
    fy, fx = (yi - y0)[:, None], (xi - x0)[None, :]
    z = z.astype(np.float64)
    top = z[y0][:, x0] * (1 - fx) + z[y0][:, x0 + 1] * fx
    bot = z[y0 + 1][:, x0] * (1 - fx) + z[y0 + 1][:, x0 + 1] * fx
    return (top * (1 - fy) + bot * fy).astype(np.float32)


def report(r: dict) -> str:
    h, w = r["shape"]
    t = r["ms"]
    lines = [f"terrain {w} x {h} ({h * w:,} pixels, {100 * r['water_fraction']:.1f}% water), one kernel "
             "call per render; 8-bit difference from the float64 render:",
             f"  {'':20s}{'time (ms)':>10s}{'max diff':>10s}{'land':>6s}{'water':>7s}{'pixels differing':>18s}"]
    for name, d in r["vs_float64"].items():
        lines.append(f"  {name:20s}{t[name]:10.2f}{d['max_diff']:>7d}/255{d['max_diff_land']:>6d}"
                     f"{d['max_diff_water']:>7d}{d['pixels']:>12,d} ({100 * d['pixels'] / (h * w):4.1f}%)")
    lines.append(f"full vs relaxed: at most {r['max_diff_full_relaxed']}/255; relaxed is "
                 f"{t['full'] / t['relaxed']:.2f}x faster than full and {t['numpy'] / t['relaxed']:.0f}x "
                 "faster than NumPy float32.")
    return "\n".join(lines)


def save_figure(r: dict, path: str) -> None:

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    full, relaxed = r["codes"]["full"], r["codes"]["relaxed"]
    d = np.abs(full.astype(np.int16) - relaxed).max(axis=-1)
    fig, axes = plt.subplots(1, 2, figsize=(8.0, 3.9), dpi=90,
                             gridspec_kw={"width_ratios": [1, 1]})
    axes[0].imshow(relaxed, interpolation="antialiased")
    axes[0].set_title(f"relaxed pow/rsqrt, {r['ms']['relaxed']:.1f} ms "
                      f"(full {r['ms']['full']:.1f} ms, NumPy {r['ms']['numpy']:.0f} ms)", fontsize=8)
    im = axes[1].imshow(d, cmap="magma", vmin=0, vmax=max(1, int(d.max())), interpolation="nearest")
    axes[1].set_title(f"|full - relaxed| in 8-bit codes (max {int(d.max())}, "
                      f"{100 * np.count_nonzero(d) / d.size:.1f}% of pixels differ)", fontsize=8)
    fig.colorbar(im, ax=axes[1], fraction=0.04, ticks=range(0, max(1, int(d.max())) + 1))
    for ax in axes:
        ax.axis("off")
    fig.tight_layout()
    save_png(fig, path)


def main(argv=None) -> dict:
    return timed_example_main(argv, __doc__, "specular", run, report, save_figure, drop=("codes",))


if __name__ == "__main__":
    main()
