"""The text table of a report.

Contract: :func:`print_table` renders a report dict (or its JSON) as text and
returns it (it prints nothing, despite its name): per function our variants,
the peers and the floors, then where each variant spends, the targets and the
run time.
"""
from __future__ import annotations

import math

from .jsonsafe import as_float as _f
from .speed import cycles_per_element as _cy, ns_per_element as _ns


def _fmt(v, spec=".3f", none="-"):
    v = _f(v) if isinstance(v, str) else v
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return none
    return format(v, spec)


def _acc_cols(acc: dict | None, precision: str):
    if not acc:
        return "-", "-", "-"
    ulp = _f(acc["max_ulp32"])
    return (_fmt(ulp, ".3g"), _fmt(_f(acc["max_margin"]), ".3f"),
            "yes" if acc["conforming"] else ("NO" if acc["nonconforming"] else "specials"))


def print_table(report, size: str = "L2") -> str:
    """The results table (our variants and the peers, per function) and notes."""
    sizes = report["settings"]["sizes"]
    big = [s for s, n in sizes.items() if n >= 2 ** 24]
    has_l1 = "L1" in sizes
    ghz = report["clock"]["ghz"]
    lines = [f"clock {ghz:.3f} GHz (FMA chain, start {report['clock']['start']['ghz']:.3f} / end "
             f"{report['clock']['end']['ghz']:.3f}); sizes "
             + ", ".join(f"{s} {n}" for s, n in sizes.items())
             + "; load by other processes (CPUs): "
             + ", ".join(f"{s} {d['other_cpus']}" for s, d in report["load"].items())
             + "\nmachine during the run (probes): "
             + ", ".join(f"{s} FP pipes {d['pipe_factor']:.2f} of nominal, FP window {d['window']:.0f} ops"
                         for s, d in report.get("machine_state", {}).items())]
    head = (f"{'function':8} {'variant':24} " + (f"{'L1 c/e':>7} " if has_l1 else "")
            + f"{size + ' ns/e':>8} {size + ' c/e':>7} {'model':>6} {'ratio':>6} "
            + (f"{big[0] + ' ns/e':>10} {'2T':>6} " if big else "")
            + f"{'max ULP32':>9} {'margin':>7} {'ok':>5}")
    lines += ["", head, "-" * len(head)]
    for func in report["settings"]["functions"]:
        rows = [v for v in report["variants"] if v["func"] == func]
        rows += [p for p in report["peers"] if p["func"] == func]
        rows += [f for f in report["floors"] if f["func"] == func]
        for e in rows:
            if e["kind"] == "ours":
                name = f"{e['precision']} {'fma' if e['fma'] else 'nofma'} w{e['width']}"
                model = e["model"]["cycles_per_element"]
                ratio = _cy(e, size) / model
                acc = _acc_cols(e.get("accuracy"), e["precision"])
            elif e["kind"] == "peer":
                name = f"{e['family']}:{e['label']}"[:24]
                model = ratio = None
                a = e.get("accuracy")
                if a:
                    full = a["full"]
                    verdict = a["verdict"]
                    acc = (_fmt(_f(full["max_ulp32"]), ".3g"), _fmt(_f(full["max_margin"]), ".3f"),
                           verdict["class"] + ("*" if verdict["special_mismatches"] else ""))
                else:
                    acc = ("absent", "", "") if not e["present"] else ("-", "-", "-")
            else:
                name, model, ratio, acc = e["key"], None, None, ("", "", "")
            if e["kind"] == "peer" and not e["present"]:
                lines.append(f"{func:8} {name:24} absent: {e['reason']}")
                continue
            cells = [f"{func:8}", f"{name:24}"]
            if has_l1:
                cells.append(f"{_fmt(_cy(e, 'L1'), '.3f'):>7}")
            cells += [f"{_fmt(_ns(e, size), '.3f'):>8}", f"{_fmt(_cy(e, size), '.3f'):>7}",
                      f"{_fmt(model, '.3f'):>6}", f"{_fmt(ratio, '.2f'):>6}"]
            if big:
                cells += [f"{_fmt(_ns(e, big[0]), '.3f'):>10}", f"{_fmt(_ns(e, big[0], '2'), '.3f'):>6}"]
            cells += [f"{acc[0]:>9}", f"{acc[1]:>7}", f"{acc[2]:>5}"]
            lines.append(" ".join(cells))
        lines.append("")
    lines.append(f"c/e = cycles/element, ns/e = ns/element (best round, one thread; 2T: two threads). "
                 f"model = dataflow throughput bound (c/e), ratio = measured/model at {size}. margin = "
                 f"max error / tolerance (ours: own precision; peers: full). ok: ours against their own "
                 f"precision's tolerance (specials = only special-value mismatches); peers: the tolerance "
                 f"class met (highp/relaxed/neither), * = special-value mismatches (C99 semantics).")
    tables = sorted({g["model"] for v in report["variants"] for g in v.get("gap", {}).values() if "model" in g})
    lines += ["", f"Where each variant spends ({', '.join(tables) or 'model'}, {size}):"]
    for v in report["variants"]:
        m, g = v["model"], v.get("gap", {}).get(size, {})
        lines.append(f"  {v['key']:26} {m['cycles_per_vector']:5.1f} c/v {m['bottleneck']}; window "
                     f"{g.get('window_cycles_per_vector', m['window_cycles_per_vector']):.1f} c/v; "
                     f"cp {m['critical_path']:.0f}; "
                     f"measured {g.get('measured_cycles_per_vector', float('nan')):.1f} c/v: "
                     f"{g.get('status', '-')}" + (f" ({g['why']})" if g.get("why") else ""))
    lines += ["", "Targets (same-run ratios, L2 size, one thread):"]
    for t in report["targets"]:
        r = t["ratio"]
        lines.append(f"  [{t['status']:>7}] {t['target']}"
                     + (f": {_f(r):.2f}x (need {_f(t['required']):.2f}x)" if r is not None else "")
                     + (f" -- {t['detail']}" if t["detail"] else ""))
    lines.append("")
    lines.append("run time: " + ", ".join(f"{k} {v} s" for k, v in report["seconds"].items()))
    return "\n".join(lines)
