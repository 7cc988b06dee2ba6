"""Two checkouts side by side, same run: import time, cold and warm (disk cache) build times and
call speed, each in fresh processes interleaved; and whether every routine variant's machine code is
the same (the assembly: IR text differs in value names alone when plumbing is renamed).

    git worktree add /tmp/base <commit>
    python benchmarks/bench_checkouts.py --base /tmp/base [--rounds 15]
"""
import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile

HERE = pathlib.Path(__file__).resolve().parents[1]

PROBE = r'''
import hashlib, json, sys, time
t0 = time.perf_counter()
import numpy as np
import reactor, routines
from reactor import Float, kernel
t_import = time.perf_counter() - t0
t0 = time.perf_counter()
@kernel
def axpb(x: Float) -> Float:
    return x * 2.0 + 1.0
axpb(np.zeros(16, np.float32))
t_first = time.perf_counter() - t0
t0 = time.perf_counter()
us = [routines.jit(n, "full") for n in ("exp2", "log2", "pow", "sin", "atan2", "tanh")]
from routines import glsl as gl
@kernel
def shade(nx: Float, ny: Float, lx: Float, ly: Float) -> Float:
    n = gl.normalize(reactor.vec3(nx, ny, 1.0))
    l = gl.normalize(reactor.vec3(lx, ly, 0.5))
    h = gl.normalize(n + l)
    return gl.clamp(gl.dot(n, l), 0.0, 1.0) * 0.8 + gl.pow(gl.max(gl.dot(n, h), 0.0), 32.0)
x = np.linspace(0.1, 2, 1 << 20, dtype=np.float32)
shade(x[:16], x[:16], x[:16], x[:16])
t_build = time.perf_counter() - t0
reactor.configure_threads(threads=1)
out = np.empty_like(x)
def best(f):
    b = 1e9
    for _ in range(15):
        t = time.perf_counter(); f(); b = min(b, time.perf_counter() - t)
    return b
r = {"import": t_import, "first kernel": t_first, "6 routines + shade": t_build,
     "call pow": best(lambda: us[2](x, x, out=out)), "call sin": best(lambda: us[3](x, out=out)),
     "call shade": best(lambda: shade(x, x, x, x, out=out)), "call x*2+1": best(lambda: axpb(x, out=out))}
if sys.argv[1] == "code":
    code = "".join(reactor.kernel_of(routines.jit(n, p, fma=f)).assembly for n in routines.NAMES
                   for p in ("full", "relaxed") for f in (True, False))
    r = {"code": hashlib.sha256(code.encode()).hexdigest()}
print(json.dumps(r))
'''


def probe(root: str, mode: str, cache: str | None) -> dict:
    env = dict(os.environ, PYTHONPATH=root)
    env.pop("REACTOR_CACHE_DIR", None)
    if cache is None:
        env["REACTOR_CACHE"] = "0"
    else:
        env["REACTOR_CACHE_DIR"] = cache
    out = subprocess.run([sys.executable, "-c", PROBE, mode], env=env, cwd=tempfile.gettempdir(),
                         capture_output=True, text=True, check=True).stdout
    return json.loads(out.splitlines()[-1])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--base", required=True, help="the other checkout (a git worktree)")
    p.add_argument("--rounds", type=int, default=15)
    args = p.parse_args()
    roots = {"base": str(pathlib.Path(args.base).resolve()), "head": str(HERE)}
    caches = {side: tempfile.mkdtemp(prefix=f"bench-{side}-") for side in roots}
    code = {side: probe(root, "code", None)["code"] for side, root in roots.items()}
    print(f"every full/relaxed routine variant's machine code: {'identical' if code['base'] == code['head'] else 'DIFFERENT'}")
    rows: dict = {}
    for side, root in roots.items():
        probe(root, "warm", caches[side])  # fills the disk cache
    for _ in range(args.rounds):
        for side, root in roots.items():
            for mode in ("cold", "warm"):
                for k, v in probe(root, mode, None if mode == "cold" else caches[side]).items():
                    rows.setdefault((mode, k), {}).setdefault(side, []).append(v)
    print(f"medians of {args.rounds} fresh processes each, interleaved; head/base")
    for (mode, k), sides in rows.items():
        b, h = statistics.median(sides["base"]), statistics.median(sides["head"])
        print(f"  {mode:4s} {k:20s} base {b * 1e3:9.3f} ms  head {h * 1e3:9.3f} ms  {h / b:.3f}")


if __name__ == "__main__":
    main()
