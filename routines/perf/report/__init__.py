"""The report: every variant's accuracy and speed beside the peers', in one run.

``run(...)`` builds every variant of ours (function x precision x FMA x SIMD
width 4/8/16) and the peers (:mod:`routines.perf.peers`), measures

* **accuracy** with the lab (:func:`routines.lab.evaluate` on
  :func:`routines.lab.sample_inputs`, or the exhaustive sweep), each variant
  against its own precision's tolerance and each peer against both;
* **speed** with the harness (:mod:`routines.perf.timing`) at the L1, L2 and
  DRAM sizes, one thread, and two threads at the DRAM size for the kernels
  reactor builds, with the clock calibrated at the start and the end
  (:mod:`routines.perf.clock`);
* the **dataflow model** of every variant (:mod:`reactor.cost`): its
  throughput bound (execution pipes) and, from the same graph, a *window*
  bound (:func:`window_bound`), with a note saying where the variant spends;

and gathers everything in one JSON-ready dict: ``print_table`` renders it,
``chart_panels`` feeds :func:`routines.perf.chart.draw`, ``check_targets``
checks the report's targets, ``to_json`` makes it JSON-safe.

One module per job: :mod:`.variants` (our variants, built and modelled),
:mod:`.bounds` (window bound, gap verdicts), :mod:`.probes` (copy floors,
machine-state probes), :mod:`.accuracy`, :mod:`.speed` (timing, clock
rescaling), :mod:`.runner` (``run``), :mod:`.targets`, :mod:`.table`,
:mod:`.panels` (chart points) and :mod:`.jsonsafe`. Nothing in this package
imports matplotlib: only :func:`routines.perf.chart.draw` does, when called.
"""
from __future__ import annotations

from .accuracy import measure_accuracy
from .bounds import DISPATCH, FP_SCHEDULER, GAP, attach_gaps, gap_verdict, window_bound
from .jsonsafe import to_json
from .panels import chart_panels, search_points
from .probes import floor_kernels, machine_state, probe_kernels
from .runner import run
from .speed import measure_speed
from .table import print_table
from .targets import check_targets
from .variants import DEFAULT, DEFAULT_FUNCTIONS, EXP_LOG, FUNCTIONS, PRECISIONS, TRIG, WIDTHS, build_variants

__all__ = [
    "run", "to_json", "print_table", "chart_panels", "search_points", "check_targets",
    "window_bound", "gap_verdict", "attach_gaps", "build_variants", "floor_kernels", "probe_kernels",
    "machine_state", "measure_accuracy", "measure_speed",
    "FUNCTIONS", "DEFAULT_FUNCTIONS", "EXP_LOG", "TRIG", "PRECISIONS", "WIDTHS", "DEFAULT", "FP_SCHEDULER", "DISPATCH", "GAP",
]
