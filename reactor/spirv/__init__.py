"""SPIR-V and GLSL in: real shaders as NumPy ufuncs, translated through reactor's DSL and its
control-flow core (``translate``), from a binary decoded by the Khronos grammars (``grammar``,
``binary``); GLSL through glslang (``glsl``). The tools are the ``glsl`` extra."""
from __future__ import annotations

import os
import typing

from .binary import SpirvError, decode
from .grammar import MissingToolError
from .translate import kernel_body, set_builtins

__all__ = ["from_spirv", "from_glsl", "SpirvError", "MissingToolError", "set_builtins"]


def from_spirv(binary_or_path: bytes | str | os.PathLike, *, uniforms: dict | None = None,
               samplers: dict | None = None, name: str | None = None, validate: bool = True,
               **options: typing.Any):
    """A fragment shader's SPIR-V (the bytes, or a file's path) as a kernel: a NumPy ufunc (a
    gufunc where vectors are involved). Its ``in`` variables, by location, are the inputs (a
    ``vecN`` as an (..., N) array; ``gl_FragCoord`` last where the shader reads it); its ``out``
    variables the outputs; the members of its uniform blocks named in ``uniforms`` are build-time
    constants, the others arguments after the inputs, in declaration order; then each
    ``sampler2D``/``sampler3D`` is a ``Texture2D``/``Texture3D`` argument (an (H, W, C) or (D, H, W, C)
    array) with the wrap and filter ``samplers={name: (wrap, filter)}`` names (default clamp,
    linear). The module is checked by ``spirv-val`` first where SPIRV-Tools is installed
    (``validate=False``: not). ``options`` are ``reactor.kernel``'s (``precision=``, ``fma=`` ...)."""
    from ..kernels.kernel import kernel
    from .glsl import validate as spirv_val

    data = binary_or_path if isinstance(binary_or_path, (bytes, bytearray)) else open(binary_or_path, "rb").read()
    if validate:
        decode(bytes(data))  # our own message for what is no SPIR-V at all, then the validator's
        spirv_val(bytes(data))
    body, translator = kernel_body(bytes(data), uniforms, samplers)
    return kernel(body, name=name or translator.entry_name, **options)


def from_glsl(source_or_path: str | os.PathLike, stage: str = "fragment", *, uniforms: dict | None = None,
              samplers: dict | None = None, name: str | None = None, **options: typing.Any):
    """A GLSL shader (its text, or a file's path) compiled by glslang to SPIR-V, then as
    :func:`from_spirv`. A compile error is one ``SpirvError`` with glslang's message (file and line).

    ``stage="shadertoy"``: a Shadertoy shader (``void mainImage(out vec4 fragColor, in vec2
    fragCoord)``), run with no edit through the prelude of :data:`reactor.spirv.glsl.SHADERTOY`:
    the kernel takes ``fragCoord`` as an (..., 2) array (pixel centres, the origin at the bottom
    left as in WebGL) and gives ``fragColor``; ``iResolution`` and ``iTime`` are arguments unless
    ``uniforms`` gives them, ``iTimeDelta``, ``iFrame``, ``iMouse``, ``iDate`` are 0 and
    ``iSampleRate`` 44100 unless it does.

    ``stage="webgl"``: a WebGL-style fragment shader (GLSL ES 1.00 as three.js and glslify write
    it: ``varying`` inputs, ``texture2D``, ``gl_FragColor``), run with no edit through the prelude
    of :data:`reactor.spirv.glsl.WEBGL`: its ``varying`` variables, in declaration order, are the
    inputs and ``gl_FragColor`` the output.

    Uniforms outside a block, as desktop and WebGL shaders declare them, are taken like a block's
    members; ``in``/``out`` variables with no ``location`` are numbered in declaration order."""
    from .glsl import SHADERTOY_DEFAULTS, compile_glsl, shadertoy_source, webgl_source

    if stage == "shadertoy":
        source_or_path, stage = shadertoy_source(source_or_path), "fragment"
        uniforms = {**SHADERTOY_DEFAULTS, **(uniforms or {})}
    elif stage == "webgl":
        source_or_path, stage = webgl_source(source_or_path), "fragment"
    spirv = compile_glsl(source_or_path, stage, use_disk=bool(options.get("cache", True)))
    return from_spirv(spirv, uniforms=uniforms, samplers=samplers, name=name, validate=False, **options)
