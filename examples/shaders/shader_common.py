"""The harness the shader ports share: pixel grids, 8-bit codes, comparisons, timing, PNG, command line.

Nothing here is shader code: the ports in this directory are straight translations of public GLSL
shaders, and this module only feeds them pixels and measures what comes out.

* ``fragcoords(w, h)``: ``gl_FragCoord.xy`` of every pixel centre, as a row (x) and a column (y) that
  broadcast against each other (NumPy does the meshgrid; the kernel's vector loop takes the column's
  element as a broadcast scalar). Row 0 of an image is its top, as GLSL's y = h - 0.5.
* ``compare(rgb, reference)``: the 8-bit codes of a render against those of the float64 reference:
  how many codes (channel values) and pixels differ, by how much at most, and the largest error
  before quantization (in codes, on values clamped to [0, 1]).
* ``best_time``, ``timed_build``: milliseconds, best of N calls after a warm-up / one build.
* ``single_thread()``: reactor's calls on one thread (restored after), for fair timings.
* ``port_lines(path)``: code lines of the port, between its ``# --- DSL port`` markers (blank and
  comment-only lines not counted; the GLSL figures in the docstrings are counted the same way).
* ``shader_main``: the command line of a port (``--out``, ``--size``, ``--repeat``).
"""
from __future__ import annotations

import argparse
import contextlib
import os
import time

import numpy as np

DEFAULT_OUT = os.path.join("out", "examples", "shaders")


def fragcoords(width: int, height: int):
    """``gl_FragCoord.x`` as a (1, w) row and ``gl_FragCoord.y`` as an (h, 1) column, float32; image
    row 0 is the top (GLSL's y grows upwards)."""
    x = (np.arange(width, dtype=np.float32) + np.float32(0.5))[None, :]
    y = (np.float32(height) - np.float32(0.5) - np.arange(height, dtype=np.float32))[:, None]
    return x, y


def best_time(fn, *args, repeat: int = 5, **kwargs) -> float:
    """The best of ``repeat`` calls in milliseconds, after one warm-up call."""
    fn(*args, **kwargs)
    best = float("inf")
    for _ in range(max(1, repeat)):
        t0 = time.perf_counter()
        fn(*args, **kwargs)
        best = min(best, time.perf_counter() - t0)
    return best * 1e3


def timed_call(fn, *args):
    """``(fn(*args), milliseconds)``: one call, for the slow NumPy renders (no warm-up needed)."""
    t0 = time.perf_counter()
    result = fn(*args)
    return result, (time.perf_counter() - t0) * 1e3


def timed_build(factory, *args, **kwargs):
    """``(factory(*args, **kwargs), milliseconds)``: how long building a kernel took."""
    t0 = time.perf_counter()
    result = factory(*args, **kwargs)
    return result, (time.perf_counter() - t0) * 1e3


@contextlib.contextmanager
def single_thread():
    """Run reactor's kernels on one thread inside the block (the previous setting is restored)."""
    import reactor

    before = reactor.thread_settings()
    reactor.configure_threads(threads=1)
    try:
        yield
    finally:
        reactor.configure_threads(threads=before.threads)


def to_codes(channels) -> np.ndarray:
    """Channels (a sequence of same-shape arrays) -> H x W x C uint8 codes: clamped to [0, 1] and
    rounded; NaN counts as 0 (what a GPU's clamp gives on most hardware)."""
    a = np.stack([np.asarray(c, dtype=np.float64) for c in channels], axis=-1)
    a = np.nan_to_num(a, nan=0.0, posinf=1.0, neginf=0.0)
    return np.rint(np.clip(a, 0.0, 1.0) * 255.0).astype(np.uint8)


def compare(channels, reference) -> dict:
    """8-bit codes of ``channels`` against those of ``reference`` (float64)."""
    codes, ref = to_codes(channels), to_codes(reference)
    d = np.abs(codes.astype(np.int16) - ref.astype(np.int16))
    a = np.stack([np.asarray(c, dtype=np.float64) for c in channels], axis=-1)
    b = np.stack([np.asarray(c, dtype=np.float64) for c in reference], axis=-1)
    a = np.clip(np.nan_to_num(a, nan=0.0, posinf=1.0, neginf=0.0), 0, 1)
    b = np.clip(np.nan_to_num(b, nan=0.0, posinf=1.0, neginf=0.0), 0, 1)
    return {
        "codes": int(d.size),
        "codes_differing": int(np.count_nonzero(d)),
        "pixels_differing": int(np.count_nonzero(d.max(axis=-1))),
        "codes_over_1": int(np.count_nonzero(d > 1)),
        "max_code_diff": int(d.max()) if d.size else 0,
        "max_error_codes": float(np.abs(a - b).max() * 255.0) if d.size else 0.0,
        "nonfinite": int(sum(np.count_nonzero(~np.isfinite(np.asarray(c))) for c in channels)),
    }


def port_lines(path: str) -> int:
    """Code lines between the ``# --- DSL port`` begin/end markers of a module (blank lines, comment
    lines and docstring lines not counted)."""
    inside, n, in_doc = False, 0, False
    with open(path, encoding="utf-8") as f:
        for line in f:
            s = line.strip()
            if s.startswith("# --- DSL port begin"):
                inside = True
                continue
            if s.startswith("# --- DSL port end"):
                inside = False
                continue
            if not inside or not s or s.startswith("#"):
                continue
            if s.startswith(('"""', "'''")):
                quote = s[:3]
                if not (len(s) > 3 and s.endswith(quote)):
                    in_doc = not in_doc
                continue
            if in_doc:
                continue
            n += 1
    return n


def save_panels(path: str, panels, gap: int = 6) -> None:
    """Write the H x W x 3 uint8 ``panels`` side by side (white gaps) as one PNG."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.image

    h = max(p.shape[0] for p in panels)
    parts = []
    for i, p in enumerate(panels):
        if p.shape[0] < h:
            p = np.concatenate([p, np.full((h - p.shape[0],) + p.shape[1:], 255, np.uint8)])
        if i:
            parts.append(np.full((h, gap, 3), 255, np.uint8))
        parts.append(p)
    matplotlib.image.imsave(path, np.concatenate(parts, axis=1))


def difference_panel(codes: np.ndarray, ref: np.ndarray, scale: int = 64) -> np.ndarray:
    """An RGB picture of where two 8-bit renders differ: black where equal, brighter per code."""
    d = np.abs(codes.astype(np.int16) - ref.astype(np.int16)).max(axis=-1)
    v = np.clip(d * scale, 0, 255).astype(np.uint8)
    return np.stack([v, v // 2, np.zeros_like(v)], axis=-1)


def parse(argv, doc: str, default_size: int = 512, out: str = DEFAULT_OUT):
    parser = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    parser.add_argument("--out", default=out, help="output directory for the PNG")
    parser.add_argument("--size", type=int, default=default_size, help="image width in pixels")
    parser.add_argument("--repeat", type=int, default=5, help="timing repetitions (the best is kept)")
    return parser.parse_args(argv)


def shader_main(argv, doc: str, name: str, run, report, default_size: int = 512, out: str = DEFAULT_OUT,
                save=None) -> dict:
    """Parse the command line, ``run(size=, repeat=)`` on one thread (returns figures and
    ``panels``), print ``report``, write ``<out>/<name>.png`` (``save(path, figures)``: another
    picture); return the figures with ``image`` (the path)."""
    args = parse(argv, doc, default_size, out)
    with single_thread():
        r = run(size=args.size, repeat=args.repeat)
    print(report(r))
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, f"{name}.png")
    (save or (lambda where, figures: save_panels(where, figures.pop("panels"))))(path, r)
    print(f"wrote {path}")
    r["image"] = path
    return r


def format_report(title: str, r: dict) -> str:
    """The common table of a port: accuracy against float64, build and run times, line counts."""
    lines = [title]
    lines.append(f"  {'':22s}{'codes differing':>18s}{'max diff':>9s}{'max err':>9s}{'ms':>9s}")
    for name, acc in r["accuracy"].items():
        ms = r["ms"].get(name)
        pct = 100.0 * acc["codes_differing"] / max(1, acc["codes"])
        lines.append(f"  {name:22s}{acc['codes_differing']:>10,d} ({pct:4.1f}%){acc['max_code_diff']:>7d}"
                     f"{acc['max_error_codes']:>9.2f}{ms if ms is not None else float('nan'):>9.2f}")
    builds = ", ".join(f"{k} {v:.0f}" for k, v in r["build_ms"].items())
    lines.append(f"  build (ms): {builds}")
    lines.append(f"  DSL full vs NumPy float32: {r['ms']['numpy_f32'] / r['ms']['full']:.1f}x faster; "
                 f"lines: DSL port {r['lines']['dsl']}, GLSL original {r['lines']['glsl']}")
    return "\n".join(lines)
