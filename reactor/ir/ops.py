"""The operation table: how each DSL operation becomes LLVM IR, per element category.

Each operation is defined once here, for every kind and width: an entry maps
an element category ("float", "int", "uint", "bool") to a *recipe*, either the
name of a ``FunctionEmitter`` instruction or a function ``recipe(em, vtype,
*irargs)``. The DSL value classes, the intrinsics, the control flow, the
kernel loops and the runtime's entry points all look operations up here;
nothing else emits arithmetic.

Semantics that LLVM leaves undefined are defined here, so no DSL program has
undefined behaviour:

* integer ``/`` and ``%`` truncate toward zero (C); ``x / 0 == 0`` and
  ``x % 0 == 0``; ``INT_MIN / -1 == INT_MIN``.
* shift counts are taken modulo the bit width (``x << 33 == x << 1`` for Int);
  ``>>`` is arithmetic on Int and logical on UInt.
* float comparisons are ordered (false if either side is NaN), except ``!=``
  which is true if either side is NaN (IEEE 754 / C semantics).
"""
from __future__ import annotations

from . import types as T
from .types import VType, const


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
        by_zero = em.icmp("==", b, zero, signed=False, name="by_zero")
        bad = by_zero
        if signed:  # INT_MIN / -1 overflows (and traps on x86)
            int_min = -(2 ** (vt.kind.bits - 1))
            ovf = em.and_(em.icmp("==", a, const(vt, int_min), signed=True, name="is_min"),
                          em.icmp("==", b, const(vt, -1), signed=True, name="is_m1"), name="overflow")
            bad = em.or_(by_zero, ovf, name="div_guard")
        safe_b = em.select(bad, one, b, name="divisor")
        q = getattr(em, op)(a, safe_b, name=op)
        return em.select(by_zero, zero, q, name=op)

    return recipe


def _shift(method: str):
    def recipe(em, vt, a, b):
        count = em.and_(b, const(vt, vt.kind.bits - 1), name="count")
        return getattr(em, method)(a, count, name=method)

    return recipe


def _not(em, vt, a):
    return em.xor(a, const(vt, -1 if vt.kind.category != "bool" else 1), name="not")


def _fminmax(pred: str, name: str):
    # x86 MINPS/MAXPS semantics: a < b ? a : b (returns b when either is NaN).
    test = {"<": "lt", ">": "gt"}[pred]
    return lambda em, vt, a, b: em.select(em.fcmp(pred, a, b, name=test), a, b, name=name)


def _overloaded(name: str, extra=()):
    return lambda em, vt, *args: intrinsic(em, name, vt, list(args), extra=list(extra))


# name -> {category: recipe}; "int" covers signed, "uint" unsigned.
BINARY = {
    "add": {"float": "fadd", "int": "add", "uint": "add"},
    "sub": {"float": "fsub", "int": "sub", "uint": "sub"},
    "mul": {"float": "fmul", "int": "mul", "uint": "mul"},
    "div": {"float": "fdiv", "int": _div(True, False), "uint": _div(False, False)},
    "rem": {"float": lambda em, vt, a, b: em.fsub(a, em.fmul(b, intrinsic(em, "llvm.floor", vt, [em.fdiv(a, b)]),
                                                             name="mul"), name="mod"),  # GLSL mod
            "int": _div(True, True), "uint": _div(False, True)},
    "and": {"int": "and_", "uint": "and_", "bool": "and_"},
    "or": {"int": "or_", "uint": "or_", "bool": "or_"},
    "xor": {"int": "xor", "uint": "xor", "bool": "xor"},
    "shl": {"int": _shift("shl"), "uint": _shift("shl")},
    "shr": {"int": _shift("ashr"), "uint": _shift("lshr")},
    "ashr": {"int": _shift("ashr"), "uint": _shift("ashr")},
    "lshr": {"int": _shift("lshr"), "uint": _shift("lshr")},
    "min": {"float": _fminmax("<", "min"), "int": _overloaded("llvm.smin"), "uint": _overloaded("llvm.umin")},
    "max": {"float": _fminmax(">", "max"), "int": _overloaded("llvm.smax"), "uint": _overloaded("llvm.umax")},
    "minnum": {"float": _overloaded("llvm.minnum")},
    "maxnum": {"float": _overloaded("llvm.maxnum")},
    "copysign": {"float": _overloaded("llvm.copysign")},
}

KINDS_BY_BITS = {16: T.KINDS["UShort"], 32: T.KINDS["Int"]}


def _sqrt(em, vt: VType, a):
    """The correctly rounded square root; a negative input gives the x86 default NaN on every
    target (AArch64's FSQRT gives 0x7fc00000 there, so a select is added on other architectures)."""
    root = intrinsic(em, "llvm.sqrt", vt, [a])
    if em.settings.target.arch == "x86_64":
        return root
    negative = em.fcmp("<", a, const(vt, 0.0), ordered=True, name="sqrt.negative")
    return with_nan_where(em, vt, negative, root)


def with_nan_where(em, vt: VType, mask, value):
    """``value`` (a NaN in the lanes of ``mask``, from an invalid operation on a non-x86 target)
    with its sign set there, which makes that target's default NaN (+, quiet, no payload) x86's.
    Done with integer operations: LLVM treats every NaN as the same value and folds a select
    between a NaN constant and a NaN-producing operation away."""
    it = VType(T.INDEX_KIND if vt.kind.bits == 64 else KINDS_BY_BITS[vt.kind.bits], vt.width)
    sign = em.select(mask, const(it, -(1 << (vt.kind.bits - 1))), const(it, 0), name="nan.sign")
    bits = em.or_(em.bitcast(value, it.ir, name="bits"), sign, name="nan.rule")
    return em.bitcast(bits, vt.ir, name="nan.ruled")


UNARY = {
    "neg": {"float": "fneg", "int": "neg", "uint": "neg"},
    "invert": {"int": _not, "uint": _not, "bool": _not},
    "abs": {
        "float": _overloaded("llvm.fabs"),
        "int": lambda em, vt, a: intrinsic(em, "llvm.abs", vt, [a], extra=[const(VType(T.KINDS["Bool"], 1), 0)]),
    },
    "floor": {"float": _overloaded("llvm.floor")},
    "ceil": {"float": _overloaded("llvm.ceil")},
    "trunc": {"float": _overloaded("llvm.trunc")},
    "round": {"float": _overloaded("llvm.roundeven")},
    "sqrt": {"float": lambda em, vt, a: _sqrt(em, vt, a)},
}

# name -> predicate symbol; all give Bool of the operand width.
COMPARE = {
    "lt": "<", "le": "<=", "gt": ">", "ge": ">=", "eq": "==", "ne": "!=",
}


def apply(recipe, em, vt, *irs, name=""):
    """Run a recipe of the tables above on IR operands of type ``vt``."""
    if isinstance(recipe, str):
        return getattr(em, recipe)(*irs, name=name or recipe.rstrip("_"))
    return recipe(em, vt, *irs)


def lookup(table: dict, name: str, vt: VType):
    """The recipe of ``name`` for ``vt``'s category, or None if it is not defined there."""
    return table[name].get(vt.kind.category)


def binary(em, name: str, vt: VType, a, b):
    """Operation ``name`` of ``BINARY`` on two operands of type ``vt``."""
    return apply(lookup(BINARY, name, vt), em, vt, a, b, name=name)


def unary(em, name: str, vt: VType, a):
    return apply(lookup(UNARY, name, vt), em, vt, a, name=name)


def compare(em, vt: VType, name: str, a, b):
    """Comparison ``name`` of ``COMPARE`` of two operands of type ``vt``: a Bool of its width."""
    sym = COMPARE[name]
    cat = vt.kind.category
    if cat == "float":
        return em.fcmp(sym, a, b, ordered=name != "ne", name=name)
    return em.icmp(sym, a, b, signed=cat == "int", name=name)


def select(em, mask, a, b):
    return em.select(mask, a, b, name="select")


# float classification
CLASSIFY = {
    "isnan": lambda em, vt, a: em.fcmp("uno", a, a, ordered=False, name="isnan"),
    "isinf": lambda em, vt, a: em.fcmp("==", intrinsic(em, "llvm.fabs", vt, [a]), const(vt, float("inf")),
                                       name="isinf"),
    "isfinite": lambda em, vt, a: em.fcmp("<", intrinsic(em, "llvm.fabs", vt, [a]), const(vt, float("inf")),
                                          name="isfinite"),
}


def fused_multiply_add(em, vt: VType, a, b, c, fused: bool):
    """a*b + c: one ``llvm.fma`` when ``fused`` (emulated exactly where the target has no FMA
    instruction, never a call to libm's fmaf), else a rounded multiply then add."""
    if not fused:
        return em.fadd(em.fmul(a, b, name="mul"), c, name="muladd")
    if "fma" in em.settings.target.feature_set:
        return intrinsic(em, "llvm.fma", vt, [a, b, c])
    return emulated_fma(em, vt, a, b, c)


def emulated_fma(em, vt: VType, a, b, c):
    """float32 ``a*b + c`` rounded once, without an FMA instruction: the product is exact in
    double, the sum is rounded to odd in double (the rounded sum, moved one ulp toward the
    exact one when it is inexact and even: TwoSum gives the error), and the one rounding to
    float then gives the fused result (53 >= 2 x 24 + 2 bits). Infinities as FMA; a NaN operand
    gives the first NaN of a, b, c, quieted."""
    if vt.kind.name != "Float":
        from ..errors import ReactorError
        raise ReactorError(f"a fused multiply-add of {vt.kind.name} values needs an FMA instruction, and target "
                           f"'{em.settings.target.name}' has none: build with fma=False (or None)")
    dt, lt = vt.with_kind("Double"), vt.with_kind(T.INDEX_KIND)
    x, y, z = (convert(em, vt, dt, v) for v in (a, b, c))
    product = em.fmul(x, y, name="fma.product")  # exact
    total = em.fadd(product, z, name="fma.sum")  # rounded to nearest
    back = em.fsub(total, product, name="fma.back")
    error = em.fadd(em.fsub(product, em.fsub(total, back, name="fma.a"), name="fma.ea"),
                    em.fsub(z, back, name="fma.eb"), name="fma.error")  # total + error = product + z
    bits = em.bitcast(total, lt, name="fma.bits")
    zero = const(dt, 0.0)
    inexact = em.fcmp("!=", error, zero, ordered=True, name="fma.inexact")  # NaN/inf: not adjusted
    even = em.icmp("==", em.and_(bits, const(lt, 1), name="fma.low"), const(lt, 0), signed=False, name="fma.even")
    up = em.icmp("==", em.fcmp(">", error, zero, ordered=True, name="fma.eup"),
                 em.fcmp(">", total, zero, ordered=True, name="fma.pos"), signed=False, name="fma.away")
    step = em.select(up, const(lt, 1), const(lt, -1), name="fma.step")
    odd = em.select(em.and_(inexact, even, name="fma.adjust"), em.add(bits, step, name="fma.next"), bits,
                    name="fma.odd")
    result = convert(em, dt, vt, em.bitcast(odd, dt, name="fma.rounded"))
    it = vt.with_kind("Int")  # a NaN operand: the first of a, b, c, quieted (as VFMADD's usual forms give)
    for v in (c, b, a):
        quiet = em.bitcast(em.or_(em.bitcast(v, it, name="fma.nanbits"), const(it, 0x00400000), name="fma.quiet"),
                           vt, name="fma.qnan")
        result = em.select(em.fcmp("uno", v, v, ordered=False, name="fma.isnan"), quiet, result, name="fma.nan")
    return result


def reduce(em, name: str, vt: VType, mask):
    """``any``/``all`` lanes of a Bool vector, as a scalar Bool."""
    llvm_name = {"any": "llvm.vector.reduce.or", "all": "llvm.vector.reduce.and"}[name]
    return intrinsic(em, llvm_name, vt, [mask], ret=vt.with_width(1))


def convert(em, src: VType, dst: VType, value, *, rounding: str = "trunc", saturate: bool = True):
    """Numeric conversion between kinds of the same width (see ``Value.__new__``).

    float -> int rounds by ``rounding`` ("trunc" toward zero, "nearest" to even);
    with ``saturate`` out-of-range values clamp and NaN gives 0; without, the
    result for such inputs is an unspecified (but fixed, never poison) value: for a signed
    32- or 64-bit result, x86's "integer indefinite" (the lowest integer) on every target.
    Integers of different sizes are sign- or zero-extended (by the source's
    signedness) or truncated.
    """
    s, d = src.kind, dst.kind
    name = f"to{d.name.lower()}"
    if s == d:
        return value
    if d.category == "bool":
        zero = const(src, 0.0 if s.is_float else 0)
        if s.is_float:
            return em.fcmp("!=", value, zero, ordered=False, name=name)
        return em.icmp("!=", value, zero, signed=False, name=name)
    if s.category == "bool":
        return em.convert("uitofp" if d.is_float else "zext", value, dst, name=name)
    if s.is_float and d.is_float:
        return em.convert("fpext" if d.bits > s.bits else "fptrunc", value, dst, name=name)
    if s.is_integer and d.is_integer:
        if d.bits == s.bits:
            return value  # Int <-> UInt: same bits, reinterpreted (like numpy astype)
        if d.bits < s.bits:
            return em.convert("trunc", value, dst, name=name)
        return em.convert("sext" if s.signed else "zext", value, dst, name=name)
    if s.is_integer:  # int -> float
        return em.convert("sitofp" if s.signed else "uitofp", value, dst, name=name)
    # float -> int
    if rounding == "nearest":
        value = intrinsic(em, "llvm.roundeven", src, [value])
    elif rounding != "trunc":
        raise ValueError(f"rounding must be 'trunc' or 'nearest', not {rounding!r}")
    if saturate:
        return _saturating_to_int(em, src, dst, value, name)
    converted = em.freeze(em.convert("fptosi" if d.signed else "fptoui", value, dst, name=name), name=name)
    if d.signed and d.bits >= 32 and em.settings.target.arch != "x86_64":
        # x86's "integer indefinite" for NaN and out-of-range inputs (CVTTPS2DQ), on every target:
        # the same bits everywhere (AArch64's FCVTZS saturates and gives 0 for NaN)
        top = 2.0 ** (d.bits - 1)
        fits = em.and_(em.fcmp("<", value, const(src, top), ordered=True, name=f"{name}.below"),
                       em.fcmp(">=", value, const(src, -top), ordered=True, name=f"{name}.above"), name=f"{name}.fits")
        converted = em.select(fits, converted, const(dst, -(2 ** (d.bits - 1))), name=name)
    return converted


def _saturating_to_int(em, src: VType, dst: VType, value, name: str):
    """``llvm.fpto[su]i.sat`` spelled out in vector operations: NaN gives 0, values beyond the
    range its ends. (LLVM lowers the intrinsic on vectors to one scalar conversion and two
    compares per lane on x86.) The bounds -2^(b-1) and 2^(b-1) (unsigned: 0 and 2^b) are exact
    in every float kind, so the compares are exact."""
    d = dst.kind
    if src.kind.bits < 32:  # Half: its range ends short of the bounds (they would be infinities)
        wider = src.with_kind("Float")
        return _saturating_to_int(em, wider, dst, em.convert("fpext", value, wider, name=f"{name}.f32"), name)
    lo, hi = (-(2.0 ** (d.bits - 1)), 2.0 ** (d.bits - 1)) if d.signed else (0.0, 2.0 ** d.bits)
    top = 2 ** (d.bits - 1) - 1 if d.signed else 2 ** d.bits - 1
    above = em.fcmp(">=", value, const(src, hi), ordered=True, name=f"{name}.above")
    inside = em.fcmp(">", value, const(src, lo), ordered=True, name=f"{name}.inside")  # false for NaN
    low = const(src, lo) if d.signed else const(src, 0.0)
    safe = em.select(inside, em.select(above, low, value, name=f"{name}.safe"), low, name=f"{name}.safe")
    converted = em.convert("fptosi" if d.signed else "fptoui", safe, dst, name=name)
    nan = em.fcmp("!=", value, value, ordered=False, name=f"{name}.nan")
    converted = em.select(nan, const(dst, 0), converted, name=name)
    return em.select(above, const(dst, top), converted, name=name)


def lrint(em, src: VType, dst: VType, value):
    """float -> int rounded to nearest even in one conversion (``llvm.lrint``: VCVTPS2DQ
    under the default rounding); out-of-range inputs give an unspecified fixed value."""
    fn = em.intrinsic(f"llvm.lrint.{dst.mangle()}.{src.mangle()}", dst.ir, [src.ir])
    return em.freeze(em.call(fn, [value], name="lrint"), name="lrint")


def bitcast(em, src: VType, dst: VType, value):
    """Reinterpret the bits of ``value`` (same total size)."""
    return value if src.ir == dst.ir else em.bitcast(value, dst, name="as")


def splat(em, width: int, scalar, name: str = "splat"):
    """Broadcast a scalar IR value to ``width`` lanes (width 1: unchanged)."""
    return em.splat(scalar, width, name=name)


# -- memory forms -----------------------------------------------------------------

def from_memory(em, vt: VType, raw, name: str = "value"):
    """A value of ``vt`` from its memory form (Bool: any nonzero byte is True, as in NumPy)."""
    if vt.kind.category != "bool":
        return raw
    return em.icmp("!=", raw, const(VType(T.BYTE_KIND, vt.width), 0), signed=False, name=name)


def to_memory(em, vt: VType, value, name: str = "byte"):
    """The memory form of a value of ``vt`` (Bool: one byte, 0 or 1)."""
    if vt.kind.category != "bool":
        return value
    return em.convert("zext", value, VType(T.BYTE_KIND, vt.width), name=name)


def load(em, vt: VType, ptr, name: str = "load"):
    """Load a ``vt`` (its memory form, converted) from ``ptr`` (any pointer; unaligned)."""
    ptr = em.cast_pointer(ptr, T.memory(vt), name=f"{name}.p")
    return from_memory(em, vt, em.load(ptr, align=vt.kind.mem_bytes, name=name), name=name)


def store(em, vt: VType, value, ptr, name: str = "out"):
    """Store a ``vt`` value to ``ptr`` (any pointer; unaligned) in its memory form."""
    ptr = em.cast_pointer(ptr, T.memory(vt), name=f"{name}.p")
    em.store(to_memory(em, vt, value), ptr, align=vt.kind.mem_bytes)
