"""Run one shader on Mesa's llvmpipe (OpenGL on the CPU, headless through EGL with moderngl) and
report its times: ``bench_glsl.py`` starts this in a process of its own per configuration (llvmpipe
reads ``LP_NUM_THREADS`` when the context is made).

    python benchmarks/llvmpipe_run.py SPEC.json

SPEC holds ``kind`` ("fragment" or "compute"), the GLSL, ``uniforms``, the size or the buffers
(``.npy`` paths), ``repeat`` and ``out`` (a ``.npy`` path: the framebuffer, rows from the bottom,
or the ``written`` buffers stacked). Prints one JSON line: first (compile and first run, s), best (s), renderer.
"""
import json
import sys
import time

import numpy as np


def fragment(ctx, spec: dict):
    import moderngl
    w, h = spec["width"], spec["height"]
    t0 = time.perf_counter()
    prog = ctx.program(vertex_shader=spec["vertex"], fragment_shader=spec["fragment"])
    for name, value in spec["uniforms"].items():
        if name in prog:  # the GL compiler drops a uniform the shader never reads
            prog[name].value = value
    if spec.get("texture"):
        image = np.load(spec["texture"])
        tex = ctx.texture((image.shape[1], image.shape[0]), 4, data=image.astype("f4").tobytes(), dtype="f4")
        tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
        tex.repeat_x = tex.repeat_y = False
        tex.use(0)
        prog[spec["sampler"]].value = 0
    fbo = ctx.framebuffer(color_attachments=[ctx.texture((w, h), 4, dtype="f4")])
    vbo = ctx.buffer(np.array([-1, -1, 1, -1, -1, 1, 1, 1], "f4").tobytes())
    vao = ctx.vertex_array(prog, [(vbo, "2f", "pos")])
    fbo.use()

    def draw():
        vao.render(moderngl.TRIANGLE_STRIP)
        ctx.finish()
    draw()
    first = time.perf_counter() - t0
    best = best_time(draw, spec["repeat"])
    np.save(spec["out"], np.frombuffer(fbo.read(components=4, dtype="f4"), np.float32).reshape(h, w, 4))
    return first, best


def compute(ctx, spec: dict):
    t0 = time.perf_counter()
    shader = ctx.compute_shader(spec["compute"])
    arrays = [np.load(p) for p in spec["buffers"]]
    buffers = [ctx.buffer(a.astype("f4").tobytes()) for a in arrays]
    for binding, buf in enumerate(buffers):
        buf.bind_to_storage_buffer(binding)

    def run():
        shader.run(group_x=spec["groups"])
        ctx.finish()
    run()
    first = time.perf_counter() - t0
    for buf, a in zip(buffers, arrays):  # the timed runs start from the same inputs
        buf.write(a.astype("f4").tobytes())
    run()
    out = np.stack([np.frombuffer(buffers[k].read(), np.float32)[:spec["groups"]] for k in spec["written"]])
    best = best_time(run, spec["repeat"])
    np.save(spec["out"], out)
    return first, best


def best_time(fn, repeat: int) -> float:
    """The best of ``repeat`` timed calls of ``fn`` (s)."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    import moderngl
    spec = json.load(open(sys.argv[1]))
    ctx = moderngl.create_standalone_context(backend="egl", require=430 if spec["kind"] == "compute" else 330)
    first, best = (compute if spec["kind"] == "compute" else fragment)(ctx, spec)
    print(json.dumps({"first": first, "best": best, "renderer": ctx.info["GL_RENDERER"]}))


if __name__ == "__main__":
    main()
