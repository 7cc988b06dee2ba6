"""Which microarchitecture this is, and the latencies the clock calibration relies on.

The clock is calibrated by timing a chain of dependent fused multiply-adds
(``clock.py``), so it needs the FMA latency of the core it runs on; a second
chain of dependent additions cross-checks it. Both latencies differ between
microarchitectures: FADD is 4 cycles on Skylake-X and Ice Lake, 3 on Zen 3/4,
2 on Golden Cove (Sapphire Rapids) and Zen 5. A table that assumes one core is
wrong on the others, so the core is identified from ``/proc/cpuinfo`` (vendor,
family, model), then from LLVM's host CPU name, and an unknown core gets the
``generic`` row, which says so.

========================  ===  ====  ==========================================================
microarchitecture         FMA  FADD  source
========================  ===  ====  ==========================================================
zen3 / zen4 (AMD 19h)     4    3     AMD Software Optimization Guide, family 19h (pub. 56665,
                                     57647); uops.info ZEN3/ZEN4 (VFMADD231PS, VADDPS)
zen5 (AMD 1Ah)            4    2     AMD Software Optimization Guide, family 1Ah (pub. 58455);
                                     uops.info ZEN5
zen1 / zen2 (AMD 17h)     5    3     AMD Software Optimization Guide, family 17h (pub. 55723)
golden cove (SPR, ADL-P)  4    2     Intel Optimization Reference Manual (Golden Cove "fast
                                     adders"); uops.info ADL-P, EMR
sunny cove (ICX, RKL)     4    4     Intel Optimization Reference Manual; uops.info ICL, RKL
skylake-x (SKX, CLX)      4    4     Intel Optimization Reference Manual; uops.info SKX, CLX
haswell / broadwell       5    3     Intel Optimization Reference Manual; uops.info HSW, BDW
neoverse v1 (AArch64)     4    2     Arm Neoverse V1 Software Optimization Guide (FMLA 4, FADD 2)
generic (unknown core)    4    3     an assumption: FMA latency is 4 on every core above made
                                     since 2017; the cross-check is not meaningful
========================  ===  ====  ==========================================================
"""
from __future__ import annotations

import dataclasses
import functools
import platform


@dataclasses.dataclass(frozen=True)
class Microarchitecture:
    """A core's name and the latencies (cycles) of the two calibration chains."""

    name: str
    fma: int
    fadd: int
    source: str
    known: bool = True

    def latency(self, op: str) -> int:
        return {"fma": self.fma, "fadd": self.fadd}[op]


_AMD_19H = "AMD SOG family 19h (pub. 56665/57647); uops.info ZEN3/ZEN4"
_INTEL_ORM = "Intel 64 and IA-32 Optimization Reference Manual; uops.info"
TABLE = {
    "zen4": Microarchitecture("zen4", 4, 3, _AMD_19H),
    "zen3": Microarchitecture("zen3", 4, 3, _AMD_19H),
    "zen5": Microarchitecture("zen5", 4, 2, "AMD SOG family 1Ah (pub. 58455); uops.info ZEN5"),
    "zen2": Microarchitecture("zen2", 5, 3, "AMD SOG family 17h (pub. 55723)"),
    "goldencove": Microarchitecture("goldencove", 4, 2, _INTEL_ORM + " ADL-P/EMR"),
    "sunnycove": Microarchitecture("sunnycove", 4, 4, _INTEL_ORM + " ICL/RKL"),
    "skylakex": Microarchitecture("skylakex", 4, 4, _INTEL_ORM + " SKX/CLX"),
    "haswell": Microarchitecture("haswell", 5, 3, _INTEL_ORM + " HSW/BDW"),
    "neoversev1": Microarchitecture("neoversev1", 4, 2, "Arm Neoverse V1 Software Optimization Guide"),
    "generic": Microarchitecture("generic", 4, 3, "assumed (unknown core): FMA latency 4", known=False),
}

# Intel family 6 model numbers (Intel SDM vol. 4, "CPUID Signature Values").
_INTEL_MODELS = {
    "skylakex": (0x55, 0x4E, 0x5E, 0x8E, 0x9E, 0xA5, 0xA6),  # SKX/CLX/CPX and the Skylake clients
    "sunnycove": (0x6A, 0x6C, 0x7D, 0x7E, 0x8C, 0x8D, 0xA7, 0xA8),  # ICX, ICL, TGL, RKL
    "goldencove": (0x8F, 0xCF, 0x97, 0x9A, 0xB7, 0xBA, 0xBF, 0xAA, 0xAC, 0xAD, 0xAE),  # SPR, EMR, ADL, RPL, MTL, GNR
    "haswell": (0x3C, 0x3F, 0x45, 0x46, 0x3D, 0x47, 0x4F, 0x56),
}
# LLVM host CPU names (llvm/lib/TargetParser/Host.cpp) for when /proc/cpuinfo is silent.
_LLVM_NAMES = {
    "znver4": "zen4", "znver3": "zen3", "znver5": "zen5", "znver2": "zen2", "znver1": "zen2",
    "sapphirerapids": "goldencove", "emeraldrapids": "goldencove", "alderlake": "goldencove",
    "raptorlake": "goldencove", "meteorlake": "goldencove", "graniterapids": "goldencove",
    "icelake-server": "sunnycove", "icelake-client": "sunnycove", "tigerlake": "sunnycove",
    "rocketlake": "sunnycove", "skylake-avx512": "skylakex", "cascadelake": "skylakex",
    "cooperlake": "skylakex", "skylake": "skylakex", "haswell": "haswell", "broadwell": "haswell",
    "neoverse-v1": "neoversev1",
}


def identify(info: dict) -> Microarchitecture:
    """The table row for a CPU described like :func:`cpu_model`'s result."""
    vendor, family, model = info.get("vendor"), info.get("family"), info.get("model")
    if vendor == "AuthenticAMD" and family is not None:
        if family == 0x19:
            return TABLE["zen4" if model is not None and (0x10 <= model <= 0x1F or 0x60 <= model <= 0x7F
                                                          or 0xA0 <= model <= 0xAF) else "zen3"]
        if family == 0x1A:
            return TABLE["zen5"]
        if family == 0x17:
            return TABLE["zen2"]
    if vendor == "GenuineIntel" and family == 6 and model is not None:
        for name, models in _INTEL_MODELS.items():
            if model in models:
                return TABLE[name]
    by_llvm = _LLVM_NAMES.get(info.get("llvm_cpu") or "")
    return TABLE[by_llvm] if by_llvm else TABLE["generic"]


def cpu_model() -> dict:
    """Vendor, family, model and model name from /proc/cpuinfo, LLVM's host CPU
    name, and the microarchitecture row chosen from them (``uarch``, ``known``)."""
    info: dict[str, object] = {"vendor": None, "family": None, "model": None, "name": None,
                               "machine": platform.machine()}
    keys = {"vendor_id": "vendor", "cpu family": "family", "model": "model", "model name": "name"}
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if not line.strip():
                    break  # the first processor's block is enough
                key, _, value = line.partition(":")
                field = keys.get(key.strip())
                if field and info[field] is None:
                    value = value.strip()
                    info[field] = int(value) if field in ("family", "model") and value.isdigit() else value
    except OSError:
        pass
    info["llvm_cpu"] = _llvm_cpu()
    uarch = identify(info)
    info["uarch"], info["known"] = uarch.name, uarch.known
    return info


@functools.cache
def _llvm_cpu() -> str | None:
    import llvmlite.binding as llvm
    return llvm.get_host_cpu_name()


@functools.cache
def host() -> Microarchitecture:
    """The table row for the CPU this process runs on."""
    return identify(cpu_model())
