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

Latency table (cycles, scalar/vector float32, register operands):

============  =======  ======  =============================================
operation     Zen 4    Zen 3   source
============  =======  ======  =============================================
VFMADD*SS/PS  4        4       AMD "Software Optimization Guide for AMD
                               Family 19h Processors" (pub. 56665), section
                               "Floating-Point Unit": FMA latency 4; uops.info
                               measurements for ZEN4 (VFMADD231SS xmm: 4)
VADDSS/PS     3        3       same guide: FADD latency 3; uops.info ZEN4
============  =======  ======  =============================================

AMD family 25 (19h) covers Zen 3 (models 0x00-0x0f, 0x20-0x5f) and Zen 4
(models 0x10-0x1f, 0x60-0x7f, 0xa0-0xaf); LLVM's host CPU name is ``znver3``
/ ``znver4``. Both have the latencies above, so the table holds for the
whole family; an unknown CPU gets the same numbers with ``known=False``.

The kernel is built with reactor (``Fma`` in a ``For`` loop, width 1), so it
is compiled by the same JIT as the kernels it times; ``assembly()`` shows the
chain (``vfmadd213ss`` / ``vaddss`` repeated, one register).
"""
from __future__ import annotations

import dataclasses
import functools
import time

import numpy as np

UNROLL = 64
#: Dependent operations per timing call (~0.3 ms at 3.6 GHz for the FMA chain).
CHAIN_OPS = 1 << 18
REPEATS = 41

#: Latency (cycles) of the chained operations on AMD family 19h (Zen 3/Zen 4).
LATENCY = {"fma": 4, "fadd": 3}
LATENCY_SOURCE = ("AMD Software Optimization Guide for AMD Family 19h Processors (pub. 56665), "
                  "FPU latencies; uops.info (ZEN4: VFMADD231SS 4, VADDSS 3)")


def cpu_model() -> dict:
    """Vendor, family, model and model name from /proc/cpuinfo, and LLVM's host CPU name."""
    info = {"vendor": None, "family": None, "model": None, "name": None}
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, _, value = line.partition(":")
                key, value = key.strip(), value.strip()
                if key == "vendor_id" and info["vendor"] is None:
                    info["vendor"] = value
                elif key == "cpu family" and info["family"] is None:
                    info["family"] = int(value)
                elif key == "model" and info["model"] is None:
                    info["model"] = int(value)
                elif key == "model name" and info["name"] is None:
                    info["name"] = value
                if line.strip() == "":
                    break
    except OSError:
        pass
    try:
        import llvmlite.binding as llvm
        info["llvm_cpu"] = llvm.get_host_cpu_name()
    except Exception:  # pragma: no cover - llvmlite is a dependency
        info["llvm_cpu"] = None
    info["known"] = (info["vendor"] == "AuthenticAMD" and info["family"] == 25) or \
        info.get("llvm_cpu") in ("znver3", "znver4")
    return info


@functools.lru_cache(maxsize=None)
def chain_kernel(op: str = "fma"):
    """The reactor ufunc ``chain(v0, a, b, n) -> v``: ``n * UNROLL`` dependent ``op``s.

    ``fma``: ``v = fma(v, a, b)``; ``fadd``: ``v = v + a`` (``b`` unused).
    Operands come from the arguments, so nothing folds at compile time.
    """
    from reactor import Fma, For, Float, Int, Variable, kernel

    if op not in LATENCY:
        raise ValueError(f"unknown chain op {op!r}; choose one of {tuple(LATENCY)}")

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
    check_ghz: float | None = None  # the cross-check chain's figure
    when: float = dataclasses.field(default_factory=time.time)

    @property
    def ns_per_cycle(self) -> float:
        return 1.0 / self.ghz

    def to_json(self) -> dict:
        return {"ghz": round(self.ghz, 4), "op": self.op, "latency_cycles": self.latency,
                "chain_ops": self.ops, "best_seconds": self.seconds, "repeats": self.repeats,
                "spread": round(self.spread, 4),
                "check_ghz": None if self.check_ghz is None else round(self.check_ghz, 4),
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


def calibrate(ops: int = CHAIN_OPS, repeats: int = REPEATS, check: bool = True) -> Calibration:
    """Measure the core clock (GHz) with the FMA chain; ``check``: also time the add chain."""
    n_ops = max(1, ops // UNROLL) * UNROLL
    best, median = time_chain("fma", ops, repeats)
    ghz = n_ops * LATENCY["fma"] / best / 1e9
    check_ghz = None
    if check:
        cbest, _ = time_chain("fadd", ops, repeats)
        check_ghz = n_ops * LATENCY["fadd"] / cbest / 1e9
    return Calibration(ghz, "fma", LATENCY["fma"], n_ops, best, repeats,
                       (median - best) / best, check_ghz)


def main() -> None:  # pragma: no cover - manual use: python -m routines.perf.clock
    print(cpu_model())
    for _ in range(3):
        c = calibrate()
        print(f"{c.ghz:.3f} GHz (fma chain), check {c.check_ghz:.3f} GHz (fadd chain), "
              f"spread {c.spread:.1%}")


if __name__ == "__main__":  # pragma: no cover
    main()
