"""The GLSL corpus (``examples/glsl/corpus``) on reactor (``reactor.from_glsl``) and on Mesa's
llvmpipe (OpenGL on the CPU, headless through EGL with moderngl), same run: for each shader the
build (reactor: glslang, translation and LLVM, no cache; llvmpipe: compile and first draw), the
best run time with one thread and with two, and the accuracy against the shader's float64
evaluation in NumPy: 8-bit codes that differ (and the worst difference) for a fragment shader,
the largest error in float32 ULPs for a compute shader. Absent peers are reported absent.

    python benchmarks/bench_glsl.py [--size 512] [--elements 65535] [--repeat 7] [--only NAME ...]

Both run each shader's text as its package holds it. Each side's prelude does what its host
does: reactor's ``stage="webgl"``/``"shadertoy"`` preludes, and for llvmpipe the same defines in
GLSL 3.30, a vertex shader that computes the varyings from the quad's corners, and, in compute
shaders, the Vulkan-only ``set =`` and ``constant_id`` qualifiers replaced (the given value
written as the constant). Needs the glsl extra and, for llvmpipe, ``pip install moderngl`` with
Debian's ``libegl1 libegl-mesa0 libgl1-mesa-dri``.
"""
import argparse
import json
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "examples" / "glsl" / "corpus"))
import corpus  # noqa: E402
from llvmpipe_run import best_time  # noqa: E402

GL_WEBGL = """#version 330
#define varying in
#define texture2D texture
#define textureCube texture
out vec4 pc_fragColor;
#define gl_FragColor pc_fragColor
#line 1
"""

GL_SHADERTOY = """#version 330
uniform vec3 iResolution; uniform float iTime; uniform float iTimeDelta; uniform int iFrame;
uniform vec4 iMouse; uniform vec4 iDate; uniform float iSampleRate;
out vec4 reactor_fragColor;
#line 1
%s
void main() { mainImage(reactor_fragColor, gl_FragCoord.xy); }
"""


def gl_fragment(shader: corpus.Shader) -> str:
    text = shader.source()
    return GL_WEBGL + text if shader.stage == "webgl" else GL_SHADERTOY % text if shader.stage == "shadertoy" \
        else text


def gl_vertex(shader: corpus.Shader, fragment: str, w: int, h: int) -> str:
    """A vertex shader over the full-screen quad giving each varying its value (by location where
    the fragment shader declares them so)."""
    located = "layout(location" in fragment.replace(" ", "")
    outs = "".join(f"{f'layout(location = {k}) ' if located else ''}out {v.glsl_type} {v.name};\n"
                   for k, v in enumerate(shader.varyings))
    sets = "".join(f"    {v.name} = {v.glsl(w, h)};\n" for v in shader.varyings)
    return f"#version {450 if located else 330}\nin vec2 pos;\n{outs}void main() {{\n{sets}" \
           f"    gl_Position = vec4(pos, 0.0, 1.0);\n}}\n"


def gl_compute(text: str, uniforms: dict) -> str:
    """A Vulkan compute shader for OpenGL: no descriptor ``set``, specialization constants written."""
    text = re.sub(r"set\s*=\s*\d+\s*,\s*", "", text)

    def constant(m: re.Match) -> str:
        typ, name, default = m.group(2), m.group(3), m.group(4)
        value = uniforms.get(name, uniforms.get(int(m.group(1)), None))
        if value is None:
            return f"const {typ} {name} = {default};"
        literal = repr(float(value)) if typ == "float" else f"{int(value)}u" if typ == "uint" else str(int(value))
        return f"const {typ} {name} = {literal};"
    return re.sub(r"layout\s*\(\s*constant_id\s*=\s*(\d+)\s*\)\s*const\s+(\w+)\s+(\w+)\s*=\s*([^;]+);", constant, text)


def codes(x: np.ndarray) -> np.ndarray:
    return np.round(np.clip(np.nan_to_num(x), 0, 1) * 255).astype(np.int32)


def code_errors(image: np.ndarray, reference: np.ndarray) -> tuple[int, int, float]:
    """(8-bit codes differing, the largest difference, the largest error before quantization in
    codes: it tells near-ties, within float32's own resolution, from real errors)."""
    got = image[..., :reference.shape[-1]] if reference.ndim == 3 else image[..., 0] if image.ndim == 3 else image
    diff = np.abs(codes(got) - codes(reference))
    inside = (reference >= 0) & (reference <= 1)  # where clamping does not hide the error
    err = float(np.max(np.abs(got.astype(float) - reference)[inside], initial=0.0)) * 255
    return int((diff != 0).sum()), int(diff.max()), err


def ulp_error(outputs, references) -> float:
    return max(float(np.max(np.abs(o.astype(float) - r) / np.spacing(np.abs(r).astype(np.float32))))
               for o, r in zip(outputs, references))


def llvmpipe(spec: dict, threads: int, tmp: str) -> dict | None:
    """Run ``spec`` in llvmpipe in a process of its own (``LP_NUM_THREADS``: 0 is one thread)."""
    path = os.path.join(tmp, "spec.json")
    with open(path, "w") as f:
        json.dump(spec, f)
    env = dict(os.environ, LP_NUM_THREADS=str(0 if threads == 1 else threads))
    try:
        run = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "llvmpipe_run.py"), path],
                             capture_output=True, text=True, timeout=900, env=env)
    except (OSError, subprocess.TimeoutExpired) as exc:
        print(f"  llvmpipe failed: {exc}")
        return None
    if run.returncode != 0:
        last = run.stderr.strip().splitlines()[-1] if run.stderr.strip() else "?"
        print(f"  llvmpipe absent or failed: {last}")
        return None
    return json.loads(run.stdout.strip().splitlines()[-1])


def peer_runs(spec: dict, tmp: str, row: dict, key: str, accuracy) -> dict:
    """llvmpipe's runs of ``spec``, one thread and two, into ``row`` (its accuracy under ``key``,
    ``accuracy`` of what it wrote); the row as it is where llvmpipe is absent."""
    for threads in (1, 2):
        got = llvmpipe(spec, threads, tmp)
        if got is None:
            return row
        row[f"llvmpipe_{threads}_ms"], row["llvmpipe_first_ms"] = got["best"] * 1e3, got["first"] * 1e3
        row["renderer"] = got["renderer"]
        row[key] = accuracy(np.load(spec["out"]))
    return row


def run_fragment(shader: corpus.Shader, a, tmp: str) -> dict:
    import reactor
    w = h = a.size
    uniforms = shader.uniforms_for(w, h)
    t0 = time.perf_counter()
    kernel = reactor.from_glsl(shader.source(), stage=shader.stage, uniforms=uniforms, cache=False,
                               name=f"{shader.name}_bench")
    row = {"name": shader.name, "build_ms": (time.perf_counter() - t0) * 1e3}
    inputs = shader.inputs(w, h)
    image = corpus.test_image(w, h)
    args = [x.astype(np.float32) for x in inputs] + ([image] if shader.texture else [])
    reference = shader.reference([x.astype(float) for x in args[:len(inputs)]], image, uniforms)  # the same inputs
    for threads in (1, 2):
        reactor.configure_threads(threads=threads)
        out = kernel(*args)
        row[f"ours_{threads}_ms"] = best_time(lambda: kernel(*args), a.repeat) * 1e3
    row["ours_codes"] = code_errors(out[0] if isinstance(out, tuple) else out, reference)
    fragment = gl_fragment(shader)
    texture = os.path.join(tmp, "texture.npy")
    np.save(texture, image)
    out_path = os.path.join(tmp, "image.npy")
    spec = {"kind": "fragment", "vertex": gl_vertex(shader, fragment, w, h), "fragment": fragment,
            "uniforms": {k: list(v) if isinstance(v, tuple) else v for k, v in uniforms.items()},
            "texture": texture if shader.texture else None, "sampler": _sampler(fragment),
            "width": w, "height": h, "repeat": a.repeat, "out": out_path}
    return peer_runs(spec, tmp, row, "llvmpipe_codes", lambda image: code_errors(image, reference))


def run_compute(shader: corpus.ComputeShader, a, tmp: str) -> dict:
    import reactor
    rng = np.random.default_rng(3)
    arrays = shader.arrays(a.elements, rng)
    t0 = time.perf_counter()
    kernel = reactor.from_glsl(shader.source(), stage="compute", uniforms=shader.uniforms, cache=False,
                               name=f"{shader.name}_bench")
    row = {"name": shader.name, "build_ms": (time.perf_counter() - t0) * 1e3}
    reference = shader.reference(arrays, shader.uniforms)
    for threads in (1, 2):
        reactor.configure_threads(threads=threads)
        out = kernel(*arrays)
        row[f"ours_{threads}_ms"] = best_time(lambda: kernel(*arrays), a.repeat) * 1e3
    out = out if isinstance(out, tuple) else (out,)
    row["ours_ulps"] = ulp_error(out, reference)
    paths = []
    for k, array in enumerate(arrays):
        paths.append(os.path.join(tmp, f"buffer{k}.npy"))
        np.save(paths[-1], array)
    out_path = os.path.join(tmp, "buffers.npy")
    spec = {"kind": "compute", "compute": gl_compute(shader.source(), shader.uniforms), "buffers": paths,
            "groups": a.elements, "written": list(shader.written), "repeat": a.repeat, "out": out_path}
    return peer_runs(spec, tmp, row, "llvmpipe_ulps", lambda buffers: ulp_error(list(buffers), reference))


def _sampler(fragment: str) -> str | None:
    found = re.search(r"uniform\s+sampler2D\s+(\w+)", fragment)
    return found.group(1) if found else None


def report(row: dict) -> str:
    accuracy = (lambda k: f"{row[k][0]} codes (worst {row[k][1]}, largest error {row[k][2]:.2g} codes)") \
        if "ours_codes" in row else (lambda k: f"{row[k]:.2f} ULP")
    ours = f"{row['name']}: reactor build {row['build_ms']:.0f} ms, 1 thread {row['ours_1_ms']:.2f} ms, " \
           f"2 threads {row['ours_2_ms']:.2f} ms, {accuracy('ours_codes' if 'ours_codes' in row else 'ours_ulps')}"
    if "llvmpipe_2_ms" not in row:
        return ours + "; llvmpipe absent"
    key = "llvmpipe_codes" if "ours_codes" in row else "llvmpipe_ulps"
    return ours + f"\n  llvmpipe: first {row['llvmpipe_first_ms']:.0f} ms, 1 thread {row['llvmpipe_1_ms']:.2f} ms, " \
                  f"2 threads {row['llvmpipe_2_ms']:.2f} ms, {accuracy(key)}; llvmpipe / reactor time " \
                  f"{row['llvmpipe_1_ms'] / row['ours_1_ms']:.2f}x (1 thread), " \
                  f"{row['llvmpipe_2_ms'] / row['ours_2_ms']:.2f}x (2 threads)"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--size", type=int, default=512, help="fragment shaders: a size x size image")
    p.add_argument("--elements", type=int, default=65535, help="compute shaders: elements (one work group each)")
    p.add_argument("--repeat", type=int, default=7)
    p.add_argument("--only", nargs="*", help="run these shaders only")
    p.add_argument("--json", help="also write the rows to this file")
    a = p.parse_args()
    import routines  # noqa: F401 - the GLSL built-ins

    rows = []
    with tempfile.TemporaryDirectory(prefix="reactor-bench-glsl-") as tmp:
        for shader in [*corpus.CORPUS, *corpus.COMPUTE]:
            if a.only and shader.name not in a.only:
                continue
            run = run_compute if isinstance(shader, corpus.ComputeShader) else run_fragment
            rows.append(run(shader, a, tmp))
            print(report(rows[-1]), flush=True)
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
