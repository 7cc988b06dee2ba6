"""The five shader ports in examples/shaders run, write their picture, and their accuracy claims hold.

Each port's ``main(["--out", tmp, "--size", "128", "--repeat", "1"])`` returns its figures; the
bounds below are the ones examples/shaders/README.md states, measured at 128 and 512 pixels, with a
margin. Full precision is within float32's own rounding of the float64 reference everywhere but
where the shader itself is chaotic (the sin hash's ``fract``, a ray grazing a silhouette), and there
as close as NumPy's float32 is. Relaxed bounds are AVX-512's: there relaxed ``rsqrt``/``sqrt`` are the
RSQRT14 estimate; on other x86 targets they are exact (see docs/routines/rsqrt.md), so the relaxed
figures there are at most as large (pbr, ray marcher) or the same (sin, pow, log2, acos ...).
"""
from __future__ import annotations


import pathlib

import pytest

import example_runner as scenes

SIZE = "128"


def load(name: str):
    return scenes.load("shaders", name)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Every port run once (about 3 s in all), keyed by name."""
    return scenes.run_all("shaders", ("gltf_pbr", "noise", "raymarch", "tonemap", "sky"), tmp_path_factory.mktemp("shaders"), SIZE)


def fraction(acc: dict, key: str = "codes_differing") -> float:
    return acc[key] / acc["codes"]


@pytest.mark.parametrize("name", ["gltf_pbr", "noise", "raymarch", "tonemap", "sky"])
def test_writes_png_and_reports(runs, name):
    r = runs[name]
    image = pathlib.Path(r["image"])
    assert image.parent == r["out"] and image.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "codes differing" in r["stdout"]
    assert all(ms > 0 for ms in r["ms"].values()) and all(ms > 0 for ms in r["build_ms"].values())
    assert {"full", "relaxed", "numpy_f32"} <= set(r["accuracy"])
    # a line-by-line port is about as long as the GLSL it translates
    assert 0 < r["lines"]["dsl"] <= 1.2 * r["lines"]["glsl"]


@pytest.mark.parametrize("name", ["gltf_pbr", "tonemap", "sky"])
def test_full_precision_is_within_one_code(runs, name):
    for method in ("full", "numpy_f32"):
        acc = runs[name]["accuracy"][method]
        assert acc["max_code_diff"] <= 1, (method, acc)
        assert fraction(acc) <= 0.002, (method, acc)


def test_pbr_relaxed_ggx_cancels_at_low_roughness(runs):
    acc = runs["gltf_pbr"]["accuracy"]["relaxed"]
    # relaxed rsqrt in normalize() shifts n.h, and 1 - n.h^2 (1 - a^2) cancels at roughness 0.12
    assert fraction(acc) <= 0.01 and fraction(acc, "codes_over_1") <= 0.002
    assert acc["max_code_diff"] <= 64


def test_noise_hash_is_float32_chaotic_and_breaks_in_relaxed(runs):
    r = runs["noise"]
    full, numpy32 = r["accuracy"]["full"], r["accuracy"]["numpy_f32"]
    # the hash's fract() wraps for some lattice points whatever float32 code computes it ...
    assert fraction(full) <= 0.2 and fraction(full, "codes_over_1") <= 0.03 and full["max_code_diff"] <= 48
    # ... as NumPy's float32 does, to the same extent
    assert abs(fraction(full) - fraction(numpy32)) <= 0.03
    # relaxed sin (abs error up to 2^-11, times 43758) gives another texture; a highp hash restores it
    assert fraction(r["accuracy"]["relaxed"]) >= 0.8
    fixed = r["accuracy"]["relaxed_highp_hash"]
    assert fraction(fixed) <= 0.25 and fraction(fixed, "codes_over_1") <= 0.03
    # float64 all the way (the hash's argument too) is a different texture altogether
    assert fraction(r["pure_float64"]["full"]) >= 0.8


def test_raymarch_lanes_leave_loops_at_their_own_step(runs):
    r = runs["raymarch"]
    steps = r["march_steps"]
    assert steps["min"] < 10 and steps["max"] == 64          # some rays hit at once, some never
    full = r["accuracy"]["full"]
    # silhouettes: a ray grazing an edge may hit in float32 and miss in float64 (NumPy float32 too)
    assert fraction(full) <= 0.002 and fraction(full, "codes_over_1") <= 0.0005
    assert fraction(r["accuracy"]["numpy_f32"]) <= 0.002
    relaxed = r["accuracy"]["relaxed"]
    assert fraction(relaxed) <= 0.12 and fraction(relaxed, "codes_over_1") <= 0.03
    assert r["ms"]["full"] < r["ms"]["numpy_f32"]


def test_tonemap_relaxed_is_faithful(runs):
    acc = runs["tonemap"]["accuracy"]["relaxed"]
    assert acc["max_code_diff"] <= 1 and fraction(acc) <= 0.06


def test_sky_relaxed_is_within_a_few_codes(runs):
    acc = runs["sky"]["accuracy"]["relaxed"]
    assert acc["max_code_diff"] <= 16 and fraction(acc) <= 0.35 and fraction(acc, "codes_over_1") <= 0.01
    assert runs["sky"]["vertex_max_relative_error"] < 1e-5
