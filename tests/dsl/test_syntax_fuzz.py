"""Differential testing of plain Python control flow in kernels: random bodies with nested if/elif/
else on per-lane conditions (and, or, not, chained comparisons), conditional expressions, while and
for-range loops with break and continue, early returns, names assigned on some paths, calls of a
plain helper with the same (its early returns returning from it, per lane), each built
as a kernel and compared lane by lane with the same source run as plain Python on float32 scalars,
element by element (Python's own semantics)."""
from __future__ import annotations

import importlib.util
import os
import random
import sys

import numpy as np
import pytest

PROGRAMS = int(os.environ.get("REACTOR_SYNTAX_FUZZ", "60"))  # more: REACTOR_SYNTAX_FUZZ=1000
HEADER = "import reactor\nfrom reactor import Float, Int\n\n\n"
VARS = ("a", "b", "c")


class Program:
    """A random body over inputs x, y (Float) and n (Int, 0..6): every loop bounded by a counter."""

    def __init__(self, seed: int, helper: str | None = None) -> None:
        self.rng = random.Random(seed)
        self.loops = 0
        self.helper = helper  # a helper function's name the expressions may call

    def expr(self, depth: int = 0) -> str:
        r = self.rng.random()
        if depth > 1 or r < 0.35:
            return self.rng.choice(["x", "y", "a", "b", "c", f"{self.rng.choice([0.5, 1.5, 2.0, -0.75])}"])
        if depth == 0 and r < 0.45:
            return f"({self.expr(1)} if {self.cond(1)} else {self.expr(1)})"
        if depth == 0 and r < 0.52 and self.helper:
            return f"{self.helper}({self.expr(1)}, {self.expr(1)}, n)"
        op = self.rng.choice(["+", "-", "*"])
        return f"({self.expr(depth + 1)} {op} {self.expr(depth + 1)})"

    def cond(self, depth: int = 0) -> str:
        r = self.rng.random()
        if depth == 0 and r < 0.15:
            return f"{self.cond(1)} {self.rng.choice(['and', 'or'])} {self.cond(1)}"
        if depth == 0 and r < 0.22:
            return f"not ({self.cond(1)})"
        if depth == 0 and r < 0.28:
            return f"{self.expr(2)} < {self.expr(2)} <= {self.expr(2)}"
        left, right = self.expr(1), self.expr(1)
        return f"{left} {self.rng.choice(['<', '>', '<=', '>='])} {right}"

    def block(self, depth: int, indent: int, in_loop: bool) -> list[str]:
        pad = "    " * indent
        out = []
        for _ in range(self.rng.randint(1, 3)):
            r = self.rng.random()
            if depth < 3 and r < 0.3:
                out.append(f"{pad}if {self.cond()}:")
                out += self.block(depth + 1, indent + 1, in_loop)
                if self.rng.random() < 0.4:
                    out.append(f"{pad}elif {self.cond()}:")
                    out += self.block(depth + 1, indent + 1, in_loop)
                if self.rng.random() < 0.6:
                    out.append(f"{pad}else:")
                    out += self.block(depth + 1, indent + 1, in_loop)
            elif depth < 2 and r < 0.42 and self.loops < 2:
                self.loops += 1
                k = f"k{self.loops}"
                if self.rng.random() < 0.5:
                    out.append(f"{pad}{k} = 0")
                    out.append(f"{pad}while {k} < n + {self.rng.randint(0, 2)}:")
                    out.append(f"{pad}    {k} = {k} + 1")
                else:
                    out.append(f"{pad}for {k} in range(n):")
                out += self.block(depth + 1, indent + 1, True)
            elif in_loop and r < 0.5:
                out.append(f"{pad}if {self.cond()}:")
                out.append(f"{pad}    {self.rng.choice(['break', 'continue'])}")
            elif r < 0.55:
                out.append(f"{pad}if {self.cond()}:")
                out.append(f"{pad}    return {self.expr()}")
            else:
                v = self.rng.choice(VARS)
                out.append(f"{pad}{v} {self.rng.choice(['=', '+=', '*='])} {self.expr()}")
        return out

    def source(self, name: str) -> str:
        """The body, after a plain helper (``<name>_h``, early returns and all) it may call."""
        helper = Program(self.rng.randrange(2**32))
        lines = ["    a = x", "    b = y", "    c = 0.5"] + helper.block(0, 1, False) + ["    return a - b * c"]
        text = f"def {name}_h(x, y, n):\n" + "\n".join(lines) + "\n\n\n"
        self.helper = f"{name}_h"
        body = ["    a = x", "    b = y", "    c = 0.25"] + self.block(0, 1, False) + ["    return a + b * c"]
        return text + f"def {name}(x: Float, y: Float, n: Int) -> Float:\n" + "\n".join(body) + "\n"


def _module(tmp_path, sources: dict[str, str]):
    path = tmp_path / "syntax_fuzz_programs.py"
    text = HEADER
    for name, src in sources.items():
        text += src + "\n\n"
        own = src[src.index(f"def {name}("):]  # the body (its helper is shared: plain Python for both)
        text += own.replace(f"def {name}(", f"def {name}_py(").replace(": Float", "").replace(": Int", "") \
            .replace(" -> Float", "") + "\n\n"
    path.write_text(text)
    spec = importlib.util.spec_from_file_location("syntax_fuzz_programs", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules["syntax_fuzz_programs"] = module
    spec.loader.exec_module(module)
    return module


def _inputs(rng, count):
    x = rng.uniform(-3, 3, count).astype(np.float32)
    y = rng.uniform(-3, 3, count).astype(np.float32)
    n = rng.integers(0, 7, count).astype(np.int32)
    return x, y, n


def test_plain_control_flow_matches_python_per_element(tmp_path):
    import reactor

    sources = {f"prog{i}": Program(20261128 + i).source(f"prog{i}") for i in range(PROGRAMS)}
    module = _module(tmp_path, sources)
    rng = np.random.default_rng(7)
    mismatches = []
    for name in sources:
        ufunc = reactor.kernel(reactor.syntax(getattr(module, name)), name=name)
        reference = getattr(module, f"{name}_py")
        x, y, n = _inputs(rng, 37)  # a vector loop and a tail
        with np.errstate(all="ignore"):
            want = np.array([reference(np.float32(a), np.float32(b), int(k)) for a, b, k in zip(x, y, n)],
                            np.float32)
        got = ufunc(x, y, n)
        strided = ufunc(np.repeat(x, 2)[::2], y, n)  # a strided operand
        broadcast = ufunc(x, y[:1], n)  # a broadcast one
        with np.errstate(all="ignore"):
            want_b = np.array([reference(np.float32(a), np.float32(y[0]), int(k)) for a, k in zip(x, n)], np.float32)
        for what, g, w in (("contiguous", got, want), ("strided", strided, want), ("broadcast", broadcast, want_b)):
            if not np.array_equal(g.view(np.uint32), w.view(np.uint32)):
                bad = int(np.flatnonzero(g.view(np.uint32) != w.view(np.uint32))[0])
                mismatches.append(f"{name} ({what}) lane {bad}: got {g[bad]!r}, want {w[bad]!r}\n{sources[name]}")
    assert not mismatches, f"{len(mismatches)} mismatches in {PROGRAMS} programs; first:\n" + mismatches[0]


@pytest.mark.parametrize("length", range(34))
def test_every_tail_length(tmp_path, length):
    import reactor

    src = Program(99 + length).source("tail_prog")
    module = _module(tmp_path, {"tail_prog": src})
    ufunc = reactor.kernel(reactor.syntax(module.tail_prog), name=f"tail_prog_{length}")
    x, y, n = _inputs(np.random.default_rng(length), length)
    with np.errstate(all="ignore"):
        want = np.array([module.tail_prog_py(np.float32(a), np.float32(b), int(k)) for a, b, k in zip(x, y, n)],
                        np.float32)
    assert np.array_equal(ufunc(x, y, n).view(np.uint32), want.reshape(-1).view(np.uint32))
