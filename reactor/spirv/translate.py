"""SPIR-V to a reactor kernel, through the DSL and its control-flow core (``reactor.dsl.flow``): no
second code generator. A fragment shader becomes a NumPy ufunc (a gufunc where vectors are
involved): its ``in`` variables, by location, are the inputs (``gl_FragCoord`` too where it is read),
its ``out`` variables the outputs, the members of its uniform blocks either build-time constants
(``uniforms={"name": value}``) or arguments after the inputs, in declaration order.

Values are *flattened*: a scalar is a DSL value (or a Python number for a constant), a vector a
tuple of scalars, a matrix a tuple of columns, a struct or array a tuple of members. A variable is
the same shape with a per-lane DSL Variable at each scalar. Structured control flow (selection and
loop merges) becomes the core's if/else and loops on per-lane masks; ``break``, ``continue`` and
``return`` act per lane; an id used outside the block that makes it, and every ``OpPhi``, lives in
a variable. GLSL.std.450 instructions call the built-ins installed with :func:`set_builtins`
(``import routines`` installs ``routines.glsl``'s)."""
from __future__ import annotations

import inspect
import struct
import typing

import numpy as np

from ..dsl.inline import inline
from ..dsl.values import value_class
from ..dsl.vectors import Vec
from ..ir.types import KINDS, VType
from ..errors import ReactorError
from .binary import Instruction, Module, SpirvError
from .cells import INVOCATION, LENGTH, Cell, _dsl, componentwise, from_vec, new_cell, pick, to_vec
from .declarations import _KIND, Declarations, Type, zero
from .frames import Frame, to_result
from .instructions import OPS, _dot, _fmul, _insert
from ..dsl.builtins import builtins_table, set_builtins  # noqa: F401 - set_builtins: reactor.spirv's



class Translator:
    """One module's translation into a kernel body (see the module docstring)."""

    def __init__(self, module: Module, uniforms: dict | None = None, samplers: dict | None = None) -> None:
        self.decl = Declarations(module)
        self.uniforms = dict(uniforms or {})
        self.decl.specialize(self.uniforms)
        self.samplers = dict(samplers or {})
        self.location: tuple[str, int] | None = None  # the shader's (file, line) being translated (OpLine)
        entry = typing.cast(Instruction, self.decl.entry)
        self.model, fn_id, self.entry_name, interface = entry.args[0], entry.args[1], entry.args[2], entry.args[3:]
        if self.model not in ("Fragment", "GLCompute"):
            raise SpirvError(f"a {self.model} shader: fragment and compute shaders are supported")
        self.gid_var: int | None = None  # gl_GlobalInvocationID's variable (a compute shader's)
        self.buffers: list = []  # (binding, variable, member, name, element type): a compute shader's arrays
        self.entry = self.decl.functions[fn_id]
        self.phi_types = {ins.id: ins.type for f in self.decl.functions.values()
                          for b in f.blocks.values() for ins in b.body if ins.op == "OpPhi"}
        self.inputs, self.outputs, self.uniform_args = self._interface(interface)
        self._check_given()
        self.global_cells: dict[int, Cell] = {}
        self.output_cells: list[Cell] = []
        self.discards = any(b.terminator.op in ("OpKill", "OpTerminateInvocation")
                            for f in self.decl.functions.values() for b in f.blocks.values())

    def _interface(self, interface):
        d = self.decl
        inputs, outputs = [], []
        for vid in interface:
            var = d.globals[vid]
            storage, typ = var.args[0], d.types[var.type].elem
            deco = d.decorations.get(vid, {})
            if "BuiltIn" in deco:
                builtin = deco["BuiltIn"][0]
                if builtin == "GlobalInvocationId" and self.model == "GLCompute":
                    self.gid_var = vid
                    continue
                if builtin != "FragCoord" or storage != "Input":
                    raise SpirvError(f"built-in {builtin} is not supported (gl_FragCoord and gl_GlobalInvocationID are)")
                inputs.append((1 << 30, vid, "gl_FragCoord", typ))
            elif storage == "Input":
                inputs.append((deco.get("Location", [0])[0], vid, d.name(vid), typ))
            elif storage == "Output":
                outputs.append((deco.get("Location", [0])[0], vid, d.name(vid), typ))
        uniform_args = []
        self.textures = [(vid, d.name(vid), d.types[var.type].elem) for vid, var in d.globals.items()
                         if var.args[0] == "UniformConstant" and d.types[var.type].elem.kind == "sampledimage"]
        for vid, var in d.globals.items():
            if self._is_buffer(vid):
                self._buffer(vid)
                continue
            if var.args[0] != "Uniform":
                continue
            block = d.types[var.type].elem
            if block.kind != "struct":
                raise SpirvError(f"uniform {d.name(vid)} of type {block.kind}: only uniform blocks are supported")
            for k, member in enumerate(block.members):
                name = d.member_names.get((d.pointee[var.type], k), f"{d.name(vid)}.{k}")
                if name not in self.uniforms:
                    uniform_args.append((vid, k, name, member))
        if self.model == "GLCompute":  # one invocation per element: each array is an operand
            self.buffers.sort()
            written = self._written_members()
            self.shared = self._shared_members(written)
            inputs = [(b, (vid, k), name, self.shared.get((vid, k), typ)) for b, vid, k, name, typ in self.buffers
                      if not ((vid, k) in self.shared and name in self.uniforms)]
            outputs = [(b, (vid, k), name, typ) for b, vid, k, name, typ in self.buffers if (vid, k) in written]
            if not outputs:
                raise SpirvError("the compute shader writes no buffer (the kernel would have no output)")
            return inputs, outputs, uniform_args
        return sorted(inputs), sorted(outputs), uniform_args

    def _check_given(self) -> None:
        """Every name in ``uniforms`` is a uniform, a specialization constant or a buffer read at
        constant indices of this shader: a misspelt one is an error, not a silent default."""
        d = self.decl
        known: set = {d.member_names.get((d.pointee[var.type], k), "") for vid, var in d.globals.items()
                 if var.args[0] == "Uniform" and d.types[var.type].elem.kind == "struct"
                 for k in range(len(d.types[var.type].elem.members))}
        known |= {d.names.get(cid) for cid in d.spec_constants} | {n for _, _, _, n, _ in self.buffers}
        known |= {sid for cid in d.spec_constants for sid in d.decorations.get(cid, {}).get("SpecId", [])}
        unknown = [k for k in self.uniforms if k not in known]
        if unknown:
            names = ", ".join(sorted(str(n) for n in known if n)) or "none"
            raise SpirvError(f"uniforms= names {', '.join(map(repr, unknown))}, which the shader does not declare "
                             f"(its uniforms and specialization constants: {names})")

    def _is_buffer(self, vid: int) -> bool:
        var = self.decl.globals[vid]
        struct_id = self.decl.pointee.get(var.type, 0)
        return var.args[0] == "StorageBuffer" or var.args[0] == "Uniform" and \
            "BufferBlock" in self.decl.decorations.get(struct_id, {})

    def _buffer(self, vid: int) -> None:
        d = self.decl
        var = d.globals[vid]
        if self.model != "GLCompute":
            raise SpirvError(f"buffer {d.name(vid)}: storage buffers are supported in compute shaders")
        binding = d.decorations.get(vid, {}).get("Binding", [0])[0]
        block = d.types[var.type].elem
        for k, member in enumerate(block.members):
            name = d.member_names.get((d.pointee[var.type], k), f"{d.name(vid)}.{k}")
            if member.kind != "runtimearray" or not (member.elem.scalar or member.elem.kind == "vector"):
                raise SpirvError(f"buffer member {name}: only arrays of scalars or vectors (T name[]) are supported, "
                                 f"one element per invocation")
            self.buffers.append((binding, vid, k, name, member.elem))

    def _chains(self) -> dict:
        """Each access chain: its base and its indices."""
        return {ins.id: (ins.args[0], ins.args[1:]) for f in self.decl.functions.values()
                for b in f.blocks.values() for ins in b.body if ins.op in ("OpAccessChain", "OpInBoundsAccessChain")}

    def _shared_members(self, written: set) -> dict:
        """The buffer members read at constant indices only, as Kompute's weights ``w[0], w[1]``
        are: each is one argument holding those elements (a ``vecN``, N the highest index read
        plus one; a scalar where N is 1), the same for every invocation."""
        highest: dict = {}
        for base, indices in self._chains().values():
            if base not in {vid for _, vid, *_ in self.buffers} or len(indices) < 2:
                continue
            key = (base, self.decl.constants.get(indices[0], indices[0]))
            index = self.decl.constants.get(indices[1])
            highest[key] = None if index is None or key in highest and highest[key] is None \
                else max(index, highest.get(key) or 0)
        shared = {}
        for _, vid, k, name, typ in self.buffers:
            n = highest.get((vid, k))
            if n is not None and (vid, k) not in written and typ.scalar:
                shared[vid, k] = typ if n == 0 else Type("vector", count=n + 1, elem=typ)
        return shared

    def _written_members(self) -> set:
        """The (buffer variable, member) pairs a store reaches."""
        chains = {cid: (base, indices[0] if indices else None) for cid, (base, indices) in self._chains().items()}
        written = set()
        for f in self.decl.functions.values():
            for b in f.blocks.values():
                for ins in b.body:
                    if ins.op != "OpStore":
                        continue
                    target, member = ins.args[0], None
                    while target in chains:
                        target, index = chains[target]
                        member = index
                    if any(vid == target for _, vid, *_ in self.buffers):
                        written.add((target, self.decl.constants.get(member, member) if member is not None else None))
        return written

    # the kernel ----------------------------------------------------------------------------------

    def signature(self):
        """(parameter names, annotations, result annotation) of the kernel body."""
        names, annotations = [], {}
        for _, vid, name, typ in self.inputs:
            names.append(_identifier(name, names))
            annotations[names[-1]] = typ.dsl()
        for _, _, name, typ in self.uniform_args:
            names.append(_identifier(name, names))
            annotations[names[-1]] = typ.dsl()
        for _, name, typ in self.textures:
            names.append(_identifier(name, names))
            annotations[names[-1]] = self._texture_type(name, typ)
        outs = [typ.dsl() for *_, typ in self.outputs]
        if not outs:
            raise SpirvError("the shader has no output (an 'out' variable with a location)")
        if self.discards:
            outs.append(Type("bool").dsl())  # True where the pixel was discarded
        return names, annotations, outs[0] if len(outs) == 1 else tuple(outs)

    def body(self, *args):
        """The kernel's body: bind inputs, uniforms and outputs, translate main. What it emits is
        located at the shader's lines (``OpLine``: glslang writes them), for errors and ``explain``."""
        from ..ir import emitter as _em
        em = _em.current()
        python_location = em.locate
        em.locate = lambda: self.location or (python_location() if python_location else None)
        d = self.decl
        self.global_cells = {}
        args = list(args)
        if self.model == "GLCompute":
            self._bind_buffers(args)
        for _, vid, _, typ in self.inputs if self.model != "GLCompute" else ():
            self.global_cells[vid] = Cell(_flatten(args.pop(0)))
        uniform_values: dict[tuple[int, int], typing.Any] = {
            (vid, k): _flatten(args.pop(0)) for vid, k, _, _ in self.uniform_args}
        for vid, _, _ in self.textures:
            self.global_cells[vid] = Cell(args.pop(0))  # the texture object, as the sampler's value
        for vid, var in d.globals.items():
            storage, typ = var.args[0], d.types[var.type].elem
            if vid in self.global_cells:
                continue  # bound above (a buffer, a sampler)
            if storage == "Uniform":
                sid = d.pointee[var.type]
                members = []
                for k, member in enumerate(typ.members):
                    name = d.member_names.get((sid, k), f"{d.name(vid)}.{k}")
                    members.append(uniform_values[vid, k] if (vid, k) in uniform_values
                                   else _constant(self.uniforms[name], member))
                self.global_cells[vid] = Cell(tuple(members))
            elif storage in ("Output", "Private"):
                init = d.constants[var.args[1]] if len(var.args) > 1 else zero(typ)
                self.global_cells[vid] = new_cell(typ, init, d.name(vid))
            elif storage != "Input" and vid not in self.global_cells:
                raise SpirvError(f"{storage} variables ({d.name(vid)}) are not supported yet")
        self.output_cells = [self.global_cells[vid] for _, vid, _, _ in self.outputs] \
            if self.model != "GLCompute" else [self.elements[key] for _, key, _, _ in self.outputs]
        if self.discards:
            self.output_cells.append(new_cell(Type("bool"), False, "discarded"))
        result = Frame(self, self.entry).run()
        return result if result is not None else self.outputs_now()

    def _bind_buffers(self, args: list) -> None:
        """A compute shader's arrays: element ``gl_GlobalInvocationID.x`` of each is this lane's
        operand (a variable, holding the input, where the shader writes it)."""
        written = {key for _, key, _, _ in self.outputs}
        self.elements = {}
        members: dict[int, dict] = {}
        for _, vid, k, name, typ in self.buffers:
            if (vid, k) in self.shared:
                shape = self.shared[vid, k]
                value = _constant(self.uniforms[name], shape) if name in self.uniforms else _flatten(args.pop(0))
                members.setdefault(vid, {})[k] = Shared(value if isinstance(value, tuple) else (value,), name)
                continue
            value = _flatten(args.pop(0))
            cell = new_cell(typ, value, name) if (vid, k) in written else Cell(value)
            self.elements[vid, k] = cell
            members.setdefault(vid, {})[k] = Elementwise(cell.slots, name)
        for vid, parts in members.items():
            self.global_cells[vid] = Cell(tuple(parts[k] for k in sorted(parts)))
        if self.gid_var is not None:
            self.global_cells[self.gid_var] = Cell((INVOCATION, 0, 0))

    def _texture_type(self, name: str, typ: Type):
        """The kernel parameter type of a sampler: ``Texture2D``/``Texture3D`` of float texels (vec4),
        with the wrap and filter ``samplers={name: (wrap, filter[, texel])}`` names (default clamp,
        linear; the texel type ``"u8vec4"`` for an 8-bit RGBA array, normalized as GLSL's unorm)."""
        from ..dsl.textures import FILTERS, WRAPS, Texture2D, Texture3D
        wrap, filter_, *texel = tuple(self.samplers.get(name, ("clamp", "linear")))
        if wrap not in WRAPS or filter_ not in FILTERS:
            raise SpirvError(f"samplers[{name!r}]: (wrap, filter[, texel]) with a wrap of {', '.join(WRAPS)} and a "
                             f"filter of {', '.join(FILTERS)}, not {self.samplers.get(name)!r}")
        from ..dsl import vectors
        family = Texture2D if typ.count == 2 else Texture3D
        wanted = texel[0] if texel else "vec4"
        element: typing.Any = getattr(vectors, wanted, None) if "vec" in wanted else None
        if element is None and wanted in KINDS:
            element = value_class(VType(KINDS[wanted], 1))
        if element is None:
            raise SpirvError(f"samplers[{name!r}]: no texel type {texel[0]!r} (vec4, u8vec4, Float ...)")
        return family[element, wrap, filter_]

    def discard(self) -> None:
        """``discard``: the lanes here end, their ``discarded`` output set."""
        self.output_cells[-1].store(True)

    def outputs_now(self):
        values = [to_result(c.load()) for c in self.output_cells]
        return values[0] if len(values) == 1 else tuple(values)

    # one instruction -----------------------------------------------------------------------------

    def instruction(self, fr: Frame, ins: Instruction) -> None:
        op = ins.op
        if op in OPS:
            OPS[op](fr, ins)
        elif op == "OpVariable":
            typ = self.decl.types[ins.type].elem
            init = fr.get(ins.args[1]) if len(ins.args) > 1 else None
            fr.cells[ins.id] = new_cell(typ, init, self.decl.name(ins.id, "var"), lazy=True)
        elif op == "OpLoad":
            fr.put(ins, fr.pointer(ins.args[0]).load())
        elif op == "OpStore":
            fr.pointer(ins.args[0]).store(fr.get(ins.args[1]))
        elif op in ("OpAccessChain", "OpInBoundsAccessChain"):
            indices = [fr.get(a) for a in ins.args[1:]]
            cell = fr.pointer(ins.args[0]).part(indices)
            fr.cells[ins.id] = cell
        elif op == "OpCompositeConstruct":
            typ = self.decl.types[ins.type]
            parts = [fr.get(a) for a in ins.args]
            if typ.kind == "vector":  # vectors of vectors and scalars concatenate
                parts = [x for p in parts for x in (p if isinstance(p, tuple) else (p,))]
            fr.put(ins, tuple(parts))
        elif op == "OpCompositeExtract":
            value = fr.get(ins.args[0])
            for k in ins.args[1:]:
                value = value[k]
            fr.put(ins, value)
        elif op == "OpCompositeInsert":
            fr.put(ins, _insert(fr.get(ins.args[1]), ins.args[2:], fr.get(ins.args[0])))
        elif op == "OpVectorExtractDynamic":
            vector, index = fr.get(ins.args[0]), fr.get(ins.args[1])
            fr.put(ins, vector[index] if isinstance(index, int) else pick(list(vector), index))
        elif op == "OpVectorInsertDynamic":
            vector, part, index = fr.get(ins.args[0]), fr.get(ins.args[1]), fr.get(ins.args[2])
            if isinstance(index, int):
                fr.put(ins, _insert(part, [index], vector))
            else:
                from ..dsl.intrinsics import Select
                fr.put(ins, tuple(Select(index == k, _dsl(part), _dsl(old)) for k, old in enumerate(vector)))
        elif op in ("OpImageSampleImplicitLod", "OpImageSampleExplicitLod"):
            texture, coord = fr.get(ins.args[0]), fr.get(ins.args[1])
            fr.put(ins, _rgba(from_vec(texture.sample(*coord))))
        elif op == "OpImageFetch":
            texture, coord = fr.get(ins.args[0]), fr.get(ins.args[1])
            fr.put(ins, _rgba(from_vec(texture.fetch(*coord))))
        elif op in ("OpImageQuerySizeLod", "OpImageQuerySize"):
            fr.put(ins, tuple(fr.get(ins.args[0]).size))
        elif op in ("OpImage", "OpSampledImage"):
            fr.put(ins, fr.get(ins.args[0]))
        elif op == "OpVectorShuffle":
            a, b = fr.get(ins.args[0]), fr.get(ins.args[1])
            both = list(a) + list(b)
            fr.put(ins, tuple(both[k] for k in ins.args[2:]))
        elif op == "OpVectorTimesScalar" or op == "OpMatrixTimesScalar":
            fr.put(ins, componentwise(_fmul, fr.get(ins.args[0]), fr.get(ins.args[1])))
        elif op == "OpDot":
            a, b = fr.get(ins.args[0]), fr.get(ins.args[1])
            fr.put(ins, _dot(a, b))
        elif op == "OpMatrixTimesVector":
            m, v = fr.get(ins.args[0]), fr.get(ins.args[1])
            fr.put(ins, tuple(_dot(tuple(col[r] for col in m), v) for r in range(len(m[0]))))
        elif op == "OpVectorTimesMatrix":
            v, m = fr.get(ins.args[0]), fr.get(ins.args[1])
            fr.put(ins, tuple(_dot(v, col) for col in m))
        elif op == "OpMatrixTimesMatrix":
            a, b = fr.get(ins.args[0]), fr.get(ins.args[1])
            fr.put(ins, tuple(tuple(_dot(tuple(col[r] for col in a), bc) for r in range(len(a[0]))) for bc in b))
        elif op == "OpTranspose":
            m = fr.get(ins.args[0])
            fr.put(ins, tuple(tuple(col[r] for col in m) for r in range(len(m[0]))))
        elif op == "OpBitcast":
            fr.put(ins, componentwise(lambda x: _bitcast(x, self.decl.types[ins.type]), fr.get(ins.args[0])))
        elif op == "OpArrayLength":
            fr.put(ins, LENGTH)  # a buffer's length: more than any invocation's index
        elif op == "OpExtInst":
            fr.put(ins, self.extended(ins, [fr.get(a) for a in ins.args[2:]]))
        elif op == "OpFunctionCall":
            fr.put(ins, self.call(fr, ins))
        elif op == "OpPhi":
            fr.values[ins.id] = fr.cells[ins.id].load() if ins.id in fr.cells else fr.get(ins.args[0])
        elif op == "OpLine":
            self.location = (_source_name(self.decl.strings.get(ins.args[0], "")), ins.args[1])
        elif op in ("OpNoLine", "OpNop", "OpFunctionParameter"):
            pass
        else:
            raise SpirvError(f"{op} (SPIR-V word {ins.word}) is not supported yet")

    def extended(self, ins: Instruction, args):
        from .grammar import grammar
        set_name = self.decl.imports.get(ins.args[0], "")
        instructions = grammar().extended(set_name)
        if set_name != "GLSL.std.450" or instructions is None:
            raise SpirvError(f"extended instruction set {set_name!r} is not supported (GLSL.std.450 is)")
        name = instructions.by_code[ins.args[1]][0]
        glsl = _GLSL_NAMES.get(name)
        table = builtins_table()
        if glsl is None or glsl not in table:
            if not table:
                raise SpirvError("GLSL.std.450 instructions need the GLSL built-ins: import routines")
            raise SpirvError(f"GLSL.std.450 {name} is not supported yet")
        options = {"precision": "relaxed"} if "RelaxedPrecision" in self.decl.decorations.get(ins.id, {}) \
            and glsl in _ROUTINES else {}
        return from_vec(table[glsl](*[to_vec(_dsl(a) if isinstance(a, float) else a) for a in args], **options))

    def call(self, fr: Frame, ins: Instruction):
        fn = self.decl.functions[ins.args[0]]
        args = []
        for param, a in zip(fn.params, ins.args[1:]):
            if self.decl.types[param.type].kind == "pointer":
                args.append(fr.pointer(a))
            else:
                args.append(fr.get(a))

        def helper(*values):
            callee = Frame(self, fn)
            for param, v in zip(fn.params, values):
                if isinstance(v, Cell):
                    callee.cells[param.id] = v
                else:
                    callee.values[param.id] = v
                    callee.spilled.discard(param.id)
                    callee.cells[param.id] = Cell(v)
            return to_result(callee.run())
        helper.__name__ = _identifier(self.decl.name(fn.id).split("(")[0], [])
        result = inline(helper)(*args)
        return from_vec(result) if result is not None else None


_GLSL_NAMES = {
    "Round": "round", "RoundEven": "roundEven", "Trunc": "trunc", "FAbs": "abs", "SAbs": "abs", "FSign": "sign",
    "SSign": "sign", "Floor": "floor", "Ceil": "ceil", "Fract": "fract", "Radians": "radians", "Degrees": "degrees",
    "Sin": "sin", "Cos": "cos", "Tan": "tan", "Asin": "asin", "Acos": "acos", "Atan": "atan", "Sinh": "sinh",
    "Cosh": "cosh", "Tanh": "tanh", "Atan2": "atan", "Pow": "pow", "Exp": "exp", "Log": "log", "Exp2": "exp2",
    "Log2": "log2", "Sqrt": "sqrt", "InverseSqrt": "inversesqrt", "FMin": "min", "UMin": "min", "SMin": "min",
    "FMax": "max", "UMax": "max", "SMax": "max", "FClamp": "clamp", "UClamp": "clamp", "SClamp": "clamp",
    "FMix": "mix", "Step": "step", "SmoothStep": "smoothstep", "Fma": "fma", "Length": "length",
    "Distance": "distance", "Cross": "cross", "Normalize": "normalize", "FaceForward": "faceforward",
    "Reflect": "reflect", "Refract": "refract", "NMin": "min", "NMax": "max", "NClamp": "clamp",
}
_ROUTINES = {"sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "pow", "exp", "log", "exp2",
             "log2", "sqrt", "inversesqrt"}




class Elementwise:
    """A buffer's array as a compute shader sees it: only the element of its own invocation."""

    def __init__(self, element, name: str) -> None:
        self.element, self.name = element, name

    def __getitem__(self, index):
        if index is not INVOCATION:
            raise SpirvError(f"buffer {self.name} is indexed by something other than gl_GlobalInvocationID.x: one "
                             f"invocation per element reads and writes its own element only (a buffer read at "
                             f"constant indices only is one argument, the same for every invocation)")
        return self.element

    def __len__(self) -> int:
        raise SpirvError(f"buffer {self.name}: an index known only at run time is not supported")

    def __iter__(self):
        return iter(())


class Shared(Elementwise):
    """A buffer's array read at constant indices only: the elements every invocation sees."""

    def __init__(self, elements: tuple, name: str) -> None:
        super().__init__(elements, name)

    def __getitem__(self, index):
        if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < len(self.element):
            raise SpirvError(f"buffer {self.name} is read at constant indices elsewhere: it cannot also be indexed "
                             f"by {index!r}")
        return self.element[index]


def _bitcast(x, typ: Type):
    """OpBitcast of one component to ``typ``'s kind (int and uint are one kind here; the
    invocation's index and a length pass as they are)."""
    kind = typ.elem.kind if typ.kind == "vector" else typ.kind
    if x is INVOCATION or x is LENGTH or isinstance(x, int) and not isinstance(x, bool) and kind == "int":
        return x
    from ..dsl.intrinsics import As
    target = _KIND[kind]
    value = _dsl(x, "Float" if isinstance(x, float) else "Int")
    if value.kind.name == target:
        return value
    return As(value_class(VType(KINDS[target], value.width)), value)


def _source_name(path: str) -> str:
    """A shader file's name for messages (GLSL text given inline was compiled from a temporary file)."""
    return "<GLSL source>" if "reactor-glsl-" in path else path


def _rgba(texel):
    """A texel as GLSL's vec4 (missing channels 0, alpha 1)."""
    channels = list(texel) if isinstance(texel, tuple) else [texel]
    return tuple(channels + [0.0, 0.0, 1.0][len(channels) - 1:]) if len(channels) < 4 else tuple(channels)


def _flatten(arg):
    return tuple(arg._c) if isinstance(arg, Vec) else arg


def _constant(value, typ: Type):
    """A uniform given at build time, flattened to its type."""
    if typ.scalar:
        return float(value) if typ.kind == "float" else bool(value) if typ.kind == "bool" else int(value)
    seq = list(value)
    if len(seq) != typ.count:
        raise SpirvError(f"a uniform of {typ.count} components was given {len(seq)}")
    return tuple(_constant(v, typ.elem) for v in seq)


def _identifier(name: str, taken: list) -> str:
    base = "".join(c if c.isalnum() or c == "_" else "_" for c in name) or "arg"
    if base[0].isdigit() or base in taken or base in ("lambda", "class", "def", "in", "out", "return"):
        base = f"{base}_{len(taken)}"
    return base


def kernel_body(spirv: bytes, uniforms: dict | None = None, samplers: dict | None = None):
    """A Python function with the shader's kernel signature that translates it (what
    ``reactor.kernel`` traces). It holds only the SPIR-V bytes and the uniforms given, so the disk
    cache keys a build by them (a warm build does not translate); marked as already written, so the
    Python rewrite leaves it alone."""
    from .binary import decode

    translator = malformed_is_an_error(lambda: Translator(decode(spirv), uniforms, samplers))
    names, annotations, result = malformed_is_an_error(translator.signature)
    given = tuple(sorted(((k, _frozen(v)) for k, v in (uniforms or {}).items()), key=repr))
    states = tuple(sorted((k, tuple(v)) for k, v in (samplers or {}).items()))

    def body(*args):
        return run_translation(spirv, given, states, args)
    setattr(body, "__signature__", inspect.Signature([  # noqa: B010 - what inspect.signature reads
        inspect.Parameter(n, inspect.Parameter.POSITIONAL_OR_KEYWORD) for n in names]))
    body.__annotations__ = dict(annotations, **{"return": result})
    body.__name__ = translator.entry_name
    setattr(body, "__reactor_syntax__", True)  # noqa: B010 - already as written: not rewritten
    return body, translator


def run_translation(spirv: bytes, given: tuple, states: tuple, args: tuple):
    """Translate ``spirv`` (with the uniforms ``given`` and the sampler ``states``) into the body
    being built, on ``args``."""
    from .binary import decode
    return malformed_is_an_error(lambda: Translator(decode(spirv), dict(given), dict(states)).body(*args))


def malformed_is_an_error(step):
    """``step()``, where a module that refers to what it never declares (an id, a type, a block),
    or nests without end, is one ``SpirvError`` (spirv-val, when installed, catches these first)."""
    try:
        return step()
    except ReactorError:
        raise
    except (KeyError, IndexError, AttributeError, TypeError, ValueError, RecursionError, struct.error) as exc:
        detail = f"%{exc.args[0]} is not declared" if isinstance(exc, KeyError) else f"{type(exc).__name__}: {exc}"
        raise SpirvError(f"malformed SPIR-V module: {detail}") from None


def _frozen(value):
    """A uniform's value as numbers and tuples (what the build's key can state)."""
    if isinstance(value, (bool, int, float)):
        return value
    if isinstance(value, np.generic):
        return value.item()
    return tuple(_frozen(v) for v in value)
