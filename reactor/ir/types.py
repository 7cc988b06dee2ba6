"""Element kinds, value types and pointer types, and their LLVM types and constants.

A *kind* is an element type (Float, Double, Int, UInt, Bool, and the pixel
formats UByte, UShort, Half); a *value type*
is a kind at a SIMD width (1 = scalar, or 4, 8, 16 lanes). Everything below is
a table: adding a kind or a width adds it for every operation at once.

Two kinds are for the plumbing only (not DSL types): ``INDEX`` (a 64-bit
signed integer: element counts, strides, addresses) and ``BYTE`` (an 8-bit
integer: raw memory). Layers above ``ir`` name types with these objects and
never with llvmlite's.
"""
from __future__ import annotations

import dataclasses
import functools

import numpy as np
from llvmlite import ir
from llvmlite.ir import Type as LLVMType

#: The SIMD widths of the DSL (1 is scalar).
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
        # pixel and table formats: 8- and 16-bit unsigned integers, IEEE binary16
        Kind("UByte", "uint", 8, ir.IntType(8), ir.IntType(8), np.dtype(np.uint8)),
        Kind("UShort", "uint", 16, ir.IntType(16), ir.IntType(16), np.dtype(np.uint16)),
        Kind("Half", "float", 16, ir.HalfType(), ir.HalfType(), np.dtype(np.float16)),
    )
}
INDEX_KIND = Kind("Index", "int", 64, ir.IntType(64), ir.IntType(64), np.dtype(np.int64))
UINDEX_KIND = Kind("UIndex", "uint", 64, ir.IntType(64), ir.IntType(64), np.dtype(np.uint64))
BYTE_KIND = Kind("Byte", "uint", 8, ir.IntType(8), ir.IntType(8), np.dtype(np.uint8))


def mangle(t: ir.Type) -> str:
    """LLVM's overload suffix for an IR type: f32, i8, v16f32, v8i1."""
    if isinstance(t, ir.VectorType):
        return f"v{t.count}{mangle(t.element)}"
    if isinstance(t, ir.HalfType):
        return "f16"
    if isinstance(t, ir.FloatType):
        return "f32"
    if isinstance(t, ir.DoubleType):
        return "f64"
    return f"i{t.width}"


@dataclasses.dataclass(frozen=True)
class VType:
    """A DSL value type: a kind at a width (1 means scalar)."""

    kind: Kind
    width: int

    @property
    def name(self) -> str:
        return self.kind.name if self.width == 1 else f"{self.kind.name}{self.width}"

    @functools.cached_property
    def ir(self) -> LLVMType:
        t = self.kind.ir_type
        return t if self.width == 1 else ir.VectorType(t, self.width)

    @functools.cached_property
    def mem_ir(self) -> LLVMType:
        t = self.kind.mem_type
        return t if self.width == 1 else ir.VectorType(t, self.width)

    def with_kind(self, kind: Kind | str) -> "VType":
        return VType(KINDS[kind] if isinstance(kind, str) else kind, self.width)

    def with_width(self, width: int) -> "VType":
        return VType(self.kind, width)

    def mangle(self) -> str:
        """The suffix LLVM uses in overloaded intrinsic names (f32, v16f32, v8i1)."""
        return mangle(self.ir)

    def __repr__(self) -> str:
        return self.name


INDEX = VType(INDEX_KIND, 1)
UINDEX = VType(UINDEX_KIND, 1)
BYTE = VType(BYTE_KIND, 1)


def memory(vt: VType) -> VType:
    """The type ``vt``'s values have in memory (a Bool is a byte, as in NumPy)."""
    return VType(BYTE_KIND, vt.width) if vt.kind.category == "bool" else vt


@dataclasses.dataclass(frozen=True)
class PointerType:
    """A pointer to elements of value type ``pointee`` (a DSL pointer argument).

    ``length`` is the number of pointee elements a routine may touch: an int,
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
    def ir(self) -> LLVMType:
        return self.pointee.mem_ir.as_pointer()

    @property
    def mem_ir(self) -> LLVMType:
        return self.ir

    def __repr__(self) -> str:
        return self.name


@dataclasses.dataclass(frozen=True)
class Address:
    """A pointer to a pointer or a struct (the plumbing's: ``char **``, ``Settings *``)."""

    pointee: "PointerType | Address | StructType"

    @property
    def ir(self) -> LLVMType:
        return self.pointee.ir.as_pointer()

    @property
    def mem_ir(self) -> LLVMType:
        return self.ir


#: ``char *`` and ``char **``: NumPy's untyped data pointers.
BYTES = PointerType(BYTE)
BYTES_ARRAY = Address(BYTES)


@dataclasses.dataclass(frozen=True)
class StructType:
    """Several values returned together (a kernel body with several outputs)."""

    fields: tuple

    @property
    def ir(self) -> LLVMType:
        return ir.LiteralStructType([f.ir for f in self.fields])

    @property
    def mem_ir(self) -> LLVMType:
        return self.ir

    @property
    def name(self) -> str:
        return "(" + ", ".join(f.name for f in self.fields) + ")"


def ir_type(t) -> LLVMType:
    """The LLVM type of a VType, PointerType or StructType (None: void)."""
    return ir.VoidType() if t is None else t.ir


def const(vtype: VType, value) -> ir.Constant:
    """A constant of ``vtype`` with every lane equal to ``value`` (shared: constants are immutable)."""
    return _const(vtype, type(value).__name__, repr(value), value)


@functools.lru_cache(maxsize=4096)
def _const(vtype: VType, kind: str, text: str, value) -> ir.Constant:
    # keyed by the value's type and repr: 0.0 and -0.0 (equal, same hash) stay apart
    scalar = ir.Constant(vtype.kind.ir_type, value)
    if vtype.width == 1:
        return scalar
    return ir.Constant(vtype.ir, [scalar] * vtype.width)


def lanes(vtype: VType, values) -> ir.Constant:
    """A vector constant of ``vtype`` with one value per lane."""
    values = list(values)
    if len(values) != vtype.width:
        raise ValueError(f"{vtype.name} needs {vtype.width} lane values, got {len(values)}")
    scalars = [ir.Constant(vtype.kind.ir_type, v) for v in values]
    return scalars[0] if vtype.width == 1 else ir.Constant(vtype.ir, scalars)


def undefined(t) -> ir.Constant:
    """An undefined value of type ``t`` (to build vectors lane by lane)."""
    return ir.Constant(ir_type(t), ir.Undefined)


def null(t: PointerType) -> ir.Constant:
    return ir.Constant(t.ir, None)


def is_constant(value) -> bool:
    return isinstance(value, ir.Constant)
