"""The timing harness: every candidate on the same inputs, in the same loop.

Rules (so that a figure here compares with every other figure of the run):

* **Same inputs.** Per function and size one set of float32 operands
  (:func:`inputs`: typical arguments, fixed seed) and one ``out=`` array,
  shared by every candidate of that function: our variants, NumPy, libmvec,
  SLEEF, numba.
* **Same loop.** A candidate is ``fn(*args, out=out)`` (a NumPy ufunc or a
  thin callable around one). At the cache-resident sizes one *call* makes
  ``passes`` passes over the same ``n`` elements: the operands are 2-D views
  ``(passes, n)`` whose outer stride is 0, so NumPy's iterator calls the inner
  loop ``passes`` times with no Python in between (NumPy's ~0.5 us call
  overhead would otherwise be 40% of an L1-sized call). ``passes`` is chosen
  per candidate (from a probe call) so that a call lasts ~0.5 ms: shorter
  than a scheduler time slice, so most rounds run uninterrupted on a busy
  machine, whether the candidate is fast or slow. NumPy's buffer size is set to
  ``n`` meanwhile: with the default 8192 the iterator copies inner loops
  shorter than that through its buffers (measured: 0.32 instead of 0.17
  ns/element at n = 2048). The largest size is one plain 1-D call.
* **Interleaved rounds, best of.** Each round times one call of every
  candidate, in an order rotated every round; each candidate keeps its best
  round (interference on a shared machine only adds time) and the median is
  kept as a noise indicator.
* **Cycles from the calibrated clock** (:mod:`routines.perf.clock`):
  ``cycles/element = ns/element * GHz``.

Sizes (chosen for Zen 4's caches: 32 KiB L1d and 1 MiB L2 per core, 32 MiB
L3; with other cache sizes a size may live in another level than its name):
``L1`` 2048 elements (pow: two 8 KiB inputs and an 8 KiB result), ``L2``
65536 (256 KiB per array, 768 KiB for pow) and ``DRAM`` 16M elements (64 MiB
per array, twice the L3).

``threads`` is a column of every result: the thread count the kernel was
allowed (``reactor.kernels.parallel.configure``, set by the caller); the
harness itself never splits work. Kernels split only calls of at least the
parallel threshold (2^20 elements), so only the DRAM size has 2-thread rows.

**Load by others.** The machine is shared: :func:`load_snapshot` before and
after a size's rounds gives the CPU time that *other* processes used meanwhile
(all CPUs' busy time from /proc/stat minus this process's own), in CPUs, and
the steal time; the report prints it beside the figures. When two vCPUs are
SMT siblings of one host core and the other one is busy, they compete for
that core's shared resources, and code limited by its out-of-order window is
slowed more than code limited by its execution pipes (see docs/performance.md).
"""
from __future__ import annotations

import dataclasses
import os
import time
from typing import Callable

import numpy as np
from numpy.lib.stride_tricks import as_strided

SIZES = {"L1": 2048, "L2": 65536, "DRAM": 1 << 24}
#: Target duration of one timed call (seconds) at the cache-resident sizes.
CALL_SECONDS = 5e-4


def inputs(func: str, n: int, seed: int = 1) -> tuple[np.ndarray, ...]:
    """Typical operands: exp/exp2 in [-10, 10]; log/log2/rcp/rsqrt/sqrt in
    [1e-3, 100]; pow: x in [1e-3, 100], y in [-10, 10] (results within float32);
    sin/cos/tan/atan/sinh/cosh/tanh in [-10, 10] (a few periods: the Cody-Waite
    path, as a shader's angles); asin/acos in [-1, 1]; atan2(y, x): y and x in
    [-10, 10] (all four quadrants)."""
    rng = np.random.default_rng(seed)
    signed = rng.uniform(-10, 10, n).astype(np.float32)
    positive = rng.uniform(1e-3, 100, n).astype(np.float32)
    if func in ("exp", "exp2", "sin", "cos", "tan", "atan", "sinh", "cosh", "tanh"):
        return (signed,)
    if func == "pow":
        return (positive, signed)
    if func in ("asin", "acos"):
        return (rng.uniform(-1, 1, n).astype(np.float32),)
    if func == "atan2":
        return (signed, rng.uniform(-10, 10, n).astype(np.float32))
    return (positive,)


@dataclasses.dataclass
class Candidate:
    """One thing to time: ``fn(*args, out=out)`` for function ``func``."""

    key: str
    func: str
    fn: Callable
    threads: int = 1


@dataclasses.dataclass
class Timing:
    key: str
    func: str
    size: str
    n: int
    passes: int
    threads: int
    best_ns: float  # ns per element, best round
    median_ns: float
    rounds: int
    ghz: float

    @property
    def cycles_per_element(self) -> float:
        return self.best_ns * self.ghz

    def to_json(self) -> dict:
        return {"key": self.key, "func": self.func, "size": self.size, "n": self.n,
                "passes": self.passes, "threads": self.threads,
                "ns_per_element": self.best_ns, "median_ns_per_element": self.median_ns,
                "cycles_per_element": self.cycles_per_element, "rounds": self.rounds}


class Workload:
    """The shared operands and result array of one function at one size."""

    def __init__(self, func: str, n: int, seed: int = 1):
        self.func, self.n = func, n
        self.base = inputs(func, n, seed)
        self.out_base = np.empty(n, np.float32)
        self._views = {}

    def views(self, passes: int):
        """(args, out) making ``passes`` passes over the ``n`` elements per call."""
        if passes <= 1:
            return self.base, self.out_base
        if passes not in self._views:
            args = tuple(as_strided(a, (passes, self.n), (0, a.strides[0]), writeable=False)
                         for a in self.base)
            self._views[passes] = (args, as_strided(self.out_base, (passes, self.n), (0, 4)))
        return self._views[passes]


PROBE_PASSES = 16


def _passes(fn, w: Workload, large: int) -> int:
    """Passes per call for ``fn``: about CALL_SECONDS (1 at the DRAM size),
    from the time of a probe call; so slow and fast candidates alike run calls
    shorter than a scheduler time slice."""
    if w.n >= large:
        return 1
    probe = max(1, min(PROBE_PASSES, int(CALL_SECONDS / (0.3e-9 * w.n))))
    args, out = w.views(probe)
    best = float("inf")
    for _ in range(3):
        t0 = time.perf_counter()
        fn(*args, out=out)
        best = min(best, time.perf_counter() - t0)
    per_pass = best / probe
    return max(1, int(CALL_SECONDS / max(per_pass, 1e-9)))


def time_candidates(candidates: list[Candidate], size: str, n: int, rounds: int, ghz: float,
                    progress=None, seed: int = 1, passes: int | None = None) -> list[Timing]:
    """Time every candidate at ``n`` elements (see the module docstring)."""
    funcs = sorted({c.func for c in candidates})
    loads = {f: Workload(f, n, seed) for f in funcs}
    samples = {c.key: [] for c in candidates}
    old = np.getbufsize()
    try:
        np.setbufsize(max(n, 16) if n < SIZES["DRAM"] else old)
        with np.errstate(all="ignore"):
            plan = {}
            for c in candidates:  # warm up (code and data paged in, caches filled), size the calls
                w = loads[c.func]
                c.fn(*w.base, out=w.out_base)
                p = passes if passes is not None else _passes(c.fn, w, SIZES["DRAM"])
                plan[c.key] = (p, *w.views(p))
            for r in range(rounds):
                k = r % len(candidates)
                for c in candidates[k:] + candidates[:k]:
                    _, args, out = plan[c.key]
                    t0 = time.perf_counter()
                    c.fn(*args, out=out)
                    samples[c.key].append(time.perf_counter() - t0)
                if progress is not None:
                    progress.update(1)
    finally:
        np.setbufsize(old)
    out = []
    for c in candidates:
        p = plan[c.key][0]
        s = np.array(samples[c.key]) / (n * p) * 1e9
        out.append(Timing(c.key, c.func, size, n, p, c.threads, float(s.min()),
                          float(np.median(s)), rounds, ghz))
    return out


@dataclasses.dataclass
class LoadSnapshot:
    wall: float
    busy: float  # busy CPU-seconds of all CPUs since boot (user, nice, system, irq, softirq)
    steal: float
    own: float  # this process's CPU-seconds (all threads)


def load_snapshot() -> LoadSnapshot:
    """A reading of the machine's and this process's CPU time (Linux /proc/stat)."""
    t = os.times()
    try:
        hz = os.sysconf("SC_CLK_TCK")
        with open("/proc/stat") as f:
            v = [int(x) for x in f.readline().split()[1:]]
        busy = (v[0] + v[1] + v[2] + v[5] + v[6]) / hz
        steal = (v[7] if len(v) > 7 else 0) / hz
    except (OSError, ValueError, IndexError):
        busy = steal = float("nan")
    return LoadSnapshot(time.perf_counter(), busy, steal, t.user + t.system)


def others_load(a: LoadSnapshot, b: LoadSnapshot) -> dict:
    """CPUs used by other processes, and stolen by the host, between two snapshots."""
    wall = max(b.wall - a.wall, 1e-9)
    others = ((b.busy - a.busy) - (b.own - a.own)) / wall
    return {"seconds": round(wall, 3), "other_cpus": round(max(0.0, others), 3),
            "steal_cpus": round((b.steal - a.steal) / wall, 3)}
