"""A kernel's operands: what each parameter and result is per element, and where it lives.

* an **element** (``x: Float``): one value per element, the ufunc's usual operand;
* a **vector** (``n: vec3``, ``-> vec4``): ``channels`` values per element, the
  array's last axis (a core dimension ``(3)``): an (H, W, 3) image is (H, W)
  elements of three channels, loaded at vector speed when the channels are
  contiguous (deinterleaving shuffles) and one by one otherwise;
* a **uniform** (``t: Texture2D[vec4]``, ``lut: Table[Float]``): the whole array
  for every element (core dimensions ``(h, w, 4)``), read with per-lane
  coordinates (``reactor.dsl.textures``).

A kernel with only elements is a plain ufunc; with vectors or uniforms it is a
generalized ufunc whose signature ``gufunc_signature`` writes (NumPy then
broadcasts the loop dimensions and checks the core ones). The loop sees each
iterated operand (elements and vectors: its *columns*) as one element of
``channels * itemsize`` bytes.
"""
from __future__ import annotations

import dataclasses
import functools

from ..errors import DSLTypeError
from ..ir.types import INDEX, Kind, PointerType, VType
from ..ir import types as T
from ..dsl.textures import TextureSpec, TextureValue
from ..dsl.values import to_ir, value_class


@dataclasses.dataclass(frozen=True)
class Operand:
    """One parameter or result: its ``kind``, ``channels`` per element, and ``texture``
    (a TextureSpec) for a uniform."""

    name: str
    kind: Kind
    channels: int = 1
    vector: bool = False  # a GLSL vector type (channels as the last axis)
    texture: TextureSpec | None = None

    @property
    def uniform(self) -> bool:
        return self.texture is not None

    @property
    def dtype(self):
        return self.kind.dtype

    @property
    def item_bytes(self) -> int:
        """Bytes of one element of an iterated operand (all its channels)."""
        return self.kind.mem_bytes * self.channels

    def core_dims(self, tag: str) -> list[str]:
        """The operand's core dimensions in a gufunc signature (names made unique by ``tag``)."""
        if self.texture is not None:
            names = [f"{tag}{axis}" for axis in "zyx"[3 - self.texture.ndim:]]
            return names + ([str(self.channels)] if self.channels > 1 else [])
        return [str(self.channels)] if self.vector else []

    # -- in the body function -------------------------------------------------------------
    def body_params(self, width: int) -> list:
        """The body function's parameter types for this operand."""
        if self.texture is not None:
            return [T.BYTES] + [INDEX] * self.texture.ndim + [INDEX] * self.texture.core_axes
        return [VType(self.kind, width)] * self.channels

    def wrap(self, em, irs, width: int):
        """The DSL value a body receives from its parameters ``irs``."""
        if self.texture is not None:
            ndim = self.texture.ndim
            return TextureValue(self.texture, irs[0], irs[1:1 + ndim], irs[1 + ndim:])
        values = [value_class(VType(self.kind, width))._wrap(v, em) for v in irs]
        if not self.vector:
            return values[0]
        from ..dsl.vectors import vec_type
        return vec_type(self.kind, self.channels)._of(values)

    def flatten(self, value, width: int, what: str) -> list:
        """The IR values of a result ``value`` (a vector result: its components)."""
        vt = VType(self.kind, width)
        if not self.vector:
            return [to_ir(value, vt)]
        from ..dsl.vectors import Vec
        if not isinstance(value, Vec) or value.size != self.channels:
            raise DSLTypeError(f"{what} is declared {self.kind.name}x{self.channels} (a vector of {self.channels}), "
                               f"but the body gives {value!r}")
        return [to_ir(c, vt) for c in value]


def operand_of(name: str, spec) -> Operand:
    """The Operand of a kernel parameter or result annotation (remembered: a memory hit asks again)."""
    try:
        return _operand_cached(name, spec)
    except TypeError:  # an unhashable annotation: its error (or Operand) the long way
        return _operand_of(name, spec)


@functools.lru_cache(maxsize=4096)
def _operand_cached(name: str, spec) -> Operand:
    return _operand_of(name, spec)


def _operand_of(name: str, spec) -> Operand:
    from ..dsl.signature import resolve
    from ..dsl.vectors import Mat, Vec

    if isinstance(spec, TextureSpec):
        return Operand(name, spec.kind, spec.channels, spec.channels > 1, spec)
    if isinstance(spec, type) and issubclass(spec, Vec):
        return Operand(name, spec.kind, spec.size, True)
    if isinstance(spec, type) and issubclass(spec, Mat):
        raise DSLTypeError(f"kernel {name}: matrices are not kernel operands yet; pass their columns as vectors "
                           f"or a Table")
    t = resolve(spec, 1, f"kernel {name}")
    if isinstance(t, PointerType) or not isinstance(t, VType) or t.width != 1:
        raise DSLTypeError(f"kernel {name}: must be a scalar element type (Float, Int, ...), a vector "
                           f"(vec3, u8vec4 ...), a Table or a Texture, not {t!r}; the body is vectorized for you")
    return Operand(name, t.kind)


def gufunc_signature(ins: list[Operand], outs: list[Operand]) -> str | None:
    """NumPy's signature for these operands (``(3),(),(t2y,t2x,4)->(4)``); None for a plain ufunc."""
    if not any(o.vector or o.uniform for o in ins + outs):
        return None

    def part(ops, start):
        return ",".join("(" + ",".join(o.core_dims(f"t{start + k}")) + ")" for k, o in enumerate(ops))
    return f"{part(ins, 0)}->{part(outs, len(ins))}"


def core_layout(ins: list[Operand], outs: list[Operand]):
    """Where a gufunc loop finds each operand's core sizes and strides: for every operand, the
    indices in ``dims`` (after the loop size) of its core dimensions, and in ``steps`` of its core
    strides (after the outer steps), in NumPy's order: distinct dimension names numbered by first
    appearance, strides operand by operand."""
    names: dict[str, int] = {}
    dims, strides = [], []
    stride = len(ins) + len(outs)
    for k, o in enumerate(ins + outs):
        own = o.core_dims(f"t{k}")
        dims.append([names.setdefault(n, len(names)) + 1 for n in own])
        strides.append(list(range(stride, stride + len(own))))
        stride += len(own)
    return dims, strides, 1 + len(names)
