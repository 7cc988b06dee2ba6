"""Build, compile, call and drop routines many times; measure resident memory.

``python -m fuzz.memcheck --cycles 10000 [--distinct]``

Each cycle builds a new ``Function`` (and, every 10th cycle, a new ``@kernel``
ufunc), compiles it, calls it, checks the result and drops it. By default
every cycle builds the same program, so its object code comes from the
in-memory cache and the cycle exercises building, linking into the JIT,
calling and unloading. With ``--distinct`` every cycle's program differs (a
new constant), so LLVM optimizes and compiles each one.

Reported: resident set size (RSS) after a warm-up and at the end, the growth
per cycle, and what must be back to its starting point: compiled-code objects
alive, executable JIT mappings, kernel registry entries, the memory cache size
(bounded by ``reactor.jit.cache.MEMORY_ENTRIES``).

The cycles use reactor's public API; only ``_reactor_state`` looks at
reactor's internals (what the check is about), and nothing else here does.
"""
from __future__ import annotations

import dataclasses
import gc
import os
import sys
import time

import numpy as np

from reactor import Float, Function, kernel


def rss_mb() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def exec_mappings() -> int:
    """Anonymous executable mappings of this process (where JIT code lives)."""
    n = 0
    with open("/proc/self/maps") as f:
        for line in f:
            parts = line.split()
            if "x" in parts[1] and len(parts) < 6:
                n += 1
    return n


@dataclasses.dataclass
class _State:
    alive_code: int  # compiled-code objects alive
    kernels_registered: int  # entries of the kernel registry
    memory_cache: int  # entries of the object-code memory cache
    memory_cache_bound: int


def _reactor_state() -> _State:
    """What reactor holds: the one place that reads reactor's internals."""
    from reactor.jit import cache
    from reactor.jit.compiler import CompiledCode
    from reactor.kernels import kernel as kernel_module
    # type(o), not isinstance(o, ...): isinstance on a dead weakref.proxy (any library may leave one
    # in the heap) raises ReferenceError, type() does not.
    compiled = sum(1 for o in gc.get_objects() if issubclass(type(o), CompiledCode))
    return _State(compiled, len(kernel_module._registry),
                  len(cache._memory), cache.MEMORY_ENTRIES)


def cycle(k: int, distinct: bool = False) -> None:
    """Build, compile, call, check and drop one routine (and every 10th cycle a ufunc)."""
    c = float(k) + 0.25 if distinct else 1.25  # distinct: a different program for every k

    def body(x, y):
        return x * c + y

    f = Function(body, args=[Float, Float], returns=Float, name=f"mem{k}" if distinct else "mem", cache=False)
    got = f(2.0, 1.0)
    if got != float(np.float32(2.0) * np.float32(c) + np.float32(1.0)):
        raise AssertionError(f"cycle {k}: got {got}")
    if k % 10 == 0:
        u = kernel(body, args=[Float, Float], returns=Float, name=f"memk{k}" if distinct else "memk", width=8,
                   cache=False)
        x = np.arange(19, dtype=np.float32)
        if not np.array_equal(u(x, x), x * np.float32(c) + x):
            raise AssertionError(f"cycle {k}: wrong ufunc result")


@dataclasses.dataclass
class Report:
    cycles: int
    distinct: bool
    seconds: float
    rss_start: float
    rss_warm: float
    rss_end: float
    warmup: int
    alive_code_start: int
    alive_code: int
    exec_maps_start: int
    exec_maps_end: int
    kernels_registered_start: int
    kernels_registered: int
    memory_cache: int
    memory_cache_bound: int

    @property
    def growth_kb_per_cycle(self) -> float:
        return (self.rss_end - self.rss_warm) * 1024 / max(1, self.cycles - self.warmup)

    def text(self) -> str:
        kind = "distinct programs (LLVM compiles each)" if self.distinct else "the same program (object cache hits)"
        return "\n".join([
            f"{self.cycles} build/compile/call/drop cycles of {kind}, a ufunc every 10th: {self.seconds:.1f} s",
            f"RSS: {self.rss_start:.1f} MB at start, {self.rss_warm:.1f} MB after {self.warmup} warm-up cycles, "
            f"{self.rss_end:.1f} MB at the end: {self.rss_end - self.rss_warm:+.1f} MB, "
            f"{self.growth_kb_per_cycle:.1f} KB per cycle",
            f"compiled-code objects alive: {self.alive_code_start} before, {self.alive_code} after; executable "
            f"JIT mappings: {self.exec_maps_start} before, {self.exec_maps_end} after",
            f"kernel registry entries: {self.kernels_registered_start} before, {self.kernels_registered} after; "
            f"memory cache: {self.memory_cache} entries (bound {self.memory_cache_bound})",
        ])


def memcheck(cycles: int, distinct: bool = False, warmup: int | None = None, progress=None) -> Report:
    warmup = min(cycles // 5, 600) if warmup is None else warmup
    from reactor.kernels import parallel
    parallel.runtime()  # the process's shared kernel runtime, built once and kept: not a cycle's
    gc.collect()
    maps0, rss0, state0 = exec_mappings(), rss_mb(), _reactor_state()
    t0 = time.perf_counter()
    for k in range(cycles):
        cycle(k, distinct)
        if k + 1 == warmup:
            gc.collect()
            rss_warm = rss_mb()
        if progress is not None and (k + 1) % 1000 == 0:
            gc.collect()
            progress(k + 1, rss_mb(), time.perf_counter() - t0)
    seconds = time.perf_counter() - t0
    gc.collect()
    if warmup == 0:
        rss_warm = rss0
    state = _reactor_state()
    return Report(cycles, distinct, seconds, rss0, rss_warm, rss_mb(), warmup, state0.alive_code, state.alive_code,
                  maps0, exec_mappings(), state0.kernels_registered, state.kernels_registered, state.memory_cache,
                  state.memory_cache_bound)


def main(argv=None) -> int:
    import argparse
    parser = argparse.ArgumentParser(prog="python -m fuzz.memcheck", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cycles", type=int, default=10_000)
    parser.add_argument("--distinct", action="store_true", help="a different program every cycle")
    args = parser.parse_args(argv)
    report = memcheck(args.cycles, args.distinct, progress=lambda k, rss, s: print(
        f"  {k} cycles: RSS {rss:.1f} MB, {s:.0f} s", file=sys.stderr, flush=True))
    print(report.text())
    return 0


if __name__ == "__main__":
    sys.exit(main())
