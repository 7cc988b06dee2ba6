"""Functions and routines: typed arguments, calling from Python, build options."""
import numpy as np
import pytest

import reactor
from reactor import (
    ArgumentError, ArityError, Bool, Double, Float, Float4, Float8, For, Function, Int,
    Module, Pointer, SIMD, UInt, function,
)

from dsl_helpers import assert_bits_equal


def test_scalar_arguments_and_results():
    @function
    def mix(f: Float, d: Double, i: Int, u: UInt, b: Bool) -> Double:
        return Double(f) + d + Double(Float(i)) + Double(Float(u)) * Double(Float(Int(b)))

    assert mix(1.5, 0.25, -3, 7, True) == 1.5 + 0.25 - 3 + 7
    assert mix(np.float32(1.5), np.float64(0.25), np.int32(-3), np.uint32(7), np.bool_(False)) == -1.25
    assert mix(1, 0, 0, 0, False) == 1.0  # ints are numbers, too

    @function
    def neg(b: Bool) -> Bool:
        return ~b

    assert neg(True) is False and neg(False) is True

    @function
    def wrap(u: UInt) -> UInt:
        return u + 1

    assert wrap(2**32 - 1) == 0
    assert isinstance(wrap(5), int)


def test_pointer_arguments():
    @function
    def axpy(a: Float, x: Pointer[Float, "n"], y: Pointer[Float, "n"], n: Int):
        with For(0, n) as i:
            y[i] = a * x[i] + y[i]

    x = np.arange(10, dtype=np.float32)
    y = np.ones(10, np.float32)
    axpy(2.0, x, y, 10)
    assert_bits_equal(y, 2 * x + 1)
    axpy(2.0, x, y, 0)
    axpy(2.0, np.zeros(0, np.float32), np.zeros(0, np.float32), 0)  # n = 0: empty arrays are fine
    assert_bits_equal(y, 2 * x + 1)

    @function
    def fixed(p: Pointer[Int, 3]) -> Int:
        return p[0] + p[1] + p[2]

    assert fixed(np.array([1, 2, 3], np.int32)) == 6
    with pytest.raises(ArgumentError, match="2 element"):
        fixed(np.array([1, 2], np.int32))

    @function
    def vec(p: Pointer[Float4, "n"], n: Int, out: Pointer[Float4]):
        acc = reactor.Variable(Float4, 0.0)
        with For(0, n) as i:
            acc += p[i]
        out[0] = acc

    p = np.arange(12, dtype=np.float32)
    out = np.zeros(4, np.float32)
    vec(p, 3, out)
    assert_bits_equal(out, p.reshape(3, 4).sum(axis=0))
    with pytest.raises(ArgumentError, match="may access 16"):
        vec(p, 4, out)  # 4 Float4 = 16 floats, the array has 12

    @function
    def flags(p: Pointer[Bool, "n"], n: Int) -> Int:
        c = reactor.Variable(Int, 0)
        with For(0, n) as i:
            c += Int(p[i])
            p[i] = ~p[i]
        return c

    b = np.array([True, False, True, True])
    assert flags(b, 4) == 3
    assert b.tolist() == [False, True, False, False]


def test_scalar_and_vector_loads_from_scalar_pointer():
    @function
    def f(p: Pointer[Float, "n"], n: Int, out: Pointer[Float, "n"]):
        with For(0, n / 8) as i:
            v = p.load(i * 8, 8)          # 8 consecutive floats, unaligned
            out.store(i * 8, v * 2.0)

    p = np.arange(24, dtype=np.float32)
    out = np.zeros(24, np.float32)
    f(p, 24, out)
    assert_bits_equal(out, p * 2)


def test_argument_checks():
    @function
    def f(p: Pointer[Float, "n"], n: Int, v: Float4) -> Float:
        return p[0] + reactor.Extract(v, 0)

    p, v = np.ones(4, np.float32), np.zeros(4, np.float32)
    assert f(p, 4, v) == 1.0
    with pytest.raises(ArityError, match="takes 3 argument"):
        f(p, 4)
    with pytest.raises(ArgumentError, match="dtype float32, not float64"):
        f(np.ones(4), 4, v)
    with pytest.raises(ArgumentError, match="4 element.*may access 5"):
        f(p, 5, v)
    with pytest.raises(ArgumentError, match="C-contiguous"):
        f(np.ones(8, np.float32)[::2], 4, v)
    with pytest.raises(ArgumentError, match="NumPy array"):
        f([1.0, 2.0], 2, v)
    with pytest.raises(ArgumentError, match="Float4"):
        f(p, 4, np.zeros(3, np.float32))
    with pytest.raises(ArgumentError, match="Float4"):
        f(p, 4, np.zeros(4, np.float64))
    with pytest.raises(ArgumentError, match="may access 2147483648"):
        f(p, 2**31, v)

    @function
    def g(x: Float, b: Bool, i: Int = 0, u: UInt = 0) -> Float:
        return x

    assert g(1.0, True, -(2**31), 2**32 - 1) == 1.0
    with pytest.raises(ArgumentError, match=r"out of range for Int \[-2147483648, 2147483647\]"):
        g(1.0, True, 2**31, 0)
    with pytest.raises(ArgumentError, match="out of range for UInt"):
        g(1.0, True, 0, -1)
    with pytest.raises(ArgumentError, match="must be an int"):
        g(1.0, True, 2.0, 0)
    with pytest.raises(ArgumentError, match="must be an int"):
        g(1.0, True, True, 0)

    with pytest.raises(ArgumentError, match="must be a number"):
        g("1.0", True, 0, 0)
    with pytest.raises(ArgumentError, match="must be a bool"):
        g(1.0, 1, 0, 0)
    assert g(np.array(2.5), np.bool_(True), np.int32(1), np.uint32(1)) == 2.5  # 0-d arrays are scalars


@pytest.mark.parametrize("width", [4, 8, 16])
def test_width_generic_function(width):
    @function
    def lerp(a: SIMD.Float, b: SIMD.Float, t: Float) -> SIMD.Float:
        assert SIMD.width == width
        return a + (b - a) * t + SIMD.Float(0.0)

    r = lerp.compile(width=width)
    assert r.build.width == width
    a = np.arange(width, dtype=np.float32)
    assert_bits_equal(r(a, a + 4, 0.5), a + np.float32(2))
    with reactor.options(width=width):
        assert lerp.compile() is r  # compiled once per set of options


def test_default_width_is_host_natural_width():
    from reactor import get_target

    @function
    def f(x: SIMD.Float) -> SIMD.Float:
        return x

    r = f.compile()
    assert r.build.width == get_target("host").natural_width
    assert r(np.zeros(r.build.width, np.float32)).shape == (r.build.width,)


def test_function_options_and_context():
    def body(x: Float) -> Float:
        return reactor.MulAdd(x, x, 1.0)

    f = Function(body, fma=False)
    r = f.compile()
    assert r.build.fma is False and r.build.opt == 3
    with reactor.options(opt=0, fma=True):
        r0 = f.compile()
    assert r0.build.opt == 0          # the context's opt applies ...
    assert r0.build.fma is False      # ... but the function's own fma wins
    assert f.compile(fma=True).build.fma is True  # an explicit argument wins over both
    assert "llvm.fma" not in r0.ir and "llvm.fma" in f.compile(fma=True).ir
    with pytest.raises(reactor.ReactorError, match="unknown build option"):
        Function(body, fast=True)
    with pytest.raises(reactor.ReactorError, match="width must be"):
        f.compile(width=3)
    with pytest.raises(reactor.ReactorError, match="optimization level"):
        f.compile(opt=4)


def test_explicit_signature_and_name():
    def body(a, b):
        return a * b

    f = Function(body, args=[Int, Int], returns=Int, name="times")
    assert f.name == "times" and f(6, 7) == 42
    assert 'define i32 @"times"' in f.compile().ir


def test_library_and_module_errors():
    mod = Module()

    @mod.function
    def one() -> Int:
        return Int(1)

    lib = mod.compile()
    assert lib.one() == 1 and lib.one.name == "one"
    with pytest.raises(AttributeError):
        lib.two
    dup = Module([one, Function(lambda: Int(2), returns=Int, name="one")])
    with pytest.raises(reactor.ReactorError, match="several functions named one"):
        dup.compile()


def test_routine_inspection():
    @function
    def f(x: Float8, y: Float8) -> Float8:
        return x * y + 1.0

    r = f.compile(target="avx2", fma=False)
    assert 'define <8 x float> @"f"' in r.ir
    assert "fmul <8 x float>" in r.optimized_ir
    assert "vmulps" in r.assembly and "ymm" in r.assembly
    assert isinstance(r.address, int) and r.address != 0
