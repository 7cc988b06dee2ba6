"""The GLSL built-ins table: every function against NumPy float64, over scalars and vectors,
GLSL's broadcasting, the precision in scope, and the routines list on the kernel."""
import numpy as np
import pytest

import reactor
from reactor import DSLTypeError, Float, kernel, kernel_of, mat2, mat3, mat4, vec2, vec3, vec4
from routines import glsl as gl

ISSUE_NAMES = """abs sign floor ceil trunc round roundEven fract mod min max clamp mix step smoothstep length
distance dot cross normalize faceforward reflect refract inversesqrt sqrt exp exp2 log log2 pow sin cos tan
asin acos atan sinh cosh tanh lessThan lessThanEqual greaterThan greaterThanEqual equal notEqual any all not_
transpose determinant inverse matrixCompMult outerProduct""".split()


def test_the_table_has_every_builtin_glsl_names():
    assert set(ISSUE_NAMES) <= set(gl.BUILTINS)
    assert set(gl.__all__) == set(gl.BUILTINS)
    for name in ISSUE_NAMES:
        assert getattr(gl, name) is gl.BUILTINS[name]


def _data(n=203, lo=-3.0, hi=3.0, seed=5):
    return np.random.default_rng(seed).uniform(lo, hi, n).astype(np.float32)


def _round_away(x):
    return np.where(np.abs(x - np.trunc(x)) >= 0.5, np.trunc(x) + np.copysign(1, x), np.trunc(x))


UNARY = {  # name: (float64 reference, max relative error, domain)
    "abs": (np.abs, 0, None), "sign": (np.sign, 0, None), "floor": (np.floor, 0, None),
    "ceil": (np.ceil, 0, None), "trunc": (np.trunc, 0, None), "round": (_round_away, 0, None),
    "roundEven": (np.round, 0, None), "fract": (lambda x: x - np.floor(x), 1e-7, None),
    "radians": (np.radians, 2e-7, None), "degrees": (np.degrees, 2e-7, None),
    "sqrt": (np.sqrt, 2e-7, (0, 9)), "inversesqrt": (lambda x: 1 / np.sqrt(x), 4e-7, (0.01, 9)),
    "exp": (np.exp, 6e-7, None), "exp2": (np.exp2, 6e-7, None), "log": (np.log, 6e-7, (0.01, 9)),
    "log2": (np.log2, 6e-7, (0.01, 9)), "sin": (np.sin, 1e-6, None), "cos": (np.cos, 1e-6, None),
    "tan": (np.tan, 2e-6, (-1.4, 1.4)), "asin": (np.arcsin, 1e-6, (-1, 1)), "acos": (np.arccos, 1e-6, (-1, 1)),
    "atan": (np.arctan, 1e-6, None), "sinh": (np.sinh, 2e-6, None), "cosh": (np.cosh, 2e-6, None),
    "tanh": (np.tanh, 2e-6, None),
}


@pytest.mark.parametrize("name", sorted(UNARY))
def test_unary_builtins_on_scalars_and_vectors(name):
    ref, tol, domain = UNARY[name]
    fn = gl.BUILTINS[name]

    @kernel
    def f(x: Float) -> (Float, Float, Float):
        v = fn(vec3(x, x * 0.5, -x))
        return fn(x), v.y, v.z

    x = _data(lo=domain[0], hi=domain[1]) if domain else _data()
    for got, arg in zip(f(x), (x, x * np.float32(0.5), -x)):
        arg64 = arg.astype(np.float64)
        if domain:
            keep = (arg64 >= domain[0]) & (arg64 <= domain[1])
            got, arg64 = got[keep], arg64[keep]
        np.testing.assert_allclose(got, ref(arg64), rtol=tol, atol=1e-6 if tol else 0)


def test_binary_and_ternary_builtins_broadcast_scalars_against_vectors():
    @kernel
    def f(x: Float, y: Float) -> (Float, Float, Float, Float, Float, Float, Float, Float):
        v = vec2(x, y)
        return (gl.mod(v, 1.5).x, gl.min(v, 0.25).y, gl.max(0.5, v).x, gl.clamp(v, -1.0, 1.0).y,
                gl.mix(v, vec2(1.0, 2.0), 0.25).y, gl.step(0.5, v).x, gl.smoothstep(-1.0, 2.0, v).y,
                gl.pow(gl.abs(v), vec2(2.5, 0.5)).y)

    x, y = _data(), _data(seed=6)
    got = f(x, y)
    x64, y64 = x.astype(np.float64), y.astype(np.float64)
    t = np.clip((y64 + 1) / 3, 0, 1)
    want = [x64 - 1.5 * np.floor(x64 / 1.5), np.minimum(y64, 0.25), np.maximum(x64, 0.5), np.clip(y64, -1, 1),
            y64 * 0.75 + 2 * 0.25, (x64 >= 0.5).astype(float), t * t * (3 - 2 * t), np.sqrt(np.abs(y64))]
    for g, w in zip(got, want):
        np.testing.assert_allclose(g, w, rtol=1e-6, atol=2e-7)


def test_geometric_builtins():
    @kernel
    def f(x: Float, y: Float, z: Float) -> (Float, Float, Float, Float, Float, Float, Float):
        a, b = vec3(x, y, z), vec3(z, x, 1.0)
        n = gl.normalize(b)
        return (gl.dot(a, b), gl.length(a), gl.distance(a, b), gl.cross(a, b).y, n.x,
                gl.reflect(a, n).z, gl.refract(gl.normalize(a), n, 0.8).x)

    x, y, z = _data(), _data(seed=7), _data(seed=8)
    A = np.stack([x, y, z]).astype(np.float64)
    B = np.stack([z, x, np.ones_like(x)]).astype(np.float64)
    N = B / np.linalg.norm(B, axis=0)
    I = A / np.linalg.norm(A, axis=0)
    d = (N * I).sum(0)
    k = 1 - 0.64 * (1 - d * d)
    refr = np.where(k < 0, 0, 0.8 * I - (0.8 * d + np.sqrt(np.maximum(k, 0))) * N)
    want = [(A * B).sum(0), np.linalg.norm(A, axis=0), np.linalg.norm(A - B, axis=0), np.cross(A.T, B.T).T[1],
            N[0], (A - 2 * (N * A).sum(0) * N)[2], refr[0]]
    for g, w in zip(f(x, y, z), want):
        np.testing.assert_allclose(g, w, rtol=3e-6, atol=3e-6)


def test_faceforward_and_relational_builtins():
    @kernel
    def f(x: Float, y: Float) -> (Float, Float, Float, Float):
        a, b = vec2(x, y), vec2(y, x)
        lt, eq = gl.lessThan(a, b), gl.equal(a, vec2(x))
        ff = gl.faceforward(vec2(1.0, 2.0), a, b)
        return (reactor.Select(gl.any(lt), 1.0, 0.0), reactor.Select(gl.all(eq), 1.0, 0.0),
                reactor.Select(gl.not_(gl.greaterThanEqual(a, b)).x, 1.0, 0.0), ff.y)

    x, y = _data(), _data(seed=9)
    y[::7] = x[::7]
    any_lt, all_eq, not_ge, ff = f(x, y)
    np.testing.assert_array_equal(any_lt, (x != y).astype(np.float32))
    np.testing.assert_array_equal(all_eq, (x == y).astype(np.float32))
    np.testing.assert_array_equal(not_ge, (x < y).astype(np.float32))
    np.testing.assert_array_equal(ff, np.where(2 * x * y < 0, 2, -2).astype(np.float32))


@pytest.mark.parametrize("mat, n", [(mat2, 2), (mat3, 3), (mat4, 4)])
def test_matrix_builtins(mat, n):
    vec = {2: vec2, 3: vec3, 4: vec4}[n]

    @kernel
    def f(x: Float) -> (Float, Float, Float, Float):
        cols = [vec(*[x * float(i + 1) + (3.0 if i == j else 0.5 * j) for i in range(n)]) for j in range(n)]
        m = mat(*cols)
        inv = gl.inverse(m)
        prod = m @ inv  # the identity
        return (gl.determinant(m), prod[n - 1][n - 1], gl.transpose(m)[0][n - 1],
                gl.matrixCompMult(m, m)[1][0] + gl.outerProduct(cols[0], cols[1])[1][0])

    x = _data(31, -1, 1)
    for k, xv in enumerate(x):
        M = np.array([[xv * (i + 1) + (3.0 if i == j else 0.5 * j) for i in range(n)] for j in range(n)]).T
        det, ident, tr, extra = (a[k] for a in f(x))
        np.testing.assert_allclose(det, np.linalg.det(M), rtol=2e-5, atol=1e-4)
        np.testing.assert_allclose(ident, 1.0, atol=1e-4)
        assert tr == np.float32(M[0, n - 1])  # transpose(m)[0] is m's first row
        np.testing.assert_allclose(extra, M[0, 1] ** 2 + M[0, 0] * M[1, 1], rtol=1e-6)  # column 1, row 0


def test_fract_is_glsl_fract():
    @kernel
    def f(x: Float) -> Float:
        return gl.fract(x)

    x = np.array([-1e-9, -0.25, 2.75, -3.0, np.inf, 0.0, -0.0], np.float32)
    got = f(x)
    np.testing.assert_array_equal(got[:4], [1.0, 0.75, 0.75, 0.0])
    assert np.isnan(got[4]) and got[5] == 0 and got[6] == 0


def test_precision_in_scope_with_per_call_override_and_the_routines_list():
    @kernel(precision="mediump")  # GLSL's name for relaxed
    def f(x: Float) -> Float:
        a = gl.sin(x)  # relaxed: the kernel's precision
        with reactor.precision("highp"):
            b = gl.exp2(x)  # full, in the block
            c = gl.log2(gl.abs(x) + 1.0, precision="relaxed")  # per call
        return a + b + c + x ** 0.5 * 0.0 + gl.normalize(vec2(x, 1.0)).y

    calls = [(c.name, c.precision) for c in kernel_of(f).routines]
    assert calls == [("sin", "relaxed"), ("exp2", "full"), ("log2", "relaxed"), ("pow", "relaxed"),
                     ("rsqrt", "relaxed")]
    assert all("test_glsl.py" in c.where for c in kernel_of(f).routines)
    x = _data(64, 0.1, 2)
    np.testing.assert_allclose(f(x), np.sin(x) + np.exp2(x) + np.log2(x + 1) + 1 / np.sqrt(x * x + 1), rtol=2e-3)


def test_misuse_is_a_clear_error():
    with pytest.raises(DSLTypeError, match="different sizes"):
        kernel(lambda x: gl.min(vec2(x), vec3(x)).x, args=[Float], returns=Float)
    with pytest.raises(DSLTypeError, match="takes no options"):
        kernel(lambda x: gl.floor(x, precision="relaxed"), args=[Float], returns=Float)
    with pytest.raises(reactor.ArityError, match="clamp takes 3"):
        kernel(lambda x: gl.clamp(x, 0.0), args=[Float], returns=Float)
    with pytest.raises(DSLTypeError, match="cross takes two vec3"):
        kernel(lambda x: gl.cross(vec2(x), vec2(x)).x, args=[Float], returns=Float)
    with pytest.raises(DSLTypeError, match="takes a bvec"):
        kernel(lambda x: reactor.Select(gl.any(vec2(x)), 1.0, 0.0), args=[Float], returns=Float)
