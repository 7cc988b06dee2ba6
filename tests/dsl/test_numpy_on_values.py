"""NumPy's functions on DSL values in a kernel body: the GLSL built-in of the same meaning
(``np.sin`` is ``sin``, ``np.clip`` is ``clamp``, per component on vectors), the same bits as
``routines.glsl``; anything else one clear error saying what to write."""
import numpy as np
import pytest

import routines  # noqa: F401 - installs the GLSL built-ins
from reactor import DSLTypeError, Float, kernel, vec3
from routines import glsl as gl

X = np.linspace(-3, 3, 37, dtype=np.float32)


def test_numpy_functions_are_the_glsl_built_ins():
    @kernel(cache=False)
    def with_numpy(x: Float) -> vec3:
        v = vec3(x, x * 0.5, np.abs(x))
        s = np.exp2(x) * np.clip(x, 0.0, 1.0) + np.arctan2(x, 2.0) + np.power(np.abs(x), 2.2)
        return np.sin(v) + np.maximum(v, s)

    @kernel(cache=False)
    def with_glsl(x: Float) -> vec3:
        v = vec3(x, x * 0.5, gl.abs(x))
        s = gl.exp2(x) * gl.clamp(x, 0.0, 1.0) + gl.atan(x, 2.0) + gl.pow(gl.abs(x), 2.2)
        return gl.sin(v) + gl.max(v, s)

    assert np.array_equal(with_numpy(X), with_glsl(X))


@pytest.mark.parametrize("body, words", [
    (lambda x: np.where(x > 0.0, x, 0.0), "write reactor.Select"),
    (lambda x: np.cumsum(x), "np.cumsum on a DSL value .* NumPy's functions take arrays"),
    (lambda x: np.sin(x, dtype=np.float32), "np.sin .* NumPy's options .* use routines.glsl.sin"),
    (lambda x: np.add.reduce(x), "np.add.reduce on a DSL value"),
])
def test_what_has_no_glsl_meaning_says_what_to_write(body, words):
    with pytest.raises(DSLTypeError, match=words):
        kernel(body, args=[Float], returns=Float, cache=False)
