"""Kernels and Functions travel as their recipe (pickle, cloudpickle, deepcopy, multiprocessing,
dask): rebuilt on the other side through its caches, for its CPU, computing the same bits."""
from __future__ import annotations

import copy
import multiprocessing
import os
import pickle
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import reactor
import routines
from reactor import Float

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
X = np.linspace(-4, 4, 1001, dtype=np.float32)

MODULE = textwrap.dedent('''
    import reactor, routines
    from reactor import Float, vec3, vec4

    GAIN = 2.5

    @reactor.kernel
    def shade(x: Float, y: Float) -> Float:
        """a user's kernel in an importable module"""
        return x * GAIN + routines.exp2(y, precision="relaxed")

    @reactor.kernel
    def tint(n: vec3, s: Float) -> vec4:
        return vec4(n * s, 1.0)

    @reactor.function
    def twice(a: Float) -> Float:
        return a * 2.0
''')

MAIN = textwrap.dedent('''
    import pickle, sys
    BLOCK = sys.argv[1] == "no-cloudpickle"
    if BLOCK:
        sys.modules["cloudpickle"] = None  # as where it is not installed: the body goes as source
    import numpy as np
    import reactor, routines
    from reactor import Float
    OFFSET = 0.25

    @reactor.kernel
    def in_main(x: Float) -> Float:
        return routines.log2(x) + OFFSET

    @reactor.function
    def f_main(a: Float) -> Float:
        return a - OFFSET

    sys.stdout.buffer.write(pickle.dumps((in_main, f_main)))
''')


def _bits(a):
    return np.asarray(a).view(np.uint32)


@pytest.fixture
def shader_module(tmp_path, monkeypatch):
    (tmp_path / "travel_shaders.py").write_text(MODULE)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(tmp_path), ROOT]))
    import importlib
    sys.modules.pop("travel_shaders", None)
    return importlib.import_module("travel_shaders")


def test_routine_variants_pickle_as_their_call():
    for u in (routines.jit("exp2"), routines.jit("pow", "relaxed", fma=False), routines.jit("log2", width=4)):
        data = pickle.dumps(u)
        assert len(data) < 200 and b"ELF" not in data  # the recipe, not the machine code
        assert pickle.loads(data) is u and copy.deepcopy(u) is u and copy.copy(u) is u
    cloudpickle = pytest.importorskip("cloudpickle")
    assert cloudpickle.loads(cloudpickle.dumps(routines.jit("exp2"))) is routines.jit("exp2")


def test_numpy_ufuncs_still_pickle_as_numpy_does():
    assert pickle.loads(pickle.dumps(np.exp2)) is np.exp2 and copy.deepcopy(np.add) is np.add


def test_in_a_fresh_process_the_same_bits(shader_module, tmp_path):
    payload = pickle.dumps((routines.jit("exp2"), routines.jit("pow", "relaxed"), shader_module.shade,
                            shader_module.twice))
    script = textwrap.dedent('''
        import pickle, sys
        import numpy as np
        e, p, s, t = pickle.loads(sys.stdin.buffer.read())
        x = np.linspace(-4, 4, 1001, dtype=np.float32)
        out = np.stack([e(x), p(np.abs(x), x), s(x, x), np.float32(t(1.5)) + 0 * x])
        sys.stdout.buffer.write(out.tobytes())
    ''')
    proc = subprocess.run([sys.executable, "-c", script], input=payload, capture_output=True, timeout=120,
                          cwd=ROOT)
    assert proc.returncode == 0, proc.stderr.decode()[-2000:]
    got = np.frombuffer(proc.stdout, np.float32).reshape(4, -1)
    want = [routines.jit("exp2")(X), routines.jit("pow", "relaxed")(np.abs(X), X), shader_module.shade(X, X)]
    for g, w in zip(got, want):
        assert np.array_equal(_bits(g), _bits(w))
    assert got[3][0] == 3.0


@pytest.mark.parametrize("how", ["cloudpickle", "no-cloudpickle"])
def test_a_kernel_defined_in_main_travels_by_value(how, tmp_path):
    if how == "cloudpickle":
        pytest.importorskip("cloudpickle")
    script = tmp_path / "scene.py"  # a script with its source on disk (python -c has none)
    script.write_text(MAIN)
    proc = subprocess.run([sys.executable, str(script), how], capture_output=True, timeout=120, cwd=ROOT,
                          env=dict(os.environ, PYTHONPATH=ROOT))
    assert proc.returncode == 0, proc.stderr.decode()[-2000:]
    k, f = pickle.loads(proc.stdout)  # here __main__ is pytest: the bodies came along
    x = np.abs(X) + 0.5
    assert np.array_equal(_bits(k(x)), _bits(routines.jit("log2")(x) + np.float32(0.25)))
    assert f(1.25) == 1.0


def test_what_cannot_travel_says_why(tmp_path):
    source = MAIN.replace("OFFSET = 0.25", "OFFSET = 0.25\nclass Opaque: pass\nTHING = Opaque()").replace(
        "return routines.log2(x) + OFFSET", "return routines.log2(x) + (OFFSET if THING else 0.0)")
    script = tmp_path / "opaque.py"
    script.write_text(source)
    proc = subprocess.run([sys.executable, str(script), "no-cloudpickle"], capture_output=True, text=True,
                          timeout=120, cwd=ROOT, env=dict(os.environ, PYTHONPATH=ROOT))
    assert proc.returncode != 0
    assert "PicklingError" in proc.stderr and "'THING'" in proc.stderr and "cloudpickle" in proc.stderr


def _apply(u, x):
    return u(x, x)


@pytest.mark.parametrize("method", ["spawn", "forkserver", "fork"])
def test_multiprocessing_pools(shader_module, method):
    ctx = multiprocessing.get_context(method)
    with ctx.Pool(1) as pool:
        for u in (routines.jit("atan2"), shader_module.shade):
            got = pool.apply(_apply, (u, X))
            assert np.array_equal(_bits(got), _bits(u(X, X)))


def test_dask_arrays_threads_and_gufuncs(shader_module):
    da = pytest.importorskip("dask.array")
    x = np.random.default_rng(3).random((300, 500), dtype=np.float32) * 8 - 4
    dx = da.from_array(x, chunks=(100, 128))
    r = shader_module.shade(dx, dx)  # NumPy hands the call to dask: lazy, chunk by chunk
    assert isinstance(r, da.Array)
    assert np.array_equal(_bits(r.compute(scheduler="threads")), _bits(shader_module.shade(x, x)))
    n = np.random.default_rng(4).random((60, 70, 3), dtype=np.float32)
    g = reactor.map_blocks(shader_module.tint, da.from_array(n, chunks=(25, 30, 2)), da.from_array(x[:60, :70],
                                                                                                 chunks=20))
    assert g.shape == (60, 70, 4)
    assert np.array_equal(_bits(g.compute(scheduler="threads")), _bits(shader_module.tint(n, x[:60, :70])))


def test_dask_operands_of_a_dtype_the_kernel_does_not_take_are_refused_when_the_graph_is_made():
    da = pytest.importorskip("dask.array")
    exp2 = routines.jit("exp2")
    with pytest.raises(TypeError, match=r"argument 'x' of 'exp2_full\w*' is float64, and the kernel computes "
                                        r"in float32: pass it as float32 \(a.astype\(np.float32\)\)"):
        reactor.map_blocks(exp2, da.from_array(np.linspace(0, 1, 8), chunks=4))
    x = np.linspace(0, 1, 8, dtype=np.float32)
    assert np.array_equal(reactor.map_blocks(exp2, da.from_array(x, chunks=4)).compute(), exp2(x))


def test_dask_local_cluster_of_processes(shader_module):
    da = pytest.importorskip("dask.array")
    distributed = pytest.importorskip("distributed")
    x = np.random.default_rng(5).random((256, 512), dtype=np.float32) * 8 - 4
    dx = da.from_array(x, chunks=(64, 256))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=40) as cluster, distributed.Client(cluster):
        for u in (routines.jit("exp2"), routines.jit("log2", "relaxed")):
            assert np.array_equal(_bits(u(dx).compute()), _bits(u(x)))
        assert np.array_equal(_bits(shader_module.shade(dx, dx).compute()), _bits(shader_module.shade(x, x)))
        n = np.random.default_rng(6).random((64, 32, 3), dtype=np.float32)
        g = reactor.map_blocks(shader_module.tint, da.from_array(n, chunks=(16, 32, 3)), np.float32(0.5))
        assert np.array_equal(_bits(g.compute()), _bits(shader_module.tint(n, np.float32(0.5))))


def test_sweeps_on_a_cluster_give_the_local_figures():
    distributed = pytest.importorskip("distributed")
    from routines.lab import sweep
    from routines.lab.pairs import stratified
    u, p = routines.jit("log2", "relaxed"), routines.jit("pow")
    lo, hi = 0x3F000000, 0x3F000000 + (1 << 23)
    local = sweep(u, "log2", "relaxed", start=lo, stop=hi, chunk=1 << 21, progress=False)
    local_pairs = stratified(p, "pow", "full", strata=4, progress=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=40) as cluster:
        remote = sweep(u, "log2", "relaxed", start=lo, stop=hi, chunk=1 << 21, progress=False,
                       scheduler=cluster.scheduler_address)
        remote_pairs = stratified(p, "pow", "full", strata=4, progress=False, scheduler=cluster.scheduler_address)
    for a, b in ((local, remote), (local_pairs, remote_pairs)):
        ja, jb = a.to_json(), b.to_json()
        ja.pop("seconds"), jb.pop("seconds")
        assert ja == jb


def test_cluster_example_renders_the_same_bits_everywhere(tmp_path):
    pytest.importorskip("distributed")
    import importlib.util
    spec = importlib.util.spec_from_file_location("reactor_cluster_example", os.path.join(ROOT, "examples",
                                                                                          "cluster.py"))
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    figures = example.main(["--size", "1024", "--chunk", "256", "--out", str(tmp_path)])
    runs = [v for v in figures.values() if isinstance(v, dict)]
    assert len(runs) == 3 and all(r["same_bits"] for r in runs)
    assert figures["pickle_round_trip_ms"] < 50
