"""The library imports only what a kernel needs: constants are literals (recomputed here with
mpmath, which the library itself never imports), and ``import reactor, routines`` and building
every routine variant import neither the lab (lab, perf, search, zoo, remez, cli) nor tqdm,
matplotlib or mpmath, even when those cannot be imported at all."""
from __future__ import annotations

import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
LAB = ("routines.lab", "routines.perf", "routines.search", "routines.zoo", "routines.remez", "routines.cli",
       "tqdm", "matplotlib", "mpmath")

#: run first in a child: the lab's dependencies cannot be imported, as where the lab extra is not installed
WITHOUT_LAB_DEPENDENCIES = r'''
import importlib.abc, sys

class Refuse(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in ("tqdm", "matplotlib", "mpmath"):
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None

sys.meta_path.insert(0, Refuse())
'''

BUILD_EVERYTHING = WITHOUT_LAB_DEPENDENCIES + r'''
LAB = {lab!r}
import numpy as np
import reactor, routines
from routines import glsl, pixels
from routines.base import tiers
x = np.linspace(0.1, 2, 64, dtype=np.float32)
for name in routines.NAMES:
    for precision in tiers(name):
        for fma in (True, False):
            u = routines.jit(name, precision, fma=fma)
            u(x, x) if name in ("pow", "atan2") else u(x)

@reactor.kernel
def shade(r: reactor.Float, g: reactor.Float) -> reactor.UByte:
    c = glsl.normalize(reactor.vec3(r, g, 1.0))
    return pixels.srgb8_encode(glsl.pow(glsl.clamp(c.x, 0.0, 1.0), 2.2)) + pixels.encode(pixels.srgb8_decode(
        pixels.encode(c.y, "unorm8")), "unorm8")

shade(x, x)
loaded = sorted(m for m in sys.modules if m.startswith(tuple(LAB)))
print("loaded:", loaded)
'''


def test_the_stored_constants_are_what_the_lab_computes():
    from routines.lab import constants
    stored = (ROOT / "routines" / "constants.py").read_text()
    assert stored == constants.module_text(), "run: python -m routines.lab.constants > routines/constants.py"


def test_building_every_routine_imports_no_lab_and_no_lab_dependency(tmp_path):
    r = subprocess.run([sys.executable, "-c", BUILD_EVERYTHING.replace("{lab!r}", repr(LAB))], capture_output=True, text=True,
                       cwd=tmp_path, timeout=600, env={**__import__("os").environ, "PYTHONPATH": str(ROOT)})
    assert r.returncode == 0, r.stderr[-3000:]
    assert r.stdout.strip().endswith("loaded: []"), r.stdout[-2000:]


WITHOUT_THE_LAB = WITHOUT_LAB_DEPENDENCIES + r'''
import runpy
sys.argv = ["routines"] + sys.argv[1:]
runpy.run_module("routines", run_name="__main__")
'''


def test_a_lab_command_without_the_lab_extra_says_what_to_install(tmp_path):
    for argv in (["accuracy", "exp2"], ["ladder", "exp2"], ["report", "--quick"]):
        r = subprocess.run([sys.executable, "-c", WITHOUT_THE_LAB, *argv], capture_output=True, text=True, cwd=tmp_path,
                           timeout=300, env={**__import__("os").environ, "PYTHONPATH": str(ROOT)})
        assert r.returncode == 2 and r.stderr.count("\n") == 1, r.stderr[-2000:]
        assert "part of the laboratory's extra: pip install 'reactor-simd[lab]'" in r.stderr, r.stderr
