"""Python's own control flow against the hand-written forms, same run, one thread, 1M float32:
a per-lane if/else against Select, a plain while with break against the hand-masked While; and
what the rewrite costs in a cold build of each of the five example shaders.

    python benchmarks/bench_syntax.py
"""
import importlib.util
import pathlib
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
    print(rewrite_share())


SHADERS = ("gltf_pbr", "noise", "raymarch", "tonemap", "sky")


def rewrite_share(rounds: int = 5) -> str:
    """What the rewrite costs in a cold build of each example shader (a fresh module: nothing of
    it rewritten yet; ``cache=False``): the time spent deciding (from bytecode) and rewriting,
    over the whole build, best of ``rounds``. A build from the disk cache traces nothing, so
    rewrites nothing."""
    import sys

    from reactor.dsl import syntax as written
    from reactor.jit import cache

    spent = {"s": 0.0, "depth": 0}

    def timed(fn):
        def wrapper(*args, **kwargs):
            spent["depth"] += 1
            t = time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                spent["depth"] -= 1
                if not spent["depth"]:
                    spent["s"] += time.perf_counter() - t
        return wrapper
    written.syntax, written._needs_rewrite = timed(written.syntax), timed(written._needs_rewrite)
    sys.path.insert(0, str(ROOT / "examples" / "shaders"))
    lines = []
    for name in SHADERS:
        best = None
        for k in range(rounds):
            spec = importlib.util.spec_from_file_location(f"{name}_{k}", ROOT / "examples" / "shaders" / f"{name}.py")
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
            cache._recipes.clear()  # noqa: SLF001 - a cold build: nothing of it in memory
            cache._memory.clear()  # noqa: SLF001
            written._REWRITES.clear()  # noqa: SLF001 - nor its rewrite (cache=False: none on disk)
            spent["s"] = 0.0
            t = time.perf_counter()
            module.build("full")
            total, rewrite = time.perf_counter() - t, spent["s"]
            best = (total, rewrite) if best is None or total < best[0] else best
        lines.append(f"cold build of {name:9s} {best[0] * 1e3:6.1f} ms, of which deciding and rewriting "
                     f"{best[1] * 1e3:.2f} ms ({100 * best[1] / best[0]:.1f}%)")
    return "\n".join(lines)

if __name__ == "__main__":
    main()
