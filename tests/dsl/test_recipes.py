"""Cache hits without tracing: a kernel whose recipe (code, the values it reads, signature,
settings, target, library sources) was built before is loaded without running its body, and
any change to the recipe is a miss, so a stale object is never linked."""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import reactor
from reactor import Float, MulAdd, kernel, kernel_of
from reactor.jit import cache

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

SCALE = 2.0
OFFSET = (1.0, 0.5)


def _helper(x):
    return x * SCALE


def _source(k) -> str:
    return kernel_of(k).code.source


def _fresh():
    cache.memory_clear()


@pytest.fixture
def traces(monkeypatch):
    """Counts the bodies traced (the kernel module's emit_body calls)."""
    from reactor.kernels import kernel as kernel_module
    calls = []
    real = kernel_module.emit_body

    def counting(*args, **kw):
        calls.append(args[1])
        return real(*args, **kw)
    monkeypatch.setattr(kernel_module, "emit_body", counting)
    return calls


def _make(c=3.0):
    def body(x: Float) -> Float:
        return MulAdd(x, c, 1.0)
    return body


def test_a_hit_does_not_trace_and_computes_the_same(traces):
    first = kernel(_make(), name="recipe_probe")
    assert len(traces) == 2 and _source(first) == "compiled"  # one trace per width
    _fresh()
    again = kernel(_make(), name="recipe_probe")
    assert len(traces) == 2 and _source(again) == "recipe, disk cache"
    x = np.linspace(-3, 3, 37, dtype=np.float32)
    assert np.array_equal(first(x), again(x)) and np.array_equal(first(x[::3]), again(x[::3]))
    assert "define internal" in kernel_of(again).ir and len(traces) == 4  # the IR on demand only


@pytest.mark.parametrize("change", ["constant", "closure", "global", "helper", "option", "target", "name",
                                    "signature", "library"])
def test_every_change_misses(change, monkeypatch):
    global SCALE

    def build(c=1.0, **options):
        def body(x: Float) -> Float:
            return _helper(x) + c + OFFSET[0] + 0.25
        return kernel(body, name=options.pop("name", "recipe_change"), **options)

    base = build()
    x = np.arange(5, dtype=np.float32)
    want = base(x)
    _fresh()
    assert _source(build()) == "recipe, disk cache"
    _fresh()
    if change == "constant":
        def body(x: Float) -> Float:
            return _helper(x) + 1.0 + OFFSET[0] + 0.5  # the literal 0.25 edited
        k = kernel(body, name="recipe_change")
    elif change == "closure":
        k = build(c=1.5)
    elif change == "global":
        monkeypatch.setattr(sys.modules[__name__], "OFFSET", (2.0, 0.5))
        k = build()
    elif change == "helper":
        monkeypatch.setattr(sys.modules[__name__], "SCALE", 3.0)
        k = build()
    elif change == "option":
        k = build(fma=False, opt=2)
    elif change == "target":
        k = build(target="avx2" if reactor.get_target("host").name == "host" else "sse4")
    elif change == "name":
        k = build(name="recipe_renamed")
    elif change == "signature":
        def body(x: Float, y: Float) -> Float:
            return _helper(x) + 1.0 + OFFSET[0] + 0.25
        k = kernel(body, name="recipe_change")
    else:  # a library's source changed (an edit to routines or reactor)
        from reactor.kernels import recipe
        monkeypatch.setattr(recipe, "library_digest", lambda: "another library")
        k = build()
    assert not _source(k).startswith("recipe")
    if change in ("option", "target", "name"):
        assert np.array_equal(k(x), want)


def test_values_it_cannot_describe_fall_back_to_tracing():
    table = np.array([1.0, 2.0], np.float32)  # an array: its contents are not part of any key

    def body(x: Float) -> Float:
        return x * float(table[1])

    k = kernel(body, name="recipe_array")
    assert kernel_of(k).recipe is None
    _fresh()
    table[1] = 5.0

    def body2(x: Float) -> Float:
        return x * float(table[1])

    assert kernel(body2, name="recipe_array")(np.float32(2.0)) == 10.0


def test_a_fresh_process_hits_without_tracing(tmp_path):
    user = tmp_path / "shader.py"
    user.write_text(textwrap.dedent('''
        import routines
        from reactor import Float, kernel

        @kernel
        def glow(d: Float, r: Float) -> Float:
            return routines.exp2(-8.0 * d * d / r, precision="relaxed")
    '''))
    script = textwrap.dedent('''
        import importlib.util, sys
        import reactor
        from reactor.kernels import kernel as K
        traced = []
        real = K.emit_body
        K.emit_body = lambda *a, **k: traced.append(1) or real(*a, **k)
        spec = importlib.util.spec_from_file_location("shader", sys.argv[1])
        m = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(m)
        print(len(traced), reactor.kernel_of(m.glow).code.source)
    ''')
    env = dict(os.environ, PYTHONPATH=ROOT)
    runs = [subprocess.run([sys.executable, "-c", script, str(user)], capture_output=True, text=True, env=env,
                           cwd=ROOT, timeout=120) for _ in range(2)]
    assert [r.stdout.split(None, 1) for r in runs] == [["2", "compiled\n"], ["0", "recipe, disk cache\n"]], \
        [r.stderr[-2000:] for r in runs]


# -- stale hits that must not happen ----------------------------------------------------------

FACTOR = 2.0


def _scaled(x: Float) -> Float:
    return x * FACTOR


def test_the_same_function_object_after_a_global_is_rebound_is_built_again():
    global FACTOR
    x = np.arange(5, dtype=np.float32)
    try:
        first = kernel(_scaled, name="rebound_probe")
        assert kernel(_scaled, name="rebound_probe") is first  # nothing changed: the same ufunc
        FACTOR = 3.0
        second = kernel(_scaled, name="rebound_probe")
        assert second is not first and np.array_equal(second(x), x * 3)
        _fresh()
        FACTOR = 2.0  # back: the recipe of the first build again
        assert np.array_equal(kernel(_scaled, name="rebound_probe")(x), x * 2)
    finally:
        FACTOR = 2.0


def _at_line(blank_lines: int):
    """The same body compiled at a later line (as after an edit above it)."""
    namespace = {"Float": Float, "glsl": __import__("routines.glsl", fromlist=["pow"])}
    src = "\n" * blank_lines + "def body(x: Float) -> Float:\n    return glsl.pow(x, 1.0 / 2.2)\n"
    exec(compile(src, "/virtual/shader.py", "exec"), namespace)
    return namespace["body"]


def test_a_body_moved_to_other_lines_is_a_miss():
    """The lines are in error messages, routine call sites and precision plans."""
    a = kernel(_at_line(0), name="moved_probe")
    b = kernel(_at_line(5), name="moved_probe")
    assert kernel_of(a).recipe != kernel_of(b).recipe
    assert [c.where for c in kernel_of(a).routines] != [c.where for c in kernel_of(b).routines]
    assert kernel_of(b).routines[0].where.endswith(":7")


def test_constant_vectors_and_matrices_are_keyed_by_their_values(traces):
    """A module's vec3 or a closure's mat2 keys the recipe by its components: a warm build skips
    tracing, and another value (rebound, or changed in place by a swizzle) is another build."""
    x = np.arange(4, dtype=np.float32)
    outs, keys = [], []
    for scale in (1.0, 2.0, 1.0):
        m = reactor.mat2(scale)

        def body(v: Float) -> Float:
            return (m @ reactor.vec2(v, 1.0)).x
        k = kernel(body, name="mat_probe")
        keys.append(kernel_of(k).recipe)
        outs.append(k(x))
    assert None not in keys and keys[0] != keys[1] and keys[0] == keys[2]
    assert np.array_equal(outs[0], x) and np.array_equal(outs[1], 2 * x) and np.array_equal(outs[2], x)
    light = reactor.vec3(0.5, 0.25, 2.0)

    def lit(v: Float) -> Float:
        return (light * v).z
    assert np.array_equal(kernel(lit, name="vec_probe")(x), 2 * x)
    light.z = 3.0  # in place: the same object, other components
    assert np.array_equal(kernel(lit, name="vec_probe")(x), 3 * x)
    _fresh()
    traced = len(traces)
    assert np.array_equal(kernel(lit, name="vec_probe")(x), 3 * x) and len(traces) == traced  # from the recipe
