"""Differential fuzzing of the reactor DSL against an independent NumPy evaluation.

A development tool, not part of the shipped ``reactor`` package (it needs
hypothesis, a development dependency); it uses only reactor's public API.

* ``ast``: the program representation (dataclasses);
* ``generate``: random typed programs (a seeded chooser, or hypothesis: ``programs()``);
* ``emit``: a program as DSL code (a Function at any width, or a @kernel);
* ``evaluate``: the same program evaluated independently with NumPy;
* ``runner``: compile at widths 1, 4, 8, 16, run on special and random inputs,
  compare every lane (``check``), many programs (``fuzz``), the command;
* ``memcheck``: build/compile/call/drop cycles with resident memory measured.

``python -m fuzz --budget N --seed S`` runs a large budget (from the repository root);
``python -m fuzz.memcheck --cycles 10000`` the memory check. See docs/reliability.md.
"""
from .ast import Program, parse, source
from .generate import RandomChooser, generate, programs
from .runner import Result, Stats, check, fuzz, program_for, run_isolated

__all__ = ["Program", "parse", "source", "RandomChooser", "generate", "programs", "Result", "Stats",
           "check", "fuzz", "program_for", "run_isolated"]
