"""The import graph matches docs/architecture.md: arrows only point down, llvmlite
is spoken only behind the seam, no private name crosses a package boundary, and no import
cycle exists inside reactor.

Every module of the shipped packages (reactor, routines) is parsed (not imported);
each import, including those inside functions, is an arrow (not those under
``if TYPE_CHECKING:``, which only annotations read)."""
from __future__ import annotations

import ast
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]

#: reactor's layers, lowest first; a module may import its own layer or lower ones,
#: and never a sibling package of its own rank.
LAYERS = {
    "reactor.errors": 0, "reactor.source": 0, "reactor.travel": 0, "reactor.targets": 0, "reactor.build": 0, "reactor.ir.types": 0,
    "reactor.ir": 1, "reactor.jit": 1,
    "reactor.dsl": 2,
    "reactor.runtime": 3, "reactor.kernels": 3,
    "reactor.cost": 4, "reactor.explain": 4, "reactor.planner": 4, "reactor.spirv": 4,
    "reactor.cli": 4, "reactor.__main__": 4, "reactor": 4,
}
#: Where llvmlite may be imported: behind the seam, and the measurement tools that read optimized IR.
LLVMLITE_ALLOWED = ("reactor.ir", "reactor.jit", "reactor.targets", "reactor.cost", "routines.perf")
#: reactor modules other packages may import (reactor's public face).
PUBLIC = {"reactor", "reactor.cli", "reactor.cost"}


def _modules():
    for package in ("reactor", "routines"):
        for path in sorted((ROOT / package).rglob("*.py")):
            rel = path.relative_to(ROOT).with_suffix("")
            parts = list(rel.parts)
            if parts[-1] == "__init__":
                parts.pop()
            yield ".".join(parts), path


def _imports(name: str, path: pathlib.Path):
    """(imported module, imported names, line) for every import statement of a module."""
    tree = ast.parse(path.read_text(), str(path))
    is_package = path.name == "__init__.py"
    for node in ast.walk(tree):
        if _type_checking_only(node):  # imports for annotations only are never executed
            for inner in ast.walk(node):
                inner._type_only = True  # type: ignore[attr-defined]
        if getattr(node, "_type_only", False):
            continue
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, [], node.lineno
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = name.split(".")
                base = base[: len(base) - node.level + (1 if is_package else 0)]
                module = ".".join(base + ([node.module] if node.module else []))
            else:
                module = node.module
            yield module, [a.name for a in node.names], node.lineno


def _type_checking_only(node) -> bool:
    """``if TYPE_CHECKING:`` or ``if typing.TYPE_CHECKING:``."""
    test = getattr(node, "test", None) if isinstance(node, ast.If) else None
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _layer(module: str):
    best = None
    for prefix, rank in LAYERS.items():
        # "reactor" is the package's face only: a module of its own must be in the map
        if module == prefix or prefix != "reactor" and module.startswith(prefix + "."):
            if best is None or len(prefix) > len(best[0]):
                best = (prefix, rank)
    return best


def _package(module: str) -> str:
    """The unit a private name must not leave: reactor's layer packages, routines' subpackages."""
    parts = module.split(".")
    return ".".join(parts[:2]) if len(parts) > 1 else parts[0]


MODULES = dict(_modules())
EDGES = [(src, dst, names, line) for src, path in MODULES.items() for dst, names, line in _imports(src, path)]


def test_the_graph_was_read():
    assert len(MODULES) > 60 and len(EDGES) > 200
    assert any(dst == "reactor.ir" and "emitter" in names for _, dst, names, _ in EDGES)


def test_reactor_never_imports_routines():
    bad = [(s, d, line) for s, d, _, line in EDGES if s.startswith("reactor") and d.split(".")[0] == "routines"]
    assert not bad, bad


def test_arrows_only_point_down_in_reactor():
    bad = []
    for src, dst, names, line in EDGES:
        if not (src.startswith("reactor") and dst.split(".")[0] == "reactor"):
            continue
        targets = [dst] + [f"{dst}.{n}" for n in names if f"{dst}.{n}" in MODULES]
        s = _layer(src)
        for target in targets:
            d = _layer(target)
            if s is None or d is None:
                bad.append((src, target, line, "module not in the layer map"))
            elif d[1] > s[1] or (d[1] == s[1] and d[0] != s[0] and 0 < s[1] < 4):
                bad.append((src, target, line, f"{s[0]} (layer {s[1]}) -> {d[0]} (layer {d[1]})"))
    assert not bad, "\n".join(map(str, bad))


def _reactor_graph() -> dict:
    """reactor's modules -> {imported reactor module: line}, imports inside functions included;
    ``from package import module`` is an arrow to the module (not to the package)."""
    graph: dict = {}
    for src, dst, names, line in EDGES:
        if not (src.startswith("reactor") and dst and dst.startswith("reactor")):
            continue
        modules = [f"{dst}.{n}" for n in names if f"{dst}.{n}" in MODULES]
        for target in modules + ([dst] if len(modules) < len(names) or not names else []):
            if target in MODULES and target != src:
                graph.setdefault(src, {}).setdefault(target, line)
    return graph


def _cycles(graph: dict) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index: dict = {}
    low: dict = {}
    stack: list = []
    found: list = []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in graph.get(v, {}):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_no_import_cycle_inside_reactor():
    graph = _reactor_graph()
    cycles = _cycles(graph)
    text = [" -> ".join(c) + ": " + ", ".join(f"{a}:{graph[a][b]} imports {b}" for a in c for b in graph.get(a, {})
                                             if b in c) for c in cycles]
    assert not cycles, "\n".join(text)


def test_the_cycle_check_sees_a_cycle():
    assert _cycles({"a": {"b": 1}, "b": {"c": 2}, "c": {"a": 3}, "d": {"a": 4}}) == [["a", "b", "c"]]


def test_llvmlite_only_behind_the_seam():
    bad = [(s, line) for s, d, _, line in EDGES if d.split(".")[0] == "llvmlite"
           and not s.startswith(LLVMLITE_ALLOWED)]
    assert not bad, bad


def test_only_the_emitter_drives_irbuilder():
    users = [s for s, path in MODULES.items() if "IRBuilder(" in path.read_text()]
    assert users == ["reactor.ir.emitter"]


def test_routines_uses_reactors_public_face_only():
    bad = [(s, d, line) for s, d, _, line in EDGES
           if s.startswith("routines") and d.split(".")[0] == "reactor" and d not in PUBLIC]
    assert not bad, bad


def test_no_private_name_crosses_a_package():
    bad = []
    for src, dst, names, line in EDGES:
        if dst.split(".")[0] not in ("reactor", "routines") or _package(src) == _package(dst):
            continue
        bad += [(src, f"{dst}.{n}", line) for n in names if n.startswith("_") and n != "__version__"]
        bad += [(src, dst, line)] if any(part.startswith("_") and part != "__main__" for part in dst.split(".")) else []
    for src, path in MODULES.items():  # attribute access such as reactor.x._private
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__"):
                base = node.value
                if isinstance(base, ast.Name) and base.id in ("reactor", "routines") and \
                        base.id != src.split(".")[0]:
                    bad.append((src, f"{base.id}.{node.attr}", node.lineno))
    assert not bad, bad


@pytest.mark.parametrize("package", ["reactor", "routines"])
def test_shipped_code_names_no_issue_numbers(package):
    import re
    pattern = re.compile(r"\bissues? #?\d+|\(#\d+\)|\bsession \d+\b|\bon this machine\b", re.I)
    bad = [f"{p.relative_to(ROOT)}:{i}" for p in sorted((ROOT / package).rglob("*.py"))
           for i, line in enumerate(p.read_text().splitlines(), 1) if pattern.search(line)]
    assert not bad, bad


def test_the_map_in_the_docs_names_every_layer():
    text = (ROOT / "docs" / "architecture.md").read_text()
    for prefix in LAYERS:
        if prefix != "reactor":
            assert f"`{prefix}`" in text, prefix
