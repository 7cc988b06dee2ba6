"""Clock calibration against the latency table of this CPU.

    python benchmarks/bench_clock.py [--runs N] [--json FILE]

Times the dependent FMA chain and the dependent FADD chain (``routines.perf.clock``)
several times and prints, for each run, the clock derived from each chain with the
latencies of the microarchitecture row chosen for this host (``reactor.cost.cpus``),
and the FADD latency the two times imply. When the row is right, the two clocks
agree within a few percent and the implied FADD latency matches the table; a
disagreement names a wrong row (or an unknown core on the ``generic`` row). This
is a timing figure, so it lives here and not in the tests.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from reactor.cost import cpus  # noqa: E402
from routines.perf import clock  # noqa: E402


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--json", help="write the figures to this file")
    args = parser.parse_args(argv)
    info = cpus.cpu_model()
    row = cpus.TABLE[info["uarch"]]
    print(f"CPU: {info['name']} (vendor {info['vendor']}, family {info['family']}, model {info['model']}, "
          f"LLVM {info['llvm_cpu']})")
    print(f"table row: {row.name} (FMA {row.fma}, FADD {row.fadd} cycles; {row.source})"
          + ("" if row.known else "  [unknown core: generic assumption]"))
    runs = []
    for k in range(args.runs):
        cal = clock.calibrate()
        runs.append(cal.to_json())
        print(f"run {k + 1}: {cal.ghz:.3f} GHz (FMA chain), {cal.check_ghz:.3f} GHz (FADD chain), "
              f"implied FADD latency {cal.fadd_latency_measured:.2f} cycles")
    implied = statistics.median(r["fadd_latency_measured"] for r in runs)
    agree = abs(implied - row.fadd) / row.fadd < 0.1
    print(f"median implied FADD latency {implied:.2f} against the table's {row.fadd}: "
          + ("the row fits this core" if agree else "THE ROW DOES NOT FIT THIS CORE"))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"cpu": info, "row": row.name, "runs": runs, "implied_fadd": implied,
                       "row_fits": agree}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
