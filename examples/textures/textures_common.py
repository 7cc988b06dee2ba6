"""The harness the texture scenes share: exact sRGB in float64, 8-bit comparisons, timing, RGBA PNG.

Nothing here is scene code: each scene's kernels and its NumPy reference live in its own module.

* ``srgb_encode64(x)`` / ``srgb_decode64(codes)``: IEC 61966-2-1 in float64 (the reference's
  transfer functions; ``reference_codes`` rounds the encode to the nearest 8-bit code, which is
  what ``routines.pixels.srgb8_encode`` computes exactly for a float32 input).
* ``numpy_codes_f32(linear)``: the NumPy float32 way of getting codes (the formula in float32,
  ``np.rint``), for the NumPy float32 figure.
* ``compare(codes, ref_codes, linear, ref_linear)``: the 8-bit codes of a render against those of
  the float64 reference (count, more than one code off, largest), and the largest error before
  quantization, in codes (``255 * |sRGB(linear) - sRGB(ref_linear)|`` evaluated in float64).
* ``best_time``, ``timed_build``, ``single_thread()``: milliseconds, best of N calls after a
  warm-up; one build; reactor's calls on one thread inside a block.
* ``code_lines(path, tag)``: code lines between ``# --- <tag> begin`` / ``end`` markers (blank,
  comment-only and docstring lines not counted).
* ``load_photo(width)``: matplotlib's sample photograph (Grace Hopper, 600 x 512 sRGB8 JPEG,
  shipped with matplotlib: no network), resized to ``width`` columns if asked.
* ``save_rgba_png(path, rgba)``: an (H, W, 4) uint8 array as an RGBA8 PNG with an sRGB chunk.
* ``scene_main``: the command line of a scene (``--out``, ``--size``, ``--repeat``).

The module is not named ``common.py`` because ``examples/common.py`` is imported under that name by
the top-level examples, in the same test process.
"""
from __future__ import annotations

import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "shaders"))
from shader_common import best_time, shader_main, single_thread, timed_build  # noqa: E402,F401 - the ports' harness

DEFAULT_OUT = os.path.join("out", "examples", "textures")
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
SRGB_LINEAR_LIMIT = 0.0031308


# -- sRGB -------------------------------------------------------------------------------------------

def srgb_encode64(x) -> np.ndarray:
    """sRGB(x) in float64 for linear ``x`` clamped to [0, 1] (NaN counts as 0)."""
    x = np.clip(np.nan_to_num(np.asarray(x, np.float64), nan=0.0), 0.0, 1.0)
    return np.where(x <= SRGB_LINEAR_LIMIT, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


def srgb_decode64(codes) -> np.ndarray:
    """The linear value of sRGB8 codes, float64."""
    y = np.asarray(codes, np.float64) / 255.0
    return np.where(y <= 12.92 * SRGB_LINEAR_LIMIT, y / 12.92, np.power((y + 0.055) / 1.055, 2.4))


def reference_codes(linear) -> np.ndarray:
    """The nearest sRGB8 code of float64 linear values."""
    return np.rint(srgb_encode64(linear) * 255.0).astype(np.uint8)


def numpy_codes_f32(linear) -> np.ndarray:
    """sRGB8 codes the NumPy float32 way: the formula in float32, clamped, ``np.rint``."""
    F = np.float32
    x = np.clip(np.nan_to_num(np.asarray(linear, F), nan=0.0), F(0), F(1))
    y = np.where(x <= F(SRGB_LINEAR_LIMIT), F(12.92) * x, F(1.055) * np.power(x, F(1 / 2.4)) - F(0.055))
    return np.rint(y * F(255)).astype(np.uint8)


def with_alpha(rgb_codes: np.ndarray, alpha: int = 255) -> np.ndarray:
    """(H, W, 3) uint8 -> (H, W, 4) with a constant alpha."""
    a = np.full(rgb_codes.shape[:-1] + (1,), alpha, np.uint8)
    return np.concatenate([rgb_codes, a], axis=-1)


# -- comparisons ------------------------------------------------------------------------------------

def compare(codes, ref_codes, linear=None, ref_linear=None) -> dict:
    """RGB codes (the last axis' first three channels) against the reference's, and the largest
    error before quantization in codes (if the unquantized linear values are given)."""
    a = np.asarray(codes)[..., :3].astype(np.int16)
    b = np.asarray(ref_codes)[..., :3].astype(np.int16)
    d = np.abs(a - b)
    out = {
        "codes": int(d.size),
        "codes_differing": int(np.count_nonzero(d)),
        "codes_over_1": int(np.count_nonzero(d > 1)),
        "max_code_diff": int(d.max()) if d.size else 0,
        "pixels_differing": int(np.count_nonzero(d.max(axis=-1))),
    }
    if linear is not None:
        e = np.abs(srgb_encode64(np.asarray(linear)[..., :3]) - srgb_encode64(np.asarray(ref_linear)[..., :3]))
        out["max_error_codes"] = float(e.max() * 255.0) if e.size else 0.0
        out["nonfinite"] = int(np.count_nonzero(~np.isfinite(np.asarray(linear)[..., :3])))
    return out


# -- timing -----------------------------------------------------------------------------------------

# -- sources ----------------------------------------------------------------------------------------

def code_lines(path: str, tag: str) -> int:
    """Code lines between ``# --- <tag> begin`` and ``# --- <tag> end`` (blank lines, comment lines
    and docstrings not counted)."""
    inside, n, in_doc = False, 0, False
    with open(path, encoding="utf-8") as f:
        for line in f:
            s = line.strip()
            if s.startswith(f"# --- {tag} begin"):
                inside = True
                continue
            if s.startswith(f"# --- {tag} end"):
                inside = False
                continue
            if not inside or not s or s.startswith("#"):
                continue
            if in_doc:                                   # inside a docstring: does it close here?
                in_doc = not s.endswith(('"""', "'''"))
                continue
            if s.startswith(('"""', "'''")):
                in_doc = not (len(s) > 3 and s.endswith(s[:3]))
                continue
            n += 1
    return n


def load_photo(width: int | None = None) -> np.ndarray:
    """Grace Hopper's portrait from matplotlib's sample data as (H, W, 3) uint8 sRGB codes,
    resized (Lanczos, in the 8-bit codes as most tools do) to ``width`` columns if given."""
    from matplotlib import cbook
    from PIL import Image

    with cbook.get_sample_data("grace_hopper.jpg") as f:
        image = Image.open(f)
        image.load()
    image = image.convert("RGB")
    if width is not None and width != image.width:
        height = max(1, round(image.height * width / image.width))
        image = image.resize((width, height), Image.LANCZOS)
    return np.ascontiguousarray(np.asarray(image, dtype=np.uint8))


def save_rgba_png(path: str, rgba: np.ndarray) -> None:
    """Write (H, W, 4) uint8 RGBA8 codes as a PNG, marked sRGB (an ``sRGB`` chunk)."""
    from PIL import Image, PngImagePlugin

    rgba = np.asarray(rgba)
    if rgba.dtype != np.uint8 or rgba.ndim != 3 or rgba.shape[-1] != 4:
        raise ValueError(f"an RGBA8 image is (H, W, 4) uint8, not {rgba.dtype} {rgba.shape}")
    info = PngImagePlugin.PngInfo()
    info.add(b"sRGB", b"\x00")  # rendering intent: perceptual
    Image.fromarray(rgba, "RGBA").save(path, pnginfo=info, optimize=True)


# -- command line and report ------------------------------------------------------------------------

def scene_main(argv, doc: str, name: str, run, report, default_size: int = 512) -> dict:
    """The ports' command line (``shader_common.shader_main``): ``run(size=, repeat=)`` on one
    thread returns the figures and the kernel's RGBA8 image under ``rgba``, written as it is to
    ``<out>/<name>.png``; the figures come back with ``image`` (the path)."""
    return shader_main(argv, doc, name, run, report, default_size, DEFAULT_OUT,
                       save=lambda path, r: save_rgba_png(path, r.pop("rgba")))


def format_report(title: str, r: dict) -> str:
    """The common table: accuracy against float64, build and run times, line counts."""
    lines = [title, f"  {'':12s}{'codes differing':>22s}{'>1':>7s}{'max':>5s}{'max err':>9s}{'ms':>9s}"]
    for name, acc in r["accuracy"].items():
        pct = 100.0 * acc["codes_differing"] / max(1, acc["codes"])
        err = acc.get("max_error_codes", float("nan"))
        lines.append(f"  {name:12s}{acc['codes_differing']:>11,d} of {acc['codes']:<7,d}({pct:4.1f}%)"
                     f"{acc['codes_over_1']:>5,d}{acc['max_code_diff']:>5d}{err:>9.3g}"
                     f"{r['ms'].get(name, float('nan')):>9.2f}")
    builds = ", ".join(f"{k} {v:.0f}" for k, v in r["build_ms"].items())
    lines.append(f"  build ms (no disk cache): {builds}")
    lines.append(f"  reactor vs NumPy float32: {r['ms']['numpy_f32'] / r['ms']['reactor']:.1f}x faster; "
                 f"lines: DSL {r['lines']['dsl']}, NumPy reference {r['lines']['numpy']}")
    return "\n".join(lines)
