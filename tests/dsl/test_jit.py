"""The JIT: targets, optimization levels, the in-memory and on-disk object
caches, and thread-safe building and compiling."""
import os
import subprocess
import sys
import textwrap
import threading

import numpy as np
import pytest

import reactor
from reactor import Float, Function, Int, MulAdd, kernel, kernel_of
from reactor.jit import cache
from reactor import TARGETS, get_target

from dsl_helpers import assert_bits_equal

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _make_body(constant):
    """A new Python function object per call; the same IR for the same constant."""
    def cached_body(x: Float) -> Float:
        return x * constant + 1.0
    return cached_body


# -- targets and options ------------------------------------------------------------

def test_host_target():
    import llvmlite.binding as llvm

    host = get_target("host")
    assert host.cpu == llvm.get_host_cpu_name()
    assert host.runnable
    assert host.natural_width == (16 if "avx512f" in host.feature_set else 8 if "avx2" in host.feature_set else 4)
    assert host.has_fma == ("fma" in host.feature_set)
    assert set(TARGETS) == {"host", "avx512", "avx2", "sse4", "aarch64"}
    with pytest.raises(reactor.ReactorError, match="unknown target"):
        get_target("riscv")
    with pytest.raises(reactor.ReactorError, match="unknown target"):
        Function(_make_body(1.0), target="riscv").compile()


@pytest.mark.parametrize("target,width,regs", [("avx512", 16, "zmm"), ("avx2", 8, "ymm"), ("sse4", 4, "xmm")])
def test_forced_targets(target, width, regs):
    u = kernel(_make_body(2.5), target=target, name=f"t_{target}")
    kern = kernel_of(u)
    assert kern.build.width == width and kern.build.target.name == target
    asm = kern.assembly
    assert regs in asm
    for wider in {"xmm": ("ymm", "zmm"), "ymm": ("zmm",), "zmm": ()}[regs]:
        assert wider not in asm
    if get_target(target).runnable:
        x = np.arange(40, dtype=np.float32)
        assert_bits_equal(u(x), x * np.float32(2.5) + 1)


def test_optimization_levels():
    def body(x: Float, n: Int) -> Float:
        acc = reactor.Variable(Float, 0.0)
        with reactor.For(0, n):
            acc += x
        return acc

    r0 = Function(body, opt=0).compile()
    r3 = Function(body, opt=3).compile()
    assert (r0.build.opt, r3.build.opt) == (0, 3)
    assert r0.ir == r3.ir  # the same IR as built ...
    assert "alloca" in r0.optimized_ir and "alloca" not in r3.optimized_ir  # ... optimized differently
    assert r0(1.5, 4) == r3(1.5, 4) == 6.0


# -- caches --------------------------------------------------------------------------

def _objects(d):
    return sorted(p.name for p in d.glob("*.o")) if d.exists() else []


def test_memory_and_disk_cache(cache_dir):
    u1 = kernel(_make_body(1.25))
    k1 = kernel_of(u1)
    assert k1.code.source == "compiled"
    assert _objects(cache_dir) == [k1.code.key + ".o"]
    # a different Python function producing the same IR: LLVM is skipped
    u2 = kernel(_make_body(1.25))
    assert u2 is not u1 and kernel_of(u2).code.source == "recipe, memory cache"  # not even traced
    cache.memory_clear()
    u3 = kernel(_make_body(1.25))
    assert kernel_of(u3).code.source == "recipe, disk cache"
    x = np.arange(50, dtype=np.float32)
    for u in (u1, u2, u3):
        assert_bits_equal(u(x), x * np.float32(1.25) + 1)
    # the key covers options that change code: another opt level is another entry
    kernel(_make_body(1.25), opt=1)
    assert len(_objects(cache_dir)) == 2


def test_disk_cache_can_be_disabled(cache_dir, monkeypatch):
    kernel(_make_body(3.75), cache=False)
    assert _objects(cache_dir) == []
    monkeypatch.setenv("REACTOR_CACHE", "0")
    kernel(_make_body(4.75))
    assert _objects(cache_dir) == []
    assert cache.directory() is None


def test_damaged_disk_cache_entry_is_a_miss(cache_dir):
    u = kernel(_make_body(5.25))
    (entry,) = cache_dir.glob("*.o")
    for damage in (b"", b"\x7fELF garbage", entry.read_bytes()[:-100]):
        entry.write_bytes(damage)
        cache.memory_clear()
        u2 = kernel(_make_body(5.25))
        assert kernel_of(u2).code.source == "compiled"
        assert_bits_equal(u2(np.ones(20, np.float32)), np.full(20, 6.25, np.float32))
    cache.memory_clear()
    assert kernel_of(kernel(_make_body(5.25))).code.source == "recipe, disk cache"  # rewritten


def test_disk_cache_hit_in_a_fresh_process(cache_dir):
    script = textwrap.dedent("""
        import numpy as np
        from reactor import Float, kernel, kernel_of

        def body(x: Float) -> Float:
            return x * 6.5 + 1.0

        u = kernel(body)
        print(kernel_of(u).code.source, u(np.float32(2.0)))
    """)
    env = dict(os.environ, REACTOR_CACHE_DIR=str(cache_dir), PYTHONPATH=REPO)
    run = lambda: subprocess.run([sys.executable, "-c", script], env=env, capture_output=True,
                                 text=True, timeout=120, cwd=REPO)
    first, second = run(), run()
    assert first.returncode == 0, first.stderr
    assert first.stdout.split() == ["compiled", "14.0"]
    assert second.stdout.split() == ["recipe,", "disk", "cache", "14.0"]  # not even traced


# -- threads ------------------------------------------------------------------------

def test_concurrent_building_and_compiling():
    n_threads, per_thread = 4, 3
    barrier = threading.Barrier(n_threads)
    errors, results = [], {}

    def work(t):
        try:
            barrier.wait()
            for k in range(per_thread):
                c = float(t * 10 + k) + 0.5
                with reactor.options(fma=bool(k % 2)):  # thread-local option contexts
                    u = kernel(_make_body(c), name=f"thr{t}_{k}")
                    assert kernel_of(u).build.fma is bool(k % 2)

                def g(x: Float, y: Float) -> Float:
                    return MulAdd(x, y, c)

                f = Function(g, name=f"g{t}_{k}")
                x = np.arange(100, dtype=np.float32) + t
                results[t, k] = (u(x), x * np.float32(c) + 1, f(2.0, 3.0), 6.0 + c)
        except BaseException as exc:  # noqa: BLE001 - reported below
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(t,)) for t in range(n_threads)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert not errors, errors
    assert len(results) == n_threads * per_thread
    for got, want, got_s, want_s in results.values():
        assert_bits_equal(got, want)
        assert got_s == want_s


def test_concurrent_memo_of_one_body():
    body = _make_body(8.5)
    barrier = threading.Barrier(4)
    out = []

    def work():
        barrier.wait()
        out.append(kernel(body))

    threads = [threading.Thread(target=work) for _ in range(4)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert len(out) == 4
    x = np.arange(33, dtype=np.float32)
    for u in out:
        assert_bits_equal(u(x), x * np.float32(8.5) + 1)


def test_forced_targets_use_their_own_estimate_instructions():
    """avx2/sse4 builds use RSQRTPS (12 bits), AVX-512 builds RSQRT14: never a silent exact division."""
    import numpy as np

    from reactor import Float, RsqrtApprox, kernel, kernel_of
    x = np.linspace(0.5, 4, 4096, dtype=np.float32)
    exact = 1 / np.sqrt(x.astype(np.float64))
    for target, instruction, bound in [("avx2", "vrsqrtps", 1.5 * 2 ** -12), ("sse4", "rsqrtps", 1.5 * 2 ** -12),
                                       ("avx512", "vrsqrt14ps", 2 ** -14)]:
        @kernel(target=target, name=f"est_{target}")
        def est(v: Float) -> Float:
            return RsqrtApprox(v)
        assert instruction in kernel_of(est).assembly
        if not reactor.get_target(target).runnable:  # built to be read: its ufunc refuses to run
            with pytest.raises(reactor.ReactorError, match="cannot run on this CPU"):
                est(x)
            continue
        err = np.abs(est(x) / exact - 1).max()
        assert 2 ** -20 < err < bound, (target, err)
