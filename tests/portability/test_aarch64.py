"""AArch64: kernels built for it are real AArch64 code, run under qemu-user, with x86's bits.

Tests that run code need qemu-user and the cross toolchain (CI installs them); they skip
where those are absent. Building and reading the assembly needs only llvmlite.
"""
import numpy as np
import pytest

import reactor
import routines
from reactor import Float
from routines.lab import crosstarget
from routines.lab.fingerprint import pow_inputs, unary_inputs

needs_emulator = pytest.mark.skipif(reactor.emulator_missing() is not None,
                                    reason=f"needs {reactor.emulator_missing()} to run AArch64 code")
#: The x86 build AArch64 is compared with: one without AVX-512, whose RCP14/RSQRT14 estimates (in
#: relaxed sqrt, rcp, rsqrt and what uses them: normalize, asin, acos, the hyperbolics) differ by design.
REF = "avx2" if reactor.get_target("avx2").runnable else "sse4"


def _bits(a):
    return np.asarray(a).view(np.uint32)


def test_aarch64_target_is_neon_with_fma():
    t = reactor.get_target("aarch64")
    assert t.arch == "aarch64" and t.triple.startswith("aarch64")
    assert t.natural_width == 4 and t.has_fma
    assert not t.runnable  # this suite runs on x86


def test_dump_shows_aarch64_assembly_and_no_x86():
    u = routines.jit("exp2", target="aarch64")
    asm = reactor.kernel_of(u).assembly
    assert "fmla" in asm and ".4s" in asm  # NEON fused multiply-add on 4 lanes
    assert "%xmm" not in asm and "ymm" not in asm
    ir = reactor.kernel_of(u).ir
    assert "llvm.x86" not in ir and "llvm.aarch64.get.fpsr" in ir  # FPSR, not MXCSR


def test_every_routine_builds_for_aarch64_without_an_x86_intrinsic():
    for name in routines.NAMES:
        for precision in ("full", "relaxed"):
            ir = reactor.kernel_of(routines.jit(name, precision=precision, target="aarch64")).ir
            assert "llvm.x86." not in ir, name


def test_an_x86_intrinsic_in_aarch64_code_is_a_build_error_naming_it():
    from reactor.ir import emitter

    with pytest.raises(reactor.ReactorError, match=r"llvm\.x86\.sse\.rcp\.ps is an x86_64 instruction.*'aarch64'"):
        emitter._check_architecture("llvm.x86.sse.rcp.ps", reactor.get_target("aarch64"))
    emitter._check_architecture("llvm.x86.sse.rcp.ps", reactor.get_target("sse4"))  # fine there


def test_calling_an_aarch64_kernel_here_says_why_and_what_to_do():
    @reactor.kernel("float32(float32)", target="aarch64")
    def twice(x: Float) -> Float:
        return x + x

    with pytest.raises(reactor.ReactorError, match="it is x86_64, not aarch64.*Emulator"):
        twice(np.ones(4, np.float32))


@needs_emulator
def test_a_kernel_runs_under_qemu_contiguous_strided_and_broadcast():
    @reactor.kernel("float32(float32, float32)", target="aarch64")
    def saxpy(x: Float, y: Float) -> Float:
        return reactor.MulAdd(x, 3.0, y)

    x = np.arange(1003, dtype=np.float32)
    y = np.full(1003, 0.5, np.float32)
    expect = x * np.float32(3) + y
    assert np.array_equal(reactor.run_emulated(saxpy, x, y), expect)
    assert np.array_equal(reactor.run_emulated(saxpy, x, y, strided=True), expect)
    assert np.array_equal(reactor.run_emulated(saxpy, x, np.float32(0.5)), expect)  # step 0


@needs_emulator
def test_an_invalid_square_root_gives_the_x86_default_nan():
    @reactor.kernel("float32(float32)", target="aarch64")
    def root(x: Float) -> Float:
        return reactor.Sqrt(x)

    x = np.array([-1, -np.inf, 4, np.nan, -0.0, -1e-45], np.float32)
    got = reactor.run_emulated(root, x)
    assert [hex(b) for b in _bits(got)] == ["0xffc00000", "0xffc00000", "0x40000000", "0x7fc00000",
                                            "0x80000000", "0xffc00000"]


@needs_emulator
@pytest.mark.parametrize("name", ["exp2", "log2", "pow", "sin", "acos", "sqrt", "atan2"])
def test_routine_bits_match_x86_on_specials_and_a_sweep(name):
    """Every precision and FMA setting, NaN payloads included (the whole set: crosstarget's test)."""
    n = 2 ** 14
    args = pow_inputs(n) if name in ("pow", "atan2") else (unary_inputs(n),)
    ufuncs, refs = [], []
    for precision in ("full", "relaxed"):
        for fma in (True, False):
            ufuncs.append(routines.jit(name, precision=precision, fma=fma, target="aarch64"))
            refs.append(routines.jit(name, precision=precision, fma=fma if reactor.get_target(REF).has_fma else
                                     ("emulate" if fma else False), target=REF)(*args))
    with reactor.Emulator(ufuncs) as run:
        outs = run([(i, args) for i in range(len(ufuncs))])
    for (out,), ref in zip(outs, refs):
        bad = np.flatnonzero(_bits(out) != _bits(ref))
        assert bad.size == 0, (name, [(args[0][i], hex(_bits(ref)[i]), hex(_bits(out)[i])) for i in bad[:5]])


@needs_emulator
def test_every_routine_variant_on_every_target_gives_the_same_bits():
    rows = crosstarget.compare(routines.NAMES, ["aarch64", "sse4", "host"], reference=REF, n=2 ** 16)
    assert len(rows) == len(routines.NAMES) * 2 * 2 * 3
    bad = [crosstarget._line(r) for r in rows if r["differ"] and not crosstarget.by_estimate(r)]
    assert not bad, bad


# -- real shaders ----------------------------------------------------------------------------

def _example(folder, name):
    import pathlib
    import sys
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "examples"))
    import example_runner
    return example_runner.load(folder, name)


@needs_emulator
@pytest.mark.parametrize("name", ["gltf_pbr", "noise", "raymarch", "sky", "tonemap"])
def test_the_example_shaders_give_x86_bits_on_aarch64(name):
    """The ported public shaders (examples/shaders) on AArch64 under qemu: every output bit as here,
    contiguous and strided. A NaN lane must be NaN there too, but may be another NaN: these inputs
    (uniform in [-2, 2], far outside what the shaders expect) make NaNs that meet other NaNs in the
    shaders' own arithmetic, where the hardware chooses which comes out (docs/dsl.md)."""
    module = _example("shaders", name)
    for precision in ("full", "relaxed"):
        here, there = module.build(precision, target=REF), module.build(precision, target="aarch64")
        rng = np.random.default_rng(3)
        args = [rng.uniform(-2, 2, 3001).astype(np.float32) for _ in reactor.kernel_of(here).ins]
        for layout in (slice(None), slice(None, None, 2)):
            want, got = here(*[a[layout] for a in args]), reactor.run_emulated(there, *[a[layout] for a in args])
            want, got = (want, got) if isinstance(want, tuple) else ((want,), (got,))
            for w, g in zip(want, got):
                nan = np.isnan(w)
                assert np.array_equal(nan, np.isnan(g)), (name, precision)
                assert np.array_equal(_bits(w)[~nan], _bits(g)[~nan]), (name, precision)


@pytest.mark.parametrize("name, body", [("sphere", "render"), ("sphere", "normal_map"), ("lut", "lut_rgba8"),
                                        ("perlin", "perlin_rgba8")])
def test_texture_kernels_build_for_aarch64(name, body):
    """Textures, tables, gathers, filtering and pixel formats compile to NEON code (no x86 intrinsic)."""
    module = _example("textures", name)
    with reactor.options(target="aarch64"):
        k = reactor.kernel_of(module.build(getattr(module, body)))
    assert k.build.target.arch == "aarch64" and "llvm.x86" not in k.ir and ".4s" in k.assembly
