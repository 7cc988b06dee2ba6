"""Core clock calibration: time a dependent chain of known latency, derive GHz.

A shared, virtualised machine runs at whatever clock its host chooses (turbo,
power limits) and its time-stamp counter says nothing about that. So every
benchmark run measures the core clock itself, with code whose cycle count is
known: a JIT-compiled (reactor) loop of ``UNROLL`` *dependent* scalar
floating-point operations per iteration, ``v = fma(v, a, b)`` (each needs the
previous result), run ``N`` times on one element. Its duration is
``N * UNROLL * latency`` cycles; nothing else in the loop is on the critical
path (the loop counter and branch run alongside), so

    GHz = N * UNROLL * latency / seconds.

The chain is short (2^18 operations, ~0.3 ms: shorter than a scheduler
time slice, so most repeats run uninterrupted even when the other core's
work competes for this one) and the best of many repeats is used
(interruptions only add time). A second
chain of dependent additions (different latency, same method) is timed as a
cross-check: the two GHz figures agree within a few percent when the latency
table is right for this core.

The latencies come from the table of the microarchitecture this process runs
on (``cpus.py``: Zen 3/4/5, Golden Cove, Sunny Cove, Skylake-X, Haswell,
Neoverse V1, and a ``generic`` row for an unknown core). The FMA latency is 4
cycles on every one of them made since 2017, so the clock is right even where
the FADD entry is not; the cross-check then shows the disagreement (the
``fadd_latency_measured`` of a calibration), which ``benchmarks/bench_clock.py``
reports.

The kernel is built with reactor (``Fma`` in a ``For`` loop, width 1), so it
is compiled by the same JIT as the kernels it times; ``assembly()`` shows the
chain (``vfmadd213ss`` / ``vaddss`` repeated, one register).
"""
from __future__ import annotations

import dataclasses
import functools
import time

import numpy as np

from reactor.cost import cpus

UNROLL = 64
#: Dependent operations per timing call (~0.3 ms at 3.6 GHz for the FMA chain).
CHAIN_OPS = 1 << 18
REPEATS = 41

OPS = ("fma", "fadd")


def cpu_model() -> dict:
    """The host CPU's description and its microarchitecture row (see ``cpus.py``)."""
    return cpus.cpu_model()


@functools.lru_cache(maxsize=None)
def chain_kernel(op: str = "fma"):
    """The reactor ufunc ``chain(v0, a, b, n) -> v``: ``n * UNROLL`` dependent ``op``s.

    ``fma``: ``v = fma(v, a, b)``; ``fadd``: ``v = v + a`` (``b`` unused).
    Operands come from the arguments, so nothing folds at compile time.
    """
    from reactor import Fma, For, Float, Int, Variable, kernel

    if op not in OPS:
        raise ValueError(f"unknown chain op {op!r}; choose one of {OPS}")

    def body(v0, a, b, n):
        v = Variable(v0)
        with For(0, n):
            for _ in range(UNROLL):
                v.set(Fma(v, a, b) if op == "fma" else v + a)
        return v

    body.__doc__ = f"clock calibration: a dependent chain of {op}"
    return kernel(body, name=f"clock_chain_{op}", args=[Float, Float, Float, Int], returns=Float,
                  width=1, fma=True)


@dataclasses.dataclass
class Calibration:
    """One calibration: the clock in GHz and how it was obtained."""

    ghz: float
    op: str
    latency: int
    ops: int
    seconds: float  # best time of one chain
    repeats: int
    spread: float  # (median - best) / best of the repeats: the noise seen
    uarch: str = "generic"  # the latency table used (cpus.TABLE)
    check_ghz: float | None = None  # the cross-check chain's figure, with the table's FADD latency
    check_seconds: float | None = None  # best time of the cross-check chain
    when: float = dataclasses.field(default_factory=time.time)

    @property
    def fadd_latency_measured(self) -> float | None:
        """The FADD latency implied by the two chains' times and the table's FMA latency
        (equal to the table's FADD entry when the table is right for this core)."""
        if self.check_seconds is None:
            return None
        return self.latency * self.check_seconds / self.seconds

    def to_json(self) -> dict:
        fadd = self.fadd_latency_measured
        return {"ghz": round(self.ghz, 4), "op": self.op, "latency_cycles": self.latency,
                "uarch": self.uarch, "chain_ops": self.ops, "best_seconds": self.seconds,
                "repeats": self.repeats, "spread": round(self.spread, 4),
                "check_ghz": None if self.check_ghz is None else round(self.check_ghz, 4),
                "fadd_latency_measured": None if fadd is None else round(fadd, 3),
                "when": self.when}


def time_chain(op: str = "fma", ops: int = CHAIN_OPS, repeats: int = REPEATS) -> tuple[float, float]:
    """(best, median) seconds of ``ops`` dependent ``op`` operations."""
    kern = chain_kernel(op)
    n = np.array([max(1, ops // UNROLL)], np.int32)
    v0, a, b = (np.array([v], np.float32) for v in (1.0, 0.5, 0.5))
    if op == "fadd":
        a = np.array([1e-30], np.float32)  # v stays 1.0: no overflow, normal numbers only
    out = np.empty(1, np.float32)
    kern(v0, a, b, np.array([16], np.int32), out=out)  # warm up (code paged in)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        kern(v0, a, b, n, out=out)
        times.append(time.perf_counter() - t0)
    return min(times), float(np.median(times))


def calibrate(ops: int = CHAIN_OPS, repeats: int = REPEATS, check: bool = True,
              uarch: "cpus.Microarchitecture | None" = None) -> Calibration:
    """Measure the core clock (GHz) with the FMA chain; ``check``: also time the add chain.
    ``uarch``: the latency table row (default: this host's)."""
    uarch = uarch or cpus.host()
    n_ops = max(1, ops // UNROLL) * UNROLL
    best, median = time_chain("fma", ops, repeats)
    ghz = n_ops * uarch.fma / best / 1e9
    check_ghz = cbest = None
    if check:
        cbest, _ = time_chain("fadd", ops, repeats)
        check_ghz = n_ops * uarch.fadd / cbest / 1e9
    return Calibration(ghz, "fma", uarch.fma, n_ops, best, repeats, (median - best) / best,
                       uarch.name, check_ghz, cbest)


def main() -> None:  # pragma: no cover - manual use: python -m routines.perf.clock
    print(cpu_model())
    for _ in range(3):
        c = calibrate()
        print(f"{c.ghz:.3f} GHz (fma chain, {c.uarch} table), check {c.check_ghz:.3f} GHz (fadd chain), "
              f"FADD latency measured {c.fadd_latency_measured:.2f}, spread {c.spread:.1%}")


if __name__ == "__main__":  # pragma: no cover
    main()
