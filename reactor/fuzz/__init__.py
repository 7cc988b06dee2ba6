"""Differential fuzzing of the reactor DSL (issue 8).

* ``ast``: the program representation (dataclasses);
* ``generate``: random typed programs (a seeded chooser, or hypothesis: ``programs()``);
* ``emit``: a program as DSL code (a Function at any width, or a @kernel);
* ``evaluate``: the same program evaluated independently with NumPy;
* ``runner``: compile at widths 1, 4, 8, 16, run on special and random inputs,
  compare every lane (``check``), many programs (``fuzz``), the command;
* ``memcheck``: build/compile/call/drop cycles with resident memory measured.

``python -m reactor fuzz --budget N --seed S`` runs a large budget;
``python -m reactor.fuzz memcheck --cycles 10000`` the memory check. See docs/reliability.md.
"""
from .ast import Program, parse, source
from .generate import RandomChooser, generate, programs
from .runner import Result, Stats, check, fuzz, program_for, run_isolated

__all__ = ["Program", "parse", "source", "RandomChooser", "generate", "programs", "Result", "Stats",
           "check", "fuzz", "program_for", "run_isolated"]
