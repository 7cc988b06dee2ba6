"""A SPIR-V module's declarations: names, decorations, types, constants, global variables and
functions (their blocks, with their merge instructions), as the translator reads them."""
from __future__ import annotations

import dataclasses
import struct
import typing

from ..dsl.values import value_class
from ..dsl.vectors import vec_type
from ..ir.types import KINDS, VType
from .binary import Instruction, Module, SpirvError


# -- types ----------------------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class Type:
    kind: str  # void bool int float vector matrix struct array pointer function
    width: int = 32
    signed: bool = True
    count: int = 0  # vector size, matrix columns, array length
    elem: typing.Any = None  # a Type: vector/matrix/array element, pointer's pointee
    members: tuple = ()
    storage: str = ""

    @property
    def scalar(self) -> bool:
        return self.kind in ("bool", "int", "float")

    def dsl(self):
        """The DSL class of a scalar or vector type (kernel arguments and results)."""
        if self.scalar:
            return value_class(VType(KINDS[_KIND[self.kind]], 1))
        if self.kind == "vector" and self.elem is not None and self.elem.scalar:
            return vec_type(_KIND[self.elem.kind], self.count)
        raise SpirvError(f"a shader interface of type {self.kind} is not supported (scalars and vectors are)")


_KIND = {"float": "Float", "int": "Int", "bool": "Bool"}
MAX_ARRAY = 4096  # elements of a shader's array (each one is a value, or a variable, of every lane)


# -- the module's declarations --------------------------------------------------------------------

@dataclasses.dataclass
class Block:
    label: int
    body: list
    terminator: Instruction
    selection_merge: int | None = None
    loop: tuple[int, int] | None = None  # (merge, continue target)


@dataclasses.dataclass
class Function:
    id: int
    type: int
    params: list
    blocks: dict
    entry: int


class Declarations:
    """What a module declares: names, decorations, types, constants, global variables, functions."""

    def __init__(self, module: Module) -> None:
        self.names: dict[int, str] = {}
        self.member_names: dict[tuple[int, int], str] = {}
        self.decorations: dict[int, dict[str, list]] = {}
        self.types: dict[int, Type] = {}
        self.pointee: dict[int, int] = {}  # pointer type id -> its pointee's type id
        self.constants: dict[int, typing.Any] = {}
        self.spec_constants: dict[int, Type] = {}  # specialization constant -> its type
        self.globals: dict[int, Instruction] = {}
        self.functions: dict[int, Function] = {}
        self.imports: dict[int, str] = {}
        self.strings: dict[int, str] = {}  # OpString: the source file names OpLine refers to
        self.entry: Instruction | None = None
        self.capabilities: list[str] = []
        current: list[Instruction] | None = None
        for ins in module.instructions:
            if current is not None:
                current.append(ins)
                if ins.op == "OpFunctionEnd":
                    self._function(current)
                    current = None
                continue
            if ins.op == "OpFunction":
                current = [ins]
            else:
                self._declare(ins)
        if self.entry is None:
            raise SpirvError("the SPIR-V module has no OpEntryPoint")

    def _declare(self, ins: Instruction) -> None:
        op, a = ins.op, ins.args
        if op == "OpName":
            self.names[a[0]] = a[1]
        elif op == "OpMemberName":
            self.member_names[a[0], a[1]] = a[2]
        elif op == "OpDecorate":
            self.decorations.setdefault(a[0], {})[a[1]] = a[2:]
        elif op == "OpEntryPoint":
            self.entry = self.entry or ins
        elif op == "OpExtInstImport":
            self.imports[ins.id] = a[0]
        elif op == "OpString":
            self.strings[ins.id] = a[0]
        elif op == "OpCapability":
            self.capabilities.append(a[0])
        elif op.startswith("OpType"):
            self.types[ins.id] = self._type(ins)
        elif op in ("OpConstant", "OpSpecConstant"):
            self.constants[ins.id] = self._number(self.types[ins.type], a)
            self._specialization(ins)
        elif op in ("OpConstantTrue", "OpSpecConstantTrue"):
            self.constants[ins.id] = True
            self._specialization(ins)
        elif op in ("OpConstantFalse", "OpSpecConstantFalse"):
            self.constants[ins.id] = False
            self._specialization(ins)
        elif op in ("OpConstantComposite", "OpSpecConstantComposite"):
            self.constants[ins.id] = tuple(self.constants[c] for c in a)
        elif op == "OpConstantNull":
            self.constants[ins.id] = zero(self.types[ins.type])
        elif op == "OpVariable":
            self.globals[ins.id] = ins
        elif op in ("OpMemberDecorate", "OpSource", "OpSourceExtension", "OpSourceContinued",
                    "OpLine", "OpNoLine", "OpExtension", "OpMemoryModel", "OpExecutionMode", "OpModuleProcessed",
                    "OpExecutionModeId", "OpDecorateString", "OpMemberDecorateString"):
            pass
        else:
            raise SpirvError(f"{op} (SPIR-V word {ins.word}) is not supported outside functions")

    def _specialization(self, ins: Instruction) -> None:
        """Note a scalar specialization constant (``layout(constant_id = N) const T name``)."""
        if ins.op.startswith("OpSpec"):
            self.spec_constants[ins.id] = self.types[ins.type]

    def specialize(self, given: dict) -> None:
        """Set the specialization constants ``given`` names (by name, or by ``constant_id``) to
        their values, as a Vulkan pipeline's specialization info would."""
        for cid, typ in self.spec_constants.items():
            spec_id = self.decorations.get(cid, {}).get("SpecId", [None])[0]
            for key in (self.names.get(cid), spec_id):
                if key is not None and key in given:
                    value = given[key]
                    self.constants[cid] = bool(value) if typ.kind == "bool" else \
                        struct.unpack("<f", struct.pack("<f", value))[0] if typ.kind == "float" else int(value)

    def _type(self, ins: Instruction) -> Type:
        op, a, t = ins.op, ins.args, self.types
        if op == "OpTypeVoid":
            return Type("void")
        if op == "OpTypeBool":
            return Type("bool")
        if op == "OpTypeInt":
            if a[0] != 32:
                raise SpirvError(f"{a[0]}-bit integers are not supported (32-bit are)")
            return Type("int", 32, bool(a[1]))
        if op == "OpTypeFloat":
            if a[0] != 32:
                raise SpirvError(f"{a[0]}-bit floats are not supported (32-bit are)")
            return Type("float", 32)
        if op in ("OpTypeVector", "OpTypeMatrix"):
            if not 2 <= a[1] <= 4:
                raise SpirvError(f"{op} (SPIR-V word {ins.word}) of {a[1]} components (2 to 4 are valid)")
            return Type("vector" if op == "OpTypeVector" else "matrix", count=a[1], elem=t[a[0]])
        if op == "OpTypeStruct":
            return Type("struct", members=tuple(t[m] for m in a))
        if op == "OpTypeRuntimeArray":
            return Type("runtimearray", elem=t[a[0]])
        if op == "OpTypeArray":
            count = self.constants[a[1]]
            if not isinstance(count, int) or not 1 <= count <= MAX_ARRAY:
                raise SpirvError(f"an array of {count} elements (SPIR-V word {ins.word}): 1 to {MAX_ARRAY} are "
                                 f"supported (each element is a value of every lane)")
            return Type("array", count=count, elem=t[a[0]])
        if op == "OpTypePointer":
            self.pointee[ins.id] = a[1]
            return Type("pointer", storage=a[0], elem=t[a[1]])
        if op == "OpTypeFunction":
            return Type("function")
        if op == "OpTypeImage":
            dims = {"2D": 2, "3D": 3}.get(a[1])
            if dims is None or a[3] or a[4]:
                raise SpirvError(f"{a[1]} images (arrayed or multisampled) are not supported (2D and 3D are)")
            return Type("image", count=dims, elem=t[a[0]])
        if op == "OpTypeSampledImage":
            return Type("sampledimage", count=t[a[0]].count, elem=t[a[0]].elem)
        if op == "OpTypeSampler":
            return Type("sampler")
        raise SpirvError(f"{op} (SPIR-V word {ins.word}) is not supported")

    @staticmethod
    def _number(typ: Type, words: list):
        if typ.kind == "float":
            return struct.unpack("<f", struct.pack("<I", words[0]))[0]
        if typ.kind == "int":
            v = words[0]
            return v - (1 << 32) if typ.signed and v >= 1 << 31 else v
        raise SpirvError(f"a constant of type {typ.kind} is not supported")

    def _function(self, instructions: list[Instruction]) -> None:
        head = instructions[0]
        params = [i for i in instructions if i.op == "OpFunctionParameter"]
        blocks: dict[int, Block] = {}
        label: int | None = None
        body: list[Instruction] = []
        entry = 0
        for ins in instructions[1:]:
            if ins.op == "OpLabel":
                label, body = ins.id, []
                entry = entry or label
            elif ins.op in ("OpBranch", "OpBranchConditional", "OpReturn", "OpReturnValue", "OpKill",
                            "OpUnreachable", "OpSwitch", "OpTerminateInvocation") and label is not None:
                block = Block(label, body, ins)
                for m in body:
                    if m.op == "OpSelectionMerge":
                        block.selection_merge = m.args[0]
                    elif m.op == "OpLoopMerge":
                        block.loop = (m.args[0], m.args[1])
                block.body = [m for m in body if m.op not in ("OpSelectionMerge", "OpLoopMerge")]
                blocks[label] = block
                label = None
            elif label is not None:
                body.append(ins)
        self.functions[head.id] = Function(head.id, head.type, params, blocks, entry)

    def name(self, id_: int, default: str = "") -> str:
        return self.names.get(id_, default or f"%{id_}")


def zero(typ: Type):
    """The flattened zero of ``typ``."""
    if typ.kind == "bool":
        return False
    if typ.kind == "int":
        return 0
    if typ.kind == "float":
        return 0.0
    if typ.kind in ("vector", "matrix", "array"):
        return tuple(zero(typ.elem) for _ in range(typ.count))
    if typ.kind == "struct":
        return tuple(zero(m) for m in typ.members)
    raise SpirvError(f"no value of type {typ.kind}")
