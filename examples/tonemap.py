"""Tone mapping with exp and log: log-average luminance and Reinhard on a synthetic HDR scene.

    python examples/tonemap.py [--out out/examples]

The scene is synthesized here (no files): a sky with a sun some 10^7 times
brighter than the shadows on the ground, lamps and their glow, a lit
checkered ground. Two ``@reactor.kernel``s tone-map it, as a post-processing pass would:

1. ``log_luminance(r, g, b) = log(delta + L)`` per pixel; NumPy's ``mean``
   reduces it (kernels are element-wise), so the scene's key is
   ``exp(mean)``, the log-average luminance of Reinhard et al. (2002);
2. ``reinhard(r, g, b, log_avg)`` scales every pixel by ``key / exp(log_avg)``
   (``log_avg`` is one scalar broadcast to every lane), compresses luminance
   with the extended operator ``L (1 + L / Lw^2) / (1 + L)``, rescales the
   colour and encodes it to sRGB with ``pow``: three outputs in [0, 1].

Full and relaxed builds are timed against NumPy float32 and measured against
a float64 reference; the picture shows a linear exposure (clipped), the log
luminance and the tone-mapped result.
"""
from __future__ import annotations

import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # the examples' common.py, however run
from common import best_time, save_png, timed_example_main, to_codes  # noqa: E402

import reactor
import routines
from reactor import Float, Max, Min, Select

DELTA = 1e-4            # keeps log() finite on black pixels
KEY = 0.18              # middle grey: where the log-average luminance lands
WHITE = 6.0             # the smallest scaled luminance mapped to pure white
LUMA = (0.2126, 0.7152, 0.0722)   # Rec. 709 luminance weights (linear RGB)


def make_kernels(precision: str):
    """(log_luminance, reinhard) ufuncs with exp, log and pow in ``precision``."""
    wr, wg, wb = LUMA

    @reactor.kernel(name=f"log_luminance_{precision}")
    def log_luminance(r: Float, g: Float, b: Float) -> Float:
        return routines.log(r * wr + g * wg + b * wb + DELTA, precision=precision)

    def encode(c):
        c = Min(Max(c, 0.0), 1.0)
        curve = routines.pow(c, 1.0 / 2.4, precision=precision) * 1.055 - 0.055
        return Select(c <= 0.0031308, c * 12.92, curve)

    @reactor.kernel(name=f"reinhard_{precision}")
    def reinhard(r: Float, g: Float, b: Float, log_avg: Float) -> (Float, Float, Float):
        scale = routines.exp(-log_avg, precision=precision) * KEY     # key / log-average
        lum = r * wr + g * wg + b * wb
        ls = lum * scale
        ld = ls * (1.0 + ls * (1.0 / (WHITE * WHITE))) / (1.0 + ls)
        ratio = Select(lum > 0.0, ld / lum, 0.0)                      # black stays black
        return encode(r * ratio), encode(g * ratio), encode(b * ratio)

    return log_luminance, reinhard


def numpy_tonemap(r, g, b):
    """The same operator in NumPy, in the inputs' precision."""
    f = r.dtype.type
    wr, wg, wb = (f(w) for w in LUMA)
    lum = r * wr + g * wg + b * wb
    log_avg = np.mean(np.log(lum + f(DELTA)), dtype=np.float64)
    ls = lum * (f(np.exp(-log_avg)) * f(KEY))
    ld = ls * (f(1) + ls / f(WHITE * WHITE)) / (f(1) + ls)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(lum > 0, ld / lum, f(0))

    def encode(c):
        c = np.clip(c, 0, 1)
        return np.where(c <= f(0.0031308), c * f(12.92), f(1.055) * c ** f(1 / 2.4) - f(0.055))

    return log_avg, (encode(r * ratio), encode(g * ratio), encode(b * ratio))


def hdr_scene(h: int = 432, w: int = 768) -> np.ndarray:
    """A high-dynamic-range RGB image (linear radiance, float32, shape (3, h, w)), about 1e-3
    in the shadows to 2e4 on the sun."""
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    u, v = x / w, y / h
    horizon = 0.58
    img = np.zeros((3, h, w))
    # sky: bright near the horizon, deep blue above
    t = np.clip((horizon - v) / horizon, 0, 1)
    for c, (lo, hi) in enumerate(((3.0, 0.25), (2.6, 0.45), (2.0, 1.1))):
        img[c] = lo + (hi - lo) * t ** 0.6
    # the sun (disc and halo)
    d = np.hypot((u - 0.74) * w / h, v - 0.36)
    sun = np.where(d < 0.018, 2.0e4, 0.0) + 60.0 * np.exp(-d / 0.04) + 4.0 * np.exp(-d / 0.2)
    img += sun * np.array([1.0, 0.85, 0.6])[:, None, None]
    # ground: a checkerboard in perspective, lit towards the horizon, with a shadow
    below = v > horizon
    depth = np.where(below, 1.0 / np.maximum(v - horizon, 1e-3), 0.0)
    gx = (u - 0.5) * depth * 2.0
    checker = ((np.floor(gx) + np.floor(depth * 0.9)) % 2) * 0.7 + 0.3
    light = 0.02 + 0.6 * np.exp(-(v - horizon) * 6.0)
    shadow = np.where((u > 0.08) & (u < 0.36) & (v > 0.7), 0.02, 1.0)
    ground = checker * light * shadow
    for c, tint in enumerate((0.55, 0.5, 0.42)):
        img[c] = np.where(below, ground * tint, img[c])
    # lamps: small, very bright, with a glow
    for lu, lv, power, colour in ((0.2, 0.8, 800.0, (1.0, 0.6, 0.25)), (0.3, 0.9, 400.0, (1.0, 0.7, 0.3)),
                                  (0.5, 0.67, 200.0, (0.4, 0.7, 1.0))):
        dl = np.hypot((u - lu) * w / h, v - lv)
        glow = power * (np.where(dl < 0.006, 1.0, 0.0) + 0.02 * np.exp(-dl / 0.03))
        img += glow * np.array(colour)[:, None, None]
    return img.astype(np.float32)


def run(repeat: int = 5) -> dict:
    img = hdr_scene()
    r, g, b = img
    lum = r * LUMA[0] + g * LUMA[1] + b * LUMA[2]
    ref_log_avg, ref = numpy_tonemap(*(c.astype(np.float64) for c in img))
    ref_codes = to_codes(ref)
    out = {"shape": tuple(r.shape), "dynamic_range": float(lum.max() / lum[lum > 0].min()),
           "luminance_range": (float(lum[lum > 0].min()), float(lum.max())),
           "log_average_luminance": {"float64": float(np.exp(ref_log_avg))}, "ms": {},
           "max_diff_vs_float64": {}, "pixels_differing": {}, "codes": {"float64": ref_codes}}
    for precision in ("full", "relaxed"):
        log_luminance, reinhard = make_kernels(precision)

        def tonemap(r, g, b):
            log_avg = np.float32(np.mean(log_luminance(r, g, b), dtype=np.float64))
            return log_avg, reinhard(r, g, b, log_avg)

        log_avg, rgb = tonemap(r, g, b)
        out["ms"][precision] = best_time(tonemap, r, g, b, repeat=repeat)
        out["log_average_luminance"][precision] = float(np.exp(np.float64(log_avg)))
        out[f"{precision}_finite"] = bool(all(np.isfinite(c).all() for c in rgb))
        out[f"{precision}_range"] = (float(min(c.min() for c in rgb)), float(max(c.max() for c in rgb)))
        codes = to_codes(rgb)
        d = np.abs(codes.astype(np.int16) - ref_codes).max(axis=-1)
        out["max_diff_vs_float64"][precision] = int(d.max())
        out["pixels_differing"][precision] = int(np.count_nonzero(d))
        out["codes"][precision] = codes
    out["ms"]["numpy"] = best_time(numpy_tonemap, r, g, b, repeat=repeat)
    _, rgb = numpy_tonemap(r, g, b)
    d = np.abs(to_codes(rgb).astype(np.int16) - ref_codes).max(axis=-1)
    out["max_diff_vs_float64"]["numpy"], out["pixels_differing"]["numpy"] = int(d.max()), int(np.count_nonzero(d))
    out["scene"] = img
    return out


def report(r: dict) -> str:
    h, w = r["shape"]
    la = r["log_average_luminance"]
    lines = [f"HDR scene {w} x {h}, luminance {r['luminance_range'][0]:.1e} to {r['luminance_range'][1]:.1e} "
             f"(dynamic range {r['dynamic_range']:.1e}:1)",
             f"log-average luminance: float64 {la['float64']:.6f}, full {la['full']:.6f}, "
             f"relaxed {la['relaxed']:.6f} (relative error {abs(la['relaxed'] / la['float64'] - 1):.1e})",
             f"  {'':10s}{'time (ms)':>10s}{'max diff vs float64':>22s}{'pixels differing':>18s}"]
    for m in ("full", "relaxed", "numpy"):
        lines.append(f"  {m:10s}{r['ms'][m]:10.2f}{r['max_diff_vs_float64'][m]:>18d}/255"
                     f"{r['pixels_differing'][m]:>12,d} ({100 * r['pixels_differing'][m] / (h * w):4.1f}%)")
    lo, hi = min(r["full_range"][0], r["relaxed_range"][0]), max(r["full_range"][1], r["relaxed_range"][1])
    lines.append(f"outputs finite: {r['full_finite'] and r['relaxed_finite']}, in [{lo:g}, {hi:g}]")
    return "\n".join(lines)


def save_figure(r: dict, path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    img = r["scene"]
    lum = img[0] * LUMA[0] + img[1] * LUMA[1] + img[2] * LUMA[2]
    exposure = KEY / r["log_average_luminance"]["float64"]
    linear = np.clip(np.moveaxis(img, 0, -1) * exposure, 0, 1)
    clipped = np.where(linear <= 0.0031308, linear * 12.92, 1.055 * linear ** (1 / 2.4) - 0.055)
    fig, axes = plt.subplots(1, 3, figsize=(10.5, 2.55), dpi=100)
    axes[0].imshow(clipped, interpolation="antialiased")
    axes[0].set_title("linear exposure, clipped", fontsize=8.5)
    im = axes[1].imshow(np.log10(lum), cmap="inferno", interpolation="antialiased")
    axes[1].set_title("log10 luminance", fontsize=8.5)
    fig.colorbar(im, ax=axes[1], fraction=0.035, pad=0.02)
    axes[2].imshow(r["codes"]["relaxed"], interpolation="antialiased")
    axes[2].set_title(f"Reinhard, relaxed exp/log/pow: {r['ms']['relaxed']:.1f} ms "
                      f"(NumPy {r['ms']['numpy']:.0f} ms)", fontsize=8.5)
    for ax in axes:
        ax.axis("off")
    fig.tight_layout()
    save_png(fig, path)


def main(argv=None) -> dict:
    return timed_example_main(argv, __doc__, "tonemap", run, report, save_figure, drop=("codes", "scene"))


if __name__ == "__main__":
    main()
