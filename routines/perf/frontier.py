"""The accuracy ladder beside its peers: every tier of ours and every peer is a point
(time per element, max ULP-32), and each peer is either dominated by one of our points (at
most its time and at most its error) or not.

Time: 64K float32 operands of ``timing.inputs`` (exp/exp2 in [-10, 10], logs in [1e-3, 100],
pow x in [1e-3, 100] and y in [-10, 10], sin, cos, tan, atan and the hyperbolic functions in
[-10, 10], asin and acos in [-1, 1], atan2's operands in [-10, 10]), one thread, every candidate called in turn in each
of ``rounds`` rounds (same-run ratios on a shared machine), the median kept.
Error: ``routines.lab.rounding.score`` on a sample of every binade: every 4099th float32 bit
pattern (1,047,811 inputs), and for pow and atan2 their hard pairs plus every 16th stratum of
the 2^30 sweep thinned to every 16th x (1M pairs); the max ULP-32 is taken over finite results (the
specials are counted apart as results not correctly rounded). The exhaustive figures of our
faithful and correct tiers come from ``python -m routines ladder --exhaustive``.
"""
from __future__ import annotations

import dataclasses
import statistics
import time

import numpy as np

FUNCS = ("exp2", "exp", "log2", "log", "pow", "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh",
         "tanh")
N = 1 << 16
SAMPLE_STRIDE = 4099


@dataclasses.dataclass
class Point:
    key: str
    func: str
    family: str           # "ours" or the peer's family
    label: str
    claimed: str = ""
    ns: float = float("nan")
    max_ulp: float = float("nan")
    misrounded: int = 0
    inputs: int = 0
    present: bool = True
    reason: str = ""
    dominated_by: str | None = None

    @property
    def ours(self) -> bool:
        return self.family == "ours"


def sample(func: str) -> tuple[np.ndarray, np.ndarray | None]:
    """The accuracy sample's operand bit patterns (see the module docstring)."""
    if func not in ("pow", "atan2"):
        return np.arange(0, 2 ** 32, SAMPLE_STRIDE, dtype=np.uint64).astype(np.uint32), None
    from ..lab.pairs import atan2_strata, x_stratum, y_strata
    from ..lab.rounding import atan2_hard_cases, pow_hard_cases
    hard = pow_hard_cases() if func == "pow" else atan2_hard_cases()
    xs, ys = [hard[0]], [hard[1]]
    for k, y in list(enumerate(y_strata(0) if func == "pow" else atan2_strata(0)))[::16]:
        x = x_stratum(k, 0)[::16]
        xs.append(x)
        ys.append(np.full(x.size, y, np.uint32))
    return np.concatenate(xs), np.concatenate(ys)


def candidates(functions=FUNCS, fma: bool | None = None, target: str | None = None) -> list[tuple[Point, object]]:
    """(point, callable ``fn(*args, out=)``) for our tiers (built for ``target``, None: this CPU)
    and every peer, absent ones included."""
    from .. import jit
    from ..base import tiers
    from . import peers as peer_mod
    out = []
    for func in functions:
        for tier in tiers(func):
            out.append((Point(f"ours {func} {tier}", func, "ours", tier), jit(func, tier, fma=fma, target=target)))
        for p in peer_mod.peers([func], families=("numpy", "libmvec", "sleef", "svml")):
            pt = Point(p.key, func, p.family, p.label, p.claimed, present=p.present, reason=p.reason)
            out.append((pt, p.fn))
    return out


def measure_accuracy(points: list[tuple[Point, object]]) -> None:
    from ..lab.rounding import score
    from .peers import as_array_function
    samples = {}
    for pt, fn in points:
        if not pt.present:
            continue
        if pt.func not in samples:
            samples[pt.func] = sample(pt.func)
        x, y = samples[pt.func]
        r = score(as_array_function(fn), pt.func, pt.label, x, y)
        pt.max_ulp, pt.misrounded, pt.inputs = r.max_ulp, r.misrounded, r.inputs


def measure_time(points: list[tuple[Point, object]], rounds: int = 21, calls: int = 5) -> None:
    """Time every present point on one thread (ours too: a 64K call would otherwise be split
    across the pool's threads, while its peers run on one)."""
    import reactor
    saved = reactor.thread_settings()
    reactor.configure_threads(threads=1)
    try:
        _measure_time(points, rounds, calls)
    finally:
        reactor.configure_threads(threads=saved[0], threshold=saved[1])


def _measure_time(points: list[tuple[Point, object]], rounds: int, calls: int) -> None:
    from .timing import inputs
    live = [(pt, fn) for pt, fn in points if pt.present]
    args = {f: inputs(f, N) for f in {pt.func for pt, _ in live}}
    out = np.empty(N, np.float32)
    times: dict[str, list[float]] = {pt.key: [] for pt, _ in live}
    for _ in range(rounds):
        for pt, fn in live:
            a = args[pt.func]
            fn(*a, out=out)
            t0 = time.perf_counter()
            for _ in range(calls):
                fn(*a, out=out)
            times[pt.key].append((time.perf_counter() - t0) / calls / N * 1e9)
    for pt, _ in live:
        pt.ns = statistics.median(times[pt.key])


def dominance(points: list[Point]) -> None:
    """Mark each peer with the cheapest of our points that is at most its time and error."""
    for p in points:
        if p.ours or not p.present:
            continue
        better = [o for o in points if o.ours and o.func == p.func and o.ns <= p.ns and o.max_ulp <= p.max_ulp]
        p.dominated_by = min(better, key=lambda o: o.ns).label if better else None


def run(functions=FUNCS, rounds: int = 21, target: str | None = None) -> list[Point]:
    """Every point of ``functions`` (those of :data:`FUNCS`), measured, peers marked."""
    pairs = candidates([f for f in functions if f in FUNCS], target=target)
    measure_accuracy(pairs)
    measure_time(pairs, rounds)
    points = [pt for pt, _ in pairs]
    dominance(points)
    return points


def statements(points: list[Point]) -> list[str]:
    """One line per peer: dominated by which of our points, or not (and why not)."""
    out = []
    for p in points:
        if p.ours:
            continue
        if not p.present:
            out.append(f"{p.key}: absent ({p.reason})")
            continue
        head = f"{p.key} ({p.max_ulp:.3g} ULP, {p.ns:.3f} ns)"
        if p.dominated_by:
            o = next(o for o in points if o.ours and o.func == p.func and o.label == p.dominated_by)
            out.append(f"{head}: dominated by ours {o.label} ({o.max_ulp:.3g} ULP, {o.ns:.3f} ns)")
            continue
        ours = [o for o in points if o.ours and o.func == p.func and o.present]
        as_good = [o for o in ours if o.max_ulp <= p.max_ulp]
        why = (f"ours {min(as_good, key=lambda o: o.ns).label} is as accurate "
               f"({min(as_good, key=lambda o: o.ns).max_ulp:.3g} ULP) but takes "
               f"{min(o.ns for o in as_good) / p.ns:.2f}x its time") if as_good else "no point of ours is as accurate"
        out.append(f"{head}: NOT dominated: {why}")
    return out


def to_json(points: list[Point]) -> list[dict]:
    return [dataclasses.asdict(p) for p in points]


def from_json(rows: list[dict]) -> list[Point]:
    return [Point(**r) for r in rows]


def table(points: list[Point]) -> str:
    lines = ["| function | point | ns/element | max ULP-32 | not correctly rounded | dominated by |",
             "|---|---|---|---|---|---|"]
    for p in points:
        if not p.present:
            lines.append(f"| {p.func} | {p.key} | absent: {p.reason} | | | |")
            continue
        dom = "" if p.ours else (f"ours {p.dominated_by}" if p.dominated_by else "**not dominated**")
        lines.append(f"| {p.func} | {p.key} | {p.ns:.3f} | {p.max_ulp:.3f} | {p.misrounded:,d} of {p.inputs:,d} "
                     f"| {dom} |")
    return "\n".join(lines)


def chart(points: list[Point], path: str) -> None:
    """Per function: time against max ULP-32 (log scales), our ladder joined in blue, each peer a
    red marker of its family, hollow where one of our points dominates it, filled where none does."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter
    funcs = list(dict.fromkeys(p.func for p in points))
    cols = min(3, len(funcs))
    rows = (len(funcs) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(5.2 * cols, 4.4 * rows), squeeze=False)
    markers = {"numpy": "s", "libmvec": "^", "sleef": "v", "svml": "D"}
    for ax, func in zip(axes.flat, funcs):
        ours = sorted((p for p in points if p.ours and p.func == func and p.present), key=lambda p: p.max_ulp)
        ax.plot([p.ns for p in ours], [max(p.max_ulp, 0.4) for p in ours], "o-", color="C0", label="ours")
        for p in ours:
            ax.annotate(p.label, (p.ns, max(p.max_ulp, 0.4)), fontsize=7, xytext=(3, 3), textcoords="offset points")
        for fam, m in markers.items():
            ps = [p for p in points if p.family == fam and p.func == func and p.present]
            for i, p in enumerate(ps):
                ax.scatter([p.ns], [max(p.max_ulp, 0.4)], marker=m, color="C3", label=fam if i == 0 else None,
                           facecolors="none" if p.dominated_by else "C3")
                name = p.key.split()[-1] if fam in ("sleef", "svml") else fam
                ax.annotate(name, (p.ns, max(p.max_ulp, 0.4)), fontsize=6, xytext=(3, -8),
                            textcoords="offset points", color="C3")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_title(f"{func} (hollow: dominated by one of our points)", fontsize=9)
        ax.set_xlabel("ns per element (64K float32, one thread)")
        ax.set_ylabel("max ULP-32 (sample)")
        ax.axhline(1.0, color="grey", lw=0.5, ls=":")
        ax.legend(fontsize=6)
    for ax in list(axes.flat)[len(funcs):]:
        ax.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
