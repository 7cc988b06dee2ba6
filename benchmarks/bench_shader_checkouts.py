"""The five example shaders in two checkouts, side by side: each checkout's own port (so a port
rewritten in another form is compared with the one it replaces), the cold build (a fresh process,
its first shader, ``cache=False``, after one small kernel so that LLVM's start is not counted) and
the best call time on one thread, in fresh processes interleaved; and whether the two renders give
the same 8-bit codes.

    git worktree add /tmp/base <commit>
    python benchmarks/bench_shader_checkouts.py --base /tmp/base [--rounds 5] [--size 256]
"""
import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys

HERE = pathlib.Path(__file__).resolve().parents[1]
SHADERS = ("gltf_pbr", "noise", "raymarch", "tonemap", "sky")

PROBE = r'''
import hashlib, importlib.util, json, sys, time
import numpy as np
root, name, size = sys.argv[1], sys.argv[2], int(sys.argv[3])
sys.path.insert(0, root + "/examples/shaders")
import reactor
from reactor import Float, kernel
@kernel
def first(x: Float) -> Float:
    return x * 2.0 + 1.0
first(np.zeros(16, np.float32))
reactor.configure_threads(threads=1)
from shader_common import to_codes
spec = importlib.util.spec_from_file_location(name, f"{root}/examples/shaders/{name}.py")
module = importlib.util.module_from_spec(spec)
spec.loader.exec_module(module)
args = module.inputs(size)
t0 = time.perf_counter()
k = module.build("full")
build = time.perf_counter() - t0
out = k(*args)
calls = []
for _ in range(5):
    t0 = time.perf_counter()
    k(*args)
    calls.append(time.perf_counter() - t0)
codes = to_codes(out)
print(json.dumps({"build": build, "call": min(calls), "codes": hashlib.sha256(np.ascontiguousarray(codes).tobytes()).hexdigest()}))
'''


def probe(root: str, name: str, size: int) -> dict:
    env = dict(os.environ, PYTHONPATH=root)
    out = subprocess.run([sys.executable, "-c", PROBE, root, name, str(size)], env=env, cwd=root,
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--base", required=True)
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--size", type=int, default=256)
    a = p.parse_args()
    print(f"{'shader':10s} {'build ms base':>14s} {'head':>8s} {'head/base':>10s} {'call ms base':>13s} "
          f"{'head':>8s} {'head/base':>10s}  same codes")
    for name in SHADERS:
        runs: dict = {"base": [], "head": []}
        for _ in range(a.rounds):
            for which, root in (("base", a.base), ("head", str(HERE))):
                runs[which].append(probe(root, name, a.size))
        b = {k: statistics.median(r[k] for r in runs["base"]) for k in ("build", "call")}
        h = {k: statistics.median(r[k] for r in runs["head"]) for k in ("build", "call")}
        same = runs["base"][0]["codes"] == runs["head"][0]["codes"]
        print(f"{name:10s} {b['build'] * 1e3:14.1f} {h['build'] * 1e3:8.1f} {h['build'] / b['build']:10.3f} "
              f"{b['call'] * 1e3:13.2f} {h['call'] * 1e3:8.2f} {h['call'] / b['call']:10.3f}  {same}")


if __name__ == "__main__":
    main()
