"""exp2 and exp.

**Full precision** (the variant search's ``rscalef``, docs/search.md), for float32 x:

    f  = x - round(x)                       in [-1/2, 1/2], exact (VREDUCEPS; +0 for infinities)
    k  = x - f                              the nearest integer, exact
    2^x = scalef((P(f) * f + f) + 1, k)     P ~ (2^f - f - 1)/f: 2^f - 1 = P(f) f + f rounded
                                            once, then 1 + (2^f - 1) rounded once; VSCALEFPS
                                            multiplies by 2^k exactly, rounding only subnormals

Round-to-nearest reduction keeps f exact and |f| <= 1/2, which is what makes it 2.7x more
accurate than the floor form below (exhaustive margin 0.235 against 0.632) with fewer
operations. Without AVX-512 the scaling is an integer add to the exponent field (exact for
normal results), x >= 128 gives +inf by one select, and a vector with a lane below -125
scales in two exact steps and one rounding (p * 2^(k+64) * 2^-64): the same bits as
VSCALEFPS, subnormal results included (``python -m routines crosstarget``). exp2(k) is exact
for every integer k with a representable result (f = 0, p = 1).

**Relaxed precision** keeps the reference write-up's form ("Gaining Significance"):

    f  = x - floor(x)                       in [0, 1), exact (0 for infinities)
    y  = P(f) * f + x                       P ~ (2^f - f - 1)/f, so y ~ floor(x) + 2^f - 1
    2^x = bits(int(y * 2^23) + (127 << 23)) the integer part of y lands in the
                                            exponent field, 2^f - 1 in the mantissa

Adding the small correction P(f)*f (range [-0.086, 0]) to x instead of
multiplying 2^floor(x) by a polynomial in [1, 2) is what keeps full precision
within Vulkan's tolerance. x >= 128 gives +inf: y = 128 is exactly the bits of
+inf, and every larger y (including the conversions that overflow int32) is
clamped to them by one *unsigned integer* min on the bits, which runs on the
vector-integer pipes instead of the FMA pipes that bound this routine (a float
clamp of x would cost an FMA-pipe slot). The relaxed variant uses a degree-2 P and, when FMA is on, inserts the
exponent with one fused multiply-add in float: int(fma(y, 2^23, 127 * 2^23)).
Without FMA that trick would cost a multiply and an add, the same as the
integer path, which rounds less, so relaxed without FMA takes the integer path.

Specials (relaxed): results below 2^-126 (x < -126, and -inf) are flushed to +0 (never
negative, never a subnormal approximation: a documented flush, monotone);
NaN -> NaN; +inf -> +inf. exp2(k) is exact for every integer k in [-126, 127]
because f = 0 there and y = k exactly. Full precision: subnormal results are rounded
(never flushed), -inf -> +0, NaN -> NaN, +inf -> +inf.
"""
from __future__ import annotations

import reactor
from reactor import (
    Any, As, Floor, If, Max, Min, MulAdd, Precision, ReduceDown, ReduceNearest, Round, ScaleF, Select, ToInt,
    Variable, fma_mode, target_features, vector_type,
)

from . import accurate, continuum
from .base import float_value, routine
from .polynomials import EXP2_RELAXED

LOG2_E = 1.4426950408889634  # rounded to float32 where used: 0x3FB8AA3B
MANTISSA_SCALE = float(2 ** 23)
BIAS_BITS = 127 << 23
INF_BITS = 0x7F800000


def insert_exponent(y, float_trick: bool):
    """2^floor(y) * (1 + fract(y)) as float bits (the piecewise-linear 2^y),
    saturated to +inf for y >= 128."""
    Int_ = vector_type("Int", y.width)
    UInt_ = vector_type("UInt", y.width)
    Float_ = vector_type("Float", y.width)
    if float_trick:
        with fma_mode(True):
            bits = ToInt(MulAdd(y, MANTISSA_SCALE, float(BIAS_BITS)), saturate=False)
    else:
        bits = ToInt(y * MANTISSA_SCALE, saturate=False) + Int_(BIAS_BITS)
    # Overflowed conversions give 0x80000000 or wrap past the exponent field:
    # as unsigned they all exceed +inf's bits.
    return As(Float_, Min(As(UInt_, bits), UInt_(INF_BITS)))


def fix_specials(x, f, r):
    """+0 where 2^x is below the normal range (x < -126, -inf), x quieted where x is NaN.
    ``f`` is ReduceDown(x) (finite for every non-NaN x, so f - f is +0 or NaN) where the
    target computes it in one instruction; None elsewhere (it is NaN for -inf there)."""
    tiny_or_nan = ~(x >= -126.0)  # unordered-or-less: one compare for both cases
    low = f if f is not None else Max(-1.0, x)  # or -1 there, or the NaN x (Max's second operand)
    return Select(tiny_or_nan, low - low, r)  # +0, or x quieted


def reduce_down(x):
    """``ReduceDown(x)`` as exp2 reads it: one VREDUCEPS with AVX-512DQ. Elsewhere the same
    value for finite x except the sign of a zero (exp2 adds f * P(f) to x, where ±0 give the
    same y), and NaN for ±inf (y is then NaN: +inf saturates to +inf, -inf is one of
    fix_specials' lanes): 5 operations instead of ReduceDown's 12."""
    if "avx512dq" in target_features():
        return ReduceDown(x)
    Int_, Float_ = vector_type("Int", x.width), vector_type("Float", x.width)
    fl = Floor(x)
    s = x - fl                                           # exact, except for -0.5 < x < 0 (rounded to nearest)
    # where it rounded up, the float below (s > 0 there): the compare's all-ones lanes added as -1
    return As(Float_, As(Int_, s) + Select(x < s + fl, Int_(-1), Int_(0)))


def _full(x):
    """Full precision: the ``rscalef`` form of the module docstring (its polynomial of lower degree
    in a continuum variant, ``routines.continuum``)."""
    EXP2_FULL = continuum.polynomial("exp2")
    if "avx512f" in target_features():                     # VREDUCEPS (or its emulation) + VSCALEFPS
        f = ReduceNearest(x)
        return ScaleF(MulAdd(EXP2_FULL(f), f, f) + 1.0, x - f)
    Int_, Float_ = vector_type("Int", x.width), vector_type("Float", x.width)
    k = Round(x)
    f = x - k                                               # exact; NaN for infinities (selected below)
    p = MulAdd(EXP2_FULL(f), f, f) + 1.0
    bits = As(Int_, p)
    n = ToInt(k, saturate=False)                            # NaN: INT_MIN, shifted out: p, i.e. x quieted
    span = continuum.operand_range("exp2")
    if span is not None and span.within(-125.0, 127.0):     # a plan proved normal results, no NaN:
        return As(Float_, bits + (n << 23))                 # no subnormal path, no overflow select
    result = Variable(Float_, As(Float_, bits + (n << 23)))
    below = x < -125.0                                      # subnormal results, zeros, -inf
    with If(Any(below)):
        scaled = As(Float_, bits + ((n + 64) << 23)) * 2.0 ** -64  # exact, then rounded once
        result.set(Select(below, Select(x < -160.0, 0.0, scaled), result))
    return Select(x >= 128.0, float("inf"), result.value)


@routine
def exp2(x, precision: Precision = Precision.FULL):
    """2^x for Float values of any width; see the module docstring."""
    x = float_value(x, "exp2")
    if precision in (Precision.FAITHFUL, Precision.CORRECT):
        return accurate.exp2(x, precision).named("exp2")
    if precision is Precision.FULL:
        return _full(x).named("exp2")
    f = reduce_down(x)
    y = MulAdd(EXP2_RELAXED(f), f, x)
    r = insert_exponent(y, float_trick=reactor.build_settings().fma)
    return fix_specials(x, f if "avx512dq" in target_features() else None, r).named("exp2")


@routine
def exp(x, precision: Precision = Precision.FULL):
    """e^x = 2^(x * log2(e)). The product's rounding (relative 2^-24, at most
    ~2^-17 absolute for |x| <= 88) costs at most ~45 ULP near overflow, well
    inside Vulkan's 3 + 2|x| ULP for exp. The faithful and correct tiers reduce
    x ln 2 exactly instead (``routines.accurate``)."""
    x = float_value(x, "exp")
    if precision in (Precision.FAITHFUL, Precision.CORRECT):
        return accurate.exp(x, precision).named("exp")
    with continuum.operand_ranges("exp2", continuum.scaled(continuum.operand_range("exp"), LOG2_E)):
        return exp2(x * LOG2_E, precision=precision).named("exp")
