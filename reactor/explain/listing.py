"""Reading optimized IR and assembly built with source lines: every instruction with its place.

A module built with ``lines`` (``reactor.ir.emitter.ModuleEmitter``) gives each
instruction a debug location: the user's file and line, and a column that encodes
the group (0: the user's own code, k: the k-th routine emitted there, plus
``TAIL_COLUMN`` in a kernel's width-1 tail body). LLVM keeps the locations through
optimization (``!dbg``) and writes them into the assembly as ``.loc`` directives;
this module reads both texts back into :class:`Instruction` lists, per function.
"""
from __future__ import annotations

import dataclasses
import os
import re

from ..ir.emitter import TAIL_COLUMN


@dataclasses.dataclass(frozen=True)
class Instruction:
    """One IR instruction or machine instruction and where it came from (line 0: plumbing)."""

    text: str
    file: str | None
    line: int
    group: int  # 0: the user's own code; k: routine k
    tail: bool  # from a kernel's width-1 tail body
    block: str

    @property
    def key(self) -> tuple:
        return (self.file, self.line, self.group)


_META = re.compile(r"^!(\d+) = (?:distinct )?!(\w+)\((.*)\)\s*$")
_FIELD = re.compile(r'(\w+): ("(?:[^"\\]|\\.)*"|![0-9]+|[\w|. -]+?)(?:,|$)')
_DEFINE = re.compile(r'^define [^@]*@("?)([^"(]+)\1\(')
_DBG = re.compile(r",?\s*!dbg !(\d+)")


def _fields(body: str) -> dict[str, str]:
    return {k: v.strip() for k, v in _FIELD.findall(body + ",")}


def parse_ir(text: str) -> dict[str, list[Instruction]]:
    """The instructions of every function defined in optimized IR ``text``."""
    meta = {}
    for line in text.splitlines():
        m = _META.match(line)
        if m:
            meta[m.group(1)] = (m.group(2), _fields(m.group(3)))

    def file_of(ref: str | None) -> str | None:
        """The file of a scope: a DIFile's path (None for reactor's own), through its scopes."""
        for _ in range(32):
            if not ref:
                return None
            kind, fields = meta.get(ref.lstrip("!"), (None, {}))
            if kind == "DIFile":
                name, directory = fields.get("filename", '""')[1:-1], fields.get("directory", '"."')[1:-1]
                return None if name == "<reactor>" else os.path.join(directory, name)
            ref = fields.get("file") or fields.get("scope")
        return None

    locations: dict[str, tuple] = {}

    def location(ref: str) -> tuple:
        found = locations.get(ref)
        if found is None:
            kind, fields = meta.get(ref, (None, {}))
            line = int(fields.get("line", "0")) if kind == "DILocation" else 0
            column = int(fields.get("column", "0")) if kind == "DILocation" else 0
            found = locations[ref] = (file_of(fields.get("scope")) if line else None, line, column)
        return found

    functions: dict[str, list[Instruction]] = {}
    current: list[Instruction] | None = None
    block = "entry"
    for raw in text.splitlines():
        m = _DEFINE.match(raw)
        if m:
            current = functions.setdefault(m.group(2), [])
            block = "entry"
            continue
        if current is None:
            continue
        if raw.startswith("}"):
            current = None
            continue
        if raw and not raw[0].isspace() and ":" in raw:
            block = raw.split(":", 1)[0].strip().strip('"')
            continue
        stripped = raw.strip()
        if not stripped or stripped.startswith(";"):
            continue
        dbg = _DBG.search(stripped)
        file, line, column = location(dbg.group(1)) if dbg else (None, 0, 0)
        body = _DBG.sub("", stripped).rstrip()
        current.append(Instruction(body, file, line, column % TAIL_COLUMN, column >= TAIL_COLUMN, block))
    return functions


_LOC = re.compile(r"^\s*\.loc\s+(\d+)\s+(\d+)(?:\s+(\d+))?")
_FILE = re.compile(r'^\s*\.file\s+(\d+)\s+"([^"]*)"(?:\s+"([^"]*)")?')
_LABEL = re.compile(r"^([.\w$@]+):")
_TYPE = re.compile(r"^\s*\.type\s+([^,]+),@function")


def parse_asm(text: str) -> dict[str, list[Instruction]]:
    """The machine instructions of every function in assembly ``text``, with their ``.loc``."""
    files: dict[str, str | None] = {}
    functions: dict[str, list[Instruction]] = {}
    names: set[str] = set()
    current: list[Instruction] | None = None
    where: tuple = (None, 0, 0)
    block = ""
    for raw in text.splitlines():
        m = _TYPE.match(raw)
        if m:
            names.add(m.group(1).strip().strip('"'))
            continue
        m = _FILE.match(raw)
        if m:
            directory, name = (m.group(2), m.group(3)) if m.group(3) is not None else ("", m.group(2))
            files[m.group(1)] = None if name == "<reactor>" else os.path.join(directory, name)
            continue
        m = _LOC.match(raw)
        if m:
            line = int(m.group(2))
            where = (files.get(m.group(1)) if line else None, line, int(m.group(3) or 0))
            continue
        m = _LABEL.match(raw)
        if m:
            label = m.group(1).strip('"')
            if label in names:
                current = functions.setdefault(label, [])
                where = (None, 0, 0)
            block = label
            continue
        stripped = raw.strip()
        if current is None or not stripped or stripped.startswith((".", "#")) or raw[0] not in "\t ":
            if stripped.startswith(".section") or stripped.startswith(".Lfunc_end"):
                current = None if stripped.startswith(".section") else current
            continue
        text_only = stripped.split("#", 1)[0].rstrip().replace("\t", " ")
        file, line, column = where
        current.append(Instruction(text_only, file, line, column % TAIL_COLUMN, column >= TAIL_COLUMN, block))
    return functions


def source_line(path: str | None, line: int) -> str:
    """The text of a source line (empty when unknown)."""
    import linecache
    return linecache.getline(path, line).rstrip() if path and line else ""
