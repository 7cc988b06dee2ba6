"""Intrinsic functions of the DSL (capitalized, like Reactor's, so a star
import never shadows Python's ``min``/``abs``/``round``).

Each works on every kind and width for which ``reactor.ir.ops`` defines it.
NaN behaviour:

* ``Min(a, b)`` is ``a < b ? a : b`` and ``Max(a, b)`` is ``a > b ? a : b``
  (x86 MINPS/MAXPS): if either operand is NaN the result is ``b``. So
  ``Min(x, 1.0)`` turns NaN into 1.0 while ``Min(1.0, x)`` propagates it.
* ``MinNum``/``MaxNum`` are IEEE 754-2008 minNum/maxNum: a NaN operand is
  ignored (the other operand is returned).
"""
from __future__ import annotations

import contextlib
import typing
from typing import Callable, Iterator

from ..build import Build, Precision, current_options, options
from ..errors import DSLTypeError, FmaDisabledError
from ..ir import emitter as _em
from ..ir import ops, x86
from ..ir import types as T
from ..ir.types import KINDS, VType
from .values import Operand, Value, binary, common_type, shown, to_ir, unary, value_class, vector_type, width_mismatch

if typing.TYPE_CHECKING:
    from .vectors import Vec

#: A value type an intrinsic keeps (``Min(Float4, Float4)`` is a ``Float4``; mixed widths give ``Value``).
_V = typing.TypeVar("_V", bound=Value)


#: Select's forms for composite DSL types: class -> select(mask, a, b) (``reactor.dsl.vectors``
#: registers the GLSL vectors' own at import)
SELECT_FORMS: dict[type, Callable] = {}


def _binary_fn(op: str, doc: str) -> Callable[[_V | float, _V | float], _V]:
    def fn(a: Operand, b: Operand) -> Value:
        return binary(op, a, b, what=fn.__name__)

    fn.__doc__ = doc
    return typing.cast(Callable[[_V | float, _V | float], _V], fn)


def _unary_fn(op: str, doc: str) -> Callable[[_V], _V]:
    def fn(x: Operand) -> Value:
        return unary(op, x, what=fn.__name__)

    fn.__doc__ = doc
    return typing.cast(Callable[[_V], _V], fn)


Min = _binary_fn("min", "Lane-wise minimum; a < b ? a : b for floats (NaN -> b).")
Max = _binary_fn("max", "Lane-wise maximum; a > b ? a : b for floats (NaN -> b).")
MinNum = _binary_fn("minnum", "IEEE minNum: the non-NaN operand if one is NaN.")
MaxNum = _binary_fn("maxnum", "IEEE maxNum: the non-NaN operand if one is NaN.")
CopySign = _binary_fn("copysign", "|a| with the sign bit of b.")
ShiftRightLogical = _binary_fn("lshr", "Logical (zero-filling) right shift, count mod 32.")
ShiftRightArithmetic = _binary_fn("ashr", "Arithmetic (sign-filling) right shift, count mod 32.")
Abs = _unary_fn("abs", "Absolute value (float: clears the sign bit; Int: INT_MIN stays INT_MIN).")
Floor = _unary_fn("floor", "Round toward -inf.")
Ceil = _unary_fn("ceil", "Round toward +inf.")
Trunc = _unary_fn("trunc", "Round toward zero.")
Round = _unary_fn("round", "Round to nearest, ties to even.")
Sqrt = _unary_fn("sqrt", "Correctly rounded square root (NaN for negative inputs).")
for _f, _n in [(Min, "Min"), (Max, "Max"), (MinNum, "MinNum"), (MaxNum, "MaxNum"),
               (CopySign, "CopySign"), (ShiftRightLogical, "ShiftRightLogical"),
               (ShiftRightArithmetic, "ShiftRightArithmetic"), (Abs, "Abs"), (Floor, "Floor"),
               (Ceil, "Ceil"), (Trunc, "Trunc"), (Round, "Round"), (Sqrt, "Sqrt")]:
    _f.__name__ = _f.__qualname__ = _n


def _classify(name: str) -> Callable[[Value], Value]:
    def fn(x: Value) -> Value:
        vt = common_type(x, what=name)
        if not vt.kind.is_float:
            raise DSLTypeError(f"{name} is defined for Float and Double, not {shown(vt)}")
        em = _em.current()
        return value_class(vt.with_kind("Bool"))._wrap(ops.CLASSIFY[name.lower()](em, vt, x.ir), em)

    fn.__name__ = fn.__qualname__ = name
    fn.__doc__ = f"Lane-wise {name[2:].lower()} test, giving a mask."
    return fn


IsNan, IsInf, IsFinite = _classify("IsNan"), _classify("IsInf"), _classify("IsFinite")


@typing.overload
def Select(mask: typing.Any, a: Vec, b: typing.Any) -> Vec: ...
@typing.overload
def Select(mask: typing.Any, a: typing.Any, b: Vec) -> Vec: ...
@typing.overload
def Select(mask: Value, a: _V, b: _V | float) -> _V: ...
@typing.overload
def Select(mask: Value, a: float, b: _V) -> _V: ...
@typing.overload
def Select(mask: Value, a: Operand, b: Operand) -> Value: ...
def Select(mask: typing.Any, a: typing.Any, b: typing.Any) -> typing.Any:
    """Lane-wise ``mask ? a : b``; a scalar Bool mask selects whole vectors; GLSL vectors
    (``vec3`` ...) per component, with a Bool mask or a ``bvec`` of their size."""
    for cls, select in SELECT_FORMS.items():
        if isinstance(a, cls) or isinstance(b, cls):
            return select(mask, a, b)
    if not isinstance(mask, Value) or mask.kind.category != "bool":
        raise DSLTypeError(f"Select needs a Bool mask as first argument, not {mask!r}")
    if not isinstance(a, Value) and not isinstance(b, Value):  # two constants: their Python kind
        kind = "Bool" if isinstance(a, bool) and isinstance(b, bool) else \
            "Float" if isinstance(a, float) or isinstance(b, float) else "Int"
        a = value_class(VType(KINDS[kind], 1))(a)
    vt = common_type(a, b, what="Select")
    if vt.width == 1 and mask.width > 1:
        vt = vt.with_width(mask.width)
    elif mask.width not in (1, vt.width):
        raise width_mismatch(f"Select: mask {shown(mask.vtype)} does not match values {shown(vt)}")
    em = _em.current()
    return value_class(vt)._wrap(ops.select(em, mask.ir, to_ir(a, vt), to_ir(b, vt)), em)


def _fused_args(a, b, c, what):
    vt = common_type(a, b, c, what=what)
    if not vt.kind.is_float:
        raise DSLTypeError(f"{what} is defined for Float and Double, not {shown(vt)}")
    return vt, to_ir(a, vt), to_ir(b, vt), to_ir(c, vt)


def MulAdd(a: _V | float, b: _V | float, c: _V | float) -> _V:
    """``a * b + c``: fused (one rounding) when the build's FMA option is on,
    otherwise a rounded multiply followed by an add. This is the FMA toggle."""
    vt, x, y, z = _fused_args(a, b, c, "MulAdd")
    em = _em.current()
    return typing.cast(_V, value_class(vt)._wrap(ops.fused_multiply_add(em, vt, x, y, z, em.settings.fma), em))


def Fma(a: _V | float, b: _V | float, c: _V | float) -> _V:
    """``a * b + c`` with a single rounding; an error in a build with fma=False
    (use ``MulAdd`` for code that should follow the toggle)."""
    vt, x, y, z = _fused_args(a, b, c, "Fma")
    em = _em.current()
    if not em.settings.fma:
        raise FmaDisabledError("Fma used where FMA is off (fma=False); use MulAdd to follow the FMA toggle")
    return typing.cast(_V, value_class(vt)._wrap(ops.fused_multiply_add(em, vt, x, y, z, True), em))


@contextlib.contextmanager
def fma_mode(enabled: bool | None) -> Iterator[None]:
    """Inside the block, ``MulAdd`` fuses iff ``enabled`` (None: keep the build's setting).
    Outside a body being built, it sets the default of the builds made in the block."""
    if enabled is None:
        yield
    elif _em.building():
        with _em.current().overriding(fma=bool(enabled)):
            yield
    else:
        with options(fma=bool(enabled)):
            yield


@contextlib.contextmanager
def precision(level: Precision | str) -> Iterator[None]:
    """``with reactor.precision("relaxed"):`` like GLSL's ``precision mediump float;``:
    the math built-ins of the block use ``level`` unless a call says otherwise.
    Inside a body it applies to the code of the block; outside, to the builds
    made in the block (a default, as ``reactor.options(precision=...)``)."""
    level = Precision.of(level)
    if _em.building():
        with _em.current().overriding(precision=level):
            yield
    else:
        with options(precision=level.value):
            yield


def build_settings() -> Build:
    """The settings (a ``reactor.Build``: target, width, fma, precision, opt) of the code
    being emitted; outside a body, those a build started here would use."""
    if _em.building():
        return _em.current().settings
    return current_options().resolved()


def As(type_: type[_V], x: Value) -> _V:
    """Reinterpret the bits of ``x`` as ``type_`` (same total size), e.g. ``As(Int4, f)``."""
    if not (isinstance(type_, type) and issubclass(type_, Value) and hasattr(type_, "vtype")):
        raise DSLTypeError(f"As needs a DSL type as first argument, not {type_!r}")
    if not isinstance(x, Value):
        raise DSLTypeError(f"As needs a DSL value as second argument, not {x!r}")
    src, dst = x.vtype, type_.vtype
    if "bool" in (src.kind.category, dst.kind.category):
        raise DSLTypeError("As cannot reinterpret masks; use Select or Int(mask)")
    if src.kind.bits * src.width != dst.kind.bits * dst.width:
        raise DSLTypeError(f"As({dst.name}, {src.name}): sizes differ "
                           f"({dst.kind.bits * dst.width} vs {src.kind.bits * src.width} bits)")
    em = _em.current()
    return type_._wrap(ops.bitcast(em, src, dst, x.ir), em)


def ToInt(x: Value, rounding: str = "trunc", *, saturate: bool = True, unsigned: bool = False) -> Value:
    """Convert floats to Int (or UInt): ``rounding`` "trunc" or "nearest" (ties to even).

    With ``saturate`` (default) out-of-range inputs clamp and NaN gives 0. With
    ``saturate=False`` the caller promises inputs are in range; others give an
    unspecified but fixed value (no undefined behaviour), saving the clamps.
    """
    if not isinstance(x, Value) or not x.kind.is_float:
        raise DSLTypeError(f"ToInt converts Float/Double values, not {x!r}")
    dst = x.vtype.with_kind("UInt" if unsigned else "Int")
    em = _em.current()
    return value_class(dst)._wrap(ops.convert(em, x.vtype, dst, x.ir, rounding=rounding, saturate=saturate), em)


def _lane_index(v: Value, i):
    if isinstance(i, Value):
        if not i.kind.is_integer or i.width != 1:
            raise DSLTypeError(f"lane index must be a scalar Int, not {shown(i.vtype)}")
        # taken modulo the width: an out-of-range index would make LLVM poison
        return ops.binary(_em.current(), "and", i.vtype, i.ir, T.const(i.vtype, v.width - 1))
    if not isinstance(i, int) or isinstance(i, bool) or not 0 <= i < v.width:
        raise DSLTypeError(f"lane index {i!r} out of range for {shown(v.vtype)}")
    return i


def Extract(v: Value, i: int | Value) -> Value:
    """Lane ``i`` of vector ``v`` as a scalar (``i`` an int, or a scalar Int taken modulo the width)."""
    if not isinstance(v, Value) or v.width == 1:
        raise DSLTypeError(f"Extract needs a vector value, not {v!r}")
    em = _em.current()
    return value_class(v.vtype.with_width(1))._wrap(em.extract(v.ir, _lane_index(v, i)), em)


def Insert(v: Value, x: Operand, i: int | Value) -> Value:
    """A copy of vector ``v`` with lane ``i`` replaced by scalar ``x``."""
    if not isinstance(v, Value) or v.width == 1:
        raise DSLTypeError(f"Insert needs a vector value, not {v!r}")
    scalar = to_ir(x, v.vtype.with_width(1))
    em = _em.current()
    return value_class(v.vtype)._wrap(em.insert(v.ir, scalar, _lane_index(v, i)), em)


def _reduce(name: str) -> Callable[[Value], Value]:
    def fn(mask: Value) -> Value:
        if not isinstance(mask, Value) or mask.kind.category != "bool":
            raise DSLTypeError(f"{name} needs a Bool mask, not {mask!r}")
        if mask.width == 1:
            return mask
        em = _em.current()
        return value_class(VType(mask.kind, 1))._wrap(ops.reduce(em, name.lower(), mask.vtype, mask.ir), em)

    fn.__name__ = fn.__qualname__ = name
    fn.__doc__ = (f"Scalar Bool: {'some' if name == 'Any' else 'every'} lane of the mask is set "
                  f"(in a kernel, every lane of the vector body holds an element of the arrays).")
    return fn


Any = _reduce("Any")
All = _reduce("All")


def LaneIndex(width: int | None = None) -> Value:
    """``Int<width>(0, 1, ..., width-1)``; the build's SIMD width by default."""
    em = _em.current()
    vt = VType(KINDS["Int"], width or em.width)
    return value_class(vt)._wrap(T.lanes(vt, range(vt.width)), em)


def _features():
    return _em.current().settings.target.feature_set


def target_features() -> frozenset[str]:
    """The CPU features of the build in progress (e.g. to choose an algorithm at build time)."""
    return _features()


def _require_float(name: str, x):
    if not isinstance(x, Value) or x.kind.name != "Float":
        raise DSLTypeError(f"{name} is defined for Float values (any width), not {x!r}")


def _known(*values) -> bool:
    """Whether every operand is a constant of the IR: then the portable form is emitted, which
    computes the same bits and which LLVM folds (an ``llvm.x86`` call it cannot), so a routine on
    a constant (``exp2(3.0)``, a constant ``mat3``'s ``cos``) is computed while compiling."""
    return all(_em.is_constant(v.ir) for v in values)


def _native(name: str, x, natives):
    em = _em.current()
    return value_class(x.vtype)._wrap(x86.by_native_width(em, x.vtype, x.ir, natives), em).named(name)


def RcpApprox(x: Value) -> Value:
    """Hardware estimate of 1/x: RCP14 (relative error < 2^-14) with AVX-512,
    RCPPS (< 1.5 * 2^-12) otherwise. 1/±0 = ±inf, 1/±inf = ±0, NaN -> NaN.
    RCP14 handles subnormal inputs and results; RCPPS treats subnormal inputs
    as zero and flushes results below 2^-126 (check ``target_features()``)."""
    _require_float("RcpApprox", x)
    em = _em.current()
    return value_class(x.vtype)._wrap(x86.estimate(em, "rcp", x.vtype, x.ir, _features()), em)


def RsqrtApprox(x: Value) -> Value:
    """Hardware estimate of 1/sqrt(x): RSQRT14 (< 2^-14) with AVX-512, RSQRTPS
    (< 1.5 * 2^-12) otherwise. ±0 -> ±inf, +inf -> +0, x < 0 -> NaN.
    RSQRTPS treats subnormal inputs as zero (-> inf); RSQRT14 does not."""
    _require_float("RsqrtApprox", x)
    em = _em.current()
    return value_class(x.vtype)._wrap(x86.estimate(em, "rsqrt", x.vtype, x.ir, _features()), em)


def ReduceDown(x: Value) -> Value:
    """``x - Floor(x)`` rounded toward -inf, so always in [0, 1) for finite ``x``
    (one AVX-512DQ VREDUCEPS, imm 1; the same bits elsewhere).

    The rounding control of VREDUCEPS ("down") applies to the subtraction too: the
    result is exact except for -0.5 < x < 0, where it is the float just below 1 + x
    (never 1; at most 1 - 2^-24), and an exact zero is -0.0 (integral ``x``).
    ``ReduceDown(±inf) = +0``, ``ReduceDown(NaN) = NaN``. The portable path computes
    the same bits: the difference rounded to nearest, its rounding error (exact, by
    Fast2Sum, where it is not zero), then one step down if it rounded up. (exp2
    reduces its argument with it; GLSL's ``fract`` is ``Fract``.)"""
    _require_float("ReduceDown", x)
    natives = x86.avx512_natives(_features(), "reduce", imm=1, need="avx512dq")
    if natives and not _known(x):
        return _native("reduce", x, natives)
    f = Floor(x)
    s = x - f
    below = As(vector_type("Float", x.width), As(vector_type("Int", x.width), s) - 1)  # s > 0 where used
    r = Select(x - (s + f) < 0.0, below, s)  # rounded up: take the float below
    r = Select(s == 0.0, -0.0, r)
    return Select(IsInf(x), 0.0, r).named("reduce")


def Fract(x: Value) -> Value:
    """GLSL's ``fract``: exactly ``x - Floor(x)``, the subtraction rounded to nearest. So
    ``Fract(-1e-9) = 1.0`` (as GLSL gives), integers give +0, ``Fract(±inf) = NaN``."""
    if not isinstance(x, Value) or not x.kind.is_float:
        raise DSLTypeError(f"Fract is defined for Float and Double values (any width), not {x!r}")
    return (x - Floor(x)).named("fract")


_MIN_NORMAL_BITS, _INF_BITS = 0x00800000, 0x7F800000


def _normalized_bits(x):
    """(|x|, its bits, tiny mask, bits of |x| with subnormals scaled by 2^23)."""
    Int_ = vector_type("Int", x.width)
    Float_ = vector_type("Float", x.width)
    ax = Abs(x)
    bits = As(Int_, ax)
    tiny = bits < _MIN_NORMAL_BITS
    scaled = As(Int_, Select(tiny, ax * float(2 ** 23), ax))
    return ax, bits, tiny, scaled, Int_, Float_


def Exponent(x: Value) -> Value:
    """floor(log2|x|) as a float, exact for subnormals; ±0 -> -inf, ±inf -> +inf,
    NaN -> that NaN quieted, sign and payload kept (AVX-512 VGETEXPPS; an
    integer-bit emulation with the same bits elsewhere)."""
    _require_float("Exponent", x)
    natives = x86.avx512_natives(_features(), "getexp")
    if natives and not _known(x):
        return _native("exponent", x, natives)
    ax, bits, tiny, scaled, Int_, Float_ = _normalized_bits(x)
    e = Float_((scaled >> 23) - Select(tiny, Int_(150), 127))
    e = Select(ax == 0.0, float("-inf"), e)
    e = Select(bits == _INF_BITS, ax, e)
    return Select(IsNan(x), _quiet(x), e).named("exponent")


#: The NaN an invalid operation gives on x86 (the "QNaN floating-point indefinite"),
#: which VGETMANTPS returns for a negative operand: the portable paths return it too.
_DEFAULT_NAN_BITS = -0x00400000  # 0xffc00000


def Significand(x: Value) -> Value:
    """|x| / 2^Exponent(x), in [1, 2) for finite non-zero x >= 0, exact for
    subnormals; +0 -> 1, -0 -> -1, +inf -> 1, x < 0 (and -inf) -> the default
    NaN 0xffc00000, NaN -> that NaN quieted (AVX-512 VGETMANTPS with sign control
    "NaN if negative"; the same bits elsewhere)."""
    _require_float("Significand", x)
    natives = x86.avx512_natives(_features(), "getmant", imm=0b1000)
    if natives and not _known(x):
        return _native("significand", x, natives)
    ax, bits, tiny, scaled, Int_, Float_ = _normalized_bits(x)
    m = As(Float_, (scaled & 0x007FFFFF) | 0x3F800000)
    m = Select(bits == _INF_BITS, 1.0, m)
    m = Select(x < 0.0, As(Float_, Int_(_DEFAULT_NAN_BITS)), m)
    m = Select(IsNan(x), _quiet(x), m)
    return Select(ax == 0.0, CopySign(1.0, x), m).named("significand")


def _quiet(x):
    """``x`` with the quiet bit set (a NaN stays the same NaN, quieted)."""
    Int_, Float_ = vector_type("Int", x.width), vector_type("Float", x.width)
    return As(Float_, As(Int_, x) | 0x00400000)


def ScaleF(a: Value, b: Operand) -> Value:
    """``a * 2^floor(b)`` rounded once (AVX-512 VSCALEFPS; elsewhere the same bits
    from an exact product in double precision rounded to float).

    Results below the normal range are correctly rounded subnormals; above it,
    ±inf. Specials follow VSCALEFPS's table: a NaN operand gives that NaN
    quieted (``a``'s if both are NaN), except that a quiet NaN ``a`` scaled by
    ``b = +inf`` gives +inf and by ``b = -inf`` gives +0; otherwise ``b = +inf``
    gives ±inf (NaN for a = ±0) and ``b = -inf`` gives ±0 (NaN for a = ±inf)."""
    _require_float("ScaleF", a)
    vt = common_type(a, b, what="ScaleF")
    a, b = (v if isinstance(v, Value) and v.width == vt.width else value_class(vt)(v) for v in (a, b))
    em = _em.current()
    native = None if _known(a, b) else x86.scalef(em, vt, a.ir, b.ir, _features())
    if native is not None:
        return value_class(vt)._wrap(native, em).named("scalef")
    Double_, Int_ = vector_type("Double", vt.width), vector_type("Int", vt.width)
    Long_ = VType(T.INDEX_KIND, vt.width)
    n = Max(Min(Floor(b), 320.0), -320.0)  # NaN -> 320 here; handled below
    exponent = ops.convert(em, vt.with_kind("Int"), Long_, ToInt(n, saturate=False).ir)
    bits = ops.binary(em, "shl", Long_, ops.binary(em, "add", Long_, exponent, T.const(Long_, 1023)),
                      T.const(Long_, 52))
    scale = value_class(Double_.vtype)._wrap(ops.bitcast(em, Long_, Double_.vtype, bits), em)
    regular = value_class(vt)(Double_(a) * scale)
    by_inf = Select(b > 0.0, float("inf"), 0.0)
    r = Select(IsInf(b), a * by_inf, regular)
    nan = Select(IsNan(a), _quiet(a), _quiet(b))
    quiet_a = IsNan(a) & ((As(Int_, a) & 0x00400000) != 0)
    nan = Select(quiet_a & IsInf(b), by_inf, nan)
    return Select(IsNan(a) | IsNan(b), nan, r).named("scalef")


def ReduceNearest(x: Value) -> Value:
    """``x - round(x)`` (ties to even), exact, in [-1/2, 1/2] (AVX-512DQ VREDUCEPS
    imm 0; the same bits elsewhere): +0 for integers and infinities, NaN for NaN."""
    _require_float("ReduceNearest", x)
    natives = x86.avx512_natives(_features(), "reduce", imm=0, need="avx512dq")
    if natives and not _known(x):
        return _native("reduce", x, natives)
    r = x - Round(x)
    return Select(IsInf(x), 0.0, r).named("reduce")


def Lookup(table, index: Value) -> Value:
    """``table[index mod len(table)]`` per lane: ``table`` a sequence of 2, 4, 8, 16 or 32 Python
    floats known at build time, ``index`` an Int value of any width; a Float value of that width.
    From registers where the target can (AVX-512: one VPERMPS, or VPERMI2PS for 32 entries;
    AVX2: one VPERMPS per 8 entries and selects); elsewhere a gather from a constant array. The
    table-driven reductions of the precision continuum read their tables with it."""
    values = [float(v) for v in table]
    n = len(values)
    if n < 2 or n > 32 or n & (n - 1):
        raise DSLTypeError(f"Lookup takes a table of 2, 4, 8, 16 or 32 floats, not {n}")
    if not isinstance(index, Value) or index.kind.name != "Int":
        raise DSLTypeError(f"Lookup's index is an Int value (any width), not {index!r}")
    em = _em.current()
    vt = index.vtype.with_kind("Float")
    native = None if _known(index) else x86.lookup(em, vt, values, index.ir, _features())
    if native is not None:
        return value_class(vt)._wrap(native, em).named("lookup")
    index = index & (n - 1)
    Long_ = VType(T.INDEX_KIND, vt.width)
    offsets = ops.convert(em, index.vtype, Long_, (index * 4).ir)
    g = em.module.constant_array(("lookup", tuple(values)), vt, values, "lookup")
    base = em.cast_pointer(g, T.BYTE, name="lookup")
    return value_class(vt)._wrap(em.gather(vt, base, offsets), em).named("lookup")


def LRint(x: Value) -> Value:
    """Float -> Int rounded to nearest even in one conversion (VCVTPS2DQ), for inputs
    known to be in Int's range: others give an unspecified (fixed) value, which
    differs between targets. ``ToInt(x, "nearest")`` is the checked, saturating form."""
    if not isinstance(x, Value) or x.kind.name != "Float":
        raise DSLTypeError(f"LRint converts Float values (any width), not {x!r}")
    em = _em.current()
    dst = x.vtype.with_kind("Int")
    return value_class(dst)._wrap(ops.lrint(em, x.vtype, dst, x.ir), em)
