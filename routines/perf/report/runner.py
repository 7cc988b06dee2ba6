"""The whole run: build, measure accuracy, time, and gather one report dict.

Contract: :func:`run` builds every variant, peer, floor and probe, measures
accuracy then speed (the clock calibrated before and after the timing, the
timings rescaled to the mean), attaches the gap verdicts and the targets, and
returns the report dict (JSON-ready after :func:`~routines.perf.report.jsonsafe.to_json`;
ufuncs and callables are left out of it). It writes no file and draws nothing.
"""
from __future__ import annotations

import datetime
import os
import platform
import sys
import time

import numpy as np

import reactor

from .. import clock, peers as peers_mod, timing
from .accuracy import measure_accuracy
from .bounds import attach_gaps
from .probes import floor_kernels, machine_state, probe_kernels
from .speed import measure_speed, rescale as _rescale
from .targets import check_targets
from .variants import DEFAULT_FUNCTIONS, PRECISIONS, WIDTHS, build_variants


def run(functions=DEFAULT_FUNCTIONS, *, sizes=None, rounds=None, samples=2 ** 20, exhaustive=False,
        exhaustive_peers=False, threads2=True, progress=True, libraries=None, calibrate_ops=None,
        scheduler=None) -> dict:
    """Measure everything; returns the report dict (JSON-ready after ``to_json``).

    ``sizes``: name -> elements (default :data:`timing.SIZES`); ``rounds``:
    name -> rounds (default 61 at the cache sizes, 9 at DRAM); ``libraries``:
    override peer library names (tests)."""
    from tqdm import tqdm

    t_start = time.perf_counter()
    functions = tuple(functions)
    sizes = dict(timing.SIZES if sizes is None else sizes)
    rounds = {s: (rounds or {}).get(s, 9 if n >= 2 ** 22 else 61) for s, n in sizes.items()}
    bar = lambda total, desc: tqdm(total=total, desc=desc, file=sys.stderr,
                                   disable=None if progress else True,  # None: only on a terminal
                                   leave=False)
    cal_kw = {} if calibrate_ops is None else {"ops": calibrate_ops}
    cal0 = clock.calibrate(**cal_kw)
    phases = {}

    t = time.perf_counter()
    with bar(len(functions) * len(PRECISIONS) * 2 * len(WIDTHS), "build + model") as b:
        variants = build_variants(functions, b)
    peer_objs = peers_mod.peers(functions, libraries)
    peer_list = [p.to_json() | {"kind": "peer", "fn": p.fn, "present": p.present,
                                "reactor": p.family in ("libmvec", "sleef"), "width": peers_mod.vector_level()[0]
                                if p.family in ("libmvec", "sleef") else None} for p in peer_objs]
    floors = floor_kernels(functions)
    probes = probe_kernels()
    phases["build"] = time.perf_counter() - t

    t = time.perf_counter()
    n_acc = len(functions) * 4 + sum(p["present"] for p in peer_list)
    with bar(n_acc, "accuracy" + (" (exhaustive)" if exhaustive else "")) as b:
        measure_accuracy(variants, peer_list, functions, samples, exhaustive, exhaustive_peers, b, scheduler=scheduler,
                         show=progress)
    phases["accuracy"] = time.perf_counter() - t

    t = time.perf_counter()
    entries = ([v | {"fn": v["ufunc"], "reactor": True} for v in variants]
               + [p for p in peer_list if p["present"]]
               + [f | {"fn": f["ufunc"], "reactor": True} for f in floors]
               + [p | {"fn": p["ufunc"], "reactor": False} for p in probes])
    total_rounds = sum(rounds[s] * (2 if threads2 and n >= 2 ** 20 else 1) for s, n in sizes.items())
    with bar(total_rounds, "timing") as b:
        loads = measure_speed(entries, sizes, rounds, cal0.ghz, threads2, b)
    phases["timing"] = time.perf_counter() - t
    cal1 = clock.calibrate(**cal_kw)
    ghz = (cal0.ghz + cal1.ghz) / 2
    _rescale(entries, ghz)
    by_key = {e["key"]: e for e in entries}
    for v in variants:
        v["timing"] = by_key[v["key"]].get("timing", {})
    for p in peer_list:
        if p["present"]:
            p["timing"] = by_key[p["key"]].get("timing", {})
    for f in floors + probes:
        f["timing"] = by_key[f["key"]].get("timing", {})
    state = {size: machine_state(probes, size) for size, n in sizes.items() if n < 2 ** 22}

    attach_gaps(variants, floors, state)

    t = time.perf_counter()
    from .. import frontier as ladder
    steps = [f for f in functions if f in ladder.FUNCS]
    points = ladder.run(steps, rounds=5 if min(rounds.values()) < 9 else 21) if steps else []
    phases["ladder"] = time.perf_counter() - t

    report = {
        "version": 1,
        "started": datetime.datetime.now().isoformat(timespec="seconds"),
        "machine": _machine(),
        "settings": {"functions": list(functions), "sizes": sizes, "rounds": rounds, "samples": samples,
                     "exhaustive": exhaustive, "exhaustive_peers": exhaustive_peers,
                     "threads": [1, 2] if threads2 else [1]},
        "clock": {"start": cal0.to_json(), "end": cal1.to_json(), "ghz": ghz,
                  "uarch": cal0.uarch, "latency_source": clock.cpus.TABLE[cal0.uarch].source},
        "load": loads,
        "machine_state": state,
        "variants": [{k: val for k, val in v.items() if k != "ufunc"} for v in variants],
        "peers": [{k: val for k, val in p.items() if k not in ("fn",)} for p in peer_list],
        "floors": [{k: val for k, val in f.items() if k not in ("ufunc", "fn")} for f in floors],
        "probes": [{k: val for k, val in p.items() if k not in ("ufunc", "fn")} for p in probes],
        "ladder": ladder.to_json(points),
    }
    report["targets"] = check_targets(report)
    phases["total"] = time.perf_counter() - t_start
    report["seconds"] = {k: round(val, 1) for k, val in phases.items()}
    return report


def _machine() -> dict:
    info = clock.cpu_model()
    info |= {"python": platform.python_version(), "numpy": np.__version__,
             "cpus": os.cpu_count(), "reactor_threads": list(reactor.thread_settings())}
    try:
        import llvmlite
        info["llvmlite"] = llvmlite.__version__
    except ImportError:  # pragma: no cover
        pass
    return info
