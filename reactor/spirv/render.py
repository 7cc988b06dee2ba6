"""A fragment shader rendered over a pixel grid, and a PNG written without extra packages: what
``python -m reactor glsl`` does."""
from __future__ import annotations

import struct
import zlib

import numpy as np

from .binary import SpirvError


def pixel_centres(width: int, height: int, bottom_left: bool) -> np.ndarray:
    """An (height, width, 2) float32 array of pixel centres, row 0 the top of the image; y counts
    from the bottom (WebGL, Shadertoy) or from the top (Vulkan's ``OriginUpperLeft``)."""
    y, x = np.mgrid[0:height, 0:width].astype(np.float32) + np.float32(0.5)
    if bottom_left:
        y = np.float32(height) - y
    return np.stack([x, y], -1)


def render(path: str, width: int, height: int, *, shadertoy: bool = False, time: float = 0.0,
           uniforms: dict | None = None, **options) -> np.ndarray:
    """The shader of the file ``path`` over ``width`` x ``height`` pixels as 8-bit RGBA, (height,
    width, 4). A Shadertoy shader gets ``iResolution`` and ``iTime``; another fragment shader may read
    ``gl_FragCoord`` and no other input."""
    from . import from_glsl

    coords = pixel_centres(width, height, bottom_left=shadertoy)
    if shadertoy:
        given = {"iResolution": (width, height, 1.0), "iTime": time, **(uniforms or {})}
        kernel = from_glsl(path, stage="shadertoy", uniforms=given, **options)
        color = kernel(coords)
    else:
        kernel = from_glsl(path, uniforms=uniforms, **options)
        if kernel.signature != "(4)->(4)" and not (kernel.signature or "").startswith("(4)->"):
            raise SpirvError(f"{path}: only a shader whose one input is gl_FragCoord renders over a grid "
                             f"(this one's kernel is {kernel.signature or kernel.nin}); call reactor.from_glsl from "
                             f"Python with arrays for its inputs")
        frag = np.concatenate([coords, np.zeros_like(coords[..., :1]), np.ones_like(coords[..., :1])], -1)
        color = kernel(frag)
    color = np.asarray(color if not isinstance(color, tuple) else color[0], np.float32)
    if color.ndim == 2:
        color = np.repeat(color[..., None], 3, -1)
    if color.shape[-1] == 3:
        color = np.concatenate([color, np.ones_like(color[..., :1])], -1)
    return np.round(np.clip(np.nan_to_num(color), 0, 1) * 255).astype(np.uint8)


def write_png(path: str, rgba: np.ndarray) -> None:
    """An 8-bit RGBA image as a PNG file."""
    height, width = rgba.shape[:2]
    raw = b"".join(b"\0" + rgba[row].tobytes() for row in range(height))

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))
