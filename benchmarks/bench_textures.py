"""Tables, textures and vector operands: what per-lane reads and (H, W, C) arrays cost, on one thread.

``python benchmarks/bench_textures.py [--json F] [--quick]`` prints, same run, one thread
(``reactor.configure_threads(threads=1)``), best of N calls:

1. **gathers**: a kernel reading ``Table[Float]`` (a 1M-element table, 4 MB) at random per-lane
   indices and at sequential ones, against a kernel reading a contiguous input of the same length
   (elements/s and the ratio), with NumPy's ``np.take`` beside them;
2. **texture sampling**: ns per sample of a 1024 x 1024 RGBA texture, float32 (``vec4``) and RGBA8
   (``u8vec4``, normalized to [0, 1]), sampled at 2048 x 2048 uv, random and on a rotated grid
   (30 degrees, 0.6 texels per pixel: neighbouring pixels read neighbouring texels), bilinear and
   nearest, ``"clamp"``; bilinear ``"repeat"`` too (its wrap is an integer remainder); against a NumPy
   float32 bilinear of the same formula;
3. **the (H, W, 3) path**: ``shade(n: vec3, l: vec3) -> vec4`` on a 2048 x 2048 x 3 float32 array
   (the light a broadcast (3,) array) against the same body over three float32 planes returning
   four planes, and against NumPy float32 (target: HWC at most 1.25x the planar time);
4. **sRGB8 encode** of 2^22 values in [0, 1]: ``routines.pixels.srgb8_encode`` (exact),
   ``srgb8_encode_pow`` (full pow, no correction), ``encode(x, "unorm8")`` (no transfer curve) and
   NumPy float32, with the codes each gets wrong against the exact thresholds.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import numpy as np  # noqa: E402

import reactor  # noqa: E402
from reactor import Float, Int, Max, Table, Texture2D, UByte, kernel, u8vec4, vec3, vec4  # noqa: E402
from routines import pixels  # noqa: E402


def best(fn, reps: int) -> float:
    """Seconds: the best of ``reps`` calls after one warm-up."""
    fn()
    t = float("inf")
    for _ in range(reps):
        t0 = time.perf_counter()
        fn()
        t = min(t, time.perf_counter() - t0)
    return t


# -- 1. gathers --------------------------------------------------------------------------------------

@kernel(name="bench_gather")
def gather(i: Int, t: Table[Float]) -> Float:
    return t[i]


@kernel(name="bench_stream")
def stream(i: Int, x: Float) -> Float:
    """The contiguous baseline: the same index stream read, plus a contiguous float input."""
    return x + Float(i) * 0.0


def bench_gathers(reps: int) -> dict:
    n = 1 << 20
    rng = np.random.default_rng(0)
    table = rng.random(n).astype(np.float32)
    out = np.empty(n, np.float32)
    idx = {"random": rng.integers(0, n, n).astype(np.int32), "sequential": np.arange(n, dtype=np.int32)}
    rows = {}
    for name, i in idx.items():
        assert np.array_equal(gather(i, table), table[i])
        rows[f"table[i] {name}"] = best(lambda i=i: gather(i, table, out=out), reps)
        rows[f"np.take {name}"] = best(lambda i=i: np.take(table, i, out=out), reps)
    rows["contiguous input"] = best(lambda: stream(idx["sequential"], table, out=out), reps)
    base = rows["contiguous input"]
    return {"n": n, "table_bytes": table.nbytes,
            "rows": {k: {"ms": t * 1e3, "elements_per_s": n / t, "vs_contiguous": t / base} for k, t in rows.items()}}


# -- 2. texture sampling -----------------------------------------------------------------------------

def _sampler(texel, wrap: str, filt: str):
    # the types are given explicitly: under ``from __future__ import annotations`` an annotation
    # naming the local ``texel`` cannot be evaluated (reactor says so and names this fix)
    return kernel(lambda u, v, tex: tex.sample(u, v), args=[Float, Float, Texture2D[texel, wrap, filt]],
                  returns=vec4, name=f"bench_sample_{texel.__name__}_{wrap}_{filt}")


def numpy_bilinear(tex, u, v):
    """The DSL's bilinear formula in NumPy float32 with clamp: ``tex`` (H, W, 4) float32 or uint8."""
    F = np.float32
    h, w = tex.shape[:2]
    t = tex.astype(F) / F(255) if tex.dtype == np.uint8 else tex
    x, y = u * F(w) - F(0.5), v * F(h) - F(0.5)
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    xi, yi = x0.astype(np.int64), y0.astype(np.int64)
    xa, xb = np.clip(xi, 0, w - 1), np.clip(xi + 1, 0, w - 1)
    ya, yb = np.clip(yi, 0, h - 1), np.clip(yi + 1, 0, h - 1)
    return ((t[ya, xa] * (F(1) - fx) + t[ya, xb] * fx) * (F(1) - fy)
            + (t[yb, xa] * (F(1) - fx) + t[yb, xb] * fx) * fy)


def bench_sampling(reps: int, np_reps: int) -> dict:
    size, tsize = 2048, 1024
    rng = np.random.default_rng(1)
    textures = {"f32": rng.random((tsize, tsize, 4)).astype(np.float32),
                "u8": rng.integers(0, 256, (tsize, tsize, 4)).astype(np.uint8)}
    texel = {"f32": vec4, "u8": u8vec4}
    ys, xs = np.mgrid[0:size, 0:size].astype(np.float32)
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    scale = np.float32(0.6 / tsize)               # 0.6 texels per pixel
    uvs = {"random": (rng.random((size, size), dtype=np.float32), rng.random((size, size), dtype=np.float32)),
           "rotated": ((xs * np.float32(c) - ys * np.float32(s)) * scale + np.float32(0.3),
                       (xs * np.float32(s) + ys * np.float32(c)) * scale + np.float32(0.05))}
    out = np.empty((size, size, 4), np.float32)
    n = size * size
    rows = []
    for kind in ("f32", "u8"):
        for filt, wrap in (("linear", "clamp"), ("nearest", "clamp"), ("linear", "repeat")):
            k = _sampler(texel[kind], wrap, filt)
            for where, (u, v) in uvs.items():
                t = best(lambda k=k, u=u, v=v: k(u, v, textures[kind], out=out), reps)
                rows.append({"texture": kind, "filter": filt, "wrap": wrap, "uv": where, "who": "reactor",
                             "ns_per_sample": t / n * 1e9})
        for where, (u, v) in uvs.items():
            got = _sampler(texel[kind], "clamp", "linear")(u[:64], v[:64], textures[kind])
            ref = numpy_bilinear(textures[kind], u[:64], v[:64])
            assert np.allclose(got, ref, atol=1e-5), "the NumPy bilinear is not the DSL's formula"
            t = best(lambda u=u, v=v: numpy_bilinear(textures[kind], u, v), np_reps)
            rows.append({"texture": kind, "filter": "linear", "wrap": "clamp", "uv": where, "who": "numpy_f32",
                         "ns_per_sample": t / n * 1e9})
    return {"samples": n, "texture": [tsize, tsize, 4], "rows": rows}


# -- 3. (H, W, 3) against planes ---------------------------------------------------------------------

@kernel(name="bench_shade_hwc")
def shade_hwc(n: vec3, l: vec3) -> vec4:
    d = Max(n.x * l.x + n.y * l.y + n.z * l.z, 0.0)
    return vec4(n * d, 1.0)


@kernel(name="bench_shade_planar")
def shade_planar(nx: Float, ny: Float, nz: Float, lx: Float, ly: Float, lz: Float) -> (Float, Float, Float, Float):
    d = Max(nx * lx + ny * ly + nz * lz, 0.0)
    return nx * d, ny * d, nz * d, d * 0.0 + 1.0


def numpy_shade(n, light):
    d = np.maximum(n @ light, np.float32(0))[..., None]
    return np.concatenate([n * d, np.ones(d.shape, np.float32)], -1)


def bench_hwc(reps: int, np_reps: int) -> dict:
    size = 2048
    rng = np.random.default_rng(2)
    n = rng.standard_normal((size, size, 3)).astype(np.float32)
    light = np.array([0.3, 0.8, 0.5], np.float32)
    planes = [np.ascontiguousarray(n[..., c]) for c in range(3)]
    lx, ly, lz = (np.float32(c) for c in light)
    out = np.empty((size, size, 4), np.float32)
    outs = tuple(np.empty((size, size), np.float32) for _ in range(4))
    hwc = shade_hwc(n, light)
    assert np.array_equal(np.stack(shade_planar(*planes, lx, ly, lz), -1), hwc)
    rows = {"HWC (2048, 2048, 3) -> (2048, 2048, 4)": best(lambda: shade_hwc(n, light, out=out), reps),
            "planar 3 planes -> 4 planes": best(lambda: shade_planar(*planes, lx, ly, lz, out=outs), reps),
            "NumPy float32 (HWC)": best(lambda: numpy_shade(n, light), np_reps)}
    planar = rows["planar 3 planes -> 4 planes"]
    return {"pixels": size * size, "rows": {k: {"ms": t * 1e3, "ns_per_pixel": t / size ** 2 * 1e9,
                                                "vs_planar": t / planar} for k, t in rows.items()}}


# -- 4. sRGB8 encode ---------------------------------------------------------------------------------

def bench_encode(reps: int, np_reps: int) -> dict:
    x = np.random.default_rng(3).random(1 << 22).astype(np.float32)
    exact = kernel(lambda v: pixels.srgb8_encode(v), args=[Float], returns=UByte, name="bench_srgb8_exact")
    with_pow = kernel(lambda v: pixels.srgb8_encode_pow(v), args=[Float], returns=UByte, name="bench_srgb8_pow")
    unorm = kernel(lambda v: pixels.encode(v, "unorm8"), args=[Float], returns=UByte, name="bench_unorm8")
    out = np.empty(x.shape, np.uint8)

    def numpy_encode():
        y = np.where(x <= np.float32(0.0031308), x * np.float32(12.92),
                     np.float32(1.055) * np.power(x, np.float32(1 / 2.4)) - np.float32(0.055))
        return np.rint(y * np.float32(255)).astype(np.uint8)

    ref = np.searchsorted(pixels.srgb8_thresholds(), x, side="right")
    rows = {"srgb8_encode (exact)": (best(lambda: exact(x, out=out), reps), int(np.count_nonzero(exact(x) != ref))),
            "srgb8_encode_pow (full pow)": (best(lambda: with_pow(x, out=out), reps),
                                            int(np.count_nonzero(with_pow(x) != ref))),
            "NumPy float32 sRGB": (best(numpy_encode, np_reps), int(np.count_nonzero(numpy_encode() != ref))),
            "encode unorm8 (no curve)": (best(lambda: unorm(x, out=out), reps), None)}
    return {"values": len(x), "rows": {k: {"ms": t * 1e3, "ns_per_value": t / len(x) * 1e9, "codes_off": off}
                                       for k, (t, off) in rows.items()}}


# -- report ------------------------------------------------------------------------------------------

def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--json", help="write every figure to this file")
    parser.add_argument("--quick", action="store_true", help="fewer repetitions")
    args = parser.parse_args(argv)
    reps, np_reps = (3, 1) if args.quick else (9, 3)
    saved = reactor.thread_settings()
    reactor.configure_threads(threads=1)
    try:
        result = {"target": reactor.get_target().name if hasattr(reactor.get_target(), "name") else
                  str(reactor.get_target()), "reps": reps, "numpy_reps": np_reps}
        result["gathers"] = g = bench_gathers(reps)
        print(f"1. gathers: {g['n']:,} reads of a {g['table_bytes'] / 2**20:.0f} MiB Table[Float], one thread")
        print(f"   {'':28s}{'ms':>8s}{'Melem/s':>10s}{'time vs contiguous':>20s}")
        for k, r in g["rows"].items():
            print(f"   {k:28s}{r['ms']:8.2f}{r['elements_per_s'] / 1e6:10.0f}{r['vs_contiguous']:19.2f}x")

        result["sampling"] = s = bench_sampling(reps, np_reps)
        print(f"\n2. texture sampling: {s['samples']:,} samples of a 1024 x 1024 RGBA texture (ns/sample)")
        print(f"   {'texture':8s}{'filter':9s}{'wrap':8s}{'who':11s}{'random uv':>11s}{'rotated uv':>12s}")
        keyed = {}
        for r in s["rows"]:
            keyed.setdefault((r["texture"], r["filter"], r["wrap"], r["who"]), {})[r["uv"]] = r["ns_per_sample"]
        for (tex, filt, wrap, who), v in keyed.items():
            print(f"   {tex:8s}{filt:9s}{wrap:8s}{who:11s}{v['random']:11.2f}{v['rotated']:12.2f}")

        result["hwc"] = h = bench_hwc(reps, np_reps)
        print(f"\n3. (H, W, 3) vector operands: shade(n: vec3, l: vec3) -> vec4 on {h['pixels']:,} pixels")
        for k, r in h["rows"].items():
            print(f"   {k:40s}{r['ms']:8.2f} ms{r['ns_per_pixel']:8.2f} ns/pixel{r['vs_planar']:7.2f}x planar")

        result["encode"] = e = bench_encode(reps, np_reps)
        print(f"\n4. sRGB8 encode of {e['values']:,} values in [0, 1]")
        for k, r in e["rows"].items():
            off = "" if r["codes_off"] is None else f"{r['codes_off']:>10,} codes off"
            print(f"   {k:30s}{r['ms']:8.2f} ms{r['ns_per_value']:8.3f} ns/value{off}")
    finally:
        reactor.configure_threads(**saved._asdict())
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)
    return result


if __name__ == "__main__":
    main()
