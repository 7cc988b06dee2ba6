"""Tiered compilation (reactor.kernels.tiers): the quick code runs at once, the optimized code is
swapped in behind the same ufunc with the same bits; safe across fork and exit."""
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import reactor
from reactor import Float, kernel
from reactor.kernels import kernel as kernel_module
from reactor.kernels import tiers
from routines import glsl as gl

X = np.linspace(-30, 30, 1001, dtype=np.float32)


@pytest.fixture
def tiered():
    tiers.configure(True)
    kernel_module._memo.clear()
    yield
    tiers.finish()
    tiers.configure(False)


def shade(x: Float, t: Float) -> Float:
    return gl.sin(x * t) * gl.exp2(-gl.abs(x) * 0.1) + gl.pow(gl.abs(x), t)


def test_the_quick_code_runs_then_the_optimized_code_with_the_same_bits(tiered):
    ufunc = kernel(shade, cache=False)
    k = reactor.kernel_of(ufunc)
    first = ufunc(X, np.float32(0.7))
    assert k.code.source == "compiled quickly" or tiers.pending() == 0
    assert tiers.finish(timeout=60)
    assert k.code.source == "compiled" and k.quick_code.source == "compiled quickly"
    assert k.config.code.contents.loop == k.code.address("shade.loop")  # what the dispatcher runs
    assert np.array_equal(ufunc(X, np.float32(0.7)), first)
    with reactor.options(cache=False):
        tiers.configure(False)
        kernel_module._memo.clear()
        assert np.array_equal(kernel(shade, cache=False)(X, np.float32(0.7)), first)


def test_the_optimized_code_is_cached_for_the_next_build(tiered, tmp_path, monkeypatch):
    monkeypatch.setenv("REACTOR_CACHE_DIR", str(tmp_path))
    body = lambda x: x * 2.5 - 1.0  # noqa: E731
    kernel(body, args=[Float], returns=Float, name="tier_cached")
    assert tiers.finish(timeout=60)
    kernel_module._memo.clear()
    again = reactor.kernel_of(kernel(body, args=[Float], returns=Float, name="tier_cached"))
    assert again.code.source.startswith("recipe")


def _run(code: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, REACTOR_TIERED="1")
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                          timeout=120, env=env)


def test_exit_with_kernels_still_compiling_neither_hangs_nor_crashes():
    run = _run("""
        import numpy as np, reactor
        from reactor import Float
        from routines import glsl as gl
        def make(k):
            return lambda x: gl.pow(gl.abs(x), 1.5 + k) + gl.cos(x)
        for k in range(6):
            u = reactor.kernel(make(k), args=[Float], returns=Float, cache=False, name=f"exit_{k}")
            u(np.ones(40, np.float32))
        print("done")
    """)
    assert run.returncode == 0 and run.stdout.strip() == "done", run.stderr


def test_a_forked_child_runs_and_tiers_up_on_its_own():
    run = _run("""
        import os, numpy as np, reactor
        from reactor import Float
        from routines import glsl as gl
        u = reactor.kernel(lambda x: gl.exp(x) * 0.5, args=[Float], returns=Float, cache=False, name="forked")
        x = np.linspace(-3, 3, 100, dtype=np.float32)
        want = u(x)
        pid = os.fork()
        if pid == 0:
            ok = np.array_equal(u(x), want) and reactor.finish_tiers(timeout=60)
            ok = ok and np.array_equal(u(x), want) and reactor.kernel_of(u).code.source == "compiled"
            os._exit(0 if ok else 3)
        _, status = os.waitpid(pid, 0)
        print(os.waitstatus_to_exitcode(status), reactor.finish_tiers(timeout=60))
    """)
    assert run.returncode == 0 and run.stdout.split() == ["0", "True"], run.stdout + run.stderr
