"""Speed per target: the routines at each x86 level against NumPy and libmvec at the same level,
and the operations of each variant's vector loop iteration on every target, AArch64 included.

For each x86 level this CPU runs (sse4, avx2, avx512), a child process times, at 64K float32
(one thread, median of interleaved repetitions):

* ours: ``routines.jit(name, precision, target=level)`` (FMA as the target has it);
* NumPy restricted to the level (``NPY_DISABLE_CPU_FEATURES``: at sse4 its X86_V3/X86_V4 and
  AVX-512 loops are disabled, at avx2 its X86_V4 and AVX-512 ones; NumPy 2.4's names);
* glibc libmvec's entry points of the level (``_ZGVbN4v_*`` SSE, ``_ZGVdN8v_*`` AVX2,
  ``_ZGVeN16v_*`` AVX-512), called from a reactor kernel built for the same level.

The figure to reach (issue 21): ours faster than NumPy and at most 1.1x libmvec's time, for
every full and relaxed exp2, log2 and pow at sse4 and avx2.

``--ladder`` times the faithful and correct tiers of exp2, exp, log2 and log instead, against the
figures of issue 31: faithful at most NumPy's and libmvec's time, correct at most NumPy's, at
every level.

Every contender runs on one thread (reactor's pool would split a 64K call; NumPy and libmvec
run on one).

    python benchmarks/bench_targets.py [--ladder] [--json out/bench_targets.json] [--reps 41]
"""
from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import time

FUNCTIONS = ("exp2", "log2", "pow")
PRECISIONS = ("full", "relaxed")
LADDER_FUNCTIONS = ("exp2", "exp", "log2", "log")
LADDER_PRECISIONS = ("faithful", "correct")
LEVELS = {  # level -> (NumPy features to disable, libmvec ISA letter, lanes)
    "sse4": ("X86_V3 X86_V4 AVX512_ICL AVX512_SPR", "b", 4),
    "avx2": ("X86_V4 AVX512_ICL AVX512_SPR", "d", 8),
    "avx512": ("", "e", 16),
}
N = 65536


def _libmvec(name: str, level: str):
    import reactor
    from reactor import External, Float

    _, isa, lanes = LEVELS[level]
    arity = 2 if name == "pow" else 1
    symbol = f"_ZGV{isa}N{lanes}{'v' * arity}_{name}f"
    vec = reactor.vector_type("Float", lanes)
    ext = External(symbol, returns=vec, args=(vec,) * arity, library="libmvec.so.1")
    if not ext.available:
        return None, symbol
    body = (lambda x: ext(x)) if arity == 1 else (lambda x, y: ext(x, y))
    return reactor.kernel(body, name=f"mvec_{name}_{level}", args=[Float] * arity, returns=Float,
                          width=lanes, target=level), symbol


def child(level: str, reps: int, ladder: bool = False) -> dict:
    """Time every function and precision at ``level`` (NumPy was restricted by the parent)."""
    import numpy as np

    import reactor
    import routines

    reactor.configure_threads(threads=1)
    rng = np.random.default_rng(21)
    inputs = {"exp2": (rng.uniform(-100, 100, N).astype(np.float32),),
              "exp": (rng.uniform(-80, 80, N).astype(np.float32),),
              "log2": (rng.uniform(1e-3, 1e3, N).astype(np.float32),),
              "log": (rng.uniform(1e-3, 1e3, N).astype(np.float32),),
              "pow": (rng.uniform(1e-2, 1e2, N).astype(np.float32), rng.uniform(-8, 8, N).astype(np.float32))}
    numpy_fn = {"exp2": np.exp2, "exp": np.exp, "log2": np.log2, "log": np.log, "pow": np.power}
    functions, precisions = (LADDER_FUNCTIONS, LADDER_PRECISIONS) if ladder else (FUNCTIONS, PRECISIONS)
    out = np.empty(N, np.float32)
    rows = []
    for name in functions:
        args = inputs[name]
        mvec, symbol = _libmvec(name, level)
        contenders = {"numpy": numpy_fn[name]}
        if mvec is not None:
            contenders["libmvec"] = mvec
        for precision in precisions:
            contenders[precision] = routines.jit(name, precision=precision, target=level)
        times: dict[str, list[float]] = {k: [] for k in contenders}
        for fn in contenders.values():
            fn(*args, out=out)  # warm
        for _ in range(reps):
            for key, fn in contenders.items():
                t = time.perf_counter()
                fn(*args, out=out)
                times[key].append(time.perf_counter() - t)
        ns = {k: statistics.median(v) / N * 1e9 for k, v in times.items()}
        for precision in precisions:
            rows.append({"level": level, "function": name, "precision": precision, "ns": ns[precision],
                         "numpy_ns": ns["numpy"], "libmvec_ns": ns.get("libmvec"), "libmvec": symbol,
                         "vs_numpy": ns[precision] / ns["numpy"],
                         "vs_libmvec": ns[precision] / ns["libmvec"] if "libmvec" in ns else None})
    return {"level": level, "numpy_disabled": LEVELS[level][0], "rows": rows}


def _iteration_operations(kern) -> int:
    """Operations one iteration of the kernel's vector loop always runs, in the target's optimized
    IR (the dataflow model's ``iteration``: cold blocks such as log2's general path without
    AVX-512 left out; phis, branches and bit casts, which emit no instruction, not counted)."""
    import llvmlite.binding as llvm

    from reactor.cost import model

    fn = llvm.parse_assembly(kern.optimized_ir).get_function(f"{kern.name}.loop")
    body, _ = model.iteration(fn)
    return sum(1 for instr in body if model.classify(instr) is not None)


def instruction_counts() -> list[dict]:
    """Operations per vector iteration per variant and target (FMA as each target has it)."""
    import reactor
    import routines

    rows = []
    targets = ("sse4", "avx2", "avx512", "aarch64")
    for name in FUNCTIONS:
        for precision in PRECISIONS:
            row = {"function": name, "precision": precision}
            for target in targets:
                k = reactor.kernel_of(routines.jit(name, precision=precision, target=target))
                n = _iteration_operations(k)
                row[target] = {"operations": n, "lanes": k.build.width, "per_element": round(n / k.build.width, 2)}
            rows.append(row)
    return rows


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", metavar="FILE")
    parser.add_argument("--reps", type=int, default=41)
    parser.add_argument("--ladder", action="store_true",
                        help="the faithful and correct tiers of exp2, exp, log2, log (issue 31's figures)")
    parser.add_argument("--child", choices=LEVELS, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        print(json.dumps(child(args.child, args.reps, args.ladder)))
        return 0
    import reactor
    levels = [lv for lv in LEVELS if reactor.get_target(lv).runnable]
    results = []
    for level in levels:
        env = dict(os.environ, NPY_DISABLE_CPU_FEATURES=LEVELS[level][0])
        if not LEVELS[level][0]:
            env.pop("NPY_DISABLE_CPU_FEATURES")
        done = subprocess.run([sys.executable, __file__, "--child", level, "--reps", str(args.reps)]
                              + ["--ladder"] * args.ladder, env=env, capture_output=True, text=True, check=True)
        results.append(json.loads(done.stdout.strip().splitlines()[-1]))
    print(f"{'level':7s} {'function':5s} {'precision':8s} {'ns/elem':>8s} {'NumPy':>7s} {'libmvec':>8s}"
          f" {'vs NumPy':>9s} {'vs libmvec':>10s}  figure")
    misses = 0
    for res in results:
        for r in res["rows"]:
            ok = _meets(r, args.ladder)
            if (args.ladder or r["level"] in ("sse4", "avx2")) and not ok:
                misses += 1
            mv = f"{r['libmvec_ns']:8.3f}" if r["libmvec_ns"] else "  absent"
            vm = f"{r['vs_libmvec']:9.2f}x" if r["vs_libmvec"] else "         -"
            print(f"{r['level']:7s} {r['function']:5s} {r['precision']:8s} {r['ns']:8.3f} {r['numpy_ns']:7.3f} "
                  f"{mv} {r['vs_numpy']:8.2f}x {vm}  {'PASS' if ok else 'MISS'}")
    if args.ladder:
        print(f"\n{misses} of {sum(len(r['rows']) for r in results)} variants miss the figure (faithful: at most "
              "NumPy's and libmvec's time; correct: at most NumPy's)")
        _write(args.json, {"cpu": reactor.get_target("host").cpu, "timings": results})
        return 0
    counts = instruction_counts()
    print("\noperations per vector iteration (per element): " + ", ".join(("sse4", "avx2", "avx512", "aarch64")))
    for row in counts:
        cells = "  ".join(f"{t} {row[t]['operations']} ({row[t]['per_element']})"
                          for t in ("sse4", "avx2", "avx512", "aarch64"))
        print(f"{row['function']:5s} {row['precision']:8s} {cells}")
    print(f"\n{misses} of {sum(len(r['rows']) for r in results if r['level'] in ('sse4', 'avx2'))} "
          f"sse4/avx2 variants miss the figure (faster than NumPy, <= 1.1x libmvec)")
    _write(args.json, {"cpu": reactor.get_target("host").cpu, "timings": results, "instructions": counts})
    return 0


def _meets(row: dict, ladder: bool) -> bool:
    """Issue 21's figure for full and relaxed; issue 31's for faithful (at most NumPy's and
    libmvec's time) and correct (at most NumPy's)."""
    if not ladder:
        return row["vs_numpy"] < 1 and (row["vs_libmvec"] is None or row["vs_libmvec"] <= 1.1)
    if row["precision"] == "correct":
        return row["vs_numpy"] <= 1
    return row["vs_numpy"] <= 1 and (row["vs_libmvec"] is None or row["vs_libmvec"] <= 1)


def _write(path, data) -> None:
    if path:
        os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
        with open(path, "w") as f:
            json.dump(data, f, indent=1)


if __name__ == "__main__":
    sys.exit(main())
