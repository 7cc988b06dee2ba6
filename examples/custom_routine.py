"""A routine of your own: a smoothstep-windowed exp2 light falloff, as a ufunc, with broadcasting.

    python examples/custom_routine.py [--out out/examples]
    python -m reactor dump examples/custom_routine.py:falloff --what asm

A routine is a plain Python function of DSL values, like ``routines.exp2``:
``smoothstep`` and ``light_falloff`` below emit inline IR wherever they are
called. ``@reactor.kernel`` turns a body that calls them into a real
``numpy.ufunc``, so NumPy supplies broadcasting (no ``meshgrid``), ``out=``
and ``where=``. The example

1. sweeps distance down the rows against radius across the columns with one
   call, ``falloff(d2[:, None], radius[None, :])``, and checks it against the
   same formula in NumPy float64, and bit for bit against the call on
   materialized (contiguous) copies and against the scalar path (a transposed
   ``out=``), and ``where=``;
2. lights a 2-D scene with five coloured lights: squared distances of shape
   (lights, H, W) against radii of shape (lights, 1, 1), summed over lights.
"""
from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # the examples' common.py, however run
from common import save_png  # noqa: E402

import reactor
import routines
from reactor import Float, Max, Min

SHARPNESS = 4.0      # exp2(-SHARPNESS * (d / r)^2): 1/16 of the peak at the radius, before the window
WINDOW_START = 0.5   # the window fades from 1 at d = 0.5 r to exactly 0 at d = r


# --- the routine: plain Python functions of DSL values -----------------------------------------

def smoothstep(edge0: float, edge1: float, x):
    """GLSL smoothstep: 0 below edge0, 1 above edge1, 3t^2 - 2t^3 between."""
    t = Min(Max((x - edge0) * (1.0 / (edge1 - edge0)), 0.0), 1.0)
    return t * t * (3.0 - 2.0 * t)


def light_falloff(d2, radius, precision: str = "relaxed"):
    """A light's intensity at squared distance ``d2``: a Gaussian-like exp2 bump, windowed by a
    smoothstep so that it is exactly 0 from ``radius`` on (a light can be culled there)."""
    q2 = d2 / (radius * radius)                     # (d / r)^2: no square root needed for exp2
    q = routines.sqrt(q2, precision=precision)      # d / r, for the window
    window = 1.0 - smoothstep(WINDOW_START, 1.0, q)
    return routines.exp2(-SHARPNESS * q2, precision=precision) * window


@reactor.kernel
def falloff(d2: Float, radius: Float) -> Float:
    """Windowed exp2 light falloff (relaxed precision) at squared distance d2 from a light of radius."""
    return light_falloff(d2, radius, precision="relaxed")


@reactor.kernel
def falloff_full(d2: Float, radius: Float) -> Float:
    """The same in full precision."""
    return light_falloff(d2, radius, precision="full")


# --- NumPy float64, the reference ----------------------------------------------------------------

def falloff_reference(d2, radius):
    d2, radius = np.asarray(d2, np.float64), np.asarray(radius, np.float64)
    q2 = d2 / (radius * radius)
    t = np.clip((np.sqrt(q2) - WINDOW_START) / (1.0 - WINDOW_START), 0, 1)
    return np.exp2(-SHARPNESS * q2) * (1.0 - t * t * (3.0 - 2.0 * t))


# --- the demonstrations --------------------------------------------------------------------------

LIGHTS = [  # x, y, radius, colour (linear RGB)
    (0.22, 0.30, 0.35, (1.00, 0.55, 0.20)),
    (0.70, 0.25, 0.28, (0.25, 0.55, 1.00)),
    (0.50, 0.62, 0.45, (0.90, 0.90, 0.85)),
    (0.15, 0.80, 0.22, (0.30, 1.00, 0.40)),
    (0.85, 0.78, 0.30, (1.00, 0.30, 0.60)),
]


def run() -> dict:
    # 1. a sweep: distance down the rows, radius across the columns, one broadcasting call
    d = np.linspace(0.0, 1.2, 241, dtype=np.float32)
    radius = np.linspace(0.25, 1.0, 301, dtype=np.float32)
    d2 = d * d
    sweep = falloff(d2[:, None], radius[None, :])
    ref = falloff_reference(d2[:, None], radius[None, :])
    dense = falloff(*(np.ascontiguousarray(a) for a in np.broadcast_arrays(d2[:, None], radius[None, :])))
    out = np.full(sweep.shape, -1.0, np.float32)
    mask = d[:, None] < radius[None, :]              # where=: compute inside the radius only
    falloff(d2[:, None], radius[None, :], out=out, where=mask)
    full = falloff_full(d2[:, None], radius[None, :])
    strided = np.empty(sweep.shape[::-1], np.float32).T   # a non-contiguous out= takes the scalar path
    falloff(d2[:, None], radius[None, :], out=strided)
    outside = d[:, None] >= radius[None, :]
    results = {
        "sweep_shape": sweep.shape,
        "max_abs_error_relaxed": float(np.abs(sweep - ref).max()),
        "max_abs_error_full": float(np.abs(full - ref).max()),
        "broadcast_equals_dense": bool(np.array_equal(sweep, dense)),
        "strided_equals_vector": bool(np.array_equal(sweep, strided)),
        "zero_outside_radius": bool(np.all(sweep[outside] == 0.0)),
        "where_respected": bool(np.all(out[~mask] == -1.0) and np.array_equal(out[mask], sweep[mask])),
        "monotone_in_distance": bool(np.all(np.diff(sweep, axis=0) <= 0)),
    }

    # 2. a scene: five lights on a 2-D floor, (lights, H, W) against (lights, 1, 1)
    h, w = 360, 540
    y = np.linspace(0, 1, h, dtype=np.float32)[None, :, None]
    x = np.linspace(0, w / h, w, dtype=np.float32)[None, None, :]
    lx = np.array([l[0] * w / h for l in LIGHTS], np.float32)[:, None, None]
    ly = np.array([l[1] for l in LIGHTS], np.float32)[:, None, None]
    lr = np.array([l[2] for l in LIGHTS], np.float32)[:, None, None]
    colours = np.array([l[3] for l in LIGHTS], np.float32)
    dist2 = (x - lx) ** 2 + (y - ly) ** 2            # (5, H, W)
    intensity = falloff(dist2, lr)                    # (5, H, W): radius broadcast per light
    t0 = time.perf_counter()
    for _ in range(5):
        falloff(dist2, lr)
    results["scene_ms"] = (time.perf_counter() - t0) / 5 * 1e3
    t0 = time.perf_counter()
    for _ in range(5):
        falloff_reference(dist2, lr)
    results["scene_numpy_float64_ms"] = (time.perf_counter() - t0) / 5 * 1e3
    scene_ref = falloff_reference(dist2, lr)
    results["scene_shape"] = intensity.shape
    results["scene_max_abs_error"] = float(np.abs(intensity - scene_ref).max())
    image = np.einsum("nhw,nc->hwc", intensity, colours) * 0.6   # exposure: keep the overlaps below white
    results["images"] = (sweep, image)
    return results


def report(r: dict) -> str:
    return "\n".join([
        f"sweep {r['sweep_shape']} from falloff(d2[:, None], radius[None, :]):",
        f"  max |error| vs NumPy float64: relaxed {r['max_abs_error_relaxed']:.2e}, full {r['max_abs_error_full']:.2e}",
        f"  broadcast call == call on contiguous copies (bit for bit): {r['broadcast_equals_dense']}; "
        f"== the scalar path (transposed out=): {r['strided_equals_vector']}",
        f"  exactly 0 from the radius on: {r['zero_outside_radius']}; monotone in distance: "
        f"{r['monotone_in_distance']}; where= leaves the rest of out= alone: {r['where_respected']}",
        f"scene: {len(LIGHTS)} lights, falloff(dist2 {r['scene_shape']}, radius {(len(LIGHTS), 1, 1)}) in "
        f"{r['scene_ms']:.2f} ms (NumPy float64 {r['scene_numpy_float64_ms']:.1f} ms), "
        f"max |error| {r['scene_max_abs_error']:.2e}",
    ])


def save_figure(r: dict, path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    sweep, image = r["images"]
    fig, axes = plt.subplots(1, 2, figsize=(9.0, 3.5), dpi=90, gridspec_kw={"width_ratios": [1, 1.25]})
    im = axes[0].imshow(sweep, origin="upper", extent=(0.25, 1.0, 1.2, 0.0), aspect="auto", cmap="magma")
    axes[0].plot([0.25, 1.0], [0.25, 1.0], color="white", lw=0.6, ls="--")
    axes[0].set_xlabel("radius (columns: radius[None, :])", fontsize=8)
    axes[0].set_ylabel("distance (rows: d2[:, None])", fontsize=8)
    axes[0].set_title("falloff(d2[:, None], radius[None, :])", fontsize=9)
    axes[0].tick_params(labelsize=7)
    fig.colorbar(im, ax=axes[0], fraction=0.05)
    srgb = np.clip(image, 0, 1)
    srgb = np.where(srgb <= 0.0031308, srgb * 12.92, 1.055 * srgb ** (1 / 2.4) - 0.055)
    axes[1].imshow(srgb)
    axes[1].set_title(f"{len(LIGHTS)} lights: (5, H, W) against (5, 1, 1), summed", fontsize=9)
    axes[1].axis("off")
    fig.tight_layout()
    save_png(fig, path)


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=os.path.join("out", "examples"), help="output directory")
    args = parser.parse_args(argv)
    r = run()
    print(report(r))
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, "custom_routine.png")
    save_figure(r, path)
    print(f"wrote {path}")
    del r["images"]
    r["image"] = path
    return r


if __name__ == "__main__":
    main()
