"""Every operation and intrinsic at widths 1, 4, 8 and 16, against NumPy.

Each test compiles one routine per (operation family, width) that evaluates
many operations on the same inputs (see ``dsl_helpers.run_ops``), and compares
bit for bit wherever the operation is exactly defined.
"""

import numpy as np
import pytest

import reactor
from reactor import (
    Abs, All, Any, As, Ceil, CopySign, Extract, Floor, Fma, Function, Insert, IsFinite,
    IsInf, IsNan, LaneIndex, Max, MaxNum, Min, MinNum, MulAdd, Pointer, Round, Select,
    ShiftRightArithmetic, ShiftRightLogical, Sqrt, ToInt, Trunc, vector_type,
)

from dsl_helpers import WIDTHS, assert_bits_equal, fma_f32, run_ops

N = 64  # a multiple of every width
I32_MIN, I32_MAX = -(2**31), 2**31 - 1


def _vt(kind):
    """``cast(x)``: convert a DSL value to ``kind`` at the value's own width."""
    return lambda x: vector_type(kind, x.width)(x)


F, I, U, D, B = _vt("Float"), _vt("Int"), _vt("UInt"), _vt("Double"), _vt("Bool")


# -- inputs ---------------------------------------------------------------------

def float_inputs(rng, count=3):
    specials = np.array([0.0, -0.0, 1.0, -1.0, 0.5, -0.5, 1.5, 2.5, -2.5, np.inf, -np.inf, np.nan,
                         1e-45, -1e-45, 1e-40, 3.4e38, -3.4e38, 2.0**31, -2.0**31, 3e9, 0.49999997,
                         1.1754944e-38], np.float32)
    out = []
    for k in range(count):
        x = (rng.standard_normal(N) * 10.0 ** rng.integers(-3, 4, N)).astype(np.float32)
        pos = rng.permutation(N)[:specials.size]
        x[pos] = rng.permutation(specials)
        out.append(x)
    # make some pairs equal so == and ties are exercised
    out[1][:6] = out[0][:6]
    return out


def int_inputs(rng):
    specials = np.array([0, 1, -1, 2, -2, 31, 32, 33, -31, -32, I32_MIN, I32_MAX, I32_MIN + 1, 7, -7],
                        np.int64)
    out = []
    for k in range(2):
        x = rng.integers(I32_MIN, I32_MAX, N, endpoint=True)
        x[: N // 4] = rng.integers(-100, 100, N // 4)
        pos = rng.permutation(N)[:specials.size]
        x[pos] = rng.permutation(specials)
        out.append(x.astype(np.int32))
    out[1][:4] = out[0][:4]
    out[1][4:6] = [0, -1]
    out[0][4:6] = [I32_MIN, I32_MIN]
    return out


# -- float arithmetic -----------------------------------------------------------

FLOAT_OPS = {
    "add": (lambda a, b, c: a + b, lambda a, b, c: a + b),
    "sub": (lambda a, b, c: a - b, lambda a, b, c: a - b),
    "mul": (lambda a, b, c: a * b, lambda a, b, c: a * b),
    "div": (lambda a, b, c: a / b, lambda a, b, c: a / b),
    "neg": (lambda a, b, c: -a, lambda a, b, c: -a),
    "pos": (lambda a, b, c: +a, lambda a, b, c: +a),
    "add_const": (lambda a, b, c: a + 1.5, lambda a, b, c: a + np.float32(1.5)),
    "rsub_const": (lambda a, b, c: 2 - a, lambda a, b, c: np.float32(2) - a),
    "rdiv_const": (lambda a, b, c: 1.0 / a, lambda a, b, c: np.float32(1) / a),
    "mul_const": (lambda a, b, c: a * 0.1, lambda a, b, c: a * np.float32(0.1)),
    "min": (lambda a, b, c: Min(a, b), lambda a, b, c: np.where(a < b, a, b)),
    "max": (lambda a, b, c: Max(a, b), lambda a, b, c: np.where(a > b, a, b)),
    "min_const": (lambda a, b, c: Min(a, 1.0), lambda a, b, c: np.where(a < 1, a, np.float32(1))),
    "copysign": (lambda a, b, c: CopySign(a, b), lambda a, b, c: np.copysign(a, b)),
    "abs": (lambda a, b, c: Abs(a), lambda a, b, c: np.abs(a)),
    "abs_builtin": (lambda a, b, c: abs(b), lambda a, b, c: np.abs(b)),
    "floor": (lambda a, b, c: Floor(a), lambda a, b, c: np.floor(a)),
    "ceil": (lambda a, b, c: Ceil(a), lambda a, b, c: np.ceil(a)),
    "trunc": (lambda a, b, c: Trunc(a), lambda a, b, c: np.trunc(a)),
    "round_even": (lambda a, b, c: Round(a), lambda a, b, c: np.rint(a)),
    "sqrt": (lambda a, b, c: Sqrt(a), lambda a, b, c: np.sqrt(a)),
    "select": (lambda a, b, c: Select(a < b, c, a * b), lambda a, b, c: np.where(a < b, c, a * b)),
    "select_const": (lambda a, b, c: Select(IsNan(a), 0.0, a), lambda a, b, c: np.where(np.isnan(a), np.float32(0), a)),
    "bitcast_roundtrip": (lambda a, b, c: As(vector_type("Float", a.width), As(vector_type("Int", a.width), a) ^ I32_MIN),
                          lambda a, b, c: -a),
    "muladd_unfused": (lambda a, b, c: MulAdd(a, b, c), lambda a, b, c: a * b + c),
}


@pytest.mark.parametrize("width", WIDTHS)
def test_float_arithmetic(width, rng):
    a, b, c = float_inputs(rng)
    names = list(FLOAT_OPS)
    got = run_ops("Float", width, [FLOAT_OPS[k][0] for k in names], [a, b, c], fma=False)
    with np.errstate(all="ignore"):
        for row, name in zip(got, names):
            want = np.asarray(FLOAT_OPS[name][1](a, b, c), np.float32)
            try:
                assert_bits_equal(row, want)
            except AssertionError as exc:
                raise AssertionError(f"{name} at width {width}: {exc}") from None


@pytest.mark.parametrize("width", WIDTHS)
def test_ieee_min_max_num(width, rng):
    """MinNum/MaxNum ignore a NaN operand; for +0/-0 either zero may come back."""
    a, b, c = float_inputs(rng)
    got = run_ops("Float", width, [lambda a, b: MinNum(a, b), lambda a, b: MaxNum(a, b)], [a, b])
    assert_bits_equal(got[0], np.fmin(a, b), signed_zero=False)
    assert_bits_equal(got[1], np.fmax(a, b), signed_zero=False)


@pytest.mark.parametrize("width", WIDTHS)
def test_fused_multiply_add_is_single_rounding(width, rng):
    a, b, c = (x[np.isfinite(x)][:16] for x in float_inputs(rng))
    # a case that distinguishes one rounding from two: (1+2^-13)^2 - (1+2^-12) = 2^-26
    a[0] = b[0] = 1 + 2.0**-13
    c[0] = -(1 + 2.0**-12)
    got = run_ops("Float", width, [lambda a, b, c: MulAdd(a, b, c), lambda a, b, c: Fma(a, b, c),
                                   lambda a, b, c: a * b + c], [a, b, c], fma=True)
    want = fma_f32(a, b, c)
    assert want[0] == 2.0**-26
    assert_bits_equal(got[0], want)
    assert_bits_equal(got[1], want)
    with np.errstate(all="ignore"):
        two_roundings = a * b + c
    assert_bits_equal(got[2], two_roundings)  # plain operators never fuse
    unfused = run_ops("Float", width, [lambda a, b, c: MulAdd(a, b, c)], [a, b, c], fma=False)
    assert_bits_equal(unfused[0], two_roundings)
    assert unfused[0][0] == 0.0


# -- float comparisons and classification ------------------------------------------

FLOAT_TESTS = {
    "lt": (lambda a, b: a < b, lambda a, b: a < b),
    "le": (lambda a, b: a <= b, lambda a, b: a <= b),
    "gt": (lambda a, b: a > b, lambda a, b: a > b),
    "ge": (lambda a, b: a >= b, lambda a, b: a >= b),
    "eq": (lambda a, b: a == b, lambda a, b: a == b),
    "ne": (lambda a, b: a != b, lambda a, b: a != b),
    "lt_const": (lambda a, b: a < 0.5, lambda a, b: a < 0.5),
    "const_lt": (lambda a, b: 0.5 < a, lambda a, b: 0.5 < a),
    "isnan": (lambda a, b: IsNan(a), lambda a, b: np.isnan(a)),
    "isinf": (lambda a, b: IsInf(a), lambda a, b: np.isinf(a)),
    "isfinite": (lambda a, b: IsFinite(a), lambda a, b: np.isfinite(a)),
    "and": (lambda a, b: (a < b) & (b < 1.0), lambda a, b: (a < b) & (b < 1)),
    "or": (lambda a, b: (a < b) | IsNan(a), lambda a, b: (a < b) | np.isnan(a)),
    "xor": (lambda a, b: (a < b) ^ (a > 0.0), lambda a, b: (a < b) ^ (a > 0)),
    "not": (lambda a, b: ~(a < b), lambda a, b: ~(a < b)),
    "mask_eq": (lambda a, b: (a < b) == (b > a), lambda a, b: (a < b) == (b > a)),
    "mask_ne": (lambda a, b: (a < b) != (a >= b), lambda a, b: (a < b) != (a >= b)),
    "mask_select": (lambda a, b: Select(a < b, a > 0.0, b > 0.0), lambda a, b: np.where(a < b, a > 0, b > 0)),
    "mask_const": (lambda a, b: (a < b) & True, lambda a, b: a < b),
    "to_bool": (lambda a, b: B(a), lambda a, b: a.astype(bool)),
}


@pytest.mark.parametrize("width", WIDTHS)
def test_float_comparisons(width, rng):
    a, b, _ = float_inputs(rng)
    names = list(FLOAT_TESTS)
    got = run_ops("Float", width, [FLOAT_TESTS[k][0] for k in names], [a, b], out_kind="Bool")
    with np.errstate(all="ignore"):
        for row, name in zip(got, names):
            assert_bits_equal(row, np.asarray(FLOAT_TESTS[name][1](a, b)), ), name


# -- conversions ------------------------------------------------------------------

def _saturate(x, lo, hi):
    x = np.asarray(x, np.float64)
    return np.where(np.isnan(x), 0, np.clip(x, lo, hi)).astype(np.int64)


@pytest.mark.parametrize("width", WIDTHS)
def test_float_to_int_conversions(width, rng):
    a, b, _ = float_inputs(rng)
    ops = [
        lambda a, b: I(a),                        # truncating, saturating, NaN -> 0
        lambda a, b: ToInt(a),
        lambda a, b: ToInt(a, "nearest"),          # ties to even
        lambda a, b: As(vector_type("Int", a.width), a),
        lambda a, b: I(a < b),                     # mask -> 0/1
        lambda a, b: ToInt(a, saturate=False) * 0 + 5,  # fixed (frozen) value, never poison
    ]
    got = run_ops("Float", width, ops, [a, b], out_kind="Int")
    with np.errstate(all="ignore"):
        trunc = _saturate(np.trunc(a), I32_MIN, I32_MAX).astype(np.int32)
        assert_bits_equal(got[0], trunc)
        assert_bits_equal(got[1], trunc)
        assert_bits_equal(got[2], _saturate(np.rint(a), I32_MIN, I32_MAX).astype(np.int32))
        assert_bits_equal(got[3], a.view(np.int32))
        assert_bits_equal(got[4], (a < b).astype(np.int32))
        assert_bits_equal(got[5], np.full(N, 5, np.int32))
    got = run_ops("Float", width, [lambda a: ToInt(a, unsigned=True), lambda a: U(a),
                                   lambda a: ToInt(a, "nearest", unsigned=True)], [a], out_kind="UInt")
    with np.errstate(all="ignore"):
        assert_bits_equal(got[0], _saturate(np.trunc(a), 0, 2**32 - 1).astype(np.uint32))
        assert_bits_equal(got[1], _saturate(np.trunc(a), 0, 2**32 - 1).astype(np.uint32))
        assert_bits_equal(got[2], _saturate(np.rint(a), 0, 2**32 - 1).astype(np.uint32))


@pytest.mark.parametrize("width", WIDTHS)
def test_int_to_float_conversions(width, rng):
    i, j = int_inputs(rng)
    ops = [lambda i, j: F(i), lambda i, j: As(vector_type("Float", i.width), i), lambda i, j: F(i < j),
           lambda i, j: F(U(i))]
    got = run_ops("Int", width, ops, [i, j], out_kind="Float")
    assert_bits_equal(got[0], i.astype(np.float32))
    assert_bits_equal(got[1], i.view(np.float32))
    assert_bits_equal(got[2], (i < j).astype(np.float32))
    assert_bits_equal(got[3], i.view(np.uint32).astype(np.float32))
    got = run_ops("Int", width, [lambda i, j: U(i), lambda i, j: As(vector_type("UInt", i.width), j)],
                  [i, j], out_kind="UInt")
    assert_bits_equal(got[0], i.view(np.uint32))
    assert_bits_equal(got[1], j.view(np.uint32))
    got = run_ops("Int", width, [lambda i: B(i), lambda i: ~B(i)], [i], out_kind="Bool")
    assert_bits_equal(got[0], i != 0)
    assert_bits_equal(got[1], i == 0)


@pytest.mark.parametrize("width", WIDTHS)
def test_double(width, rng):
    a, b, _ = float_inputs(rng)
    got = run_ops("Float", width, [lambda a, b: D(a), lambda a, b: D(a) * D(b), lambda a, b: D(a) / 3.0],
                  [a, b], out_kind="Double")
    with np.errstate(all="ignore"):
        assert_bits_equal(got[0], a.astype(np.float64))
        assert_bits_equal(got[1], a.astype(np.float64) * b.astype(np.float64))
        assert_bits_equal(got[2], a.astype(np.float64) / 3.0)
    x, y = a.astype(np.float64) * 1.1, b.astype(np.float64)
    ops = [lambda x, y: x + y, lambda x, y: x * y - 1.0, lambda x, y: x / y, lambda x, y: Sqrt(x),
           lambda x, y: Floor(x), lambda x, y: Round(x), lambda x, y: Min(x, y), lambda x, y: CopySign(x, y),
           lambda x, y: D(F(x))]
    got = run_ops("Double", width, ops, [x, y])
    with np.errstate(all="ignore"):
        wants = [x + y, x * y - 1.0, x / y, np.sqrt(x), np.floor(x), np.rint(x), np.where(x < y, x, y),
                 np.copysign(x, y), x.astype(np.float32).astype(np.float64)]
        for k, want in enumerate(wants):
            assert_bits_equal(got[k], want)


# -- integers -----------------------------------------------------------------------

def _div_signed(a, b):
    a, b = a.astype(np.int64), b.astype(np.int64)
    safe = np.where(b == 0, 1, b)
    q = np.abs(a) // np.abs(safe) * np.sign(a) * np.sign(safe)
    r = a - q * safe
    return np.where(b == 0, 0, q).astype(np.int32), np.where(b == 0, 0, r).astype(np.int32)


def _div_unsigned(a, b):
    a, b = a.astype(np.uint64), b.astype(np.uint64)
    safe = np.where(b == 0, 1, b)
    return np.where(b == 0, 0, a // safe).astype(np.uint32), np.where(b == 0, 0, a % safe).astype(np.uint32)


def _shl(a, b):
    return ((a.view(np.uint32).astype(np.uint64) << (b.astype(np.uint64) & 31)) & 0xFFFFFFFF).astype(np.uint32)


def _lshr(a, b):
    return a.view(np.uint32) >> (b.view(np.uint32) & 31)


def _ashr(a, b):
    return a.view(np.int32) >> (b.view(np.int32) & 31)


def _wrap(x, dtype):
    return (np.asarray(x, np.int64) & 0xFFFFFFFF).astype(np.uint32).view(dtype)


INT_OPS = {
    "add": (lambda a, b: a + b, lambda a, b, t: _wrap(a.astype(np.int64) + b, t)),
    "sub": (lambda a, b: a - b, lambda a, b, t: _wrap(a.astype(np.int64) - b, t)),
    "mul": (lambda a, b: a * b, lambda a, b, t: _wrap(a.astype(np.int64) * b, t)),
    "add_const": (lambda a, b: a + 7, lambda a, b, t: _wrap(a.astype(np.int64) + 7, t)),
    "rsub_const": (lambda a, b: 100 - a, lambda a, b, t: _wrap(100 - a.astype(np.int64), t)),
    "mul_const": (lambda a, b: a * 3, lambda a, b, t: _wrap(a.astype(np.int64) * 3, t)),
    "neg": (lambda a, b: -a, lambda a, b, t: _wrap(-a.astype(np.int64), t)),
    "and": (lambda a, b: a & b, lambda a, b, t: a & b),
    "or": (lambda a, b: a | b, lambda a, b, t: a | b),
    "xor": (lambda a, b: a ^ b, lambda a, b, t: a ^ b),
    "not": (lambda a, b: ~a, lambda a, b, t: ~a),
    "and_const": (lambda a, b: a & 0xFF0, lambda a, b, t: a & t(0xFF0)),
    "shl": (lambda a, b: a << b, lambda a, b, t: _shl(a, b).view(t)),
    "shl_const": (lambda a, b: a << 3, lambda a, b, t: _shl(a, np.full_like(b, 3)).view(t)),
    "shl_33": (lambda a, b: a << 33, lambda a, b, t: _shl(a, np.full_like(b, 1)).view(t)),
    "shr": (lambda a, b: a >> b, None),  # arithmetic on Int, logical on UInt
    "lshr": (lambda a, b: ShiftRightLogical(a, b), lambda a, b, t: _lshr(a, b).view(t)),
    "ashr": (lambda a, b: ShiftRightArithmetic(a, b), lambda a, b, t: _ashr(a, b).view(t)),
    "lshr_const": (lambda a, b: ShiftRightLogical(a, 35), lambda a, b, t: _lshr(a, np.full_like(b, 3)).view(t)),
    "min": (lambda a, b: Min(a, b), lambda a, b, t: np.minimum(a, b)),
    "max": (lambda a, b: Max(a, b), lambda a, b, t: np.maximum(a, b)),
    "select": (lambda a, b: Select(a < b, a * 2, b), lambda a, b, t: np.where(a < b, _wrap(a.astype(np.int64) * 2, t), b)),
    "div": (lambda a, b: a / b, None),
    "rem": (lambda a, b: a % b, None),
    "div_const": (lambda a, b: a / 7, None),
}


@pytest.mark.parametrize("kind", ["Int", "UInt"])
@pytest.mark.parametrize("width", WIDTHS)
def test_integer_arithmetic(kind, width, rng):
    i, j = int_inputs(rng)
    t = np.int32 if kind == "Int" else np.uint32
    a, b = i.view(t), j.view(t)
    ops = dict(INT_OPS)
    if kind == "Int":
        ops["abs"] = (lambda a, b: Abs(a), lambda a, b, t: np.abs(a))  # INT_MIN stays INT_MIN
    names = list(ops)
    got = run_ops(kind, width, [ops[k][0] for k in names], [a, b])
    divide = _div_signed if kind == "Int" else _div_unsigned
    special = {
        "shr": (_ashr if kind == "Int" else _lshr)(a, b).view(t),
        "div": divide(a, b)[0],
        "rem": divide(a, b)[1],
        "div_const": divide(a, np.full_like(b, 7))[0],
    }
    for row, name in zip(got, names):
        want = special[name] if name in special else np.asarray(ops[name][1](a, b, t)).astype(t)
        try:
            assert_bits_equal(row, want)
        except AssertionError as exc:
            raise AssertionError(f"{kind} {name} at width {width}: {exc}") from None


@pytest.mark.parametrize("kind", ["Int", "UInt"])
@pytest.mark.parametrize("width", WIDTHS)
def test_integer_comparisons(kind, width, rng):
    i, j = int_inputs(rng)
    t = np.int32 if kind == "Int" else np.uint32
    a, b = i.view(t), j.view(t)
    ops = [lambda a, b: a < b, lambda a, b: a <= b, lambda a, b: a > b, lambda a, b: a >= b,
           lambda a, b: a == b, lambda a, b: a != b, lambda a, b: a < 5, lambda a, b: 5 <= a]
    got = run_ops(kind, width, ops, [a, b], out_kind="Bool")
    wants = [a < b, a <= b, a > b, a >= b, a == b, a != b, a < 5, 5 <= a]
    for k, want in enumerate(wants):
        assert_bits_equal(got[k], want)


@pytest.mark.parametrize("width", WIDTHS)
def test_bool_operations(width, rng):
    p, q = rng.random(N) < 0.5, rng.random(N) < 0.5
    ops = [lambda p, q: p & q, lambda p, q: p | q, lambda p, q: p ^ q, lambda p, q: ~p,
           lambda p, q: p == q, lambda p, q: p != q, lambda p, q: Select(p, q, ~q),
           lambda p, q: p | False, lambda p, q: p & True, lambda p, q: True ^ q]
    got = run_ops("Bool", width, ops, [p, q])
    wants = [p & q, p | q, p ^ q, ~p, p == q, p != q, np.where(p, q, ~q), p, p, ~q]
    for k, want in enumerate(wants):
        assert_bits_equal(got[k], want)
    got = run_ops("Bool", width, [lambda p, q: I(p) * 2 + I(q)], [p, q], out_kind="Int")
    assert_bits_equal(got[0], (p * 2 + q).astype(np.int32))


# -- lanes, masks and reductions ------------------------------------------------------------

@pytest.mark.parametrize("width", [4, 8, 16])
def test_lane_extract_insert_and_reductions(width, rng):
    T = vector_type("Float", width)
    x = rng.standard_normal(width).astype(np.float32)

    def lanes(v: Pointer[T], idx: reactor.Int, out: Pointer[reactor.Float], vout: Pointer[T],
              iout: Pointer[vector_type("Int", width)], bout: Pointer[reactor.Bool]):
        a = v[0]
        for k in range(width):  # unrolled at build time
            out[k] = Extract(a, k)
        out[width] = Extract(a, idx)
        out[width + 1] = Extract(a, idx + width)  # dynamic indices are taken modulo the width
        vout[0] = Insert(a, 42.0, 1)
        vout[1] = Insert(a, Extract(a, 0) * 2.0, idx)
        vout[2] = T(*[float(k) for k in range(width)])
        vout[3] = T(Extract(a, 2))  # broadcast a scalar
        iout[0] = LaneIndex()
        iout[1] = LaneIndex(width) * 3
        thresholds = [-100.0, 0.0, 100.0]
        for k, t in enumerate(thresholds):
            bout[2 * k] = Any(a > t)
            bout[2 * k + 1] = All(a > t)
        bout[6] = Any(reactor.Bool(True))
        bout[7] = All(a == a)

    fn = Function(lanes, width=width)
    out = np.zeros(width + 2, np.float32)
    vout = np.zeros((4, width), np.float32)
    iout = np.zeros((2, width), np.int32)
    bout = np.zeros(8, bool)
    fn(x, 3, out, vout.reshape(-1), iout.reshape(-1), bout)
    assert_bits_equal(out[:width], x)
    assert out[width] == out[width + 1] == x[3]
    want = x.copy(); want[1] = 42.0
    assert_bits_equal(vout[0], want)
    want = x.copy(); want[3] = x[0] * 2
    assert_bits_equal(vout[1], want)
    assert_bits_equal(vout[2], np.arange(width, dtype=np.float32))
    assert_bits_equal(vout[3], np.full(width, x[2]))
    assert_bits_equal(iout[0], np.arange(width, dtype=np.int32))
    assert_bits_equal(iout[1], np.arange(width, dtype=np.int32) * 3)
    wants = []
    for t in (-100.0, 0.0, 100.0):
        wants += [np.any(x > t), np.all(x > t)]
    assert_bits_equal(bout, np.array(wants + [True, True]))


def test_scalar_any_all_are_identity():
    def f(x: reactor.Float) -> reactor.Int:
        return reactor.Int(Any(x > 0.0)) * 2 + reactor.Int(All(x > 1.0))

    fn = Function(f, width=1)
    assert [fn(v) for v in (-1.0, 0.5, 2.0)] == [0, 2, 3]


@pytest.mark.parametrize("width", [4, 8, 16])
def test_vector_arguments_and_results(width):
    """Vector parameters/results cross the Python boundary as arrays of `width` elements."""
    T, I_ = vector_type("Float", width), vector_type("Int", width)

    def f(x: T, k: I_, s: reactor.Float) -> T:
        return x * s + F(k)

    fn = Function(f)
    x = np.arange(width, dtype=np.float32)
    k = np.arange(width, dtype=np.int32)[::-1].copy()
    got = fn(x, k, 0.5)
    assert isinstance(got, np.ndarray) and got.shape == (width,) and got.dtype == np.float32
    assert_bits_equal(got, x * np.float32(0.5) + k.astype(np.float32))


@pytest.mark.parametrize("src", ["Float", "Double", "Half"])
@pytest.mark.parametrize("dst", ["Int", "UInt", "UByte", "UShort"])
def test_saturating_conversions_at_the_range_ends(src, dst):
    """Float -> integer conversions saturate (NaN -> 0) in vector code, at and next to each bound."""
    import reactor
    from reactor import kernel

    dtype = {"Float": np.float32, "Double": np.float64, "Half": np.float16}[src]
    info = np.iinfo({"Int": np.int32, "UInt": np.uint32, "UByte": np.uint8, "UShort": np.uint16}[dst])
    ends = [info.min, info.max, info.max + 1, info.min - 1, -0.5, 0.5, -1, 255.9, 65535.5, 2**31 - 128,
            -2**31 - 256, 2**32 - 256, 1e30, -1e30, np.inf, -np.inf, np.nan]
    rng = np.random.default_rng(7)
    with np.errstate(all="ignore"):
        x = np.concatenate([np.array(ends, np.float64).astype(dtype), np.nextafter(
            np.array(ends, dtype), dtype(np.inf)), np.nextafter(np.array(ends, dtype), dtype(-np.inf)),
            (rng.standard_normal(5000) * 2.0 ** rng.integers(0, 40, 5000)).astype(dtype)])
    kind_in, kind_out = getattr(reactor, src), getattr(reactor, dst)

    @kernel
    def convert(a: kind_in) -> kind_out:
        return kind_out(a)

    with np.errstate(all="ignore"):
        wide = x.astype(np.float64)
        expected = np.where(np.isnan(wide), 0, np.clip(np.trunc(np.nan_to_num(wide, posinf=1e300, neginf=-1e300)),
                                                        info.min, info.max)).astype(info.dtype)
    np.testing.assert_array_equal(convert(x), expected)
