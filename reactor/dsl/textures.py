"""Tables and textures: whole arrays a kernel reads with per-lane coordinates.

A kernel parameter annotated ``Table[Float]``, ``Texture2D[vec4]`` or
``Texture3D[vec3]`` is not iterated over: every lane sees the whole array (the
kernel becomes a NumPy generalized ufunc with the array's axes as core
dimensions, so ``shade(uv_x, uv_y, image)`` takes an (H, W, 4) image whole).
The element names the texel: a kind (``Float``, ``UByte``, ``Half`` ...: one
channel) or a vector (``vec4``, ``u8vec4``, ``f16vec3`` ...: that many channels,
the array's last axis). Further items set the sampler state::

    Texture2D[u8vec4, "repeat", "linear"]     # RGBA8, wrapping, bilinear
    Table[Int, "clamp"]                         # a lookup table of int32

Out-of-range coordinates follow the wrap mode: ``"clamp"`` (to the edge, the
default), ``"repeat"``, ``"mirror"`` (mirrored repeat) or ``"border"`` (zero:
GLSL's transparent black). No lane ever reads outside the array; lanes that
are not active (per-lane control flow) read nothing.

* ``table[i]`` (a Table): the element at index ``i`` (an Int per lane or a
  scalar), in its own kind (an Int table gives Int).
* ``tex.fetch(x, y)`` / GLSL ``texelFetch``: the texel at integer coordinates
  (``x`` along the last image axis before the channels: an (H, W, C) array is
  indexed ``[y, x]``), as Float (UByte and UShort texels normalized to [0, 1]
  as GLSL's unorm formats, Half converted); a vector for several channels.
* ``tex.sample(u, v)`` / GLSL ``texture``: at normalized coordinates (0..1
  across the texture, ``v = 0`` the array's first row, as the first row
  OpenGL uploads), filtered ``"nearest"`` (the default) or ``"linear"``
  (bilinear: ``mix(mix(t00, t10, fx), mix(t01, t11, fx), fy)`` at ``u * W - 0.5``).
* ``tex.size`` : the sizes as Int values (x first: ``(W, H)``).
"""
from __future__ import annotations

import dataclasses
import typing

from ..errors import DSLTypeError
from ..ir import emitter as _em
from ..ir import ops
from ..ir import types as T
from ..ir.types import INDEX, KINDS, Kind, VType
from .context import active_mask
from .values import Value, shown, value_class

WRAPS = ("clamp", "repeat", "mirror", "border")
FILTERS = ("nearest", "linear")
#: What a texel's kind becomes when sampled: unorm formats are normalized by this.
UNORM_SCALE = {"UByte": 255.0, "UShort": 65535.0}


@dataclasses.dataclass(frozen=True)
class TextureSpec:
    """What ``Texture2D[vec4, "repeat"]`` names: ``ndim`` coordinate axes, the texel's
    ``kind`` and ``channels``, the wrap mode and the filter."""

    family: str
    ndim: int
    kind: Kind
    channels: int
    wrap: str = "clamp"
    filter: str = "nearest"

    @property
    def name(self) -> str:
        element = self.kind.name if self.channels == 1 else f"{self.kind.name}x{self.channels}"
        return f"{self.family}[{element}, {self.wrap!r}, {self.filter!r}]"

    @property
    def core_axes(self) -> int:
        """The array's axes: the coordinates, then the channels (if more than one)."""
        return self.ndim + (1 if self.channels > 1 else 0)

    def __repr__(self) -> str:
        return self.name


class _Family:
    """``Table``, ``Texture2D``, ``Texture3D``: subscripted to make a TextureSpec."""

    def __init__(self, name: str, ndim: int) -> None:
        self.name, self.ndim = name, ndim

    def __getitem__(self, items) -> TextureSpec:
        from .vectors import Vec

        items = items if isinstance(items, tuple) else (items,)
        element, rest = items[0], items[1:]
        if isinstance(element, type) and issubclass(element, Vec):
            kind, channels = element.kind, element.size
        elif isinstance(element, type) and issubclass(element, Value) and getattr(element, "vtype", None) \
                and element.vtype.width == 1:
            kind, channels = element.vtype.kind, 1
        else:
            raise DSLTypeError(f"{self.name}[...] takes a texel type first (Float, UByte, vec4, u8vec4 ...), "
                               f"not {element!r}")
        if kind.category == "bool":
            raise DSLTypeError(f"{self.name} of Bool: store masks as UByte")
        wrap, filt = "clamp", "nearest"
        for item in rest:
            if item in WRAPS:
                wrap = item
            elif item in FILTERS:
                filt = item
            else:
                raise DSLTypeError(f"{self.name}[...]: {item!r} is neither a wrap mode ({', '.join(WRAPS)}) "
                                   f"nor a filter ({', '.join(FILTERS)})")
        if filt == "linear" and not kind.is_float and kind.name not in UNORM_SCALE:
            raise DSLTypeError(f"{self.name} of {kind.name}: linear filtering needs float or unorm texels")
        return TextureSpec(self.name, self.ndim, kind, channels, wrap, filt)

    def __repr__(self) -> str:
        return self.name


Table = _Family("Table", 1)
Texture2D = _Family("Texture2D", 2)
Texture3D = _Family("Texture3D", 3)


class TextureValue:
    """A table or texture inside a body: its base address, sizes and byte strides (uniform)."""

    def __init__(self, spec: TextureSpec, base, sizes, strides) -> None:
        self.spec, self.base = spec, base
        self._sizes = list(sizes)  # i64 IR values, array axis order (z, y, x)
        self._strides = list(strides)  # i64 IR values, per array axis (+ the channel axis)

    # -- what a body asks ----------------------------------------------------------------
    @property
    def size(self) -> tuple[Value, ...]:
        """The sizes as Int values, x first (``(W, H)`` for an (H, W, C) image)."""
        em = _em.current()
        i32 = VType(KINDS["Int"], 1)
        return tuple(value_class(i32)._wrap(ops.convert(em, INDEX, i32, s, saturate=False), em)
                     for s in reversed(self._sizes))

    def __getitem__(self, index) -> typing.Any:
        if self.spec.ndim != 1:
            raise DSLTypeError(f"{self.spec.family} is indexed with fetch(x, y ...); [] is for a Table")
        return self._texels([index], normalize=False)

    def __setitem__(self, index, value) -> None:
        raise DSLTypeError("tables and textures are read-only in a kernel (GLSL's samplers are too); to write "
                           "per lane, pass a Pointer[Float, \"n\"] to a Function (a scatter: lanes outside [0, n) "
                           "write nothing), or return the values as the kernel's result")

    def fetch(self, *coords) -> typing.Any:
        """The texel at integer coordinates (x first), as Float (a vector for several channels)."""
        coords = _coords(coords, self.spec.ndim, "fetch")
        return self._texels(coords, normalize=True)

    def sample(self, *coords) -> typing.Any:
        """The filtered texel at normalized coordinates (x first: u, v, w)."""
        coords = _coords(coords, self.spec.ndim, "sample")
        for c in coords:
            if not (isinstance(c, (int, float)) or isinstance(c, Value) and c.kind.is_float):
                raise DSLTypeError(f"sample takes Float coordinates (0..1 across the texture), not {c!r}")
        sizes = [self._float_size(a) for a in range(self.spec.ndim)]  # x first
        if self.spec.filter == "nearest":
            from .intrinsics import Floor
            ints = [_to_int(Floor(_as_float(c) * s)) for c, s in zip(coords, sizes)]
            return self._texels(ints, normalize=True)
        return self._linear(coords, sizes)

    # -- how ---------------------------------------------------------------------------------
    def _float_size(self, axis: int) -> Value:
        """The size along coordinate ``axis`` (x = 0) as a Float."""
        em = _em.current()
        size = self._sizes[self.spec.ndim - 1 - axis]
        f32 = VType(KINDS["Float"], 1)
        return value_class(f32)._wrap(ops.convert(em, INDEX, f32, size), em)

    def _linear(self, coords, sizes):
        from .intrinsics import Floor
        fracs, lows = [], []
        for c, s in zip(coords, sizes):
            t = _as_float(c) * s - 0.5
            low = Floor(t)
            fracs.append(t - low)
            lows.append(_to_int(low))
        located = {corner: self._locate([low + ((corner >> a) & 1) for a, low in enumerate(lows)])
                   for corner in range(1 << self.spec.ndim)}
        em = _em.current()
        width = max(w for _, _, w in located.values())
        if not self._by_rows(em, width):
            return _blend({c: self._texels_at(em, o, m, w, normalize=True) for c, (o, m, w) in located.items()}, fracs)
        head = em.block
        with em.if_else(self._adjacent(em), name="texels") as (rows, gathers):
            with rows:
                by_rows = self._blend_rows(em, located, fracs, width)
                rows_end = em.block
            with gathers:
                gathered = _blend({c: self._texels_at(em, o, m, w, normalize=True, rows=False)
                                   for c, (o, m, w) in located.items()}, fracs)
                gathered = [x.ir for x in gathered._c]
                gathers_end = em.block
        f32 = VType(KINDS["Float"], width)
        phis = [em.phi(f32, [(a, rows_end), (b, gathers_end)], name="texel") for a, b in zip(by_rows, gathered)]
        _gather_if_few_read(em, head.terminator, phis)
        comps = [value_class(f32)._wrap(x, em) for x in phis]
        from .vectors import vec_type
        return vec_type("Float", self.spec.channels)._of(comps)

    def _by_rows(self, em, width: int) -> bool:
        """Whether to filter whole texels (a load per lane and corner, the blend on the texels as
        they lie in memory, then one transpose) rather than gather each channel: where gathers
        are slow, for 2 or 4 channels."""
        c = self.spec.channels
        return c in (2, 4) and width > 1 and width % c == 0 and not em.module.build.target.fast_gather

    def _adjacent(self, em):
        """When the kernel runs: the array has texels, and a texel's channels are adjacent."""
        return ops.binary(em, "and", VType(KINDS["Bool"], 1), self._nonempty(em, 1), ops.compare(
            em, INDEX, "eq", self._strides[self.spec.ndim], T.const(INDEX, self.spec.kind.mem_bytes)))

    def _blend_rows(self, em, located, fracs, width: int) -> list:
        """Bilinear (trilinear) filtering on whole texels: each group of ``width // channels`` lanes
        holds their texels' channels side by side, the same arithmetic as :func:`_blend` on
        each, so the results are the same bits. Gives each channel's values (IR)."""
        c = self.spec.channels
        group = width // c
        vt, f32 = VType(self.spec.kind, width), VType(KINDS["Float"], width)
        spread = [[g * group + j // c for j in range(width)] for g in range(c)]  # lane values beside its channels
        corners = {}
        for corner, (offset, mask, w) in located.items():
            offset, mask = _splat(em, offset, w, width), _splat(em, mask, w, width)
            safe = em.select(mask, offset, T.const(VType(INDEX.kind, width), 0), name="texel.at")
            groups = em.row_groups(vt, self.base, safe, c, name="texel")
            corners[corner] = [_normalized(value_class(vt)._wrap(em.select(
                em.shuffle(mask, mask, lanes), g, T.const(T.memory(vt), 0)), em)) for g, lanes in zip(groups, spread)]
        weights = [[value_class(f32)._wrap(em.shuffle(x, x, lanes), em)
                    for lanes in spread] for x in (_splat(em, _as_float(f).ir, f.width, width) for f in fracs)]
        for a, per_group in enumerate(weights):  # mix along x, then y, then z
            step = 1 << a
            corners = {k: [_mix(p, q, t) for p, q, t in zip(corners[k], corners[k | step], per_group)]
                       for k in corners if not k & step}
        return em.ungroup([x.ir for x in corners[0]], c, name="texel")

    def _texels(self, coords, normalize: bool):
        """Gather the texels at integer ``coords`` (x first) with the wrap mode."""
        offset, mask, width = self._locate(coords)
        return self._texels_at(_em.current(), offset, mask, width, normalize=normalize)

    def _locate(self, coords):
        """(byte offsets, lanes that read, width) of the texels at integer ``coords`` (x first),
        after the wrap mode; a lane reads where it is active, inside (border) and the array has
        texels."""
        em = _em.current()
        spec = self.spec
        coords = [_as_int(c) for c in coords]
        width = max(c.width for c in coords)
        i32, i64 = VType(KINDS["Int"], width), VType(INDEX.kind, width)
        mask = active_mask()
        mask_ir = None if mask is None else _widen_mask(mask, width)
        offset = T.const(i64, 0)
        for axis, c in enumerate(coords):
            array_axis = spec.ndim - 1 - axis
            n = ops.convert(em, INDEX, VType(KINDS["Int"], 1), _clamped_size(em, self._sizes[array_axis]),
                            saturate=False)
            index, inside = _wrap(em, spec.wrap, _splat(em, c.ir, c.width, width), em.splat(n, width), i32)
            if inside is not None:
                mask_ir = inside if mask_ir is None else ops.binary(em, "and", i32.with_kind("Bool"), mask_ir, inside)
            index64 = ops.convert(em, i32, i64, index)
            offset = ops.binary(em, "add", i64, offset, ops.binary(em, "mul", i64, index64,
                                                                  em.splat(self._strides[array_axis], width)))
        # an empty array: no lane reads
        nonempty = self._nonempty(em, width)
        mask_ir = nonempty if mask_ir is None else ops.binary(em, "and", i32.with_kind("Bool"), mask_ir, nonempty)
        return offset, mask_ir, width

    def _texels_at(self, em, offset, mask_ir, width: int, normalize: bool, rows: bool = True):
        vt = VType(self.spec.kind, width)
        comps = []
        for raw in self._read(em, vt, offset, mask_ir) if rows else self._gathers(em, vt, offset, mask_ir):
            value = value_class(vt)._wrap(raw, em)
            comps.append(_normalized(value) if normalize else value)
        if self.spec.channels == 1:
            return comps[0]
        from .vectors import vec_type
        return vec_type(comps[0].kind, self.spec.channels)._of(comps)

    def _read(self, em, vt: VType, offset, mask):
        """The channels of the texels at byte ``offset`` (lanes off in ``mask`` give 0): one
        gather per channel; where gathers are slow and a texel's channels are adjacent in memory
        (checked when the kernel runs), one load per lane instead."""
        if self.spec.channels == 1 or vt.width == 1 or em.module.build.target.fast_gather:
            return self._gathers(em, vt, offset, mask)
        mem = T.memory(vt)
        head = em.block
        with em.if_else(self._adjacent(em), name="texels") as (rows, gathers):
            with rows:  # masked lanes read the first texel (there is one), then give 0
                safe = em.select(mask, offset, T.const(VType(INDEX.kind, vt.width), 0), name="texel.at")
                loaded = [em.select(mask, x, T.const(mem, 0)) for x in
                          em.load_rows(vt, self.base, safe, self.spec.channels, name="texel")]
                rows_end = em.block
            with gathers:
                gathered = self._gathers(em, vt, offset, mask)
                gathers_end = em.block
        phis = [em.phi(mem, [(a, rows_end), (b, gathers_end)], name="texel") for a, b in zip(loaded, gathered)]
        _gather_if_few_read(em, head.terminator, phis)
        return phis

    def _gathers(self, em, vt: VType, offset, mask):
        i64 = VType(INDEX.kind, vt.width)
        out = []
        for ch in range(self.spec.channels):
            at = offset if ch == 0 else ops.binary(em, "add", i64, offset, ops.binary(
                em, "mul", i64, em.splat(self._strides[self.spec.ndim], vt.width), T.const(i64, ch)))
            out.append(em.gather(vt, self.base, at, mask, name="texel"))
        return out

    def _nonempty(self, em, width: int):
        bool1 = VType(KINDS["Bool"], 1)
        ok = T.const(bool1, 1)
        for s in self._sizes:
            ok = ops.binary(em, "and", bool1, ok, ops.compare(em, INDEX, "gt", s, T.const(INDEX, 0)))
        return em.splat(ok, width)


def _coords(coords, ndim: int, what: str):
    from .vectors import Vec
    flat: list = []
    for c in coords:
        flat.extend(c if isinstance(c, Vec) else [c])
    if len(flat) != ndim:
        raise DSLTypeError(f"{what} takes {ndim} coordinate(s) (x first), got {len(flat)}")
    return flat


def _as_int(c) -> Value:
    if isinstance(c, bool) or not isinstance(c, (int, Value)):
        raise DSLTypeError(f"a texel index must be an Int (per lane or uniform) or an int, not {c!r}")
    if isinstance(c, int):
        return value_class(VType(KINDS["Int"], 1))(c)
    if not c.kind.is_integer:
        raise DSLTypeError(f"a texel index must be an integer, not {shown(c.vtype)}: use fetch for integer "
                           f"coordinates and sample for normalized ones")
    return c if c.kind.name == "Int" else value_class(c.vtype.with_kind("Int"))(c)


def _as_float(c) -> Value:
    return c if isinstance(c, Value) else value_class(VType(KINDS["Float"], 1))(float(c))


def _to_int(x: Value) -> Value:
    from .intrinsics import ToInt
    return ToInt(x)  # saturating: NaN gives 0, huge values the largest Int (then wrapped)


def _splat(em, ir_value, from_width: int, width: int):
    return ir_value if from_width == width else em.splat(ir_value, width)


def _widen_mask(mask: Value, width: int):
    if mask.width == width:
        return mask.ir
    if mask.width == 1:
        return _em.current().splat(mask.ir, width)
    raise DSLTypeError(f"texel coordinates of {width} lanes under a condition of {mask.width} lanes")


def _clamped_size(em, size):
    """A size as an i64 no larger than the largest Int (coordinates are Int)."""
    big = T.const(INDEX, 2 ** 31 - 1)
    return em.select(ops.compare(em, INDEX, "gt", size, big), big, size, name="size")


def _wrap(em, mode: str, i, n, vt: VType):
    """(index in [0, n), inside mask or None) for coordinate ``i`` of an axis of ``n`` texels."""
    zero, one = T.const(vt, 0), T.const(vt, 1)
    last = ops.binary(em, "sub", vt, n, one)
    if mode == "clamp" or mode == "border":
        clamped = ops.binary(em, "max", vt, ops.binary(em, "min", vt, i, last), zero)
        if mode == "clamp":
            return clamped, None
        inside = ops.binary(em, "and", vt.with_kind("Bool"), ops.compare(em, vt, "ge", i, zero),
                            ops.compare(em, vt, "lt", i, n))
        return clamped, inside
    if mode == "repeat":
        return _floor_mod(em, vt, i, n), None
    # mirror: period 2n, the second half reflected (GL_MIRRORED_REPEAT)
    two_n = ops.binary(em, "add", vt, n, n)
    m = _floor_mod(em, vt, i, two_n)
    back = ops.binary(em, "sub", vt, ops.binary(em, "sub", vt, two_n, one), m)
    return em.select(ops.compare(em, vt, "lt", m, n), m, back, name="mirror"), None


def _floor_mod(em, vt, i, n):
    """``i mod n`` in [0, n) (n > 0; n = 0 gives 0, and no lane reads then).

    x86 has no vector integer division (a vector ``srem`` is one scalar ``idiv`` per lane), so
    for 32-bit coordinates the quotient is ``floor(i * (1/n))`` in double. The inputs are exact and
    the product's relative error is below 2^-52, with |i|, n < 2^31: where i/n is not an integer it
    is at least 1/n from one, further than the error, so the floor is right; where i = k n it
    may round just below k (n = 2366, i = 2366 gives 0). So the quotient is the true one or one
    less, and one compare-select (remainder >= n: subtract n) makes the remainder exact."""
    if vt.kind.bits > 32:
        r = ops.binary(em, "rem", vt, i, n)
        negative = ops.compare(em, vt, "lt", r, T.const(vt, 0))
        return em.select(negative, ops.binary(em, "add", vt, r, n), r, name="mod")
    dt, wide = vt.with_kind("Double"), vt.with_kind(T.INDEX_KIND)
    zero = T.const(vt, 0)
    n = em.select(ops.compare(em, vt, "eq", n, zero), T.const(vt, 1), n, name="period")  # n = 0: i mod 1
    inverse = ops.binary(em, "div", dt, T.const(dt, 1.0), ops.convert(em, vt, dt, n))
    quotient = ops.unary(em, "floor", dt, ops.binary(em, "mul", dt, ops.convert(em, vt, dt, i), inverse))
    q = ops.convert(em, dt, wide, quotient, saturate=False)  # |quotient| <= 2^31: always in range
    i64, n64 = ops.convert(em, vt, wide, i), ops.convert(em, vt, wide, n)
    r = ops.binary(em, "sub", wide, i64, ops.binary(em, "mul", wide, q, n64))
    r = em.select(ops.compare(em, wide, "ge", r, n64), ops.binary(em, "sub", wide, r, n64), r, name="mod.down")
    return ops.convert(em, wide, vt, r)


def _normalized(v: Value) -> Value:
    """A texel as Float: unorm integers over their maximum (correctly rounded), Half widened."""
    kind = v.kind.name
    f32 = value_class(v.vtype.with_kind("Float"))
    if kind in UNORM_SCALE:
        return f32(v) / UNORM_SCALE[kind]
    if kind == "Half":
        return f32(v)
    return v


def _gather_if_few_read(em, branch, channels: list) -> None:
    """Once the body is complete: where at most one of the texel's channels is read (a luminance
    tap ``.r``), gathering it alone costs less than loading whole texels, so take that path."""
    em.at_finish(lambda used: em.never_take(branch) if sum(id(c) in used for c in channels) <= 1 else None)


def _mix(a, b, t):
    return a * (1.0 - t) + b * t


def _blend(corners: dict, fracs):
    """Linear filtering of the texels at a cell's corners (corner bit a: +1 along axis a)."""
    for a, f in enumerate(fracs):  # mix along x, then y, then z
        step = 1 << a
        corners = {c: _mix(corners[c], corners[c | step], f) for c in corners if not c & step}
    return corners[0]


class ConstantTable:
    """A lookup table known at build time (``ConstantTable([...], Float)``, made anywhere, e.g.
    at module level): inside a body ``table[i]`` reads it with per-lane indices under ``wrap``
    ("clamp" by default), from a constant array in the module's read-only data."""

    def __init__(self, values, element=None, wrap: str = "clamp") -> None:
        import numpy as np

        from .values import Value as _Value
        kind = (KINDS["Float"] if element is None else
                element.vtype.kind if isinstance(element, type) and issubclass(element, _Value) else None)
        if kind is None or kind.category == "bool":
            raise DSLTypeError(f"ConstantTable element type must be a scalar kind (Float, Int, UByte ...), "
                               f"not {element!r}")
        self.values = np.asarray(values, dtype=kind.dtype).ravel().copy()
        self.values.setflags(write=False)
        if self.values.size == 0:
            raise DSLTypeError("a ConstantTable needs at least one value")
        self.spec = Table[value_class(VType(kind, 1)), wrap]

    def __len__(self) -> int:
        return int(self.values.size)

    def __repr__(self) -> str:  # names the contents (kernels' recipe keys read it)
        import hashlib
        digest = hashlib.sha256(self.values.tobytes()).hexdigest()[:16]
        return f"ConstantTable({self.spec.kind.name} x {self.values.size}, {self.spec.wrap!r}, sha256 {digest})"

    def __getitem__(self, index):
        em = _em.current()
        kind = self.spec.kind
        vt = VType(kind, 1)
        if kind.is_float:
            values = [float(v) for v in self.values]
        else:
            bits = kind.bits
            values = [int(v) - (1 << bits) if int(v) >= 1 << (bits - 1) else int(v) for v in self.values]
        g = em.module.constant_array(id(self), vt, values, "table")
        base = em.cast_pointer(g, T.BYTE, name="table")
        n = T.const(INDEX, len(values))
        view = TextureValue(self.spec, base, [n], [T.const(INDEX, kind.mem_bytes)])
        return view[index]
