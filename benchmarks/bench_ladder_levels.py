"""The accuracy ladder beside its peers at every x86 level this CPU runs: an AVX2 (and SSE4)
host modelled on a wider one.

For each level (avx512, avx2, sse4 where the CPU runs it), a child process runs
``routines.perf.frontier.run`` (every tier and every peer: time per element on one thread,
max ULP-32 on a sample of every binade, which of our points dominates each peer) with
our tiers built for that level, NumPy restricted to it (``NPY_DISABLE_CPU_FEATURES``, as
bench_targets.py does) and libmvec, SLEEF and SVML at its vector-function level
(``ROUTINES_PEER_LEVEL``). The error points do not depend on the level (our results are the
same bits at every level; the peers' may differ slightly).

    python benchmarks/bench_ladder_levels.py [--levels avx512 avx2] [--functions exp2 log2]
        [--rounds 21] [--json out/ladder_levels.json] [--markdown] [--chart out]
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

NUMPY_DISABLED = {"sse4": "X86_V3 X86_V4 AVX512_ICL AVX512_SPR", "avx2": "X86_V4 AVX512_ICL AVX512_SPR", "avx512": ""}


def child(level: str, functions: list[str], rounds: int) -> list[dict]:
    from routines.perf import frontier
    return frontier.to_json(frontier.run(functions, rounds=rounds, target=level))


def main(argv=None) -> int:
    from routines.perf import frontier

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--levels", nargs="+", choices=list(NUMPY_DISABLED), default=list(NUMPY_DISABLED)[::-1])
    p.add_argument("--functions", nargs="+", choices=frontier.FUNCS, default=list(frontier.FUNCS))
    p.add_argument("--rounds", type=int, default=21)
    p.add_argument("--json", metavar="FILE")
    p.add_argument("--markdown", action="store_true", help="print each level's table and statements")
    p.add_argument("--chart", metavar="DIR", help="draw each level's DIR/ladder_<level>.png")
    p.add_argument("--child", choices=list(NUMPY_DISABLED), help=argparse.SUPPRESS)
    args = p.parse_args(argv)
    if args.child:
        print(json.dumps(child(args.child, args.functions, args.rounds)))
        return 0
    import reactor
    out = {}
    for level in args.levels:
        if not reactor.get_target(level).runnable:
            print(f"{level}: this CPU does not run it")
            continue
        env = dict(os.environ, ROUTINES_PEER_LEVEL=level, NPY_DISABLE_CPU_FEATURES=NUMPY_DISABLED[level])
        if not NUMPY_DISABLED[level]:
            env.pop("NPY_DISABLE_CPU_FEATURES")
            env.pop("ROUTINES_PEER_LEVEL")
        done = subprocess.run([sys.executable, __file__, "--child", level, "--rounds", str(args.rounds),
                               "--functions", *args.functions], env=env, capture_output=True, text=True)
        if done.returncode:
            print(done.stderr, file=sys.stderr)
            return 1
        points = frontier.from_json(json.loads(done.stdout.strip().splitlines()[-1]))
        out[level] = frontier.to_json(points)
        present = [q for q in points if not q.ours and q.present]
        dominated = sum(q.dominated_by is not None for q in present)
        print(f"{level}: {dominated} of {len(present)} present peers dominated")
        if args.chart:
            os.makedirs(args.chart, exist_ok=True)
            frontier.chart(points, os.path.join(args.chart, f"ladder_{level}.png"))
        if args.markdown:
            print(frontier.table(points))
            print("\n".join(f"- {line}" for line in frontier.statements(points)))
        else:
            for line in frontier.statements(points):
                if "NOT dominated" in line:
                    print(f"  {line}")
    if args.json:
        os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
