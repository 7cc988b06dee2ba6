"""A SPIR-V binary decoded by its grammar: each instruction's name, result type and id, and its
other operands in order (ids as ints, literals as ints or strings, enumerants by name followed by
their parameters). Bad input is a ``SpirvError`` naming the word where decoding stopped."""
from __future__ import annotations

import dataclasses
import struct

from ..errors import ReactorError
from .grammar import Grammar, grammar

_ID_KINDS = {"IdRef", "IdScope", "IdMemorySemantics"}
_ONE_WORD = {"LiteralInteger", "LiteralExtInstInteger", "LiteralSpecConstantOpInteger"}


class SpirvError(ReactorError):
    """A SPIR-V module this front end cannot read or translate."""


@dataclasses.dataclass
class Instruction:
    op: str
    type: int  # the result type's id (0: none; ids start at 1)
    id: int  # the result id (0: none)
    args: list  # the other operands, in order
    word: int  # where it starts in the module (words)
    ext: str | None = None  # OpExtInst: the instruction's name in its set, once resolved


@dataclasses.dataclass
class Module:
    version: tuple[int, int]
    generator: int
    bound: int
    instructions: list[Instruction]


def decode(data: bytes, g: Grammar | None = None) -> Module:
    """Decode a SPIR-V module (either byte order)."""
    g = g or grammar()
    if len(data) % 4 or len(data) < 20:
        raise SpirvError(f"not a SPIR-V module: {len(data)} bytes (a multiple of 4, at least 20, expected)")
    order = "<" if struct.unpack("<I", data[:4])[0] == g.magic else ">"
    words = struct.unpack(f"{order}{len(data) // 4}I", data)
    if words[0] != g.magic:
        raise SpirvError(f"not a SPIR-V module: magic number 0x{words[0]:08x}, not 0x{g.magic:08x}")
    version = ((words[1] >> 16) & 0xFF, (words[1] >> 8) & 0xFF)
    out, at = [], 5
    while at < len(words):
        count, code = words[at] >> 16, words[at] & 0xFFFF
        if count == 0 or at + count > len(words):
            raise SpirvError(f"SPIR-V word {at}: an instruction of {count} words overruns the module")
        if code not in g.core.by_code:
            raise SpirvError(f"SPIR-V word {at}: unknown opcode {code}")
        name, operands = g.core.by_code[code]
        out.append(_instruction(g, name, operands, words[at + 1:at + count], at))
        at += count
    return Module(version, words[2], words[3], out)


def _instruction(g: Grammar, name: str, operands: list[dict], words, at: int) -> Instruction:
    reader = _Reader(g, words, at, name)
    rtype = rid = 0
    args: list = []
    for operand in operands:
        kind, quantifier = operand["kind"], operand.get("quantifier")
        if kind == "IdResultType":
            rtype = reader.word()
        elif kind == "IdResult":
            rid = reader.word()
        elif quantifier == "*":
            while reader.left():
                reader.operand(kind, args)
        elif quantifier == "?":
            if reader.left():
                reader.operand(kind, args)
        else:
            reader.operand(kind, args)
    if reader.left():
        raise SpirvError(f"SPIR-V word {at}: {name} has {reader.left()} word(s) more than its grammar")
    return Instruction(name, rtype, rid, args, at)


class _Reader:
    def __init__(self, g: Grammar, words, at: int, name: str) -> None:
        self.g, self.words, self.pos, self.at, self.name = g, words, 0, at, name

    def left(self) -> int:
        return len(self.words) - self.pos

    def word(self) -> int:
        if not self.left():
            raise SpirvError(f"SPIR-V word {self.at}: {self.name} ends before its operands do")
        self.pos += 1
        return self.words[self.pos - 1]

    def operand(self, kind: str, args: list) -> None:
        info = self.g.kinds.get(kind)
        if kind in _ID_KINDS or kind in _ONE_WORD:
            args.append(self.word())
        elif kind == "LiteralString":
            args.append(self.string())
        elif kind in ("LiteralContextDependentNumber", "LiteralFloat"):
            while self.left():  # the last operand: one or two words, by the type
                args.append(self.word())
        elif info is not None and info["category"] == "Composite":
            for base in info["bases"]:
                self.operand(base, args)
        elif info is not None and info["category"] == "ValueEnum":
            value = self.word()
            enumerant = self.g.enumerants[kind].get(value)
            if enumerant is None:
                raise SpirvError(f"SPIR-V word {self.at}: {self.name}: {value} is no {kind}")
            args.append(enumerant["enumerant"])
            for parameter in enumerant.get("parameters", []):
                self.operand(parameter["kind"], args)
        elif info is not None and info["category"] == "BitEnum":
            mask = self.word()
            args.append(mask)
            for bit, enumerant in sorted(self.g.enumerants[kind].items()):
                if bit and mask & bit:
                    for parameter in enumerant.get("parameters", []):
                        self.operand(parameter["kind"], args)
        else:
            raise SpirvError(f"SPIR-V word {self.at}: {self.name}: operand kind {kind} is not supported")

    def string(self) -> str:
        raw = bytearray()
        while True:
            w = self.word()
            chunk = w.to_bytes(4, "little")
            if 0 in chunk:
                raw += chunk[:chunk.index(0)]
                return raw.decode("utf-8", "replace")
            raw += chunk
