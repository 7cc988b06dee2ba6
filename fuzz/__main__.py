"""``python -m fuzz [--budget N --seed S] [--in-process] [--quiet]`` (the fuzz command), and
``python -m fuzz worker --seed S --start K --count N``, the worker process the command starts.
The memory check is ``python -m fuzz.memcheck``."""
import argparse
import sys

from .runner import _worker, main

if __name__ == "__main__":
    if sys.argv[1:2] == ["worker"]:
        p = argparse.ArgumentParser(prog="python -m fuzz worker")
        p.add_argument("worker")
        p.add_argument("--seed", default="0")
        p.add_argument("--start", type=int, default=0)
        p.add_argument("--count", type=int, default=1)
        a = p.parse_args()
        sys.exit(_worker(a.seed, a.start, a.count))
    sys.exit(main())
