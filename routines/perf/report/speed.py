"""Speed: every entry timed by the harness, and cycles from the run's clock.

Contract: :func:`measure_speed` times every entry (a dict with ``key``,
``func``, ``fn``) at every size with :mod:`routines.perf.timing`, one thread
(and two threads at the sizes the kernels split, for the width-16 reactor
entries), fills ``entry["timing"][size][threads]`` in place and returns the
load by other processes per size; it restores reactor's thread settings.
:func:`rescale` recomputes the cycles/element of those timings with a new
clock figure. :func:`ns_per_element` and :func:`cycles_per_element` read one
timing back (NaN where it was not measured).
"""
from __future__ import annotations

import reactor

from .. import timing

#: Calls of at least this many elements are timed with two threads too.
TWO_THREAD_SIZE = 2 ** 20


def measure_speed(entries, sizes: dict, rounds: dict, ghz: float, threads2: bool = True,
                  progress=None) -> dict:
    """Time every entry (dicts with key, func, fn) at every size; returns the
    machine load per size. Fills ``entry["timing"][size][threads]``."""
    saved = reactor.thread_settings()
    loads = {}
    try:
        for size, n in sizes.items():
            reactor.configure_threads(threads=1)
            cands = [timing.Candidate(e["key"], e["func"], e["fn"], 1) for e in entries]
            a = timing.load_snapshot()
            res = timing.time_candidates(cands, size, n, rounds[size], ghz, progress=progress)
            if threads2 and n >= TWO_THREAD_SIZE:
                reactor.configure_threads(threads=2, threshold=TWO_THREAD_SIZE)
                two = [timing.Candidate(e["key"], e["func"], e["fn"], 2) for e in entries
                       if e.get("reactor") and (e.get("kind") == "peer" or e.get("width") == 16)]
                res += timing.time_candidates(two, size, n, rounds[size], ghz, progress=progress)
            loads[size] = timing.others_load(a, timing.load_snapshot())
            by_key = {e["key"]: e for e in entries}
            for t in res:
                by_key[t.key].setdefault("timing", {}).setdefault(size, {})[str(t.threads)] = t.to_json()
    finally:
        reactor.configure_threads(threads=saved[0], threshold=saved[1])
    return loads


def rescale(entries, ghz: float) -> None:
    """Recompute cycles/element with the run's final clock figure."""
    for e in entries:
        for per in e.get("timing", {}).values():
            for t in per.values():
                t["cycles_per_element"] = t["ns_per_element"] * ghz
                t["median_cycles_per_element"] = t["median_ns_per_element"] * ghz


def ns_per_element(e, size="L2", threads="1"):
    t = e.get("timing", {}).get(size, {}).get(threads)
    return t["ns_per_element"] if t else float("nan")


def cycles_per_element(e, size="L2", threads="1"):
    t = e.get("timing", {}).get(size, {}).get(threads)
    return t["cycles_per_element"] if t else float("nan")
