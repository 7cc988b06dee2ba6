"""The report: every variant's accuracy and speed beside the peers', in one run.

``run(...)`` builds every variant of ours (function x precision x FMA x SIMD
width 4/8/16) and the peers (:mod:`routines.perf.peers`), measures

* **accuracy** with the lab (:func:`routines.lab.evaluate` on
  :func:`routines.lab.sample_inputs`, or the exhaustive sweep), each variant
  against its own precision's tolerance and each peer against both;
* **speed** with the harness (:mod:`routines.perf.timing`) at the L1, L2 and
  DRAM sizes, one thread, and two threads at the DRAM size for the kernels
  reactor builds, with the clock calibrated at the start and the end
  (:mod:`routines.perf.clock`);
* the **dataflow model** of every variant (:mod:`routines.perf.model`): its
  throughput bound (execution pipes) and, from the same graph, a *window*
  bound (:func:`window_bound`), with a note saying where the variant spends;

and gathers everything in one JSON-ready dict: ``print_table`` renders it,
``chart_panels`` feeds :func:`routines.perf.chart.draw`, ``check_targets``
checks the targets of issue 5.
"""
from __future__ import annotations

import datetime
import math
import os
import platform
import sys
import time

import numpy as np

from . import clock, peers as peers_mod, timing

FUNCTIONS = ("exp2", "log2", "pow", "exp", "log", "rcp", "rsqrt", "sqrt")
PRECISIONS = ("full", "relaxed")
WIDTHS = (4, 8, 16)
DEFAULT = {"fma": True, "width": 16}  # routines.jit(name) on this machine
#: Zen 4 floating-point scheduler: 2 x 32 macro-ops (AMD SOG for family 19h, section 2.11).
FP_SCHEDULER = 64
DISPATCH = 6  # macro-ops dispatched per cycle (AMD SOG, 2.9.8)
GAP = 1.3  # the target: measured within 1.3x of the model


def _num(v):
    """A JSON-safe number (non-finite floats as strings, None kept)."""
    if v is None:
        return None
    v = float(v)
    return v if math.isfinite(v) else str(v)


def _f(v) -> float:
    """The inverse of _num (strings back to floats)."""
    return float(v) if v is not None else float("nan")


# -- the model: where a variant spends ---------------------------------------------------

def window_bound(ufunc) -> dict:
    """The out-of-order window bound of a kernel's vector loop.

    An operation waits in the FP scheduler from dispatch until its operands are
    ready. Take one iteration of ``vec.body`` dispatched in program order at
    ``DISPATCH`` ops per cycle and its ASAP schedule with the model's
    latencies: the sum over FP operations of (start - dispatch) is the
    scheduler occupancy one iteration costs, in op-cycles. The scheduler
    holds ``FP_SCHEDULER`` ops, so by Little's law an iteration cannot start
    more often than every ``sum / FP_SCHEDULER`` cycles however many pipes are
    free. This bites long dependent chains at narrow widths (the same chain
    and op count carry half or a quarter of the elements of a zmm iteration).
    """
    import llvmlite.binding as llvm
    from reactor import kernel_of

    from . import model as M

    kern = kernel_of(ufunc)
    fn = llvm.parse_assembly(kern.optimized_ir).get_function(f"{kern.name}.loop")
    body = next(b for b in fn.blocks if b.name == "vec.body")
    minmax = M._minmax_selects(body)
    folded = set(minmax.values())
    finish: dict[int, float] = {}
    wait, fp_ops, position = 0.0, 0, 0
    for instr in body.instructions:
        cls = M.classify(instr)
        if M._key(instr) in folded:
            cls = None
        elif M._key(instr) in minmax:
            cls = "fminmax"
        start = max((finish.get(M._key(op), 0.0) for op in instr.operands), default=0.0)
        finish[M._key(instr)] = start + (M.ZEN4[cls].latency if cls else 0.0)
        if cls and cls not in ("load", "store"):
            wait += max(0.0, start - position / DISPATCH)
            fp_ops += 1
        if cls:
            position += 1
    return {"wait_op_cycles": wait, "fp_ops": fp_ops, "cycles_per_vector": wait / FP_SCHEDULER}


def gap_verdict(measured_cv: float, pipe_cv: float, window_cv: float,
                floor_cv: float = float("nan"), pipe_factor: float = 1.0) -> tuple[str, str]:
    """(status, explanation) of a measured cycles/vector against the bounds.

    ``met``: within GAP of the pipe bound. ``memory``: within GAP of the
    measured memory floor (a kernel that only copies the same streams at this
    size: the model assumes L1 hits). ``window``: the window bound is the
    larger and the measurement within GAP of it. ``pipes+window``: both
    limits close to each other; their quadrature sum sqrt(p^2 + w^2) (an
    empirical combination: two nearly saturated resources queue against each
    other) is within GAP. ``pipes+memory``: the same with the copy floor
    added. ``unexplained`` otherwise. ``window_cv`` should use
    the run's effective window and ``pipe_factor`` (<= 1) is the share of the
    FP pipes the probe saw; both only enter the explanations, never ``met``."""
    if not (measured_cv > 0 and pipe_cv > 0):
        return "n/a", ""
    r = measured_cv / pipe_cv
    if r <= GAP:
        return "met", f"{r:.2f}x the pipe bound"
    nominal = pipe_cv
    pipe_cv = pipe_cv / pipe_factor if pipe_factor > 0 else pipe_cv
    derated = f" (pipes derated to {pipe_factor:.2f} by the probe)" if pipe_factor < 0.995 else ""
    if pipe_cv != nominal and measured_cv <= GAP * pipe_cv and pipe_cv >= window_cv:
        return "pipes (shared core)", (f"{measured_cv / pipe_cv:.2f}x the pipe bound {pipe_cv:.1f} c/v"
                                       + derated)
    if floor_cv > 0 and measured_cv <= GAP * floor_cv:
        return "memory", (f"{measured_cv / floor_cv:.2f}x the copy floor {floor_cv:.1f} c/v: moving the "
                          f"data at this size costs more than the arithmetic")
    hi = max(pipe_cv, window_cv)
    if window_cv > pipe_cv and measured_cv <= GAP * hi:
        return "window", (f"{measured_cv / hi:.2f}x the window bound {window_cv:.1f} c/v: the dependent "
                          f"chain keeps the FP scheduler full")
    combined = math.hypot(pipe_cv, window_cv)
    if measured_cv <= GAP * combined:
        return "pipes+window", (f"{measured_cv / combined:.2f}x sqrt(pipe^2 + window^2) = {combined:.1f} c/v: "
                                f"pipes ({pipe_cv:.1f}) and window ({window_cv:.1f}) both near saturation"
                                + derated)
    if floor_cv > 0:
        combined = math.sqrt(pipe_cv ** 2 + window_cv ** 2 + floor_cv ** 2)
        if measured_cv <= GAP * combined:
            return "pipes+memory", (f"{measured_cv / combined:.2f}x sqrt(pipe^2 + window^2 + floor^2) = "
                                    f"{combined:.1f} c/v: arithmetic ({pipe_cv:.1f}, window {window_cv:.1f}) "
                                    f"and data movement ({floor_cv:.1f}) both near saturation" + derated)
    return "unexplained", (f"{r:.2f}x the pipe bound, {measured_cv / combined:.2f}x the combined bound"
                           + (f", {measured_cv / floor_cv:.2f}x the copy floor" if floor_cv > 0 else ""))


# -- building -----------------------------------------------------------------------------

def _variant_key(func, precision, fma, width):
    return f"{func} {precision} {'fma' if fma else 'nofma'} w{width}"


def build_variants(functions, progress=None) -> list[dict]:
    """Every variant of ours with its ufunc and model figures."""
    from routines import jit

    from .model import predict_kernel

    out = []
    for func in functions:
        for precision in PRECISIONS:
            for fma in (True, False):
                for width in WIDTHS:
                    u = jit(func, precision, fma, width)
                    pred = predict_kernel(u)
                    win = window_bound(u)
                    out.append({
                        "key": _variant_key(func, precision, fma, width), "kind": "ours",
                        "family": f"ours {precision}", "func": func, "precision": precision,
                        "fma": fma, "width": width, "ufunc": u,
                        "model": {"cycles_per_vector": pred.throughput_bound,
                                  "cycles_per_element": pred.cycles_per_element,
                                  "bottleneck": pred.bottleneck, "critical_path": pred.critical_path,
                                  "counts": dict(pred.counts), "explain": pred.explain(),
                                  "window_cycles_per_vector": win["cycles_per_vector"],
                                  "window_wait_op_cycles": win["wait_op_cycles"]},
                    })
                    if progress is not None:
                        progress.update(1)
    return out


def floor_kernels(functions) -> list[dict]:
    """Reactor kernels that only move data, at widths 4/8/16: ``out = x``
    (timed on the first unary function's inputs) and ``out = x + y`` (on
    pow's): the memory and loop floor of the harness at each size and width."""
    import reactor
    from reactor import Float

    def copy(x):
        return x

    def add(x, y):
        return x + y

    out = []
    unary = [f for f in functions if f != "pow"]
    for width in WIDTHS:
        if unary:
            out.append({"key": f"floor copy w{width}", "func": unary[0], "kind": "floor", "family": "floor",
                        "width": width, "label": "out = x (one input stream)",
                        "ufunc": reactor.kernel(copy, name=f"perf_floor_copy_w{width}", args=[Float],
                                                returns=Float, width=width)})
        if "pow" in functions:
            out.append({"key": f"floor add w{width}", "func": "pow", "kind": "floor", "family": "floor",
                        "width": width, "label": "out = x + y (two input streams)",
                        "ufunc": reactor.kernel(add, name=f"perf_floor_add_w{width}", args=[Float, Float],
                                                returns=Float, width=width)})
    return out


def probe_kernels() -> list[dict]:
    """Two reactor kernels timed in the same rounds as everything else, to see
    what the machine delivers during the run (a shared core's pipes and window
    shrink when its sibling is busy):

    * ``probe pipes`` (width 16): 8 independent chains of 4 FMAs per element,
      summed: FP0/FP1-bound (model: 32 cycles/vector, window ~7);
    * ``probe window`` (width 8): one dependent chain of 32 FMAs per element:
      window-bound (pipes 16 cycles/vector, window ~33 at 64 entries).

    ``pipe factor`` = model bound / measured (1 = all of the FMA pipes),
    ``window`` = the probe's scheduler occupancy / measured cycles per vector
    (the effective scheduler entries: 64 on a quiet core)."""
    import reactor
    from reactor import Float, MulAdd

    def pipes(x):
        chains = [MulAdd(MulAdd(MulAdd(MulAdd(x + float(k), 0.999, 0.001), 0.999, 0.001), 0.999, 0.001),
                         0.999, 0.001) for k in range(8)]
        total = chains[0]
        for c in chains[1:]:
            total = total + c
        return total

    def window(x):
        v = x
        for _ in range(32):
            v = MulAdd(v, 0.999, 0.001)
        return v

    out = []
    for key, body, width in (("probe pipes", pipes, 16), ("probe window", window, 8)):
        u = reactor.kernel(body, name=f"perf_{key.replace(' ', '_')}", args=[Float], returns=Float,
                           width=width, fma=True)
        out.append({"key": key, "func": "exp2", "kind": "probe", "family": "probe", "width": width,
                    "ufunc": u, "wait_op_cycles": window_bound(u)["wait_op_cycles"]})
    from .model import predict_kernel
    out[0]["model_cycles_per_vector"] = predict_kernel(out[0]["ufunc"]).throughput_bound
    return out


def machine_state(probes, size) -> dict:
    """(pipe factor, effective window) at ``size`` from the probes' timings."""
    pp, pw = probes
    cv_p = _cy(pp, size) * pp["width"]
    cv_w = _cy(pw, size) * pw["width"]
    factor = min(1.0, pp["model_cycles_per_vector"] / cv_p) if cv_p > 0 else 1.0
    window = min(float(FP_SCHEDULER), pw["wait_op_cycles"] / cv_w) if cv_w > 0 else float(FP_SCHEDULER)
    return {"pipe_factor": factor, "window": window, "pipe_probe_cycles_per_vector": cv_p,
            "window_probe_cycles_per_vector": cv_w}


# -- accuracy -------------------------------------------------------------------------------

def _summary(r) -> dict:
    j = r.to_json()
    keep = ("inputs", "count", "seconds", "conforming", "max_ulp32", "max_ulp16", "max_margin",
            "max_margin_at", "nonconforming", "special_mismatches", "flushed_to_zero")
    return {k: j[k] for k in keep}


def _measure(fn, func, precision, sample, exhaustive, progress):
    from routines.lab import evaluate, sweep
    with np.errstate(all="ignore"):
        if not exhaustive:
            return evaluate(fn, func, precision, *sample)
        if func == "pow":
            from routines.lab.pairs import stratified_pow
            return stratified_pow(fn, precision, progress=progress)
        return sweep(fn, func, precision, progress=progress)


def measure_accuracy(variants, peer_list, functions, samples, exhaustive=False,
                     exhaustive_peers=False, progress=None, show=False) -> None:
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
                r = _measure(ref["ufunc"], func, precision, sample, exhaustive, show)
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
                                                              exhaustive, show)) | {"measured_at": f"w{w}"}
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


# -- timing -------------------------------------------------------------------------------

def _threads_api():
    try:
        from reactor.kernels import parallel
        return parallel
    except ImportError:  # a reactor without multi-threaded kernels
        return None


def measure_speed(entries, sizes: dict, rounds: dict, ghz: float, threads2: bool = True,
                  progress=None) -> dict:
    """Time every entry (dicts with key, func, fn) at every size; returns the
    machine load per size. Fills ``entry["timing"][size][threads]``."""
    parallel = _threads_api()
    saved = parallel.settings() if parallel else None
    loads = {}
    try:
        for size, n in sizes.items():
            if parallel:
                parallel.configure(threads=1)
            cands = [timing.Candidate(e["key"], e["func"], e["fn"], 1) for e in entries]
            a = timing.load_snapshot()
            res = timing.time_candidates(cands, size, n, rounds[size], ghz, progress=progress)
            if threads2 and parallel and n >= parallel.DEFAULT_THRESHOLD:
                parallel.configure(threads=2, threshold=parallel.DEFAULT_THRESHOLD)
                two = [timing.Candidate(e["key"], e["func"], e["fn"], 2) for e in entries
                       if e.get("reactor") and e.get("width", 16) == 16]
                res += timing.time_candidates(two, size, n, rounds[size], ghz, progress=progress)
            loads[size] = timing.others_load(a, timing.load_snapshot())
            by_key = {e["key"]: e for e in entries}
            for t in res:
                by_key[t.key].setdefault("timing", {}).setdefault(size, {})[str(t.threads)] = t.to_json()
    finally:
        if parallel:
            parallel.configure(threads=saved[0], threshold=saved[1])
    return loads


def _rescale(entries, ghz: float) -> None:
    """Recompute cycles/element with the run's final clock figure."""
    for e in entries:
        for per in e.get("timing", {}).values():
            for t in per.values():
                t["cycles_per_element"] = t["ns_per_element"] * ghz
                t["median_cycles_per_element"] = t["median_ns_per_element"] * ghz


def _ns(e, size="L2", threads="1"):
    t = e.get("timing", {}).get(size, {}).get(threads)
    return t["ns_per_element"] if t else float("nan")


def _cy(e, size="L2", threads="1"):
    t = e.get("timing", {}).get(size, {}).get(threads)
    return t["cycles_per_element"] if t else float("nan")


# -- the whole run --------------------------------------------------------------------------

def run(functions=FUNCTIONS, *, sizes=None, rounds=None, samples=2 ** 20, exhaustive=False,
        exhaustive_peers=False, threads2=True, progress=True, libraries=None, calibrate_ops=None) -> dict:
    """Measure everything; returns the report dict (JSON-ready after ``to_json``).

    ``sizes``: name -> elements (default :data:`timing.SIZES`); ``rounds``:
    name -> rounds (default 61 at the cache sizes, 9 at DRAM); ``libraries``:
    override peer library names (tests)."""
    from tqdm import tqdm

    t_start = time.perf_counter()
    functions = tuple(functions)
    sizes = dict(timing.SIZES if sizes is None else sizes)
    rounds = {s: (rounds or {}).get(s, 9 if n >= 2 ** 22 else 61) for s, n in sizes.items()}
    bar = lambda total, desc: tqdm(total=total, desc=desc, file=sys.stderr, disable=not progress,
                                   leave=False)
    cal_kw = {} if calibrate_ops is None else {"ops": calibrate_ops}
    cal0 = clock.calibrate(**cal_kw)
    phases = {}

    t = time.perf_counter()
    with bar(len(functions) * len(PRECISIONS) * 2 * len(WIDTHS), "build + model") as b:
        variants = build_variants(functions, b)
    peer_objs = peers_mod.peers(functions, libraries)
    peer_list = [p.to_json() | {"kind": "peer", "fn": p.fn, "present": p.present,
                                "reactor": p.family in ("libmvec", "sleef"), "width": 16 if
                                p.family in ("libmvec", "sleef") else None} for p in peer_objs]
    floors = floor_kernels(functions)
    probes = probe_kernels()
    phases["build"] = time.perf_counter() - t

    t = time.perf_counter()
    n_acc = len(functions) * 4 + sum(p["present"] for p in peer_list)
    with bar(n_acc, "accuracy" + (" (exhaustive)" if exhaustive else "")) as b:
        measure_accuracy(variants, peer_list, functions, samples, exhaustive, exhaustive_peers, b,
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

    floor_of = {f["key"]: f for f in floors}
    for v in variants:  # where it spends, at the L1 and L2 sizes
        m = v["model"]
        fl = (floor_of.get(f"floor {'add' if v['func'] == 'pow' else 'copy'} w{v['width']}")
              or floor_of.get(f"floor copy w{v['width']}"))
        v["gap"] = {}
        for size in ("L1", "L2"):
            cv = _cy(v, size) * v["width"]
            if math.isfinite(cv):
                floor_cv = _cy(fl, size) * v["width"] if fl else float("nan")
                st = state.get(size, {"pipe_factor": 1.0, "window": float(FP_SCHEDULER)})
                window_cv = m["window_wait_op_cycles"] / st["window"]
                status, why = gap_verdict(cv, m["cycles_per_vector"], window_cv, floor_cv, st["pipe_factor"])
                v["gap"][size] = {"measured_cycles_per_vector": cv, "floor_cycles_per_vector": floor_cv,
                                  "window_cycles_per_vector": window_cv,
                                  "ratio": cv / m["cycles_per_vector"], "status": status, "why": why}

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
    }
    report["targets"] = check_targets(report)
    phases["total"] = time.perf_counter() - t_start
    report["seconds"] = {k: round(val, 1) for k, val in phases.items()}
    return report


def _machine() -> dict:
    info = clock.cpu_model()
    parallel = _threads_api()
    info |= {"python": platform.python_version(), "numpy": np.__version__,
             "cpus": os.cpu_count(), "reactor_threads": list(parallel.settings()) if parallel else None}
    try:
        import llvmlite
        info["llvmlite"] = llvmlite.__version__
    except ImportError:  # pragma: no cover
        pass
    return info


# -- targets ---------------------------------------------------------------------------------

def _find(report, func, precision, fma=True, width=16):
    for v in report["variants"]:
        if (v["func"], v["precision"], v["fma"], v["width"]) == (func, precision, fma, width):
            return v
    return None


def _peer(report, key):
    return next((p for p in report["peers"] if p["key"] == key and p["present"]), None)


def _target(name, required, ratio, detail, status=None):
    if status is None:
        status = "not measured" if ratio is None or not math.isfinite(ratio) else \
            ("met" if ratio >= required else "missed")
    return {"target": name, "required": required, "ratio": _num(ratio), "status": status, "detail": detail}


def check_targets(report) -> list[dict]:
    """The targets of issue 5 (same-run ratios at the L2 size, one thread)."""
    out = []
    funcs = report["settings"]["functions"]
    for func in ("exp2", "log2"):
        ours = _find(report, func, "full")
        if func not in funcs or ours is None or "L2" not in report["settings"]["sizes"]:
            out.append(_target(f"{func} full faster than every highp peer", 1.0, None, "not in this run"))
            continue
        rivals = [p for p in report["peers"] if p["func"] == func and p["present"]
                  and p.get("accuracy", {}).get("verdict", {}).get("meets_full_tolerance")]
        t = _ns(ours)
        ratios = {p["key"]: _ns(p) / t for p in rivals}
        worst = min(ratios.values()) if ratios else float("nan")
        detail = ", ".join(f"{k} {r:.2f}x" for k, r in sorted(ratios.items(), key=lambda kv: kv[1]))
        absent = [p["key"] for p in report["peers"] if p["func"] == func and not p["present"]]
        detail = (detail or "no highp peer present") + (f"; absent: {', '.join(absent)}" if absent else "")
        out.append(_target(f"{func} full (fma w16) faster than every highp peer", 1.0,
                           worst if ratios else None, detail, None if ratios else "not measured"))
    # relaxed >= 1.4x full, every function x fma x width
    ratios, misses = [], []
    for v in report["variants"]:
        if v["precision"] != "relaxed":
            continue
        full = _find(report, v["func"], "full", v["fma"], v["width"])
        r = _ns(full) / _ns(v)
        if math.isfinite(r):
            ratios.append(r)
            if r < 1.4:
                model_r = full["model"]["cycles_per_vector"] / v["model"]["cycles_per_vector"]
                g = v.get("gap", {}).get("L2", {}).get("status")
                misses.append(f"{v['func']} {'fma' if v['fma'] else 'nofma'} w{v['width']} {r:.2f}x "
                              f"(model {model_r:.2f}x" + (", relaxed at the memory floor" if g == "memory"
                                                          else "") + ")")
    defaults = []
    for func in funcs:
        full, rel = _find(report, func, "full"), _find(report, func, "relaxed")
        if full and rel:
            defaults.append(f"{func} {_ns(full) / _ns(rel):.2f}x")
    out.append(_target("relaxed >= 1.4x faster than full (same function, FMA, width)", 1.4,
                       min(ratios) if ratios else None,
                       f"{len(ratios) - len(misses)}/{len(ratios)} variants met; fma w16: "
                       + ", ".join(defaults) + (f"; missed: {', '.join(misses)}" if misses else "")))
    np_pow = _peer(report, "numpy pow")
    for precision, req in (("full", 1.5), ("relaxed", 2.5)):
        ours = _find(report, "pow", precision)
        r = _ns(np_pow) / _ns(ours) if ours and np_pow else None
        out.append(_target(f"pow {precision} (fma w16) >= {req}x np.power", req, r,
                           f"np.power {_ns(np_pow):.3f} ns/elem, ours {_ns(ours):.3f}" if r else "not in this run"))
    # within 1.3x of the model bound, or the gap explained
    counts, unexplained = {}, []
    for v in report["variants"]:
        g = v.get("gap", {}).get("L2")
        if not g:
            continue
        counts[g["status"]] = counts.get(g["status"], 0) + 1
        if g["status"] == "unexplained":
            unexplained.append(f"{v['key']} {g['ratio']:.2f}x")
    total = sum(counts.values())
    status = "not measured" if not total else ("met" if counts.get("met", 0) == total else
                                              "missed (gaps explained)" if not unexplained else "missed")
    out.append({"target": "every variant within 1.3x of its model bound, or the gap explained",
                "required": GAP, "ratio": None, "status": status,
                "detail": ", ".join(f"{k}: {n}" for k, n in sorted(counts.items()))
                + (f"; unexplained: {', '.join(unexplained)}" if unexplained else "")})
    # two cores >= 1.8x one core on 16M elements
    big = [s for s, n in report["settings"]["sizes"].items() if n >= 2 ** 24]
    if not big or 2 not in report["settings"]["threads"]:
        out.append(_target("two cores >= 1.8x one core (16M elements)", 1.8, None, "not in this run"))
    else:
        s = big[0]
        rs = {}
        for func in funcs:
            for precision in PRECISIONS:
                v = _find(report, func, precision)
                if v:
                    rs[f"{func} {precision}"] = _ns(v, s, "1") / _ns(v, s, "2")
        load = report["load"].get(s, {}).get("other_cpus")
        worst = min(rs.values()) if rs else None
        out.append(_target("two cores >= 1.8x one core (16M elements, fma w16)", 1.8, worst,
                           ", ".join(f"{k} {r:.2f}x" for k, r in rs.items())
                           + f"; other processes used {load} CPUs meanwhile"))
    return out


# -- output ---------------------------------------------------------------------------------

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
    lines += ["", f"Where each variant spends (model, {size}):"]
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
                     + (f": {_f(r):.2f}x (need {t['required']}x)" if r is not None else "")
                     + (f" -- {t['detail']}" if t["detail"] else ""))
    lines.append("")
    lines.append("run time: " + ", ".join(f"{k} {v} s" for k, v in report["seconds"].items()))
    return "\n".join(lines)


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


def to_json(report) -> dict:
    """``report`` with every float JSON-safe."""
    def clean(o):
        if isinstance(o, dict):
            return {str(k): clean(v) for k, v in o.items()}
        if isinstance(o, (list, tuple)):
            return [clean(v) for v in o]
        if isinstance(o, (bool, str)) or o is None:
            return o
        if isinstance(o, (int, np.integer)):
            return int(o)
        if isinstance(o, (float, np.floating)):
            return _num(o)
        return str(o)
    return clean(report)
