"""Accuracy: every variant and peer measured by the lab, on the same sample.

Contract: :func:`measure_accuracy` sets ``accuracy`` (in place) on every
variant of ``functions`` and every present peer: the lab's figures on a
seeded sample (or the exhaustive sweep), ours against their own precision's
tolerance (and the full one for ``full_margin``), peers against both with a
tolerance verdict. Timings are not touched.
"""
from __future__ import annotations

import numpy as np

from .. import peers as peers_mod
from .jsonsafe import json_number as _num
from .variants import PRECISIONS


def _summary(r) -> dict:
    j = r.to_json()
    keep = ("inputs", "count", "seconds", "conforming", "max_ulp32", "max_ulp16", "max_margin",
            "max_margin_at", "nonconforming", "special_mismatches", "flushed_to_zero")
    return {k: j[k] for k in keep}


def _measure(fn, func, precision, sample, exhaustive, progress, scheduler=None):
    from routines.lab import evaluate, sweep
    with np.errstate(all="ignore"):
        if not exhaustive:
            return evaluate(fn, func, precision, *sample)
        if func in ("pow", "atan2"):  # two operands: the stratified pair sweep
            from routines.lab.pairs import stratified
            return stratified(fn, func, precision, progress=progress, scheduler=scheduler)
        return sweep(fn, func, precision, progress=progress, scheduler=scheduler)


def measure_accuracy(variants, peer_list, functions, samples, exhaustive=False,
                     exhaustive_peers=False, progress=None, show=False, scheduler=None) -> None:
    """Fill ``accuracy`` of every variant and present peer (in place).

    Our variants are measured at width 16; the other widths are checked to be
    bit-identical to it on the sample (then they share its figures), else
    measured themselves."""
    from routines.lab import sample_inputs

    for func in functions:
        sample = sample_inputs(func, samples, seed=0)
        mine = [v for v in variants if v["func"] == func]
        for precision in PRECISIONS:
            for fma in (True, False):
                group = {v["width"]: v for v in mine if v["precision"] == precision and v["fma"] == fma}
                ref = group[16]
                r = _measure(ref["ufunc"], func, precision, sample, exhaustive, show, scheduler)
                ref["accuracy"] = _summary(r) | {"measured_at": "w16"}
                if precision == "full":
                    ref["accuracy"]["full_margin"] = ref["accuracy"]["max_margin"]
                else:  # the same inputs scored against the highp tolerance: the chart's common axis
                    rf = _measure(ref["ufunc"], func, "full", sample, False, show)
                    ref["accuracy"]["full_margin"] = _num(rf.max_margin)
                args = tuple(b.view(np.float32) for b in sample)
                with np.errstate(all="ignore"):
                    base = ref["ufunc"](*args)
                    for w, v in group.items():
                        if w == 16:
                            continue
                        same = np.array_equal(v["ufunc"](*args).view(np.uint32), base.view(np.uint32))
                        if same:
                            v["accuracy"] = dict(ref["accuracy"], measured_at="w16 (bit-identical on the sample)")
                        else:
                            v["accuracy"] = _summary(_measure(v["ufunc"], func, precision, sample,
                                                              exhaustive, show, scheduler)) | {"measured_at": f"w{w}"}
                if progress is not None:
                    progress.update(1)
        for p in peer_list:
            if p["func"] != func or not p["present"]:
                continue
            fn = peers_mod.as_array_function(p["fn"])
            results = {prec: _measure(fn, func, prec, sample, exhaustive and exhaustive_peers, show)
                       for prec in PRECISIONS}
            p["accuracy"] = {prec: _summary(r) for prec, r in results.items()}
            p["accuracy"]["verdict"] = peers_mod.accuracy_verdict(results["full"], results["relaxed"])
            if progress is not None:
                progress.update(1)
