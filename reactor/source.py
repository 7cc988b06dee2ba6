"""The Python source of a DSL body: its syntax tree, walked once for every question.

Errors found after a body ran (its returned value, a Python ``return`` inside a
run-time block) are reported at the user's line, which needs the body's
source. ``body_tree(code)`` parses it once per code object; ``walk(tree)``
visits the body's own statements (not those of nested functions or classes)
with the name of the innermost run-time block (``If``, ``For`` ...) around each.
"""
from __future__ import annotations

import ast
import functools
import inspect
import linecache
import textwrap
import threading

#: CPython's conversions between source, syntax trees and code keep a recursion count that is not
#: safe across threads (3.11: "AST constructor recursion depth mismatch"): one at a time
AST_LOCK = threading.Lock()

#: The context managers whose bodies run at run time, per lane or per iteration.
RUNTIME_BLOCKS = frozenset({"If", "Elif", "Else", "For", "While"})


@functools.lru_cache(maxsize=1024)
def body_tree(code) -> tuple[ast.FunctionDef | ast.AsyncFunctionDef, int] | None:
    """(the ``def`` node, the file line of its first source line) of a code object, or None."""
    if code is None:
        return None
    try:
        lines, start = _source_lines(code)
        with AST_LOCK:
            tree = ast.parse(textwrap.dedent("".join(lines)))
    except (OSError, TypeError, SyntaxError, IndentationError):
        return None
    fn = tree.body[0] if tree.body else None
    if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
        return None
    return fn, start


def _source_lines(code) -> tuple[list[str], int]:
    """``inspect.getsourcelines(code)`` for a function's code object, read through ``linecache``
    by its file name: inspect's own search for the module walks ``sys.modules`` (0.5-1 ms a
    build). Raises OSError where the source is not available (``exec``'d text, a REPL line)."""
    filename = code.co_filename
    linecache.checkcache(filename)
    lines = linecache.getlines(filename)
    first = code.co_firstlineno - 1
    if not lines and filename.startswith("<") and filename.endswith(">"):
        raise OSError(f"no source for code from {filename}")
    if not lines or not 0 <= first < len(lines):
        return inspect.getsourcelines(code)  # a zip import or a loader linecache has not seen yet
    return inspect.getblock(lines[first:]), first + 1


def _block_name(node: ast.With) -> str | None:
    for item in node.items:
        call = item.context_expr
        if isinstance(call, ast.Call):
            f = call.func
            name = f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else None
            if name in RUNTIME_BLOCKS:
                return name
    return None


def walk(node, block: str | None = None):
    """Yield ``(node, innermost run-time block name or None)`` for the body's own nodes."""
    for child in ast.iter_child_nodes(node):
        if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda, ast.ClassDef)):
            continue  # nested scopes are not this body
        yield child, block
        inner = _block_name(child) if isinstance(child, ast.With) else None
        yield from walk(child, inner or block)


def return_lines(code) -> list[tuple[int, str | None]]:
    """File lines of the body's ``return <value>`` statements, with their enclosing block."""
    parsed = body_tree(code)
    if parsed is None:
        return []
    fn, start = parsed
    return [(start + node.lineno - 1, block) for node, block in walk(fn)
            if isinstance(node, ast.Return) and node.value is not None]


@functools.lru_cache(maxsize=1024)
def returns_in_blocks(code):
    """``((file, line), block)`` of the first ``return`` inside a run-time block, or None."""
    parsed = body_tree(code)
    if parsed is None:
        return None
    fn, start = parsed
    for node, block in walk(fn):
        if isinstance(node, ast.Return) and block:
            return (code.co_filename, start + node.lineno - 1), block
    return None


def with_block_calls(code, line: int) -> set[str] | None:
    """The names called inside the ``with`` statement at ``line`` of ``code``'s body (its own
    statements and nested blocks, not nested functions), or None if the source is unavailable."""
    parsed = body_tree(code)
    if parsed is None:
        return None
    fn, start = parsed
    for node, _ in walk(fn):
        if isinstance(node, ast.With) and start + node.lineno - 1 == line:
            names = set()
            for child, _ in walk(node):
                if isinstance(child, ast.Call):
                    f = child.func
                    names.add(f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else "")
                elif isinstance(child, ast.Return):  # Python's own, which @syntax runs as Return
                    names.add("Return")
            return names
    return None
