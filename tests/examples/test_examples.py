"""The examples run, write their picture, and their numeric claims hold.

Each example is loaded from examples/*.py and its ``main(["--out", tmp])`` is
called; it returns a dict of its figures, which these tests assert (no stdout
parsing). The bounds are the ones examples/README.md states.
"""
from __future__ import annotations

import contextlib
import importlib.util
import io
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
NAMES = ("gamma", "specular", "tonemap", "inspect_ir", "custom_routine")


def _host_has(feature: str) -> bool:
    from reactor import get_target
    return feature in get_target("host").feature_set


# Relaxed rsqrt and sqrt are the hardware estimate: RSQRT14 (< 2^-14) with AVX-512, RSQRTPS
# (< 1.5 * 2^-12) elsewhere. The bounds that depend on it are the ones measured with AVX-512.
AVX512 = _host_has("avx512f")


def load(name: str):
    spec = importlib.util.spec_from_file_location(f"reactor_example_{name}", EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run(name: str, tmp_path, *args) -> dict:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        result = load(name).main(["--out", str(tmp_path), *args])
    image = pathlib.Path(result["image"])
    assert image.parent == tmp_path and image.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert out.getvalue().strip(), f"{name} printed nothing"
    return result


def test_gamma_relaxed_is_within_one_code_of_correct_rounding(tmp_path):
    r = run("gamma", tmp_path, "--repeat", "1")
    n = r["pixels"]
    assert n == 600 * 512
    for curve in ("srgb", "gamma"):
        for method in ("full", "relaxed", "numpy"):
            m = r[curve][method]
            assert m["decode_ms"] > 0 and m["encode_ms"] > 0
            # an 8-bit texture copied to an 8-bit target comes back unchanged, whatever the precision
            assert m["round_trip"]["pixels"] == 0
            for stage in ("encode", "pipeline"):
                assert m[stage]["max_diff"] <= 1
                assert m[stage]["faithful"]
        # full and NumPy float32: a handful of pixels one code off (ties within float32 rounding)
        for method in ("full", "numpy"):
            assert r[curve][method]["encode"]["pixels"] <= 50
            assert r[curve][method]["pipeline"]["pixels"] <= 50
            assert r[curve][method]["encode"]["max_error_codes"] < 1e-3
        relaxed = r[curve]["relaxed"]
        # relaxed: a few percent of the pixels round the other way, never further than 1 code
        assert 0 < relaxed["encode"]["pixels"] <= 0.06 * n
        assert relaxed["pipeline"]["pixels"] <= 0.12 * n
        assert relaxed["encode"]["max_error_codes"] < 0.1
        assert relaxed["pipeline"]["max_error_codes"] < 0.25
        assert relaxed["decode_max_rel_error"] < 2e-3


def test_specular_full_and_relaxed_renders_differ_by_at_most_3_of_255(tmp_path):
    r = run("specular", tmp_path, "--repeat", "1")
    assert r["finite"]
    ref = r["vs_float64"]
    assert ref["full"]["max_diff"] <= 1 and ref["numpy"]["max_diff"] <= 1
    assert ref["relaxed pow only"]["max_diff"] <= 3       # pow(n.h, 250) on the water: 3 codes
    assert ref["relaxed pow only"]["max_diff_land"] <= 1  # shininess 16: within 1 code
    if AVX512:
        assert r["max_diff_full_relaxed"] <= 3
        assert ref["relaxed"]["max_diff"] <= 3 and ref["relaxed"]["max_diff_land"] <= 1
        assert ref["relaxed rsqrt only"]["max_diff"] <= 2
    assert 0 < r["water_fraction"] < 0.05
    assert all(t > 0 for t in r["ms"].values())


def test_tonemap_output_is_finite_and_in_unit_range(tmp_path):
    r = run("tonemap", tmp_path, "--repeat", "1")
    assert r["dynamic_range"] > 1e6
    for precision in ("full", "relaxed"):
        assert r[f"{precision}_finite"]
        lo, hi = r[f"{precision}_range"]
        assert 0.0 <= lo and hi <= 1.0
        assert r["max_diff_vs_float64"][precision] <= 1
    la = r["log_average_luminance"]
    assert abs(la["full"] / la["float64"] - 1) < 1e-6
    assert abs(la["relaxed"] / la["float64"] - 1) < 1e-3
    assert r["max_diff_vs_float64"]["numpy"] <= 1


@pytest.mark.skipif(not _host_has("fma"), reason="the host has no FMA instructions")
def test_inspect_ir_finds_fma_only_in_the_fma_build(tmp_path):
    r = run("inspect_ir", tmp_path, "--quiet")
    assert r["ir_fma_calls"]["on"] > 0 and r["ir_fma_calls"]["off"] == 0
    assert r["asm_fma"]["on"] > 0 and r["asm_fma"]["off"] == 0
    assert r["ufunc_vfmadd"]["on"] > 0 and r["ufunc_vfmadd"]["off"] == 0
    assert r["asm_instructions"]["on"] < r["asm_instructions"]["off"]
    assert r["ir_lines_differing"] > 0
    # the full-precision routine is within Vulkan's 3 + 2|x| ULP on [-8, 8) either way
    assert r["max_ulp"]["on"] < 4 and r["max_ulp"]["off"] < 4
    # python -m reactor dump FILE.py:NAME works on a routine of the user's
    assert r["dump"]["status"] == 0 and r["dump"]["instructions"] > 0 and r["dump"]["vfmadd"] == 0


def test_custom_routine_broadcasts_like_numpy_float64(tmp_path):
    r = run("custom_routine", tmp_path)
    assert r["sweep_shape"] == (241, 301)
    assert r["scene_shape"] == (5, 360, 540)
    relaxed_bound = 2e-4 if AVX512 else 2e-3                # relaxed sqrt: the hardware estimate
    assert r["max_abs_error_relaxed"] < relaxed_bound
    assert r["scene_max_abs_error"] < relaxed_bound
    assert r["max_abs_error_full"] < 1e-6
    assert r["broadcast_equals_dense"] and r["strided_equals_vector"]
    assert r["zero_outside_radius"] and r["where_respected"]
    if AVX512:
        assert r["monotone_in_distance"]


def test_reactor_dump_of_a_kernel_in_an_example_file():
    from reactor.__main__ import main as reactor_cli

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        status = reactor_cli(["dump", str(EXAMPLES / "custom_routine.py") + ":falloff", "--what", "ir"])
    assert status == 0
    assert "define" in out.getvalue() and "falloff" in out.getvalue()


@pytest.mark.parametrize("name", NAMES)
def test_readme_picture_is_committed_and_small(name):
    image = ROOT / "docs" / "img" / "examples" / f"{name}.png"
    assert image.exists(), f"run: python examples/{name}.py --out docs/img/examples"
    assert image.stat().st_size < 300_000
