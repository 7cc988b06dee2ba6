"""GLSL fragment shaders through glslang, SPIR-V and the translator, each checked lane by lane
against the same shader evaluated per element in NumPy float32 (skipped without the glsl extra)."""
import numpy as np
import pytest

import reactor
import routines  # noqa: F401 - installs the GLSL built-ins
from reactor.spirv import SpirvError
from reactor.spirv.glsl import glslang
from reactor.spirv.grammar import MissingToolError

try:
    glslang()
    reactor.spirv.grammar.grammar_directory()
except MissingToolError as exc:  # pragma: no cover - the glsl extra is optional
    pytest.skip(str(exc), allow_module_level=True)

F = np.float32
RNG = np.random.default_rng(7)
UV = RNG.uniform(-1.5, 1.5, (37, 2)).astype(F)  # a vector loop and a tail

LOOPS = """#version 450
layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;
layout(binding = 0) uniform U { float gain; };
float sq(float x) { return x * x; }
void main() {
    float r = length(uv);
    if (r > 1.0) { color = vec4(0.0); return; }
    float s = 0.0;
    for (int i = 0; i < 4; i++) { s += sq(uv.x) * float(i); if (s > 2.0) break; }
    color = vec4(exp2(r) * gain, s, uv.y, 1.0);
}
"""


def loops_reference(u, gain):
    r = F(np.sqrt(F(u[0] * u[0] + u[1] * u[1])))
    if r > 1:
        return [0, 0, 0, 0]
    s = F(0)
    for i in range(4):
        s = F(s + F(u[0] * u[0]) * F(i))
        if s > 2:
            break
    return [F(np.exp2(r)) * F(gain), s, u[1], 1]


def close(got, want, ulps=2):
    want = np.asarray(want, F)
    return np.all(np.abs(got - want) <= ulps * np.spacing(np.abs(want).astype(F)) + 1e-30)


def test_a_shader_with_a_helper_an_early_return_and_a_loop_that_breaks():
    shade = reactor.from_glsl(LOOPS, uniforms={"gain": 2.0})
    assert shade.signature == "(2)->(4)"
    got = shade(UV)
    assert close(got, [loops_reference(u, 2.0) for u in UV])


def test_a_uniform_not_given_is_an_argument_after_the_inputs():
    shade = reactor.from_glsl(LOOPS)
    got = shade(UV, F(0.5))
    assert close(got, [loops_reference(u, 0.5) for u in UV])


CONTROL = """#version 450
layout(location = 0) in float x;
layout(location = 1) in float y;
layout(location = 0) out float result;
float steps(float v) {
    for (int i = 0; i < 8; i++) {
        if (v > 4.0) return v;          // returns from the helper, per lane
        v = v * 2.0 + 0.5;
    }
    return -v;
}
void main() {
    float acc = 0.0;
    int k = 0;
    while (k < 6) {
        k++;
        if (mod(float(k), 2.0) == 0.0) continue;
        if (acc > 3.0 && x > 0.0) break;  // && as glslang writes it: a phi
        acc += abs(x) + 0.25;
    }
    switch (int(y * 2.0 + 3.0)) {
        case 0: acc = -acc; break;
        case 1: acc = acc * 0.5; break;
        default: acc = acc + 1.0; break;
    }
    result = acc + steps(y);
}
"""


def control_reference(x, y):
    acc, k = F(0), 0
    while k < 6:
        k += 1
        if k % 2 == 0:
            continue
        if acc > 3 and x > 0:
            break
        acc = F(acc + F(abs(x) + F(0.25)))
    sel = int(F(y * F(2) + F(3)))
    acc = -acc if sel == 0 else F(acc * F(0.5)) if sel == 1 else F(acc + F(1))
    v = y
    for _ in range(8):
        if v > 4:
            return F(acc + v)
        v = F(F(v * F(2)) + F(0.5))
    return F(acc - v)


def test_continue_break_short_circuit_switch_and_a_helpers_return_in_its_loop():
    shade = reactor.from_glsl(CONTROL)
    x, y = UV[:, 0], UV[:, 1]
    assert np.array_equal(shade(x, y), np.array([control_reference(a, b) for a, b in zip(x, y)], F))


VECTORS = """#version 450
layout(location = 0) in vec3 n;
layout(location = 0) out vec4 color;
void main() {
    vec3 l = normalize(vec3(0.3, 0.8, 0.5));
    vec3 nn = normalize(n);
    mat3 m = mat3(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0);
    vec3 r = reflect(-l, nn);
    float d = max(dot(nn, l), 0.0);
    color = vec4(m * nn, 1.0);
    color.w = d + 0.5 * r.z;
}
"""


def test_vectors_matrices_swizzles_and_geometric_built_ins():
    shade = reactor.from_glsl(VECTORS)
    n = RNG.uniform(-1, 1, (37, 3)).astype(F) + F(0.01)
    got = shade(n)
    nn = n / np.sqrt((n * n).sum(1, keepdims=True))
    l = np.array([0.3, 0.8, 0.5]) / np.sqrt(0.98)
    r = -l - 2 * (nn @ -l)[:, None] * nn
    want = np.stack([nn[:, 0], -nn[:, 2], nn[:, 1], np.maximum(nn @ l, 0) + 0.5 * r[:, 2]], 1)
    assert np.allclose(got, want, rtol=2e-6, atol=2e-6)


def test_a_glsl_error_names_the_line_and_an_unsupported_stage_is_refused():
    with pytest.raises(SpirvError, match=r"glslang could not compile .*:4: .*undeclared"):
        reactor.from_glsl("#version 450\nlayout(location = 0) out float o;\nvoid main() {\n  o = nope;\n}\n")
    with pytest.raises(SpirvError, match="a Vertex shader: fragment and compute shaders are supported"):
        reactor.from_glsl("#version 450\nvoid main() { gl_Position = vec4(0.0); }\n", stage="vertex")


def test_bad_spirv_is_one_clear_error():
    with pytest.raises(SpirvError, match="not a SPIR-V module"):
        reactor.from_spirv(b"\x00" * 24)
    good = reactor.spirv.glsl.compile_glsl(LOOPS)
    with pytest.raises(SpirvError, match="overruns the module|unknown opcode|more than its grammar"):
        reactor.from_spirv(good[:20] + b"\xff\xff\xff\x7f" + good[24:])


def test_glsl_fbm_runs_unchanged_and_matches_its_hand_port_bit_for_bit():
    """examples/glsl/fbm2d.frag (yiwenl/glsl-fbm's 2d.glsl, its functions unchanged) against
    examples/shaders/noise.py, the hand port: every output bit the same (its counted loop is
    unrolled while building, as the hand port's Python loop is)."""
    import pathlib
    import sys

    root = pathlib.Path(__file__).resolve().parents[2]
    sys.path.insert(0, str(root / "examples" / "shaders"))
    import noise

    fx, fy, h = noise.inputs(64)
    shade = reactor.from_glsl(root / "examples" / "glsl" / "fbm2d.frag")
    assert np.array_equal(shade(fx, fy, h).view(np.uint32), noise.build("full")(fx, fy, h).view(np.uint32))


def test_gl_fragcoord_is_the_last_input():
    shade = reactor.from_glsl("""#version 450
layout(location = 0) in float t;
layout(location = 0) out vec2 o;
void main() { o = vec2(gl_FragCoord.x * t, gl_FragCoord.y + gl_FragCoord.w); }
""")
    coord = RNG.uniform(0, 100, (37, 4)).astype(F)
    t = RNG.uniform(0, 1, 37).astype(F)
    got = shade(t, coord)
    assert np.array_equal(got, np.stack([coord[:, 0] * t, coord[:, 1] + coord[:, 3]], 1))


def test_a_shadertoy_shader_runs_with_no_edit():
    src = """void mainImage(out vec4 fragColor, in vec2 fragCoord) {
    vec2 uv = fragCoord / iResolution.xy;
    fragColor = vec4(0.5 + 0.5 * cos(iTime + uv.xyx + vec3(0, 2, 4)), 1.0);
}"""
    shade = reactor.from_glsl(src, stage="shadertoy", uniforms={"iResolution": (64, 32, 1)})
    assert shade.signature == "(2),()->(4)"  # fragCoord, then iTime
    from reactor.spirv.render import pixel_centres
    coord = pixel_centres(64, 32, bottom_left=True)
    uv = coord / np.array([64, 32], F)
    want = 0.5 + 0.5 * np.cos(1.0 + np.stack([uv[..., 0], uv[..., 1], uv[..., 0]], -1) + np.array([0, 2, 4]))
    assert np.abs(shade(coord, F(1.0))[..., :3] - want).max() < 1e-6
    with pytest.raises(SpirvError, match=r":2: .*undeclared"):  # the user's own line numbers
        reactor.from_glsl("void mainImage(out vec4 c, in vec2 p) {\n  c = vec4(nope);\n}", stage="shadertoy")


def test_the_glsl_command_renders_a_png(tmp_path):
    import subprocess
    import sys
    import zlib

    out = tmp_path / "rings.png"
    run = subprocess.run([sys.executable, "-m", "reactor", "glsl", "examples/glsl/rings.frag", "--shadertoy",
                          "--size", "40x20", "--out", str(out)], capture_output=True, text=True, timeout=300,
                         cwd=__import__("pathlib").Path(__file__).resolve().parents[2])
    assert run.returncode == 0, run.stderr
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    width, height = int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")
    assert (width, height) == (40, 20)
    start = data.index(b"IDAT") + 4
    raw = zlib.decompress(data[start:data.index(b"IEND") - 8])
    rows = np.frombuffer(raw, np.uint8).reshape(20, 1 + 40 * 4)[:, 1:].reshape(20, 40, 4)
    assert (rows[10, 20, :3] == 255).all() and rows[..., 3].min() == 255  # the white centre, opaque


def test_discard_is_a_mask_output_also_from_a_helper():
    shade = reactor.from_glsl("""#version 450
layout(location = 0) in vec2 uv;
layout(location = 0) out float o;
void check(float v) { if (v > 1.0) discard; }
void main() {
    o = 1.0;
    if (uv.x < 0.0) discard;
    check(uv.y);
    o = uv.x + uv.y;
}
""")
    color, discarded = shade(UV)
    want = (UV[:, 0] < 0) | (UV[:, 1] > 1)
    assert np.array_equal(discarded, want)
    assert np.array_equal(color[~want], (UV[:, 0] + UV[:, 1])[~want])
    assert np.all(color[want] == 1.0)  # what the pixel had stored when it was discarded


def test_indices_known_only_at_run_time():
    shade = reactor.from_glsl("""#version 450
layout(location = 0) in float x;
layout(location = 0) out vec2 o;
const float table[4] = float[4](0.5, 1.5, 2.5, 3.5);
void main() {
    int i = int(clamp(x, 0.0, 3.0));
    float local[3] = float[3](0.0, 0.0, 0.0);
    local[i % 3] = x;
    vec3 v = vec3(10.0, 20.0, 30.0);
    o = vec2(table[i] + v[i % 3], local[0] + local[1] * 2.0 + local[2] * 4.0);
}
""")
    x = RNG.uniform(-1, 5, 37).astype(F)
    i = np.clip(x, 0, 3).astype(np.int32)
    table, v = np.array([0.5, 1.5, 2.5, 3.5], F), np.array([10, 20, 30], F)
    weight = np.array([1, 2, 4], F)[i % 3]
    assert np.array_equal(shade(x), np.stack([table[i] + v[i % 3], x * weight], 1))


def test_samplers_are_texture_arguments():
    shade = reactor.from_glsl("""#version 450
layout(location = 0) in vec2 uv;
layout(location = 0) out vec4 color;
layout(binding = 1) uniform sampler2D image;
void main() {
    ivec2 size = textureSize(image, 0);
    vec4 filtered = texture(image, uv);
    vec4 texel = texelFetch(image, ivec2(1, 2), 0);
    color = vec4(filtered.rg, texel.b, float(size.x * 100 + size.y));
}
""", samplers={"image": ("repeat", "linear")})
    image = RNG.uniform(0, 1, (5, 7, 4)).astype(F)  # H=5, W=7
    uv = RNG.uniform(-0.5, 1.5, (37, 2)).astype(F)
    got = shade(uv, image)
    # the same through the DSL directly: Texture2D[vec4, "repeat", "linear"].sample
    from reactor import Texture2D, vec2, vec4

    @reactor.kernel
    def direct(p: vec2, tex: Texture2D[vec4, "repeat", "linear"]) -> vec4:
        s = tex.sample(p.x, p.y)
        return vec4(s.x, s.y, tex.fetch(1, 2).z, 705.0)  # textureSize: (W, H) = (7, 5)
    assert np.array_equal(got, direct(uv, image))


COMPUTE = """#version 450
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer Data { float values[]; };
layout(std430, binding = 1) buffer Out { float result[]; };
layout(binding = 2) uniform Params { float scale; };
void main() {
    uint i = gl_GlobalInvocationID.x;
    float v = values[i];
    if (v < 0.0) { result[i] = 0.0; return; }
    result[i] = sqrt(v) * scale;
    values[i] = v + 1.0;
}
"""


def test_a_compute_shader_is_one_invocation_per_element():
    shade = reactor.from_glsl(COMPUTE, stage="compute")
    assert (shade.nin, shade.nout) == (3, 2)  # values, result, scale -> values, result
    v = RNG.uniform(-2, 10, 37).astype(F)
    values, result = shade(v, np.zeros_like(v), F(3))
    assert np.array_equal(values, np.where(v < 0, v, v + F(1)))
    assert np.array_equal(result, np.where(v < 0, F(0), np.sqrt(np.abs(v)) * F(3)))
    data = v.copy()
    shade(data, np.zeros_like(v), F(3), out=(data, np.empty_like(v)))  # in place, as the shader updates it
    assert np.array_equal(data, values)


def test_a_compute_shaders_bounds_check_holds():
    shade = reactor.from_glsl(COMPUTE.replace("uint i = gl_GlobalInvocationID.x;",
                                              "uint i = gl_GlobalInvocationID.x;\n    if (i >= values.length()) return;"),
                              stage="compute", uniforms={"scale": 2.0})
    v = RNG.uniform(0, 10, 37).astype(F)
    values, result = shade(v, np.zeros_like(v))
    assert np.array_equal(result, np.sqrt(v) * F(2)) and np.array_equal(values, v + F(1))


def test_a_buffer_read_elsewhere_than_its_own_element_is_refused():
    with pytest.raises(SpirvError, match="arithmetic on it, or another comparison, is not yet"):
        reactor.from_glsl(COMPUTE.replace("float v = values[i];", "float v = values[i + 1u];"), stage="compute")


def test_products_and_sums_are_rounded_apart_as_precise_asks():
    """GLSL's precise (SPIR-V NoContraction): a * b - c * d is two roundings of products and one of
    the difference, never a fused multiply-add, also in a build with fma on (which only lets the
    routines fuse)."""
    shade = reactor.from_glsl("""#version 450
layout(location = 0) in vec4 v;
layout(location = 0) out float o;
void main() { precise float r = v.x * v.y - v.z * v.w; o = r; }
""", fma=True)
    v = RNG.uniform(-1, 1, (4096, 4)).astype(F)
    want = v[:, 0] * v[:, 1] - v[:, 2] * v[:, 3]  # NumPy float32: each operation rounded
    assert np.array_equal(shade(v), want)


def test_a_shadertoy_channel_is_a_texture_argument():
    shade = reactor.from_glsl("""void mainImage(out vec4 fragColor, in vec2 fragCoord) {
    fragColor = texture(iChannel0, fragCoord / iResolution.xy) * 0.5;
}""", stage="shadertoy", uniforms={"iResolution": (8, 4, 1), "iTime": 0.0}, samplers={"iChannel0": ("clamp", "nearest")})
    from reactor.spirv.render import pixel_centres
    image = RNG.uniform(0, 1, (4, 8, 4)).astype(F)
    got = shade(pixel_centres(8, 4, bottom_left=True), image)
    # fragCoord.y counts from the bottom and v = 0 is the array's first row: the render is the array
    # upside down (Shadertoy flips images on upload: pass np.flipud(image) to see one upright)
    assert np.array_equal(got, image[::-1] * F(0.5))


def test_a_translation_error_names_the_shaders_line(tmp_path):
    shader = tmp_path / "wide.frag"
    shader.write_text("""#version 450
layout(location = 0) in vec2 uv;
layout(location = 0) out float o;
void main() {
    float big[8000];
    big[0] = uv.x;
    o = big[0];
}
""")
    with pytest.raises(SpirvError, match="an array of 8000 elements"):
        reactor.from_glsl(shader)
    shader.write_text("""#version 450
layout(location = 0) in vec2 uv;
layout(location = 0) out float o;
void main() {
    o = uv.x;
    o += dFdx(uv.y);
}
""")
    with pytest.raises(SpirvError, match=r"OpDPdx .*not supported.*wide\.frag:6"):
        reactor.from_glsl(shader)


def test_bit_casts():
    shade = reactor.from_glsl("""#version 450
layout(location = 0) in float x;
layout(location = 0) out float o;
void main() { o = intBitsToFloat(floatBitsToInt(x) & 0x7fffffff) + float(floatBitsToInt(x) & 255); }
""")
    x = RNG.uniform(-4, 4, 37).astype(F)
    bits = x.view(np.int32)
    assert np.array_equal(shade(x), (bits & 0x7FFFFFFF).view(F) + (bits & 255).astype(F))


WEBGL = """precision highp float;
uniform sampler2D tDiffuse;
uniform float amount;
varying vec2 vUv;
void main() {
    vec4 c = texture2D(tDiffuse, vUv);
    gl_FragColor = vec4(c.rgb * amount, c.a);
    if (any(greaterThan(c.rgb, vec3(0.9)))) gl_FragColor.a = 0.0;
}
"""


def test_a_webgl_shader_runs_with_no_edit():
    """three.js and glslify write GLSL ES 1.00: varying, texture2D, gl_FragColor, loose uniforms."""
    shade = reactor.from_glsl(WEBGL, stage="webgl", uniforms={"amount": 0.5})
    image = RNG.uniform(0, 1, (4, 4, 4)).astype(F)
    uv = ((np.argwhere(np.ones((4, 4))) + 0.5) / 4)[:, ::-1].astype(F)  # texel centres: exact texels
    got = shade(uv, image)
    texels = image.reshape(-1, 4)
    want = np.concatenate([texels[:, :3] * F(0.5), np.where((texels[:, :3] > F(0.9)).any(1), 0, texels[:, 3])[:, None]], 1)
    assert np.array_equal(got, want)


def test_desktop_glsl_without_locations_or_blocks():
    """In/out variables with no location are numbered in declaration order; loose uniforms are
    uniforms; all() of a vector comparison."""
    shade = reactor.from_glsl("""#version 330
in float a;
in vec2 b;
out vec4 color;
uniform vec3 shading;
void main() {
    if (shading == vec3(0.0)) { color = vec4(a, b, 1.0); return; }
    color = vec4(shading, a);
}""", uniforms={"shading": (0.0, 0.0, 0.0)})
    assert shade.signature == "(),(2)->(4)"
    assert np.array_equal(shade(F(3), np.array([1, 2], F)), [3, 1, 2, 1])


def test_a_misspelt_uniform_is_an_error():
    with pytest.raises(SpirvError, match="names 'gian', which the shader does not declare .*gain"):
        reactor.from_glsl(LOOPS, uniforms={"gian": 2.0})


SPECIALIZED = """#version 450
layout(local_size_x = 1) in;
layout(constant_id = 0) const float m = 1.0;
layout(constant_id = 7) const int k = 1;
layout(binding = 0) buffer X { float x[]; };
layout(binding = 1) buffer W { float w[]; };
layout(binding = 2) buffer Y { float y[]; };
void main() {
    uint i = gl_GlobalInvocationID.x;
    y[i] = (w[0] * x[i] + w[2]) / m + float(k);
}
"""


def test_specialization_constants_by_name_or_id_and_buffers_read_at_constant_indices():
    """Kompute's pattern: weights read as w[0], w[2] by every invocation are one vec3 argument."""
    shade = reactor.from_glsl(SPECIALIZED, stage="compute", uniforms={"m": 4.0, 7: 3})
    assert shade.signature == "(),(3),()->()"
    x, w = RNG.uniform(-1, 1, 37).astype(F), np.array([0.5, 9.0, 0.25], F)
    want = (w[0] * x + w[2]) / F(4) + F(3)
    assert np.array_equal(shade(x, w, np.zeros_like(x)), want)
    folded = reactor.from_glsl(SPECIALIZED, stage="compute", uniforms={"m": 4.0, 7: 3, "w": w})
    assert np.array_equal(folded(x, np.zeros_like(x)), want)
    with pytest.raises(SpirvError, match="buffer w is indexed by something .* read at constant indices only"):
        reactor.from_glsl(SPECIALIZED.replace("+ w[2]", "+ w[2] + w[i]"), stage="compute")


def test_a_loop_after_an_early_return_still_counts_while_building():
    """Lanes that returned never read the helper's locals again, so its loop counter stays known
    while building and the loop unrolls (glsl-atmosphere's shape); the results stay per lane."""
    shade = reactor.from_glsl("""#version 450
layout(location = 0) in float x;
layout(location = 0) out float result;
float steps(float v) {
    if (v < 0.0) return -1.0;
    float s = 0.0;
    for (int i = 0; i < 4; i++) { s += v * float(i); v = v * 0.5; }
    return s;
}
void main() { result = steps(x) + 1.0; }""")
    x = RNG.uniform(-2, 2, 37).astype(F)

    def steps(v):
        if v < 0:
            return F(-1)
        s = F(0)
        for i in range(4):
            s, v = F(s + F(v * F(i))), F(v * F(0.5))
        return s
    assert np.array_equal(shade(x), [F(steps(v) + F(1)) for v in x])


def test_integer_division_and_unsigned_arithmetic_never_trap():
    """int and uint /, %, >> and conversions, on hostile operands: a division by zero gives 0
    (GLSL leaves it undefined; no lane traps), INT_MIN / -1 wraps, uint is unsigned."""
    shade = reactor.from_glsl("""#version 450
layout(location = 0) flat in int a;
layout(location = 1) flat in int b;
layout(location = 0) out ivec4 signed_;
layout(location = 1) out uvec4 unsigned_;
layout(location = 2) out float as_float;
void main() {
    signed_ = ivec4(a / b, a % b, a >> 3, -a);
    uint ua = uint(a), ub = uint(b);
    unsigned_ = uvec4(ua / ub, ua % ub, ua >> 3, ua * 3u);
    as_float = float(ua);
}""")
    edge = np.array([0, 1, -1, 7, -7, 2, 3, 2**31 - 1, -2**31, 1000003, -65536], np.int64)
    a, b = (x.ravel() for x in np.meshgrid(edge, edge))
    signed_, unsigned_, as_float = shade(a.astype(np.int32), b.astype(np.int32))

    def wrap(x):
        return ((np.asarray(x, np.int64) + 2**31) % 2**32 - 2**31).astype(np.int32)
    safe = np.where(b == 0, 1, b)
    q = np.where(b == 0, 0, np.sign(a) * np.sign(safe) * (np.abs(a) // np.abs(safe)))
    smod = np.where(b == 0, 0, np.mod(a, safe))  # glslang writes GLSL's % as OpSMod
    ua, ub = a % 2**32, b % 2**32
    assert np.array_equal(signed_, np.stack([wrap(q), wrap(smod), wrap(a >> 3), wrap(-a)], -1))
    uq = np.where(ub == 0, 0, ua // np.where(ub == 0, 1, ub))
    ur = np.where(ub == 0, 0, ua % np.where(ub == 0, 1, ub))
    assert np.array_equal(unsigned_.astype(np.int64) % 2**32, np.stack([uq, ur, ua >> 3, ua * 3 % 2**32], -1))
    assert np.array_equal(as_float, ua.astype(np.float32))


def test_glslang_in_this_process_writes_what_the_command_writes():
    """With the cmeel wheel, glslang runs in this process (its C interface): the same code as
    ``glslangValidator -V -g -R --aml --amb``, debug text aside, and errors at the line."""
    from reactor.spirv import glsl
    from reactor.spirv.binary import decode
    lib = glsl._library()
    if lib is None:
        pytest.skip("glslang's library is not the cmeel wheel's glslang 13: the command is used")
    tool, env = glsl.glslang()
    debug = {"OpSource", "OpSourceContinued", "OpString", "OpLine", "OpNoLine", "OpModuleProcessed"}

    def code(spirv):
        return [(i.op, i.type, i.id, i.args) for i in decode(spirv).instructions if i.op not in debug]
    for source in (LOOPS, CONTROL, COMPUTE):
        stage = "compute" if "local_size_x" in source else "fragment"
        assert code(lib.compile(source, stage, "x.glsl")) == code(glsl._run_glslang(tool, env, None, source, stage))
    with pytest.raises(glsl.glslang_lib.CompileError, match=r"ERROR: x\.glsl:2: 'nope' : undeclared"):
        lib.compile("#version 450\nvoid main() { float a = nope; }\n", "fragment", "x.glsl")
