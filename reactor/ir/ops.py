"""The operation table: how each DSL operation becomes LLVM IR, per element category.

Each operation is defined once here, for every kind and width: an entry maps
an element category ("float", "int", "uint", "bool") to a *recipe*, either the
name of an ``IRBuilder`` method or a function ``recipe(em, vtype, *irargs)``.
The DSL value classes (``reactor.dsl.values``) and intrinsics
(``reactor.dsl.intrinsics``) look operations up here; nothing else emits
arithmetic.

Semantics that LLVM leaves undefined are defined here, so no DSL program has
undefined behaviour:

* integer ``/`` and ``%`` truncate toward zero (C); ``x / 0 == 0`` and
  ``x % 0 == 0``; ``INT_MIN / -1 == INT_MIN``.
* shift counts are taken modulo 32 (``x << 33 == x << 1``); ``>>`` is
  arithmetic on Int and logical on UInt.
* float comparisons are ordered (false if either side is NaN), except ``!=``
  which is true if either side is NaN (IEEE 754 / C semantics).
"""
from __future__ import annotations

from llvmlite import ir

from ..dsl.types import VType


def const(vtype: VType, value) -> ir.Constant:
    """A constant of ``vtype`` with every lane equal to ``value``."""
    scalar = ir.Constant(vtype.kind.ir_type, value)
    if vtype.width == 1:
        return scalar
    return ir.Constant(vtype.ir, [scalar] * vtype.width)


def splat(em, width: int, scalar_ir, name: str = "splat"):
    """Broadcast a scalar IR value to ``width`` lanes (width 1: unchanged)."""
    if width == 1:
        return scalar_ir
    undef = ir.Constant(ir.VectorType(scalar_ir.type, width), ir.Undefined)
    one = em.emit("insert_element", undef, scalar_ir, ir.Constant(ir.IntType(32), 0), name=name)
    zeros = ir.Constant(ir.VectorType(ir.IntType(32), width), [0] * width)
    return em.emit("shuffle_vector", one, undef, zeros, name=name)


def mangle(t: ir.Type) -> str:
    """LLVM's overload suffix for an IR type: f32, i8, v16f32, v8i1."""
    if isinstance(t, ir.VectorType):
        return f"v{t.count}{mangle(t.element)}"
    if isinstance(t, ir.FloatType):
        return "f32"
    if isinstance(t, ir.DoubleType):
        return "f64"
    return f"i{t.width}"


def intrinsic(em, name: str, vtype: VType, args, ret: VType | None = None, extra=(), opname=""):
    """Call the overloaded intrinsic ``name.<mangled vtype>``."""
    ret_ir = (ret or vtype).ir
    fn = em.intrinsic(f"{name}.{vtype.mangle()}", ret_ir, [a.type for a in args] + [e.type for e in extra])
    return em.call(fn, list(args) + list(extra), name=opname or name.split(".")[-1])


# -- guarded integer division ---------------------------------------------

def _div(signed: bool, rem: bool):
    op = ("srem" if rem else "sdiv") if signed else ("urem" if rem else "udiv")

    def recipe(em, vt, a, b):
        zero, one = const(vt, 0), const(vt, 1)
        by_zero = em.emit("icmp_unsigned", "==", b, zero, name="by_zero")
        bad = by_zero
        if signed:  # INT_MIN / -1 overflows (and traps on x86)
            ovf = em.emit("and_", em.emit("icmp_signed", "==", a, const(vt, -(2**31)), name="is_min"),
                          em.emit("icmp_signed", "==", b, const(vt, -1), name="is_m1"), name="overflow")
            bad = em.emit("or_", by_zero, ovf, name="div_guard")
        safe_b = em.emit("select", bad, one, b, name="divisor")
        q = em.emit(op, a, safe_b, name=op)
        return em.emit("select", by_zero, zero, q, name=op)

    return recipe


def _shift(method: str):
    def recipe(em, vt, a, b):
        count = em.emit("and_", b, const(vt, 31), name="count")
        return em.emit(method, a, count, name=method.rstrip("_"))

    return recipe


def _not(em, vt, a):
    return em.emit("xor", a, const(vt, -1 if vt.kind.category != "bool" else 1), name="not")


# name -> {category: recipe}; "int" covers signed, "uint" unsigned.
BINARY = {
    "add": {"float": "fadd", "int": "add", "uint": "add"},
    "sub": {"float": "fsub", "int": "sub", "uint": "sub"},
    "mul": {"float": "fmul", "int": "mul", "uint": "mul"},
    "div": {"float": "fdiv", "int": _div(True, False), "uint": _div(False, False)},
    "rem": {"int": _div(True, True), "uint": _div(False, True)},
    "and": {"int": "and_", "uint": "and_", "bool": "and_"},
    "or": {"int": "or_", "uint": "or_", "bool": "or_"},
    "xor": {"int": "xor", "uint": "xor", "bool": "xor"},
    "shl": {"int": _shift("shl"), "uint": _shift("shl")},
    "shr": {"int": _shift("ashr"), "uint": _shift("lshr")},
    "ashr": {"int": _shift("ashr"), "uint": _shift("ashr")},
    "lshr": {"int": _shift("lshr"), "uint": _shift("lshr")},
    "min": {
        # x86 MINPS semantics: a < b ? a : b (returns b when either is NaN).
        "float": lambda em, vt, a, b: em.emit("select", em.emit("fcmp_ordered", "<", a, b, name="lt"), a, b, name="min"),
        "int": lambda em, vt, a, b: intrinsic(em, "llvm.smin", vt, [a, b]),
        "uint": lambda em, vt, a, b: intrinsic(em, "llvm.umin", vt, [a, b]),
    },
    "max": {
        "float": lambda em, vt, a, b: em.emit("select", em.emit("fcmp_ordered", ">", a, b, name="gt"), a, b, name="max"),
        "int": lambda em, vt, a, b: intrinsic(em, "llvm.smax", vt, [a, b]),
        "uint": lambda em, vt, a, b: intrinsic(em, "llvm.umax", vt, [a, b]),
    },
    "minnum": {"float": lambda em, vt, a, b: intrinsic(em, "llvm.minnum", vt, [a, b])},
    "maxnum": {"float": lambda em, vt, a, b: intrinsic(em, "llvm.maxnum", vt, [a, b])},
    "copysign": {"float": lambda em, vt, a, b: intrinsic(em, "llvm.copysign", vt, [a, b])},
}

UNARY = {
    "neg": {"float": "fneg", "int": "neg", "uint": "neg"},
    "invert": {"int": _not, "uint": _not, "bool": _not},
    "abs": {
        "float": lambda em, vt, a: intrinsic(em, "llvm.fabs", vt, [a]),
        "int": lambda em, vt, a: intrinsic(em, "llvm.abs", vt, [a], extra=[ir.Constant(ir.IntType(1), 0)]),
    },
    "floor": {"float": lambda em, vt, a: intrinsic(em, "llvm.floor", vt, [a])},
    "ceil": {"float": lambda em, vt, a: intrinsic(em, "llvm.ceil", vt, [a])},
    "trunc": {"float": lambda em, vt, a: intrinsic(em, "llvm.trunc", vt, [a])},
    "round": {"float": lambda em, vt, a: intrinsic(em, "llvm.roundeven", vt, [a])},
    "sqrt": {"float": lambda em, vt, a: intrinsic(em, "llvm.sqrt", vt, [a])},
}

# name -> (symbol, float predicate kind); all give Bool of the operand width.
COMPARE = {
    "lt": "<", "le": "<=", "gt": ">", "ge": ">=", "eq": "==", "ne": "!=",
}


def compare(em, vt: VType, name: str, a, b):
    sym = COMPARE[name]
    cat = vt.kind.category
    if cat == "float":
        method = "fcmp_unordered" if name == "ne" else "fcmp_ordered"
    elif cat == "int":
        method = "icmp_signed"
    else:  # uint, bool
        method = "icmp_unsigned"
    return em.emit(method, sym, a, b, name=name)


# float classification: name -> (comparison of |x| with +inf, ordered?)
CLASSIFY = {
    "isnan": lambda em, vt, a: em.emit("fcmp_unordered", "uno", a, a, name="isnan"),
    "isinf": lambda em, vt, a: em.emit("fcmp_ordered", "==", intrinsic(em, "llvm.fabs", vt, [a]),
                                       const(vt, float("inf")), name="isinf"),
    "isfinite": lambda em, vt, a: em.emit("fcmp_ordered", "<", intrinsic(em, "llvm.fabs", vt, [a]),
                                          const(vt, float("inf")), name="isfinite"),
}


def fused_multiply_add(em, vt: VType, a, b, c, fused: bool):
    """a*b + c: one ``llvm.fma`` when ``fused``, else a rounded multiply then add."""
    if fused:
        return intrinsic(em, "llvm.fma", vt, [a, b, c])
    return em.emit("fadd", em.emit("fmul", a, b, name="mul"), c, name="muladd")


def convert(em, src: VType, dst: VType, value, *, rounding: str = "trunc", saturate: bool = True):
    """Numeric conversion between kinds of the same width (see ``Value.__new__``).

    float -> int rounds by ``rounding`` ("trunc" toward zero, "nearest" to even);
    with ``saturate`` out-of-range values clamp and NaN gives 0; without, the
    result for such inputs is an unspecified (but fixed, never poison) value.
    """
    s, d = src.kind, dst.kind
    name = f"to{d.name.lower()}"
    if s == d:
        return value
    if d.category == "bool":
        zero = const(src, 0.0 if s.is_float else 0)
        pred = "fcmp_unordered" if s.is_float else "icmp_unsigned"
        return em.emit(pred, "!=", value, zero, name=name)
    if s.category == "bool":
        if d.is_float:
            return em.emit("uitofp", value, dst.ir, name=name)
        return em.emit("zext", value, dst.ir, name=name)
    if s.is_float and d.is_float:
        op = "fpext" if d.bits > s.bits else "fptrunc"
        return em.emit(op, value, dst.ir, name=name)
    if s.is_integer and d.is_integer:
        return value  # Int <-> UInt: same 32 bits, reinterpreted (like numpy astype)
    if s.is_integer:  # int -> float
        op = "sitofp" if s.signed else "uitofp"
        return em.emit(op, value, dst.ir, name=name)
    # float -> int
    if rounding == "nearest":
        value = intrinsic(em, "llvm.roundeven", src, [value])
    elif rounding != "trunc":
        raise ValueError(f"rounding must be 'trunc' or 'nearest', not {rounding!r}")
    if saturate:
        base = "llvm.fptosi.sat" if d.signed else "llvm.fptoui.sat"
        fn = em.intrinsic(f"{base}.{dst.mangle()}.{src.mangle()}", dst.ir, [src.ir])
        return em.call(fn, [value], name=name)
    op = "fptosi" if d.signed else "fptoui"
    return em.freeze(em.emit(op, value, dst.ir, name=name), name=name)


# -- x86 instructions at any width ------------------------------------------

def by_native_width(em, vt: VType, value, natives):
    """Apply a width-specific instruction to a value of any width.

    ``natives`` lists ``(width, emit)`` pairs the target has, widest first,
    where ``emit(value_ir) -> ir`` handles exactly that many float lanes.
    Wider values are split into native pieces and joined; a scalar is
    broadcast into the narrowest native vector and lane 0 is taken.
    """
    idx = ir.IntType(32)
    if vt.width == 1:
        width, emit = natives[-1]
        return em.emit("extract_element", emit(splat(em, width, value)), ir.Constant(idx, 0), name="lane0")
    for width, emit in natives:
        if width == vt.width:
            return emit(value)
    width, emit = next((w, e) for w, e in natives if w < vt.width)
    parts = []
    for start in range(0, vt.width, width):
        mask = ir.Constant(ir.VectorType(idx, width), [ir.Constant(idx, start + i) for i in range(width)])
        parts.append(emit(em.emit("shuffle_vector", value, value, mask, name="part")))
    while len(parts) > 1:
        merged = []
        for a, b in zip(parts[::2], parts[1::2]):
            n = a.type.count * 2
            mask = ir.Constant(ir.VectorType(idx, n), [ir.Constant(idx, i) for i in range(n)])
            merged.append(em.emit("shuffle_vector", a, b, mask, name="join"))
        parts = merged
    return parts[0]


def _avx512_masked(em, base: str, width: int, value, imm=None, name=""):
    """Call ``llvm.x86.avx512.mask.<base>.ps.<bits>`` with all lanes enabled."""
    vty = ir.VectorType(ir.FloatType(), width)
    mask_ty = ir.IntType(max(width, 8))
    zero = ir.Constant(vty, [ir.Constant(ir.FloatType(), 0.0)] * width)
    args = [value] + ([ir.Constant(ir.IntType(32), imm)] if imm is not None else []) + [zero, ir.Constant(mask_ty, -1)]
    if width == 16 and base != "rcp14" and base != "rsqrt14":
        args.append(ir.Constant(ir.IntType(32), 4))  # current rounding direction
    fn = em.intrinsic(f"llvm.x86.avx512.{'' if base.endswith('14') else 'mask.'}{base}.ps.{32 * width}",
                      vty, [a.type for a in args])
    return em.call(fn, args, name=name or base)


def avx512_natives(features: frozenset[str], base: str, imm=None, need: str = "avx512f"):
    """(width, emit) pairs for an AVX-512 float instruction, or () without AVX-512."""
    if need not in features:
        return ()
    widths = (16, 8, 4) if "avx512vl" in features else (16,)
    return tuple((w, lambda v, w=w: _avx512_masked(_em_of(v), base, w, v, imm)) for w in widths)


def _em_of(value):
    from . import emitter
    return emitter.current()


# -- hardware estimates (x86) -------------------------------------------------

def _estimate_natives(features: frozenset[str], op: str):
    out = list(avx512_natives(features, f"{op}14"))
    legacy = {8: f"llvm.x86.avx.{op}.ps.256", 4: f"llvm.x86.sse.{op}.ps"}
    have = {w for w, _ in out}
    for width, name in legacy.items():
        if width in have or (width == 8 and "avx" not in features) or "sse" not in features:
            continue
        def emit(v, name=name, width=width):
            em = _em_of(v)
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
        one = const(vt, 1.0)
        if op == "rsqrt":
            value = intrinsic(em, "llvm.sqrt", vt, [value])
        return em.emit("fdiv", one, value, name=f"{op}.exact")
    return by_native_width(em, vt, value, natives)
