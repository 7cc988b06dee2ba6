"""The dataflow cost model of a kernel's vector loop: cycles per element on a CPU's table.

* :mod:`reactor.cost.model` -- the model (``predict``, ``predict_kernel``, ``kernel_cycles``)
  and the CPU tables (``MACHINES``, ``machine_for``, ``host_machine``);
* :mod:`reactor.cost.cpus` -- which core this is (from /proc/cpuinfo and LLVM's CPU name) and
  its FMA and FADD latencies;
* :mod:`reactor.cost.lines` -- each instruction's share of the cost, for ``reactor.explain``.

``reactor.plan`` ranks builds by :func:`kernel_cycles`; ``reactor.explain`` shows
:func:`line_costs`; routines' report and variant search predict with the same model.
"""
from __future__ import annotations

from . import cpus, lines, model
from .lines import line_costs
from .model import MACHINES, Machine, Prediction, host_machine, kernel_cycles, machine_for, predict, predict_kernel

__all__ = ["MACHINES", "Machine", "Prediction", "cpus", "host_machine", "kernel_cycles", "line_costs", "lines",
           "machine_for", "model", "predict", "predict_kernel"]
