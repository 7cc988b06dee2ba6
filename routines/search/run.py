"""Measure candidates on their compiled code, cost them, keep the Pareto set.

Error. Every candidate is scored on the *compiled* kernel against the
float64 reference with the accuracy lab's definitions (``routines.lab``:
``tolerance(func, precision)``, ``ulp32``/``ulp16``, margin = |error| /
allowed; conforming iff every margin < 1 and no special value is wrong):

* **core domain**, where the maximum margin lies (docs/search.md, "Where the
  maximum is"): exp2 ``[-2, 2)`` (the tolerance 3 + 2|x| is smallest there,
  and round reduction's k = -2..2) plus ``[-126, -64)`` and ``[64, 128)``
  (where the additive forms' rounding of ``y = x + correction`` costs up to
  32 ULP against 131: a floor of 0.244 for them); log2 ``[1/16, 16)`` (eight
  binades around 1: results of magnitude up to 4, where ``e + m`` rounds or
  the allowance is 3 ULP of a value below 4; farther binades repeat the same
  error over a larger ULP). Swept **exhaustively** (exp2: the 5.0e8 inputs
  with |x| >= 2^-28; below, every candidate returns one constant per sign and
  the ends, every power of two and a random sample are evaluated, as in
  ``routines.zoo``), or sampled (``--quick``, and the first screening pass).
  The sweep uses a lean scorer (:func:`score_bits`, ~6 ns per input, about
  3x the lab sweep's speed) with the lab's tolerance and ULP functions; it
  agrees with ``routines.lab.evaluate`` to the last bit (tests/search).
* **everything else**: ``routines.lab.evaluate`` on ``sample_inputs`` (every
  special value, thresholds, powers of two, random patterns over all 2^32)
  plus, for exp2, a random sample of the rest of ``[-126, 128)``: catches
  wrong special values and any failure outside the core.

ULP-32 is reported over the reference's own domain (exp2 ``[-1, 1)``, log2
``[2, 4)``, where its 2.15 and 1.70 ULP are read; elsewhere ULP figures are
meaningless for exp2, 33 ULP at x = 64.8 for every variant, and log2, whose
bound near 1 is absolute).

Cost. ``reactor.cost.predict``: throughput-bound cycles per vector of
the kernel's loop, divided by its width. Two intrinsics the model does not
know (it would count an opaque call) are rewritten in the IR it reads:
``llvm.lrint`` (one VCVTPS2DQ) as the ``fptosi`` it replaces (same class,
pipes and latency as VCVTTPS2DQ) and ``llvm.x86.avx512.mask.scalef`` (one
VSCALEFPS, FP0/FP1) as an ``fmul``. Plus a measured ns/element (best of several rounds, 2048
elements in L1, as ``routines.perf.timing`` does; the machine is shared, so
it is indicative).
"""
from __future__ import annotations

import dataclasses
import math
import re
import time
from typing import Callable

import numpy as np

from reactor.cli import forked_pool

from ..lab import evaluate, sample_inputs, tolerance, ulp16, ulp32
from ..zoo.methods import Domain
from ..zoo.table import range_sample, split_tiny, subtract, tiny_sample
from .candidates import Candidate, grid

BLOCK = 1 << 16
CORE = {"exp2": (Domain(-2.0, 2.0), Domain(-126.0, -64.0), Domain(64.0, 128.0)),
        "log2": (Domain(2.0 ** -4, 2.0 ** 4),)}
CORE_LABEL = {"exp2": "[-2,2) u [-126,-64) u [64,128)", "log2": "[1/16,16)"}
ULP_DOMAIN = {"exp2": Domain(-1.0, 1.0, "[-1,1)"), "log2": Domain(2.0, 4.0, "[2,4)")}
WIDE = {"exp2": Domain(-126.0, 128.0, "[-126,128)"), "log2": None}
REFERENCE = {"exp2": np.exp2, "log2": np.log2}
SCREEN = 1 << 22          # sampled core inputs per candidate (screening, non-quick)
QUICK = 1 << 20           # sampled core inputs per candidate (--quick)
WIDE_SAMPLE = 1 << 18     # lab.evaluate: random inputs beside the hard ones


# --------------------------------------------------------------------------
# Lean exhaustive scorer

@dataclasses.dataclass
class Score:
    """Maxima over scored inputs (all regular: normal reference, finite result)."""

    count: int = 0
    max_margin: float = 0.0
    max_margin_x: float = math.nan
    max_ulp32: float = 0.0        # over the ULP domain only
    max_ulp32_x: float = math.nan
    max_ulp16: float = 0.0
    nonconforming: int = 0
    hard: np.ndarray = dataclasses.field(default_factory=lambda: np.empty(0, np.uint32))
    seconds: float = 0.0

    def merge(self, o: "Score", keep: int = 1 << 16) -> None:
        self.count += o.count
        if o.max_margin > self.max_margin:
            self.max_margin, self.max_margin_x = o.max_margin, o.max_margin_x
        if o.max_ulp32 > self.max_ulp32:
            self.max_ulp32, self.max_ulp32_x = o.max_ulp32, o.max_ulp32_x
        self.max_ulp16 = max(self.max_ulp16, o.max_ulp16)
        self.nonconforming += o.nonconforming
        if o.hard.size:
            self.hard = np.concatenate([self.hard, o.hard])[-keep:]
        self.seconds += o.seconds


class _Scorer:
    def __init__(self, ufunc, func, precision, ulp_ranges, keep_margin):
        self.ufunc, self.func, self.ref = ufunc, func, REFERENCE[func]
        self.tol = tolerance(func, precision)
        self.keep = keep_margin
        self.ulp_lo_hi = ulp_ranges
        n = BLOCK
        self.got = np.empty(n, np.float32)
        self.r, self.d, self.a, self.u = (np.empty(n) for _ in range(4))

    def _in_ulp_domain(self, bits):
        lo, hi = int(bits[0]), int(bits[-1])
        return any(a <= lo and hi < b for a, b in self.ulp_lo_hi), \
            any(a < hi + 1 and lo < b for a, b in self.ulp_lo_hi)

    def block(self, bits: np.ndarray, out: Score) -> None:
        n = bits.size
        x = bits.view(np.float32)
        got = self.ufunc(x, out=self.got[:n])
        ref = self.ref(x, out=self.r[:n], dtype=np.float64)
        d = np.subtract(got, ref, out=self.d[:n], dtype=np.float64)
        np.abs(d, out=d)
        a = self.tol.ulps(x, ref, out=self.a[:n])
        np.multiply(a, self.tol.unit_of(ref, out=self.u[:n]), out=a)
        m = np.divide(d, a, out=a)
        m[np.isnan(m)] = np.inf                      # NaN result for a regular input: a failure
        i = int(np.argmax(m))
        mi = float(m[i])
        if mi > out.max_margin:
            out.max_margin, out.max_margin_x = mi, float(x[i])
        bad = int(np.count_nonzero(m >= 1.0))
        out.nonconforming += bad
        if self.keep is not None:
            sel = np.flatnonzero(m >= self.keep)
            if sel.size:
                out.hard = np.concatenate([out.hard, bits[sel]])[-(1 << 16):]
        u = ulp32(ref, out=self.u[:n])
        np.divide(d, u, out=u)
        inside, touches = self._in_ulp_domain(bits) if bits.size else (False, False)
        if touches:
            if not inside:  # mixed block (sample): mask
                mask = np.zeros(n, bool)
                for lo, hi in self.ulp_lo_hi:
                    mask |= (bits >= lo) & (bits < hi)
                u = np.where(mask, u, 0.0)
            j = int(np.argmax(u))
            if u[j] > out.max_ulp32:
                out.max_ulp32, out.max_ulp32_x = float(u[j]), float(x[j])
        e16 = d / ulp16(ref)
        out.max_ulp16 = max(out.max_ulp16, float(e16.max()))
        out.count += n


def score_bits(ufunc, func, precision, bits, keep_margin=None) -> Score:
    """Score the inputs ``bits`` (uint32 patterns of regular inputs: normal,
    finite reference); ``keep_margin``: remember inputs at least this bad."""
    s = Score()
    t0 = time.perf_counter()
    sc = _Scorer(ufunc, func, precision, ULP_DOMAIN[func].ranges, keep_margin)
    bits = np.sort(np.asarray(bits, np.uint32))
    with np.errstate(all="ignore"):
        for i in range(0, bits.size, BLOCK):
            sc.block(bits[i:i + BLOCK], s)
    s.seconds = time.perf_counter() - t0
    return s


_WORKER: dict = {}


def _task(args):
    a, b = args
    sc, s = _WORKER["scorer"], Score()
    t0 = time.perf_counter()
    with np.errstate(all="ignore"):
        for lo in range(a, b, BLOCK):
            sc.block(np.arange(lo, min(lo + BLOCK, b), dtype=np.uint32), s)
    s.seconds = time.perf_counter() - t0
    return s


def score_ranges(ufunc, func, precision, ranges, *, workers=1, keep_margin=None,
                 chunk=1 << 23) -> Score:
    """Exhaustively score every pattern of the half-open bit ranges."""
    _WORKER["scorer"] = _Scorer(ufunc, func, precision, ULP_DOMAIN[func].ranges, keep_margin)
    tasks = [(lo, min(lo + chunk, b)) for a, b in ranges for lo in range(a, b, chunk)]
    total = Score()
    t0 = time.perf_counter()
    if workers <= 1:
        parts = map(_task, tasks)
        for p in parts:
            total.merge(p)
    else:
        with forked_pool(workers) as pool:
            for p in pool.imap_unordered(_task, tasks):
                total.merge(p)
    total.seconds = time.perf_counter() - t0
    return total


# --------------------------------------------------------------------------
# Cost

def _model_ir(kern) -> str:
    """The optimized IR with ``llvm.lrint`` calls written as the ``fptosi`` they
    compile like (VCVTPS2DQ vs VCVTTPS2DQ: same class, pipes and latency)."""
    text = kern.optimized_ir
    # VSCALEFPS: one FP0/FP1 operation like a multiply (the model has no class for it)
    sc = re.compile(r"(?:tail )?call (<\d+ x float>) @llvm\.x86\.avx512\.mask\.scalef\.ps\.\d+\("
                    r"<\d+ x float> (%[\w.]+), <\d+ x float> (%[\w.]+)[^)]*\)")
    text = sc.sub(lambda m: f"fmul {m.group(1)} {m.group(2)}, {m.group(3)}", text)
    pat = re.compile(r"(?:tail )?call (<\d+ x i32>|i32) @llvm\.lrint\.[\w.]+\(((?:<\d+ x float>|float)) (%[\w.]+)\)")
    return pat.sub(lambda m: f"fptosi {m.group(2)} {m.group(3)} to {m.group(1)}", text)


def model_cost(ufunc):
    """``Prediction`` of reactor.cost for the kernel (lrint as a conversion)."""
    from reactor import kernel_of
    from reactor.cost import predict
    kern = kernel_of(ufunc)
    return predict(_model_ir(kern), f"{kern.name}.loop", kern.build.width)


def time_ns(ufunc, x: np.ndarray, rounds: int = 9, target: float = 3e-4) -> float:
    """Best-of-rounds ns/element over the cache-resident ``x`` (2-D stride-0
    views: one call makes ``passes`` passes with no Python in between)."""
    from numpy.lib.stride_tricks import as_strided
    n = x.size
    out = np.empty(n, np.float32)
    old = np.getbufsize()
    np.setbufsize(max(8192, n))
    try:
        ufunc(x, out=out)
        t0 = time.perf_counter()
        ufunc(x, out=out)
        one = max(time.perf_counter() - t0, 1e-7)
        passes = max(1, int(target / one))
        X = as_strided(x, (passes, n), (0, 4))
        O = as_strided(out, (passes, n), (0, 4))
        best = math.inf
        for _ in range(rounds):
            t0 = time.perf_counter()
            ufunc(X, out=O)
            best = min(best, time.perf_counter() - t0)
        return best / (passes * n) * 1e9
    finally:
        np.setbufsize(old)


def timing_inputs(func: str, n: int = 2048) -> np.ndarray:
    rng = np.random.default_rng(1)
    if func == "exp2":
        return rng.uniform(-10.0, 10.0, n).astype(np.float32)
    return np.exp2(rng.uniform(-10.0, 10.0, n)).astype(np.float32)


# --------------------------------------------------------------------------
# Points

@dataclasses.dataclass
class Point:
    """A measured candidate (one point of the chart)."""

    candidate: Candidate
    cost: object                  # reactor.cost.Prediction
    core: Score
    exhaustive: bool
    wide: object                  # routines.lab.SweepResult of the wide checks
    core_inputs: str
    ns_per_element: float | None = None
    pareto: bool = False
    seconds: float = 0.0
    properties: dict = dataclasses.field(default_factory=dict)

    @property
    def cycles_per_element(self) -> float:
        return self.cost.throughput_bound / self.cost.width

    @property
    def max_margin(self) -> float:
        return max(self.core.max_margin, self.wide.max_margin)

    @property
    def max_margin_x(self) -> float:
        if self.wide.max_margin > self.core.max_margin and self.wide.max_margin_case:
            return self.wide.max_margin_case.x
        return self.core.max_margin_x

    @property
    def conforming(self) -> bool:
        return self.core.nonconforming == 0 and self.wide.conforming and self.max_margin < 1.0

    @property
    def admissible(self) -> bool:
        """Conforming, and the exactness/sign/monotonicity properties hold (the
        production routines promise them; the margin does not see them)."""
        return self.conforming and all(self.properties.values())

    @property
    def measured(self) -> str:
        how = "exhaustive" if self.exhaustive else "sampled"
        return (f"core {CORE_LABEL[self.candidate.function]} {how} ({self.core_inputs}); "
                f"elsewhere {self.wide.inputs} with routines.lab.evaluate")

    def to_json(self) -> dict:
        """JSON-ready (non-finite numbers as strings, as routines.lab does)."""
        c = self.candidate
        d = {
            "function": c.function, "precision": c.precision, "name": c.name,
            "description": c.description, "fma": c.fma,
            "cost_cycles_per_element": round(self.cycles_per_element, 4),
            "cost_cycles_per_vector": self.cost.throughput_bound, "width": self.cost.width,
            "bottleneck": self.cost.bottleneck, "ops": self.cost.counts,
            "ns_per_element": None if self.ns_per_element is None else round(self.ns_per_element, 4),
            "max_ulp32": round(self.core.max_ulp32, 4), "max_ulp32_domain": str(ULP_DOMAIN[c.function]),
            "max_ulp32_at": self.core.max_ulp32_x,
            "max_margin": round(self.max_margin, 5), "max_margin_at": self.max_margin_x,
            "conforming": self.conforming, "admissible": self.admissible, "pareto": self.pareto,
            "measured": self.measured, "exhaustive": self.exhaustive,
            "core_domain": CORE_LABEL[c.function], "core_count": self.core.count,
            "nonconforming": self.core.nonconforming + self.wide.nonconforming,
            "special_mismatches": self.wide.mismatches,
            "baseline": "production" if c.production else "",
            "properties": self.properties,
        }
        d = {k: _num(v) if isinstance(v, float) else v for k, v in d.items()}
        return d | {"candidate": c.to_json()}


def _num(v: float):
    return v if math.isfinite(v) else str(v)


def core_ranges(func: str):
    """(swept ranges, tiny sample) of the core domain (exp2 splits off |x| < 2^-28)."""
    ranges = [r for d in CORE[func] for r in d.ranges]
    if func == "exp2":
        big, tiny = split_tiny(ranges)
        return big, (tiny_sample(tiny) if tiny else np.empty(0, np.uint32))
    return ranges, np.empty(0, np.uint32)


def _wide_bits(func: str, seed: int = 0) -> np.ndarray:
    (bits,) = sample_inputs(func, WIDE_SAMPLE, seed=seed)
    if WIDE[func] is not None:
        rest = subtract(list(WIDE[func].ranges), [r for d in CORE[func] for r in d.ranges])
        bits = np.concatenate([bits, range_sample(rest, WIDE_SAMPLE, seed + 1)])
    return bits


_WIDE_CACHE: dict = {}


def measure(c: Candidate, *, exhaustive: bool, sample: int = SCREEN, workers: int = 1,
            keep_margin: float | None = None, time_it: bool = True, seed: int = 0) -> Point:
    """Build, cost and measure one candidate."""
    t0 = time.perf_counter()
    k = c.kernel()
    cost = model_cost(k)
    big, tiny = core_ranges(c.function)
    if exhaustive:
        core = score_ranges(k, c.function, c.precision, big, workers=workers, keep_margin=keep_margin)
        n = sum(b - a for a, b in big)
        label = f"all {n} inputs" + (" with |x| >= 2^-28" if tiny.size else "")
    else:
        core = score_bits(k, c.function, c.precision, range_sample(big, sample, seed), keep_margin)
        label = f"{core.count} random inputs"
    if tiny.size:
        core.merge(score_bits(k, c.function, c.precision, tiny))
        label += f"; |x| < 2^-28: {tiny.size} inputs (ends, powers of two, random)"
    key = (c.function, seed)
    if key not in _WIDE_CACHE:
        _WIDE_CACHE[key] = _wide_bits(c.function, seed)
    wide = evaluate(k, c.function, c.precision, _WIDE_CACHE[key])
    ns = time_ns(k, timing_inputs(c.function)) if time_it else None
    return Point(c, cost, core, exhaustive, wide, label, ns, seconds=time.perf_counter() - t0,
                 properties=properties(c.function, k))


def properties(func: str, ufunc) -> dict:
    """Exactness and sign properties the margin does not see. exp2: 2^k exact
    for every integer k in [-126, 127], monotone on [-1, 1) (every float).
    log2: log2(2^k) = k exactly for k in [-149, 127], and the sign right on
    [1/2, 2] (negative below 1, positive above: pow(x < 1, +-inf) and the
    like depend on it)."""
    with np.errstate(all="ignore"):
        if func == "exp2":
            k = np.arange(-126, 128, dtype=np.float32)
            exact = bool(np.array_equal(ufunc(k), np.exp2(k.astype(np.float64)).astype(np.float32)))
            x = range_sample(list(Domain(-1.0, 1.0).ranges), 1 << 20, 3).view(np.float32)
            up = np.nextafter(x, np.float32(np.inf))
            mono = bool(np.all(ufunc(x) <= ufunc(up)))
            return {"exact_at_integers": exact, "monotone_on_random_adjacent_pairs_in_[-1,1)": mono}
        k = np.arange(-149, 128)
        exact = bool(np.array_equal(ufunc(np.ldexp(1.0, k).astype(np.float32)), k.astype(np.float32)))
        below = Domain(0.5, 1.0).values()
        above = Domain(1.0, 2.0).values()[1:]
        sign = bool(np.all(ufunc(below) < 0) and np.all(ufunc(above) > 0))
        return {"exact_at_powers_of_two": exact, "sign_correct_on_[1/2,2]": sign}


# --------------------------------------------------------------------------
# Pareto

def pareto(points: list, cost: Callable = lambda p: p.cycles_per_element,
           error: Callable = lambda p: p.max_margin,
           ok: Callable = lambda p: getattr(p, "admissible", p.conforming)) -> list:
    """The points no other admissible point dominates (cost <= and error <=,
    one of them strictly); inadmissible points (``ok`` false) are never in it.
    Equal points are all kept."""
    adm = [p for p in points if ok(p)]
    front = []
    for p in adm:
        dominated = any(cost(q) <= cost(p) and error(q) <= error(p)
                        and (cost(q) < cost(p) or error(q) < error(p)) for q in adm)
        if not dominated:
            front.append(p)
    return sorted(front, key=cost)


# --------------------------------------------------------------------------
# Retuning

def retune_candidate(c: Candidate, hard_bits: np.ndarray, *, max_evals: int = 150,
                     log=None) -> tuple[Candidate, float, float]:
    """Greedy float32-ulp nudges of ``c``'s coefficients minimising the compiled
    kernel's max margin on ``hard_bits`` (plus a tie-breaker: 1/10 of the mean
    of the 32 worst). Returns (retuned candidate, start and final objective)."""
    from ..remez import retune
    bits = np.sort(np.unique(np.asarray(hard_bits, np.uint32)))
    cache: dict = {}

    def err(coeffs: np.ndarray) -> float:
        key = tuple(np.asarray(coeffs, np.float32).view(np.uint32).tolist())
        if key not in cache:
            cand = c.with_coefficients(coeffs, tag="trial")
            k = cand.kernel()
            x = bits.view(np.float32)
            with np.errstate(all="ignore"):
                got = k(x)
                ref = REFERENCE[c.function](x, dtype=np.float64)
                tol = tolerance(c.function, c.precision)
                m = np.abs(got - ref) / (tol.ulps(x, ref) * tol.unit_of(ref))
            m = np.nan_to_num(m, nan=np.inf)
            top = np.partition(m, -32)[-32:] if m.size > 32 else m
            cache[key] = float(m.max() + 0.1 * top.mean())
        return cache[key]

    start = np.array(c.values, np.float32)
    r = retune(start, err, max_evals=max_evals, max_ulps=64)
    coeffs = np.asarray(r.coefficients, np.float32)
    new = c.with_coefficients(coeffs, tag="retuned",
                              provenance=f"retuned from {c.name} ({c.provenance}) with "
                                         "routines.remez.retune against the compiled max margin")
    return new, r.initial_error, r.error


# --------------------------------------------------------------------------
# The search

def search(function: str, precision: str, *, quick: bool = False, retune: bool = False,
           workers: int = 1, time_it: bool = True, finalists: int = 4, log=None,
           candidates: list | None = None) -> list:
    """Measure the candidate grid and return every Point, Pareto set marked."""
    say = log or (lambda s: None)
    cands = candidates if candidates is not None else grid(function, precision, quick=quick)
    exhaustive_all = (function == "log2") and not quick   # 6.7e7 inputs: ~0.5 s each
    points = []
    for c in cands:
        p = measure(c, exhaustive=exhaustive_all, sample=QUICK if quick else SCREEN,
                    workers=workers, time_it=time_it)
        points.append(p)
        say(f"  {c.name:<58} {p.cycles_per_element:6.4f} c/e  margin {p.max_margin:.4f}"
            f"{'' if p.exhaustive else ' (sample)'}  ULP {p.core.max_ulp32:.3f}  {p.seconds:5.1f} s")
    if not quick:
        points = _refine(points, workers, time_it, finalists, say)
        if retune:
            points += _retune_best(points, workers, time_it, say)
            points = _refine(points, workers, time_it, 0, say)
    best: dict = {}
    for p in points:  # a fresh retune may repeat a stored retuned candidate's name: keep the better
        q = best.get(p.candidate.name)
        if q is None or (p.exhaustive, -p.max_margin) > (q.exhaustive, -q.max_margin):
            best[p.candidate.name] = p
    points = [p for p in points if best[p.candidate.name] is p]
    for p in points:
        p.pareto = False
    for p in pareto(points):
        p.pareto = True
    return points


def _refine(points, workers, time_it, finalists, say):
    """Sweep exhaustively the baselines, the best ``finalists`` at the
    production routine's cost and below (and the best of each form there),
    and every point of the Pareto set, until the Pareto set is all exhaustive."""
    def redo(p):
        q = measure(p.candidate, exhaustive=True, workers=workers, time_it=False)
        q.ns_per_element = p.ns_per_element
        say(f"  exhaustive {p.candidate.name:<47} margin {p.max_margin:.4f} -> {q.max_margin:.4f}"
            f"  ULP {q.core.max_ulp32:.3f}  {q.seconds:5.1f} s")
        return q

    by_name = {p.candidate.name: p for p in points}
    prod = [p for p in points if p.candidate.production and p.candidate.fma]
    want = {p.candidate.name for p in points if p.candidate.production}
    if prod and finalists:
        budget = prod[0].cycles_per_element
        ok = sorted((p for p in points if p.admissible and p.cycles_per_element <= budget + 1e-9),
                    key=lambda p: p.max_margin)
        want |= {p.candidate.name for p in ok[:finalists]}
        forms = {}
        for p in ok:  # and the best of every form at that cost
            forms.setdefault(p.candidate.form, p)
        want |= {p.candidate.name for p in forms.values()}
    while True:
        want |= {p.candidate.name for p in pareto(list(by_name.values()))}
        todo = [n for n in want if not by_name[n].exhaustive]
        if not todo:
            break
        for n in todo:
            by_name[n] = redo(by_name[n])
    return [by_name[p.candidate.name] for p in points]


def _retune_best(points, workers, time_it, say):
    """Retune the best conforming candidate at production's cost (and the best
    one of each other form at that cost), verified exhaustively."""
    prod = [p for p in points if p.candidate.production and p.candidate.fma]
    if not prod:
        return []
    budget = prod[0].cycles_per_element
    pool = sorted((p for p in points if p.admissible and p.exhaustive and not p.candidate.production
                   and p.candidate.tag != "retuned" and p.cycles_per_element <= budget + 1e-9),
                  key=lambda p: p.max_margin)
    chosen, forms = [], set()
    for p in pool:
        if p.candidate.form not in forms:
            forms.add(p.candidate.form)
            chosen.append(p)
    out = []
    for p in chosen[:2]:
        c = p.candidate
        best = p
        for rnd in range(3):
            hard = _hard_set(best, workers)
            new, before, after = retune_candidate(best.candidate, hard)
            say(f"  retune round {rnd + 1} {c.name}: objective {before:.5f} -> {after:.5f}")
            if new.coefficients == best.candidate.coefficients:
                break
            q = measure(new, exhaustive=True, workers=workers, time_it=time_it)
            say(f"    exhaustive: margin {best.max_margin:.4f} -> {q.max_margin:.4f}, "
                f"ULP {q.core.max_ulp32:.3f}; coefficients {', '.join(new.coefficients)}")
            if q.max_margin >= best.max_margin:
                break
            best = q
        if best is not p:
            out.append(best)
    return out


def _hard_set(p: Point, workers: int) -> np.ndarray:
    """Inputs within 5% of the point's exhaustive maximum, plus a random core sample."""
    c = p.candidate
    big, tiny = core_ranges(c.function)
    s = score_ranges(c.kernel(), c.function, c.precision, big, workers=workers,
                     keep_margin=0.95 * p.max_margin)
    return np.concatenate([s.hard, range_sample(big, 1 << 17, 7), tiny])
