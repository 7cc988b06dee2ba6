"""Memory: build/compile/call/drop cycles with resident memory measured and bounded;
compiled code is freed with its routine; caches are bounded.

The full 10,000-cycle runs are marked ``slow`` (REACTOR_SLOW_TESTS=1) and are also
``python -m fuzz.memcheck --cycles 10000 [--distinct]``. The growth that
remains comes from llvmlite, not reactor (docs/reliability.md): about 10 KB per
JIT link (ORC keeps every JITDylib) and about 50-80 KB per LLVM optimization run
(a PassInstrumentationCallbacks object per PassBuilder that is never freed).
"""
import gc
import weakref

import numpy as np
import pytest

from fuzz.memcheck import exec_mappings, memcheck
from reactor import Float, Function, kernel, kernel_of
from reactor.jit import cache
from reactor.kernels import kernel as kernel_module


def _check(report, per_cycle_kb):
    assert report.alive_code <= report.alive_code_start, report.text()     # every routine's code freed
    assert report.exec_maps_end <= report.exec_maps_start, report.text()  # and its machine code unmapped
    assert report.kernels_registered <= report.kernels_registered_start, report.text()
    assert report.memory_cache <= report.memory_cache_bound
    assert report.growth_kb_per_cycle < per_cycle_kb, report.text()


def test_500_cycles_of_the_same_program():
    _check(memcheck(500, warmup=100), per_cycle_kb=40)


def test_200_cycles_of_distinct_programs():
    _check(memcheck(200, distinct=True, warmup=50), per_cycle_kb=250)


@pytest.mark.slow
def test_10000_cycles_of_the_same_program():
    _check(memcheck(10_000), per_cycle_kb=20)


@pytest.mark.slow
def test_10000_cycles_of_distinct_programs():
    _check(memcheck(10_000, distinct=True), per_cycle_kb=120)


def test_compiled_code_is_freed_with_its_routine():
    """Dropping a routine or kernel frees its compiled code; repeated build/drop cycles do
    not grow the executable mappings (their exact count depends on how the JIT's allocator
    reuses pages after earlier tests, so only growth is checked)."""
    def body(x: Float) -> Float:
        return x * 3.0

    def cycle(i):
        f = Function(body, name=f"freed{i}", cache=False)
        assert f(2.0) == 6.0
        code = weakref.ref(f.compile().code)
        u = kernel(body, name=f"freed_kernel{i}", cache=False)
        assert u(np.float32(2)) == 6
        kern, kcode = weakref.ref(kernel_of(u)), weakref.ref(kernel_of(u).code)
        del f, u
        gc.collect()
        assert code() is None and kern() is None and kcode() is None
        assert not any(ref() is not None and ref().kernels[0].name == f"freed_kernel{i}"
                       for ref in kernel_module._registry.values())

    cycle(0)
    gc.collect()
    maps = exec_mappings()
    for i in range(1, 21):
        cycle(i)
    gc.collect()
    assert exec_mappings() <= maps + 2


def test_the_memory_cache_is_bounded(monkeypatch):
    monkeypatch.setattr(cache, "MEMORY_ENTRIES", 8)
    for k in range(20):
        c = float(k) + 0.5

        def body(x: Float) -> Float:
            return x + c
        assert Function(body, name=f"bounded{k}", cache=False)(1.0) == 1.0 + c
    assert len(cache._memory) == 8


def test_function_compiles_once_per_option_set():
    def body(x: Float) -> Float:
        return x - 1.0

    f = Function(body, name="per_options", cache=False)
    for _ in range(3):
        for width in (1, 4, 8, 16):
            f.compile(width=width)
    assert len(f._compiled) == 4
