"""Variables and run-time control flow; build-time Python loops and ifs."""
import math

import numpy as np
import pytest

import reactor
from reactor import (
    Any, Elif, Else, Float, Float4, For, Function, If, Int, IsNan, Module, Pointer, Return, Select,
    UInt, Variable, While, function, kernel, vector_type,
)

from dsl_helpers import assert_bits_equal


def test_loop_carried_variables():
    @function
    def stats(p: Pointer[Float, "n"], n: Int, out: Pointer[Float, 3]):
        total = Variable(Float, 0.0, name="total")
        lo = Variable(Float, math.inf, name="lo")
        hi = Variable(p[0])  # type and initial value from a value
        with For(0, n) as i:
            x = p[i]
            total += x
            lo.set(reactor.Min(lo, x))
            with If(x > hi):
                hi.set(x)
        out[0], out[1], out[2] = total, lo, hi

    x = np.array([3, -1, 4, 1, -5, 9, 2, 6], np.float32)
    out = np.zeros(3, np.float32)
    stats(x, x.size, out)
    assert out.tolist() == [x.sum(), x.min(), x.max()]


def test_vector_accumulator_and_in_place_operators():
    @function
    def f(p: Pointer[Float4, "n"], n: Int) -> Float4:
        acc = Variable(Float4, 1.0)
        k = Variable(Int, 0)
        with For(0, n) as i:
            acc *= 2.0
            acc += p[i]
            acc -= 1.0
            acc /= 1.0
            k += 3
            k -= 1
            k *= 1
            k <<= 1
            k >>= 1
            k |= 0
            k &= -1
            k ^= 0
            k %= 1000
        return acc + Float4(k)  # Float4(Int) broadcasts after converting

    p = np.arange(12, dtype=np.float32)
    acc = np.ones(4, np.float32)
    for row in p.reshape(3, 4):
        acc = acc * 2 + row - 1
    assert_bits_equal(f(p, 3), acc + 6)


def test_while_loop_and_bool_variable():
    @function
    def collatz(x: Int) -> Int:
        steps = Variable(Int, 0, name="steps")
        v = Variable(x, name="v")
        with While(lambda: v != 1):
            with If((v & 1) == 0):
                v.set(v >> 1)
            with Else():
                v.set(v * 3 + 1)
            steps += 1
        return steps

    @function
    def count_down(x: Int) -> Int:
        going = Variable(reactor.Bool, True)
        k = Variable(x)
        with While(going):  # a Bool Variable is re-read every iteration
            k -= 1
            going.set(k > 0)
        return k

    def py_collatz(x):
        n = 0
        while x != 1:
            x = x // 2 if x % 2 == 0 else 3 * x + 1
            n += 1
        return n

    assert [collatz(x) for x in (1, 6, 27, 97)] == [py_collatz(x) for x in (1, 6, 27, 97)]
    assert count_down(5) == 0


def test_for_variants():
    @function
    def sums(n: Int, out: Pointer[Int, 5]):
        s = Variable(Int, 0)
        with For(n) as i:          # 0 .. n-1
            s += i
        out[0] = s
        s.set(0)
        with For(n, 0, -2) as i:   # n, n-2, ... > 0
            s += i
        out[1] = s
        s.set(0)
        with For(3, n, 3) as i:
            s += i
        out[2] = s
        s.set(0)
        with For(5, 2) as i:       # empty
            s += 1
        out[3] = s
        s.set(0)
        with For(0, n) as i:       # nested, inner bound depends on the outer counter
            with For(0, i) as j:
                s += j
        out[4] = s

    out = np.zeros(5, np.int32)
    sums(10, out)
    assert out.tolist() == [45, 30, 3 + 6 + 9, 0, sum(j for i in range(10) for j in range(i))]

    @function
    def usum(n: UInt) -> UInt:
        s = Variable(UInt, 0)
        with For(UInt(0), n) as i:
            s += i
        return s

    assert usum(100) == 4950


def _py_for(start, stop, step):
    out, i = [], start
    while (i < stop if step > 0 else i > stop) and len(out) < 50:
        out.append(i)
        i += step
    return out


@pytest.mark.parametrize("kind,step,bounds", [
    ("UInt", -2, [(9, 0), (10, 0), (3, 1)]),            # 9, 7, ..., 1 must not wrap to 2**32 - 1
    ("UInt", 5, [(2**32 - 3, 2**32 - 1), (0, 12)]),
    ("UInt", 2**31, [(0, 2**32 - 1)]),
    ("Int", 8, [(2**31 - 5, 2**31 - 1), (-20, 0)]),      # must not wrap to INT_MIN
    ("Int", -4, [(-(2**31) + 3, -(2**31)), (5, -5)]),
    ("Int", 3, [(0, 9), (0, 10), (5, 5), (7, 3)]),
])
def test_for_never_wraps_around(kind, step, bounds):
    K = {"Int": Int, "UInt": UInt}[kind]

    def visit(a: K, b: K, out: Pointer[K, 50]) -> Int:
        c = Variable(Int, 0)
        with For(a, b, step) as i:
            with If(c >= 50):
                Return(-1)   # a wrapped-around loop would run (almost) forever
            out[c] = i
            c += 1
        return c

    f = Function(visit, name=f"visit_{kind}_{abs(step)}_{step < 0}")
    for start, stop in bounds:
        out = np.zeros(50, np.int32 if kind == "Int" else np.uint32)
        n = f(start, stop, out)
        assert out[:max(n, 0)].tolist() == _py_for(start, stop, step), (start, stop)


def test_nested_if_elif_else():
    @function
    def classify(x: Float) -> Int:
        r = Variable(Int, -1, name="r")
        with If(x < 0.0):
            with If(x < -10.0):
                r.set(0)
            with Else():
                r.set(1)
        with Elif(x < 1.0):
            with If(x < 0.5):
                r.set(2)
            with Elif(x < 0.75):
                r.set(3)
            with Else():
                r.set(4)
        with Elif(IsNan(x)):
            r.set(9)
        with Else():
            with If(x > 100.0):
                r.set(6)
            r.set(r + 6)
        return r

    cases = {-20.0: 0, -1.0: 1, 0.25: 2, 0.6: 3, 0.9: 4, float("nan"): 9, 5.0: 5, 500.0: 12}
    assert {x: classify(x) for x in cases} == cases


def test_elif_condition_is_evaluated_only_when_reached():
    @function
    def safe(p: Pointer[Float, "n"], n: Int, i: Int) -> Float:
        r = Variable(Float, -1.0)
        with If(i >= n):
            r.set(-2.0)
        inside = p[i] > 0.0          # belongs to the Elif: not evaluated when i >= n
        with Elif(inside):
            r.set(Select(inside, p[i], 0.0))
            with If(inside):
                r += 100.0
        with Else():
            r.set(Select(inside, Float(9.0), 3.0))
        return r

    p = np.array([1.5, -1.0], np.float32)
    assert [safe(p, 2, i) for i in (0, 1, 2)] == [101.5, 3.0, -2.0]


def test_if_without_else_keeps_value():
    @function
    def f(x: Float) -> Float:
        y = Variable(x)
        with If(x < 0.0):
            y.set(-x)
        return y * 10.0

    assert (f(-2.0), f(3.0)) == (20.0, 30.0)


def test_early_return():
    @function
    def find(p: Pointer[Float, "n"], n: Int, target: Float) -> Int:
        with For(0, n) as i:
            with If(p[i] == target):
                Return(i)
        return -1

    @function
    def sign(x: Float) -> Float:
        with If(x > 0.0):
            Return(1.0)
        with Elif(x < 0.0):
            Return(-1.0)
        with Else():
            Return(0.0)

    @function
    def fill(p: Pointer[Int, "n"], n: Int, stop: Int):  # void function, early Return()
        with For(0, n) as i:
            with If(i == stop):
                Return()
            p[i] = i + 1

    p = np.array([5, 7, 9, 7], np.float32)
    assert (find(p, 4, 7.0), find(p, 4, 1.0), find(p, 0, 5.0)) == (1, -1, -1)
    assert [sign(v) for v in (3.0, -2.0, 0.0)] == [1.0, -1.0, 0.0]
    q = np.zeros(6, np.int32)
    fill(q, 6, 3)
    assert q.tolist() == [1, 2, 3, 0, 0, 0]


def test_python_loops_and_ifs_run_at_build_time():
    def make(degree, horner):
        @function(name=f"poly{degree}_{horner}")
        def poly(x: Float) -> Float:
            if horner:                            # decided while building
                acc = Float(1.0)
                for k in range(degree):           # unrolled
                    acc = acc * x + float(k + 2)
                return acc
            return x * float(degree)
        return poly

    horner = make(3, True)
    assert horner(2.0) == ((1 * 2 + 2) * 2 + 3) * 2 + 4
    ir = horner.compile().ir
    assert "for.cond" not in ir and "br i1" not in ir     # no run-time loop or branch
    assert ir.count("fmul") == 3
    plain = make(3, False)
    assert plain(2.0) == 6.0 and plain.compile().ir.count("fmul") == 1


def test_functions_call_each_other_in_a_module():
    mod = Module()

    @mod.function
    def square(x: Float) -> Float:
        return x * x

    @mod.function
    def norm2(p: Pointer[Float4], n: Int) -> Float:
        s = Variable(Float, 0.0)
        with For(0, n) as i:
            v = p[i]
            for k in range(4):
                s += square(reactor.Extract(v, k))
        return s

    @mod.function
    def fact(n: Int) -> Int:  # recursion
        with If(n <= 1):
            Return(1)
        return n * fact(n - 1)

    lib = mod.compile()
    assert set(lib) == {"square", "norm2", "fact"}
    p = np.arange(8, dtype=np.float32)
    assert lib.norm2(p, 2) == float((p * p).sum())
    assert lib["square"](3.0) == 9.0
    assert lib.fact(10) == math.factorial(10)
    ir = lib.norm2.ir
    assert ir.count('define float @"square"') == 1  # one definition, shared by callers
    assert 'call float @"square"' in ir


def test_function_called_at_different_widths():
    @function
    def scale(x: reactor.SIMD.Float) -> reactor.SIMD.Float:
        return x * 3.0

    for width in (4, 8, 16):
        T = vector_type("Float", width)

        def twice(x: T) -> T:
            return scale(scale(x))

        f = Function(twice, width=width)
        x = np.arange(width, dtype=np.float32)
        assert_bits_equal(f(x), x * 9)


def test_variables_in_kernels_and_runtime_if():
    @kernel
    def soft_abs(x: Float) -> Float:
        y = Variable(x)
        with If(Any(x < 0.0)):       # a uniform branch around lane-wise work
            y.set(Select(x < 0.0, -x, x))
        return y

    for n in (1, 5, 17, 40):
        x = np.linspace(-3, 3, n).astype(np.float32)
        assert_bits_equal(soft_abs(x), np.abs(x))
        assert_bits_equal(soft_abs(x[::-1]), np.abs(x[::-1]))
