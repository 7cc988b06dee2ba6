"""The FMA toggle, checked in the machine code: fma=True emits llvm.fma and FMA
instructions; fma=False leaves no fused instruction anywhere."""
import re

import numpy as np
import pytest

import reactor
from reactor import (
    Float, FmaDisabledError, For, Function, MulAdd, Pointer, Variable, kernel, kernel_of, vector_type,
)
from reactor import get_target

FUSED = re.compile(r"\bvf(?:n)?m(?:add|sub)\w*", re.I)
HOST_FMA = get_target("host").has_fma  # without it, llvm.fma becomes a call to fmaf


def _muladd(a: Float, b: Float, c: Float) -> Float:
    return MulAdd(a, b, c) - MulAdd(a, c, 1.0)


@pytest.mark.parametrize("width", [1, 4, 8, 16])
@pytest.mark.parametrize("fma", [True, False])
def test_kernel_fma_toggle(width, fma):
    u = kernel(_muladd, width=width, fma=fma, name=f"muladd_{width}_{fma}")
    kern = kernel_of(u)
    asm = kern.assembly
    assert ("llvm.fma" in kern.ir) is fma
    assert bool(FUSED.search(asm)) is (fma and HOST_FMA), FUSED.findall(asm)[:5]
    x = np.linspace(-2, 2, 37).astype(np.float32)
    got = u(x, x[::-1].copy(), np.float32(0.5))
    if not fma:
        with np.errstate(all="ignore"):
            want = (x * x[::-1] + np.float32(0.5)) - (x * np.float32(0.5) + np.float32(1))
        np.testing.assert_array_equal(got, want)


def _polynomial(width):
    T = vector_type("Float", width)

    def horner(p: Pointer[T, "n"], n: reactor.Int, out: Pointer[T, "n"]):
        with For(0, n) as i:
            x = p[i]
            acc = Variable(T, 0.5)
            for c in (1.0, -0.5, 0.25, -0.125, 0.0625, 3.0):   # unrolled at build time
                acc.set(MulAdd(acc, x, c))
            out[i] = acc * x + 1.0    # plain operators are never contracted

    return horner


@pytest.mark.parametrize("width", [4, 16])
@pytest.mark.parametrize("fma", [True, False])
def test_routine_fma_toggle(width, fma):
    f = Function(_polynomial(width), fma=fma, name=f"horner{width}{fma}")
    r = f.compile()
    fused = FUSED.findall(r.assembly)
    assert (len(fused) >= 6) if fma and HOST_FMA else (not fused), fused
    assert r.ir.count("llvm.fma") >= (7 if fma else 0) and ("fmul" in r.ir) is True
    x = np.linspace(-1, 1, 4 * width).astype(np.float32)
    out = np.zeros_like(x)
    f(x, 4, out)
    acc = np.full_like(x, 0.5)
    for c in (1.0, -0.5, 0.25, -0.125, 0.0625, 3.0):
        acc = acc * x + np.float32(c)
    np.testing.assert_allclose(out, acc * x + 1, rtol=1e-6)


def test_fma_follows_forced_targets():
    for target, fused in (("avx2", True), ("avx512", True)):
        r = Function(_polynomial(8), target=target, fma=True, name=f"h_{target}").compile()
        assert bool(FUSED.search(r.assembly)) is fused
        r = Function(_polynomial(8), target=target, fma=False, name=f"h_{target}_nofma").compile()
        assert not FUSED.search(r.assembly)
    # fma=None means "what the target has": avx2 (haswell) has FMA, sse4 (nehalem) does not
    assert Function(_polynomial(4), target="avx2").compile().build.fma is True
    r = Function(_polynomial(4), target="sse4").compile()
    assert r.build.fma is False and not FUSED.search(r.assembly) and "ymm" not in r.assembly


def test_fma_in_fma_off_build_is_an_error():
    def body(x: Float) -> Float:
        return reactor.Fma(x, x, x)

    with pytest.raises(FmaDisabledError):
        kernel(body, fma=False)
    with reactor.options(fma=False):
        with pytest.raises(FmaDisabledError):
            Function(body).compile()
    assert Function(body, fma=True)(2.0) == 6.0


# -- an honest toggle: fma=True needs FMA hardware; "emulate" is exact software; never libm's fmaf ----

def _fused3(a: Float, b: Float, c: Float) -> Float:
    return reactor.MulAdd(a, b, c)


def test_fma_true_on_a_target_without_fma_is_an_error_naming_it():
    with pytest.raises(reactor.ReactorError, match=r"target 'sse4' \(nehalem\) has no fused multiply-add.*'emulate'"):
        kernel(_fused3, name="fma_sse4_true", target="sse4", fma=True)
    with pytest.raises(reactor.ReactorError, match="has no fused multiply-add"):
        import routines
        routines.jit("exp2", target="sse4", fma=True)


@pytest.mark.skipif(not reactor.get_target("host").has_fma, reason="compares with the hardware's FMA")
def test_emulated_fma_gives_the_hardware_bits():
    emulated = kernel(_fused3, name="fma_emulated", target="sse4", fma="emulate")
    hardware = kernel(_fused3, name="fma_hardware", fma=True)
    assert "fma=emulated" in reactor.kernel_of(emulated).build.describe()
    rng = np.random.default_rng(7)
    n = 1 << 20
    a, b, c = rng.integers(0, 2 ** 32, (3, n), dtype=np.uint64).astype(np.uint32).view(np.float32)
    x, y = rng.standard_normal((2, n)).astype(np.float32)
    exact = x.astype(np.float64) * y
    cases = [(a, b, c), (x, y, (-exact).astype(np.float32)),                       # cancellation
             (x, y, (-exact * (1 + rng.standard_normal(n) * 2e-7)).astype(np.float32)),  # near ties
             (x * np.float32(1e-20), y * np.float32(1e-20), (-exact * 1e-40).astype(np.float32))]  # subnormal
    with np.errstate(all="ignore"):
        for args in cases:
            assert np.array_equal(emulated(*args).view(np.uint32), hardware(*args).view(np.uint32))
        assert np.array_equal(emulated(a[::3], b[::3], c[::3]).view(np.uint32),
                              hardware(a[::3], b[::3], c[::3]).view(np.uint32))  # the scalar path too


def test_no_build_calls_libm_fmaf_and_emulated_routines_match_fused_ones():
    import routines
    from routines.lab import sample_inputs
    for fma in (None, False, "emulate"):
        for name in ("exp2", "log2", "pow"):
            assert "fmaf" not in reactor.kernel_of(routines.jit(name, "full", fma, target="sse4")).assembly
    if reactor.get_target("avx2").runnable:
        for name in ("exp2", "log2", "pow"):
            ops = [v.view(np.float32) for v in sample_inputs(name, 1 << 14, seed=2)]
            got = routines.jit(name, "full", "emulate", target="sse4")(*ops)
            want = routines.jit(name, "full", True, target="avx2")(*ops)
            assert np.array_equal(got.view(np.uint32), want.view(np.uint32)), name


def test_a_fused_double_fused3_without_fma_hardware_says_so():
    def body(a: reactor.Double) -> reactor.Double:
        return reactor.MulAdd(a, a, a)
    with pytest.raises(reactor.ReactorError, match="Double values needs an FMA instruction"):
        kernel(body, name="fma_double_emulate", target="sse4", fma="emulate")
