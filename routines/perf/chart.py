"""The cost/error chart: one panel per function, every variant and peer.

x = cost in cycles per element (L2-resident size, one thread), y = error
(max ULP-32 on a log scale, or the max margin = error / the full (highp)
tolerance, so 1 is the highp limit). Lower-left is better. On every panel:

* the **Pareto frontier** (dashed): the points no other point beats on both
  axes (another point with cost <= and error <=, one of them strictly);
* its **lower convex hull** (solid): the frontier points that minimise
  ``w1 * cost + w2 * error`` for some weights ``w1, w2 >= 0`` -- sliding a
  straightedge of any non-positive slope up from the lower left, these are the
  points it can touch first (shared/refs/003, "The pareto frontier"). A
  frontier point above the hull is efficient, but never the best trade at any
  fixed exchange rate. With a log error axis the hull is taken in the
  chart's coordinates (cost, log10 error): a straight segment is a constant
  exchange rate between cycles and orders of magnitude of error.
  Points exactly on a hull segment (collinear) are not hull vertices;
* FMA-off variants are drawn with a light fill, marker size is the SIMD width;
* a point far to the right of the others (more than ``FAR`` times the median
  cost of its panel, e.g. numba's scalar loops at 30-90 cycles/element beside
  vector code at 1-3) would squeeze the rest into the left edge: the axis ends
  after the other points (:func:`x_limit`) and the far point is drawn at the
  right edge as a ``>`` with its label and cost; the frontier and hull still
  include it;
* **non-conforming** points (ours: against their own precision's tolerance,
  special values included; peers: meeting neither the full nor the relaxed
  tolerance) are drawn hollow with a red cross.

Uses matplotlib's Agg backend (no display needed); writes PNG and SVG.
matplotlib is optional (``pip install "reactor-simd[plot]"``) and imported only
inside :func:`draw`: the frontier functions and :func:`missing_matplotlib`
work without it.
"""
from __future__ import annotations

import math
import os
from typing import Sequence

FLOOR = 1e-3  # smallest error drawn on a log axis (an exact result has error 0)
INSTALL = 'pip install "reactor-simd[plot]"'  # how to get matplotlib, for the chart


def missing_matplotlib() -> str | None:
    """None if matplotlib can be imported (:func:`draw` will work), else one line
    saying that the chart needs it and how to install it."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return f"no chart: it needs matplotlib, which is not installed ({INSTALL})"
    return None


def pareto_front(points: Sequence[tuple[float, float]]) -> list[int]:
    """Indices of the Pareto-efficient points (minimising both coordinates),
    in increasing x. Of identical points only the first is kept; points with
    a NaN coordinate are never efficient."""
    idx = [i for i, (x, y) in enumerate(points) if not (math.isnan(x) or math.isnan(y))]
    idx.sort(key=lambda i: (points[i][0], points[i][1], i))
    front, best_y = [], math.inf
    for i in idx:
        if points[i][1] < best_y:
            front.append(i)
            best_y = points[i][1]
    return front


def _cross(o, a, b) -> float:
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def lower_hull(points: Sequence[tuple[float, float]], front: Sequence[int] | None = None) -> list[int]:
    """Indices of the vertices of the lower-left convex hull of the Pareto
    frontier (``front``, computed if not given), in increasing x: Andrew's
    monotone chain over the frontier, which runs from the cheapest point to
    the most accurate one."""
    front = pareto_front(points) if front is None else list(front)
    hull: list[int] = []
    for i in front:
        while len(hull) >= 2 and _cross(points[hull[-2]], points[hull[-1]], points[i]) <= 0:
            hull.pop()
        hull.append(i)
    return hull


def _coords(p, log_y: bool) -> tuple[float, float]:
    y = max(p["y"], FLOOR) if log_y else p["y"]
    return (p["x"], math.log10(y) if log_y else y)


def frontier(points: list[dict], log_y: bool = True) -> tuple[list[int], list[int]]:
    """(Pareto indices, hull indices) of chart points ``{"x", "y", ...}``, in the
    chart's coordinates (log10 of the error when ``log_y``)."""
    xy = [_coords(p, log_y) for p in points]
    front = pareto_front(xy)
    return front, lower_hull(xy, front)


FAR = 6.0  # a point beyond FAR x the panel's median cost is drawn at the right edge


def x_limit(xs: Sequence[float]) -> float | None:
    """The right end of a panel's cost axis: None (matplotlib's own) unless some cost is
    more than ``FAR`` times the median, then 1.1 x the largest of the others."""
    xs = sorted(x for x in xs if math.isfinite(x))
    if len(xs) < 3 or xs[len(xs) // 2] <= 0:
        return None
    near = [x for x in xs if x <= FAR * xs[len(xs) // 2]]
    return 1.1 * near[-1] if len(near) < len(xs) else None


STYLE = {  # family -> (marker, colour)
    "ours full": ("o", "#1f77b4"), "ours relaxed": ("^", "#ff7f0e"), "numpy": ("s", "#2ca02c"),
    "libmvec": ("D", "#9467bd"), "sleef": ("P", "#8c564b"), "svml": ("v", "#bcbd22"), "numba": ("X", "#e377c2"),
    "search": ("*", "#17becf"),
}
SIZE = {4: 22, 8: 38, 16: 60, None: 50}


def draw(panels: dict[str, list[dict]], path_base: str, *, error: str = "ulp", title: str = "",
         log_y: bool = True) -> list[str]:
    """Draw one panel per function and write ``path_base``.png and .svg.

    ``panels``: function -> points, each ``{"x": cycles/element, "y": error,
    "label": str, "family": one of STYLE, "width": 4/8/16/None, "fma": bool/None,
    "conforming": bool}``. Returns the written paths.
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import to_rgba
    from matplotlib.lines import Line2D

    names = [f for f, pts in panels.items() if pts]
    ncols = min(4, max(1, len(names)))
    nrows = max(1, -(-len(names) // ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.6 * ncols, 4.0 * nrows), squeeze=False)
    ylabel = "max error, ULP-32 (log)" if error == "ulp" else "max margin vs the highp tolerance (log)"
    for ax in axes.flat[len(names):]:
        ax.set_visible(False)
    for ax, func in zip(axes.flat, names):
        pts = [p for p in panels[func] if p["x"] is not None and p["y"] is not None
               and math.isfinite(p["x"]) and not math.isnan(p["y"])]
        front, hull = frontier(pts, log_y)
        xlim = x_limit([p["x"] for p in pts])
        for p in pts:
            marker, colour = STYLE.get(p["family"], ("o", "gray"))
            y = max(p["y"], FLOOR) if log_y else p["y"]
            if xlim is not None and p["x"] > xlim:  # far right: at the edge, with its cost
                ax.scatter([xlim], [y], marker=">", s=50, color=colour, zorder=3, clip_on=False)
                ax.annotate(f"{p['label']} {p['x']:.0f} c/e", (xlim, y), textcoords="offset points",
                            xytext=(-4, 5), ha="right", fontsize=6.5, color=colour, zorder=5)
                continue
            hollow = not p.get("conforming", True)
            face = "none" if hollow else to_rgba(colour, 0.3 if p.get("fma") is False else 1.0)
            ax.scatter([p["x"]], [y], marker=marker, s=SIZE.get(p.get("width"), 50),
                       facecolors=face, edgecolors=colour, linewidths=1.2, zorder=3)
            if hollow:
                ax.scatter([p["x"]], [y], marker="x", s=SIZE.get(p.get("width"), 50) * 0.8,
                           color="red", linewidths=1.2, zorder=4)
        if front:
            fx = [pts[i]["x"] for i in front]
            fy = [max(pts[i]["y"], FLOOR) if log_y else pts[i]["y"] for i in front]
            ax.step(fx, fy, where="post", ls="--", color="gray", lw=1, zorder=2)
            for i in front:
                p = pts[i]
                if xlim is not None and p["x"] > xlim:
                    continue  # labelled at the edge
                ax.annotate(p["label"], (p["x"], max(p["y"], FLOOR) if log_y else p["y"]),
                            textcoords="offset points", xytext=(4, 4), fontsize=6.5, zorder=5)
        if len(hull) >= 1:
            hx = [pts[i]["x"] for i in hull]
            hy = [max(pts[i]["y"], FLOOR) if log_y else pts[i]["y"] for i in hull]
            ax.plot(hx, hy, "-", color="#2ca02c", lw=2, alpha=0.6, zorder=2.5)
        if error == "margin":
            ax.axhline(1.0, color="red", lw=0.8, ls=":", zorder=1)
            ax.text(0.99, 1.0, "highp limit", color="red", fontsize=7, ha="right", va="bottom",
                    transform=ax.get_yaxis_transform())
        if log_y:
            ax.set_yscale("log")
        ax.set_title(func)
        ax.set_xlabel("cycles / element (L2-resident, 1 thread)")
        ax.set_ylabel(ylabel)
        ax.grid(True, which="major", alpha=0.3)
        ax.set_xlim(left=0, right=xlim)
    legend = [Line2D([], [], marker=m, color=c, ls="", label=f) for f, (m, c) in STYLE.items()]
    legend += [Line2D([], [], marker="o", color="#1f77b4", markerfacecolor=to_rgba("#1f77b4", 0.3),
                      ls="", label="FMA off (light)"),
               Line2D([], [], marker="x", color="red", ls="", label="non-conforming"),
               Line2D([], [], ls="--", color="gray", label="Pareto frontier"),
               Line2D([], [], ls="-", color="#2ca02c", lw=2, label="lower convex hull")]
    fig.legend(handles=legend, loc="lower center", ncol=min(10, len(legend)), fontsize=8,
               frameon=False)
    fig.suptitle(title or "cost vs error (marker size: SIMD width 4/8/16)", fontsize=11)
    fig.tight_layout(rect=(0, 0.05, 1, 0.97))
    paths = []
    os.makedirs(os.path.dirname(os.path.abspath(path_base)), exist_ok=True)
    for ext in ("png", "svg"):
        path = f"{path_base}.{ext}"
        fig.savefig(path, dpi=130 if ext == "png" else None)
        paths.append(path)
    plt.close(fig)
    return paths
