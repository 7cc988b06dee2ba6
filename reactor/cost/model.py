"""A dataflow cost model of a kernel's vector loop (shared/refs/003, "dataflow graphs").

The loop body of a kernel (from block ``vec.body`` of its optimized IR back
to it: :func:`iteration`) is a dataflow graph: each instruction a node, each
operand an edge. Iterations are independent, so an out-of-order core overlaps
them and the steady state is bounded by *throughput*: for every class of
operation, the number of such operations per vector divided by how many the
machine can start per cycle; and by the issue width over all operations.
The *critical path* (the longest latency chain through one iteration) tells
how many iterations must be in flight to reach that bound.

The machine is described by a :class:`Machine`: a table of operation classes
(each with a latency in cycles, a throughput in operations per cycle and the
execution pipes it can run on), its FP/vector issue width, its native vector
width and how it runs an operation wider than one pipe (``split``). An
operation takes ``ceil(bits / slot_bits)`` slots: on Zen 4 (256-bit pipes)
a 512-bit zmm operation is two 256-bit halves, two slots; Zen 5 has 512-bit
pipes (one slot); a core without 512-bit registers (Zen 3, Haswell: 256;
Neoverse V1 NEON: 128) gets a wider vector of the IR split by LLVM into
several native instructions. Intel's AVX-512 cores run a 512-bit operation
natively, as one operation, but on other ports (ports 0 and 1 fused, and
port 5): their tables carry ``wide_ops`` for 512-bit operations.

Tables (:data:`MACHINES`; every one has the same classes): ``zen2``,
``zen3``, ``zen4``, ``zen5``, ``goldencove`` (Sapphire Rapids),
``sunnycove`` (Ice Lake), ``skylakex``, ``haswell`` (AVX2 class),
``neoversev1`` (AArch64 NEON), and ``generic`` for an unknown core (a stated
assumption). Each table's provenance is in its ``source`` and the comment
above it; numbers are rounded. :func:`host_machine` chooses the table of the
CPU this process runs on (``cpus.py`` identifies it) and falls back to
``generic``, saying why; :func:`machine_for` gives a table by name (table
key or LLVM CPU name). Every prediction names the table it used
(:attr:`Prediction.machine_label`, and :meth:`Prediction.explain`).

Classes share pipes (for Zen 4 the pipe map of AMD's Software Optimization
Guide for Family 19h, pub. 57647, section 2.11.1, as encoded in LLVM's
``X86ScheduleZnver4.td``): FP0/FP1 run multiplies, FMAs, compares, min/max
and reciprocal estimates; FP2/FP3 additions, conversions and roundings; all
four integer ALU ops and logic; FP1/FP2 shifts and shuffles; FP1 the
divider/square root. The throughput bound is therefore the largest, over
every set S of pipes, of (slots of the classes that can only run on S) / |S|
(with an operation that keeps a pipe busy for several cycles counted that
many times): the exact bound of spreading the work over the pipes.
"""
from __future__ import annotations

import collections
import ctypes
import dataclasses
import functools
import math
import re
import types
from collections.abc import Mapping

import llvmlite.binding as llvm

from . import cpus


@dataclasses.dataclass(frozen=True)
class OpClass:
    latency: float
    per_cycle: float  # operations of up to the machine's slot width started per cycle (all pipes of the class)
    what: str
    pipes: tuple = ()  # the pipes it can use (empty: a resource of its own)

    @property
    def busy(self) -> float:
        """Cycles one operation (one slot) keeps one of its pipes busy."""
        return len(self.pipes) / self.per_cycle if self.pipes else 1 / self.per_cycle


# -- the tables -------------------------------------------------------------------------------
# Latency in cycles; per_cycle in operations of the machine's slot width per cycle; rounded.

_FP01, _FP23, _FP12, _FP0123 = ("FP0", "FP1"), ("FP2", "FP3"), ("FP1", "FP2"), ("FP0", "FP1", "FP2", "FP3")
_CALL = OpClass(20, 0.1, "external call (opaque)")

# AMD Zen 4 (family 19h, models 10h-1Fh, 60h-7Fh, A0h-AFh): AMD Software Optimization Guide
# for Family 19h (pub. 57647) and uops.info ZEN4; pipes as in LLVM X86ScheduleZnver4.td.
# Four 256-bit FP pipes; a 512-bit operation is two 256-bit halves (two slots).
ZEN4 = {
    "fma": OpClass(4, 2, "fused multiply-add (FP0/FP1)", _FP01),
    "fmul": OpClass(3, 2, "multiply (FP0/FP1)", _FP01),
    "fadd": OpClass(3, 2, "add/subtract (FP2/FP3)", _FP23),
    "fminmax": OpClass(2, 2, "compare-select min/max (FP0/FP1)", _FP01),
    "fcmp": OpClass(3, 2, "compare into a mask (FP0/FP1)", _FP01),
    "blend": OpClass(1, 4, "select: masked move, or folded into the producer's mask (any FP pipe)", _FP0123),
    "convert": OpClass(4, 2, "float<->int conversion (FP2/FP3)", _FP23),
    "round": OpClass(3, 2, "floor/ceil/round, VREDUCEPS, VGETEXPPS, VGETMANTPS (FP2/FP3)", _FP23),
    "estimate": OpClass(5, 2, "RCP14 estimate (FP0/FP1)", _FP01),
    "estimate_rsqrt": OpClass(5, 1, "RSQRT14 estimate (FP1)", ("FP1",)),
    "sqrt": OpClass(15, 0.2, "square root (FP1, not pipelined)", ("FP1",)),
    "divide": OpClass(11, 1 / 3, "division (FP1, not pipelined)", ("FP1",)),
    "int": OpClass(1, 4, "integer vector ALU, logic (any FP pipe)", _FP0123),
    "shift": OpClass(1, 2, "vector integer shift (FP1/FP2)", _FP12),
    "shuffle": OpClass(1, 2, "broadcast/shuffle (FP1/FP2)", _FP12),
    "call": _CALL,
    "load": OpClass(7, 2, "vector load (L1 hit)", ("LD0", "LD1")),
    "store": OpClass(1, 1, "vector store", ("ST",)),
}
ISSUE_WIDTH = 4  # Zen 4: 256-bit FP/vector slots per cycle

# AMD Zen 3 (family 19h, models 00h-0Fh, 20h-5Fh): AMD SOG for Family 19h (pub. 56665), LLVM
# X86ScheduleZnver3.td (latencies from llvm-exegesis), uops.info ZEN3. The pipes of Zen 4, no
# AVX-512: compares write a vector mask (VCMPPS, 1 cycle), a select is VBLENDVPS on FP0/FP1,
# min/max 1 cycle; VRCPPS/VRSQRTPS 3 cycles. A 512-bit vector of the IR is two ymm instructions.
ZEN3 = dict(ZEN4) | {
    "fminmax": OpClass(1, 2, "VMINPS/VMAXPS (FP0/FP1)", _FP01),
    "fcmp": OpClass(1, 2, "VCMPPS into a vector mask (FP0/FP1)", _FP01),
    "blend": OpClass(1, 2, "select: VBLENDVPS (FP0/FP1)", _FP01),
    "convert": OpClass(3, 2, "float<->int conversion (FP2/FP3)", _FP23),
    "round": OpClass(3, 2, "VROUNDPS floor/ceil/round (FP2/FP3)", _FP23),
    "estimate": OpClass(3, 2, "VRCPPS estimate (FP0/FP1)", _FP01),
    "estimate_rsqrt": OpClass(3, 1, "VRSQRTPS estimate (FP1)", ("FP1",)),
    "load": OpClass(7, 2, "vector load (L1 hit; at most two 256-bit loads per cycle)", ("LD0", "LD1")),
}

# AMD Zen 2 (family 17h; cpus.py also files Zen 1 here): AMD SOG for Family 17h (pub. 56305)
# and LLVM X86ScheduleZnver2.td: Zen 3's pipe layout and latencies but a 5-cycle FMA and
# 5-cycle VRCPPS. (Zen 1 runs a 256-bit operation as two 128-bit halves: this table is
# optimistic for it by up to 2x.)
ZEN2 = dict(ZEN3) | {
    "fma": OpClass(5, 2, "fused multiply-add (FP0/FP1)", _FP01),
    "estimate": OpClass(5, 2, "VRCPPS estimate (FP0/FP1)", _FP01),
    "estimate_rsqrt": OpClass(5, 1, "VRSQRTPS estimate (FP1)", ("FP1",)),
}

# AMD Zen 5 (family 1Ah; desktop/server: Granite Ridge, Turin): AMD SOG for family 1Ah
# (pub. 58455), LLVM X86ScheduleZnver5.td (pipes, latencies), A. Yee's "Zen5's AVX512
# Teardown" (numberworld.org, 2024: all four FP pipes 512 bits wide, two 512-bit FMAs and two
# 512-bit adds per cycle). One slot is a 512-bit operation. FADD 2 cycles; simple vector
# integer/logic/shuffle/masked-move ops 2 cycles (1 on Zen 4). The divider/square root is
# taken as LLVM models it for zmm (not widened: 10 resp. 6 cycles of FP1 per zmm op). Mobile
# Zen 5 (Strix Point) has 256-bit pipes: use the zen4 table for it.
ZEN5 = {
    "fma": OpClass(4, 2, "fused multiply-add (FP0/FP1, 512-bit)", _FP01),
    "fmul": OpClass(3, 2, "multiply (FP0/FP1)", _FP01),
    "fadd": OpClass(2, 2, "add/subtract (FP2/FP3)", _FP23),
    "fminmax": OpClass(2, 2, "compare-select min/max (FP0/FP1)", _FP01),
    "fcmp": OpClass(3, 2, "compare into a mask (FP0/FP1)", _FP01),
    "blend": OpClass(2, 4, "select: masked move (any FP pipe)", _FP0123),
    "convert": OpClass(4, 2, "float<->int conversion (FP2/FP3)", _FP23),
    "round": OpClass(3, 2, "floor/ceil/round, VREDUCEPS, VGETEXPPS, VGETMANTPS (FP2/FP3)", _FP23),
    "estimate": OpClass(5, 2, "RCP14 estimate (FP0/FP1)", _FP01),
    "estimate_rsqrt": OpClass(5, 0.5, "RSQRT14 estimate (FP1)", ("FP1",)),
    "sqrt": OpClass(14, 0.1, "square root (FP1, not pipelined)", ("FP1",)),
    "divide": OpClass(10, 1 / 6, "division (FP1, not pipelined)", ("FP1",)),
    "int": OpClass(2, 4, "integer vector ALU, logic (any FP pipe)", _FP0123),
    "shift": OpClass(2, 2, "vector integer shift (FP1/FP2)", _FP12),
    "shuffle": OpClass(2, 2, "broadcast/shuffle (FP1/FP2)", _FP12),
    "call": _CALL,
    "load": OpClass(7, 2, "vector load (L1 hit; two 512-bit loads per cycle)", ("LD0", "LD1")),
    "store": OpClass(1, 1, "vector store (one 512-bit store per cycle)", ("ST",)),
}

# Intel Skylake-X / Cascade Lake (SKX, CLX): Intel 64 and IA-32 Architectures Optimization
# Reference Manual, LLVM X86SchedSkylakeServer.td, uops.info SKX. Vector ports p0, p1, p5;
# operations of up to 256 bits use p0/p1 (FMA, add, multiply) and p0/p1/p5 (logic, blends);
# a 512-bit operation is one operation on p0 (p0 and p1 fused) or p5: ``wide_ops``. With
# AVX-512VL a compare writes a mask register (p5, 3 cycles). The divider is its own resource.
_P01, _P015, _P05 = ("p0", "p1"), ("p0", "p1", "p5"), ("p0", "p5")
SKYLAKEX = {
    "fma": OpClass(4, 2, "fused multiply-add (p0/p1)", _P01),
    "fmul": OpClass(4, 2, "multiply (p0/p1)", _P01),
    "fadd": OpClass(4, 2, "add/subtract (p0/p1)", _P01),
    "fminmax": OpClass(4, 2, "min/max (p0/p1)", _P01),
    "fcmp": OpClass(3, 1, "compare into a mask (p5)", ("p5",)),
    "blend": OpClass(1, 3, "select: masked move/VBLENDMPS (p0/p1/p5)", _P015),
    "convert": OpClass(4, 2, "float<->int conversion (p0/p1)", _P01),
    "round": OpClass(8, 1, "VRNDSCALEPS/VROUNDPS, two uops (p0/p1)", _P01),
    "estimate": OpClass(4, 1, "RCP14 estimate (p0)", ("p0",)),
    "estimate_rsqrt": OpClass(4, 1, "RSQRT14 estimate (p0)", ("p0",)),
    "sqrt": OpClass(12, 1 / 6, "square root (divider, 6 cycles per ymm)", ("DIV",)),
    "divide": OpClass(11, 1 / 5, "division (divider, 5 cycles per ymm)", ("DIV",)),
    "int": OpClass(1, 3, "integer vector ALU, logic (p0/p1/p5)", _P015),
    "shift": OpClass(1, 2, "vector integer shift (p0/p1)", _P01),
    "shuffle": OpClass(1, 1, "broadcast/shuffle (p5)", ("p5",)),
    "call": _CALL,
    "load": OpClass(7, 2, "vector load (L1 hit, p2/p3)", ("LD0", "LD1")),
    "store": OpClass(1, 1, "vector store (p4)", ("ST",)),
}
SKYLAKEX_512 = {
    "fma": OpClass(4, 2, "512-bit fused multiply-add (p0+p1 fused, p5)", _P05),
    "fmul": OpClass(4, 2, "512-bit multiply (p0, p5)", _P05),
    "fadd": OpClass(4, 2, "512-bit add/subtract (p0, p5)", _P05),
    "fminmax": OpClass(4, 2, "512-bit min/max (p0, p5)", _P05),
    "fcmp": OpClass(3, 1, "512-bit compare into a mask (p5)", ("p5",)),
    "blend": OpClass(1, 2, "512-bit masked move/VBLENDMPS (p0, p5)", _P05),
    "convert": OpClass(4, 1, "512-bit float<->int conversion (p0)", ("p0",)),
    "round": OpClass(8, 1, "512-bit VRNDSCALEPS, two uops (p0, p5)", _P05),
    "estimate": OpClass(4, 0.5, "512-bit RCP14 (two uops on p0, one on p5)", ("p0",)),
    "estimate_rsqrt": OpClass(9, 0.5, "512-bit RSQRT14 (two uops on p0, one on p5)", ("p0",)),
    "sqrt": OpClass(20, 1 / 12, "512-bit square root (divider, 12 cycles)", ("DIV",)),
    "divide": OpClass(18, 1 / 10, "512-bit division (divider, 10 cycles)", ("DIV",)),
    "int": OpClass(1, 2, "512-bit integer ALU, logic (p0, p5)", _P05),
    "shift": OpClass(1, 1, "512-bit integer shift (p0)", ("p0",)),
    "shuffle": OpClass(1, 1, "512-bit broadcast/shuffle (p5)", ("p5",)),
    "call": _CALL,
    "load": OpClass(8, 2, "512-bit load (L1 hit, p2/p3)", ("LD0", "LD1")),
    "store": OpClass(1, 1, "512-bit store (p4)", ("ST",)),
}

# Intel Sunny Cove (Ice Lake SP/client, Tiger Lake, Rocket Lake): Intel Optimization Reference
# Manual, LLVM X86SchedIceLake.td, uops.info ICL/RKL. Skylake-X's ports, plus a second shuffle
# port (p1) and a second store port for operations up to 256 bits; 512-bit division 17 cycles.
SUNNYCOVE = dict(SKYLAKEX) | {
    "shuffle": OpClass(1, 2, "broadcast/shuffle (p1/p5)", ("p1", "p5")),
    "store": OpClass(1, 2, "vector store (p4/p9)", ("ST0", "ST1")),
}
SUNNYCOVE_512 = dict(SKYLAKEX_512) | {
    "divide": OpClass(17, 1 / 10, "512-bit division (divider, 10 cycles)", ("DIV",)),
    "store": OpClass(1, 1, "512-bit store (one per cycle)", ("ST0",)),
}

# Intel Golden Cove (Sapphire/Emerald Rapids, Alder Lake P-core): Intel Optimization Reference
# Manual ("fast adders" on p1 and p5), LLVM X86SchedSapphireRapids.td, uops.info ADL-P/SPR/EMR.
# Sunny Cove's ports; FADD 2 cycles on p1/p5 (512-bit: p0/p5); three loads per cycle up to
# 256 bits (two of 512); two stores per cycle (one of 512).
GOLDENCOVE = dict(SUNNYCOVE) | {
    "fadd": OpClass(2, 2, "add/subtract, fast adders (p1/p5)", ("p1", "p5")),
    "load": OpClass(7, 3, "vector load (L1 hit, p2/p3/p11)", ("LD0", "LD1", "LD2")),
}
GOLDENCOVE_512 = dict(SUNNYCOVE_512) | {
    "fadd": OpClass(2, 2, "512-bit add/subtract (p0, p5)", _P05),
    "sqrt": OpClass(19, 1 / 12, "512-bit square root (divider, 12 cycles)", ("DIV",)),
}

# Intel Haswell / Broadwell (AVX2 class, no AVX-512): Intel Optimization Reference Manual,
# LLVM X86SchedHaswell.td, uops.info HSW/BDW. FMA and multiply 5 cycles on p0/p1; add,
# min/max, compare, conversion on p1 only (3 cycles); VBLENDVPS two uops on p5; VROUNDPS two
# uops on p1; VRCPPS/VRSQRTPS ymm three uops (two on p0), 7 cycles; the divider 14 cycles per ymm.
HASWELL = {
    "fma": OpClass(5, 2, "fused multiply-add (p0/p1)", _P01),
    "fmul": OpClass(5, 2, "multiply (p0/p1)", _P01),
    "fadd": OpClass(3, 1, "add/subtract (p1)", ("p1",)),
    "fminmax": OpClass(3, 1, "min/max (p1)", ("p1",)),
    "fcmp": OpClass(3, 1, "VCMPPS into a vector mask (p1)", ("p1",)),
    "blend": OpClass(2, 0.5, "select: VBLENDVPS, two uops (p5)", ("p5",)),
    "convert": OpClass(3, 1, "float<->int conversion (p1)", ("p1",)),
    "round": OpClass(6, 0.5, "VROUNDPS, two uops (p1)", ("p1",)),
    "estimate": OpClass(7, 0.5, "VRCPPS ymm (two uops on p0)", ("p0",)),
    "estimate_rsqrt": OpClass(7, 0.5, "VRSQRTPS ymm (two uops on p0)", ("p0",)),
    "sqrt": OpClass(19, 1 / 14, "square root (divider, 14 cycles per ymm)", ("DIV",)),
    "divide": OpClass(18, 1 / 14, "division (divider, 14 cycles per ymm)", ("DIV",)),
    "int": OpClass(1, 3, "integer vector ALU, logic (p0/p1/p5)", _P015),
    "shift": OpClass(1, 1, "vector integer shift (p0)", ("p0",)),
    "shuffle": OpClass(1, 1, "broadcast/shuffle (p5)", ("p5",)),
    "call": _CALL,
    "load": OpClass(7, 2, "vector load (L1 hit, p2/p3)", ("LD0", "LD1")),
    "store": OpClass(1, 1, "vector store (p4)", ("ST",)),
}

# Arm Neoverse V1 (AArch64, Graviton 3): Arm Neoverse V1 Software Optimization Guide, as
# encoded in LLVM AArch64SchedNeoverseV1.td. Four 128-bit FP/ASIMD pipes V0-V3: FMLA (4
# cycles; an accumulator chain forwards in 2), FMUL (3), FADD/FMAX/FCM/BSL and integer ops (2)
# on all four; FCVTZS/SCVTF and FRINT .4s two uops on V0/V2 (4 cycles), FRECPE/FRSQRTE one
# uop on V0/V2 (4); FDIV/FSQRT .4s on V0/V2, 10 cycles, 7 cycles of the pipe each; shifts on
# V1/V3. Three loads (6 cycles) and two stores per cycle. reactor emits NEON (128 bits):
# a 256- or 512-bit vector of the IR is two or four instructions. SVE is not modelled.
_V, _V02, _V13 = ("V0", "V1", "V2", "V3"), ("V0", "V2"), ("V1", "V3")
NEOVERSEV1 = {
    "fma": OpClass(4, 4, "FMLA fused multiply-add (V0-V3)", _V),
    "fmul": OpClass(3, 4, "FMUL (V0-V3)", _V),
    "fadd": OpClass(2, 4, "FADD/FSUB (V0-V3)", _V),
    "fminmax": OpClass(2, 4, "FMINNM/FMAXNM (V0-V3)", _V),
    "fcmp": OpClass(2, 4, "FCMxx into a vector mask (V0-V3)", _V),
    "blend": OpClass(2, 4, "select: BSL/BIT/BIF (V0-V3)", _V),
    "convert": OpClass(4, 1, "FCVTZS/SCVTF .4s, two uops (V0/V2)", _V02),
    "round": OpClass(4, 1, "FRINTx .4s, two uops (V0/V2)", _V02),
    "estimate": OpClass(4, 2, "FRECPE (V0/V2)", _V02),
    "estimate_rsqrt": OpClass(4, 2, "FRSQRTE (V0/V2)", _V02),
    "sqrt": OpClass(10, 2 / 7, "FSQRT .4s (V0/V2, 7 cycles each)", _V02),
    "divide": OpClass(10, 2 / 7, "FDIV .4s (V0/V2, 7 cycles each)", _V02),
    "int": OpClass(2, 4, "integer vector ALU, logic (V0-V3)", _V),
    "shift": OpClass(2, 2, "vector integer shift (V1/V3)", _V13),
    "shuffle": OpClass(2, 4, "DUP/EXT/ZIP/INS (V0-V3)", _V),
    "call": _CALL,
    "load": OpClass(6, 3, "vector load (L1 hit, L0-L2)", ("LD0", "LD1", "LD2")),
    "store": OpClass(1, 2, "vector store (two per cycle)", ("ST0", "ST1")),
}

# generic (unknown core): an assumption, not a measurement -- a 2017-or-later x86 core with four
# 256-bit vector pipes (two FMA/multiply, two add) and Zen 3's latencies (FMA 4, FADD 3 cycles,
# the generic row of cpus.py), a wider vector as several 256-bit slots.
GENERIC = dict(ZEN3)

_SPLITS = {
    "halves": "a wider operation runs as several slot-wide parts on the same pipes",
    "native": "operations up to the slot width run in one pass",
    "fused ports": "a 512-bit operation runs as one operation on p0 (p0+p1 fused) and p5",
    "legalized": "a vector wider than a register is split by LLVM into several native instructions",
}


@dataclasses.dataclass(frozen=True)
class Machine:
    """One core's description for the model (see the module docstring)."""

    name: str                      # table key: "zen4"
    title: str                     # "Zen 4"
    source: str                    # where the numbers come from (or, for generic, what is assumed)
    ops: Mapping[str, OpClass]     # the classes, for operations of up to ``slot_bits``
    issue_width: float             # FP/vector slots started per cycle
    vector_bits: int               # native (widest register) vector width: 512 AVX-512, 256 AVX2, 128 NEON
    slot_bits: int                 # what one slot (one pipe pass) processes
    split: str                     # how a wider operation runs (a key of ``_SPLITS``)
    wide_ops: Mapping[str, OpClass] = dataclasses.field(default_factory=dict)  # 512-bit ops ("fused ports")
    dispatch: int = 6              # macro-ops dispatched per cycle (the window bound)
    fp_scheduler: int = 64         # FP/vector scheduler entries (the window bound)
    known: bool = True
    reason: str = ""               # why this table was chosen when the core is unknown

    def __getitem__(self, cls: str) -> OpClass:
        return self.ops[cls]

    def __contains__(self, cls: object) -> bool:
        return cls in self.ops

    def keys(self):
        return self.ops.keys()

    @property
    def label(self) -> str:
        """The table's name as the model's results state it."""
        if self.known:
            return f"{self.title} table"
        why = f" {self.reason}" if self.reason else ""
        return f"generic table (unknown core{why}: assumed {self.source})"

    def cost(self, cls: str, bits: int) -> tuple[str, OpClass, int]:
        """(resource key, class, slots) of one operation of class ``cls`` on ``bits``-bit values."""
        if bits > self.slot_bits and self.wide_ops and cls in self.wide_ops:
            return f"{cls}@{self.vector_bits}", self.wide_ops[cls], max(1, math.ceil(bits / self.vector_bits))
        return cls, self.ops[cls], max(1, math.ceil(bits / self.slot_bits))

    def op(self, key: str) -> OpClass:
        """The class of a resource key of :meth:`cost`."""
        cls, wide, _ = key.partition("@")
        return self.wide_ops[cls] if wide else self.ops[cls]

    def describe(self) -> str:
        """One paragraph: the table, its widths and its source."""
        return (f"{self.label}: {self.vector_bits}-bit vectors, {self.slot_bits}-bit slots, "
                f"{self.issue_width:g} slots/cycle ({self.split}: {_SPLITS[self.split]}); source: {self.source}")


_AMD19 = "AMD SOG family 19h (pub. 56665/57647), LLVM X86ScheduleZnver3/4.td, uops.info ZEN3/ZEN4"
MACHINES: dict[str, Machine] = {m.name: m for m in (
    Machine("zen4", "Zen 4", _AMD19, types.MappingProxyType(ZEN4), ISSUE_WIDTH, 512, 256, "halves"),
    Machine("zen3", "Zen 3", _AMD19, types.MappingProxyType(ZEN3), 4, 256, 256, "legalized"),
    Machine("zen2", "Zen 2", "AMD SOG family 17h (pub. 56305), LLVM X86ScheduleZnver2.td (Zen 3 otherwise)",
            types.MappingProxyType(ZEN2), 4, 256, 256, "legalized", fp_scheduler=36),
    Machine("zen5", "Zen 5", "AMD SOG family 1Ah (pub. 58455), LLVM X86ScheduleZnver5.td, "
            "A. Yee, Zen5's AVX512 Teardown (2024)", types.MappingProxyType(ZEN5), 4, 512, 512, "native",
            dispatch=8, fp_scheduler=114),
    Machine("goldencove", "Golden Cove (Sapphire Rapids)", "Intel Optimization Reference Manual, "
            "LLVM X86SchedSapphireRapids.td, uops.info ADL-P/SPR", types.MappingProxyType(GOLDENCOVE), 3, 512,
            256, "fused ports", types.MappingProxyType(GOLDENCOVE_512), dispatch=6, fp_scheduler=97),
    Machine("sunnycove", "Sunny Cove (Ice Lake)", "Intel Optimization Reference Manual, "
            "LLVM X86SchedIceLake.td, uops.info ICL/RKL", types.MappingProxyType(SUNNYCOVE), 3, 512, 256,
            "fused ports", types.MappingProxyType(SUNNYCOVE_512), dispatch=5, fp_scheduler=160),
    Machine("skylakex", "Skylake-X", "Intel Optimization Reference Manual, LLVM X86SchedSkylakeServer.td, "
            "uops.info SKX", types.MappingProxyType(SKYLAKEX), 3, 512, 256, "fused ports",
            types.MappingProxyType(SKYLAKEX_512), dispatch=4, fp_scheduler=97),
    Machine("haswell", "Haswell (AVX2)", "Intel Optimization Reference Manual, LLVM X86SchedHaswell.td, "
            "uops.info HSW/BDW", types.MappingProxyType(HASWELL), 3, 256, 256, "legalized",
            dispatch=4, fp_scheduler=60),
    Machine("neoversev1", "Neoverse V1", "Arm Neoverse V1 Software Optimization Guide via LLVM "
            "AArch64SchedNeoverseV1.td (FP scheduler size assumed 64)", types.MappingProxyType(NEOVERSEV1),
            4, 128, 128, "legalized", dispatch=8),
    Machine("generic", "generic", "four 256-bit vector pipes (two FMA/multiply, two add), Zen 3 latencies "
            "(FMA 4, FADD 3 cycles), wider vectors as 256-bit slots, dispatch 6, FP scheduler 64",
            types.MappingProxyType(GENERIC), 4, 256, 256, "legalized", known=False),
)}

#: LLVM CPU names of parts whose table has AVX-512 but which do not (client Skylake, Alder Lake
#: and its successors: AVX-512 fused off): their 512-bit vectors are two 256-bit instructions.
_NO_AVX512 = {"skylake", "alderlake", "raptorlake", "meteorlake"}


def _without_avx512(m: Machine) -> Machine:
    """The table of a core of ``m``'s kind that runs without AVX-512 (256-bit registers)."""
    if m.vector_bits <= 256:
        return m
    return dataclasses.replace(m, name=m.name + "-avx2", title=m.title + " without AVX-512", vector_bits=256,
                               slot_bits=min(m.slot_bits, 256), split="legalized", wide_ops={})


def machine_for(name: str) -> Machine:
    """The table for a core by table key (``zen4``, ``skylakex`` ...; see :data:`MACHINES`) or
    LLVM CPU name (``znver4``, ``sapphirerapids``, ``neoverse-v1`` ...); an unknown name gets
    the generic table, whose label says so."""
    key = name.strip().lower()
    if key in MACHINES:
        return MACHINES[key]
    row = cpus.identify({"llvm_cpu": key})
    if row.known and row.name in MACHINES:
        m = MACHINES[row.name]
        return _without_avx512(m) if key in _NO_AVX512 else m
    return dataclasses.replace(MACHINES["generic"], reason=f"{name!r}")


@functools.cache
def host_machine() -> Machine:
    """The table for the CPU this process runs on (identified by ``cpus.py`` from /proc/cpuinfo
    and LLVM's host CPU name), without AVX-512 where the host has none; the generic table,
    with the reason, for a core no table describes."""
    info = cpus.cpu_model()
    row = cpus.identify(info)
    if not (row.known and row.name in MACHINES):
        seen = ", ".join(f"{k} {info[k]!r}" for k in ("vendor", "family", "model", "llvm_cpu")
                         if info.get(k) is not None)
        return dataclasses.replace(MACHINES["generic"], reason=f"({seen or 'nothing identified'})")
    m = MACHINES[row.name]
    if m.vector_bits > 256 and not _host_avx512():
        m = _without_avx512(m)
    return m


def _host_avx512() -> bool:
    try:
        return bool(llvm.get_host_cpu_features().get("avx512f", False))
    except Exception:  # noqa: BLE001 - no feature list: take the table as it is
        return True


def as_machine(machine=None) -> Machine:
    """A :class:`Machine` from what the model's functions accept: None (the host's table), a
    Machine, a table name, or a bare class table (a dict like :data:`ZEN4`; slots of 256
    bits, ``ISSUE_WIDTH``, as the model always took one)."""
    if machine is None:
        return host_machine()
    if isinstance(machine, Machine):
        return machine
    if isinstance(machine, str):
        return machine_for(machine)
    if machine is ZEN4:
        return MACHINES["zen4"]
    return Machine("given", "given", "a class table passed by the caller", machine, ISSUE_WIDTH, 512, 256,
                   "halves")


_FREE = {"bitcast", "freeze", "phi", "getelementptr", "br", "icmp", "shl"}
_VECTOR_OPS = {"icmp": "int", "shl": "shift"}  # free on scalars (addressing, loop control), not on vectors

_INTRINSIC_CLASSES = [
    (r"llvm\.fma\.", "fma"), (r"llvm\.fmuladd", "fma"), (r"llvm\.(minnum|maxnum)", "fminmax"),
    (r"llvm\.(smin|smax|umin|umax)", "int"),  # VPMIN/VPMAX: integer ALU, any pipe
    (r"llvm\.(floor|ceil|trunc|roundeven|rint)", "round"),
    (r"x86\.avx512\.mask\.(reduce|getexp|getmant|rndscale)", "round"),
    (r"x86\.avx512\.(permvar|vpermi2var)|x86\.avx2\.perm", "shuffle"),  # Lookup: VPERMPS/VPERMI2PS
    (r"x86\.avx512\.mask\.scalef", "fma"),  # VSCALEFPS (ScaleF): FP0/FP1, latency ~4, like an FMA
    (r"rsqrt", "estimate_rsqrt"), (r"rcp", "estimate"), (r"llvm\.sqrt", "sqrt"), (r"llvm\.fabs|llvm\.copysign", "int"),
    (r"llvm\.fpto[su]i\.sat", "convert"), (r"llvm\.masked\.load", "load"), (r"llvm\.masked\.store", "store"),
    (r"llvm\.x86\.sse\.(st|ld)mxcsr", None), (r"llvm\.vector\.reduce", "shuffle"),
]
_OPCODE_CLASSES = {
    "fadd": "fadd", "fsub": "fadd", "fneg": "int", "fmul": "fmul", "fdiv": "divide",
    "fcmp": "fcmp", "select": "blend", "fptosi": "convert", "fptoui": "convert", "sitofp": "convert",
    "uitofp": "convert", "add": "int", "sub": "int", "and": "int", "or": "int", "xor": "int",
    "lshr": "shift", "ashr": "shift", "mul": "int", "insertelement": "shuffle",
    "extractelement": "shuffle", "shufflevector": "shuffle", "load": "load", "store": "store",
    "zext": "int", "sext": "int", "trunc": "int",
}


def _vector_bits(type_text: str) -> int:
    m = re.match(r"<(\d+) x (float|i32|i1|i8|double|i64)>", type_text)
    if not m:
        return 32
    bits = {"float": 32, "i32": 32, "i1": 1, "i8": 8, "double": 64, "i64": 64}[m.group(2)]
    return int(m.group(1)) * bits


def classify(instr) -> str | None:
    """The operation class of an instruction (None: free or loop bookkeeping)."""
    op = instr.opcode
    if op == "call":
        callee = list(instr.operands)[-1].name
        for pattern, cls in _INTRINSIC_CLASSES:
            if re.search(pattern, callee):
                return cls
        return "call"
    if op in _VECTOR_OPS and str(instr.type).startswith("<"):
        return _VECTOR_OPS[op]
    if op in _FREE:
        return None
    if op in ("add", "and", "or", "xor") and str(instr.type) == "i64":
        return None  # induction variable
    return _OPCODE_CLASSES.get(op, "int")


def _bits(instr) -> int:
    """The width in bits of the values an instruction operates on (a store's and a compare's
    operands, everything else its result)."""
    type_text = str(instr.type)
    if instr.opcode in ("store", "fcmp"):
        type_text = str(list(instr.operands)[0].type)
    return _vector_bits(type_text)


def _slots(instr, machine=None, cls: str | None = None) -> int:
    """Slots an instruction occupies on ``machine`` (default the Zen 4 table: 256-bit slots, 2
    for a 512-bit zmm operation)."""
    m = MACHINES["zen4"] if machine is None else as_machine(machine)
    cls = cls or classify(instr) or "int"
    return m.cost(cls, _bits(instr))[2]


@dataclasses.dataclass
class Prediction:
    """What the model says about one vector iteration of a kernel's loop."""

    width: int
    counts: dict[str, int]
    slots: dict[str, int]
    critical_path: float
    throughput_bound: float  # cycles per vector
    bottleneck: str
    skipped: list = dataclasses.field(default_factory=list)  # conditional blocks left out
    machine: str = "zen4"  # the table used (a key of MACHINES)
    machine_label: str = "Zen 4 table"  # its name as stated: "Zen 3 table", "generic table (unknown core ...)"

    @property
    def cycles_per_element(self) -> float:
        return self.throughput_bound / self.width

    def explain(self) -> str:
        ops = ", ".join(f"{n} {c}" for c, n in sorted(self.counts.items(), key=lambda kv: -kv[1]))
        return (f"{sum(self.counts.values())} ops/vector ({ops}); throughput bound "
                f"{self.throughput_bound:.2f} cycles/vector, limited by {self.bottleneck}; "
                f"critical path {self.critical_path:.0f} cycles"
                + (f"; not modelled (conditional): {', '.join(self.skipped)}" if self.skipped else "")
                + f"; model: {self.machine_label}")


def _key(value) -> int:
    return ctypes.cast(value._ptr, ctypes.c_void_p).value or 0


def _minmax_selects(instructions) -> dict[int, int]:
    """select(fcmp(a, b), a, b) or select(fcmp(a, b), b, a) is one x86 MIN/MAX:
    maps each such select to its compare (``instructions``: a block or a list)."""
    instructions = list(getattr(instructions, "instructions", instructions))
    defs = {_key(i): i for i in instructions}
    out = {}
    for instr in instructions:
        if instr.opcode != "select":
            continue
        cond, a, b = list(instr.operands)
        cmp = defs.get(_key(cond))
        if cmp is not None and cmp.opcode == "fcmp" and {_key(o) for o in cmp.operands} == {_key(a), _key(b)}:
            out[_key(instr)] = _key(cmp)
    return out


def _successors(block) -> list[str]:
    term = list(block.instructions)[-1]
    return [o.name for o in term.operands if str(o.type) == "label"]


def iteration(fn, start: str = "vec.body") -> tuple[list, list[str]]:
    """(instructions, skipped blocks) of one iteration of the loop at block ``start``.

    A kernel whose body has no ``If`` is one block, ``start``, branching back to
    itself. With ``If`` blocks the iteration runs from ``start`` through
    conditional blocks to a latch that branches back to ``start``; the model
    takes the blocks that *every* iteration runs (those whose removal would cut
    every path back to ``start``), in the function's order, and leaves out the
    conditional ones -- e.g. the trigonometric routines' ``If(Any(|x| >
    limit))`` large-argument reduction, which typical arguments never enter
    (a phi's operand from a skipped block counts as ready)."""
    blocks = {b.name: b for b in fn.blocks}
    if start not in blocks:
        raise ValueError(f"{fn.name} has no vector loop (block {start})")
    # the elements the vector loop cannot read in place go round through reactor_move (blocks
    # ``tail.*``) and back into the body: not part of a vector iteration
    succ = loop_successors(blocks)

    def back_to_start(avoid: str | None) -> bool:
        seen, todo = set(), [n for n in succ[start] if n != avoid]
        while todo:
            n = todo.pop()
            if n == start:
                return True
            if n in seen:
                continue
            seen.add(n)
            todo += [m for m in succ[n] if m != avoid]
        return False

    inside, todo = set(), list(succ[start])  # blocks reachable from start before returning to it
    while todo:
        n = todo.pop()
        if n == start or n in inside:
            continue
        inside.add(n)
        todo += succ[n]
    if not back_to_start(None):
        raise ValueError(f"{fn.name}: block {start} is not a loop")
    on_path = {n for n in inside if _reaches(succ, n, start)}
    every = {start} | {n for n in on_path if not back_to_start(n)}
    instructions = [i for b in fn.blocks if b.name in every for i in b.instructions]
    skipped = [b.name for b in fn.blocks if b.name in on_path - every]
    return instructions, skipped


def loop_successors(blocks: dict) -> dict[str, list[str]]:
    """Each block's successors as a call of arrays runs the vector loop: not the ``tail.*`` blocks
    (elements gathered through reactor_move, not part of a vector iteration), and from a branch to
    ``uniform.else`` (the body's uniform work computed per iteration: ``reactor.ir.hoist``) only
    that arm, not the one a call takes when the work was done once, so it counts per element."""
    succ = {}
    for name, b in blocks.items():
        names = [n for n in _successors(b) if not n.startswith("tail.")]
        if any(n.startswith("uniform.else") for n in names):
            names = [n for n in names if n.startswith("uniform.else")]
        succ[name] = names
    return succ


def _reaches(succ, a: str, b: str) -> bool:
    seen, todo = set(), [a]
    while todo:
        n = todo.pop()
        if n == b:
            return True
        if n in seen:
            continue
        seen.add(n)
        todo += succ[n]
    return False


def _pipe_bounds(slots, machine) -> dict[str, float]:
    """Cycles per vector forced by each set of pipes (see the module docstring), named by the
    classes confined to it; classes without pipes on their own. ``slots``: per class (or
    resource key of :meth:`Machine.cost`, ``"fma@512"``), the slots of one iteration."""
    m = as_machine(machine)
    op = {key: m.op(key) for key in slots}
    bounds = {key.partition("@")[0]: 0.0 for key in slots if not op[key].pipes}
    for key, n in slots.items():
        if not op[key].pipes:
            bounds[key.partition("@")[0]] += n / op[key].per_cycle
    pipes = sorted({p for key in slots for p in op[key].pipes})
    for mask in range(1, 1 << len(pipes)):
        subset = {p for k, p in enumerate(pipes) if mask >> k & 1}
        inside = [key for key in slots if op[key].pipes and set(op[key].pipes) <= subset]
        if not inside:
            continue
        demand = sum(slots[key] * op[key].busy for key in inside)
        name = "/".join(sorted(subset)) + " (" + ", ".join(sorted({k.partition("@")[0] for k in inside})) + ")"
        bounds[name] = max(bounds.get(name, 0.0), demand / len(subset))
    return bounds


def predict(optimized_ir: str, function: str, width: int, machine=None, issue_width=None) -> Prediction:
    """Model one iteration of the vector loop (:func:`iteration`: from block ``vec.body``,
    the blocks every iteration runs) of ``function`` in ``optimized_ir`` on ``machine`` (a
    :class:`Machine`, a table name, or None: the host's, :func:`host_machine`)."""
    m = as_machine(machine)
    if issue_width is not None:
        m = dataclasses.replace(m, issue_width=issue_width)
    mod = llvm.parse_assembly(optimized_ir)
    fn = mod.get_function(function)
    body, skipped = iteration(fn)
    counts: collections.Counter[str] = collections.Counter()
    slots: collections.Counter[str] = collections.Counter()
    demand: collections.Counter[str] = collections.Counter()  # per resource key (a 512-bit op on Intel: "fma@512")
    finish: dict[int, float] = {}
    critical = 0.0
    minmax = _minmax_selects(body)
    folded = set(minmax.values())
    for instr in body:
        cls = classify(instr)
        if _key(instr) in folded:
            cls = None  # the compare of a min/max: part of one VMINPS/VMAXPS
        elif _key(instr) in minmax:
            cls = "fminmax"
        start = max((finish.get(_key(op), 0.0) for op in instr.operands), default=0.0)
        latency = 0.0
        if cls:
            key, op, n = m.cost(cls, _bits(instr))
            latency = op.latency
            counts[cls] += 1
            slots[cls] += n
            demand[key] += n
        finish[_key(instr)] = start + latency
        critical = max(critical, start + latency)
    fp_slots = sum(n for cls, n in slots.items() if cls not in ("load", "store"))
    bounds = {"issue width": fp_slots / m.issue_width}  # first: named so on a tie
    bounds.update(_pipe_bounds(dict(demand), m))
    bottleneck = max(bounds, key=lambda k: bounds[k])
    return Prediction(width, dict(counts), dict(slots), critical, bounds[bottleneck], bottleneck, skipped,
                      m.name, m.label)


def predict_kernel(ufunc, machine=None) -> Prediction:
    """``predict`` for a reactor kernel (its ``<name>.loop`` function), on ``machine`` (default
    the host's table)."""
    from ..kernels.kernel import kernel_of
    kern = kernel_of(ufunc)
    return predict(kern.optimized_ir, f"{kern.name}.loop", kern.build.width, machine)


def kernel_cycles(kern, machine=None) -> float:
    """Cycles per element of a ``reactor.Kernel``'s vector loop on ``machine`` (default the
    host's table): the cost ``reactor.plan`` ranks builds by."""
    return predict(kern.optimized_ir, f"{kern.name}.loop", kern.build.width, machine).cycles_per_element
