"""Element kinds and value types of the DSL.

A *kind* is an element type (Float, Double, Int, UInt, Bool); a *value type*
is a kind at a SIMD width (1 = scalar, or 4, 8, 16 lanes). Everything below is
a table: adding a kind or a width adds it for every operation at once.
"""
from __future__ import annotations

import dataclasses
import functools

import numpy as np
from llvmlite import ir

WIDTHS = (1, 4, 8, 16)


@dataclasses.dataclass(frozen=True)
class Kind:
    """An element type: its name, arithmetic category and representations."""

    name: str
    category: str  # "float", "int" (signed), "uint" (unsigned) or "bool"
    bits: int
    ir_type: ir.Type  # in registers
    mem_type: ir.Type  # in memory (Bool is stored as one byte, like numpy.bool_)
    dtype: np.dtype

    @property
    def mem_bytes(self) -> int:
        """Bytes per element in memory (also the alignment used for loads and stores)."""
        return self.dtype.itemsize

    @property
    def is_float(self) -> bool:
        return self.category == "float"

    @property
    def is_integer(self) -> bool:
        return self.category in ("int", "uint")

    @property
    def signed(self) -> bool:
        return self.category == "int"

    def __repr__(self) -> str:
        return self.name


KINDS = {
    k.name: k
    for k in (
        Kind("Float", "float", 32, ir.FloatType(), ir.FloatType(), np.dtype(np.float32)),
        Kind("Double", "float", 64, ir.DoubleType(), ir.DoubleType(), np.dtype(np.float64)),
        Kind("Int", "int", 32, ir.IntType(32), ir.IntType(32), np.dtype(np.int32)),
        Kind("UInt", "uint", 32, ir.IntType(32), ir.IntType(32), np.dtype(np.uint32)),
        Kind("Bool", "bool", 1, ir.IntType(1), ir.IntType(8), np.dtype(np.bool_)),
    )
}


@dataclasses.dataclass(frozen=True)
class VType:
    """A DSL value type: a kind at a width (1 means scalar)."""

    kind: Kind
    width: int

    @property
    def name(self) -> str:
        return self.kind.name if self.width == 1 else f"{self.kind.name}{self.width}"

    @functools.cached_property
    def ir(self) -> ir.Type:
        t = self.kind.ir_type
        return t if self.width == 1 else ir.VectorType(t, self.width)

    @functools.cached_property
    def mem_ir(self) -> ir.Type:
        t = self.kind.mem_type
        return t if self.width == 1 else ir.VectorType(t, self.width)

    def with_kind(self, kind: Kind | str) -> "VType":
        return VType(KINDS[kind] if isinstance(kind, str) else kind, self.width)

    def with_width(self, width: int) -> "VType":
        return VType(self.kind, width)

    def mangle(self) -> str:
        """The suffix LLVM uses in overloaded intrinsic names (f32, v16f32, v8i1)."""
        base = {"float": "f", "int": "i", "uint": "i", "bool": "i"}[self.kind.category]
        scalar = f"{base}{self.kind.bits}"
        return scalar if self.width == 1 else f"v{self.width}{scalar}"

    def __repr__(self) -> str:
        return self.name


@dataclasses.dataclass(frozen=True)
class PointerType:
    """A pointer argument to elements of ``pointee`` (a scalar or vector type).

    ``length`` is the number of pointee elements the routine may touch: an int,
    the name of an Int/UInt argument of the same function, or None (unchecked
    beyond "at least one element").
    """

    pointee: VType
    length: int | str | None = None

    @property
    def name(self) -> str:
        extra = "" if self.length is None else f", {self.length!r}"
        return f"Pointer[{self.pointee.name}{extra}]"

    @property
    def ir(self) -> ir.Type:
        return self.pointee.mem_ir.as_pointer()

    def __repr__(self) -> str:
        return self.name
