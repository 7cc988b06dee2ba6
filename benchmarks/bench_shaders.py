"""The five shader ports of examples/shaders against their peers, one thread each.

    python benchmarks/bench_shaders.py [--size 512 | --sizes 256 1024] [--repeat 5] [--only raymarch,noise]
                                       [--json out.json] [--readme examples/shaders/README.md]

For every port (examples/shaders/<name>.py): the reactor kernel at full and relaxed precision, the
NumPy float32 version of the example, and, when importable, the same shader for numba
(benchmarks/shaders/<name>_numba.py: ``@njit(parallel=True)`` over ``prange``, run with numba's
threads set to 1) and for Dr.Jit's LLVM backend (benchmarks/shaders/<name>_drjit.py: ``dr.freeze``d,
``dr.set_thread_count(1)``). A peer that cannot be imported is reported absent (with the reason).

Per row: run time (best of --repeat calls after a warm-up; the NumPy ray marcher, ~1 s a call, once),
first-call time (reactor: the build, traced and compiled without its disk cache; numba: the JIT
compilation on the first call; Dr.Jit: tracing, compiling or loading from its kernel cache, and the
first run) and the 8-bit codes that differ from the example's float64 reference (count, more than one
code off, largest difference). Dr.Jit's time is its frozen function's replay plus ``dr.eval``, on
arrays already on the Jit side (the copies from and to NumPy are not counted); numba's and reactor's
include allocating their outputs.
"""
from __future__ import annotations

import argparse
import importlib.util
import json
import os
import sys
import time

import numpy as np

# numba's OpenMP threads would otherwise spin after a parallel region and slow the next timings down
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
EXAMPLES = os.path.join(ROOT, "examples", "shaders")
PEERS = os.path.join(HERE, "shaders")
NAMES = ("gltf_pbr", "noise", "raymarch", "tonemap", "sky")
SLOW_NUMPY = {"raymarch"}


def _load(path: str, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def load_example(name: str):
    if EXAMPLES not in sys.path:
        sys.path.insert(0, EXAMPLES)
    return _load(os.path.join(EXAMPLES, f"{name}.py"), f"shader_example_{name}")


def load_peer(name: str, peer: str):
    """(module, None) or (None, why it is absent)."""
    path = os.path.join(PEERS, f"{name}_{peer}.py")
    if not os.path.exists(path):
        return None, "no port"
    try:
        return _load(path, f"shader_peer_{name}_{peer}"), None
    except ImportError as e:   # the peer's package is not installed
        return None, f"not importable: {e}"


def _best(fn, *args, repeat: int) -> float:
    best = float("inf")
    for _ in range(max(1, repeat)):
        t0 = time.perf_counter()
        fn(*args)
        best = min(best, time.perf_counter() - t0)
    return best * 1e3


def _first(fn, *args):
    t0 = time.perf_counter()
    out = fn(*args)
    return out, (time.perf_counter() - t0) * 1e3


def _channels(out):
    """A kernel's or a function's result as a tuple of channels (one output is a bare array)."""
    return out if isinstance(out, tuple) else (out,)


def bench(name: str, size: int, repeat: int) -> dict:
    ex = load_example(name)                # puts examples/shaders on sys.path
    from shader_common import compare, single_thread, timed_build

    args = ex.inputs(size)
    ref = ex.reference(args)
    rows: dict = {}
    with single_thread():
        for precision in ("full", "relaxed"):
            k, build_ms = timed_build(ex.build, precision)
            out = k(*args)
            rows[f"reactor {precision}"] = {"ms": _best(k, *args, repeat=repeat), "first_ms": build_ms,
                                            "accuracy": compare(_channels(out), ref)}
    with np.errstate(all="ignore"):
        out, first = _first(ex.numpy_shader, *args)
        ms = first if name in SLOW_NUMPY else _best(ex.numpy_shader, *args, repeat=repeat)
    rows["numpy float32"] = {"ms": ms, "first_ms": first, "accuracy": compare(_channels(out), ref)}

    numba_mod, why = load_peer(name, "numba")
    if numba_mod is None:
        rows["numba"] = {"absent": why}
    else:
        import numba
        threads = numba.get_num_threads()
        numba.set_num_threads(1)
        try:
            out, first = _first(numba_mod.render, *args)
            rows["numba"] = {"ms": _best(numba_mod.render, *args, repeat=repeat), "first_ms": first,
                             "accuracy": compare(_channels(out), ref)}
        finally:
            numba.set_num_threads(threads)

    drjit_mod, why = load_peer(name, "drjit")
    if drjit_mod is None:
        rows["drjit"] = {"absent": why}
    else:
        import drjit as dr
        threads = dr.thread_count()
        dr.set_thread_count(1)
        try:
            prepared = drjit_mod.prepare(*args)
            _, first = _first(drjit_mod.run, *prepared)
            out = drjit_mod.render(*args)
            rows["drjit"] = {"ms": _best(drjit_mod.run, *prepared, repeat=repeat), "first_ms": first,
                             "accuracy": compare(_channels(out), ref)}
        finally:
            dr.set_thread_count(threads)
    return {"shader": name, "size": size, "rows": rows}


def table(results: list) -> str:
    lines = [f"{'shader':10s}{'peer':16s}{'ms':>10s}{'vs reactor':>11s}{'first ms':>10s}"
             f"{'codes differing':>17s}{'>1 code':>9s}{'max':>5s}"]
    for r in results:
        base = r["rows"]["reactor full"]["ms"]
        for peer, row in r["rows"].items():
            if "absent" in row:
                lines.append(f"{r['shader']:10s}{peer:16s}  absent ({row['absent']})")
                continue
            a = row["accuracy"]
            lines.append(f"{r['shader']:10s}{peer:16s}{row['ms']:10.2f}{row['ms'] / base:10.1f}x{row['first_ms']:10.0f}"
                         f"{a['codes_differing']:>17,d}{a['codes_over_1']:>9,d}{a['max_code_diff']:>5d}")
    return "\n".join(lines)


def readme_table(results: list) -> str:
    """The README's table of one run: per shader and size, the run times, Dr.Jit's over reactor's,
    and the first calls (reactor: its build without caches; Dr.Jit: tracing and compiling or
    loading from its cache, and the first run)."""
    lines = ["| port | pixels | reactor full ms | reactor relaxed ms | NumPy f32 ms | numba ms | Dr.Jit ms | "
             "Dr.Jit / reactor full | first call: reactor / Dr.Jit ms |", "|---|---|---|---|---|---|---|---|---|"]

    def ms(row):
        return "absent" if "absent" in row else f"{row['ms']:.3g}"
    for r in results:
        rows, full = r["rows"], r["rows"]["reactor full"]
        drjit = rows.get("drjit", {"absent": ""})
        ratio = "-" if "absent" in drjit else f"{drjit['ms'] / full['ms']:.2f}x"
        first = f"{full['first_ms']:.0f} / " + ("-" if "absent" in drjit else f"{drjit['first_ms']:.0f}")
        lines.append(f"| {r['shader']} | {r['size']}² | {ms(full)} | {ms(rows['reactor relaxed'])} | "
                     f"{ms(rows['numpy float32'])} | {ms(rows.get('numba', {'absent': ''}))} | {ms(drjit)} | "
                     f"{ratio} | {first} |")
    return "\n".join(lines)


#: The markers around the generated table in examples/shaders/README.md
BEGIN, END = "<!-- bench_shaders: begin -->", "<!-- bench_shaders: end -->"


def write_readme(path: str, results: list, command: str) -> None:
    """Replace the text between ``BEGIN`` and ``END`` in ``path`` by this run's table."""
    with open(path) as f:
        text = f.read()
    if BEGIN not in text or END not in text:
        raise SystemExit(f"{path} has no {BEGIN} ... {END} markers")
    head, rest = text.split(BEGIN, 1)
    tail = rest.split(END, 1)[1]
    import platform
    body = (f"\nGenerated by `{command}` on {time.strftime('%Y-%m-%d')} ({platform.processor() or platform.machine()}, "
            f"NumPy {np.__version__}; one thread, best of the repeats):\n\n{readme_table(results)}\n")
    with open(path, "w") as f:
        f.write(head + BEGIN + body + END + tail)


def main(argv=None) -> list:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--sizes", type=int, nargs="+", default=None, help="several sizes in one run")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--only", default="", help="comma-separated shader names")
    parser.add_argument("--json", default=None, help="write the results here")
    parser.add_argument("--readme", default=None, metavar="FILE",
                        help="write this run's table into FILE between its bench_shaders markers "
                             "(examples/shaders/README.md)")
    args = parser.parse_args(argv)
    names = [n for n in args.only.split(",") if n] or list(NAMES)
    results: list = []
    for size in args.sizes or [args.size]:
        for name in names:
            results.append(bench(name, size, args.repeat))
            print(table(results[-1:]).split("\n", 1)[1] if results[:-1] else table(results[-1:]), flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)
        print(f"wrote {args.json}")
    if args.readme:
        write_readme(args.readme, results, "python benchmarks/bench_shaders.py " + " ".join(argv or sys.argv[1:]))
        print(f"wrote {args.readme}")
    return results


if __name__ == "__main__":
    main()
