"""The chart's points: a report's variants and peers, and the search's candidates.

Contract: :func:`chart_panels` turns a report dict (or its JSON) into
function -> points for :func:`routines.perf.chart.draw`; :func:`search_points`
reads the variant search's JSON files. Neither draws anything, so neither
needs matplotlib.
"""
from __future__ import annotations

import os

from .jsonsafe import as_float as _f
from .speed import cycles_per_element as _cy


def search_points(search_dir: str, ghz: float) -> dict[str, list[dict]]:
    """The variant search's full-precision Pareto candidates (``python -m routines search
    ... --json out/search/F_full.json``) as margin-chart points: x = their measured
    ns/element at this run's clock, y = their max margin against the highp tolerance."""
    import glob
    import json
    panels: dict[str, list[dict]] = {}
    for path in sorted(glob.glob(os.path.join(search_dir, "*_full.json"))):
        with open(path) as f:
            points = json.load(f)
        for p in points:
            if p.get("pareto") and p.get("admissible") and p.get("ns_per_element") and not p["candidate"].get("production"):
                panels.setdefault(p["function"], []).append({
                    "x": p["ns_per_element"] * ghz, "y": _f(p["max_margin"]),
                    "label": "search " + p["name"].split(".", 2)[-1], "family": "search",
                    "width": 16, "fma": p["fma"], "conforming": p["conforming"]})
    return panels


def chart_panels(report, error: str = "ulp", size: str = "L2", search_dir: str | None = None) -> dict[str, list[dict]]:
    """Points for :func:`routines.perf.chart.draw`, per function.

    ``error="ulp"``: max ULP-32; ``"margin"``: max margin against the *full*
    (highp) tolerance for every point (relaxed variants measured on the sample
    for this), so that one axis serves all. Non-conforming: ours against their
    own precision, peers meeting neither tolerance. With ``search_dir`` the margin
    chart also shows the variant search's full-precision Pareto candidates."""
    panels: dict[str, list[dict]] = {f: [] for f in report["settings"]["functions"]}
    for v in report["variants"]:
        a = v.get("accuracy")
        if not a:
            continue
        y = _f(a["max_ulp32"]) if error == "ulp" else _f(a["full_margin"])
        label = f"{v['precision'][0]}{'' if v['fma'] else ' nofma'} w{v['width']}"
        panels[v["func"]].append({"x": _cy(v, size), "y": y, "label": label, "family": v["family"],
                                  "width": v["width"], "fma": v["fma"], "conforming": a["conforming"]})
    for p in report["peers"]:
        a = p.get("accuracy")
        if not p["present"] or not a:
            continue
        full = a["full"]
        y = _f(full["max_ulp32"]) if error == "ulp" else _f(full["max_margin"])
        short = p["key"].replace(f" {p['func']}", "").replace("numpy", "np")
        panels[p["func"]].append({"x": _cy(p, size), "y": y, "label": short, "family": p["family"],
                                  "width": None, "fma": None,
                                  "conforming": a["verdict"]["class"] != "neither"})
    if search_dir and error == "margin":
        for func, points in search_points(search_dir, report["clock"]["ghz"]).items():
            if func in panels:
                panels[func] += points
    return panels
