"""A GLSL shader translated by reactor.from_glsl against its hand port, same run, one thread:
examples/glsl/fbm2d.frag (yiwenl/glsl-fbm's 2d.glsl, unchanged) and examples/shaders/noise.py.
The 8-bit codes and float bits that differ, the best call time of each (and their ratio), the cold
build of each (cache=False; glslang's run included for the GLSL), and the build from the disk cache.

    python benchmarks/bench_glsl_port.py [--size 512] [--rounds 7]
"""
import argparse
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "examples" / "shaders"))

import noise  # noqa: E402
from shader_common import to_codes  # noqa: E402

import reactor  # noqa: E402
import routines  # noqa: E402, F401 - the GLSL built-ins


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--size", type=int, default=512)
    p.add_argument("--rounds", type=int, default=7)
    a = p.parse_args()
    reactor.configure_threads(threads=1)
    args = noise.inputs(a.size)
    shader = ROOT / "examples" / "glsl" / "fbm2d.frag"
    t = time.perf_counter()
    hand = noise.build("full")
    build_hand = time.perf_counter() - t
    t = time.perf_counter()
    glsl = reactor.from_glsl(shader, cache=False, name="fbm2d_cold")
    build_glsl = time.perf_counter() - t
    reactor.from_glsl(shader, name="fbm2d_warm")  # into the disk cache
    t = time.perf_counter()
    reactor.from_glsl(shader, name="fbm2d_warm")
    warm = time.perf_counter() - t
    a_out, b_out = hand(*args), glsl(*args)
    times: dict = {"hand": [], "glsl": []}
    for _ in range(a.rounds):
        for name, k in (("hand", hand), ("glsl", glsl)):
            t = time.perf_counter()
            k(*args)
            times[name].append(time.perf_counter() - t)
    th, tg = min(times["hand"]), min(times["glsl"])
    print(f"{a.size}x{a.size}: 8-bit codes differing {int((to_codes(a_out) != to_codes(b_out)).sum())}, "
          f"float bits differing {int((a_out.view(np.uint32) != b_out.view(np.uint32)).sum())}")
    print(f"call: hand port {th * 1e3:.2f} ms, GLSL {tg * 1e3:.2f} ms, GLSL/hand {tg / th:.3f}")
    print(f"cold build: hand port {build_hand * 1e3:.0f} ms, GLSL {build_glsl * 1e3:.0f} ms, "
          f"GLSL/hand {build_glsl / build_hand:.2f}; from the disk cache {warm * 1e3:.1f} ms")


if __name__ == "__main__":
    main()
