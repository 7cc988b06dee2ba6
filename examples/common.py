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
