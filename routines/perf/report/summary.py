"""The report in one screen: per function, our tiers' time and error beside NumPy's and the
fastest peer's; which peers a tier of ours dominates; the absent peers in one line; each target
met or missed in words. ``print_table`` (``--verbose``) has every variant, peer and model gap.

Contract: :func:`summary` renders a report dict (or its JSON) as text and returns it."""
from __future__ import annotations

import collections

from .jsonsafe import as_float as _f
from .speed import ns_per_element as _ns

TIERS = ("relaxed", "full", "faithful", "correct")


def _cell(ns, ulp) -> str:
    """``0.12 (0.89)``: ns per element and max ULP-32, rounded for reading."""
    if ns is None or ns != ns:
        return "-"
    return f"{ns:.2f} ({ulp:.2g})" if ulp == ulp else f"{ns:.2f}"


def _ours(report, func: str) -> dict[str, str]:
    """Tier -> cell: the ladder's points (same timing run as its peers) where the function has
    them, else the widest FMA variant of each tier at the L2 size."""
    cells = {p["label"]: _cell(_f(p["ns"]), _f(p["max_ulp"])) for p in report.get("ladder", [])
             if p["family"] == "ours" and p["func"] == func and p["present"]}
    if cells:
        return cells
    variants = [v for v in report["variants"] if v["func"] == func and v["fma"]]
    for tier in TIERS:
        rows = sorted((v for v in variants if v["precision"] == tier), key=lambda v: -v["width"])
        if rows:
            acc = rows[0].get("accuracy") or {}
            cells[tier] = _cell(_ns(rows[0], "L2"), _f(acc.get("max_ulp32", float("nan"))))
    return cells


def _peers(report, func: str) -> tuple[str, str]:
    """(NumPy's cell, the fastest other present peer's ``name cell``) at the L2 size."""
    present = [p for p in report["peers"] if p["func"] == func and p["present"] and _ns(p, "L2") is not None]

    def ulp(p):
        return _f(((p.get("accuracy") or {}).get("full") or {}).get("max_ulp32", float("nan")))
    numpy = next((_cell(_ns(p, "L2"), ulp(p)) for p in present if p["family"] == "numpy"), "-")
    others = sorted((p for p in present if p["family"] != "numpy"), key=lambda p: _ns(p, "L2"))
    fastest = f"{others[0]['family']} {_cell(_ns(others[0], 'L2'), ulp(others[0]))}" if others else "-"
    return numpy, fastest


def _dominance(report) -> list[str]:
    """The ladder's verdict in two lines: how many present peers are dominated, which are not."""
    peers = [p for p in report.get("ladder", []) if p["family"] != "ours" and p["present"]]
    if not peers:
        return []
    free = [p["key"] for p in peers if not p["dominated_by"]]
    line = (f"Peers dominated by a tier of ours (no slower, no less accurate): {len(peers) - len(free)} of "
            f"{len(peers)} present")
    return [line + (f"; not: {', '.join(free)}" if free else "")]


def _absent(report) -> list[str]:
    """The absent peers in one line, grouped by why."""
    why: collections.Counter = collections.Counter(p["reason"] for p in report["peers"] if not p["present"])
    if not why:
        return []
    total = sum(why.values())
    if len(why) == 1:
        return [f"Absent: {total} peer variant{'s' * (total > 1)}: {next(iter(why))}"]
    return [f"Absent: {total} peer variants (" + "; ".join(f"{n}: {reason}" for reason, n in why.most_common()) + ")"]


def _targets(report) -> list[str]:
    """One line per target: met or missed, in words, with the ratio rounded."""
    lines = ["Targets (same-run ratios):"]
    for t in report["targets"]:
        ratio = _f(t["ratio"]) if t["ratio"] is not None else None
        figure = f": {ratio:.2f}x, needs {_f(t['required']):.2f}x" if ratio is not None else ""
        lines.append(f"  {t['status']}: {t['target']}{figure}")
    return lines


def summary(report) -> str:
    """The one-screen report (see the module docstring)."""
    m = report["machine"]
    sizes = report["settings"]["sizes"]
    lines = [f"routines report on {m.get('llvm_cpu')} ({m.get('cpus')} CPUs), {_f(report['clock']['ghz']):.2f} GHz; "
             f"one thread, {sizes.get('L2', 65536):,} float32 per call; FMA on, widest vectors",
             "ns per element (max ULP-32 on the accuracy sample); peers: NumPy's, and the fastest other one", ""]
    head = f"{'function':9}" + "".join(f"{t:16}" for t in TIERS) + f"{'NumPy':16}fastest other peer"
    lines += [head, "-" * len(head)]
    for func in report["settings"]["functions"]:
        ours = _ours(report, func)
        numpy, fastest = _peers(report, func)
        lines.append(f"{func:9}" + "".join(f"{ours.get(t, '-'):16}" for t in TIERS) + f"{numpy:16}{fastest}")
    lines += ["", "relaxed and full are Vulkan's mediump and highp: judged against Vulkan's bounds, which allow large "
              "ULP figures (pow's follows", "exp2(y log2 x)); faithful is below 1 ULP, correct is correctly rounded. "
              "A tier is chosen by routines.jit(name, precision=...).", ""]
    lines += _dominance(report) + _absent(report) + [""] + _targets(report)
    took = report["seconds"].get("total")
    lines += ["", "Every variant, peer and model gap: --verbose" + (f". Took {_f(took):.0f} s." if took else ".")]
    return "\n".join(lines)
