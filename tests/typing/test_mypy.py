"""mypy on the public API: reactor and routines' library modules type-check, and a user's
program (usage.py) type-checks under --strict, so every public name it uses has type hints."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

pytest.importorskip("mypy")

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
LIBRARY = ["-p", "reactor", "-m", "routines", "-m", "routines.kernels", "-m", "routines.base",
           "-m", "routines.exponential", "-m", "routines.logarithm", "-m", "routines.power",
           "-m", "routines.reciprocal", "-m", "routines.polynomials", "-m", "routines.specials",
           "-m", "routines.glsl", "-m", "routines.trig", "-m", "routines.pixels", "-m", "routines.accurate",
           "-m", "routines.doubled", "-m", "routines.correct", "-m", "routines.accurate_trig",
           "-m", "routines.accurate_inverse", "-m", "routines.accurate_hyperbolic", "-m", "routines.accurate_atan2"]


def _mypy(args, tmp_path):
    cmd = [sys.executable, "-m", "mypy", "--ignore-missing-imports", "--no-error-summary",
           "--cache-dir", str(tmp_path / "mypy-cache"), *args]
    return subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, timeout=600)


def test_the_library_type_checks(tmp_path):
    run = _mypy(LIBRARY, tmp_path)
    assert run.returncode == 0, run.stdout + run.stderr


def test_a_users_program_type_checks_strictly(tmp_path):
    run = _mypy(["--strict", "--follow-imports=silent", os.path.join("tests", "typing", "usage.py")], tmp_path)
    assert run.returncode == 0, run.stdout + run.stderr
