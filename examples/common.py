"""Helpers shared by the examples: timing, 8-bit codes and PNG output."""
from __future__ import annotations

import io
import time

import numpy as np


def best_time(fn, *args, repeat: int = 5) -> float:
    """The best of ``repeat`` calls, in milliseconds (one warm-up call first)."""
    fn(*args)
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn(*args)
        best = min(best, time.perf_counter() - t0)
    return best * 1e3


def save_png(fig, path: str) -> None:
    """Save a matplotlib figure as an optimized RGB PNG (smaller than matplotlib's RGBA) and close it."""
    import matplotlib.pyplot as plt
    from PIL import Image

    buf = io.BytesIO()
    fig.savefig(buf, format="png", facecolor="white")
    plt.close(fig)
    buf.seek(0)
    Image.open(buf).convert("RGB").save(path, optimize=True)


def to_codes(rgb) -> np.ndarray:
    """Channels in [0, 1] (a sequence of arrays) -> an H x W x C array of 8-bit codes, rounded."""
    return np.rint(np.clip(np.stack(rgb, axis=-1).astype(np.float64), 0, 1) * 255).astype(np.uint8)


def timed_example_main(argv, doc: str, name: str, run, report, save_figure, drop=()) -> dict:
    """The command line of an example that times ``run(repeat=...)``: print ``report``, write
    ``<out>/<name>.png`` with ``save_figure``, return the numeric results (``drop``: large arrays)."""
    import argparse
    import os

    parser = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    parser.add_argument("--out", default=os.path.join("out", "examples"), help="output directory")
    parser.add_argument("--repeat", type=int, default=5, help="timing repetitions (best is kept)")
    args = parser.parse_args(argv)
    r = run(repeat=args.repeat)
    print(report(r))
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, f"{name}.png")
    save_figure(r, path)
    print(f"wrote {path}")
    for key in drop:
        del r[key]
    r["image"] = path
    return r
