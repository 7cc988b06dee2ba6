"""Bool arguments follow NumPy in every path: any nonzero byte is True."""
import numpy as np
import pytest

from reactor import Bool, Float, Function, Int, Pointer, Select, Variable, kernel

BYTES = np.arange(256, dtype=np.uint8)
WANT = BYTES != 0  # NumPy: np.bool_ viewed from byte b is True iff b != 0


def test_kernel_reads_every_byte_as_numpy_does():
    @kernel(name="bool_to_int")
    def to_int(b: Bool) -> Int:
        return Select(b, 1, 0)

    got = to_int(BYTES.view(np.bool_))
    assert np.array_equal(got, WANT.astype(np.int32))
    assert np.array_equal(to_int(BYTES.view(np.bool_)[::3]), WANT[::3].astype(np.int32))  # strided blocks


def test_routine_scalar_argument_reads_every_byte():
    f = Function(lambda b: Select(b, 1.0, 0.0), args=[Bool], returns=Float, name="bool_arg")
    r = f.compile()
    for byte in range(256):
        arg = np.array([byte], np.uint8).view(np.bool_)[0]  # a np.bool_ backed by that byte
        assert r(arg) == float(WANT[byte])


@pytest.mark.parametrize("width", [4, 8, 16])
def test_routine_vector_argument_reads_every_byte(width):
    """A Bool4/8/16 argument from a bool array whose bytes are 0..255 (the path that read the low bit)."""
    import reactor
    BoolW, IntW = reactor.vector_type("Bool", width), reactor.vector_type("Int", width)
    r = Function(lambda b: Select(b, IntW(1), IntW(0)), args=[BoolW], returns=IntW,
                 name=f"bool{width}_arg").compile()
    for chunk in BYTES.reshape(-1, width):
        assert np.array_equal(r(chunk.view(np.bool_)), (chunk != 0).astype(np.int32))


@pytest.mark.parametrize("width", [1, 4, 8, 16])
def test_pointer_loads_read_every_byte(width):
    def body(p: Pointer[Bool, 256], out: Pointer[Int, 256]) -> None:
        from reactor import For
        with For(0, 256 // width) as i:
            v = Variable(p.load(i * width, width)) if width > 1 else Variable(p[i])
            if width > 1:
                out.store(i * width, Select(v, 1, 0))
            else:
                out[i] = Select(v, 1, 0)

    r = Function(body, name=f"bool_ptr_{width}").compile()
    out = np.zeros(256, np.int32)
    r(BYTES.view(np.bool_), out)
    assert np.array_equal(out, WANT.astype(np.int32))
