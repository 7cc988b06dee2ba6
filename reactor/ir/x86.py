"""x86 instructions the DSL's intrinsics use where the target has them.

Each function takes the CPU features of the build (``Build.target.feature_set``)
and returns what the target can do, so the intrinsics (``reactor.dsl.intrinsics``)
choose between a native instruction and their portable fallback at build
time. ``by_native_width`` applies a width-specific instruction to a value of
any width (splitting or widening it).
"""
from __future__ import annotations

from llvmlite import ir

from .types import VType, const

_I32 = ir.IntType(32)


def by_native_width(em, vt: VType, values, natives):
    """Apply a width-specific instruction to operands of any width.

    ``values`` is one IR value or a list of operands of type ``vt``;
    ``natives`` lists ``(width, emit)`` pairs the target has, widest first,
    where ``emit(em, *operands) -> ir`` handles exactly that many float lanes.
    Wider values are split into native pieces and joined; scalars are
    broadcast into the narrowest native vector and lane 0 is taken.
    """
    values = list(values) if isinstance(values, (list, tuple)) else [values]
    if vt.width == 1:
        width, emit = natives[-1]
        return em.extract(emit(em, *[em.splat(v, width) for v in values]), 0, name="lane0")
    for width, emit in natives:
        if width == vt.width:
            return emit(em, *values)
    width, emit = next((w, e) for w, e in natives if w < vt.width)
    parts = []
    for start in range(0, vt.width, width):
        lanes = list(range(start, start + width))
        parts.append(emit(em, *[em.shuffle(v, v, lanes, name="part") for v in values]))
    while len(parts) > 1:
        parts = [em.shuffle(a, b, list(range(2 * a.type.count)), name="join")
                 for a, b in zip(parts[::2], parts[1::2])]
    return parts[0]


def _avx512_masked(em, base: str, width: int, args, imm=None, name=""):
    """Call ``llvm.x86.avx512.[mask.]<base>.ps.<bits>`` with all lanes enabled."""
    vty = ir.VectorType(ir.FloatType(), width)
    mask_ty = ir.IntType(max(width, 8))
    zero = ir.Constant(vty, [ir.Constant(ir.FloatType(), 0.0)] * width)
    full = list(args) + ([ir.Constant(_I32, imm)] if imm is not None else []) + [zero, ir.Constant(mask_ty, -1)]
    estimate = base.endswith("14")
    if width == 16 and not estimate:
        full.append(ir.Constant(_I32, 4))  # the current rounding direction
    fn = em.intrinsic(f"llvm.x86.avx512.{'' if estimate else 'mask.'}{base}.ps.{32 * width}",
                      vty, [a.type for a in full])
    return em.call(fn, full, name=name or base)


def avx512_natives(features: frozenset[str], base: str, imm=None, need: str = "avx512f"):
    """(width, emit) pairs for an AVX-512 float instruction, or () without it."""
    if need not in features:
        return ()
    widths = (16, 8, 4) if "avx512vl" in features else (16,)
    return tuple((w, lambda em, *v, w=w: _avx512_masked(em, base, w, v, imm)) for w in widths)


def scalef(em, vt: VType, a, b, features: frozenset[str]):
    """VSCALEFPS ``a * 2^floor(b)`` at any width, or None without AVX-512."""
    natives = avx512_natives(features, "scalef")
    return by_native_width(em, vt, [a, b], natives) if natives else None


# -- hardware estimates ---------------------------------------------------------

def _estimate_natives(features: frozenset[str], op: str):
    out = list(avx512_natives(features, f"{op}14"))
    legacy = {8: f"llvm.x86.avx.{op}.ps.256", 4: f"llvm.x86.sse.{op}.ps"}
    have = {w for w, _ in out}
    for width, name in legacy.items():
        if width in have or (width == 8 and "avx" not in features) or "sse" not in features:
            continue

        def emit(em, v, name=name, width=width):
            vty = ir.VectorType(ir.FloatType(), width)
            return em.call(em.intrinsic(name, vty, [vty]), [v], name=f"{op}.est")
        out.append((width, emit))
    return tuple(sorted(out, key=lambda p: -p[0]))


def estimate(em, op: str, vt: VType, value, features: frozenset[str]):
    """Hardware estimate of 1/x (op "rcp") or 1/sqrt(x) (op "rsqrt") at any width:
    RCP14/RSQRT14 (relative error < 2^-14) with AVX-512, RCPPS/RSQRTPS
    (< 1.5 * 2^-12) with SSE/AVX; targets without either get the exact value."""
    natives = _estimate_natives(features, op)
    if not natives:
        if op == "rsqrt":
            fn = em.intrinsic(f"llvm.sqrt.{vt.mangle()}", vt.ir, [vt.ir])
            value = em.call(fn, [value], name="sqrt")
        return em.fdiv(const(vt, 1.0), value, name=f"{op}.exact")
    return by_native_width(em, vt, value, natives)


# -- small constant tables in registers ------------------------------------------------

def _float_vector(values):
    return ir.Constant(ir.VectorType(ir.FloatType(), len(values)), [ir.Constant(ir.FloatType(), v) for v in values])


def _lookup_512(em, table, index):
    """16 lanes: VPERMPS (up to 16 entries, index bits 0-3) or VPERMI2PS (32, bits 0-4)."""
    vty, ity = ir.VectorType(ir.FloatType(), 16), ir.VectorType(_I32, 16)
    if len(table) <= 16:
        fn = em.intrinsic("llvm.x86.avx512.permvar.sf.512", vty, [vty, ity])
        return em.call(fn, [_float_vector((table * 16)[:16]), index], name="lookup")
    fn = em.intrinsic("llvm.x86.avx512.vpermi2var.ps.512", vty, [vty, ity, vty])
    return em.call(fn, [_float_vector(table[:16]), index, _float_vector(table[16:])], name="lookup")


def _lookup_256(em, table, index):
    """8 lanes: one VPERMPS per 8 entries (index bits 0-2), joined by selects on bits 3 and 4."""
    vty, ity = ir.VectorType(ir.FloatType(), 8), ir.VectorType(_I32, 8)
    fn = em.intrinsic("llvm.x86.avx2.permps", vty, [vty, ity])
    parts = [em.call(fn, [_float_vector((table[i:i + 8] * 8)[:8]), index], name="lookup")
             for i in range(0, len(table), 8)]
    bit = 8
    while len(parts) > 1:
        on = em.icmp("!=", em.and_(index, ir.Constant(ity, [ir.Constant(_I32, bit)] * 8)),
                     ir.Constant(ity, [ir.Constant(_I32, 0)] * 8), signed=False, name="bit")
        parts = [em.select(on, hi, lo, name="lookup") for lo, hi in zip(parts[::2], parts[1::2])]
        bit *= 2
    return parts[0]


def lookup(em, vt: VType, table: list[float], index, features: frozenset[str]):
    """``table[index mod len(table)]`` per lane (``table``: 2, 4, ... 32 floats; ``index``: i32
    lanes of ``vt``'s width) from registers: VPERMPS/VPERMI2PS with AVX-512, VPERMPS and selects
    with AVX2; None on other targets (a gather from memory does it there)."""
    natives = []
    if "avx512f" in features:
        natives.append((16, lambda em, i: _lookup_512(em, table, i)))
    if "avx2" in features:
        natives.append((8, lambda em, i: _lookup_256(em, table, i)))
    return by_native_width(em, vt.with_kind("Int"), [index], natives) if natives else None
