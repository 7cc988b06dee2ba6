"""Tables and textures read with per-lane coordinates, vector operands as gufunc axes, the small
kinds: every result against a NumPy reference written from the documented formulas."""
import numpy as np
import pytest

import reactor
from reactor import DSLTypeError, Float, If, Int, Table, Texture2D, Texture3D, kernel, vec2, vec3, vec4
from reactor import u8vec4

WRAPS = ["clamp", "repeat", "mirror", "border"]


def wrap(i, n, mode):
    """(index, inside) of integer coordinates ``i`` on an axis of ``n``, NumPy's way."""
    i = np.asarray(i, np.int64)
    if mode == "clamp":
        return np.clip(i, 0, n - 1), np.ones(i.shape, bool)
    if mode == "border":
        return np.clip(i, 0, n - 1), (i >= 0) & (i < n)
    if mode == "repeat":
        return np.mod(i, n), np.ones(i.shape, bool)
    m = np.mod(i, 2 * n)
    return np.where(m < n, m, 2 * n - 1 - m), np.ones(i.shape, bool)


def to_index(x):
    """Float32 to Int as the DSL's saturating conversion: NaN 0, out of range clamped."""
    x = np.asarray(x, np.float64)
    return np.where(np.isnan(x), 0, np.clip(np.trunc(np.nan_to_num(x)), -2**31, 2**31 - 1)).astype(np.int64)


HOSTILE = np.array([-2**31, -1e9, -37, -11, -10, -1, 0, 1, 5, 9, 10, 11, 19, 20, 21, 1e9, 2**31 - 1], np.float64)


@pytest.mark.parametrize("mode", WRAPS)
def test_table_lookup_per_lane_follows_the_wrap_mode(mode):
    @kernel
    def look(i: Int, t: Table[Float, mode]) -> Float:
        return t[i]

    table = (np.arange(10, dtype=np.float32) + 1) * 1.5
    i = np.clip(HOSTILE, -2**31, 2**31 - 1).astype(np.int32)
    i = np.concatenate([i, np.arange(-25, 25, dtype=np.int32)])
    idx, inside = wrap(i, 10, mode)
    np.testing.assert_array_equal(look(i, table), np.where(inside, table[idx], 0).astype(np.float32))
    # a scalar (uniform) index, and a per-lane one under a per-lane condition
    assert look(np.int32(3), table) == table[3]


@pytest.mark.parametrize("mode", ["repeat", "mirror"])
@pytest.mark.parametrize("n", [1, 3, 7, 2366, 3746, 4884, 65537, 3_000_017])
def test_wraps_are_exact_over_the_whole_int_range(mode, n):
    """The wraps compute the quotient in double (no vector integer division): exact for every
    Int coordinate and table length, including the ends of the range and exact multiples (where
    the double quotient can fall one short: 2366, 3746 and 4884 have such
    multiples, found by search)."""
    @kernel
    def look(i: Int, t: Table[Int, mode]) -> Int:
        return t[i]

    table = np.arange(n, dtype=np.int32)
    rng = np.random.default_rng(n)
    k = rng.integers(-2**31 // (2 * n), 2**31 // (2 * n), 4000)
    i = np.concatenate([rng.integers(-2**31, 2**31, 20000), k * n, k * n - 1, k * n + 1, 2 * k * n,
                        2 * k * n - 1, [-2**31, -2**31 + 1, 2**31 - 1, 2**31 - 2, 0, -1]])
    i = np.clip(i, -2**31, 2**31 - 1).astype(np.int32)
    np.testing.assert_array_equal(look(i, table), table[wrap(i, n, mode)[0]])


def test_table_of_each_kind_returns_that_kind():
    @kernel
    def look(i: Int, a: Table[Int], b: Table[reactor.UByte], c: Table[vec3]) -> (Int, Int, Float):
        v = c[i]
        return a[i] * 2, Int(b[i]) + 1, v.y + v.z

    a = np.arange(-5, 5, dtype=np.int32) * 3
    b = np.arange(250, 260, dtype=np.int64).astype(np.uint8)
    c = np.arange(30, dtype=np.float32).reshape(10, 3)
    i = np.array([0, 3, 9, 4], np.int32)
    x, y, z = look(i, a, b, c)
    np.testing.assert_array_equal(x, a[i] * 2)
    np.testing.assert_array_equal(y, b[i].astype(np.int32) + 1)
    np.testing.assert_array_equal(z, c[i, 1] + c[i, 2])


def _texture(kind, shape, rng):
    if kind == "f32":
        return rng.random(shape).astype(np.float32)
    if kind == "f16":
        return rng.random(shape).astype(np.float16)
    return rng.integers(0, 256, shape).astype(np.uint8)


def _normalized(tex):
    return tex.astype(np.float32) / np.float32(255) if tex.dtype == np.uint8 else tex.astype(np.float32)


ELEMENTS = {  # (kind, channels) -> DSL texel type
    ("f32", 1): Float, ("f32", 2): vec2, ("f32", 3): vec3, ("f32", 4): vec4,
    ("f16", 1): reactor.Half, ("f16", 3): reactor.f16vec3, ("f16", 4): reactor.f16vec4,
    ("u8", 1): reactor.UByte, ("u8", 2): reactor.u8vec2, ("u8", 3): reactor.u8vec3, ("u8", 4): u8vec4,
}


def _sample_ref(tex, u, v, mode, filt):
    """The DSL's documented formulas in float32 (x along axis 1, y along axis 0)."""
    h, w = tex.shape[:2]
    t = _normalized(tex)
    if t.ndim == 2:
        t = t[..., None]
    u, v = np.float32(u), np.float32(v)
    if filt == "nearest":
        x, okx = wrap(to_index(np.floor(u * np.float32(w))), w, mode)
        y, oky = wrap(to_index(np.floor(v * np.float32(h))), h, mode)
        return np.where((okx & oky)[:, None], t[y, x], 0)
    tx, ty = u * np.float32(w) - np.float32(0.5), v * np.float32(h) - np.float32(0.5)
    x0, y0 = np.floor(tx), np.floor(ty)
    fx, fy = (tx - x0)[:, None], (ty - y0)[:, None]
    xi, yi = to_index(x0), to_index(y0)

    def at(dx, dy):
        x, okx = wrap(xi + dx, w, mode)
        y, oky = wrap(yi + dy, h, mode)
        return np.where((okx & oky)[:, None], t[y, x], np.float32(0))

    one = np.float32(1)
    bottom = at(0, 0) * (one - fx) + at(1, 0) * fx
    top = at(0, 1) * (one - fx) + at(1, 1) * fx
    return bottom * (one - fy) + top * fy


@pytest.mark.filterwarnings("ignore:invalid value:RuntimeWarning")  # the reference's inf - inf
@pytest.mark.parametrize("mode", WRAPS)
@pytest.mark.parametrize("filt", ["nearest", "linear"])
@pytest.mark.parametrize("fmt", sorted(ELEMENTS))
def test_texture_sampling_matches_numpy(fmt, filt, mode):
    kind, channels = fmt
    element = ELEMENTS[fmt]

    @kernel(fma=False)
    def sample(u: Float, v: Float, img: Texture2D[element, mode, filt]) -> vec4:
        t = img.sample(u, v)
        if channels == 1:
            return vec4(t, 0.0, 0.0, 0.0)
        return vec4(t, *([0.0] * (4 - channels)))

    rng = np.random.default_rng(channels * 7 + len(mode))
    tex = _texture(kind, (5, 7) if channels == 1 else (5, 7, channels), rng)
    u = rng.uniform(-1.3, 2.3, 300).astype(np.float32)
    v = rng.uniform(-1.3, 2.3, 300).astype(np.float32)
    u[:6] = [0, 1, 0.5, np.nan, np.inf, -np.inf]
    got = sample(u, v, tex)[:, :channels]
    want = _sample_ref(tex, u, v, mode, filt)
    if filt == "nearest":
        np.testing.assert_array_equal(got, want)
    else:
        finite = np.isfinite(u) & np.isfinite(v)
        np.testing.assert_array_max_ulp(got[finite], want[finite].astype(np.float32), maxulp=1)


def test_texel_fetch_3d_textures_and_size():
    @kernel
    def fetch(x: Int, y: Int, z: Int, vol: Texture3D[vec3, "repeat"]) -> (Float, Int, Int, Int):
        w, h, d = vol.size
        return vol.fetch(x, y, z).y, w, h, d

    vol = np.arange(4 * 5 * 6 * 3, dtype=np.float32).reshape(4, 5, 6, 3)
    x = np.array([0, 5, 6, -1, 13], np.int32)
    y = np.array([0, 4, 5, 2, -7], np.int32)
    z = np.array([0, 3, 4, 1, 9], np.int32)
    got, w, h, d = fetch(x, y, z, vol)
    np.testing.assert_array_equal(got, vol[np.mod(z, 4), np.mod(y, 5), np.mod(x, 6), 1])
    assert (w == 6).all() and (h == 5).all() and (d == 4).all()


def test_trilinear_sampling_of_a_3d_lut():
    n = 9

    @kernel(fma=False)
    def grade(r: Float, g: Float, b: Float, lut: Texture3D[vec3, "clamp", "linear"]) -> vec3:
        scale, offset = (n - 1) / n, 0.5 / n  # texel centres: node k at (k + 0.5) / n
        return lut.sample(r * scale + offset, g * scale + offset, b * scale + offset)

    grid = np.linspace(0, 1, n, dtype=np.float32)
    lut = np.stack(np.meshgrid(grid, grid, grid, indexing="ij")[::-1], -1) ** 2  # [b, g, r] -> (r^2, g^2, b^2)
    lut = lut.astype(np.float32)
    rng = np.random.default_rng(3)
    r, g, b = (rng.random(500).astype(np.float32) for _ in range(3))
    got = grade(r, g, b, lut)
    for c, x in enumerate((r, g, b)):  # linear between nodes: below h^2 / 4 from x^2
        np.testing.assert_allclose(got[:, c], x ** 2, atol=1 / (4 * (n - 1) ** 2) + 1e-6)


def test_non_contiguous_and_several_textures_in_one_kernel():
    @kernel
    def two(i: Int, a: Texture2D[Float], b: Table[vec2]) -> Float:
        return a.fetch(i, i + 1) + b[i].y

    big = np.arange(12 * 20, dtype=np.float32).reshape(12, 20)
    a = big[::3, ::2]  # strided: (4, 10)
    b = np.arange(40, dtype=np.float32).reshape(10, 4)[:, 1:3]  # (10, 2), stride 16 bytes
    i = np.array([0, 1, 2, 3, 9, -4], np.int32)
    want = a[np.clip(i + 1, 0, 3), np.clip(i, 0, 9)] + b[np.clip(i, 0, 9), 1]
    np.testing.assert_array_equal(two(i, a, b), want)


def test_images_as_they_come_vector_operands_are_the_last_axis():
    @kernel
    def shade(n: vec3, l: vec3) -> vec4:
        d = reactor.Max(n.x * l.x + n.y * l.y + n.z * l.z, 0.0)
        return vec4(n * d, 1.0)

    assert shade.signature == "(3),(3)->(4)"
    rng = np.random.default_rng(1)
    n = rng.standard_normal((33, 17, 3)).astype(np.float32)
    light = np.array([0.3, 0.8, 0.5], np.float32)
    d = np.maximum((n * light).sum(-1, dtype=np.float32), 0)[..., None]
    want = np.concatenate([n * d, np.ones((33, 17, 1), np.float32)], -1)
    np.testing.assert_allclose(shade(n, light), want, rtol=1e-6, atol=1e-6)
    # channels not contiguous (a transposed view): the element-by-element path, same results
    nt = np.moveaxis(np.ascontiguousarray(np.moveaxis(n, -1, 0)), 0, -1)
    np.testing.assert_array_equal(shade(nt, light), shade(n, light))
    with pytest.raises(ValueError):
        shade(n[..., :2], light)  # NumPy checks the core dimension


def test_a_split_call_reads_core_dimensions_on_every_thread():
    saved = reactor.thread_settings()
    reactor.configure_threads(threads=2, threshold=64, min_work=0)
    try:
        @kernel
        def look(u: Float, t: Texture2D[vec2, "repeat", "linear"]) -> vec2:
            return t.sample(u, u * 0.5)

        tex = np.random.default_rng(2).random((3, 11, 2)).astype(np.float32)
        u = np.linspace(-2, 2, 5000, dtype=np.float32)
        reactor.configure_threads(threads=1)
        one = look(u, tex)
        reactor.configure_threads(threads=2)
        np.testing.assert_array_equal(look(u, tex), one)
    finally:
        reactor.configure_threads(**saved._asdict())


def test_inactive_lanes_read_nothing_and_get_zero():
    @kernel
    def guarded(i: Int, t: Table[Float, "border"]) -> Float:
        y = reactor.Variable(Float, -1.0)
        with If(i >= 0):
            y.set(t[i] + 1.0)
        return y

    t = np.arange(4, dtype=np.float32)
    i = np.array([-5, 0, 3, 4, 2, -1], np.int32)
    np.testing.assert_array_equal(guarded(i, t), [-1, 1, 4, 1, 3, -1])


def test_texture_misuse_is_a_clear_error():
    with pytest.raises(DSLTypeError, match="wrap mode"):
        Texture2D[vec4, "wrapp"]
    with pytest.raises(DSLTypeError, match="linear filtering"):
        Texture2D[Int, "linear"]
    with pytest.raises(DSLTypeError, match="at least one input"):
        kernel(lambda t: t[0], args=[Table[Float]], returns=Float)
    with pytest.raises(DSLTypeError, match="sample takes Float"):
        kernel(lambda i, t: t.sample(i, i), args=[Int, Texture2D[Float]], returns=Float)


def test_pointer_reads_and_writes_with_per_lane_indices():
    from reactor import Extract, Int4, Pointer, function

    @function
    def scatter_gather(p: Pointer[Float, "n"], n: Int, q: Pointer[Float, "n"]) -> Float:
        v = p[Int4(3, -1, 5, 100)]  # lanes outside [0, n) read 0
        q[Int4(0, 1, 7, 2)] = v * 2.0
        return Extract(v, 0) + Extract(v, 2)

    p, q = np.arange(8, dtype=np.float32), np.zeros(8, np.float32)
    assert scatter_gather(p, 8, q) == 8.0
    np.testing.assert_array_equal(q, [6, 0, 0, 0, 0, 0, 0, 10])

    def unbounded(p: Pointer[Float], i: reactor.Int4) -> reactor.Float4:
        return p[i]

    with pytest.raises(DSLTypeError, match="needs the pointer's length"):
        reactor.Function(unbounded).compile()


def test_an_integer_image_for_a_float_texture_is_a_clear_error_not_a_silent_conversion():
    @kernel
    def look(u: Float, img: Texture2D[vec4, "repeat"]) -> vec4:
        return img.sample(u, u)

    img = np.full((4, 4, 4), 0.5, np.float32)
    np.testing.assert_array_equal(look(np.float32([0.3]), img), [[0.5] * 4])
    np.testing.assert_array_equal(look(np.float32([0.3]), img.astype(np.float16)), [[0.5] * 4])  # exact: fine
    with pytest.raises(reactor.ArgumentError, match=r"u8vec4.*astype"):
        look(np.float32([0.3]), (img * 255).astype(np.uint8))
    with pytest.raises(ValueError, match="core dimension"):
        look(np.float32([0.3]), img[..., :3])


def test_writing_a_table_in_a_kernel_says_how_to_scatter():
    from reactor import Int, Table
    with pytest.raises(reactor.DSLTypeError, match="read-only in a kernel.*Pointer"):
        @reactor.kernel
        def w(i: Int, t: Table[Float]) -> Float:
            t[i] = 1.0
            return 0.0


@pytest.mark.parametrize("mode", ["clamp", "border"])
def test_one_load_per_texel_and_one_gather_per_channel_agree(mode):
    """Where gathers are slow (AMD, Haswell, AArch64) a texel whose channels are adjacent is one
    load per lane; elsewhere, or for channels apart in memory (checked when the kernel runs), one
    gather per channel. Both read the same texels; lanes off read nothing; an empty image reads
    nothing."""
    def build(target):
        @kernel(target=target, fma=False)
        def look(u: Float, v: Float, t: Texture2D[vec4, mode, "linear"]) -> vec4:
            c = reactor.Variable(vec4, vec4(-1.0))
            with If(u < 0.9):
                c.set(t.sample(u, v))
            return c
        return look

    assert not reactor.targets.get_target("avx2").fast_gather and reactor.targets.get_target("avx512").fast_gather
    rng = np.random.default_rng(5)
    image = rng.random((9, 13, 4)).astype(np.float32)
    apart = np.moveaxis(np.ascontiguousarray(np.moveaxis(image, -1, 0)), 0, -1)  # channel stride 468 bytes
    u, v = rng.uniform(-0.3, 1.3, 1000).astype(np.float32), rng.uniform(-0.3, 1.3, 1000).astype(np.float32)
    runnable = [t for t in ("avx2", "avx512") if reactor.targets.get_target(t).runnable]
    results = [build(t)(u, v, img) for t in runnable for img in (image, apart)]
    for got in results[1:]:
        np.testing.assert_array_equal(got, results[0])
    assert np.all(results[0][u >= 0.9] == -1)
    for t in runnable:
        empty = build(t)(u, v, np.zeros((0, 5, 4), np.float32))
        assert np.all(empty[u < 0.9] == 0) and np.all(empty[u >= 0.9] == -1)
