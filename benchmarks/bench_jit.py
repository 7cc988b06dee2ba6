"""Benchmark of the reactor DSL/JIT layer.

    python benchmarks/bench_jit.py [--json FILE] [--quick]

1. JIT compile time of a small kernel (``x * c + 1.0``, one input):
   * cold: disk cache off, a body never built in this process (median over
     distinct generated kernels);
   * memory hit: ``kernel(body)`` again for the same body (the memo: nothing is
     traced or compiled);
   * recipe hit: a different Python function object with the same code and
     values (not traced: its recipe key finds the object);
   * disk hit: a fresh subprocess builds kernels whose objects are on disk
     (import time reported separately; the first build there also pays what the
     import's warm-up thread has not yet done of the one-time LLVM/JIT start-up,
     reported separately too: it must meet the same 5 ms).
2. Kernel call overhead against ``np.negative`` at 1 and 1024 elements.
3. Throughput of ``x*y+z`` against NumPy (``multiply`` then ``add``, both with
   ``out=``) at 64K and 16M float32 elements, best of N.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
import timeit

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, REPO)

import numpy as np  # noqa: E402

TARGETS = {  # name -> (limit, unit); a figure passes when it is <= limit
    "cold_ms": (12.0, "ms"),
    "memo_hit_ms": (0.1, "ms"),
    "disk_hit_ms": (5.0, "ms"),
    "disk_first_build_ms": (5.0, "ms"),
    "overhead_ratio_1": (1.5, "x"),
    "overhead_ratio_1024": (1.5, "x"),
}


def _body_source(k: int, nin: int = 1) -> str:
    """Source of a small kernel body with its own constant (so its own IR)."""
    c = 1.0 + k / 1024.0
    if nin == 1:
        return f"def body(x: Float) -> Float:\n    return x * {c!r} + 1.0\n"
    return f"def body(x: Float, y: Float) -> Float:\n    return x * y + {c!r}\n"


def _make_body(k: int, nin: int = 1):
    from reactor import Float

    scope = {"Float": Float}
    exec(_body_source(k, nin), scope)
    return scope["body"]


# -- 1. compile time -------------------------------------------------------------------

def bench_compile(count: int, cache_dir: str) -> dict:
    from reactor import kernel, kernel_of

    os.environ["REACTOR_CACHE_DIR"] = cache_dir
    kernel(_make_body(-1), cache=False)  # one-time LLVM/JIT initialisation, not measured

    def timed_builds(start, nin, **opts):
        times = []
        for k in range(start, start + count):
            body = _make_body(k, nin)
            t0 = time.perf_counter()
            u = kernel(body, **opts)
            times.append(time.perf_counter() - t0)
            assert kernel_of(u).code.source == "compiled"
        return times

    # cold: the disk cache is off, every body and IR is new
    os.environ["REACTOR_CACHE"] = "0"
    cold = timed_builds(1000, 1)
    cold2 = timed_builds(2000, 2)
    os.environ.pop("REACTOR_CACHE")
    # populate the disk cache (for the fresh-process measurement) with other kernels
    fill = timed_builds(0, 1)

    # memo hit: the same body again
    body = _make_body(1000)
    u = kernel(body)
    memo = []
    for _ in range(200):
        t0 = time.perf_counter()
        assert kernel(body) is u
        memo.append(time.perf_counter() - t0)

    # recipe hit: a new Python function object with the same code and values (not traced)
    ir_hits = []
    for k in range(1000, 1000 + count):
        body = _make_body(k)
        t0 = time.perf_counter()
        u = kernel(body)
        ir_hits.append(time.perf_counter() - t0)
        assert kernel_of(u).code.source == "recipe, memory cache"

    return {
        "cold_ms": 1e3 * statistics.median(cold),
        "cold_min_ms": 1e3 * min(cold),
        "cold_2in_ms": 1e3 * statistics.median(cold2),
        "cold_with_disk_write_ms": 1e3 * statistics.median(fill),
        "memo_hit_ms": 1e3 * statistics.median(memo),
        "ir_cache_hit_ms": 1e3 * statistics.median(ir_hits),
    }


_CHILD = textwrap.dedent("""
    import json, sys, time
    t0 = time.perf_counter()
    sys.path.insert(0, {repo!r})
    import numpy
    import reactor
    from reactor import Float, kernel, kernel_of
    t1 = time.perf_counter()
    builds, sources = [], []
    for k in range({count}):
        scope = {{"Float": Float}}
        exec({source!r}.replace("CONST", repr(1.0 + k / 1024.0)), scope)
        t = time.perf_counter()
        u = kernel(scope["body"])
        builds.append(time.perf_counter() - t)
        sources.append(kernel_of(u).code.source)
    print(json.dumps({{"import": t1 - t0, "builds": builds, "sources": sources}}))
""")


def bench_disk_hit(count: int, cache_dir: str) -> dict:
    """Build, in a fresh interpreter, kernels whose objects are already on disk."""
    source = "def body(x: Float) -> Float:\n    return x * CONST + 1.0\n"
    assert source.replace("CONST", repr(1.0)) == _body_source(0)
    script = _CHILD.format(repo=REPO, count=count, source=source)
    env = dict(os.environ, REACTOR_CACHE_DIR=cache_dir)
    env.pop("REACTOR_CACHE", None)
    out = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True,
                         check=True, timeout=300)
    data = json.loads(out.stdout)
    assert set(data["sources"]) == {"recipe, disk cache"}, data["sources"]
    return {
        "import_ms": 1e3 * data["import"],
        "disk_first_build_ms": 1e3 * data["builds"][0],
        "disk_hit_ms": 1e3 * statistics.median(data["builds"][1:]),
    }


# -- 2. call overhead --------------------------------------------------------------------

def _best_per_call(fn, number: int, repeat: int) -> float:
    return min(timeit.repeat(fn, number=number, repeat=repeat)) / number


def bench_overhead(quick: bool) -> dict:
    from reactor import Float, kernel

    @kernel
    def neg(x: Float) -> Float:
        return -x

    res = {}
    for n in (1, 1024):
        x = np.random.default_rng(1).standard_normal(n).astype(np.float32)
        o = np.empty_like(x)
        np.testing.assert_array_equal(neg(x), np.negative(x))
        number, repeat = (20000, 5) if not quick else (2000, 3)
        mine, theirs = [], []
        for _ in range(3):  # interleave to share any frequency/noise drift
            mine.append(_best_per_call(lambda: neg(x, out=o), number, repeat))
            theirs.append(_best_per_call(lambda: np.negative(x, out=o), number, repeat))
        res[f"call_ns_{n}"] = 1e9 * min(mine)
        res[f"numpy_call_ns_{n}"] = 1e9 * min(theirs)
        res[f"overhead_ratio_{n}"] = min(mine) / min(theirs)
        # without out= (allocating the result), for reference
        res[f"alloc_call_ns_{n}"] = 1e9 * _best_per_call(lambda: neg(x), number, repeat)
        res[f"numpy_alloc_call_ns_{n}"] = 1e9 * _best_per_call(lambda: np.negative(x), number, repeat)
    return res


# -- 3. throughput -----------------------------------------------------------------------

def bench_throughput(quick: bool) -> dict:
    from reactor import Float, MulAdd, kernel

    @kernel
    def xyz(x: Float, y: Float, z: Float) -> Float:
        return x * y + z  # two roundings, like NumPy's multiply then add

    @kernel(fma=True)
    def xyz_fused(x: Float, y: Float, z: Float) -> Float:
        return MulAdd(x, y, z)

    res = {}
    rng = np.random.default_rng(2)
    for label, n, repeat in (("64K", 1 << 16, 200 if not quick else 20), ("16M", 1 << 24, 7 if not quick else 2)):
        x, y, z = (rng.standard_normal(n, dtype=np.float32) for _ in range(3))
        out, tmp = np.empty(n, np.float32), np.empty(n, np.float32)
        xyz(x, y, z, out=out)
        np.multiply(x, y, out=tmp)
        np.add(tmp, z, out=tmp)
        np.testing.assert_array_equal(out, tmp)

        def numpy_xyz():
            np.multiply(x, y, out=tmp)
            np.add(tmp, z, out=tmp)

        number = 5 if n < 1 << 20 else 1
        t_k = min(timeit.repeat(lambda: xyz(x, y, z, out=out), number=number, repeat=repeat)) / number
        t_f = min(timeit.repeat(lambda: xyz_fused(x, y, z, out=out), number=number, repeat=repeat)) / number
        t_n = min(timeit.repeat(numpy_xyz, number=number, repeat=repeat)) / number
        res[f"xyz_ns_per_elem_{label}"] = 1e9 * t_k / n
        res[f"xyz_fused_ns_per_elem_{label}"] = 1e9 * t_f / n
        res[f"numpy_ns_per_elem_{label}"] = 1e9 * t_n / n
        res[f"speedup_{label}"] = t_n / t_k
        res[f"speedup_fused_{label}"] = t_n / t_f
        del x, y, z, out, tmp
    return res


# -- report ----------------------------------------------------------------------------------

def _row(label, value, unit, key=None):
    target = ""
    if key in TARGETS:
        limit, _ = TARGETS[key]
        target = f"<= {limit:g} {TARGETS[key][1]}  {'PASS' if value <= limit else 'MISS'}"
    return f"  {label:<46} {value:>10.4g} {unit:<8} {target}"


def report(r: dict, env: dict) -> str:
    lines = [f"reactor JIT benchmark  ({env['cpu']}, width {env['width']}, fma {env['fma']}, "
             f"llvmlite {env['llvmlite']}, numpy {env['numpy']})", "", "compile time (small kernel x*c+1):"]
    lines += [
        _row("cold (no disk cache, new body), median", r["cold_ms"], "ms", "cold_ms"),
        _row("cold, fastest", r["cold_min_ms"], "ms"),
        _row("cold, 2-input kernel x*y+c, median", r["cold_2in_ms"], "ms"),
        _row("cold + disk cache write, median", r["cold_with_disk_write_ms"], "ms"),
        _row("memory hit (kernel(body) memo), median", r["memo_hit_ms"], "ms", "memo_hit_ms"),
        _row("recipe hit (new function object, same code)", r["ir_cache_hit_ms"], "ms"),
        _row("disk hit in a fresh process, median", r["disk_hit_ms"], "ms", "disk_hit_ms"),
        _row("  first build there (+ the start-up the warm-up left)", r["disk_first_build_ms"], "ms",
             "disk_first_build_ms"),
        _row("  'import numpy, reactor' there", r["import_ms"], "ms"),
        "", "call overhead (out= given) vs np.negative:",
    ]
    for n in (1, 1024):
        lines += [
            _row(f"kernel, n={n}", r[f"call_ns_{n}"], "ns"),
            _row(f"np.negative, n={n}", r[f"numpy_call_ns_{n}"], "ns"),
            _row(f"ratio, n={n}", r[f"overhead_ratio_{n}"], "x", f"overhead_ratio_{n}"),
            _row(f"  without out=: kernel / numpy, n={n}",
                 r[f"alloc_call_ns_{n}"] / r[f"numpy_alloc_call_ns_{n}"], "x"),
        ]
    lines += ["", "throughput of x*y+z (float32, out= given, best of N):"]
    for label in ("64K", "16M"):
        lines += [
            _row(f"kernel x*y+z, {label}", r[f"xyz_ns_per_elem_{label}"], "ns/elem"),
            _row(f"kernel MulAdd (fma=True), {label}", r[f"xyz_fused_ns_per_elem_{label}"], "ns/elem"),
            _row(f"numpy multiply+add, {label}", r[f"numpy_ns_per_elem_{label}"], "ns/elem"),
            _row(f"speedup over numpy, {label}", r[f"speedup_{label}"], "x"),
        ]
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--json", metavar="FILE", help="also write the figures to FILE as JSON")
    parser.add_argument("--kernels", type=int, default=20, help="distinct kernels per compile figure")
    parser.add_argument("--quick", action="store_true", help="fewer repetitions (a smoke test)")
    args = parser.parse_args(argv)

    import llvmlite

    from reactor import build_settings, get_target

    opts = build_settings()
    env = {"cpu": get_target("host").cpu, "width": opts.width, "fma": opts.fma,
           "llvmlite": llvmlite.__version__, "numpy": np.__version__, "python": sys.version.split()[0]}
    saved = {k: os.environ.get(k) for k in ("REACTOR_CACHE_DIR", "REACTOR_CACHE")}
    t0 = time.perf_counter()
    try:
        with tempfile.TemporaryDirectory(prefix="reactor-bench-") as cache_dir:
            results = bench_compile(args.kernels, cache_dir)
            results.update(bench_disk_hit(args.kernels, cache_dir))
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
    results.update(bench_overhead(args.quick))
    results.update(bench_throughput(args.quick))
    print(report(results, env))
    print(f"\n(total {time.perf_counter() - t0:.1f} s)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"env": env, "results": results,
                       "targets": {k: {"limit": v[0], "unit": v[1], "pass": results[k] <= v[0]}
                                   for k, v in TARGETS.items()}}, f, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
