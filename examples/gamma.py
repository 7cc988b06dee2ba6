"""sRGB and gamma 2.2 on a real photograph: full, relaxed and NumPy, against 8-bit output.

    python examples/gamma.py [--out out/examples]

The photograph is Grace Hopper's portrait that ships with matplotlib
(``matplotlib.cbook.get_sample_data("grace_hopper.jpg")``: no network). Each
transfer function is a ``@reactor.kernel``; the sRGB curve has a linear segment
near black and a power segment above it, written as one ``Select`` on a mask
(every lane computes both; nothing branches).

The pipeline is what a shader does with an sRGB texture and an sRGB render
target: decode the 8-bit codes to linear light, work there (here a vignette,
a smooth per-pixel factor, so the values reaching the encoder are not just 256
levels), encode and quantize to 8 bits. Every stage runs with the full
routine, the relaxed routine and NumPy float32, and every 8-bit output is
compared with the correctly rounded reference: the same formulas in float64,
rounded to the nearest code.

The question: is relaxed precision enough for 8-bit output? Printed: the time
of each stage and how many pixels of the 8-bit output differ from the
reference (and by how much), for
  * the round trip decode -> encode (a texture copied to a render target),
  * the encoder alone, on the same float32 linear input for everyone,
  * the whole pipeline decode -> vignette -> encode.
"""
from __future__ import annotations

import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # the examples' common.py, however run
from common import best_time, save_png  # noqa: E402

import reactor
import routines
from reactor import Float, Max, Min, Select

PRECISIONS = ("full", "relaxed")
METHODS = PRECISIONS + ("numpy",)

# sRGB (IEC 61966-2-1) constants, in the form shaders write them.
SRGB_KNEE_CODE = 0.04045       # encoded value where the power segment starts
SRGB_KNEE_LINEAR = 0.0031308   # the same point in linear light
GAMMA = 2.2


# --- the kernels -------------------------------------------------------------------------------

def make_kernels(precision: str) -> dict:
    """The four transfer functions as ufuncs, in ``precision`` ("full" or "relaxed")."""

    @reactor.kernel(name=f"srgb_decode_{precision}")
    def srgb_decode(code: Float) -> Float:
        """8-bit code (as float, 0..255) -> linear light in [0, 1]."""
        v = code * (1.0 / 255.0)
        curve = routines.pow((v + 0.055) * (1.0 / 1.055), 2.4, precision=precision)
        return Select(v <= SRGB_KNEE_CODE, v * (1.0 / 12.92), curve)

    @reactor.kernel(name=f"srgb_encode_{precision}")
    def srgb_encode(linear: Float) -> Float:
        """linear light -> encoded value in [0, 1] (clamped; NaN -> 0)."""
        x = Min(Max(linear, 0.0), 1.0)      # Max(NaN, 0) = 0: a NaN pixel becomes black
        curve = routines.pow(x, 1.0 / 2.4, precision=precision) * 1.055 - 0.055
        return Select(x <= SRGB_KNEE_LINEAR, x * 12.92, curve)

    @reactor.kernel(name=f"gamma_decode_{precision}")
    def gamma_decode(code: Float) -> Float:
        return routines.pow(code * (1.0 / 255.0), GAMMA, precision=precision)

    @reactor.kernel(name=f"gamma_encode_{precision}")
    def gamma_encode(linear: Float) -> Float:
        x = Min(Max(linear, 0.0), 1.0)
        # pow(+0, y) is +0 for y > 0, so black needs no special case
        return routines.pow(x, 1.0 / GAMMA, precision=precision)

    return {"srgb": (srgb_decode, srgb_encode), "gamma": (gamma_decode, gamma_encode)}


# --- NumPy float32 and the float64 reference ---------------------------------------------------

def numpy_kernels(dtype) -> dict:
    """The same transfer functions written with NumPy, in ``dtype`` (float32 or float64)."""
    c = dtype.type

    def srgb_decode(code):
        v = code.astype(dtype) / c(255)
        return np.where(v <= c(SRGB_KNEE_CODE), v / c(12.92), ((v + c(0.055)) / c(1.055)) ** c(2.4))

    def srgb_encode(linear):
        x = np.clip(linear.astype(dtype), 0, 1)
        return np.where(x <= c(SRGB_KNEE_LINEAR), x * c(12.92), c(1.055) * x ** c(1 / 2.4) - c(0.055))

    def gamma_decode(code):
        return (code.astype(dtype) / c(255)) ** c(GAMMA)

    def gamma_encode(linear):
        return np.clip(linear.astype(dtype), 0, 1) ** c(1 / GAMMA)

    return {"srgb": (srgb_decode, srgb_encode), "gamma": (gamma_decode, gamma_encode)}


def quantize(encoded) -> np.ndarray:
    """Encoded values in [0, 1] -> 8-bit codes, rounded to nearest (in float64 for everyone)."""
    return np.rint(np.clip(np.asarray(encoded, np.float64), 0, 1) * 255).astype(np.uint8)


# --- the photograph and the linear-light operation ---------------------------------------------

def load_photograph() -> np.ndarray:
    """Grace Hopper, 600 x 512 RGB, from matplotlib's sample data, as float32 codes 0..255."""
    from matplotlib import cbook
    from PIL import Image

    with cbook.get_sample_data("grace_hopper.jpg") as f:
        img = Image.open(f).convert("RGB")
        return np.asarray(img, dtype=np.float32).copy()


def vignette(shape) -> np.ndarray:
    """A smooth per-pixel light factor, 1 in the centre, 0.45 in the corners, shape (H, W, 1)."""
    h, w = shape[:2]
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float64)
    r2 = ((xx - (w - 1) / 2) / (w / 2)) ** 2 + ((yy - (h - 1) / 2) / (h / 2)) ** 2
    return (1.0 - 0.275 * r2)[..., None]


# --- measuring ---------------------------------------------------------------------------------

def compare(encoded: np.ndarray, exact: np.ndarray) -> dict:
    """A method's encoded output (float, [0, 1]) against the exact value (float64, [0, 1]):
    pixels whose 8-bit codes differ from the correctly rounded ones (any channel), channel
    values that differ, the largest code difference, the largest error before rounding (in
    codes), and whether every code is one of the two around the exact value (faithful)."""
    codes, reference = quantize(encoded), quantize(exact)
    diff = np.abs(codes.astype(np.int16) - reference.astype(np.int16))
    exact_codes = np.clip(exact, 0, 1) * 255
    return {"pixels": int(np.count_nonzero(diff.max(axis=-1))),
            "values": int(np.count_nonzero(diff)),
            "max_diff": int(diff.max()),
            "max_error_codes": float(np.abs(np.clip(encoded, 0, 1) * 255.0 - exact_codes).max()),
            "faithful": bool(np.all(np.abs(codes - exact_codes) < 1.0)),
            "codes": codes}


def run(photo: np.ndarray, repeat: int = 5) -> dict:
    """Every curve, method and measure on ``photo`` (float32 codes, H x W x 3)."""
    light = vignette(photo.shape)
    light32 = light.astype(np.float32)
    ours = {p: make_kernels(p) for p in PRECISIONS}
    ours["numpy"] = numpy_kernels(np.dtype(np.float32))
    ref = numpy_kernels(np.dtype(np.float64))
    results = {"pixels": int(photo.shape[0] * photo.shape[1])}
    for curve in ("srgb", "gamma"):
        ref_decode, ref_encode = ref[curve]
        linear64 = ref_decode(photo)
        # the encoder's input: one float32 array, the same for every method
        linear32 = linear64.astype(np.float32) * light32
        res = {}
        for method in METHODS:
            decode, encode = ours[method][curve]
            decoded = decode(photo)
            rel = np.abs(decoded - linear64) / np.where(linear64 > 0, linear64, 1.0)
            res[method] = {
                "decode_ms": best_time(decode, photo, repeat=repeat),
                "encode_ms": best_time(encode, linear32, repeat=repeat),
                "decode_max_rel_error": float(rel.max()),
                # a texture copied to a render target: the exact result is the input itself
                "round_trip": compare(encode(decoded), photo.astype(np.float64) / 255),
                "encode": compare(encode(linear32), ref_encode(linear32)),
                "pipeline": compare(encode(decoded * light32), ref_encode(linear64 * light)),
            }
        res["reference_pipeline"] = ref_encode(linear64 * light)
        results[curve] = res
    return results


# --- output ------------------------------------------------------------------------------------

def report(results: dict) -> str:
    n = results["pixels"]
    lines = [f"Grace Hopper, {n:,} RGB pixels. Pixels of the 8-bit output that differ from the "
             "correctly rounded reference,", "(largest code difference), and the largest error "
             "before rounding, in codes:", ""]
    head = f"{'':24s}" + "".join(f"{m:>19s}" for m in METHODS)
    for curve, title in (("srgb", "sRGB"), ("gamma", "gamma 2.2")):
        r = results[curve]
        lines += [f"{title}", head]
        for key, label, fmt in (("decode_ms", "decode time (ms)", "{:19.2f}"),
                                ("encode_ms", "encode time (ms)", "{:19.2f}"),
                                ("decode_max_rel_error", "decode max rel. error", "{:19.1e}")):
            lines.append(f"  {label:22s}" + "".join(fmt.format(r[m][key]) for m in METHODS))
        for key, label in (("round_trip", "round trip"), ("encode", "encoder alone"),
                           ("pipeline", "decode-light-encode")):
            cells = "".join(f"{r[m][key]['pixels']:,} ({r[m][key]['max_diff']}) "
                            f"{r[m][key]['max_error_codes']:.3f}".rjust(19) for m in METHODS)
            lines.append(f"  {label:22s}" + cells)
        lines.append("")
    s, g = results["srgb"]["relaxed"], results["gamma"]["relaxed"]
    worst = max(s["pipeline"]["max_error_codes"], g["pipeline"]["max_error_codes"])
    lines += [
        f"Relaxed is {results['srgb']['numpy']['encode_ms'] / s['encode_ms']:.0f}x faster than NumPy "
        f"and {results['srgb']['full']['encode_ms'] / s['encode_ms']:.1f}x faster than full (sRGB encode).",
        "8-bit round trip: exact with every method. On continuous linear input, relaxed rounds "
        f"{100 * s['encode']['pixels'] / n:.1f}% (encoder) to {100 * s['pipeline']['pixels'] / n:.1f}% "
        "(pipeline) of the pixels",
        f"to the other neighbour: never more than 1 code off (error before rounding <= {worst:.2f} code, "
        f"faithful: {all(x[k]['faithful'] for x in (s, g) for k in ('encode', 'pipeline'))}); "
        "full and NumPy float32 differ on a handful.",
    ]
    return "\n".join(lines)


def save_figure(results: dict, path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pipe = {m: results["srgb"][m]["pipeline"] for m in METHODS}
    reference = quantize(results["srgb"]["reference_pipeline"])
    differs = {m: np.abs(pipe[m]["codes"].astype(np.int16) - reference).max(axis=-1) > 0 for m in METHODS}
    crop = (slice(70, 370), slice(128, 384))            # the face, at 1:1
    marked = (reference[crop].astype(np.float32) * 0.3).astype(np.uint8)
    marked[differs["relaxed"][crop]] = (255, 60, 40)
    marked[differs["full"][crop]] = (60, 200, 255)
    n = results["pixels"]
    fig, axes = plt.subplots(1, 2, figsize=(5.6, 3.6), dpi=100)
    axes[0].imshow(pipe["relaxed"]["codes"][::2, ::2], interpolation="antialiased")
    axes[0].set_title("relaxed sRGB: decode, vignette, encode", fontsize=8)
    axes[1].imshow(marked, interpolation="nearest")
    axes[1].set_title(f"1 code off the reference (crop, 1:1):\nrelaxed {100 * pipe['relaxed']['pixels'] / n:.1f}%"
                      f" (red), full {pipe['full']['pixels']} px (blue), NumPy {pipe['numpy']['pixels']} px",
                      fontsize=8)
    for ax in axes:
        ax.axis("off")
    fig.tight_layout()
    save_png(fig, path)


def _numbers(d):
    """``d`` without its arrays: the numeric results only."""
    return {k: _numbers(v) if isinstance(v, dict) else v for k, v in d.items()
            if not isinstance(v, np.ndarray)}


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=os.path.join("out", "examples"), help="output directory")
    parser.add_argument("--repeat", type=int, default=5, help="timing repetitions (best is kept)")
    args = parser.parse_args(argv)
    photo = load_photograph()
    results = run(photo, repeat=args.repeat)
    print(report(results))
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, "gamma.png")
    save_figure(results, path)
    print(f"wrote {path}")
    results = _numbers(results)
    results["image"] = path
    return results


if __name__ == "__main__":
    main()
