"""Object-code caches: a bounded in-memory LRU and an on-disk directory that runs only
code this user compiled.

The disk cache lives in ``$REACTOR_CACHE_DIR``, else ``$XDG_CACHE_HOME/reactor``, else
``~/.cache/reactor``; ``REACTOR_CACHE=0`` disables it. Entries are object files (``.o``)
named by a SHA-256 over the IR text, target CPU and features, options and llvmlite
version, and *recipes* (``.r``: small JSON records named by ``reactor.recipe`` keys,
which say which object a body builds without building it).

Threat model (docs/reliability.md): anyone who can write to the directory could plant
an object that this process links and runs. So the directory is created 0700 and is
used only if it is owned by this user and not writable by group or others (else one
``CacheWarning`` and compiling goes on without it); every entry carries an HMAC-SHA256
of its key and contents under a per-user random secret (``secret.key``, 0600, in the
directory), so a planted, altered, swapped or truncated entry is a miss, never code.
Writes are atomic (a temporary file renamed) and their temporary file is removed when
they fail; a full or read-only disk only costs a compile. The directory is bounded
(``REACTOR_CACHE_SIZE`` bytes, default 256 MiB): the least recently used entries go
first. ``python -m reactor cache info|clear`` shows and empties it.
"""
from __future__ import annotations

import collections
import contextlib
import hashlib
import hmac
import json
import os
import secrets
import stat
import tempfile
import threading
import warnings

from ..errors import CacheWarning

MEMORY_ENTRIES = 512
DEFAULT_SIZE = 256 << 20
_MAGIC = b"RXCACHE1"
_SECRET = "secret.key"
_SUFFIXES = (".o", ".r", ".w", ".s", ".d")  # objects, recipes, rewritten Python (reactor.syntax), SPIR-V of GLSL,
# the digest of the library sources (kernels.recipe)
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


def memory_remove(key: str) -> None:
    with _memory_lock:
        _memory.pop(key, None)


def memory_clear() -> None:
    with _memory_lock:
        _memory.clear()
        _recipes.clear()


def directory() -> str | None:
    """The disk cache directory (trusted or not), or None when disabled."""
    if os.environ.get("REACTOR_CACHE", "1") == "0":
        return None
    if os.environ.get("REACTOR_CACHE_DIR"):
        return os.environ["REACTOR_CACHE_DIR"]
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "reactor")


def size_bound() -> int:
    """The directory's size bound in bytes (``REACTOR_CACHE_SIZE``)."""
    try:
        return max(0, int(os.environ.get("REACTOR_CACHE_SIZE", DEFAULT_SIZE)))
    except ValueError:
        return DEFAULT_SIZE


# -- trust -----------------------------------------------------------------------------------

_warned: set = set()
_secrets: "dict[tuple, bytes]" = {}


_quiet = threading.local()


@contextlib.contextmanager
def quietly():
    """Warn of nothing on this thread (the import's background warm-up: its warnings would come
    from no line of the user's, and outside any ``catch_warnings`` of theirs); what it would
    have said is said by the next use on another thread, which meets the same state."""
    _quiet.on = True
    try:
        yield
    finally:
        _quiet.on = False


def _warn(message: str) -> None:
    """One warning per message and process (a distrusted cache is not news at every compile)."""
    if getattr(_quiet, "on", False):
        return
    if message not in _warned:
        _warned.add(message)
        warnings.warn(message, CacheWarning, stacklevel=4)


def _unsafe(st: os.stat_result, what: str, path: str) -> str | None:
    """Why a file or directory with status ``st`` cannot be trusted (None: it can)."""
    if st.st_uid != os.geteuid():
        return f"{what} {path} is owned by uid {st.st_uid}, not by this user (uid {os.geteuid()})"
    if st.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
        return f"{what} {path} is writable by {'others' if st.st_mode & stat.S_IWOTH else 'its group'} " \
               f"(mode {stat.S_IMODE(st.st_mode):04o})"
    return None


def trusted_directory() -> tuple[str | None, str]:
    """(the disk cache directory if it can be used, else None; why not). Creates it 0700."""
    root = directory()
    if root is None:
        return None, "disabled (REACTOR_CACHE=0)"
    try:
        os.makedirs(root, mode=0o700, exist_ok=True)
        st = os.stat(root)
    except OSError as exc:
        reason = f"the cache directory {root} cannot be created: {exc.strerror}"
        _warn(f"reactor: {reason}; compiling without the disk cache")
        return None, reason
    if not stat.S_ISDIR(st.st_mode):
        reason = f"the cache path {root} is not a directory"
    else:
        reason = _unsafe(st, "the cache directory", root) or ""
    if reason:
        _warn(f"reactor: {reason}; compiling without the disk cache (another user could plant code "
              f"there; see docs/reliability.md)")
        return None, reason
    return root, ""


def _secret(root: str) -> bytes | None:
    """This user's key for the entries of ``root`` (made on first use, 0600), or None."""
    path = os.path.join(root, _SECRET)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
    except FileNotFoundError:
        fd = None
    except OSError as exc:
        _warn(f"reactor: the cache key {path} cannot be read ({exc.strerror}); compiling without the disk cache")
        return None
    if fd is None:  # the first use: write a new key aside, then link it in (atomic, never half a key)
        key, tmp = secrets.token_bytes(32), None
        try:
            fd, tmp = tempfile.mkstemp(dir=root, prefix=".", suffix=".tmp")  # 0600
            with os.fdopen(fd, "wb") as f:
                f.write(key)
            os.link(tmp, path)
        except FileExistsError:  # another process made it first: read theirs
            return _secret(root)
        except OSError as exc:
            _warn(f"reactor: the cache key {path} cannot be written ({exc.strerror}); compiling without "
                  f"the disk cache")
            return None
        finally:
            _remove(tmp)
        return key
    with os.fdopen(fd, "rb") as f:
        st = os.fstat(f.fileno())
        ident = (root, st.st_ino, st.st_mtime_ns)
        if ident in _secrets:
            return _secrets[ident]
        reason = _unsafe(st, "the cache key", path)
        if reason is None and st.st_mode & stat.S_IRWXO | st.st_mode & stat.S_IRWXG:
            reason = f"the cache key {path} is readable by others (mode {stat.S_IMODE(st.st_mode):04o})"
        key = f.read(64)
    if reason or len(key) != 32:
        _warn(f"reactor: {reason or f'the cache key {path} is damaged'}; compiling without the disk cache")
        return None
    _secrets[ident] = key
    return key


def _remove(path: str | None) -> bool:
    """Delete ``path`` if there is one; whether it went."""
    if path is None:
        return False
    try:
        os.unlink(path)
        return True
    except OSError:
        return False


def _mac(secret: bytes, name: str, payload: bytes) -> bytes:
    return hmac.new(secret, name.encode() + b"\0" + payload, hashlib.sha256).digest()


# -- entries ---------------------------------------------------------------------------------

def entry_path(key: str, suffix: str = ".o") -> str | None:
    """Where the entry ``key`` lives (None: no usable disk cache)."""
    root = directory()
    return None if root is None else os.path.join(root, key + suffix)


def disk_get(key: str, suffix: str = ".o") -> bytes | None:
    """The authenticated contents of entry ``key``, or None (missing, planted, damaged)."""
    root, _ = trusted_directory()
    secret = _secret(root) if root else None
    if root is None or secret is None:
        return None
    path = os.path.join(root, key + suffix)
    try:
        with open(path, "rb") as f:
            reason = _unsafe(os.fstat(f.fileno()), "the cache entry", path)
            data = f.read()
    except OSError:
        return None
    if reason:
        _warn(f"reactor: {reason}; not used")
        return None
    head, mac, payload = data[:8], data[8:40], data[40:]
    if head != _MAGIC or not payload or not hmac.compare_digest(mac, _mac(secret, key + suffix, payload)):
        return None  # damaged or not ours: a miss, never code to link
    try:
        os.utime(path)  # most recently used (the size bound evicts the least recently used)
    except OSError:
        pass
    return payload


def disk_put(key: str, obj: bytes, suffix: str = ".o") -> None:
    """Store ``obj`` as entry ``key`` (atomically; failures only cost a compile later)."""
    root, _ = trusted_directory()
    secret = _secret(root) if root else None
    if root is None or secret is None:
        return
    tmp = None
    try:
        fd, tmp = tempfile.mkstemp(dir=root, prefix=".", suffix=".tmp")
        with os.fdopen(fd, "wb") as f:
            f.write(_MAGIC + _mac(secret, key + suffix, obj) + obj)
        os.replace(tmp, os.path.join(root, key + suffix))
        tmp = None
    except OSError as exc:  # a full or read-only disk: the entry is compiled again next time
        _warn(f"reactor: cannot write to the cache {root} ({exc.strerror}); entries are not kept")
    finally:
        _remove(tmp)
    _bound(root, len(_MAGIC) + 32 + len(obj))


def disk_remove(key: str, suffix: str, why: str) -> None:
    """Remove an authenticated entry that still failed (e.g. to link), saying which file."""
    path = entry_path(key, suffix)
    if path is None:
        return
    _remove(path)
    if not getattr(_quiet, "on", False):
        warnings.warn(f"reactor: removed the cache entry {path} ({why}); it is compiled again",
                      CacheWarning, stacklevel=3)


def _entries(root: str) -> list[tuple[float, int, str]]:
    """(last use, size, path) of every entry and stale temporary file in ``root``."""
    out: list[tuple[float, int, str]] = []
    try:
        names = os.listdir(root)
    except OSError:
        return out
    for name in names:
        if name.endswith(_SUFFIXES) or name.endswith(".tmp"):
            path = os.path.join(root, name)
            try:
                st = os.lstat(path)
            except OSError:
                continue
            if stat.S_ISREG(st.st_mode):
                out.append((st.st_mtime, st.st_size, path))
    return out


#: root -> the bytes this process believes are in it (from its last scan plus what it wrote since)
_believed: dict[str, int] = {}


def _bound(root: str, added: int) -> None:
    """Evict the least recently used entries until the directory fits its bound. The directory is
    scanned once per process and again only when what this process wrote may pass the bound (a
    scan stats every entry: tens of milliseconds for a cache of ten thousand entries)."""
    bound = size_bound()
    with _memory_lock:
        believed = _believed.get(root)
        if believed is not None and believed + added <= bound:
            _believed[root] = believed + added
            return
    entries = _entries(root)
    total = sum(e[1] for e in entries)
    for _, size, path in sorted(entries):
        if total <= bound:
            break
        if _remove(path):
            total -= size
    with _memory_lock:
        _believed[root] = total


def info() -> dict:
    """What ``python -m reactor cache info`` shows: where, whether trusted, entries, bytes, bound."""
    root, reason = trusted_directory()
    where = directory()
    entries = _entries(where) if where and os.path.isdir(where) else []
    return {"directory": where, "usable": root is not None, "reason": reason,
            "objects": sum(e[2].endswith(".o") for e in entries),
            "recipes": sum(e[2].endswith(".r") for e in entries),
            "bytes": sum(e[1] for e in entries), "bound": size_bound()}


def clear() -> int:
    """Remove every entry of this user's cache directory (and the memory caches); the count."""
    memory_clear()
    root, _ = trusted_directory()
    removed = 0
    for _, _, path in _entries(root) if root else ():
        removed += _remove(path)
    with _memory_lock:
        _believed.clear()
    return removed


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
