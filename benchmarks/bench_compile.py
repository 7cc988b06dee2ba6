"""Compile time: cold builds, memory hits and disk hits in a fresh process, against body size.

``python benchmarks/bench_compile.py [--quick] [--json FILE] [--out DIR]`` measures, same run:

1. synthetic shaders of 10 to 2,000 DSL operations with 1 input, and of 100 operations with 1, 2, 4
   and 8 inputs (generated source, so each is a distinct function with its own recipe): the cold
   build (no cache, median of 3 distinct bodies), the memory hit (the same body again, median of 21) and the disk
   hit in a fresh process (the build alone, after the process's one-time start-up, which is
   reported apart);
2. the routines (``routines.jit``, full precision, every function), the examples' kernels
   (gamma/sRGB, specular, tone mapping) and a PBR shader (8 inputs, 4 pow, 4 rsqrt, ~60 lines:
   ``benchmarks/shaders/pbr.py``): cold and disk hit;
3. Dr.Jit's LLVM backend building the same PBR shader, cold and from its own cache, when ``drjit``
   is installed (it needs libLLVM: Debian's libllvm19); otherwise reported absent.

Writes ``DIR/compile.json`` and ``DIR/compile.png`` (ms against operations, log-log).

``--pipelines`` measures instead, per optimization setting (``opt`` 1, 2, 3 = reactor's own pass
pipeline, and ``"llvm-o3"`` = LLVM's full O3): the cold build of a PBR shader and of the exp2, log2
and pow kernels, and each kernel's speed (ns/element at 64K elements, one thread, median of 101
calls interleaved across the settings, same run).
"""
from __future__ import annotations

import argparse
import json
import os
import random
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
SHADERS = os.path.join(ROOT, "benchmarks", "shaders")


def shader_source(n_ops: int, n_inputs: int, seed: int) -> str:
    """A straight-line body of ``n_ops`` DSL operations over ``n_inputs`` inputs, all live: each
    operation reads the previous result and values from the last few lines or an input, as
    shader code does (not values from anywhere, which would keep hundreds live at once)."""
    rng = random.Random(seed * 7919 + n_ops * 31 + n_inputs)
    args = ", ".join(f"x{i}: Float" for i in range(n_inputs))
    lines = [f"def shader({args}) -> Float:"]
    values = [f"x{i}" for i in range(n_inputs)]
    ops = 0
    k = 0
    while ops < n_ops:
        near = values[-8:] + values[:n_inputs]
        a, b, c = values[-1], rng.choice(near), rng.choice(near)
        const = round(rng.uniform(0.1, 2.0), 3) + seed * 1e-3
        form, cost = rng.choice([(f"{a} * {b}", 1), (f"{a} + {const}", 1), (f"MulAdd({a}, {b}, {c})", 1),
                                 (f"Min({a}, {b})", 1), (f"Max({a}, {const})", 1), (f"{a} - {b} * {const}", 2),
                                 (f"Select({a} < {b}, {a}, {c})", 2)])
        lines.append(f"    v{k} = {form}")
        values.append(f"v{k}")
        ops += cost
        k += 1
    lines.append(f"    return {values[-1]} + " + " + ".join(f"x{i}" for i in range(n_inputs)))
    return "\n".join(lines) + "\n"


PRELUDE = "from reactor import Float, MulAdd, Min, Max, Select\n"


def build_synthetic(n_ops, n_inputs, seed):
    import reactor
    ns = {}
    exec(compile(PRELUDE + shader_source(n_ops, n_inputs, seed), f"<shader {n_ops}x{n_inputs}#{seed}>", "exec"), ns)
    t = time.perf_counter()
    u = reactor.kernel(ns["shader"], name=f"shader_{n_ops}_{n_inputs}_{seed}")
    return time.perf_counter() - t, u, ns["shader"]


# -- a fresh process: build from the disk cache ------------------------------------------------

CHILD = textwrap.dedent('''
    import json, sys, time
    t0 = time.perf_counter()
    sys.path.insert(0, sys.argv[1]); sys.path.insert(0, sys.argv[2])
    import reactor, routines
    from reactor.kernels import parallel
    t1 = time.perf_counter()
    parallel.runtime()   # what is left of the one-time JIT start-up (the import's warm-up thread runs it)
    t2 = time.perf_counter()
    from bench_compile import build_synthetic, build_named
    out = {"import_ms": 1e3 * (t1 - t0), "startup_ms": 1e3 * (t2 - t1), "builds": {}}
    for job in json.loads(sys.argv[3]):
        if job[0] == "synthetic":
            seconds = build_synthetic(*job[1:])[0]
        else:
            seconds = build_named(job[1])[0]
        out["builds"][repr(tuple(job))] = 1e3 * seconds
    print(json.dumps(out))
''')


def build_named(name):
    """Build one of the named kernels (routines, examples, the PBR shader); (seconds, ufuncs)."""
    import routines
    if name.startswith("examples:"):  # the example's own imports (image libraries ...) are not the build
        sys.path.insert(0, os.path.join(ROOT, "examples"))
        import importlib
        example = importlib.import_module(name.split(":")[1])
    t = time.perf_counter()
    if name.startswith("routines:"):
        made = [routines.jit(name.split(":")[1])]
    elif name == "pbr":
        import importlib.util
        spec = importlib.util.spec_from_file_location(f"pbr_{time.perf_counter_ns()}", os.path.join(SHADERS, "pbr.py"))
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        made = [module.pbr]
    else:
        made = {"gamma": lambda: [k for pair in example.make_kernels("full").values() for k in pair],
                "specular": lambda: [example.make_shader("full", 1.0, 1.0)],
                "tonemap": lambda: list(example.make_kernels("full"))}[name.split(":")[1]]()
    return time.perf_counter() - t, made


def pipelines(repeats: int = 5) -> list[dict]:
    """Cold build and kernel speed of the named kernels per optimization setting (same run)."""
    import numpy as np

    import reactor
    from reactor.jit import cache
    from reactor.kernels import parallel

    settings = (1, 2, 3, "llvm-o3")
    bodies = {}
    for name in ("pbr", "routines:exp2", "routines:log2", "routines:pow"):
        _, made = build_named(name)
        k = reactor.kernel_of(made[0])
        bodies[name] = (k.body, k.name, list(k.signature.params), k.signature.returns)
    rows, kernels = [], {}
    for name, (body, kname, args, returns) in bodies.items():
        for opt in settings:
            times = []
            for rep in range(repeats):
                cache.memory_clear()
                t = time.perf_counter()
                u = reactor.kernel(body, name=f"{kname}_o{opt}_{rep}", args=args, returns=returns, opt=opt,
                                   cache=False)
                times.append(time.perf_counter() - t)
            kernels[name, opt] = u
            rows.append({"kernel": name, "opt": opt, "cold_ms": 1e3 * statistics.median(times)})
    saved = parallel.settings()
    parallel.configure(threads=1)
    x = np.random.default_rng(0).random(1 << 16, dtype=np.float32) + np.float32(0.25)
    samples: dict = {key: [] for key in kernels}
    for _ in range(101):
        for key, u in kernels.items():
            operands = [x] * u.nin
            t = time.perf_counter()
            u(*operands)
            samples[key].append(time.perf_counter() - t)
    parallel.configure(threads=saved[0], threshold=saved[1])
    for row in rows:
        row["ns_per_element"] = 1e9 * statistics.median(samples[row["kernel"], row["opt"]]) / x.size
    for name in bodies:
        base = next(r for r in rows if r["kernel"] == name and r["opt"] == 3)
        for r in rows:
            if r["kernel"] == name:
                print(f"{name:14s} opt={str(r['opt']):8s} cold {r['cold_ms']:7.1f} ms "
                      f"({r['cold_ms'] / base['cold_ms']:.2f}x opt 3)   {r['ns_per_element']:.3f} ns/element "
                      f"({r['ns_per_element'] / base['ns_per_element']:.3f}x opt 3)", flush=True)
    return rows


def fresh_process(jobs, cache_dir):
    env = dict(os.environ, REACTOR_CACHE_DIR=cache_dir, PYTHONPATH=ROOT)
    env.pop("REACTOR_CACHE", None)
    run = subprocess.run([sys.executable, "-c", CHILD, ROOT, os.path.join(ROOT, "benchmarks"), json.dumps(jobs)],
                         capture_output=True, text=True, env=env, timeout=900)
    if run.returncode:
        raise RuntimeError(run.stderr[-3000:])
    return json.loads(run.stdout.strip().splitlines()[-1])


# -- Dr.Jit --------------------------------------------------------------------------------------

DRJIT = textwrap.dedent('''
    import sys, time
    t0 = time.perf_counter()
    import drjit as dr
    from drjit.llvm import Float
    sys.path.insert(0, sys.argv[1])
    from pbr_drjit import pbr
    x = dr.linspace(Float, 0.1, 0.9, 1024)
    t1 = time.perf_counter()
    r = pbr(x, x, x, x, x, x, x, x)
    dr.eval(r)
    t2 = time.perf_counter()
    print(1e3 * (t2 - t1))
''')


def drjit_times():
    try:
        import drjit  # noqa: F401
    except ImportError:
        return None
    home = tempfile.mkdtemp(prefix="drjit-home-")
    times = []
    for _ in range(2):  # cold, then from its kernel cache (a fresh process each time)
        run = subprocess.run([sys.executable, "-c", DRJIT, SHADERS], capture_output=True, text=True, timeout=300,
                             env=dict(os.environ, HOME=home))
        if run.returncode:
            return {"error": run.stderr[-500:]}
        times.append(float(run.stdout.strip().splitlines()[-1]))
    return {"cold_ms": times[0], "cache_hit_ms": times[1]}


# -- the run -------------------------------------------------------------------------------------

def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="fewer sizes and repeats")
    parser.add_argument("--json")
    parser.add_argument("--out", default="out")
    parser.add_argument("--pipelines", action="store_true",
                        help="compile time and kernel speed per optimization setting (1, 2, 3, llvm-o3)")
    args = parser.parse_args(argv)
    os.environ["REACTOR_CACHE"] = "0"  # cold builds: no disk cache (the memory cache is cleared too)
    if args.pipelines:
        rows = pipelines(2 if args.quick else 5)
        if args.json:
            with open(args.json, "w") as f:
                json.dump(rows, f, indent=1)
        return rows
    import reactor
    from reactor.jit import cache
    from reactor.kernels import parallel
    parallel.runtime()
    build_synthetic(20, 1, 0)  # warm up: the first build pays Python's and LLVM's one-time costs
    sizes = [10, 100, 1000] if args.quick else [10, 30, 100, 300, 1000, 2000]
    inputs = [1, 8] if args.quick else [1, 2, 4, 8]
    repeats = 1 if args.quick else 3
    results = {"synthetic": [], "named": [], "drjit": None}
    jobs = []
    for n_ops, n_inputs in [(s, 1) for s in sizes] + [(100, k) for k in inputs if k != 1]:
        colds = []
        for seed in range(repeats):
            cache.memory_clear()
            seconds, u, body = build_synthetic(n_ops, n_inputs, seed + 1)
            colds.append(seconds)
        hits = []
        for _ in range(21):  # the median of 21 hits (one sample is at the mercy of a collection)
            t = time.perf_counter()
            reactor.kernel(body, name=f"shader_{n_ops}_{n_inputs}_{repeats}")
            hits.append(time.perf_counter() - t)
        memo = statistics.median(hits)
        row = {"ops": n_ops, "inputs": n_inputs, "cold_ms": 1e3 * statistics.median(colds), "memory_hit_ms": 1e3 * memo}
        results["synthetic"].append(row)
        jobs.append(("synthetic", n_ops, n_inputs, 101))
        print(f"synthetic {n_ops:5d} ops {n_inputs} inputs: cold {row['cold_ms']:8.1f} ms, memory hit {1e3 * memo:.3f} ms",
              flush=True)
    names = [f"routines:{n}" for n in ("exp2", "log2", "pow", "exp", "log", "rcp", "rsqrt", "sqrt")] + \
        ["examples:gamma", "examples:specular", "examples:tonemap", "pbr"]
    for name in names:
        times = []
        for _ in range(repeats):
            cache.memory_clear()
            if name.startswith("routines:"):
                import routines
                routines.kernels._build.cache_clear()
            seconds, made = build_named(name)
            times.append(seconds)
        seconds = statistics.median(times)
        results["named"].append({"name": name, "kernels": len(made), "cold_ms": 1e3 * seconds})
        jobs.append(("named", name))
        print(f"{name:18s} cold {1e3 * seconds:8.1f} ms ({len(made)} kernel{'s' * (len(made) > 1)})", flush=True)
    with tempfile.TemporaryDirectory(prefix="reactor-compile-") as d:
        fresh_process(jobs, d)            # fills the disk cache
        hit = fresh_process(jobs, d)      # a new process builds everything again from it
    print(f"fresh process: import {hit['import_ms']:.0f} ms, one-time JIT start-up left after it "
          f"{hit['startup_ms']:.1f} ms (run during the import by its warm-up thread; REACTOR_WARMUP=0: none)")
    for row, job in zip(results["synthetic"] + results["named"], jobs):
        row["disk_hit_ms"] = hit["builds"][repr(job if isinstance(job, tuple) else tuple(job))]
    for row in results["synthetic"] + results["named"]:
        label = row.get("name") or f"synthetic {row['ops']} ops {row['inputs']} in"
        print(f"  disk hit {label:28s} {row['disk_hit_ms']:7.2f} ms")
    results["fresh_process"] = {k: hit[k] for k in ("import_ms", "startup_ms")}
    results["drjit"] = drjit_times()
    if results["drjit"] and "cold_ms" in results["drjit"]:
        ours = next(r for r in results["named"] if r["name"] == "pbr")
        print(f"PBR: reactor cold {ours['cold_ms']:.1f} ms, disk hit {ours['disk_hit_ms']:.2f} ms; Dr.Jit cold "
              f"{results['drjit']['cold_ms']:.1f} ms, cache hit {results['drjit']['cache_hit_ms']:.1f} ms")
    else:
        print(f"Dr.Jit: absent ({results['drjit']})")
    one = [r for r in results["synthetic"] if r["inputs"] == 1]
    hundred = {r["inputs"]: r["cold_ms"] for r in results["synthetic"] if r["ops"] == 100}
    if 8 in hundred:
        print(f"100 ops: 8 inputs / 1 input cold = {hundred[8] / hundred[1]:.2f}x")
    print("cold ms per operation: " + ", ".join(f"{r['ops']}: {r['cold_ms'] / r['ops']:.3f}" for r in one))
    os.makedirs(args.out, exist_ok=True)
    with open(args.json or os.path.join(args.out, "compile.json"), "w") as f:
        json.dump(results, f, indent=1)
    _chart(results, os.path.join(args.out, "compile.png"))


def _chart(results, path):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("no chart: matplotlib is not installed")
        return
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for inputs in sorted({r["inputs"] for r in results["synthetic"]}):
        rows = sorted((r for r in results["synthetic"] if r["inputs"] == inputs), key=lambda r: r["ops"])
        if len(rows) < 2:
            r = rows[0]
            ax.plot([r["ops"]], [r["cold_ms"]], "s", label=f"cold, {inputs} inputs")
            continue
        xs = [r["ops"] for r in rows]
        ax.plot(xs, [r["cold_ms"] for r in rows], "o-", label=f"cold, {inputs} input{'s' * (inputs > 1)}")
        ax.plot(xs, [r["disk_hit_ms"] for r in rows], "^--", label="disk hit, fresh process")
        ax.plot(xs, [max(r["memory_hit_ms"], 1e-3) for r in rows], "v:", label="memory hit")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("DSL operations in the body")
    ax.set_ylabel("ms to a callable ufunc")
    ax.set_title("reactor build time")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
