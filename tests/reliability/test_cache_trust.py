"""The disk cache runs only code this user compiled, heals, and can be managed.

Tried as an attacker would: a second Unix user (nobody, when the tests run as root) makes a
shared cache directory and plants entries for ``routines.jit("exp2")`` whose code returns 42,
authenticated under its own key. Every other damage (a truncated entry, a full or read-only
disk, a path that is a file, an entry that no longer links) must give a compile, never a crash
or a foreign object."""
from __future__ import annotations

import errno
import os
import stat
import subprocess
import sys
import textwrap
import warnings

import numpy as np
import pytest

from reactor import Float, kernel, kernel_of
from reactor.errors import CacheWarning
from reactor.jit import cache

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
NOBODY = 65534
X = np.linspace(-3, 3, 37, dtype=np.float32)

RUN_EXP2 = textwrap.dedent('''
    import json, sys, warnings
    import numpy as np
    import reactor, routines
    warnings.simplefilter("always")
    with warnings.catch_warnings(record=True) as seen:
        u = routines.jit("exp2")
        got = u(np.linspace(-3, 3, 37, dtype=np.float32))
    print(json.dumps({"bits": got.view(np.uint32).tolist(), "source": reactor.kernel_of(u).code.source,
                      "warnings": [str(w.message) for w in seen], "name": u.__name__}))
''')


def _run(script: str, cache_dir, **env) -> dict:
    import json
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, cwd=ROOT,
                          env=dict(os.environ, PYTHONPATH=ROOT, REACTOR_CACHE_DIR=str(cache_dir), **env))
    assert proc.returncode == 0, proc.stderr[-3000:]
    return json.loads(proc.stdout.splitlines()[-1])


@pytest.fixture
def fresh(tmp_path, monkeypatch):
    """A fresh cache directory for this process (and no memory of earlier entries)."""
    d = tmp_path / "cache"
    monkeypatch.setenv("REACTOR_CACHE_DIR", str(d))
    monkeypatch.delenv("REACTOR_CACHE", raising=False)
    cache.memory_clear()
    cache._warned.clear()
    yield d
    cache.memory_clear()


def _body(c):
    def body(x: Float) -> Float:
        return x * c + 1.0
    return body


def test_directory_is_made_0700_even_under_umask_000(tmp_path):
    d = tmp_path / "made"
    script = "import os; os.umask(0); import reactor\nfrom reactor.jit import cache\nprint(cache.trusted_directory())"
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT,
                          env=dict(os.environ, PYTHONPATH=ROOT, REACTOR_CACHE_DIR=str(d)))
    assert proc.returncode == 0, proc.stderr
    assert stat.S_IMODE(d.stat().st_mode) == 0o700
    r = _run(RUN_EXP2, d)
    assert stat.S_IMODE((d / "secret.key").stat().st_mode) == 0o600
    assert all(stat.S_IMODE(p.stat().st_mode) == 0o600 for p in d.iterdir())
    assert r["source"] == "compiled" and not r["warnings"]
    assert _run(RUN_EXP2, d)["source"] == "recipe, disk cache"


@pytest.mark.parametrize("mode", [0o777, 0o770, 0o1777])
def test_a_directory_others_can_write_is_not_used(tmp_path, mode):
    d = tmp_path / "shared"
    d.mkdir()
    d.chmod(mode)
    r = _run(RUN_EXP2, d)
    assert r["source"] == "compiled"
    assert len(r["warnings"]) == 1 and "writable by" in r["warnings"][0] and str(d) in r["warnings"][0]
    assert list(d.iterdir()) == []  # nothing written there either


def test_a_path_that_is_a_file_gives_a_compile(tmp_path):
    f = tmp_path / "not-a-dir"
    f.write_text("x")
    r = _run(RUN_EXP2, f)
    assert r["source"] == "compiled" and len(r["warnings"]) == 1
    assert f.read_text() == "x"


@pytest.fixture
def request_cleanup():
    done: list = []
    yield done
    for f in done:
        f()


def _as_nobody(command: str) -> None:
    def drop():
        os.setgid(NOBODY)
        os.setuid(NOBODY)
    subprocess.run(["/bin/sh", "-c", command], check=True, preexec_fn=drop, timeout=30)


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0,
                    reason="planting as a second user needs root (to run a process as nobody)")
def test_entries_planted_by_another_user_are_never_linked(tmp_path, request_cleanup):
    """nobody makes a shared directory and plants, under its own key, objects with the exact
    names and exports of routines.jit("exp2")'s that return 42; root's run must ignore them."""
    import hashlib
    import hmac
    legit, evil = tmp_path / "legit", tmp_path / "evil"
    want = _run(RUN_EXP2, legit)
    evil_script = RUN_EXP2.replace('u = routines.jit("exp2")', textwrap.dedent('''
        from reactor import Float
        def forty_two(x: Float) -> Float:
            return x * 0.0 + 42.0
        u = reactor.kernel(forty_two, name=NAME)''').replace("\n", "\n    ")).replace("NAME", repr(want["name"]))
    assert set(_run(evil_script, evil)["bits"]) == {np.float32(42).view(np.uint32)}
    # the attacker's key and entries: every name root's build looks up, holding the evil build's code
    key = b"k" * 32
    import pathlib
    import shutil
    import tempfile
    base = pathlib.Path(tempfile.mkdtemp(prefix="reactor-plant-"))  # outside pytest's 0700 folders
    request_cleanup.append(lambda: shutil.rmtree(base, ignore_errors=True))
    base.chmod(0o777)
    shared, stage = base / "shared", base / "stage"
    stage.mkdir()
    evil_objects = sorted(evil.glob("*.o"))
    evil_recipe = next(evil.glob("*.r")).read_bytes()[40:]

    def plant(name, payload):
        mac = hmac.new(key, name.encode() + b"\0" + payload, hashlib.sha256).digest()
        (stage / name).write_bytes(b"RXCACHE1" + mac + payload)

    for p in legit.iterdir():  # root's names: the recipe points at the evil object, objects are evil
        if p.name != "secret.key":
            plant(p.name, evil_recipe if p.suffix == ".r" else evil_objects[0].read_bytes()[40:])
    for p in evil_objects:
        plant(p.name, p.read_bytes()[40:])
    (stage / "secret.key").write_bytes(key)
    for p in [stage, *stage.iterdir()]:
        os.chmod(p, 0o755 if p.is_dir() else 0o644)
    _as_nobody(f"mkdir -m 1777 {shared} && cp {stage}/* {shared}/ && chmod 600 {shared}/secret.key")
    assert (shared / "secret.key").stat().st_uid == NOBODY
    r = _run(RUN_EXP2, shared)
    assert r["bits"] == want["bits"] and r["source"] == "compiled"
    assert len(r["warnings"]) == 1 and "owned by uid 65534" in r["warnings"][0]
    # the same entries copied into root's own trusted directory: authenticated with the wrong key
    own = tmp_path / "own"
    _run(RUN_EXP2.replace('routines.jit("exp2")', 'routines.jit("log2")'), own)  # makes own/secret.key
    for p in stage.iterdir():
        if p.name != "secret.key":
            (own / p.name).write_bytes(p.read_bytes())
            os.chmod(own / p.name, 0o600)
    r = _run(RUN_EXP2, own)
    assert r["bits"] == want["bits"] and r["source"] == "compiled" and not r["warnings"]
    # an entry owned by another user inside a trusted directory is not read
    os.chown(own / next(legit.glob("*.r")).name, NOBODY, NOBODY)
    r = _run(RUN_EXP2, own)
    assert r["bits"] == want["bits"]


def test_truncated_and_foreign_format_entries_are_misses(fresh):
    u = kernel(_body(2.5), name="trunc_probe")
    want = u(X)
    entries = sorted(fresh.glob("*.o"))
    assert entries
    for damage in (lambda b: b[:-1], lambda b: b[:50], lambda b: b"", lambda b: b[40:],
                   lambda b: __import__("hashlib").sha256(b[40:]).digest() + b[40:]):  # the old format
        for e in entries:
            e.write_bytes(damage(e.read_bytes()) if e.stat().st_size else b"")
        cache.memory_clear()
        u2 = kernel(_body(2.5), name="trunc_probe")
        assert np.array_equal(u2(X), want) and kernel_of(u2).code.source == "compiled"
        entries = sorted(fresh.glob("*.o"))


def test_full_or_read_only_disk_leaves_no_temporary_files(fresh, monkeypatch):
    cache.trusted_directory()
    real_fdopen = os.fdopen

    class Full:
        def __init__(self, f):
            self.f = f

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.f.close()

        def write(self, data):
            raise OSError(errno.ENOSPC, "No space left on device")

    for code in (errno.ENOSPC, errno.EROFS):
        monkeypatch.setattr(cache.os, "fdopen", lambda fd, mode="r", *a: Full(real_fdopen(fd, mode, *a))
                            if "w" in mode else real_fdopen(fd, mode, *a))
        cache._warned.clear()
        with pytest.warns(CacheWarning, match="cannot"):
            u = kernel(_body(3.5 + code), name=f"full_{code}")
        assert np.array_equal(u(X), X * np.float32(3.5 + code) + 1)
        monkeypatch.setattr(cache.os, "fdopen", real_fdopen)
        assert not [p for p in fresh.iterdir() if p.name.endswith(".tmp")]
        assert not list(fresh.glob("*.o"))


def test_an_entry_that_does_not_link_is_removed_and_rebuilt(fresh):
    kernel(_body(4.5), name="heal_other")
    other = {p.name for p in fresh.glob("*.o")}
    u = kernel(_body(5.5), name="heal_me")
    mine = [p for p in fresh.glob("*.o") if p.name not in other]
    assert len(mine) == 1
    # an authenticated entry (this user's key) whose object lacks the symbols: as after an upgrade
    donor = (fresh / sorted(other)[0]).read_bytes()[40:]
    cache.disk_put(mine[0].stem, donor)
    cache.memory_clear()
    with pytest.warns(CacheWarning, match=f"removed the cache entry {mine[0]}"):
        u2 = kernel(_body(5.5), name="heal_me")
    assert np.array_equal(u2(X), X * np.float32(5.5) + 1) and kernel_of(u2).code.source == "compiled"
    cache.memory_clear()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert kernel_of(kernel(_body(5.5), name="heal_me")).code.source == "recipe, disk cache"
    del u


def test_size_bound_evicts_the_least_recently_used(fresh, monkeypatch):
    kernel(_body(6.5), name="lru_probe")
    one = sum(p.stat().st_size for p in fresh.iterdir() if p.name != "secret.key")
    monkeypatch.setenv("REACTOR_CACHE_SIZE", str(int(one * 2.5)))
    for i in range(8):
        kernel(_body(7.5 + i), name=f"lru_{i}")
        total = sum(p.stat().st_size for p in fresh.iterdir() if p.name != "secret.key")
        assert total <= one * 2.5
    cache.memory_clear()
    assert kernel_of(kernel(_body(7.5 + 7), name="lru_7")).code.source == "recipe, disk cache"  # the newest
    assert kernel_of(kernel(_body(7.5), name="lru_0")).code.source == "compiled"  # the oldest: evicted


def test_default_location_follows_xdg(monkeypatch, tmp_path):
    monkeypatch.delenv("REACTOR_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache.directory() == str(tmp_path / "xdg" / "reactor")
    monkeypatch.delenv("XDG_CACHE_HOME")
    assert cache.directory() == os.path.join(os.path.expanduser("~"), ".cache", "reactor")


def test_cache_command_shows_and_clears(tmp_path):
    d = tmp_path / "cmd"
    _run(RUN_EXP2, d)
    env = dict(os.environ, PYTHONPATH=ROOT, REACTOR_CACHE_DIR=str(d))
    info = subprocess.run([sys.executable, "-m", "reactor", "cache", "info"], capture_output=True, text=True,
                          env=env, cwd=ROOT)
    assert info.returncode == 0 and str(d) in info.stdout and "usable     yes" in info.stdout
    assert "objects, 2 recipes" in info.stdout  # the kernel's, and the shared runtime's
    clear = subprocess.run([sys.executable, "-m", "reactor", "cache", "clear"], capture_output=True, text=True,
                           env=env, cwd=ROOT)
    assert clear.returncode == 0 and "removed" in clear.stdout
    assert [p.name for p in d.iterdir()] == ["secret.key"]


def test_writes_scan_the_directory_once_while_under_the_bound(fresh, monkeypatch):
    scans = []
    real = cache._entries
    monkeypatch.setattr(cache, "_entries", lambda root: scans.append(root) or real(root))
    with cache._memory_lock:
        cache._believed.clear()
    for i in range(4):
        kernel(_body(31.5 + i), name=f"scan_{i}")  # each writes an object and a recipe
    assert len(scans) == 1  # a cache of ten thousand entries costs one scan a process, not one a write
    monkeypatch.setenv("REACTOR_CACHE_SIZE", "1")  # past the bound: scanned and evicted again
    kernel(_body(41.5), name="scan_past")
    assert len(scans) >= 2
