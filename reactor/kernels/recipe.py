"""What determines a body's IR, hashed without building it: the key of a cache hit without tracing.

``recipe_watch(body, *parts)`` hashes everything that decides the IR a DSL body
produces, without running it: its code object (bytecode, constants, names,
nested code), the values it reads from its closure cells, defaults and module
globals, recursively through the plain Python helpers and reactor Functions it
calls, the sources of reactor and of the builder libraries registered with
``reactor.hide_frames_of`` (routines), llvmlite's version, and ``parts`` (the
signature and build settings). The file and line numbers count too (the
user's lines are in error messages, routine call sites and plans). A value
that is not a number, string, bytes, bool, None, a tuple of those, a module of
a known library, a reactor object that states its value (an enum, a frozen
dataclass), a constant vector or matrix (a module's ``vec3``) or a Python
function makes the key ``None``: such a body is traced
(its IR is the key then), so a stale object is never linked. Builtins count by
name.

It gives, with the key, what it read (each global, closure cell
and defaults tuple, by identity), so a kernel built from the same function
object can be reused in memory while none of them was rebound (``unchanged``).
"""
from __future__ import annotations

import dataclasses
import enum
import functools
import hashlib
import os
import types

import numpy as np

from ..dsl.external import External
from ..dsl.definition import FunctionDef
from ..dsl.signature import GenericType
from ..dsl.values import Value
from ..dsl.vectors import Mat, Vec
from ..errors import library_dirs
from ..jit import cache
from ..jit.compiler import toolchain

_SIMPLE = (int, float, complex, str, bytes, bool, type(None))
#: Modules whose functions a body may use for constants: keyed by name and version.
_STABLE_MODULES = {"math": "", "numpy": np.__version__, "operator": "", "functools": ""}


class Unkeyable(Exception):
    """A value the key cannot describe (the body must be traced)."""


@functools.cache
def _library_digest(dirs: tuple[str, ...]) -> str:
    """SHA-256 over the Python sources of reactor and the registered builder libraries. Kept in
    the disk cache under the files' names, sizes and modification times, so a process whose
    sources are as the last one saw them reads none of them."""
    sources = _sources(dirs)
    index = "d" + hashlib.sha256(repr((toolchain(), [(rel, st.st_size, st.st_mtime_ns)
                                                     for rel, _, st in sources])).encode()).hexdigest()[:40]
    known = cache.disk_get(index, ".d")
    if known is not None:
        return known.decode()
    h = hashlib.sha256(toolchain().encode())
    for rel, path, _ in sources:
        h.update(rel.encode())
        with open(path, "rb") as f:
            h.update(f.read())
    cache.disk_put(index, h.hexdigest().encode(), ".d")
    return h.hexdigest()


def _sources(dirs: tuple[str, ...]) -> list[tuple[str, str, os.stat_result]]:
    """(name under its root, path, stat) of every Python source under ``dirs``, in order (one
    directory listing and one stat a file: half os.walk's time, paid once per process)."""
    found: list = []

    def visit(root: str, folder: str) -> None:
        with os.scandir(folder) as listing:
            entries = sorted(listing, key=lambda e: e.name)
        for entry in entries:
            if entry.name.endswith(".py") and entry.is_file():
                found.append((entry.path[len(root):], entry.path, entry.stat()))
            elif entry.is_dir() and entry.name != "__pycache__":
                visit(root, entry.path)
    for root in dirs:
        visit(root, root)
    return found


def library_digest() -> str:
    return _library_digest(tuple(sorted(library_dirs())))


def _in_library(module_name: str | None) -> bool:
    return module_name is not None and module_name.split(".")[0] in _library_packages()


def _library_packages() -> set[str]:
    return {os.path.basename(os.path.normpath(d)) for d in library_dirs()}


_MISSING = object()


class _Hasher:
    def __init__(self):
        self.h = hashlib.sha256()
        self.seen: set[int] = set()
        self.watch: list[tuple] = []  # (scope dict, name, value) read, for ``unchanged``

    def put(self, *parts) -> None:
        for p in parts:
            self.h.update(b"\1" + p if isinstance(p, bytes) else repr(p).encode())  # bytes as they are: fast
            self.h.update(b"\0")

    def code(self, code: types.CodeType, scope: dict) -> None:
        lines = getattr(code, "co_linetable", None) or code.co_lnotab
        self.put("code", code.co_code, code.co_names, code.co_varnames, code.co_freevars, code.co_cellvars,
                 code.co_argcount, code.co_kwonlyargcount, code.co_flags, code.co_filename, code.co_firstlineno,
                 lines)
        for const in code.co_consts:
            if isinstance(const, types.CodeType):
                self.code(const, scope)
            else:
                self.value(const)
        for name in code.co_names:
            self.watch.append((scope, name, scope.get(name, _MISSING)))
            if name in scope:
                self.put("global", name)
                self.value(scope[name])
            elif isinstance(__builtins__, dict) and name in __builtins__ or hasattr(__builtins__, name):
                self.put("builtin", name)
            else:
                self.put("attribute", name)  # an attribute name, or a global defined later

    def function(self, fn) -> None:
        if id(fn) in self.seen:
            self.put("again", fn.__qualname__)
            return
        self.seen.add(id(fn))
        self.put("function", fn.__qualname__)
        self.code(fn.__code__, fn.__globals__)
        for cell in fn.__closure__ or ():
            try:
                contents = cell.cell_contents
            except ValueError:  # an empty cell (a name bound later)
                self.put("empty cell")
                self.watch.append((cell, None, _MISSING))
                continue
            self.watch.append((cell, None, contents))
            self.value(contents)
        self.watch.append((fn, "__defaults__", fn.__defaults__))
        self.watch.append((fn, "__kwdefaults__", fn.__kwdefaults__))
        for default in (fn.__defaults__ or ()) + tuple((fn.__kwdefaults__ or {}).values()):
            self.value(default)

    def value(self, v) -> None:

        if isinstance(v, _SIMPLE):
            self.put(type(v).__name__, v)
        elif isinstance(v, np.generic) and v.dtype.kind in "biuf":
            self.put("numpy scalar", v.dtype.str, v.tobytes())
        elif isinstance(v, (tuple, frozenset)):
            self.put(type(v).__name__, len(v))
            for item in (sorted(v, key=repr) if isinstance(v, frozenset) else v):
                self.value(item)
        elif isinstance(v, Vec) and all(isinstance(c, _SIMPLE) for c in v._comps):
            # a constant vector (a module's vec3): its components, watched (a swizzle assignment replaces them)
            self.put("vector", type(v).__name__, v._comps)
            self.watch.append((v, "_comps", v._comps))
        elif isinstance(v, Mat) and all(isinstance(c, _SIMPLE) for col in v._cols for c in col._comps):
            self.put("matrix", type(v).__name__, tuple(col._comps for col in v._cols))
            self.watch.append((v, "_cols", v._cols))
            for col in v._cols:
                self.watch.append((col, "_comps", col._comps))
        elif isinstance(v, type) and issubclass(v, Value):
            self.put("value type", v.__name__)
        elif isinstance(v, GenericType):
            self.put("generic type", repr(v))
        elif isinstance(v, FunctionDef):
            self.put("dsl function", v.name, sorted(v.option_overrides.items()), v.signature)
            self.function(v.body)
        elif isinstance(v, External):
            self.put("external", v.symbol, v.library, v.returns, v.args)
        elif isinstance(v, types.ModuleType):
            if v.__name__ in _STABLE_MODULES:
                self.put("module", v.__name__, _STABLE_MODULES[v.__name__])
            elif _in_library(v.__name__):
                self.put("library module", v.__name__)
            else:
                raise Unkeyable(f"module {v.__name__}")
        elif isinstance(v, (types.FunctionType, types.BuiltinFunctionType)) or callable(v) and hasattr(v, "__wrapped__"):
            module = getattr(v, "__module__", None)
            stable = (module or "").split(".")[0] in _STABLE_MODULES
            if _in_library(module) or stable or isinstance(v, types.BuiltinFunctionType):
                self.put("library function", module, getattr(v, "__qualname__", repr(v)))
            elif isinstance(v, types.FunctionType):
                self.function(v)
            else:
                raise Unkeyable(repr(v))
        elif isinstance(v, type) and (_in_library(v.__module__) or v.__module__ in ("builtins", "numpy")):
            self.put("class", v.__module__, v.__qualname__)
        elif _in_library(getattr(type(v), "__module__", None)) and (
                isinstance(v, enum.Enum) or dataclasses.is_dataclass(v) and getattr(v, "__dataclass_params__").frozen):
            # a reactor object that states its value (a Precision, a Target ...): its state by repr
            self.put("library object", type(v).__qualname__, repr(v))
        else:  # anything else (a user's object, a vector holding DSL values) is traced
            raise Unkeyable(type(v).__name__)


def recipe_watch(body, *parts) -> tuple[str | None, list[tuple]]:
    """The key of ``body``'s IR with ``parts`` (signature, settings) and what it read (for
    ``unchanged``); ``(None, [])`` if it has no key."""
    hasher = _Hasher()
    hasher.put("reactor recipe 2", library_digest(), *parts)
    try:
        hasher.function(body)
    except Unkeyable:
        return None, []
    return hasher.h.hexdigest(), hasher.watch


def unchanged(watch: list[tuple]) -> bool:
    """Whether every global, closure cell and default a key read still holds the same object."""
    for where, name, value in watch:
        if name is None:
            try:
                now = where.cell_contents
            except ValueError:
                now = _MISSING
        elif isinstance(where, dict):
            now = where.get(name, _MISSING)
        else:
            now = getattr(where, name)
        if now is not value:
            return False
    return True
