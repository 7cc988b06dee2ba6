"""The value and vector classes as type checkers see them (reactor/dsl/value_types.py): generated
from the run-time tables by tools/value_types.py and up to date; the same classes at run time;
``Float4 + Float4`` is a ``Float4`` and ``Float4 + Int4`` an operator error under ``mypy --strict``."""
from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys

import pytest

import reactor
from reactor.dsl import value_types

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TOOL = os.path.join(ROOT, "tools", "value_types.py")
HERE = os.path.join("tests", "typing")


def _tool():
    spec = importlib.util.spec_from_file_location("value_types_tool", TOOL)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_generated_module_is_up_to_date():
    run = subprocess.run([sys.executable, TOOL, "--check"], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert run.returncode == 0, run.stderr + "\n(regenerate with: python tools/value_types.py)"


def test_the_check_notices_a_stale_module(tmp_path, monkeypatch, capsys):
    tool = _tool()
    stale = tmp_path / "value_types.py"
    stale.write_text(tool.render().replace("-> Float4:", "-> Float8:", 1))
    monkeypatch.setattr(tool, "TARGET", stale)
    monkeypatch.setattr(tool, "ROOT", tmp_path)
    assert tool.main(["--check"]) == 1
    assert "out of date" in capsys.readouterr().err
    assert tool.main([]) == 0 and tool.main(["--check"]) == 0


def test_every_class_of_the_tables_is_declared_and_is_the_run_time_class():
    expected = ({reactor.vector_type(k, w).__name__ for k in reactor.KINDS for w in reactor.WIDTHS}
                | {f"{prefix}{n}" for _, prefix in reactor.dsl.vectors.VECTORS for n in (2, 3, 4)}
                | {"mat2", "mat3", "mat4"})
    assert set(value_types.__all__) == expected
    for name in expected:
        assert getattr(value_types, name) is getattr(reactor, name), name
        assert name in reactor.__all__, name


def test_operators_follow_the_operation_table():
    with open(os.path.join(ROOT, "reactor", "dsl", "value_types.py")) as f:
        text = f.read()
    classes = {m.group(1): (m.group(2), m.group(3)) for m in re.finditer(
        r"\n    class (\w+)\((.*?)\):(?:  # type: ignore\[misc\])?\n(.*?)(?=\n    class |\Z)", text, re.S)}

    def ops_of(name):  # the operators' class a value or vector class takes, and its body
        base = classes[name][0].split("[")[0]
        return classes[base][1]
    assert classes["Int4"][0] == '_IntOps["Int | int", "Int | int", "Bool4"], Value'
    assert "def __and__(self, other: Self | _O, /) -> Self" in ops_of("Int4")
    assert "def __and__(self, other: NoReturn, /) -> NoReturn" in ops_of("Float4")  # floats have no '&'
    assert "__neg__: None" in ops_of("UInt") or "def __neg__(self) -> Self" in ops_of("UInt")
    assert "__abs__: None" in ops_of("UInt")  # the table has abs for float and int only
    assert "def __lt__(self, other: NoReturn" in ops_of("Bool8") and "def __eq__(self, other: Self | _O" in ops_of("Bool8")
    assert classes["Bool8"][0].endswith('"Bool8"], Value')
    assert classes["vec3"][0] == '_FloatOps["_AnyFloat", "_AnyFloat", "bvec3"], Vec'
    assert "def __lt__(self, other: Self | _O, /) -> _M" in ops_of("vec3")
    declared = [n for n in classes if not n.startswith("_")]
    assert len(declared) == len(value_types.__all__) and text.count("GENERATED") == 1


def _mypy(path, tmp_path):
    cmd = [sys.executable, "-m", "mypy", "--strict", "--follow-imports=silent", "--ignore-missing-imports",
           "--no-error-summary", "--show-error-codes", "--cache-dir", str(tmp_path / "mypy-cache"), path]
    return subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT, timeout=600)


def test_types_of_expressions_pass_mypy_strict(tmp_path):
    pytest.importorskip("mypy")
    run = _mypy(os.path.join(HERE, "values_ok.py"), tmp_path)
    assert run.returncode == 0, run.stdout + run.stderr


def test_mixing_kinds_is_a_mypy_error_on_exactly_the_marked_lines(tmp_path):
    pytest.importorskip("mypy")
    path = os.path.join(HERE, "values_bad.py")
    with open(os.path.join(ROOT, path)) as f:
        expected = {n: m.group(1) for n, line in enumerate(f, 1) if (m := re.search(r"# error: ([\w-]+)", line))}
    run = _mypy(path, tmp_path)
    got = {int(m.group(1)): m.group(2) for m in re.finditer(r"values_bad\.py:(\d+): error: .*\[([\w-]+)\]$",
                                                             run.stdout, re.M)}
    assert got == expected, run.stdout
    assert 'Unsupported operand types for + ("Float4" and "Int4")  [operator]' in run.stdout


#: (expression, class the declarations give): evaluated at run time inside a build, the operators
#: must give that class too (the declarations describe the classes, they do not invent).
AT_RUN_TIME = [
    ("a + b", "Float4"), ("a * 2.0 - 1", "Float4"), ("0.5 * a", "Float4"), ("a / s", "Float4"),
    ("s - a", "Float4"), ("a % b", "Float4"), ("a ** 2", "Float4"), ("-a", "Float4"), ("abs(a)", "Float4"),
    ("a < b", "Bool4"), ("s >= a", "Bool4"), ("a == 1.0", "Bool4"), ("(a < b) & (a > 0.0) | ~m", "Bool4"),
    ("i << 2", "Int4"), ("i & n ^ 3", "Int4"), ("-i", "Int4"), ("s + 1.0", "Float"), ("n < 2", "Bool"),
    ("p + p", "vec3"), ("p * s", "vec3"), ("2.0 * p", "vec3"), ("p < p", "bvec3"), ("p[0]", "Float"),
    ("q * 3", "ivec3"), ("mat @ p", "vec3"), ("p @ mat", "vec3"), ("mat @ mat", "mat3"),
    ("mat * 2.0 + mat", "mat3"), ("mat[1]", "vec3"), ("Float4(1.0)", "Float4"), ("Float(n)", "Float"),
]


def test_the_declared_result_classes_are_those_of_the_run_time_operators():
    from reactor import Bool4, Float, Float4, Int, Int4, ivec3, mat3, vec3

    seen: dict[str, str] = {}

    def body(a, b, s, i, n, m):  # type: ignore[no-untyped-def]
        scope = {"a": a, "b": b, "s": s, "i": i, "n": n, "m": m, "p": vec3(s, 2.0, 3.0), "q": ivec3(n, 1, 2),
                 "mat": mat3(2.0), "Float4": Float4, "Float": Float}
        for expression, _ in AT_RUN_TIME:
            seen[expression] = type(eval(expression, {}, scope)).__name__
        return a

    reactor.Function(body, args=[Float4, Float4, Float, Int4, Int, Bool4], returns=Float4).compile()
    assert seen == dict(AT_RUN_TIME)
    with open(os.path.join(ROOT, HERE, "values_ok.py")) as f:
        declared = f.read()
    for expression, cls in AT_RUN_TIME[:10]:  # the same claims are checked statically there
        assert f"assert_type({expression}, {cls})" in declared, expression
