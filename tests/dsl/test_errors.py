"""Every user error is a ReactorError subclass naming the problem and the user's
file:line; nothing a user writes crashes the process."""
import os

import numpy as np
import pytest

import reactor
from reactor import (
    Any, ArgumentError, ArityError, ControlFlowError, DSLTypeError, Elif, Else, Float,
    Float4, Float8, Fma, FmaDisabledError, For, Function, If, Int, MissingReturnError, Pointer,
    ReactorError, Return, ScopeError, ToInt, UInt, Variable, WidthMismatchError, While, kernel,
)

from dsl_helpers import assert_bits_equal


def here(marker: str) -> int:
    """Line number in this file of the (unique) line ending with ``# <marker>``."""
    lines = open(__file__).read().splitlines()
    hits = [k + 1 for k, line in enumerate(lines) if line.rstrip().endswith(f"# {marker}")]
    assert len(hits) == 1, (marker, hits)
    return hits[0]


def check(excinfo, cls, marker: str, *words):
    exc = excinfo.value
    assert type(exc) is cls, type(exc)
    assert isinstance(exc, ReactorError)
    line = here(marker)
    assert exc.location == (__file__, line), (exc.location, line)
    text = str(exc)
    assert f"{os.path.basename(__file__)}:{line}" in text, text
    for word in words:
        assert word in text, (word, text)


# -- item 9 ---------------------------------------------------------------------------

def test_type_mismatch():
    def f(x: Float, i: Int) -> Float:
        return x + i  # E-type

    with pytest.raises(DSLTypeError) as e:
        Function(f).compile()
    check(e, DSLTypeError, "E-type", "operator '+'", "Float and Int")
    assert isinstance(e.value, TypeError)  # also a Python TypeError


def test_width_mismatch():
    def f(x: Float4, y: Float8) -> Float4:
        return reactor.Min(x, y)  # E-width

    with pytest.raises(WidthMismatchError) as e:
        Function(f).compile()
    check(e, WidthMismatchError, "E-width", "Min", "Float4 and Float8")


def test_return_type_mismatch():
    def f(x: Float) -> Float4:
        Return(Float8(x))  # E-return

    with pytest.raises(DSLTypeError) as e:
        Function(f).compile()
    check(e, DSLTypeError, "E-return", "Float8", "returns Float4")


def test_value_used_outside_its_function():
    leaked = []

    def g(x: Float) -> Float:
        leaked.append(x * 2.0)
        return x

    def h(x: Float) -> Float:
        return leaked[0] + x  # E-scope-fn

    Function(g).compile()
    with pytest.raises(ScopeError) as e:
        Function(h).compile()
    check(e, ScopeError, "E-scope-fn", "function 'g'", "'h'")
    with pytest.raises(ScopeError) as e:
        leaked[0] + 1.0  # E-scope-none
    check(e, ScopeError, "E-scope-none", "outside a function being built")


def test_value_used_after_its_block():
    def f(x: Float) -> Float:
        with If(x > 0.0):
            y = x * 2.0
        return y  # E-scope-block

    with pytest.raises(DSLTypeError) as e:  # caught at its use, naming the name (Python as written)
        Function(f).compile()
    check(e, DSLTypeError, "E-scope-block", "'y' is assigned on some paths", "give it a value before")

    def g(n: Int) -> Int:
        with For(0, n) as i:
            pass
        return i + 1  # E-scope-counter

    with pytest.raises(ScopeError) as e:
        Function(g).compile()
    check(e, ScopeError, "E-scope-counter", "'For' block")


def test_value_from_an_elif_condition_used_after_the_chain():
    def f(x: Float) -> Float:
        r = Variable(Float, 0.0)
        with If(x < 0.0):
            r.set(1.0)
        big = x > 10.0                 # evaluated only on the path that reaches the Elif
        with Elif(big):
            r.set(2.0)
        return reactor.Select(big, r, 0.0)  # E-chain-value

    with pytest.raises(ScopeError) as e:
        Function(f).compile()
    check(e, ScopeError, "E-chain-value", "between the blocks of an If/Elif chain")

    def g(x: Float) -> Float:
        with If(x < 0.0):
            pass
        v = Variable(Float, 5.0)
        with Elif(x > v):
            v.set(1.0)
        return v + 1.0  # E-chain-var

    with pytest.raises(ScopeError) as e:
        Function(g).compile()
    check(e, ScopeError, "E-chain-var", "Variable 'var' was created between the blocks")


def test_missing_return():
    def f(x: Float) -> Float:  # E-missing
        with If(x > 0.0):
            Return(x)

    with pytest.raises(MissingReturnError) as e:
        Function(f).compile()
    check(e, MissingReturnError, "E-missing", "'f' returns Float", "without Return")
    assert isinstance(e.value, ControlFlowError)


def test_wrong_argument_count():
    def add(x: Float, y: Float) -> Float:
        return x + y

    g = Function(add)

    def caller(x: Float) -> Float:
        return g(x)  # E-arity-dsl

    with pytest.raises(ArityError) as e:
        Function(caller).compile()
    check(e, ArityError, "E-arity-dsl", "'add' takes 2 argument(s), got 1")
    with pytest.raises(ArityError) as e:
        g(1.0, 2.0, 3.0)  # E-arity-py
    check(e, ArityError, "E-arity-py", "routine 'add' takes 2 argument(s) (x, y), got 3")


def test_wrong_dtype_and_size():
    def total(p: Pointer[Float, "n"], n: Int) -> Float:
        acc = Variable(Float, 0.0)
        with For(0, n) as i:
            acc += p[i]
        return acc

    f = Function(total)
    with pytest.raises(ArgumentError) as e:
        f(np.zeros(4, np.float64), 4)  # E-dtype
    check(e, ArgumentError, "E-dtype", "argument 'p'", "dtype float32, not float64")
    with pytest.raises(ArgumentError) as e:
        f(np.zeros(4, np.float32), 5)  # E-short
    check(e, ArgumentError, "E-short", "4 element(s)", "may access 5")


# -- further misuse ------------------------------------------------------------------------

def test_control_flow_misuse():
    def orphan(x: Float) -> Float:
        with Else():  # E-orphan
            pass
        return x

    with pytest.raises(ControlFlowError) as e:
        Function(orphan).compile()
    check(e, ControlFlowError, "E-orphan", "Else must directly follow an If")

    def python_bool(x: Float) -> Float:
        with If(True):  # E-pybool
            pass
        return x

    with pytest.raises(DSLTypeError) as e:
        Function(python_bool).compile()
    check(e, DSLTypeError, "E-pybool", "Python bool")

    def vector_cond(x: Float4) -> Float4:
        y = Variable(Float, 0.0)
        with If(x > 0.0):
            y.set(1.0)  # E-mask
        return x

    with pytest.raises(ControlFlowError) as e:
        Function(vector_cond).compile()
    check(e, ControlFlowError, "E-mask", "per-lane condition of 4 lanes", "Variable(Float4")

    def truthiness(x: Float) -> Float:
        # Python's max asks for the truth of a mask
        return max(x, 0.0)  # E-truth

    with pytest.raises(DSLTypeError) as e:
        Function(truthiness).compile()
    check(e, DSLTypeError, "E-truth", "no Python truth value")

    def while_value(x: Int) -> Int:
        with While(x < 3):  # E-while
            pass
        return x

    with pytest.raises(DSLTypeError) as e:
        Function(while_value).compile()
    check(e, DSLTypeError, "E-while", "lambda")


def test_return_in_kernel_body_counts_its_results():
    def body(x: Float) -> (Float, Float):
        with If(x < 0.0):
            Return(x)  # E-kernel-return
        return x, x

    with pytest.raises(DSLTypeError) as e:
        kernel(body)
    check(e, DSLTypeError, "E-kernel-return", "Return of 1 value(s)", "gives 2")


def test_kernel_signature_errors():
    def two(x: Float) -> (Float, Float):
        return x  # E-kernel-outs

    with pytest.raises(DSLTypeError) as e:
        kernel(two)
    check(e, DSLTypeError, "E-kernel-outs", "returned 1 value(s)", "2 output(s)")

    def wrong_kind(x: Float) -> Int:
        if x.width > 1:
            pass
        return x * 2.0  # E-kernel-kind

    with pytest.raises(DSLTypeError) as e:
        kernel(wrong_kind)
    check(e, DSLTypeError, "E-kernel-kind", "expected Int", "got Float")

    def ptr(p: Pointer[Float]) -> Float:
        return p[0]

    with pytest.raises(DSLTypeError, match="scalar element type"):
        kernel(ptr)

    def noann(x):
        return x

    with pytest.raises(DSLTypeError, match="need a type annotation"):
        kernel(noann)


def test_fma_disabled():
    def f(x: Float) -> Float:
        return Fma(x, x, 1.0)  # E-fma

    with pytest.raises(FmaDisabledError) as e:
        Function(f, fma=False).compile()
    check(e, FmaDisabledError, "E-fma", "fma=False", "MulAdd")
    assert Function(f, fma=True)(3.0) == 10.0


def test_bad_operands():
    def f(x: Float) -> Float:
        return x + "one"  # E-operand

    with pytest.raises(DSLTypeError) as e:
        Function(f).compile()
    check(e, DSLTypeError, "E-operand", "str")

    def g(i: Int) -> Int:
        return i + 2**40  # E-bigint

    with pytest.raises(DSLTypeError) as e:
        Function(g).compile()
    check(e, DSLTypeError, "E-bigint", "does not fit in 32 bits")

    def h(x: Float) -> Float:
        return x << 2  # E-rem

    with pytest.raises(DSLTypeError) as e:
        Function(h).compile()
    check(e, DSLTypeError, "E-rem", "not defined for Float")

    def k(x: Float4) -> Float:
        return reactor.Extract(x, 4)  # E-lane

    with pytest.raises(DSLTypeError) as e:
        Function(k).compile()
    check(e, DSLTypeError, "E-lane", "lane index 4 out of range")


# -- never a crash -----------------------------------------------------------------------

def test_integer_division_is_total():
    def div(a: Int, b: Int, out: Pointer[Int, 2]):
        out[0] = a / b
        out[1] = a % b

    def udiv(a: UInt, b: UInt, out: Pointer[UInt, 2]):
        out[0] = a / b
        out[1] = a % b

    f, g = Function(div, opt=0), Function(udiv)  # opt=0: the division really executes
    out = np.zeros(2, np.int32)
    for a, b, q, r in [(7, 0, 0, 0), (-(2**31), -1, -(2**31), 0), (-(2**31), 0, 0, 0), (-7, 2, -3, -1)]:
        f(a, b, out)
        assert out.tolist() == [q, r]
    uout = np.zeros(2, np.uint32)
    g(5, 0, uout)
    assert uout.tolist() == [0, 0]


def test_shift_counts_wrap_and_conversions_saturate():
    def sh(a: Int, n: Int) -> Int:
        return (a << n) ^ (a >> n)

    f = Function(sh)
    assert f(1, 32) == (1 ^ 1) and f(1, 33) == (2 ^ 0) and f(-8, 65) == ((-16) ^ (-4))

    def conv(x: Float) -> Int:
        return Int(x)

    c = Function(conv)
    assert [c(v) for v in (float("nan"), float("inf"), -float("inf"), 1e30, -1e30, -2.5)] == \
        [0, 2**31 - 1, -(2**31), 2**31 - 1, -(2**31), -2]

    def uconv(x: Float) -> UInt:
        return ToInt(x, "nearest", unsigned=True)

    u = Function(uconv)
    assert [u(v) for v in (float("nan"), -5.0, 1e30, 2.5)] == [0, 0, 2**32 - 1, 2]

    @kernel
    def kconv(x: Float) -> Int:
        return reactor.SIMD.Int(x)

    x = np.array([np.nan, np.inf, -np.inf, 3e9, -3e9, 1.9] * 6, np.float32)
    with np.errstate(invalid="ignore"):
        assert_bits_equal(kconv(x), np.array([0, 2**31 - 1, -(2**31), 2**31 - 1, -(2**31), 1] * 6, np.int32))
