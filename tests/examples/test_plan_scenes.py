"""examples/plan/scenes.py: every planned scene changes no stored output and says how it was proved."""
import importlib.util
import pathlib

import numpy as np

import reactor

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_scenes_plan_with_no_change(tmp_path):
    spec = importlib.util.spec_from_file_location("reactor_plan_scenes", ROOT / "examples" / "plan" / "scenes.py")
    scenes = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(scenes)
    r = scenes.main(["--out", str(tmp_path), "--size", "48", "--only", "srgb_blit", "exposure", "linear_half",
                     "gltf_pbr"])
    assert (tmp_path / "plans.json").exists() and (tmp_path / "chart.png").exists()
    by = {(x["scene"], x["format"]): x for x in r["results"]}
    assert len(by) == 9  # linear_half: float16, unorm16 and unorm8
    for x in r["results"]:
        p = x["plan"]
        assert p["changes"]["plan"] == 0 and p["proof"] == "exhaustive"
        assert p["cycles"]["plan"] <= p["cycles"]["all full"] + 1e-9
    blit = by[("srgb_blit", "unorm8")]["plan"]
    assert [s["tier"] for s in blit["reports"]] == ["relaxed", "relaxed"]
    if "avx512f" in reactor.get_target("host").feature_set:
        # with VGETEXPPS/VGETMANTPS pow's cost is its polynomials, which relaxing shortens; elsewhere
        # the portable exponent split (the same in both tiers) bounds it and the saving is smaller
        assert blit["cycles"]["all full"] / blit["cycles"]["plan"] > 1.3
    else:
        assert blit["cycles"]["plan"] < blit["cycles"]["all full"]
    assert by[("srgb_blit", "unorm10")]["plan"]["changes"]["all relaxed"] > 0
    exposure = {s["routine"]: s["tier"] for s in by[("exposure", "unorm8")]["plan"]["reports"]}
    assert exposure == {"exp2": "relaxed", "pow": "full"}  # whole stops: exp2 exact at every tier
    assert np.isfinite(by[("gltf_pbr", "unorm8")]["speedup"])
