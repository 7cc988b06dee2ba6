"""GLSL shaders on reactor (``reactor.from_glsl``) and on Mesa's llvmpipe (OpenGL on the CPU, headless
through EGL with moderngl), same run: the best render time of each, one thread and two, and the
8-bit codes each gets wrong against a float64 evaluation of the same shader in NumPy. A shader
Shadertoy-style (``mainImage``) runs unchanged on both: reactor through its prelude, llvmpipe
through the equivalent GLSL 3.30 wrapper. Each llvmpipe configuration runs in a process of its own
(``LP_NUM_THREADS`` is read when the context is made); absent peers are reported absent.

    python benchmarks/bench_glsl.py [--size 512] [--repeat 7]

Needs the glsl extra and, for llvmpipe, ``pip install moderngl`` with Debian's ``libegl1
libegl-mesa0 libgl1-mesa-dri``.
"""
import argparse
import json
import os
import pathlib
import subprocess
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]

#: name -> (file, its float64 evaluation over fragCoord (H, W, 2) at time t, giving (H, W, 3))
CORPUS = {"rings": "examples/glsl/rings.frag"}


def rings_float64(coord: np.ndarray, width: int, height: int, t: float) -> np.ndarray:
    p = (2.0 * coord - np.array([width, height], float)) / height
    r = np.hypot(p[..., 0], p[..., 1])
    rings = 0.5 + 0.5 * np.cos(24.0 * r - 3.0 * t)
    a, b = np.array([0.08, 0.1, 0.2]), np.array([1.0, 0.75, 0.3])
    k = (rings * np.exp(-1.5 * r))[..., None]
    col = a * (1 - k) + b * k
    col = np.where((r < 0.1)[..., None], 1.0, col)
    return col ** (1.0 / 2.2)


REFERENCE = {"rings": rings_float64}

LLVMPIPE = r'''
import json, sys, time
import numpy as np
import moderngl
source, width, height, t, repeat = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5])
ctx = moderngl.create_standalone_context(backend="egl")
fs = """#version 330
uniform vec3 iResolution; uniform float iTime; uniform float iTimeDelta; uniform int iFrame;
uniform vec4 iMouse; uniform vec4 iDate; uniform float iSampleRate;
out vec4 reactor_fragColor;
""" + open(source).read() + """
void main() { mainImage(reactor_fragColor, gl_FragCoord.xy); }
"""
t0 = time.perf_counter()
prog = ctx.program(vertex_shader="#version 330\nin vec2 pos;\nvoid main() { gl_Position = vec4(pos, 0.0, 1.0); }",
                   fragment_shader=fs)
prog["iResolution"].value = (width, height, 1.0)
if "iTime" in prog:
    prog["iTime"].value = t
fbo = ctx.framebuffer(color_attachments=[ctx.texture((width, height), 4, dtype="f4")])
vbo = ctx.buffer(np.array([-1, -1, 1, -1, -1, 1, 1, 1], "f4").tobytes())
vao = ctx.vertex_array(prog, [(vbo, "2f", "pos")])
fbo.use()
vao.render(moderngl.TRIANGLE_STRIP)
ctx.finish()
first = time.perf_counter() - t0
times = []
for _ in range(repeat):
    t0 = time.perf_counter()
    vao.render(moderngl.TRIANGLE_STRIP)
    ctx.finish()
    times.append(time.perf_counter() - t0)
image = np.frombuffer(fbo.read(components=4, dtype="f4"), np.float32).reshape(height, width, 4)[::-1]
np.save(sys.argv[6], image)
print(json.dumps({"first": first, "best": min(times), "renderer": ctx.info["GL_RENDERER"]}))
'''


def codes(x: np.ndarray) -> np.ndarray:
    return np.round(np.clip(np.nan_to_num(x), 0, 1) * 255).astype(np.int32)


def llvmpipe(path: str, width: int, height: int, t: float, repeat: int, threads: int, out: str) -> dict | None:
    env = dict(os.environ, LP_NUM_THREADS=str(threads))
    try:
        run = subprocess.run([sys.executable, "-c", LLVMPIPE, path, str(width), str(height), str(t), str(repeat), out],
                             capture_output=True, text=True, timeout=600, env=env)
    except (OSError, subprocess.TimeoutExpired):
        return None
    if run.returncode != 0:
        print(f"  llvmpipe absent or failed: {run.stderr.strip().splitlines()[-1] if run.stderr.strip() else '?'}")
        return None
    return json.loads(run.stdout.strip().splitlines()[-1])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--size", type=int, default=512)
    p.add_argument("--repeat", type=int, default=7)
    p.add_argument("--time", type=float, default=1.0)
    a = p.parse_args()
    import reactor
    import routines  # noqa: F401 - the GLSL built-ins
    from reactor.spirv.render import pixel_centres

    w = h = a.size
    coord = pixel_centres(w, h, bottom_left=True)
    for name, rel in CORPUS.items():
        path = str(ROOT / rel)
        t0 = time.perf_counter()
        kernel = reactor.from_glsl(path, stage="shadertoy", uniforms={"iResolution": (w, h, 1.0), "iTime": a.time},
                                   cache=False, name=f"{name}_bench")
        build = time.perf_counter() - t0
        reference = codes(REFERENCE[name](coord.astype(float), w, h, a.time))
        ours = {}
        for threads in (1, 2):
            reactor.configure_threads(threads=threads)
            image = kernel(coord)
            best = min(_timed(kernel, coord) for _ in range(a.repeat))
            ours[threads] = best
        wrong = int((codes(image[..., :3]) != reference).sum())
        worst = int(np.abs(codes(image[..., :3]) - reference).max())
        print(f"{name} {w}x{h}: reactor build {build * 1e3:.0f} ms, 1 thread {ours[1] * 1e3:.2f} ms, "
              f"2 threads {ours[2] * 1e3:.2f} ms; codes wrong {wrong} of {reference.size} (worst {worst})")
        for threads, lp_threads in ((1, 0), (2, 2)):
            out = str(pathlib.Path(os.environ.get("TMPDIR", "/tmp")) / f"reactor-bench-{name}-{threads}.npy")
            got = llvmpipe(path, w, h, a.time, a.repeat, lp_threads, out)
            if got is None:
                continue
            image = np.load(out)
            lp_wrong = int((codes(image[..., :3]) != reference).sum())
            lp_worst = int(np.abs(codes(image[..., :3]) - reference).max())
            print(f"  llvmpipe ({got['renderer']}), {threads} thread(s): first draw {got['first'] * 1e3:.0f} ms, "
                  f"best {got['best'] * 1e3:.2f} ms; codes wrong {lp_wrong} (worst {lp_worst}); "
                  f"llvmpipe / reactor time {got['best'] / ours[threads]:.2f}x")


def _timed(kernel, coord) -> float:
    t0 = time.perf_counter()
    kernel(coord)
    return time.perf_counter() - t0


if __name__ == "__main__":
    main()
