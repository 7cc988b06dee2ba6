"""reactor.plan on a GLSL kernel: each ``mediump`` site (RelaxedPrecision: the relaxed tier) is
planned like the others from a reference built at full precision everywhere, and the plan says
whether the author's choice changes the stored output (skipped without the glsl extra)."""
import numpy as np
import pytest

import reactor
import routines  # noqa: F401 - the GLSL built-ins
from reactor.spirv.glsl import glslang
from reactor.spirv.grammar import MissingToolError

try:
    glslang()
    reactor.spirv.grammar.grammar_directory()
except MissingToolError as exc:  # pragma: no cover - the glsl extra is optional
    pytest.skip(str(exc), allow_module_level=True)

SHADER = """#version 450
layout(location = 0) in mediump float x;
layout(location = 1) in float y;
layout(location = 0) out vec4 color;
void main() {
    mediump float a = exp2(x * 3.0) / 8.0;   // mediump: x is
    float g = pow(y, 1.0 / 2.2);
    color = vec4(a, g, x * y, 1.0);
}
"""


def test_the_plan_says_whether_each_mediump_site_changes_the_stored_output(tmp_path):
    shade = reactor.from_glsl(SHADER)
    plan = reactor.plan(shade, inputs={"x": "unorm8", "y": "unorm8"}, output="unorm8")
    by_routine = {r.routine: r for r in plan.reports}
    exp2, pow_ = by_routine["exp2"], by_routine["pow"]
    assert exp2.where.endswith(":6") and pow_.where.endswith(":7")  # the shader's lines
    assert exp2.source == "relaxed" and pow_.source is None
    # the author's mediump changes codes: the plan raises it (to full's form, with the shortest polynomial
    # of the continuum that changes no code)
    assert exp2.source_changes and (exp2.tier == "full" or exp2.tier.startswith("full-"))
    assert plan.changes["as written"] == exp2.source_changes and plan.changes["plan"] == 0
    assert f"the source asks relaxed here: changes {exp2.source_changes:,} stored outputs" in str(plan)
    # the plan, saved and applied to the kernel, rebuilds the same code (mediump raised)
    plan.save(str(tmp_path / "p.json"))
    again = reactor.Plan.load(str(tmp_path / "p.json")).apply(shade)
    x, y = np.meshgrid(np.arange(256, dtype=np.float32) / 255, np.arange(256, dtype=np.float32) / 255)
    assert np.array_equal(again(x, y), plan.ufunc(x, y))
    full = reactor.from_glsl(SHADER.replace("mediump ", ""))
    assert np.array_equal(np.round(again(x, y) * 255), np.round(full(x, y) * 255))


def test_a_harmless_mediump_is_said_to_be_safe():
    shade = reactor.from_glsl("""#version 450
layout(location = 0) in mediump float x;
layout(location = 0) out float color;
void main() { color = sin(x) * 0.5 + 0.5; }
""")
    plan = reactor.plan(shade, inputs={"x": "unorm8"}, output="unorm8")
    (site,) = plan.reports
    assert site.source == "relaxed" and site.source_changes == 0 and site.tier == "relaxed"
    assert "the source asks relaxed here: safe" in str(plan)
