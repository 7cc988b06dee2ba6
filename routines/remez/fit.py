"""Weighted minimax polynomial fitting (Remez exchange) on mpmath.

Conventions (those of LolRemez):

* the weight ``w`` is a *tolerance*: the fitter minimises
  ``max |p(x) - f(x)| / |w(x)|`` over ``[a, b]``, so a larger weight allows a
  larger error there;
* ``f`` and ``w`` may have removable singularities or poles (``(2^x-1)/x``,
  ``1/x`` at 0): where an evaluation raises or is not finite, the value is
  taken as the limit from inside the interval (see :func:`evaluate`); a pole
  of ``w`` makes the weighted error vanish there;
* internally the variable is mapped to ``t`` in ``[-1, 1]`` for conditioning;
  the returned coefficients are those of ``p`` in the original ``x``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from mpmath import mp, mpf

from .expr import parse

__all__ = ["RemezError", "RemezResult", "RetuneResult", "evaluate", "remez", "retune", "to_float32"]

Function = Callable[[mpf], mpf]

#: Samples per sub-interval when looking for the extremum of the error there.
_SAMPLES = 16
#: Dense-grid points per reference point for the final equioscillation check.
_CHECK_GRID = 48


class RemezError(ValueError):
    """The exchange did not converge, or its result failed the final checks."""


def to_float32(value: mpf) -> np.float32:
    """Round ``value`` to the nearest binary32 (ties to even), subnormals included."""
    with mp.workprec(24):
        r = +value
    if r != 0 and abs(r) < mpf(2) ** -126:
        r = mp.nint(value * mpf(2) ** 149) * mpf(2) ** -149
    with np.errstate(over="ignore"):
        return np.float32(float(r))


@dataclass(frozen=True)
class RemezResult:
    """A minimax polynomial ``p`` of ``f`` on ``[a, b]`` under a tolerance weight.

    ``coefficients`` are exact (high-precision) and lowest degree first;
    ``error`` is the levelled error ``|E|`` of the last exchange step and
    ``max_error`` the largest weighted error observed on the final reference
    and on the dense check grid (equal to ``error`` within ``check_tol``);
    ``reference`` holds the ``degree + 2`` points (in ``x``, ascending) where
    the weighted error equioscillates; ``iterations`` counts exchange steps.
    """

    coefficients: tuple[mpf, ...]
    error: mpf
    max_error: mpf
    reference: tuple[mpf, ...]
    iterations: int
    interval: tuple[mpf, mpf]

    @property
    def degree(self) -> int:
        return len(self.coefficients) - 1

    @property
    def highest_first(self) -> tuple[mpf, ...]:
        """The exact coefficients, highest degree first (Horner order)."""
        return self.coefficients[::-1]

    @property
    def float32(self) -> np.ndarray:
        """Coefficients rounded to binary32, lowest degree first."""
        return np.array([to_float32(c) for c in self.coefficients], dtype=np.float32)

    @property
    def float32_strings(self) -> tuple[str, ...]:
        """Shortest decimal strings that round-trip the binary32 coefficients."""
        return tuple(str(c) for c in self.float32)

    def __call__(self, x) -> mpf:
        """Evaluate the exact polynomial at ``x`` (Horner)."""
        return _horner(self.coefficients, mpf(x))


def evaluate(fn: Function, x: mpf, a: mpf, b: mpf) -> mpf:
    """``fn(x)``, or its limit from inside ``[a, b]`` if that raises or is not finite.

    The limit is probed at doubled precision at the points ``x + d`` and
    ``x + 2d``, ``|d| = (b - a) * 2**-prec``, on the interior side of ``x``.
    If both values agree to half the working precision (a removable
    singularity such as ``(2^x-1)/x`` at 0) the first is returned, otherwise
    the limit diverges (a pole or ``log(0)``) and a signed ``mp.inf`` is
    returned.  Raises :class:`RemezError` if ``fn`` cannot be evaluated there.
    """
    try:
        y = mpf(fn(x))
        if mp.isfinite(y):
            return y
    except (ArithmeticError, ValueError):
        pass
    half_eps = mpf(2) ** -(mp.prec // 2)
    with mp.workprec(2 * mp.prec):
        step = (b - a) * mpf(2) ** -(mp.prec // 2)
        step = step if x + 2 * step <= b else -step
        try:
            y1, y2 = mpf(fn(x + step)), mpf(fn(x + 2 * step))
        except (ArithmeticError, ValueError) as exc:
            reason = str(exc) or type(exc).__name__
            raise RemezError(f"cannot evaluate {fn} at or near x = {mp.nstr(x, 15)}: {reason}") from exc
        converges = mp.isfinite(y1) and abs(y1 - y2) <= half_eps * max(abs(y1), 1)
    if converges:
        return +y1
    return mp.inf if y1 > 0 else -mp.inf


def _horner(coefficients: Sequence[mpf], x: mpf) -> mpf:
    acc = mpf(0)
    for c in reversed(coefficients):
        acc = acc * x + c
    return acc


class _Problem:
    """``f``, ``|w|`` and the weighted error as functions of ``t`` in ``[-1, 1]``."""

    def __init__(self, f: Function, weight: Function | None, a: mpf, b: mpf, degree: int):
        self.f, self.weight, self.a, self.b, self.n = f, weight, a, b, degree
        self.mid, self.half = (a + b) / 2, (b - a) / 2

    def x(self, t: mpf) -> mpf:
        return self.a if t == -1 else self.b if t == 1 else self.mid + self.half * t

    def fw(self, t: mpf) -> tuple[mpf, mpf]:
        """``f(x)`` and ``|w(x)|``, evaluated with as many guard bits as working
        bits so that cancellation within ``2**-(prec/2)`` of a removable
        singularity does not reach the working precision."""
        x = self.x(t)
        with mp.workprec(2 * mp.prec):
            fx = evaluate(self.f, x, self.a, self.b)
            wx = mpf(1) if self.weight is None else abs(evaluate(self.weight, x, self.a, self.b))
        if not mp.isfinite(fx):
            raise RemezError(f"f(x) = {self.f} has a pole or non-removable singularity at x = {mp.nstr(x, 15)}")
        if wx == 0:
            raise RemezError(f"weight {self.weight} is zero at x = {mp.nstr(x, 15)}")
        return +fx, +wx

    def error(self, q: Sequence[mpf], t: mpf) -> mpf:
        fx, wx = self.fw(t)
        return (_horner(q, t) - fx) / wx

    def solve(self, nodes: Sequence[mpf], signs: Sequence[int] | None) -> tuple[list[mpf], mpf]:
        """Solve ``q(t_i) + s_i E |w(t_i)| = f(t_i)``; without signs, interpolate."""
        rows, rhs = [], []
        for i, t in enumerate(nodes):
            fx, wx = self.fw(t)
            rows.append([t**k for k in range(self.n + 1)] + ([signs[i] * wx] if signs else []))
            rhs.append(fx)
        try:
            sol = mp.lu_solve(mp.matrix(rows), mp.matrix(rhs))
        except ZeroDivisionError as exc:
            raise RemezError(f"singular reference system at t = {[mp.nstr(t, 8) for t in nodes]}") from exc
        q = [sol[k] for k in range(self.n + 1)]
        return q, (sol[self.n + 1] if signs else mpf(0))

    def zero(self, q: Sequence[mpf], lo: mpf, hi: mpf) -> mpf:
        """A sign change of the error in ``[lo, hi]`` (Illinois, bisection fallback)."""
        elo, ehi = self.error(q, lo), self.error(q, hi)
        if elo * ehi > 0:
            raise RemezError(f"lost alternation between t = {mp.nstr(lo, 8)} and {mp.nstr(hi, 8)}")
        xtol = mpf(2) ** -(mp.prec // 3)
        side = 0
        for _ in range(4 * mp.prec):
            if hi - lo <= xtol or elo == 0 or ehi == 0:
                break
            width = hi - lo
            m = hi - ehi * width / (ehi - elo) if ehi != elo else (lo + hi) / 2
            em = self.error(q, m)
            if (em > 0) == (ehi > 0):
                hi, ehi = m, em
                elo = elo / 2 if side == -1 else elo
                side = -1
            else:
                lo, elo = m, em
                ehi = ehi / 2 if side == 1 else ehi
                side = 1
            if hi - lo > width / 2:  # slow progress: bisect once
                m = (lo + hi) / 2
                em = self.error(q, m)
                lo, elo, hi, ehi = (lo, elo, m, em) if (em > 0) == (ehi > 0) else (m, em, hi, ehi)
        return lo if elo == 0 else hi if ehi == 0 else (lo + hi) / 2

    def extremum(self, q: Sequence[mpf], lo: mpf, hi: mpf, sign: int) -> tuple[mpf, mpf]:
        """``(t, sign * e(t))`` maximising ``sign * e`` (or ``|e|`` if sign is 0) on ``[lo, hi]``."""

        def g(t: mpf) -> mpf:
            e = self.error(q, t)
            return sign * e if sign else abs(e)

        ts = [lo + (hi - lo) * j / _SAMPLES for j in range(_SAMPLES + 1)]
        gs = [g(t) for t in ts]
        j = max(range(len(ts)), key=gs.__getitem__)
        t, v = _brent_max(g, ts[max(j - 1, 0)], ts[min(j + 1, _SAMPLES)])
        return (t, v) if v > gs[j] else (ts[j], gs[j])

    def extrema(self, q: Sequence[mpf], bounds: Sequence[mpf], signs: Sequence[int]) -> tuple[list, list]:
        found = [self.extremum(q, bounds[i], bounds[i + 1], signs[i]) for i in range(self.n + 2)]
        return [t for t, _ in found], [v for _, v in found]


def _brent_max(g: Function, lo: mpf, hi: mpf) -> tuple[mpf, mpf]:
    """Maximise ``g`` on ``[lo, hi]`` by Brent's method (port of fminbound)."""
    eps = mpf(2) ** -(mp.prec // 2)
    golden = (3 - mp.sqrt(5)) / 2
    xf = v = w = lo + golden * (hi - lo)
    fx = fv = fw = -g(xf)
    d = e = mpf(0)
    for _ in range(mp.prec):
        xm = (lo + hi) / 2
        tol1 = eps * (abs(xf) + 1)
        tol2 = 2 * tol1
        if abs(xf - xm) <= tol2 - (hi - lo) / 2:
            break
        parabolic = False
        if abs(e) > tol1:
            r = (xf - w) * (fx - fv)
            p = (xf - v) * (fx - fw)
            num, den = (xf - v) * p - (xf - w) * r, 2 * (p - r)
            num, den = (-num if den > 0 else num), abs(den)
            if abs(num) < abs(den * e / 2) and den * (lo - xf) < num < den * (hi - xf):
                parabolic, e, d = True, d, num / den
                if (xf + d) - lo < tol2 or hi - (xf + d) < tol2:
                    d = tol1 if xm >= xf else -tol1
        if not parabolic:
            e = (lo - xf) if xf >= xm else (hi - xf)
            d = golden * e
        u = xf + (d if abs(d) >= tol1 else (tol1 if d >= 0 else -tol1))
        fu = -g(u)
        if fu <= fx:
            lo, hi = (xf, hi) if u >= xf else (lo, xf)
            v, fv, w, fw, xf, fx = w, fw, xf, fx, u, fu
        else:
            lo, hi = (u, hi) if u < xf else (lo, u)
            if fu <= fw or w == xf:
                v, fv, w, fw = w, fw, u, fu
            elif fu <= fv or v == xf or v == w:
                v, fv = u, fu
    return xf, -fx


def _to_x_basis(q: Sequence[mpf], mid: mpf, half: mpf) -> list[mpf]:
    """Coefficients of ``q((x - mid) / half)`` in powers of ``x``."""
    lin = [-mid / half, 1 / half]
    out = [mpf(0)] * len(q)
    for c in reversed(q):
        prod = [mpf(0)] * len(q)
        for k, ok in enumerate(out[:-1]):
            prod[k] += ok * lin[0]
            prod[k + 1] += ok * lin[1]
        prod[0] += c
        out = prod
    return out


def remez(
    f: Function | str,
    a,
    b,
    degree: int,
    weight: Function | str | None = None,
    *,
    dps: int = 50,
    max_iter: int = 40,
    tol: float | None = None,
    check_tol: float = 1e-6,
) -> RemezResult:
    """Minimax polynomial of ``degree`` for ``f`` on ``[a, b]`` with tolerance ``weight``.

    ``f`` and ``weight`` are callables on ``mpf`` or expression strings (see
    :mod:`routines.remez.expr`); ``a`` and ``b`` anything ``mpf`` accepts.
    The exchange runs at ``dps`` decimal digits until the largest weighted
    error on the new reference exceeds the levelled error ``|E|`` by at most
    ``tol`` relatively (default ``10**-(dps // 2)``) or by the evaluation
    noise, whichever is larger.  The result is then checked: the weighted
    errors on the reference must alternate in sign and equal ``|E|`` within
    ``check_tol``, and no point of a dense grid may exceed
    ``|E| * (1 + check_tol)``.

    Raises :class:`RemezError` if the exchange does not converge within
    ``max_iter`` steps, if the check fails, if ``f`` has a pole on the
    interval, or if the best error is at the noise level of ``dps`` digits
    (``f`` is numerically a polynomial of this degree: lower the degree or
    raise ``dps``); :class:`ValueError` if ``degree < 0`` or ``a >= b``, and
    :class:`~routines.remez.expr.ExpressionError` for an invalid expression.
    """
    if degree < 0:
        raise ValueError(f"degree must be >= 0, got {degree}")
    f = parse(f) if isinstance(f, str) else f
    weight = parse(weight) if isinstance(weight, str) else weight
    with mp.workdps(dps):
        a, b = mpf(a), mpf(b)
        if not a < b:
            raise ValueError(f"empty interval [{a}, {b}]")
        tol = mpf(10) ** -(dps // 2) if tol is None else mpf(tol)
        prob = _Problem(f, weight, a, b, degree)
        n = degree
        # Start: interpolate at Chebyshev roots (exact 0 in the middle), then
        # take the largest |error| between consecutive roots as the reference.
        nodes = sorted(mp.sin(mp.pi * (n - 2 * k) / (2 * n + 2)) for k in range(n + 1))
        q, _ = prob.solve(nodes, None)
        ref, vals = prob.extrema(q, [mpf(-1), *nodes, mpf(1)], [0] * (n + 2))
        noise = mpf(2) ** (8 - mp.prec) * max(abs(fx / wx) for fx, wx in map(prob.fw, ref))
        if max(vals) <= 2**20 * noise:
            raise RemezError(
                f"the weighted error ({mp.nstr(max(vals), 3)}) is at the noise level of dps={dps}: "
                f"f is numerically a polynomial of degree <= {n}; lower the degree or raise dps"
            )
        for iteration in range(1, max_iter + 1):
            signs = [1 if i % 2 else -1 for i in range(n + 2)]
            q, E = prob.solve(ref, signs)
            signs = [-s if E > 0 else s for s in signs]  # sign of e at ref[i]
            zeros = [prob.zero(q, ref[i], ref[i + 1]) for i in range(n + 1)]
            new_ref, vals = prob.extrema(q, [mpf(-1), *zeros, mpf(1)], signs)
            if max(vals) - abs(E) <= tol * abs(E) + noise:
                return _checked(prob, q, abs(E), new_ref, vals, iteration, check_tol)
            ref = new_ref
        raise RemezError(
            f"no convergence after {max_iter} iterations: max weighted error {mp.nstr(max(vals), 8)} "
            f"vs levelled {mp.nstr(abs(E), 8)} (is f smooth on the interval? is the degree too high?)"
        )


def _checked(prob: _Problem, q, E: mpf, ref, vals, iterations: int, check_tol: float) -> RemezResult:
    """Verify equioscillation of the converged exchange, then build the result."""
    if min(vals) < E * (1 - check_tol) or max(vals) > E * (1 + check_tol):
        raise RemezError(
            f"weighted error at the reference does not equioscillate around |E| = {mp.nstr(E, 8)}: "
            f"{[mp.nstr(v, 8) for v in vals]}"
        )
    m = _CHECK_GRID * (prob.n + 2)
    grid_max = max(abs(prob.error(q, -mp.cos(mp.pi * j / m))) for j in range(m + 1))
    if grid_max > E * (1 + check_tol):
        raise RemezError(f"weighted error {mp.nstr(grid_max, 8)} on the check grid exceeds |E| = {mp.nstr(E, 8)}")
    return RemezResult(
        coefficients=tuple(_to_x_basis(q, prob.mid, prob.half)),
        error=E,
        max_error=max(grid_max, *vals),
        reference=tuple(prob.x(t) for t in ref),
        iterations=iterations,
        interval=(prob.a, prob.b),
    )


@dataclass(frozen=True)
class RetuneResult:
    """Outcome of :func:`retune`: the best coefficients found and their error."""

    coefficients: np.ndarray
    error: float
    initial_error: float
    evaluations: int


def retune(
    coefficients: Sequence[float],
    err: Callable[[np.ndarray], float],
    *,
    max_evals: int = 2000,
    max_ulps: int = 64,
) -> RetuneResult:
    """Nudge binary32 coefficients by ulp steps to minimise ``err(coefficients)``.

    Greedy coordinate descent: for each coefficient in turn, keep stepping one
    ulp in a direction while ``err`` strictly decreases; repeat sweeps until a
    sweep improves nothing, ``max_evals`` calls were made, or moves would
    leave ``max_ulps`` ulps of the start.  ``err`` receives a fresh float32
    array in the caller's order and must be deterministic.
    """
    best = np.array(coefficients, dtype=np.float32)
    offsets = np.zeros(len(best), dtype=np.int64)
    best_err = initial = float(err(best.copy()))
    evals, improved = 1, True
    while improved and evals < max_evals:
        improved = False
        for i in range(len(best)):
            for step in (1, -1):
                while evals < max_evals and abs(offsets[i] + step) <= max_ulps:
                    cand = best.copy()
                    cand[i] = np.nextafter(best[i], np.float32(step * np.inf))
                    e = float(err(cand.copy()))
                    evals += 1
                    if not e < best_err:
                        break
                    best, best_err, improved = cand, e, True
                    offsets[i] += step
    return RetuneResult(best, best_err, initial, evals)
