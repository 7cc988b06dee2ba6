"""A kernel that travels: a large image rendered chunk by chunk with dask, locally and on a cluster.

    python examples/cluster.py [--size 16384] [--workers 2] [--chunk 2048] [--out DIR]

A procedural shader (a soft spot light with ``exp2`` falloff and ``pow`` gamma) is evaluated on a
size x size image whose pixel coordinates are lazy dask arrays, so no process ever holds more than
a few chunks: once in this process on NumPy arrays (the baseline; one call on the whole image when
it fits), once with dask's threaded scheduler, once on a ``distributed.LocalCluster`` of worker
processes, to which the kernel travels as its recipe (pickled, rebuilt there for that CPU). Every
run reduces the image to its mean and a 1/16 preview, which must be the same bits in all three.
Prints megapixels per second and the pickle round trip of the kernel; writes the preview as PNG.
Needs the distributed extra: ``pip install "reactor-simd[distributed]"``.
"""
from __future__ import annotations

import argparse
import os
import pickle
import sys
import time

import numpy as np

import reactor
import routines
from reactor import Float, Select


# --- DSL begin
@reactor.kernel
def spot(u: Float, v: Float) -> Float:
    """A soft spot light: exp2 falloff from the centre, a cosine-like rim, gamma 1/2.2."""
    d2 = (u - 0.5) * (u - 0.5) + (v - 0.45) * (v - 0.45)
    light = routines.exp2(-12.0 * d2) + 0.05
    rim = Select(d2 < 0.16, 1.0 - 6.25 * d2, 0.0)
    return routines.pow(light * (0.7 + 0.3 * rim), 1.0 / 2.2)
# --- DSL end


def coordinates(size: int, chunk: int):
    import dask.array as da
    axis = (da.arange(size, chunks=chunk, dtype=np.float32) + np.float32(0.5)) / np.float32(size)
    return axis[None, :], axis[:, None]


def summarize(image):
    """The image's mean (in float64) and a 1/16 preview: what every run must agree on."""
    return image.mean(dtype=np.float64), image[::16, ::16]


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--size", type=int, default=16384, help="image side in pixels (16384)")
    parser.add_argument("--chunk", type=int, default=2048, help="chunk side (2048)")
    parser.add_argument("--workers", type=int, default=2, help="worker processes of the local cluster (2)")
    parser.add_argument("--out", default=os.path.join("out", "examples"), help="where the preview goes")
    args = parser.parse_args(argv)
    try:
        import dask
        import distributed
    except ImportError:
        print('this example needs dask.distributed: pip install "reactor-simd[distributed]"', file=sys.stderr)
        return {}
    mpix = args.size * args.size / 1e6
    figures: dict = {"size": args.size, "megapixels": mpix}

    t = time.perf_counter()
    for _ in range(20):
        pickle.loads(pickle.dumps(spot))
        pickle.loads(pickle.dumps(routines.jit("exp2")))
    figures["pickle_round_trip_ms"] = (time.perf_counter() - t) / 40 * 1e3

    u, v = coordinates(args.size, args.chunk)
    runs = {}
    if mpix <= 300:  # one call on the whole image in this process: the baseline
        uu, vv = u.compute(), v.compute()
        t = time.perf_counter()
        whole = spot(uu, vv)
        runs["one process, one call"] = (time.perf_counter() - t, summarize(whole))
        del whole
    lazy = spot(u, v)  # NumPy hands the call to dask: a lazy array, chunk by chunk
    mean, preview = summarize(lazy)
    t = time.perf_counter()
    runs["dask threads"] = (0.0, dask.compute(mean, preview, scheduler="threads"))
    runs["dask threads"] = (time.perf_counter() - t, runs["dask threads"][1])
    with distributed.LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                                  dashboard_address=None, silence_logs=40) as cluster, distributed.Client(cluster):
        dask.compute(spot(u[:, :args.chunk], v[:args.chunk]))  # the workers build the kernel (their caches)
        t = time.perf_counter()
        result = dask.compute(mean, preview)
        runs[f"local cluster, {args.workers} processes"] = (time.perf_counter() - t, result)
    reference = next(iter(runs.values()))[1]
    print(f"{args.size} x {args.size} image ({mpix:,.0f} Mpixel), chunks of {args.chunk}^2; "
          f"pickle round trip {figures['pickle_round_trip_ms']:.3f} ms")
    for name, (seconds, (m, p)) in runs.items():
        same = m == reference[0] and np.array_equal(np.asarray(p).view(np.uint32),
                                                    np.asarray(reference[1]).view(np.uint32))
        figures[name] = {"seconds": seconds, "mpix_per_s": mpix / seconds, "same_bits": bool(same)}
        print(f"  {name:<32} {seconds:7.2f} s  {mpix / seconds:8.1f} Mpixel/s  same bits: {same}")
    os.makedirs(args.out, exist_ok=True)
    try:
        import matplotlib.pyplot as plt
        path = os.path.join(args.out, "cluster.png")
        plt.imsave(path, np.asarray(reference[1]), cmap="gray", vmin=0, vmax=1)
        print(f"wrote {path}")
    except ImportError:
        pass
    return figures


if __name__ == "__main__":
    main()
