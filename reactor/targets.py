"""Code-generation targets: the host CPU, a forced x86 level, or AArch64.

The target is a build setting (see ``reactor.build``): resolved once per
build into a ``Target`` object that every layer reads (the IR emitter for the
triple, data layout and CPU features, the JIT for the machine).

A target fixes the LLVM triple, CPU name and feature string, and from them the
natural SIMD width (16 lanes of float32 with AVX-512, 8 with AVX2, else 4) and
whether FMA exists. A forced target whose features the host lacks, or whose
architecture is not the host's (``aarch64`` on an x86 machine), can still be
compiled (to read its assembly, or to run under an emulator: see
``reactor.kernels.qemu``) but its code refuses to run in this process.

``aarch64`` is ARMv8.2-A with NEON (LLVM's ``neoverse-n1``: AWS Graviton2, and a
subset of Apple M1 and Graviton3): 4 float32 lanes, fused multiply-add always
(FMADD/FMLA are part of the base architecture). On an ARM machine ``host`` is
the machine's own CPU.
"""
from __future__ import annotations

import dataclasses
import functools

import llvmlite.binding as llvm

from .errors import ReactorError


@functools.cache
def _llvm_ready() -> None:
    llvm.initialize_native_target()
    llvm.initialize_native_asmprinter()
    llvm.initialize_native_asmparser()


@functools.cache
def _all_architectures() -> None:
    """Other architectures' code generators: ~2 ms, paid only by a build for one (AArch64)."""
    _llvm_ready()
    llvm.initialize_all_targets()
    llvm.initialize_all_asmprinters()


@dataclasses.dataclass(frozen=True)
class Target:
    """An LLVM code-generation target."""

    name: str
    triple: str
    cpu: str
    features: str
    required: tuple[str, ...]

    @property
    def arch(self) -> str:
        """The instruction set: "x86_64" or "aarch64" (from the triple)."""
        return architecture(self.triple)

    @functools.cached_property
    def feature_set(self) -> frozenset[str]:
        """Every feature code for this target may use (the CPU's, implied ones included;
        "fma" on every AArch64 target, whose base architecture has fused multiply-add)."""
        feats = host_features() if self.name == "host" else frozenset(_FORCED[self.name][3])
        return feats | {"fma"} if self.arch == "aarch64" else feats

    @property
    def natural_width(self) -> int:
        if "avx512f" in self.feature_set:
            return 16
        if "avx2" in self.feature_set:
            return 8
        return 4

    @property
    def fast_gather(self) -> bool:
        """Whether gather instructions beat one load per lane: Intel's cores from Skylake on (as
        LLVM tunes them); not AMD's (a 16-lane ``vgatherdps`` costs ~32 cycles on Zen 4,
        measured), Haswell's, or AArch64's (which has none)."""
        return self.arch == "x86_64" and self.cpu.startswith(_FAST_GATHER)

    @property
    def has_fma(self) -> bool:
        return "fma" in self.feature_set

    @property
    def runnable(self) -> bool:
        """Whether this process can run the target's code (same architecture, every required feature)."""
        return self.arch == host_arch() and set(self.required) <= host_features()

    def missing(self) -> str:
        """What this CPU lacks to run the target's code (for error messages)."""
        if self.arch != host_arch():
            return f"it is {host_arch()}, not {self.arch}"
        return f"it lacks {', '.join(sorted(set(self.required) - host_features()))}"

    @functools.cached_property
    def machine(self) -> llvm.TargetMachine:
        _llvm_ready()
        if self.arch != host_arch():
            _all_architectures()
        return llvm.Target.from_triple(self.triple).create_target_machine(
            cpu=self.cpu, features=self.features, opt=3, reloc="pic", codemodel="default"
        )

    @functools.cached_property
    def quick_machine(self) -> llvm.TargetMachine:
        """The same target at LLVM's quickest code generation (no optimization: ~5x faster to
        emit, slower code): a tiered kernel's first code (``reactor.kernels.tiers``)."""
        _ = self.machine  # the same initialization
        return llvm.Target.from_triple(self.triple).create_target_machine(
            cpu=self.cpu, features=self.features, opt=0, reloc="pic", codemodel="default"
        )

    @functools.cached_property
    def data_layout(self) -> str:
        return str(self.machine.target_data)

    def key(self) -> str:
        """Everything about the target that changes generated code."""
        return f"{self.triple}|{self.cpu}|{self.features}"


def architecture(triple: str) -> str:
    """ "x86_64" or "aarch64" for an LLVM triple (anything else: its first field)."""
    arch = triple.split("-")[0]
    return {"arm64": "aarch64", "amd64": "x86_64"}.get(arch, arch)


@functools.cache
def host_arch() -> str:
    _llvm_ready()
    return architecture(llvm.get_process_triple())


@functools.cache
def host_features() -> frozenset[str]:
    _llvm_ready()
    return frozenset(k for k, v in llvm.get_host_cpu_features().items() if v)


#: CPUs (LLVM names) with fast gathers: LLVM's TuningFastGather processors
_FAST_GATHER = ("skylake", "cascadelake", "cooperlake", "cannonlake", "icelake", "tigerlake", "rocketlake",
                "sapphirerapids", "emeraldrapids", "graniterapids", "alderlake", "raptorlake", "meteorlake",
                "arrowlake", "lunarlake", "pantherlake", "diamondrapids", "x86-64-v4")

# Forced targets: (triple, cpu, required features, every feature the CPU implies). LLVM
# derives its feature set from the CPU name; "required" is what the host must
# have to run the code; the implied set is what the DSL may use (estimates,
# AVX-512 instructions) and must match what LLVM enables for that CPU.
_SSE4 = ("sse", "sse2", "sse3", "ssse3", "sse4.1", "sse4.2", "popcnt", "cx16")
_AVX2 = _SSE4 + ("avx", "avx2", "fma", "f16c", "bmi", "bmi2", "lzcnt", "movbe")
_AVX512 = _AVX2 + ("avx512f", "avx512vl", "avx512bw", "avx512dq", "avx512cd")
_NEON = ("neon", "fp-armv8", "crc", "lse", "rdm", "fullfp16", "dotprod")
_X86 = "x86_64-unknown-linux-gnu"
_FORCED = {
    "avx512": (_X86, "skylake-avx512", ("avx512f", "avx512vl", "avx512bw", "avx512dq", "avx2", "fma"), _AVX512),
    "avx2": (_X86, "haswell", ("avx2", "fma"), _AVX2),
    "sse4": (_X86, "nehalem", ("sse4.1", "sse4.2"), _SSE4),
    "aarch64": ("aarch64-unknown-linux-gnu", "neoverse-n1", ("neon",), _NEON),
}

TARGETS = ("host",) + tuple(_FORCED)


@functools.cache
def get_target(name: str = "host") -> Target:
    """Return the target called ``name`` (one of ``TARGETS``)."""
    _llvm_ready()
    triple = llvm.get_process_triple()
    if name == "host":
        feats = llvm.get_host_cpu_features().flatten()
        return Target("host", triple, llvm.get_host_cpu_name(), feats, ())
    if name not in _FORCED:
        raise ReactorError(f"unknown target {name!r}; choose one of {', '.join(TARGETS)}")
    forced_triple, cpu, required, _ = _FORCED[name]
    if architecture(forced_triple) == architecture(triple):
        forced_triple = triple  # the host's own spelling (vendor, OS, ABI)
    return Target(name, forced_triple, cpu, "", required)
