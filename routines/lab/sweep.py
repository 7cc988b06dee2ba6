"""Chunked exhaustive sweep of a float32 kernel against the float64 reference.

``sweep(ufunc, func, precision)`` runs ``ufunc`` on every float32 bit pattern
in ``[start, stop)`` (default: all 2**32, including NaNs, infinities and
subnormals), scores each result with :mod:`routines.lab.measures` against
:func:`routines.lab.reference.reference` and the Vulkan tolerance of
:mod:`routines.lab.tolerance`, and reduces everything to a
:class:`SweepResult`.  ``evaluate`` does the same for given inputs, e.g. the
hard-region sample of :func:`sample_inputs` (the accuracy command's quick
mode).

The kernel is any callable float32 array -> float32 array (``pow``: two
operands); a NumPy ufunc is called with ``out=`` so no result is allocated.
The range is split into tasks of ``chunk`` inputs run by a pool of
``workers`` forked processes (the kernel is inherited, never pickled).
Threads were measured and do not scale here: a block is scored by ~40 cheap
NumPy calls, some of which (argmax, count_nonzero, comparisons) hold the GIL.
Each worker scores its task in cache-sized blocks of :data:`BLOCK` inputs
with preallocated buffers (fresh temporaries of that size would cost page
faults).  Blocks whose references are all normal float32 values and whose
results are all finite skip the special-value path entirely.
"""

from __future__ import annotations

import contextlib
import math
import pickle
import sys
import time
from dataclasses import dataclass, field

import numpy as np
from tqdm import tqdm

from reactor.cli import forked_pool

from . import measures as M
from .reference import ARITY, BINARY, FUNCS, reference
from .tolerance import inside_pi, tolerance

BLOCK = 2**15
WORST = 10
EXAMPLES = 5


def _num(v):
    """A float for JSON: non-finite values as strings."""
    v = float(v)
    return v if math.isfinite(v) else str(v)


def _f32(bits):
    return float(np.uint32(bits).view(np.float32))


@dataclass
class Case:
    """One evaluated input: operands (bit patterns), result, reference, scores."""

    x_bits: int
    y_bits: int | None
    got_bits: int
    expected: float
    ulp32: float
    ulp16: float
    margin: float
    category: str

    @property
    def x(self) -> float:
        return _f32(self.x_bits)

    @property
    def y(self) -> float | None:
        return None if self.y_bits is None else _f32(self.y_bits)

    @property
    def got(self) -> float:
        return _f32(self.got_bits)

    def key(self):
        return (self.x_bits, -1 if self.y_bits is None else self.y_bits)

    def to_json(self) -> dict:
        d = {"x": _num(self.x), "x_bits": f"0x{self.x_bits:08x}"}
        if self.y_bits is not None:
            d |= {"y": _num(self.y), "y_bits": f"0x{self.y_bits:08x}"}
        return d | {"got": _num(self.got), "got_bits": f"0x{self.got_bits:08x}",
                    "expected": _num(self.expected), "ulp32": _num(self.ulp32),
                    "ulp16": _num(self.ulp16), "margin": _num(self.margin),
                    "category": self.category}

    def describe(self) -> str:
        arg = f"x={self.x:.9g} (0x{self.x_bits:08x})"
        if self.y_bits is not None:
            arg += f", y={self.y:.9g} (0x{self.y_bits:08x})"
        return f"{arg}: got {self.got:.9g}, expected {self.expected:.17g}"


@dataclass
class SweepResult:
    """Reduction of a sweep.  An input conforms iff its margin is < 1;
    special-value mismatches are counted per category of
    :data:`routines.lab.measures.CATEGORIES`; flushes to zero are neither."""

    func: str
    precision: str
    inputs: str
    count: int = 0
    seconds: float = 0.0
    max_ulp32: float = 0.0
    max_ulp32_case: Case | None = None
    max_ulp16: float = 0.0
    max_ulp16_case: Case | None = None
    max_margin: float = 0.0
    max_margin_case: Case | None = None
    nonconforming: int = 0
    special_mismatches: dict = field(
        default_factory=lambda: {M.CATEGORIES[c]: 0 for c in M.MISMATCHES})
    special_examples: list = field(default_factory=list)
    flushed: int = 0
    flush_examples: list = field(default_factory=list)
    worst: list = field(default_factory=list)
    #: per input region of :data:`REGIONS` (the trigonometric and hyperbolic functions):
    #: name -> {"count", "max_abs", "max_abs_at", "max_ulp32", "max_ulp32_at", "max_ulp16",
    #: "max_ulp16_at", "max_margin", "max_margin_at"} over the scored inputs (Case objects)
    regions: dict = field(default_factory=dict)

    @property
    def mismatches(self) -> int:
        return sum(self.special_mismatches.values())

    @property
    def conforming(self) -> bool:
        return self.nonconforming == 0 and self.mismatches == 0

    def threshold(self) -> float:
        """Margin an input must exceed to enter :attr:`worst`."""
        return self.worst[-1].margin if len(self.worst) >= WORST else 0.0

    def merge(self, other: SweepResult) -> None:
        """Fold ``other`` (same func/precision) into this result."""
        self.count += other.count
        for name in ("ulp32", "ulp16", "margin"):  # ties go to the lowest input: any merge order agrees
            theirs, ours = getattr(other, f"max_{name}"), getattr(self, f"max_{name}")
            if theirs > ours or theirs == ours and _lower(getattr(other, f"max_{name}_case"),
                                                          getattr(self, f"max_{name}_case")):
                setattr(self, f"max_{name}", theirs)
                setattr(self, f"max_{name}_case", getattr(other, f"max_{name}_case"))
        self.nonconforming += other.nonconforming
        for k, v in other.special_mismatches.items():
            self.special_mismatches[k] += v
        self.flushed += other.flushed
        self.special_examples = _first(self.special_examples + other.special_examples)
        self.flush_examples = sorted(self.flush_examples + other.flush_examples,
                                     key=Case.key)[:EXAMPLES]
        self.worst = sorted(self.worst + other.worst, key=_worst_order)[:WORST]
        for name, theirs in other.regions.items():
            ours = self.regions.setdefault(name, _region_stats())
            ours["count"] += theirs["count"]
            for key in _REGION_KEYS:
                if theirs[key] > ours[key] or theirs[key] == ours[key] and _lower(theirs[key + "_at"],
                                                                                  ours[key + "_at"]):
                    ours[key], ours[key + "_at"] = theirs[key], theirs[key + "_at"]

    def to_json(self) -> dict:
        """A dict ready for ``json.dump`` (non-finite floats as strings)."""
        def case(c):
            return None if c is None else c.to_json()
        return {
            "func": self.func, "precision": self.precision, "inputs": self.inputs,
            "count": self.count, "seconds": round(self.seconds, 3),
            "conforming": self.conforming,
            "max_ulp32": _num(self.max_ulp32), "max_ulp32_at": case(self.max_ulp32_case),
            "max_ulp16": _num(self.max_ulp16), "max_ulp16_at": case(self.max_ulp16_case),
            "max_margin": _num(self.max_margin), "max_margin_at": case(self.max_margin_case),
            "nonconforming": self.nonconforming,
            "special_mismatches": dict(self.special_mismatches),
            "special_examples": [c.to_json() for c in self.special_examples],
            "flushed_to_zero": self.flushed,
            "flush_examples": [c.to_json() for c in self.flush_examples],
            "worst": [c.to_json() for c in self.worst],
        } | ({"regions": {name: {k: (case(v) if k.endswith("_at") else v if k == "count" else _num(v))
                                 for k, v in r.items()}
                          for name, r in self.regions.items()}} if self.regions else {})

    def table(self) -> str:
        """A short human-readable summary."""
        verdict = "CONFORMS" if self.conforming else "DOES NOT CONFORM"
        lines = [f"{self.func} ({self.precision}) over {self.inputs}: {self.count} inputs, "
                 f"{self.seconds:.1f} s -- {verdict}"]
        for label, value, c in (("max ULP-32", self.max_ulp32, self.max_ulp32_case),
                                ("max ULP-16", self.max_ulp16, self.max_ulp16_case),
                                ("max margin", self.max_margin, self.max_margin_case)):
            lines.append(f"  {label:<11} {value:<12.6g}"
                         + (f" at {c.describe()}" if c else ""))
        lines.append(f"  non-conforming (margin >= 1): {self.nonconforming}")
        counts = ", ".join(f"{k} {v}" for k, v in self.special_mismatches.items())
        lines.append(f"  special mismatches: {self.mismatches} ({counts})")
        lines += [f"    {c.category:<13} {c.describe()}" for c in self.special_examples]
        lines.append(f"  flushed to zero (subnormal expected): {self.flushed}")
        for name, r in self.regions.items():
            lines.append(f"  region {name}: {r['count']} scored, max abs error {r['max_abs']:.6g}, "
                         f"max ULP-32 {r['max_ulp32']:.6g}, max ULP-16 {r['max_ulp16']:.6g}, "
                         f"max margin {r['max_margin']:.6g}")
            for key in ("max_abs", "max_ulp32"):
                if r[key + "_at"] is not None:
                    lines.append(f"    {key:<9} at {r[key + '_at'].describe()}")
        if self.worst:
            lines.append(f"  worst inputs:  {'margin':>10} {'ULP-32':>10}")
            lines += [f"{'':16} {c.margin:>10.4g} {c.ulp32:>10.4g}  {c.describe()}"
                      for c in self.worst]
        return "\n".join(lines)


#: Input regions reported apart (first operand): Vulkan bounds sin and cos only inside
#: [-pi, pi], so the error outside (where a user still expects accuracy) is shown separately.
_PI_SPLIT = (("|x| <= pi", lambda x: inside_pi(x)), ("|x| > pi", lambda x: ~inside_pi(x)))
_ALL = (("all inputs", None),)
REGIONS = {"sin": _PI_SPLIT, "cos": _PI_SPLIT, "tan": _PI_SPLIT,
           "asin": _ALL, "acos": _ALL, "atan": _ALL, "atan2": _ALL,
           "sinh": _ALL, "cosh": _ALL, "tanh": _ALL}
_REGION_KEYS = ("max_abs", "max_ulp32", "max_ulp16", "max_margin")


def _region_stats():
    return {"count": 0} | {k: v for key in _REGION_KEYS for k, v in ((key, 0.0), (key + "_at", None))}


def _lower(a, b) -> bool:
    """Whether case ``a`` is at a lower input than case ``b`` (a tie-break independent of order)."""
    return a is not None and (b is None or a.key() < b.key())


def _worst_order(c):
    return (-c.margin, c.key())


def _first(examples):
    """Up to EXAMPLES examples per category, lowest inputs first."""
    kept, seen = [], {}
    for c in sorted(examples, key=Case.key):
        if seen.get(c.category, 0) < EXAMPLES:
            seen[c.category] = seen.get(c.category, 0) + 1
            kept.append(c)
    return kept


def _top(m, threshold, largest):
    """Indices of the (up to) WORST largest values of ``m`` above ``threshold``.

    Candidates are first narrowed to values close to ``largest`` (= m.max()),
    so the selection touches few elements (NumPy's partition is slow here).
    """
    if largest <= threshold:
        return np.empty(0, dtype=np.intp)
    for frac in (0.999, 0.99, 0.5, 0.0):
        cand = np.flatnonzero(m > max(threshold, largest * frac))
        if cand.size >= WORST:
            break
    values = m[cand]
    picked = []
    for _ in range(min(WORST, cand.size)):
        j = int(np.argmax(values))
        picked.append(cand[j])
        values[j] = -np.inf
    return np.array(picked, dtype=np.intp)


class _Block:
    """Preallocated buffers for scoring up to BLOCK inputs at a time."""

    def __init__(self, ufunc, func, precision):
        self.ufunc, self.func = ufunc, func
        self.tol = tolerance(func, precision)
        self.regions = REGIONS.get(func, ())
        self.bits = np.empty(BLOCK, np.uint32)
        self.iota = np.arange(BLOCK, dtype=np.uint32)
        self.got = np.empty(BLOCK, np.float32)
        self.ref, self.d, self.s, self.e32, self.e16, self.m = (
            np.empty(BLOCK) for _ in range(6))
        self.reg, self.tmp, self.b_fin, self.b_exact, self.b_tmp = (
            np.empty(BLOCK, bool) for _ in range(5))
        self.r32, self.cat = np.empty(BLOCK, np.float32), np.empty(BLOCK, np.uint8)
        self.floor = 0.0  # margin below which no input can enter `worst`

    def _run_kernel(self, x, y, n):
        args = (x,) if y is None else (x, y)
        if isinstance(self.ufunc, np.ufunc):
            return self.ufunc(*args, out=self.got[:n])
        got = self.ufunc(*args)
        if not (isinstance(got, np.ndarray) and got.dtype == np.float32):
            raise TypeError("the kernel must return a float32 array")
        return got

    def score_range(self, lo, hi, y_bits, result):
        """Score bit patterns [lo, hi) (``y_bits``: fixed second operand)."""
        for s in range(lo, hi, BLOCK):
            n = min(BLOCK, hi - s)
            xb = np.add(self.iota[:n], np.uint32(s), out=self.bits[:n])
            self.score(xb, y_bits, result)
        self.floor = max(self.floor, result.threshold())

    def score(self, xb, yb, result):
        """Score operands given as bit patterns ``xb`` (``yb``: scalar/array/None)."""
        n = xb.size
        x = xb.view(np.float32)
        y = None if yb is None else np.broadcast_to(
            np.asarray(yb, dtype=np.uint32).view(np.float32), x.shape)
        args = (x,) if y is None else (x, y)
        got = self._run_kernel(x, y, n)
        ref = reference(self.func, x, y, out=self.ref[:n])
        d = M.abs_error(got, ref, out=self.d[:n])
        # Regular inputs: normal float32 reference and finite result.  (Every
        # reference maps a non-finite operand to NaN, +-inf or +-0, so those
        # inputs are never regular.)  Decided per block by reductions first.
        a = np.abs(ref, out=self.s[:n])
        a_min = a.min()
        regular = bool(a_min >= M.MIN_NORMAL32 and a.max() < M.OVERFLOW32
                       and np.isfinite(d.max()))
        e32 = np.divide(d, M.ulp32(ref, out=self.e32[:n]), out=self.e32[:n])
        e16_scaled = bool(a_min >= 2.0**-14)
        if e16_scaled:  # ulp16 = 2**13 ulp32 throughout
            e16 = np.multiply(e32, 2.0**-13, out=self.e16[:n])
        else:
            e16 = np.divide(d, M.ulp16(ref, out=self.e16[:n]), out=self.e16[:n])
        special = None
        if not regular:
            special, tmp = self.reg[:n], self.tmp[:n]
            np.less(a, M.MIN_NORMAL32, out=special)
            np.logical_or(special, np.greater_equal(a, M.OVERFLOW32, out=tmp), out=special)
            np.logical_or(special, np.isnan(a, out=tmp), out=special)
            np.logical_or(special, np.isinf(d, out=tmp), out=special)
            np.logical_or(special, np.isnan(d, out=tmp), out=special)
        allowed = self.tol.ulps(*args, ref, out=self.m[:n])
        np.multiply(allowed, self.tol.unit_of(ref, out=self.s[:n]), out=allowed)
        if special is not None:
            sel = slice(None) if special.all() else np.flatnonzero(special)
            cat = self._classify(x[sel], None if y is None else y[sel],
                                 got[sel], ref[sel], allowed[sel])
            inf_ok = np.flatnonzero(cat == M.INF_ALLOWED)
            allowed_inf = allowed[sel][inf_ok]
        m = np.divide(d, allowed, out=self.m[:n])
        scored = None
        if special is not None:
            scored = self._specials(sel, cat, inf_ok, allowed_inf, xb, yb, got, ref, d, e32, e16,
                                    m, result)
        result.count += n
        self._reduce(xb, yb, got, ref, e32, e16, m, result, e16_scaled)
        if self.regions:
            self._regions(x, scored, xb, yb, got, ref, d, e32, e16, m, result)

    def _classify(self, x, y, got, ref, allowed):
        """:func:`measures.classify`, short-cut for results equal to the
        correctly rounded reference (the bulk of special inputs): those are
        ``match`` if the value or an operand is non-finite, else ``scored``."""
        k = x.size
        x_finite = np.isfinite(x, out=self.b_fin[:k])
        if y is not None:
            x_finite &= np.isfinite(y)
        r32 = self.r32[:k]
        r32[...] = ref
        exact = np.equal(got.view(np.uint32), r32.view(np.uint32), out=self.b_exact[:k])
        both_nan = np.isnan(got, out=self.b_tmp[:k])
        both_nan &= np.isnan(r32)
        exact |= both_nan
        cat = self.cat[:k]
        cat.fill(M.MATCH)
        finite = np.isfinite(r32, out=self.b_tmp[:k])
        finite &= x_finite
        np.copyto(cat, M.SCORED, where=finite)
        rest = np.flatnonzero(~exact)
        if rest.size:
            cat[rest] = M.classify(x_finite[rest], got[rest], ref[rest], allowed[rest])
        return cat

    def _specials(self, sel, cat, inf_ok, allowed_inf, xb, yb, got, ref, dist, e32, e16, m,
                  result):
        """Unscore special inputs, rescore permitted infinities, count the rest.
        Returns the mask of scored inputs when per-region statistics are kept."""
        whole = isinstance(sel, slice)
        pos = (lambda i: i) if whole else (lambda i: sel[i])
        unscored = (cat != M.SCORED) & (cat != M.INF_ALLOWED)
        for arr in (e32, e16, m) + ((dist,) if self.regions else ()):
            if whole and unscored.all():
                arr.fill(0.0)
            elif whole:
                np.putmask(arr, unscored, 0.0)
            else:
                arr[sel[unscored]] = 0.0
        if inf_ok.size:  # scored as if +-FLT_MAX had been returned
            i = pos(inf_ok)
            d = M.F32_MAX - np.abs(ref[i])
            e32[i], e16[i], m[i] = d / M.ulp32(ref[i]), d / M.ulp16(ref[i]), d / allowed_inf
            dist[i] = d
        scored = None
        if self.regions:
            scored = np.ones(dist.size, dtype=bool)
            scored[pos(np.flatnonzero(unscored))] = False
        if not np.any(cat >= M.FLUSH):  # only scored/matched/permitted-inf inputs
            return scored
        for code in M.MISMATCHES + (M.FLUSH,):
            hits = np.flatnonzero(cat == code)
            if not hits.size:
                continue
            name = M.CATEGORIES[code]
            cases = [self._case(i, xb, yb, got, ref, e32, e16, m, name)
                     for i in pos(hits[:EXAMPLES])]
            if code == M.FLUSH:
                result.flushed += hits.size
                result.flush_examples = sorted(result.flush_examples + cases,
                                               key=Case.key)[:EXAMPLES]
            else:
                result.special_mismatches[name] += hits.size
                result.special_examples = _first(result.special_examples + cases)
        return scored

    def _regions(self, x, scored, xb, yb, got, ref, d, e32, e16, m, result):
        """Fold the block into the per-region maxima (unscored inputs hold 0 in d, e32, e16, m)."""
        for name, predicate in self.regions:
            stats = result.regions.setdefault(name, _region_stats())
            inside = None if predicate is None else predicate(x)
            if inside is not None and not inside.any():
                continue
            members = inside if scored is None else (scored if inside is None else inside & scored)
            stats["count"] += x.size if members is None else int(np.count_nonzero(members))
            for key, arr in (("max_abs", d), ("max_ulp32", e32), ("max_ulp16", e16), ("max_margin", m)):
                masked = arr if inside is None else np.where(inside, arr, 0.0)
                i = int(np.argmax(masked))
                if masked[i] > stats[key]:
                    stats[key] = float(masked[i])
                    stats[key + "_at"] = self._case(i, xb, yb, got, ref, e32, e16, m, "scored")

    def _reduce(self, xb, yb, got, ref, e32, e16, m, result, e16_scaled):
        """Fold the block's scores into ``result`` (``e16_scaled``: e16 is e32
        times a constant, so its maximum is at e32's)."""
        at = {}
        for name, arr in (("ulp32", e32), ("ulp16", e16), ("margin", m)):
            i = at["ulp32"] if name == "ulp16" and e16_scaled else int(np.argmax(arr))
            at[name] = i
            if arr[i] > getattr(result, f"max_{name}"):
                setattr(result, f"max_{name}", float(arr[i]))
                setattr(result, f"max_{name}_case",
                        self._case(i, xb, yb, got, ref, e32, e16, m, "scored"))
        largest = float(m[at["margin"]])
        if largest >= 1.0:
            bad = np.greater_equal(m, 1.0, out=self.tmp[:m.size])
            result.nonconforming += int(np.count_nonzero(bad))
        cand = _top(m, max(result.threshold(), self.floor), largest)
        if cand.size:
            result.worst = sorted(
                result.worst + [self._case(i, xb, yb, got, ref, e32, e16, m, "scored")
                                for i in cand], key=_worst_order)[:WORST]

    @staticmethod
    def _case(i, xb, yb, got, ref, e32, e16, m, category):
        y_bits = None if yb is None else int(np.asarray(yb).reshape(-1)[i if np.ndim(yb) else 0])
        return Case(int(xb[i]), y_bits, int(got[i:i + 1].view(np.uint32)[0]),
                    float(ref[i]), float(e32[i]), float(e16[i]), float(m[i]), category)


_WORKER: _Block | None = None


def _init_worker(ufunc, func, precision):
    global _WORKER
    _WORKER = _Block(ufunc, func, precision)


_REMOTE: dict = {}


def _remote_task(task, context):
    """``_run_task`` on a cluster worker: its scorer made once per worker process and context."""
    global _WORKER
    key = pickle.dumps(context)
    if key not in _REMOTE:
        _REMOTE.clear()
        _REMOTE[key] = _Block(*context)
    _WORKER = _REMOTE[key]
    return _run_task(task)


def _run_task(task):
    lo, hi, y_bits, func, precision, inputs = task
    part = SweepResult(func, precision, inputs)
    with np.errstate(all="ignore"):
        _WORKER.score_range(lo, hi, y_bits, part)
    return part


def _bits(values):
    return np.asarray(values, dtype=np.float32).reshape(-1).view(np.uint32)


def _around(values, k):
    """The bit patterns within k ULPs of each value (both directions)."""
    centre = _bits(values).astype(np.int64)[:, None] + np.arange(-k, k + 1)
    return np.clip(centre, 0, 2**32 - 1).astype(np.uint32).reshape(-1)


def _uniform(rng, n, lo, hi):
    """n bit patterns uniform in [bits(lo), bits(hi)] (lo, hi of equal sign)."""
    a, b = sorted(int(v) for v in _bits([lo, hi]))
    return rng.integers(a, b + 1, size=n, dtype=np.uint64).astype(np.uint32)


_SPECIAL_BITS = np.array([
    0x00000000, 0x80000000, 0x7F800000, 0xFF800000,   # +-0, +-inf
    0x7FC00000, 0xFFC00000, 0x7F800001, 0x7FFFFFFF,   # NaNs (quiet, signalling)
    0x00000001, 0x00000002, 0x00400000, 0x007FFFFF,   # subnormals
    0x00800000, 0x00800001, 0x7F7FFFFF, 0x7F7FFFFE,   # min normal, FLT_MAX
], dtype=np.uint32)

#: Per function: thresholds to surround, and the value range sampled densely.
_HARD = {
    "exp2": ([128, 127, 126, -126, -127, -149, -150, -151, 1.0, 2.0**-24], (-151.0, 129.0)),
    "exp": ([88.7228391, 88.0, -87.3365448, -103.278929, -103.972077, 1.0, 2.0**-24],
            (-105.0, 90.0)),
    "log2": ([1.0, 0.5, 2.0, 2.0**-126, 2.0**127], (2.0**-149, 3.0e38)),
    "log": ([1.0, 0.5, 2.0, 2.718281828, 2.0**-126], (2.0**-149, 3.0e38)),
    "rcp": ([2.0**126, 2.0**-126, 2.0**127, 2.0**-127, 2.0**-128, 1.0, 3.0], (2.0**-149, 3.0e38)),
    "rsqrt": ([1.0, 2.0, 4.0, 2.0**-126, 2.0**126], (2.0**-149, 3.0e38)),
    "sqrt": ([1.0, 2.0, 4.0, 2.0**-126, 2.0**126], (2.0**-149, 3.0e38)),
    # sin/cos/tan: the Cody-Waite/Payne-Hanek switch at 2^17, pi, the hash range ~1e5
    # (plus, below, the floats nearest to k pi/2 and each binade's hardest reduction)
    "sin": ([np.pi, np.pi / 2, 2.0**17, 1e5, 43758.5453, 2.0**24, 1e10], (-1.2e5, 1.2e5)),
    "cos": ([np.pi, np.pi / 2, 2.0**17, 1e5, 43758.5453, 2.0**24, 1e10], (-1.2e5, 1.2e5)),
    "tan": ([np.pi, np.pi / 2, 2.0**17, 1e5, 2.0**24, 1e10], (-1.2e5, 1.2e5)),
    "asin": ([0.5, 1.0, 2.0**-12], (-1.0, 1.0)),
    "acos": ([0.5, 1.0, 2.0**-12], (-1.0, 1.0)),
    "atan": ([1.0, 2.0**-12, 2.0**12, 2.0**24], (-1e6, 1e6)),
    # sinh/cosh/tanh: the polynomial/exp switches (1, 0.55), ln FLT_MAX, the overflow of
    # sinh/cosh (89.415986), tanh's rounding to 1 (9.0109)
    "sinh": ([1.0, 88.7228391, 89.4159851, 2.0**-12], (-90.0, 90.0)),
    "cosh": ([1.0, 88.7228391, 89.4159851, 2.0**-12], (-90.0, 90.0)),
    "tanh": ([0.55, 9.01091, 44.361419, 2.0**-12], (-12.0, 12.0)),
}

#: Per binade 2^0 ... 2^127, the float32 closest to a multiple of pi/2 relative to pi/2 (the
#: hardest argument reduction of that binade; overall 0x6F79BE45 = 7.729179e28, 2^-29.9 quadrants away).
#: Found by frac(m * C_e) over all 2^23 significands m, C_e = frac(2^(e-23) * 2/pi) as a
#: 64-bit fixed-point fraction (uint64 products wrap modulo 2^64).
_REDUCTION_WORST = np.array([
    0x3FC90FDB, 0x40490FDB, 0x4096CBE4, 0x4116CBE4, 0x4196CBE4, 0x4216CBE4, 0x4296CBE4, 0x437CE5F1,
    0x43FCE5F1, 0x447CE5F1, 0x44FCE5F1, 0x450BE628, 0x458BE628, 0x460BE628, 0x468BE628, 0x474D246F,
    0x47CD246F, 0x484D246F, 0x4882665E, 0x4902665E, 0x4982665E, 0x4A2562AE, 0x4AA562AE, 0x4B2562AE,
    0x4BF3B47B, 0x4C2332E9, 0x4CA332E9, 0x4D2332E9, 0x4D847661, 0x4E13D4A5, 0x4E93D4A5, 0x4F0FFD14,
    0x4FDBD32F, 0x507FD274, 0x50A3E87F, 0x5123E87F, 0x51A3E87F, 0x5223E87F, 0x52A3E87F, 0x5323E87F,
    0x53B146A6, 0x543146A6, 0x54B146A6, 0x553146A6, 0x55B146A6, 0x56787577, 0x56F87577, 0x57787577,
    0x57B82989, 0x58382989, 0x58DC36C9, 0x596E3D69, 0x59F740B9, 0x5A7BC261, 0x5AFE0335, 0x5B7F239F,
    0x5BFFB3D4, 0x5C07BCD0, 0x5C87BCD0, 0x5D07BCD0, 0x5D87BCD0, 0x5E07BCD0, 0x5E87BCD0, 0x5F07BCD0,
    0x5FE4112C, 0x6064112C, 0x60AB0CE1, 0x617C556B, 0x61D3B126, 0x6253B126, 0x62EC1B4A, 0x636C1B4A,
    0x63E600C1, 0x642E0733, 0x64AE0733, 0x652E0733, 0x65898498, 0x66098498, 0x66898498, 0x67098498,
    0x67898498, 0x68098498, 0x68898498, 0x6946E3BB, 0x69C6E3BB, 0x6A1976F1, 0x6A9976F1, 0x6B1976F1,
    0x6B9976F1, 0x6C55DA58, 0x6CD5DA58, 0x6D2063C2, 0x6D85A877, 0x6E05A877, 0x6E85A877, 0x6F79BE45,
    0x6FF9BE45, 0x7079BE45, 0x70F9BE45, 0x7179BE45, 0x71F9BE45, 0x723FA09A, 0x72BFA09A, 0x733FA09A,
    0x73E61C18, 0x7452DE59, 0x74D2DE59, 0x756FA1DC, 0x75949471, 0x76507CE8, 0x76A426EB, 0x77584625,
    0x77D84625, 0x78584625, 0x78A8B883, 0x79407F54, 0x79C07F54, 0x7A105F7F, 0x7AFCCBAB, 0x7B1675C0,
    0x7B9675C0, 0x7C6C3305, 0x7CFF01BD, 0x7D7F01BD, 0x7DFF01BD, 0x7E7F01BD, 0x7EBDCDA0, 0x7F3DCDA0,
], dtype=np.uint32)
_TRIG = ("sin", "cos", "tan")


def _hard_unary(func):
    thresholds, _ = _HARD[func]
    t = np.asarray(thresholds, dtype=np.float64)
    powers = np.ldexp(1.0, np.arange(-149, 128))
    ints = np.arange(-300.0, 301.0)
    parts = [
        _SPECIAL_BITS, _SPECIAL_BITS | np.uint32(0x80000000),
        _around(np.concatenate([powers, -powers]), 1), _around(ints, 1),
        _around(np.concatenate([t, -t]), 64), _around([1.0], 4096)]
    if func in _TRIG:  # k pi/2 for k up to 4096 and a few far ones; each binade's hardest case
        k = np.concatenate([np.arange(1.0, 4097.0), [65535.0, 65536.0, 83443.0, 1e6, 1e9]])
        near = k * (np.pi / 2)
        worst = _REDUCTION_WORST.view(np.float32).astype(np.float64)
        parts += [_around(np.concatenate([near, -near]), 1), _around(np.concatenate([worst, -worst]), 2)]
    return np.concatenate(parts)


def _hard_pow():
    xs = np.array([0.0, -0.0, np.inf, -np.inf, np.nan, 1.0, -1.0, 0.5, 2.0, 3.0, 10.0,
                   2.718281828, 1e-45, 1e-40, 2.0**-126, 3.4e38, 1 + 2.0**-23,
                   1 - 2.0**-24, 0.999, 1.001, 7.5, 1e10, -2.0], np.float32)
    ys = np.array([0.0, -0.0, np.inf, -np.inf, np.nan, 1.0, -1.0, 0.5, -0.5, 2.0, -2.0,
                   3.0, 127.9, 128.0, -126.0, -149.0, -150.0, 1e10, -1e10, 1e-30,
                   38.5, 2.0**23, -(2.0**23), 100.5], np.float32)
    gx, gy = np.meshgrid(_bits(xs), _bits(ys))
    # overflow/underflow edges: pow(2, ~128), pow(10, ~38.53), pow(1+ulp, ~2**30)
    edges = [(2.0, _around([128.0, 127.0, -126.0, -149.0, -150.0], 32)),
             (10.0, _around([38.5318394, -37.9297794], 32)),
             (1 + 2.0**-23, _around([1.0 * 2**30, -1.0 * 2**30], 32))]
    ex = np.concatenate([np.full(b.size, _bits([v])[0]) for v, b in edges])
    ey = np.concatenate([b for _, b in edges])
    return np.concatenate([gx.ravel(), ex]), np.concatenate([gy.ravel(), ey])


def _hard_atan2():
    """Pairs (first operand, second operand) of atan2 where the C99 special cases and the
    placement by quadrant change: every pair of zeros, infinities, NaN, +-1, tiny and huge
    values, and pairs at and next to the diagonal |x| = |y|."""
    v = np.array([0.0, np.inf, np.nan, 1.0, 2.0, 0.5, 3.0, 1e-30, 1e30, 2.0**-149, 2.0**-126,
                  3.4028235e38, 7.0, 1e-10], np.float32)
    v = np.concatenate([v, -v])
    gx, gy = np.meshgrid(_bits(v), _bits(v))
    diag = _around(np.array([1.0, 3.0, 1e-20, 1e20, 2.0**-140, 3e38]), 8)
    dx = np.concatenate([diag, diag, diag ^ np.uint32(0x80000000)])
    dy = np.concatenate([_bits(np.repeat(np.array([1.0, 3.0, 1e-20, 1e20, 2.0**-140, 3e38],
                                                  np.float32), 17))] * 3)
    return np.concatenate([gx.ravel(), dx, dy]), np.concatenate([gy.ravel(), dy, dx])


def _atan2_pairs(rng, n):
    """n pairs: half uniform over all bit patterns, half at random angles and magnitudes
    (radius log-uniform over the float32 range, so y/x spans every ratio)."""
    half = n // 2
    raw = rng.integers(0, 2**32, (2, half), dtype=np.uint64).astype(np.uint32)
    theta = rng.uniform(-np.pi, np.pi, n - half)
    radius = np.exp2(rng.uniform(-140, 120, n - half))
    with np.errstate(all="ignore"):
        a = (radius * np.sin(theta)).astype(np.float32)
        b = (radius * np.cos(theta)).astype(np.float32)
    return np.concatenate([raw[0], _bits(a)]), np.concatenate([raw[1], _bits(b)])


def _unique(bits):
    """Sorted distinct values (np.unique is ~30x slower on uint32 in NumPy 2.4)."""
    bits = np.sort(bits)
    keep = np.ones(bits.size, dtype=bool)
    keep[1:] = bits[1:] != bits[:-1]
    return bits[keep]


def sample_inputs(func, n, seed=0):
    """A sample of float32 operands (as uint32 bit patterns) for quick checks.

    Always contains the hard regions (all +-0/inf/NaN kinds, subnormals,
    min normal and FLT_MAX, every power of two and +-300 integers with their
    neighbours, the function's overflow/underflow thresholds and domain
    boundaries +-64 ULP, 4096 ULP around 1; sin/cos/tan also the floats next
    to k pi/2 for k <= 4096 and each binade's hardest argument reduction),
    plus ``n`` random patterns: half uniform over all 2**32, half uniform (in
    bits) over the function's interesting range.  pow: the product of hard x
    and y values, the overflow and underflow edges of pow(2, y), pow(10, y),
    pow(1+ulp, y), and ``n`` random pairs.  atan2: every pair of special and
    diagonal operands and ``n`` random pairs (half at random angles).  Returns
    a tuple with one uint32 array per operand.
    """
    if func not in FUNCS:
        raise ValueError(f"unknown function {func!r}; expected one of {FUNCS}")
    rng = np.random.default_rng(seed)
    half = n // 2
    if func == "atan2":
        hx, hy = _hard_atan2()
        rx, ry = _atan2_pairs(rng, n)
        return np.concatenate([hx, rx]), np.concatenate([hy, ry])
    if func == "pow":
        hx, hy = _hard_pow()
        rx = np.concatenate([rng.integers(0, 2**32, half, dtype=np.uint64).astype(np.uint32),
                             _uniform(rng, n - half, 2.0**-149, 3.0e38)])
        x = rx.view(np.float32)
        with np.errstate(all="ignore"):  # y with |y log2 x| up to ~160: results in range
            y = rng.uniform(-160.0, 140.0, n) / np.log2(x.astype(np.float64))
        ry = np.where(np.arange(n) < half,
                      rng.integers(0, 2**32, n, dtype=np.uint64).astype(np.uint32),
                      _bits(np.nan_to_num(y, nan=1.0, posinf=1.0, neginf=1.0)))
        return np.concatenate([hx, rx]), np.concatenate([hy, ry])
    lo, hi = _HARD[func][1]
    random = [rng.integers(0, 2**32, half, dtype=np.uint64).astype(np.uint32)]
    if lo < 0:
        random += [_uniform(rng, (n - half) // 2, 0.0, hi),
                   _uniform(rng, n - half - (n - half) // 2, -0.0, lo)]
    else:
        random += [_uniform(rng, n - half, lo, hi)]
    return (_unique(np.concatenate([_hard_unary(func)] + random)),)


def _check(func, precision, y):
    if func not in FUNCS:
        raise ValueError(f"unknown function {func!r}; expected one of {FUNCS}")
    tolerance(func, precision)  # validates precision
    if (ARITY[func] == 2) != (y is not None):
        raise ValueError(f"{func} takes {ARITY[func]} operand(s); pass y for {' and '.join(BINARY)} only")


def evaluate(ufunc, func, precision, x_bits, y_bits=None) -> SweepResult:
    """Score ``ufunc`` on the float32 operands given as uint32 bit patterns."""
    _check(func, precision, y_bits)
    xb = np.ascontiguousarray(x_bits, dtype=np.uint32).reshape(-1)
    yb = None if y_bits is None else np.broadcast_to(
        np.asarray(y_bits, dtype=np.uint32), xb.shape)
    result = SweepResult(func, precision, f"{xb.size} given inputs")
    block = _Block(ufunc, func, precision)
    t0 = time.perf_counter()
    with np.errstate(all="ignore"):
        for s in range(0, xb.size, BLOCK):
            block.score(xb[s:s + BLOCK], None if yb is None else yb[s:s + BLOCK], result)
    result.seconds = time.perf_counter() - t0
    return result


def sweep(ufunc, func, precision, *, start=0, stop=2**32, chunk=2**22, workers=2,
          progress=True, y=None, scheduler=None) -> SweepResult:
    """Exhaustively score ``ufunc`` on float32 bit patterns [start, stop).

    ``func``: one of :data:`routines.lab.reference.FUNCS`; ``precision``:
    'full' or 'relaxed'; ``chunk``: inputs per task (the progress step);
    ``workers``: forked processes (1: run in this process, no fork);
    ``progress``: tqdm bar on stderr; ``y``: for pow and atan2, the fixed
    float32 second operand (x, the first, is swept); ``scheduler``: a dask
    cluster's address (or Client) to spread the chunks over instead of
    ``workers`` local processes (``routines.lab.cluster``): the same figures.
    """
    _check(func, precision, y)
    if not 0 <= start < stop <= 2**32:
        raise ValueError("need 0 <= start < stop <= 2**32")
    y_bits = None if y is None else np.float32(y).view(np.uint32)
    inputs = f"bits [0x{start:08x}, 0x{stop:08x})" + ("" if y is None else f", y={float(y):.9g}")
    total = SweepResult(func, precision, inputs)
    tasks = [(lo, min(lo + chunk, stop), y_bits, func, precision, inputs)
             for lo in range(start, stop, chunk)]
    t0 = time.perf_counter()
    if scheduler is not None:
        from .cluster import on_cluster
        parts = on_cluster(scheduler, _remote_task, tasks, (ufunc, func, precision))
        pool = contextlib.nullcontext()
    elif workers == 1:
        _init_worker(ufunc, func, precision)
        parts = map(_run_task, tasks)
        pool = contextlib.nullcontext()
    else:  # fork: the kernel is inherited, never pickled
        parts = ()  # the pool's, below
        pool = forked_pool(workers, _init_worker, (ufunc, func, precision))
    with pool as started, tqdm(total=stop - start, unit="in", unit_scale=True, file=sys.stderr,
                    disable=None if progress else True,  # None: only on a terminal
                    desc=f"{func} {precision}") as bar:
        for part in parts if started is None else started.imap_unordered(_run_task, tasks):
            total.merge(part)
            bar.update(part.count)
    total.seconds = time.perf_counter() - t0
    return total
