"""Golden IR: the as-built IR of a few tiny functions, checked in under golden/.

The header (module id, target triple and data layout) is host-specific and is
left out. After an intended change to the emitted IR, regenerate with
``REACTOR_UPDATE_GOLDEN=1 python -m pytest tests/dsl/test_golden.py`` and
review the diff.
"""
import os
import pathlib

import pytest

from reactor import (
    Float, Float4, For, Function, If, Int, Max, Min, MulAdd, Pointer, Select, Variable,
)

GOLDEN = pathlib.Path(__file__).parent / "golden"


def axpy(a: Float, x: Float, y: Float) -> Float:
    return MulAdd(a, x, y)


def relu_sum(p: Pointer[Float, "n"], n: Int) -> Float:
    acc = Variable(Float, 0.0, name="acc")
    with For(0, n) as i:
        x = p[i]
        with If(x > 0.0):
            acc += x
    return acc


def clamp4(v: Float4, lo: Float) -> Float4:
    c = Min(Max(v, lo), 1.0)
    return Select(v != v, 0.0, c)


CASES = {
    "axpy": dict(fma=True),
    "relu_sum": dict(),
    "clamp4": dict(),
}


def _body_ir(text: str) -> str:
    skip = ("; ModuleID", "target triple", "target datalayout")
    return "\n".join(line for line in text.strip().splitlines() if not line.startswith(skip)).strip() + "\n"


@pytest.mark.parametrize("name", sorted(CASES))
def test_golden_ir(name):
    fn = Function(globals()[name], target="avx2", **CASES[name])
    text = _body_ir(fn.compile().ir)
    path = GOLDEN / f"{name}.ll"
    if os.environ.get("REACTOR_UPDATE_GOLDEN"):
        path.write_text(text)
    assert text == path.read_text(), f"IR of {name} changed; see the module docstring to update"
