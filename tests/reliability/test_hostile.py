"""Hostile inputs at the kernel (ufunc) and routine (compiled Function) boundary:
each case gives the right answer or a clear exception; guard pages prove that
no read or write lands outside an operand."""
import os
import subprocess
import sys

import numpy as np
import pytest

import reactor

import routines
from reactor import (
    ArgumentError, ArityError, Bool, Float, Float4, For, Int, Pointer, Variable, function, kernel,
)

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


@kernel(fma=False, name="hostile_k2")
def k2(a: Float, b: Float) -> Float:
    return a * b + 1.0


def ref(a, b):
    a, b = np.asarray(a, np.float32), np.asarray(b, np.float32)
    return a * b + np.float32(1)


@function
def total(p: Pointer[Float, "n"], n: Int) -> Float:
    acc = Variable(Float, 0.0)
    with For(0, n) as i:
        acc += p[i]
    return acc


@function
def scale(p: Pointer[Float, "n"], n: Int, s: Float):
    with For(0, n) as i:
        p[i] = p[i] * s


@function
def vsum(p: Pointer[Float4, "n"], n: Int) -> Float4:
    acc = Variable(Float4, 0.0)
    with For(0, n) as i:
        acc += p[i]
    return acc


@function
def first8(p: Pointer[Float, 8]) -> Float:
    return p[0] + p[7]


@function
def head(p: Pointer[Float]) -> Float:
    return p[0]


@function
def double_into(dst: Pointer[Float, "n"], src: Pointer[Float, "n"], n: Int):
    with For(0, n) as i:
        dst[i] = src[i] * 2.0


@function
def count(b: Pointer[Bool, "n"], n: Int) -> Int:
    c = Variable(Int, 0)
    with For(0, n) as i:
        c += Int(b[i])
    return c


@function
def lane_sum(v: Float4, k: Int) -> Float:
    return v[0] + Float(k) if False else _lane_sum(v, k)


def _lane_sum(v, k):
    from reactor import Extract
    return Extract(v, 0) + Extract(v, 3) + Float(k)


X = np.linspace(-3, 3, 37, dtype=np.float32)
Y = np.linspace(2, -1, 37, dtype=np.float32)


def _ro(a):
    a = a.copy()
    a.setflags(write=False)
    return a


def _unaligned(a):
    buf = np.zeros(a.nbytes + 1, np.uint8)
    out = np.frombuffer(buf.data, dtype=a.dtype, count=a.size, offset=1)
    out[:] = a
    return out


def _overlap_kernel():
    a = np.arange(40, dtype=np.float32)
    want = ref(a[:-1], a[1:])
    k2(a[:-1], a[1:], out=a[1:])
    return a[1:], want


def _overlap_routine():
    a = np.arange(1, 12, dtype=np.float32)
    want = a.copy()
    for i in range(10):  # the routine's defined semantics: element by element, in order
        want[i + 1] = want[i] * 2
    double_into(a[1:], a[:-1], 10)
    return a, want


def _in_place():
    a = X.copy()
    k2(a, Y, out=a)
    return a, ref(X, Y)


def _where():
    out = np.full(X.size, 9, np.float32)
    mask = np.arange(X.size) % 3 == 0
    k2(X, Y, out=out, where=mask)
    return out, np.where(mask, ref(X, Y), np.float32(9))


def _parallel_reversed():
    saved = reactor.thread_settings()
    reactor.configure_threads(threads=2, threshold=1000, min_work=0)
    try:
        x = np.linspace(-2, 2, 10_001, dtype=np.float32)
        return k2(x[::-1], x[::-1]), ref(x[::-1], x[::-1])
    finally:
        reactor.configure_threads(**saved._asdict())


def _routine_layouts(name):
    u = routines.jit(name)
    x = np.linspace(0.1, 9, 64, dtype=np.float32)
    want = u(x)
    m = np.empty((8, 16), np.float32)
    m[:, ::2] = x.reshape(8, 8)
    return np.concatenate([u(x[::-1])[::-1], u(m[:, ::2]).ravel(), u(_unaligned(x))]), np.concatenate([want] * 3)


# (case id, thunk giving (got, want)) -- the right answer, bit for bit
RIGHT = [
    ("kernel int16 input: safe cast", lambda: (k2(X.astype(np.int16), Y), ref(X.astype(np.int16), Y))),
    ("kernel float16 input: safe cast", lambda: (k2(X.astype(np.float16), Y), ref(X.astype(np.float16), Y))),
    ("kernel bool input: safe cast", lambda: (k2(X > 0, Y), ref(X > 0, Y))),
    ("kernel Python float and int operands", lambda: (k2(1.5, Y), ref(np.float32(1.5), Y))),
    ("kernel Python int operand", lambda: (k2(X, 2), ref(X, np.float32(2)))),
    ("kernel byte-swapped input", lambda: (k2(X.astype(">f4"), Y), ref(X, Y))),
    ("kernel float64 input, dtype=float32 casting='unsafe'",
     lambda: (k2(X.astype(np.float64), Y, dtype=np.float32, casting="unsafe"), ref(X, Y))),
    ("kernel float64 input, dtype=float32 casting='same_kind'",
     lambda: (k2(X.astype(np.float64), Y, dtype=np.float32, casting="same_kind"), ref(X, Y))),
    ("kernel float64 out= (output cast)",
     lambda: (k2(X, Y, out=np.zeros(X.size)), ref(X, Y).astype(np.float64))),
    ("kernel non-contiguous 2-D views",
     lambda: (k2(np.tile(X, (3, 2))[:, ::3], np.tile(Y, (3, 2))[:, 1::3]),
              ref(np.tile(X, (3, 2))[:, ::3], np.tile(Y, (3, 2))[:, 1::3]))),
    ("kernel transposed (Fortran-order) operands",
     lambda: (k2(np.tile(X, (4, 1)).T, np.tile(Y, (4, 1)).T), ref(np.tile(X, (4, 1)).T, np.tile(Y, (4, 1)).T))),
    ("kernel negative strides", lambda: (k2(X[::-2], Y[::-2]), ref(X[::-2], Y[::-2]))),
    ("kernel stride-0 broadcast view", lambda: (k2(np.broadcast_to(X[:1], (37,)), Y), ref(X[0], Y))),
    ("kernel zero-size 1-D", lambda: (k2(X[:0], Y[:0]), ref(X[:0], Y[:0]))),
    ("kernel zero-size 2-D (3, 0)",
     lambda: (k2(np.zeros((3, 0), np.float32), np.zeros((3, 0), np.float32)), np.zeros((3, 0), np.float32))),
    ("kernel 0-d arrays", lambda: (k2(np.array(2, np.float32), np.array(3, np.float32)), np.float32(7))),
    ("kernel NumPy scalars", lambda: (k2(np.float32(2), np.float32(-3)), np.float32(-5))),
    ("kernel in place (out aliases an input)", _in_place),
    ("kernel output overlapping an input (shifted)", _overlap_kernel),
    ("kernel where= with out=", _where),
    ("kernel read-only inputs", lambda: (k2(_ro(X), _ro(Y)), ref(X, Y))),
    ("kernel unaligned input and output",
     lambda: (k2(_unaligned(X), _unaligned(Y), out=_unaligned(np.zeros_like(X))), ref(X, Y))),
    ("kernel split across threads, reversed", _parallel_reversed),
    ("routine exp2: reversed, strided 2-D, unaligned", lambda: _routine_layouts("exp2")),
    ("routine pow: 0-d operands and a broadcast exponent (as with full arrays)",
     lambda: (np.array([routines.jit("pow")(np.float32(2), np.float32(3)), *routines.jit("pow")(Y, 0.5)]),
              np.array([*routines.jit("pow")(np.float32([2]), np.float32([3])),
                        *routines.jit("pow")(Y, np.full_like(Y, 0.5))]))),
    ("Function: C-contiguous 2-D array as a pointer",
     lambda: (total(np.ones((4, 5), np.float32), 20), 20.0)),
    ("Function: 0-d array as a one-element pointer", lambda: (total(np.array(2.5, np.float32), 1), 2.5)),
    ("Function: empty array with n = 0", lambda: (total(np.zeros(0, np.float32), 0), 0.0)),
    ("Function: negative n (no iterations)", lambda: (total(np.ones(3, np.float32), -5), 0.0)),
    ("Function: unaligned array", lambda: (total(_unaligned(np.arange(9, dtype=np.float32)), 9), 36.0)),
    ("Function: read-only array for a pointer it only reads", lambda: (total(_ro(np.ones(6, np.float32)), 6), 6.0)),
    ("Function: offset view (a[2:])", lambda: (total(np.arange(10, dtype=np.float32)[2:], 8), 44.0)),
    ("Function: overlapping pointer arguments", _overlap_routine),
    ("Function: NumPy integer and 0-d scalar arguments",
     lambda: (total(np.ones(7, np.float32), np.int64(7)) + total(np.ones(7, np.float32), np.array(3)), 10.0)),
    ("Function: NaN and inf scalar arguments",
     lambda: (_scaled(np.ones(3, np.float32), float("inf")), np.full(3, np.inf, np.float32))),
    ("Function: Bool pointer", lambda: (count(np.array([1, 0, 1, 1], bool), 4), 3)),
    ("Function: vector argument from a strided array",
     lambda: (lane_sum(np.arange(8, dtype=np.float32)[::2], 1), 0 + 6 + 1.0)),
]


def _scaled(a, s):
    scale(a, a.size, s)
    return a


# (case id, thunk, exception type, words in the message)
RAISES = [
    ("kernel int32 input (unsafe cast)", lambda: k2(X.astype(np.int32), Y), TypeError, "argument 'a' is int32"),
    ("kernel int64 input", lambda: k2(X.astype(np.int64), Y), TypeError, "argument 'a' is int64"),
    ("kernel float64 input (casting rules)", lambda: k2(X.astype(np.float64), Y), TypeError,
     "dtype=np.float32, casting='same_kind'"),
    ("kernel complex input", lambda: k2(X.astype(np.complex64), Y), TypeError, "not supported"),
    ("kernel object input", lambda: k2(X.astype(object), Y), TypeError, "not supported"),
    ("kernel string input", lambda: k2(np.array(["a"] * 37), Y), TypeError, "not supported"),
    ("kernel list of floats (float64)", lambda: k2([1.0, 2.0], [3.0, 4.0]), TypeError, "and 'b' is float64"),
    ("kernel too few arguments", lambda: k2(X), TypeError, "takes from 2 to 3 positional arguments"),
    ("kernel too many arguments", lambda: k2(X, Y, X, Y), TypeError, "takes from 2 to 3 positional arguments"),
    ("kernel out= of the wrong shape", lambda: k2(X, Y, out=np.zeros(36, np.float32)), ValueError, "broadcast"),
    ("kernel read-only out=", lambda: k2(X, Y, out=_ro(np.zeros(37, np.float32))), ValueError, "read-only"),
    ("kernel int32 out= (unsafe cast)", lambda: k2(X, Y, out=np.zeros(37, np.int32)), TypeError, "Cannot cast"),
    ("kernel out= a list", lambda: k2(X, Y, out=[np.zeros(37, np.float32)]), TypeError, "ArrayType"),
    ("kernel out= tuple of the wrong length",
     lambda: k2(X, Y, out=(np.zeros(37, np.float32),) * 2), ValueError, "one entry per ufunc output"),
    ("kernel out given twice", lambda: k2(X, Y, np.zeros(37, np.float32), out=np.zeros(37, np.float32)),
     TypeError, "both a positional and keyword"),
    ("kernel dtype=float64 (no such loop)", lambda: k2(X, Y, dtype=np.float64), TypeError, "No loop matching"),
    ("kernel operands that do not broadcast", lambda: k2(X, Y[:36]), ValueError, "could not be broadcast"),
    ("kernel where= of the wrong shape",
     lambda: k2(X, Y, out=np.zeros(37, np.float32), where=np.ones(36, bool)), ValueError, "broadcast"),
    ("routine pow with float64 inputs", lambda: routines.jit("pow")(X.astype(np.float64), Y), TypeError,
     "computes in float32, and its argument 'x' is float64"),
    ("routine exp2 into a read-only out=", lambda: routines.jit("exp2")(X, out=_ro(X)), ValueError, "read-only"),
    ("Function: float64 array", lambda: total(np.zeros(4), 4), ArgumentError, "dtype float32, not float64"),
    ("Function: byte-swapped array", lambda: total(np.zeros(4, ">f4"), 4), ArgumentError, "dtype float32"),
    ("Function: int8 array for a Bool pointer", lambda: count(np.zeros(4, np.int8), 4), ArgumentError,
     "dtype bool"),
    ("Function: Python list for a pointer", lambda: total([1.0, 2.0], 2), ArgumentError, "must be a NumPy array"),
    ("Function: negative-stride array", lambda: total(np.ones(8, np.float32)[::-1], 8), ArgumentError,
     "C-contiguous"),
    ("Function: non-contiguous array", lambda: total(np.ones(8, np.float32)[::2], 4), ArgumentError,
     "C-contiguous"),
    ("Function: Fortran-order 2-D array", lambda: total(np.asfortranarray(np.ones((3, 4), np.float32)), 12),
     ArgumentError, "C-contiguous"),
    ("Function: array one element shorter than n", lambda: total(np.ones(8, np.float32), 9), ArgumentError,
     "8 element(s) but the routine may access 9"),
    ("Function: Float4 pointer short by one float", lambda: vsum(np.ones(11, np.float32), 3), ArgumentError,
     "may access 12"),
    ("Function: fixed-length pointer too short", lambda: first8(np.ones(7, np.float32)), ArgumentError,
     "may access 8"),
    ("Function: empty array for a pointer of unchecked length", lambda: head(np.zeros(0, np.float32)),
     ArgumentError, "0 element(s) but the routine may access 1"),
    ("Function: huge n with a small array", lambda: total(np.ones(4, np.float32), 2**31 - 1), ArgumentError,
     "may access 2147483647"),
    ("Function: read-only array for a pointer it stores to", lambda: scale(_ro(np.ones(4, np.float32)), 4, 2.0),
     ArgumentError, "read-only, but the routine stores to it"),
    ("Function: too few arguments", lambda: total(np.ones(4, np.float32)), ArityError, "takes 2 argument(s)"),
    ("Function: too many arguments", lambda: total(np.ones(4, np.float32), 4, 4), ArityError,
     "takes 2 argument(s)"),
    ("Function: Int argument out of range", lambda: scale(np.ones(4, np.float32), 2**31, 1.0), ArgumentError,
     "may access 2147483648"),
    ("Function: Int argument below its range", lambda: total(np.ones(4, np.float32), -2**31 - 1), ArgumentError,
     "out of range for Int"),
    ("Function: float for an Int argument", lambda: total(np.ones(4, np.float32), 4.0), ArgumentError,
     "must be an int"),
    ("Function: string for the Int that sizes a pointer", lambda: total(np.ones(4, np.float32), "x"),
     ArgumentError, "must be an int"),
    ("Function: None for an Int argument", lambda: total(np.ones(4, np.float32), None), ArgumentError,
     "must be an int"),
    ("Function: bool for an Int argument", lambda: total(np.ones(4, np.float32), True), ArgumentError,
     "must be an int"),
    ("Function: string for a Float argument", lambda: scale(np.ones(4, np.float32), 4, "2"), ArgumentError,
     "must be a number"),
    ("Function: vector argument of the wrong length", lambda: lane_sum(np.zeros(3, np.float32), 0),
     ArgumentError, "Float4"),
    ("Function: vector argument of the wrong dtype", lambda: lane_sum(np.zeros(4), 0), ArgumentError, "Float4"),
]

HOSTILE_CASES = len(RIGHT) + len(RAISES)


@pytest.mark.parametrize("name, thunk", RIGHT, ids=[r[0] for r in RIGHT])
def test_right_answer(name, thunk):
    with np.errstate(all="ignore"):
        got, want = thunk()
    got = np.asarray(got)
    want = np.asarray(want, got.dtype)
    assert got.shape == want.shape, (got.shape, want.shape)
    if got.dtype.kind == "f":  # bit for bit, NaNs alike
        bits = {2: np.uint16, 4: np.uint32, 8: np.uint64}[got.dtype.itemsize]
        same = np.ascontiguousarray(got).view(bits) == np.ascontiguousarray(want).view(bits)
        assert np.all(same | (np.isnan(got) & np.isnan(want))), (got, want)
    else:
        assert np.array_equal(got, want), (got, want)


@pytest.mark.parametrize("name, thunk, exc, words", RAISES, ids=[r[0] for r in RAISES])
def test_clear_exception(name, thunk, exc, words):
    with pytest.raises(exc) as info:
        thunk()
    assert words in str(info.value), str(info.value)


def test_case_count():
    assert HOSTILE_CASES >= 70


def test_guard_pages_around_every_operand():
    """Kernels at widths 1/4/8/16 on host, avx2 and sse4 code, lengths 0..70, contiguous,
    reversed, strided and broadcast layouts, and routines with vector loads and stores:
    every operand sits against a PROT_NONE page with canaries on its other side. Run in a
    subprocess: a stray access would kill it (a failure here, not the end of the run)."""
    script = os.path.join(HERE, "guard_pages.py")
    env = dict(os.environ, PYTHONPATH=ROOT)
    out = subprocess.run([sys.executable, script], capture_output=True, text=True, env=env, timeout=300)
    assert out.returncode == 0, f"exit {out.returncode}\n{out.stdout}\n{out.stderr}"
    assert out.stdout.startswith("ok "), out.stdout
    assert int(out.stdout.split()[1]) > 5000
    # and the guard does catch a stray write
    bad = subprocess.run([sys.executable, script, "--selftest"], capture_output=True, text=True, env=env,
                         timeout=60)
    assert bad.returncode != 0 and "not reached" not in bad.stdout
