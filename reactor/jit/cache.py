"""Object-code caches: a bounded in-memory LRU and an on-disk directory.

The disk cache lives in ``$REACTOR_CACHE_DIR`` (default
``~/.cache/reactor``); ``REACTOR_CACHE=0`` disables it. Entries are object
files (``.o``) named by a SHA-256 over the IR text, target CPU and features,
options and llvmlite version, and *recipes* (``.r``: small JSON records named
by ``reactor.recipe`` keys, which say which object a body builds without
building it), written atomically with a SHA-256 of their contents (a damaged
file is a miss), so concurrent processes can share the directory and a stale
entry can never be picked up.
"""
from __future__ import annotations

import collections
import hashlib
import json
import os
import tempfile
import threading

MEMORY_ENTRIES = 512
_memory: "collections.OrderedDict[str, bytes]" = collections.OrderedDict()
_memory_lock = threading.Lock()


def memory_get(key: str) -> bytes | None:
    with _memory_lock:
        obj = _memory.get(key)
        if obj is not None:
            _memory.move_to_end(key)
        return obj


def memory_put(key: str, obj: bytes) -> None:
    with _memory_lock:
        _memory[key] = obj
        _memory.move_to_end(key)
        while len(_memory) > MEMORY_ENTRIES:
            _memory.popitem(last=False)


def memory_clear() -> None:
    with _memory_lock:
        _memory.clear()
        _recipes.clear()


def directory() -> str | None:
    """The disk cache directory, or None when disabled."""
    if os.environ.get("REACTOR_CACHE", "1") == "0":
        return None
    return os.environ.get("REACTOR_CACHE_DIR") or os.path.join(os.path.expanduser("~"), ".cache", "reactor")


def disk_get(key: str, suffix: str = ".o") -> bytes | None:
    root = directory()
    if root is None:
        return None
    try:
        with open(os.path.join(root, key + suffix), "rb") as f:
            data = f.read()
    except OSError:
        return None
    # A damaged entry (truncated, overwritten) is a miss, never an object to link.
    digest, obj = data[:32], data[32:]
    return obj if obj and hashlib.sha256(obj).digest() == digest else None


def disk_put(key: str, obj: bytes, suffix: str = ".o") -> None:
    root = directory()
    if root is None:
        return
    try:
        os.makedirs(root, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=root, suffix=".tmp")
        with os.fdopen(fd, "wb") as f:
            f.write(hashlib.sha256(obj).digest() + obj)
        os.replace(tmp, os.path.join(root, key + suffix))
    except OSError:
        pass  # a read-only or full disk only costs a recompile next time


_recipes: "collections.OrderedDict[str, dict]" = collections.OrderedDict()


def recipe_get(key: str, use_disk: bool = True) -> dict | None:
    """The recipe stored for ``key`` (memory, then disk), or None."""
    with _memory_lock:
        found = _recipes.get(key)
    if found is None and use_disk:
        raw = disk_get(key, ".r")
        try:
            found = json.loads(raw) if raw else None
        except ValueError:
            found = None
        if found is not None:
            with _memory_lock:
                _recipes[key] = found
    return found


def recipe_put(key: str, recipe: dict, use_disk: bool = True) -> None:
    with _memory_lock:
        _recipes[key] = recipe
        while len(_recipes) > MEMORY_ENTRIES:
            _recipes.popitem(last=False)
    if use_disk:
        disk_put(key, json.dumps(recipe, sort_keys=True).encode(), ".r")
