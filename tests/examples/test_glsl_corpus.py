"""The GLSL corpus (examples/glsl/corpus): every public shader, as its package holds it, compiles
and runs through reactor.from_glsl, and agrees with its float64 evaluation in NumPy: every 8-bit
code within one of it (a fragment shader; fbm's sin hash aside), every compute result within a
few float32 ULPs. Skipped without the glsl extra."""
from __future__ import annotations

import pathlib
import sys

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

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "examples" / "glsl" / "corpus"))
import corpus  # noqa: E402

SIZE = 48
#: codes differing from float64 (of all channels) at most, where float32 rounding meets a code boundary
SHARE = {"fbm": 0.2}  # the hash fract(sin(a) * 43758.5) magnifies a's rounding 43758 times


def codes(x: np.ndarray) -> np.ndarray:
    return np.round(np.clip(np.nan_to_num(x), 0, 1) * 255).astype(np.int32)


def test_the_corpus_has_a_dozen_public_shaders_each_with_its_licence():
    public = [s for s in [*corpus.CORPUS, *corpus.COMPUTE] if s.public]
    assert len(public) >= 12 and any(isinstance(s, corpus.ComputeShader) for s in public)
    for s in public:
        licence = (corpus.HERE / s.licence).read_text(encoding="utf-8")
        assert any(word in licence for word in ("MIT", "Permission is hereby granted", "Apache License",
                                                "public domain")), s.name


@pytest.mark.parametrize("shader", corpus.CORPUS, ids=lambda s: s.name)
def test_a_fragment_shader_agrees_with_its_float64_evaluation(shader):
    uniforms = shader.uniforms_for(SIZE, SIZE)
    kernel = reactor.from_glsl(shader.source(), stage=shader.stage, uniforms=uniforms)
    inputs = [x.astype(np.float32) for x in shader.inputs(SIZE, SIZE)]
    image = corpus.test_image(SIZE, SIZE)
    got = kernel(*inputs, *([image] if shader.texture else []))
    want = shader.reference([x.astype(float) for x in inputs], image, uniforms)
    diff = np.abs(codes(got[0] if isinstance(got, tuple) else got) - codes(want))
    if shader.name in SHARE:
        assert (diff != 0).mean() <= SHARE[shader.name]
    else:
        assert diff.max() <= 1 and (diff != 0).mean() <= 0.02


@pytest.mark.parametrize("shader", corpus.COMPUTE, ids=lambda s: s.name)
def test_a_compute_shader_agrees_with_its_float64_evaluation(shader):
    kernel = reactor.from_glsl(shader.source(), stage="compute", uniforms=shader.uniforms)
    arrays = shader.arrays(1000, np.random.default_rng(0))
    got = kernel(*arrays)
    got = got if isinstance(got, tuple) else (got,)
    assert len(got) == len(shader.written)
    for out, want in zip(got, shader.reference(arrays, shader.uniforms)):
        ulps = np.abs(out.astype(float) - want) / np.spacing(np.abs(want).astype(np.float32))
        assert ulps.max() <= 6


def test_sources_are_assembled_as_their_tools_would(tmp_path, monkeypatch):
    """glslify's require (a renamed export becomes a #define), three.js's #include <chunk>."""
    text = corpus.assemble(corpus.HERE / "glsl-dither" / "example" / "index.frag")
    assert "#pragma glslify" not in text and "#define dither dither8x8" in text
    assert text.count("float luma(vec3 color)") == 1  # required twice (8x8 needs it), inlined once
    agx = corpus.assemble(corpus.HERE.parent / "agx_output.frag")
    assert "vec3 AgXToneMapping( vec3 color )" in agx and "#include" not in agx
