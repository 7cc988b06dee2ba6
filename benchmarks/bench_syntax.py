"""Python's own control flow against the hand-written forms, same run, one thread, 1M float32:
a per-lane if/else against Select, a plain while with break against the hand-masked While; and
what rewriting a PBR-size body costs (examples/shaders/gltf_pbr.py's main_image).

    python benchmarks/bench_syntax.py
"""
import importlib.util
import pathlib
import statistics
import time

import numpy as np

import reactor
from reactor import Break, Float, If, Select, Variable, While, kernel, syntax

ROOT = pathlib.Path(__file__).resolve().parents[1]


@kernel
def plain_if(x: Float) -> Float:
    if x > 0.5:
        r = x * x + 1.0
    else:
        r = x * 0.5 - 2.0
    return r


@kernel
def with_select(x: Float) -> Float:
    return Select(x > 0.5, x * x + 1.0, x * 0.5 - 2.0)


@kernel
def plain_while(x: Float) -> Float:
    v = x
    while v < 1000.0:
        v = v * 1.5 + 0.25
        if v > 900.0:
            break
    return v


@kernel
def hand_while(x: Float) -> Float:
    v = Variable(Float, x)
    with While(lambda: v < 1000.0):
        v.set(v * 1.5 + 0.25)
        with If(v > 900.0):
            Break()
    return v


def _best(f, rounds: int) -> float:
    best = float("inf")
    for _ in range(rounds):
        t = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t)
    return best


def main() -> None:
    x = np.random.default_rng(1).uniform(0.01, 2, 1 << 20).astype(np.float32)
    out = np.empty_like(x)
    reactor.configure_threads(threads=1)
    assert np.array_equal(plain_if(x), with_select(x)) and np.array_equal(plain_while(x), hand_while(x))
    for name, a, b in (("if/else vs Select", plain_if, with_select), ("while+break vs While", plain_while,
                                                                       hand_while)):
        ta = min(_best(lambda: a(x, out=out), 5) for _ in range(9))
        tb = min(_best(lambda: b(x, out=out), 5) for _ in range(9))
        print(f"{name:22s} plain {ta * 1e3:.3f} ms  hand {tb * 1e3:.3f} ms  plain/hand {ta / tb:.3f}")
    spec = importlib.util.spec_from_file_location("pbr", ROOT / "examples" / "shaders" / "gltf_pbr.py")
    pbr = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(pbr)
    times = []
    for _ in range(40):
        t = time.perf_counter()
        syntax(pbr.main_image)
        times.append(time.perf_counter() - t)
    print(f"rewriting gltf_pbr's main_image: median {statistics.median(times) * 1e3:.2f} ms, "
          f"best {min(times) * 1e3:.2f} ms")


if __name__ == "__main__":
    main()
