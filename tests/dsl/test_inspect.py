"""Inspection: IR as built, optimized IR and assembly, and `python -m reactor dump`."""
import os
import re
import subprocess
import sys
import textwrap

import pytest

from reactor import Float, Function, kernel, kernel_of
from reactor.__main__ import main

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FUSED = re.compile(r"\bvfn?m(?:add|sub)", re.I)

USER_FILE = textwrap.dedent('''
    from reactor import Float, Function, MulAdd, kernel

    def _poly(x: Float, y: Float) -> Float:
        return MulAdd(x, y, 2.0)

    poly = Function(_poly, name="poly")

    @kernel
    def ufunc_poly(x: Float, y: Float) -> Float:
        return MulAdd(x, y, 2.0)

    not_reactor = 42
''')


@pytest.fixture
def user_file(tmp_path):
    path = tmp_path / "user_dsl.py"
    path.write_text(USER_FILE)
    return str(path)


def test_kernel_and_routine_text():
    @kernel(width=8, fma=False)
    def k(x: Float) -> Float:
        return x * 3.0

    kern = kernel_of(k)
    assert 'define void @"k.loop"' in kern.ir and 'define internal <8 x float> @"k.body"' in kern.ir
    assert "fmul <8 x float>" in kern.ir
    assert "define void @k.loop" in kern.optimized_ir.replace('"', "")
    assert "vmulps" in kern.assembly
    assert repr(kern) == "<reactor.Kernel k target=host width=8 fma=off precision=full>"
    r = Function(lambda x: x + 1.0, args=[Float], returns=Float, name="inc").compile()
    assert r.ir.startswith('; ModuleID = "inc"') and "fadd float" in r.ir
    assert "ret float" in r.optimized_ir and ("addss" in r.assembly or "vaddss" in r.assembly)


@pytest.mark.parametrize("what,needle", [("ir", 'define float @"poly"'), ("opt", "@llvm.fma.f32"), ("asm", "vfmadd")])
def test_dump_function(user_file, capsys, what, needle):
    assert main(["dump", f"{user_file}:poly", "--what", what, "--fma", "on", "--target", "avx2"]) == 0
    assert needle in capsys.readouterr().out


def test_dump_kernel_and_options(user_file, capsys):
    # a @kernel decorated at import time is built with the context's options
    assert main(["dump", f"{user_file}:ufunc_poly", "--what", "asm", "--fma", "off", "--width", "4"]) == 0
    asm = capsys.readouterr().out
    assert not FUSED.search(asm)
    assert re.search(r"vmulps[^\n]*%xmm", asm) and not re.search(r"vmulps[^\n]*%[yz]mm", asm)  # 4 lanes
    assert main(["dump", f"{user_file}:poly", "--what", "asm", "--fma", "off", "--opt", "1"]) == 0
    assert not FUSED.search(capsys.readouterr().out)


def test_dump_errors(user_file, capsys):
    assert main(["dump", f"{user_file}:missing"]) == 2
    assert "has no attribute 'missing'" in capsys.readouterr().err
    assert main(["dump", f"{user_file}:not_reactor"]) == 2
    assert "neither a reactor Function nor a reactor kernel" in capsys.readouterr().err
    assert main(["dump", "/no/such/file.py:x"]) == 2
    assert "no such file" in capsys.readouterr().err
    assert main(["dump", "nocolon"]) == 2


def test_dump_command_line(user_file):
    run = subprocess.run([sys.executable, "-m", "reactor", "dump", f"{user_file}:poly", "--what", "ir"],
                         capture_output=True, text=True, timeout=120, cwd=REPO,
                         env=dict(os.environ, PYTHONPATH=REPO))
    assert run.returncode == 0, run.stderr
    assert 'define float @"poly"' in run.stdout
