"""float64 and 32/64-bit integer data given to a float32 kernel: one TypeError that names the
argument, its dtype and the two ways on (NumPy's own message names neither); what NumPy casts
safely (int16, a Python float beside a float32 array) runs as before."""
import numpy as np
import pytest

import routines
from reactor import Float, kernel

X = np.linspace(0, 2, 7, dtype=np.float32)


@pytest.mark.parametrize("arg, dtype", [(np.arange(5), "int64"), (np.arange(5, dtype=np.int32), "int32"),
                                        (np.linspace(0, 1, 5), "float64"), (3, "int64"), (2.5, "float64"),
                                        (np.float64(2.2), "float64"), ([1.0, 2.0], "float64")])
def test_a_wide_argument_is_one_clear_type_error(arg, dtype):
    exp2 = routines.jit("exp2")
    with pytest.raises(TypeError, match=rf"'exp2_full\w*' computes in float32, and its argument 'x' is {dtype}.*"
                                        r"astype\(np.float32\).*dtype=np.float32, casting='same_kind'"):
        exp2(arg)


def test_each_argument_is_named_and_the_ways_on_work():
    @kernel(cache=False)
    def blend(a: Float, b: Float) -> Float:
        return a * 0.25 + b

    with pytest.raises(TypeError, match="argument 'b' is float64"):
        blend(X, X.astype(np.float64))
    with pytest.raises(TypeError, match="argument 'a' is int64 .* and 'b' is float64"):
        blend(np.arange(7), X.astype(np.float64))
    want = blend(X, X)
    assert np.array_equal(blend(X, X.astype(np.float64), dtype=np.float32, casting="same_kind"), want)
    assert np.array_equal(blend(X, X.astype(np.float64), signature="ff->f", casting="same_kind"), want)
    assert np.array_equal(blend(X.astype(np.float64).astype(np.float32), X), want)
    assert np.array_equal(blend(np.arange(7, dtype=np.int16), X), blend(np.arange(7, dtype=np.float32), X))
    assert np.array_equal(blend(X, 2.0), X * np.float32(0.25) + np.float32(2.0))  # a Python float beside float32
    assert blend.types[0] == "ff->f"  # the kernel's own loop comes first


def test_pows_float64_exponent_and_mgrids_int64_grid_are_named():
    pow_ = routines.jit("pow")
    with pytest.raises(TypeError, match=r"argument 'y' is float64 .*astype\(np.float32\)"):
        pow_(X, np.float64(2.2))
    assert np.array_equal(pow_(X, np.float32(2.2)), pow_(X, 2.2))  # a Python float beside float32 is float32

    from reactor import vec2

    @kernel(cache=False)
    def shade(uv: vec2) -> Float:
        return uv.x * 0.5 + uv.y

    grid = np.stack(np.mgrid[0:4, 0:3], axis=-1)
    with pytest.raises(TypeError, match=r"argument 'uv' is int64 .*astype\(np.float32\)"):
        shade(grid)
    assert np.array_equal(shade(grid.astype(np.float32)), grid[..., 0] * 0.5 + grid[..., 1])


def test_a_float64_dask_array_is_named_by_map_blocks():
    da = pytest.importorskip("dask.array")
    import reactor
    exp2 = routines.jit("exp2")
    lazy = da.from_array(np.linspace(0, 1, 8), chunks=4)
    with pytest.raises(TypeError, match=r"argument 'x' of 'exp2_full\w*' is float64.*astype\(np.float32\)"):
        reactor.map_blocks(exp2, lazy)
    assert np.array_equal(exp2(lazy.astype(np.float32)).compute(), exp2(np.linspace(0, 1, 8).astype(np.float32)))
