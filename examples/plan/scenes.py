"""Scenes planned by ``reactor.plan``: each call site's cheapest tier that changes no stored output.

    python examples/plan/scenes.py [--out DIR] [--size N] [--only NAME ...] [--target avx2 [--machine zen3]]

Each scene is a kernel, the domain of its inputs and the formats it is stored in. For every
(scene, format) the planner picks each routine call site's tier so that the stored output is
identical to the most accurate build's (every routine correctly rounded) on every input of the
domain (exhaustive: every row is checked), and the same run times every all-one-tier build and the
plan. Writes ``DIR/plans.json`` (every plan
as data), ``DIR/chart.png`` (per scene: modelled cost against outputs changed) and prints a table.

Scenes (the first four are here; the others are the ports in examples/shaders, their inputs the
scene's pixels, so "exhaustive" means: every pixel of that render):

* ``srgb_blit``: an 8-bit sRGB texture drawn into an sRGB render target through linear light
  (GL_FRAMEBUFFER_SRGB: decode with the IEC 61966-2-1 curve, encode again); unorm8 and unorm10.
* ``exposure``: a half-float HDR value (every finite float16) times 2^stops for five exposure
  stops, Reinhard, sRGB-encoded; unorm8 and unorm10.
* ``linear_half``: an 8-bit sRGB texture converted to a linear half-float target; float16, unorm16
  and unorm8.
* ``gamma_exposure``: an 8-bit gamma-2.2 value decoded, exposed by -2 to +2 stops (an 8-bit
  control), clipped and encoded again: every unorm8 x unorm8 pair; unorm8 and unorm10.
* ``tonemap`` (three.js ACES + AgX + sRGB OETF on an HDR chart), ``gltf_pbr`` (glTF viewer GGX),
  ``raymarch`` (sphere tracer with soft shadows and reflections): unorm8 and one wider format.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "shaders"))

import reactor  # noqa: E402
from reactor import Float, Min, Rows, Select, kernel  # noqa: E402
from routines import glsl as gl  # noqa: E402

DEFAULT_OUT = os.path.join("out", "examples", "plan")


# --- DSL begin
def srgb_decode(c):
    return Select(c <= 0.04045, c * (1.0 / 12.92), gl.pow((c + 0.055) * (1.0 / 1.055), 2.4))


def srgb_encode(v):
    return Select(v <= 0.0031308, v * 12.92, 1.055 * gl.pow(v, 1.0 / 2.4) - 0.055)


@kernel
def srgb_blit(c: Float) -> Float:
    return srgb_encode(srgb_decode(c))


@kernel
def exposure(x: Float, stops: Float) -> Float:
    v = x * gl.exp2(stops)
    return srgb_encode(v / (1.0 + v))


@kernel
def linear_half(c: Float) -> Float:
    return srgb_decode(c)


@kernel
def gamma_exposure(c: Float, s: Float) -> Float:
    v = gl.pow(c, 2.2) * gl.exp2(s * 4.0 - 2.0)  # decode gamma 2.2, expose by -2..+2 stops
    return gl.pow(Min(v, 1.0), 1.0 / 2.2)          # clip, encode gamma 1/2.2
# --- DSL end


STOPS = [-2.0, -1.0, 0.0, 1.0, 2.0]


def _rows(kern_ufunc, args) -> Rows:
    """The pixels of a port's render as joint rows (broadcast rows, columns and scalars expanded)."""
    names = reactor.kernel_of(kern_ufunc).signature.names
    arrays = np.broadcast_arrays(*[np.asarray(a, np.float32) for a in args])
    return Rows(**{n: a.ravel() for n, a in zip(names, arrays)})


def _port(module_name: str, size: int, target: str | None = None):
    module = __import__(module_name)
    u = reactor.kernel(module.main_image, name=module_name, **({"target": target} if target else {}))
    return u, {"rows": _rows(u, module.inputs(size))}


def _for(u, target: str | None):
    """The kernel ``u`` built for ``target`` (None: as it is, for this CPU)."""
    if target is None:
        return u
    k = reactor.kernel_of(u)
    return reactor.kernel(k.body, name=k.name, args=list(k.signature.params), target=target)


def scenes(size: int, target: str | None = None) -> list[tuple[str, object, dict, list, int]]:
    """(name, kernel, inputs, formats, timing rows) of every scene; ``size``: the ports' width;
    ``target``: the x86 level the kernels are built for (None: this CPU's)."""
    ports = [("tonemap", ["unorm8", "float16"], 1 << 20), ("gltf_pbr", ["unorm8", "unorm10"], 1 << 20),
             ("raymarch", ["unorm8", "unorm16"], 1 << 16)]
    found = [("srgb_blit", srgb_blit, {"c": "unorm8"}, ["unorm8", "unorm10"], 1 << 20),
             ("exposure", exposure, {"x": "float16", "stops": STOPS}, ["unorm8", "unorm10"], 1 << 20),
             ("linear_half", linear_half, {"c": "unorm8"}, ["float16", "unorm16", "unorm8"], 1 << 20),
             ("gamma_exposure", gamma_exposure, {"c": "unorm8", "s": "unorm8"}, ["unorm8", "unorm10"], 1 << 20)]
    found = [(name, _for(u, target), inputs, formats, timing) for name, u, inputs, formats, timing in found]
    for name, formats, timing in ports:
        port_size = size if name != "raymarch" else size // 2
        u, inputs = _port(name, port_size, target)
        found.append((name, u, inputs, formats, timing))
    return found


def run(size: int = 128, only=None, target: str | None = None, machine: str | None = None) -> dict:
    """Plan every scene for every format; the figures as a dict (see the module docstring).
    ``machine``: the cost model's table the plans rank builds by (None: this host's)."""
    results = []
    with reactor.options():
        for name, u, inputs, formats, timing in scenes(size, target):
            if only and name not in only:
                continue
            for fmt in formats:
                p = reactor.plan(u, inputs=inputs, output=fmt, timing_rows=timing, machine=machine)
                results.append({"scene": name, "format": fmt, "plan": p.to_json(), "text": str(p),
                                "speedup": p.times_ms["all full"] / p.times_ms["plan"],
                                "speedup_correct": p.times_ms["all correct"] / p.times_ms["plan"],
                                "model_speedup": p.cycles["all full"] / p.cycles["plan"]})
    return {"size": size, "target": target or "host", "machine": machine or "host", "results": results}


def table(r: dict) -> str:
    """One row per (scene, format): the sites at each tier, what all-relaxed and all-full change
    against the correctly rounded reference, and the plan's speed against all-full and all-correct."""
    rows = [f"{'scene':<14} {'format':<8} {'proof':<11} {'rows':>10} {'sites':>5} {'relaxed':>7} {'between':>7} "
            f"{'full':>4} {'above':>5} {'relaxed: changed':>16} {'full: changed':>13} {'plan: changed':>13} "
            f"{'model x':>7} {'timed x':>7} {'x correct':>9} {'plan s':>6}"]
    for x in r["results"]:
        p = x["plan"]
        tiers = [s["tier"] for s in p["reports"]]
        between = sum(t.startswith("full-") for t in tiers)  # the continuum's variants
        rows.append(f"{x['scene']:<14} {x['format']:<8} {p['proof']:<11} {p['checked']:>10,} {len(tiers):>5} "
                    f"{tiers.count('relaxed'):>7} {between:>7} {tiers.count('full'):>4} "
                    f"{len(tiers) - tiers.count('relaxed') - tiers.count('full') - between:>5} "
                    f"{p['changes']['all relaxed']:>16,} {p['changes']['all full']:>13,} {p['changes']['plan']:>13,} "
                    f"{x['model_speedup']:>7.2f} {x['speedup']:>7.2f} {x['speedup_correct']:>9.2f} "
                    f"{p['seconds']:>6.1f}")
    return "\n".join(rows)


def chart(r: dict, path: str) -> None:
    """Per scene and format: modelled cycles/element against outputs changed, for all-relaxed,
    all-full and the plan (the plan's point: no change, at the lowest cost that allows it)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    results = r["results"]
    cols = 4
    rows = -(-len(results) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 3.0 * rows), squeeze=False)
    for ax, x in zip(axes.flat, results):
        p = x["plan"]
        styles = {"plan": ("*", "tab:green")}
        others = [label for label in p["cycles"] if label != "plan"]  # every tier: "all relaxed", "all full", ...
        for i, label in enumerate(others):
            styles[label] = ("vsDo"[i % 4], ("tab:orange", "tab:blue", "tab:purple", "tab:red")[i % 4])
        for label in others + ["plan"]:
            marker, colour = styles[label]
            ax.scatter(p["cycles"][label], p["changes"][label] + 0.5, marker=marker, s=110 if label == "plan" else 45,
                       color=colour, label=label, zorder=3 if label == "plan" else 2)
        ax.set_yscale("log")
        ax.set_title(f"{x['scene']} -> {x['format']} ({p['proof']})", fontsize=9)
        ax.set_xlabel("modelled cycles / element", fontsize=8)
        ax.set_ylabel("outputs changed + 0.5", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(alpha=0.3)
    for ax in list(axes.flat)[len(results):]:
        ax.axis("off")
    axes.flat[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default=DEFAULT_OUT)
    parser.add_argument("--size", type=int, default=128, help="width of the ports' renders (raymarch: half)")
    parser.add_argument("--only", nargs="+", metavar="NAME", help="these scenes only")
    parser.add_argument("--target", help="build and plan for this x86 level (e.g. avx2; default: this CPU)")
    parser.add_argument("--machine", help="rank builds by this cost table (e.g. zen3 for an AVX2 host; "
                                          "default: this CPU's)")
    args = parser.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    t0 = time.perf_counter()
    r = run(args.size, args.only, args.target, args.machine)
    print(table(r))
    for x in r["results"]:
        print("\n" + x["text"])
    with open(os.path.join(args.out, "plans.json"), "w") as f:
        json.dump(r, f, indent=1)
    chart(r, os.path.join(args.out, "chart.png"))
    print(f"\nwrote {args.out}/plans.json and chart.png ({time.perf_counter() - t0:.0f} s)")
    r["out"] = args.out
    return r


if __name__ == "__main__":
    main()
