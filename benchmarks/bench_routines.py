"""Issue 3's benchmark: every routine variant against NumPy at 64K float32 elements.

Same as ``python -m routines bench``; run ``python benchmarks/bench_routines.py --json out.json``.
"""
import sys

from routines.cli.bench import main

if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
