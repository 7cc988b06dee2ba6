"""The stratified sweep of two-operand pow (2^64 pairs cannot all be tried).

``stratified_pow(ufunc, precision)`` scores at least 2^30 pairs:

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

Strata run in forked worker processes (the kernel is inherited).
"""
from __future__ import annotations

import multiprocessing
import sys
import time

import numpy as np
from tqdm import tqdm

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


def _x_stratum(k: int, seed: int) -> np.ndarray:
    offset = int(np.random.default_rng((seed, k)).integers(0, X_STRIDE))
    return np.arange(offset, 2**32, X_STRIDE, dtype=np.uint64).astype(np.uint32)


_WORKER = {}


def _init(ufunc, precision, seed):
    _WORKER.update(ufunc=ufunc, precision=precision, seed=seed)


def _stratum(task):
    k, y_bits = task
    x = _x_stratum(k, _WORKER["seed"])
    return evaluate(_WORKER["ufunc"], "pow", _WORKER["precision"], x, np.full(x.size, y_bits, np.uint32))


def stratified_pow(ufunc, precision: str, *, seed: int = 0, workers: int = 2, strata: int = STRATA,
                   progress: bool = True) -> SweepResult:
    """Score ``ufunc`` (pow) on the stratified sweep described in the module doc."""
    t0 = time.perf_counter()
    total = SweepResult("pow", precision, f"stratified: {strata} y strata x 2^22 x, specials, 2^24 random")
    hx, hy = sample_inputs("pow", 2 ** 24, seed=seed)
    total.merge(evaluate(ufunc, "pow", precision, hx, hy))
    tasks = list(enumerate(y_strata(seed)[:strata]))
    ctx = multiprocessing.get_context("fork")
    with ctx.Pool(workers, initializer=_init, initargs=(ufunc, precision, seed)) as pool, \
            tqdm(total=len(tasks), unit="stratum", file=sys.stderr,
                 disable=None if progress else True,  # None: only on a terminal
                 desc=f"pow {precision}") as bar:
        for part in pool.imap_unordered(_stratum, tasks):
            total.merge(part)
            bar.update(1)
    total.seconds = time.perf_counter() - t0
    return total
