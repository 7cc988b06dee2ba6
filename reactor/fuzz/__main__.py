"""``python -m reactor.fuzz [--budget N --seed S]`` (the fuzz command),
``python -m reactor.fuzz memcheck [--cycles N] [--distinct]``, and the fuzz command's worker."""
import argparse
import sys

from .runner import _worker, main

if __name__ == "__main__":
    if sys.argv[1:2] == ["worker"]:
        p = argparse.ArgumentParser(prog="python -m reactor.fuzz worker")
        p.add_argument("worker")
        p.add_argument("--seed", default="0")
        p.add_argument("--start", type=int, default=0)
        p.add_argument("--count", type=int, default=1)
        a = p.parse_args()
        sys.exit(_worker(a.seed, a.start, a.count))
    if sys.argv[1:2] == ["memcheck"]:
        from .memcheck import main as memcheck_main
        sys.exit(memcheck_main(sys.argv[2:]))
    sys.exit(main())
