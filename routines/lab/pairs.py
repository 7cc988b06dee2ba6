"""The stratified sweeps of the two-operand pow and atan2 (2^64 pairs cannot all be tried).

``stratified(ufunc, func, precision)`` (``stratified_pow(ufunc, precision)`` for
pow) scores at least 2^30 pairs. pow:

* **strata** -- 256 exponents y: every special (±0, ±inf, NaN, ±1, ±0.5, ±2)
  and, for each binade 2^e with e in [-24, 30] and both signs, two random
  significands (plus random fill), so that y*log2(x) spans underflow, the
  normal range and overflow; for each y, 2^22 x values: every 1024th float32
  bit pattern from a random offset, i.e. every binade of x (subnormals, NaNs
  and infinities included) with 2^13 significands each;
* **specials** -- every pair of the hard x and y values of ``sample_inputs``
  (zeros, infinities, NaNs, 1 and its neighbours, overflow/underflow edges);
* **random** -- 2^24 pairs like the Vulkan CTS's: bit patterns uniform over
  all 2^32 for both operands, and x uniform over positive floats with y drawn
  so that |y log2 x| stays in the representable range.

atan2 (operands in the routine's order, atan2(a, b); b stratified):

* **strata** -- 256 values of b: +-0, +-inf, NaN, +-1, and for every second
  binade 2^e, e in [-149, 127], one random significand with alternating sign
  (plus random fill), so that a/b spans every ratio from underflow to
  overflow of a float32 quotient; for each b, 2^22 values of a: every 1024th
  bit pattern (all binades, both signs, zeros, infinities and NaNs);
* **specials** -- every pair of zeros, infinities, NaN, +-1, tiny and huge
  values, and pairs on and next to the diagonal |a| = |b|;
* **random** -- 2^24 pairs: half uniform over all bit patterns, half at
  random angles with log-uniform radius.

Strata run in forked worker processes (the kernel is inherited).
"""
from __future__ import annotations

import contextlib
import sys
import time

import numpy as np
from tqdm import tqdm

from reactor.cli import forked_pool

from .sweep import SweepResult, evaluate, sample_inputs

STRATA = 256
X_STRIDE = 1024  # 2^32 / 1024 = 2^22 x values per stratum

_SPECIAL_Y = [0.0, -0.0, np.inf, -np.inf, np.nan, 1.0, -1.0, 0.5, -0.5, 2.0, -2.0]


def y_strata(seed: int = 0) -> np.ndarray:
    """The 256 float32 exponents y of the strata, as bit patterns."""
    rng = np.random.default_rng(seed)
    ys = list(_SPECIAL_Y)
    for e in range(-24, 31):
        for sign in (1.0, -1.0):
            ys += [sign * np.ldexp(1.0 + rng.random(), e) for _ in range(2)]
    while len(ys) < STRATA:
        ys.append(float(np.ldexp(rng.uniform(-1, 1), int(rng.integers(-24, 31)))))
    return np.asarray(ys[:STRATA], np.float32).view(np.uint32)


def atan2_strata(seed: int = 0) -> np.ndarray:
    """The 256 second operands b of atan2's strata, as bit patterns."""
    rng = np.random.default_rng(seed)
    bs = [0.0, -0.0, np.inf, -np.inf, np.nan, 1.0, -1.0]
    for i, e in enumerate(range(-149, 128, 2)):
        bs.append((-1.0) ** i * float(np.ldexp(1.0 + rng.random(), e)))
    while len(bs) < STRATA:
        bs.append(float(np.ldexp(rng.uniform(-1, 1), int(rng.integers(-149, 128)))))
    return np.asarray(bs[:STRATA], np.float32).view(np.uint32)


STRATA_OF = {"pow": y_strata, "atan2": atan2_strata}


def x_stratum(k: int, seed: int) -> np.ndarray:
    offset = int(np.random.default_rng((seed, k)).integers(0, X_STRIDE))
    return np.arange(offset, 2**32, X_STRIDE, dtype=np.uint64).astype(np.uint32)


_WORKER = {}


def _init(ufunc, func, precision, seed):
    _WORKER.update(ufunc=ufunc, func=func, precision=precision, seed=seed)


def _stratum(task):
    k, y_bits = task
    x = x_stratum(k, _WORKER["seed"])
    return evaluate(_WORKER["ufunc"], _WORKER["func"], _WORKER["precision"], x,
                    np.full(x.size, y_bits, np.uint32))


def _remote_stratum(task, context):
    """``_stratum`` on a cluster worker."""
    _init(*context)
    return _stratum(task)


def stratified_pow(ufunc, precision: str, *, seed: int = 0, workers: int = 2, strata: int = STRATA,
                   progress: bool = True) -> SweepResult:
    """Score ``ufunc`` (pow) on the stratified sweep described in the module doc."""
    return stratified(ufunc, "pow", precision, seed=seed, workers=workers, strata=strata,
                      progress=progress)


def stratified(ufunc, func: str, precision: str, *, seed: int = 0, workers: int = 2,
               strata: int = STRATA, progress: bool = True, scheduler=None) -> SweepResult:
    """Score ``ufunc`` (``func``: "pow" or "atan2") on the stratified sweep of the module doc
    (``scheduler``: a dask cluster's address or Client to spread the strata over)."""
    if func not in STRATA_OF:
        raise ValueError(f"no stratified sweep for {func!r}; choose one of {', '.join(STRATA_OF)}")
    t0 = time.perf_counter()
    total = SweepResult(func, precision, f"stratified: {strata} y strata x 2^22 x, specials, 2^24 random")
    hx, hy = sample_inputs(func, 2 ** 24, seed=seed)
    total.merge(evaluate(ufunc, func, precision, hx, hy))
    tasks = list(enumerate(STRATA_OF[func](seed)[:strata]))
    if scheduler is not None:
        from .cluster import on_cluster
        pool = contextlib.nullcontext()
        parts = on_cluster(scheduler, _remote_stratum, tasks, (ufunc, func, precision, seed))
    else:
        parts = ()  # the pool's, below
        pool = forked_pool(workers, _init, (ufunc, func, precision, seed))
    with pool as started, tqdm(total=len(tasks), unit="stratum", file=sys.stderr,
                    disable=None if progress else True,  # None: only on a terminal
                    desc=f"{func} {precision}") as bar:
        for part in parts if started is None else started.imap_unordered(_stratum, tasks):
            total.merge(part)
            bar.update(1)
    total.seconds = time.perf_counter() - t0
    return total
