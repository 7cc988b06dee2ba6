"""The accuracy ladder's proof: a compiled unary kernel on every float32 input, against a
correctly rounded reference.

The reference is NumPy's float64 function (relative error below 2^-52; for rsqrt two
correctly rounded float64 operations) rounded to float32. That rounding is the correct one
unless the float64 value lies within ``NEAR`` (2^-40) relative of a float32 rounding
boundary (the midpoint between two neighbouring floats, subnormal ones included): those
inputs, about one in 2^15, are decided by mpmath at 50 digits against the exact midpoint.

Per variant: results not correctly rounded (bits, the sign of zero included; a NaN must meet
a NaN), the largest error in ULP-32 (against the float64 value, in the spacing of float32
there), results in the subnormal range and how many of them are wrong, and how many
inputs mpmath decided. ``python -m routines ladder`` runs it; ``--exhaustive`` sweeps all
2^32 inputs in chunks on every core.
"""
from __future__ import annotations

import dataclasses
import multiprocessing
import time

import mpmath
import numpy as np

from reactor.cli import forked_pool

from .measures import ulp32
from .reference import reference

UNARY = ("exp2", "exp", "log2", "log", "rcp", "rsqrt", "sqrt", "sin", "cos", "tan", "asin", "acos", "atan",
         "sinh", "cosh", "tanh")
NEAR = 2.0 ** -40
BLOCK = 2 ** 18
_MP = {"exp2": lambda v: mpmath.power(2, v), "exp": mpmath.exp, "log2": lambda v: mpmath.log(v, 2),
       "log": mpmath.log, "rcp": lambda v: 1 / v, "rsqrt": lambda v: 1 / mpmath.sqrt(v),
       "sqrt": mpmath.sqrt, "pow": mpmath.power, "sin": mpmath.sin, "cos": mpmath.cos, "tan": mpmath.tan,
       "asin": mpmath.asin, "acos": mpmath.acos, "atan": mpmath.atan, "atan2": mpmath.atan2,
       "sinh": mpmath.sinh, "cosh": mpmath.cosh, "tanh": mpmath.tanh}
_LOW29 = np.uint64((1 << 29) - 1)
_MID_MINUS_NEAR = np.uint64((1 << 28) - (1 << 13))
_NEAR2 = np.uint64(1 << 14)
_NO_SIGN = np.uint64((1 << 63) - 1)
_MIN_NORMAL64 = np.float64(2.0 ** -126).view(np.uint64)


def c99_reference(func: str, x: np.ndarray, y: np.ndarray | None = None) -> np.ndarray:
    """float64 ``func(x)`` (pow: C99's pow(x, y), NumPy's float64 power). log2 is ln(x) / ln(2)
    (relative error below 2^-51, 3x faster than NumPy's float64 log2 here)."""
    if func == "pow":
        with np.errstate(all="ignore"):
            return np.power(x.astype(np.float64), y.astype(np.float64))
    if func == "log2":
        with np.errstate(all="ignore"):
            out = np.log(x, dtype=np.float64)
            return np.multiply(out, 1.4426950408889634, out=out)
    return reference(func, x, y)


def _near(ref: np.ndarray, near: float = NEAR) -> np.ndarray:
    """Indices where the float64 ``ref`` lies within ``near`` (a power of two, at most 2^-40)
    relative of a float32 rounding boundary: the midpoint of two floats (subnormal ones
    included) or the overflow threshold 2^128 - 2^103.

    Where |ref| is normal in float32 (or overflows), its 29 bits below float32's last one say
    how far it is from the midpoint (2^28): within 2^13 of it is within 2^-40 relative (a
    tighter ``near``: measured exactly on those). Below 2^-126 the grid is 2^-149 whatever the
    binade."""
    with np.errstate(all="ignore"):
        bits = ref.view(np.uint64)
        low = np.bitwise_and(bits - _MID_MINUS_NEAR, _LOW29)          # |low29 - 2^28| <= 2^13
        candidates = np.flatnonzero(np.less_equal(low, _NEAR2, out=np.empty(low.shape, bool)))
        a = np.abs(ref[candidates])
        normal = candidates[(a >= 2.0 ** -126) & (a < 2.0 ** 128)]
        if near < NEAR:
            a = np.abs(ref[normal])
            mid = (np.bitwise_and(a.view(np.uint64), ~_LOW29) | np.uint64(1 << 28)).view(np.float64)
            normal = normal[np.abs(a - mid) <= near * a]
        magnitude = np.bitwise_and(bits, _NO_SIGN, out=low)
        tiny = np.flatnonzero((magnitude < _MIN_NORMAL64) & (magnitude > 0))
        if tiny.size:
            t = np.abs(ref[tiny]) * 2.0 ** 149
            tiny = tiny[np.abs(t - np.floor(t) - 0.5) <= near * np.maximum(t, 1.0)]
    return np.concatenate([normal, tiny])


def correctly_rounded(func: str, x: np.ndarray, ref: np.ndarray | None = None,
                      y: np.ndarray | None = None) -> tuple[np.ndarray, int]:
    """The correctly rounded float32 ``func(x)`` (``func(x, y)``) and how many lanes mpmath decided:
    the float64 reference rounded, except within 2^-40 of a boundary (``_near``), where mpmath
    decides at 50 digits."""
    ref = c99_reference(func, x, y) if ref is None else ref
    with np.errstate(all="ignore"):
        r = ref.astype(np.float32)
    near = _near(ref)
    if near.size:
        exact = _MP[func]
        with mpmath.workdps(50):
            for i in near:
                r[i] = _decide(exact, x[i] if y is None else (x[i], y[i]), float(ref[i]))
    return r, int(near.size)


def _decide(exact, args, ref: float) -> np.float32:
    """The float32 nearest to the exact value, whose float64 approximation ``ref`` lies near the
    midpoint of two floats (ties to even)."""
    a = abs(ref)
    if a < 2.0 ** -126:
        lo = np.floor(a * 2.0 ** 149) * 2.0 ** -149
        hi = lo + 2.0 ** -149
    else:
        lo = float(np.uint64(np.float64(a).view(np.uint64) & ~_LOW29).view(np.float64))
        hi = float(np.nextafter(np.float32(lo), np.float32(np.inf)))
    args = args if isinstance(args, tuple) else (args,)
    v = abs(exact(*(mpmath.mpf(float(z)) for z in args)))
    mid = mpmath.mpf(lo) / 2 + mpmath.mpf(hi) / 2
    if v != mid:
        pick = hi if v > mid else lo
    else:
        pick = lo if int(np.float32(lo).view(np.uint32)) % 2 == 0 else hi
    return np.float32(np.copysign(pick, ref))


@dataclasses.dataclass
class LadderResult:
    """One variant's sweep (see the module docstring)."""

    func: str
    variant: str
    inputs: int = 0
    misrounded: int = 0
    max_ulp: float = 0.0
    max_ulp_at: float = float("nan")
    subnormal_results: int = 0
    subnormal_misrounded: int = 0
    decided_by_mpmath: int = 0
    seconds: float = 0.0
    examples: list = dataclasses.field(default_factory=list)

    def merge(self, other: "LadderResult") -> None:
        for name in ("inputs", "misrounded", "subnormal_results", "subnormal_misrounded", "decided_by_mpmath"):
            setattr(self, name, getattr(self, name) + getattr(other, name))
        if other.max_ulp > self.max_ulp:
            self.max_ulp, self.max_ulp_at = other.max_ulp, other.max_ulp_at
        self.examples = (self.examples + other.examples)[:8]

    def line(self) -> str:
        return (f"{self.func:6s} {self.variant:22s} {self.inputs:>11,d} inputs  misrounded {self.misrounded:,d}  "
                f"max {self.max_ulp:.4f} ULP (x = {self.max_ulp_at:.9g})  subnormal results "
                f"{self.subnormal_results:,d} ({self.subnormal_misrounded} wrong)  mpmath decided "
                f"{self.decided_by_mpmath:,d}  {self.seconds:.1f} s")


def score(ufunc, func: str, variant: str, bits: np.ndarray, y_bits: np.ndarray | None = None) -> LadderResult:
    """Score ``ufunc`` on the float32 inputs with these bit patterns (pow: and exponents)."""
    return score_many({variant: ufunc}, func, bits, y_bits)[variant]


def score_many(ufuncs: dict, func: str, bits: np.ndarray, y_bits: np.ndarray | None = None) -> dict:
    """Score every variant of ``ufuncs`` (name -> ufunc) on these inputs against one reference.

    What does not depend on the variant is computed once per block: the reference, the correctly
    rounded result, and the error of the nearest float32 (which a variant's result is, on most
    lanes); a variant's own error is measured only where its result differs from that float."""
    out = {variant: LadderResult(func, variant) for variant in ufuncs}
    for s in range(0, bits.size, BLOCK):
        x = bits[s:s + BLOCK].view(np.float32)
        y = None if y_bits is None else y_bits[s:s + BLOCK].view(np.float32)
        ref = c99_reference(func, x, y)
        want, decided = correctly_rounded(func, x, ref, y)
        tiny = (np.abs(want) < 2.0 ** -126) & (want != 0)  # the correct result is a subnormal float
        with np.errstate(all="ignore"):
            nearest = ref.astype(np.float32)
            base = _ulp_error(nearest, ref)
        for variant, ufunc in ufuncs.items():
            with np.errstate(all="ignore"):  # peers (NumPy) warn at overflow and invalid inputs
                got = ufunc(x) if y is None else ufunc(x, y)
            out[variant].merge(_block(func, variant, x, y, got, want, ref, nearest, base, tiny, decided))
    return out


def _ulp_error(got: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """|got - ref| in ULP-32 at ref; 0 where either is not finite."""
    with np.errstate(all="ignore"):
        err = np.abs(got.astype(np.float64) - ref) / ulp32(ref)
    err[~(np.isfinite(err) & np.isfinite(got))] = 0.0
    return err


def _block(func, variant, x, y, got, want, ref, nearest, base, tiny, decided) -> LadderResult:
    got_bits, want_bits = got.view(np.uint32), want.view(np.uint32)
    wrong = np.flatnonzero(got_bits != want_bits)
    wrong = wrong[~(np.isnan(got[wrong]) & np.isnan(want[wrong]))]
    other = np.flatnonzero(got_bits != nearest.view(np.uint32))
    err = base.copy()
    err[other] = _ulp_error(got[other], ref[other])
    block = LadderResult(func, variant, inputs=x.size, misrounded=int(wrong.size),
                         subnormal_results=int(tiny.sum()), subnormal_misrounded=int(tiny[wrong].sum()),
                         decided_by_mpmath=decided)
    i = int(np.argmax(err))
    block.max_ulp, block.max_ulp_at = float(err[i]), float(x[i])
    block.examples = [(float(x[j]),) + (() if y is None else (float(y[j]),)) + (float(got[j]), float(want[j]))
                      for j in wrong[:8]]
    return block


_WORKER: dict = {}


def _init(ufuncs, func):
    _WORKER.update(ufuncs=ufuncs, func=func)


def _task(span):
    start, stop, step = span
    bits = np.arange(start, stop, step, dtype=np.uint64).astype(np.uint32)
    return score_many(_WORKER["ufuncs"], _WORKER["func"], bits)


def _pair_task(task):
    k, y = task
    from .pairs import x_stratum
    x = x_stratum(k, 0)
    return score_many(_WORKER["ufuncs"], _WORKER["func"], x, np.full(x.size, y, np.uint32))


def atan2_hard_cases() -> tuple[np.ndarray, np.ndarray]:
    """atan2's hard pairs (first operand, second): every pair of special and extreme values,
    pairs on and next to the diagonal |a| = |b| and at the ratios where its reduction changes
    sector (tan(pi/8), tan(3pi/8)), quotients that underflow to subnormal results, and random
    angles of every magnitude."""
    rng = np.random.default_rng(23)
    specials = [0.0, -0.0, np.inf, -np.inf, np.nan, 1.0, -1.0, 2.0 ** -149, -(2.0 ** -149), 2.0 ** -126,
                3.4028235e38, -3.4028235e38, 1e-30, 1e30, 0.5, -3.0]
    a, b = np.meshgrid(np.asarray(specials, np.float32), np.asarray(specials, np.float32))
    xs, ys = [a.ravel()], [b.ravel()]
    base = np.exp(rng.uniform(-80, 80, 20000)).astype(np.float32) * rng.choice([-1, 1], 20000).astype(np.float32)
    for ratio in (1.0, np.tan(np.pi / 8), np.tan(3 * np.pi / 8), 1 / 64, 1 / 32):
        for step in (-2, -1, 0, 1, 2):
            other = np.nextafter(np.float32(ratio) * base, np.float32(np.inf) * step) if step else \
                (np.float32(ratio) * base).astype(np.float32)
            xs += [other, base]
            ys += [base, other]
    tiny = np.ldexp(rng.uniform(1, 2, 20000), rng.integers(-149, -100, 20000)).astype(np.float32)
    xs.append(tiny)
    ys.append(np.ldexp(rng.uniform(1, 2, 20000), rng.integers(0, 40, 20000)).astype(np.float32))
    radius = np.exp(rng.uniform(-60, 60, 100000))
    angle = rng.uniform(-np.pi, np.pi, 100000)
    xs.append((radius * np.sin(angle)).astype(np.float32))
    ys.append((radius * np.cos(angle)).astype(np.float32))
    x, y = np.concatenate(xs).astype(np.float32), np.concatenate(ys).astype(np.float32)
    return x.view(np.uint32), y.view(np.uint32)



def pow_hard_cases() -> tuple[np.ndarray, np.ndarray]:
    """pow's hard pairs: x next to 1 with large |y|, results at the overflow, underflow and
    subnormal thresholds, exact cases (2^k, 4^0.5, (-8)^3, ...), and every C99 special."""
    rng = np.random.default_rng(17)
    xs, ys = [], []
    one = np.float32(1.0)
    near_one = [np.nextafter(one, np.float32(2)), np.nextafter(one, np.float32(0))]
    for k in range(1, 2000):
        near_one += [np.float32(1 + k * 2.0 ** -23), np.float32(1 - k * 2.0 ** -24)]
    for x in near_one:
        for target in (127.9, 100.0, 10.0, -125.5, -149.5, -140.0):
            y = np.float32(target / np.log2(np.float64(x)))
            xs += [x, x, x]
            ys += [y, np.nextafter(y, np.float32(np.inf)), np.nextafter(y, np.float32(-np.inf))]
    for t in np.concatenate([np.linspace(127.0, 128.5, 3000), np.linspace(-152.0, -125.0, 3000)]):
        x = np.float32(rng.uniform(0.1, 10.0))
        xs.append(x)
        ys.append(np.float32(t / np.log2(np.float64(x))))
    for b in range(-149, 128):                    # 2^b = x^y exactly
        for x, y in ((2.0, b), (4.0, b / 2), (0.5, -b), (2.0 ** max(-126, min(b, 127)), 1.0)):
            xs.append(x)
            ys.append(y)
    for n in range(2, 16):                        # exact results halfway between two floats
        for m in range(3, int(2 ** (25 / n)) + 2, 2):
            if 2 ** 24 < m ** n < 2 ** 25:            # 25 significant bits: a midpoint of normal floats
                for scale in (2.0 ** -m.bit_length(), 2.0 ** (3 - m.bit_length()), -(2.0 ** -m.bit_length())):
                    xs.append(m * scale)
                    ys.append(n)
            if 150 % n == 0 and m ** n < 2 ** 24:     # m^n 2^-150: a midpoint of subnormal floats
                xs.append(m * 2.0 ** (-150 // n))
                ys.append(n)
    for n, p in [(n, 3) for n in range(257, 322, 2)] + [(29, 5), (31, 5), (11, 7)]:   # x^(p/2) = n^p, x = n^2
        for root, y in ((n * n, p / 2), (n ** 4, p / 4)):
            if root < 2 ** 24:
                for scale in (1.0, 2.0 ** -40, 2.0 ** 30):
                    xs.append(root * scale)
                    ys.append(y)
    for n in range(3, 256, 2):                        # n^3 2^-150: halfway between subnormals
        xs.append(n * n * 2.0 ** -100)
        ys.append(1.5)
    for k in range(1, 151):                           # 2^-150 = x^y with x a power of two: halfway to 0
        if 150 % k == 0:
            xs.append(2.0 ** -k)
            ys.append(150 // k)
    for base in range(-12, 13):                   # whole powers of whole numbers, negative bases too
        for n in range(-8, 9):
            xs.append(base)
            ys.append(n)
    specials = [0.0, -0.0, 1.0, -1.0, 0.5, -0.5, 2.0, -2.0, 3.0, -3.0, 2.5, -2.5, np.inf, -np.inf, np.nan,
                1e-45, -1e-45, 3.4e38, -3.4e38, 2.0 ** 24, -(2.0 ** 24) - 2, 1.0000001, 0.99999994]
    for x in specials:
        for y in specials:
            xs.append(x)
            ys.append(y)
    return np.asarray(xs, np.float32).view(np.uint32), np.asarray(ys, np.float32).view(np.uint32)


def sweep(ufunc, func: str, variant: str, **options) -> LadderResult:
    """``sweep_many`` of one variant."""
    return sweep_many({variant: ufunc}, func, **options)[variant]


def sweep_many(ufuncs: dict, func: str, *, start: int = 0, stop: int = 2 ** 32, step: int = 1,
               chunk: int = 2 ** 22, workers: int | None = None, progress=None) -> dict:
    """Every ``step``-th float32 bit pattern in [start, stop), in tasks of ``chunk`` patterns on
    forked workers, each variant of ``ufuncs`` (name -> ufunc) scored against one reference per
    input. pow and atan2: the stratified sweep of ``routines.lab.pairs`` (256 second operands,
    2^22 first operands each: 2^30 pairs; ``step`` > 1 takes every step-th stratum) plus
    ``pow_hard_cases`` or ``atan2_hard_cases``."""
    t0 = time.perf_counter()
    if func in ("pow", "atan2"):
        from .pairs import atan2_strata, y_strata
        strata = y_strata(0) if func == "pow" else atan2_strata(0)
        tasks, run = list(enumerate(strata))[::step], _pair_task
        totals = score_many(ufuncs, func, *(pow_hard_cases() if func == "pow" else atan2_hard_cases()))
    else:
        span = chunk * step
        tasks, run = [(s, min(s + span, stop), step) for s in range(start, stop, span)], _task
        totals = {variant: LadderResult(func, variant) for variant in ufuncs}
    workers = workers or multiprocessing.cpu_count()
    with forked_pool(workers, _init, (ufuncs, func)) as pool:
        for part in pool.imap_unordered(run, tasks):
            for variant, result in part.items():
                totals[variant].merge(result)
            if progress:
                progress(next(iter(part.values())).inputs)
    for result in totals.values():
        result.seconds = time.perf_counter() - t0
    return totals


def hard_cases(func: str, bits: np.ndarray, near: float) -> np.ndarray:
    """(input bits, correctly rounded result bits) as int32 pairs, for the float32 inputs among
    ``bits`` whose exact ``func`` lies within ``near`` relative of a float32 rounding boundary
    (judged on the float64 reference with a margin of 2^-49 for its error; mpmath decides each)."""
    x = bits.view(np.float32)
    ref = c99_reference(func, x)
    picked = _near(ref, near + 2.0 ** -49)
    with np.errstate(all="ignore"):
        r = ref[picked].astype(np.float32)
    with mpmath.workdps(50):
        for n, i in enumerate(picked):
            r[n] = _decide(_MP[func], x[i], float(ref[i]))
    return np.stack([bits[picked].view(np.int32), r.view(np.int32)], axis=1)


def _hard_task(span):
    start, stop = span
    bits = np.arange(start, stop, dtype=np.uint64).astype(np.uint32)
    return hard_cases(_WORKER["func"], bits, _WORKER["near"])


def sweep_hard_cases(func: str, near: float, *, chunk: int = 2 ** 22, workers: int | None = None,
                     progress=None) -> np.ndarray:
    """``hard_cases`` over all 2^32 float32 inputs, sorted by input bits as signed integers."""
    _WORKER.update(func=func, near=near)
    tasks = [(s, s + chunk) for s in range(0, 2 ** 32, chunk)]
    parts = []
    with forked_pool(workers or multiprocessing.cpu_count(), None, ()) as pool:
        for part in pool.imap_unordered(_hard_task, tasks):
            parts.append(part)
            if progress:
                progress(chunk)
    pairs = np.concatenate(parts)
    return pairs[np.argsort(pairs[:, 0], kind="stable")]
