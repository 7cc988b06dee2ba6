"""``@kernel``: a per-element DSL body becomes a real ``numpy.ufunc``.

::

    @reactor.kernel
    def saxpy(a: Float, x: Float, y: Float) -> Float:
        return a * x + y

    saxpy(2.0, xs, ys, out=zs)          # broadcasting, out=, where=, any shape

The body is written once for any width: it receives values of the build's
SIMD width on the vector path and scalars on the strided path. Several
inputs and several outputs (``-> (Float, Float)``) are supported. The result
is an ordinary ufunc (``isinstance(saxpy, numpy.ufunc)``); ``kernel_of(saxpy)``
returns its ``Kernel`` with the IR, optimized IR and assembly.

Several signatures make one ufunc with one loop each, as numba's
``@vectorize([...])`` (the body is kind-generic; NumPy picks the loop)::

    @reactor.kernel(["float32(float32, float32)", "float64(float64, float64)"])
    def hypot(x, y):
        return Sqrt(x * x + y * y)

Types are NumPy's names (float32, float64, int32, uint32, bool) or reactor's
(Float, Double, Int, UInt, Bool); several results are written
``(float32, bool)(float32)``. A signature with 64-bit elements is built at
half the target's natural width (the same bytes per vector) unless a width
is given.
"""
from __future__ import annotations

import ctypes
import dataclasses
import gc
import threading
import typing
import weakref

import re

import numpy as np

from ..build import Build, current_options
from ..dsl import builtins as _builtins
from ..dsl.syntax import as_written
from ..dsl.signature import Signature
from ..dsl.values import value_class
from ..errors import DSLTypeError, ReactorError
from ..ir import emitter as _em
from ..ir.types import KINDS, VType
from ..dsl.external import External
from ..dsl.intrinsics import precision
from ..jit import cache
from ..jit.compiler import CompiledCode, ShowsCode, cached_object
from ..dsl.calls import RoutineCall, calls_of
from ..dsl.limits import STATUS, messages_of
from .recipe import recipe_watch, unchanged
from . import loop, parallel, tiers
from .loop import LoopEmitter, emit_body, estimated_cycles
from .operands import core_layout, gufunc_signature, operand_of
from .ufunc_api import make_ufunc

_registry: "dict[int, weakref.ref[Kernels]]" = {}
_registry_lock = threading.Lock()
_memo: "dict[tuple, weakref.ref[Kernels]]" = {}


#: Vector bodies of at least this many IR instructions are compiled once (see ``Kernel._module``):
#: below it a second, width-1 body compiles faster than the code that gathers elements for the
#: vector body (``python benchmarks/bench_compile.py`` measures both sides).
ONE_BODY_MIN = 200


class Kernel(ShowsCode):
    """A compiled kernel: its ufunc's machine code and how it was made (``routines``: the
    library routines it calls, with precision, FMA and the user's line)."""

    ufunc_ref: "_UfuncRef"  # set when its ufunc is made
    routines: "list[RoutineCall]"
    config: "ctypes.Structure"  # the ufunc loop's data: an abi.LOOP_CONFIG or abi.ERROR_LOOP

    def __init__(self, body, name: str, signature: Signature, build: Build):
        self.name, self.build, self.signature = name, build, signature
        self.body = body  # traced again by reactor.explain (with source lines) and reactor.plan
        ins, outs = _operands(signature, name)
        self.ins, self.outs = ins, outs
        self.in_kinds, self.out_kinds = [o.kind for o in ins], [o.kind for o in outs]
        self.gufunc_signature = gufunc_signature(ins, outs)
        self.code = self._from_recipe(body, signature) or self._traced(body, signature)
        if build.target.runnable:
            self._loop = parallel.dispatcher()  # every kernel's ufunc loop: its code comes with the config
            self.config = parallel.make_config(len(ins) + len(outs), self.cycles_per_element, self.messages,
                                               core_layout(ins, outs)[2], *self._code_addresses(self.code))
        else:  # built to be read (assembly, IR): its ufunc raises instead of running foreign instructions
            self._loop, self.config = parallel.error_loop(self.code.unrunnable_reason(), ReactorError)
        self._signature = [[k.dtype for k in ins + outs]]
        self.types = "".join(k.dtype.char for k in ins) + "->" + "".join(k.dtype.char for k in outs)

    def _exports(self) -> tuple[str, ...]:
        """The symbols the dispatcher needs from this kernel's code: its loop, and its status when
        a loop of its body is limited (``messages``)."""
        return (f"{self.name}.loop",) + ((STATUS,) if self.messages else ())

    def _code_addresses(self, code: CompiledCode) -> tuple[int, int]:
        """(loop, status) of ``code`` for ``parallel.make_config``/``set_code`` (status 0: none)."""
        return code.address(f"{self.name}.loop"), code.address(STATUS) if self.messages else 0

    def _module(self, body, lines: bool = False) -> tuple[_em.ModuleEmitter, float]:
        """Trace ``body`` into its module: the bodies and the loop (with the
        user's source line on every instruction if ``lines``)."""
        body = as_written(body, self.build.cache)  # Python's if/while/for on DSL values run at run time
        build, name, ins, outs = self.build, self.name, self.ins, self.outs
        collecting = gc.isenabled()
        gc.disable()  # tracing makes many objects and frees none: collections there cost, find nothing
        try:
            module = _em.ModuleEmitter(name, build, lines=lines)
            vector, hoisted = emit_body(module, name, body, ins, outs, build.width) if build.width > 1 else (None, None)
            size = _size(vector, hoisted) if vector is not None else 0
            # A large body is compiled once: the vector body also serves the elements the vector loop
            # cannot read in place (reactor_move gathers them into W-lane buffers). A small one is
            # traced again at width 1 for them: its copy costs less than the gathering code. Uniform
            # operands, which may differ per element, always take the width-1 body.
            needs_scalar = vector is None or any(o.uniform for o in ins) or size < ONE_BODY_MIN
            scalar = emit_body(module, name, body, ins, outs, 1)[0] if needs_scalar else None
            LoopEmitter(module, f"{name}.loop", vector, scalar, ins, outs, build.width, hoisted).emit()
            module.text  # noqa: B018 - serialized here, once, still without collections
        finally:
            if collecting:
                gc.enable()
        return module, estimated_cycles(size if vector is not None else _size(scalar, None),
                                        build.width if vector else 1)

    def traced_with_lines(self) -> _em.ModuleEmitter:
        """This kernel's module traced again with source lines (for ``reactor.explain``)."""
        return self._module(self.body, lines=True)[0]

    def _recipe(self, body, signature) -> str | None:
        build_key = self.build.key() + (() if loop.UNIFORM_WORK else ("no uniform work",))
        key, self.watch = recipe_watch(body, "kernel", self.name, signature, build_key)
        return key

    def unchanged(self) -> bool:
        """Whether a build of the same body now would give this kernel (nothing it read was rebound;
        a body without a recipe key is traced again)."""
        return self.recipe is not None and unchanged(self.watch)

    def _from_recipe(self, body, signature) -> CompiledCode | None:
        """The code a body with this recipe compiled to before, without tracing it (None: trace)."""
        build = self.build
        self.recipe = self._recipe(body, signature)
        found = cache.recipe_get(self.recipe, build.cache) if self.recipe else None
        if not found:
            return None
        obj, source = cached_object(found["ir_key"], build.cache)
        imports: dict[str, int] = {}
        for symbol, library in found["imports"]:
            address = External.resolve(symbol, library)
            if address is None:
                return None  # the library is gone: trace, and let the External report it
            imports[symbol] = address
        if obj is None:
            return None
        self.cycles_per_element, self.messages = found["cycles"], found["messages"]
        self.routines = [RoutineCall(*call) for call in found.get("routines", [])]
        code = CompiledCode(None, build.target, build.opt, self._exports(), build.cache, imports, key=found["ir_key"],
                            obj=obj, source=source, ir_source=lambda: self._module(body)[0].text)
        code.source = f"recipe, {source}" if code.source != "compiled" else code.source
        return code

    def _traced(self, body, signature) -> CompiledCode:
        build = self.build
        module, self.cycles_per_element = self._module(body)
        self.messages = messages_of(module)
        self.routines = calls_of(module)
        full = (module.text, build.target, build.opt, self._exports(), build.cache, module.imports)
        if tiers.enabled() and build.target.runnable:
            self.full_compile: tuple | None = (full, sorted(module.import_libraries.items()))  # tier_up
            return CompiledCode(*full, quick=True)
        code = CompiledCode(*full)
        self._put_recipe(code, sorted(module.import_libraries.items()))
        return code

    def _put_recipe(self, code: CompiledCode, libraries: list) -> None:
        if self.recipe:
            cache.recipe_put(self.recipe, {"ir_key": code.key, "cycles": self.cycles_per_element,
                                           "imports": libraries, "messages": self.messages,
                                           "routines": [dataclasses.astuple(c) for c in self.routines]},
                             self.build.cache)

    def tier_up(self) -> None:
        """Compile this kernel's IR fully, cache it, and make its dispatcher run it from the next
        call on; its quick code is kept (a call may still be running it)."""
        assert self.full_compile is not None
        full, libraries = self.full_compile
        code = CompiledCode(*full)
        self._put_recipe(code, libraries)
        self.quick_code, self.code = self.code, code
        parallel.set_code(self.config, *self._code_addresses(code))
        self.full_compile = None

    def __repr__(self):
        return f"<reactor.Kernel {self.name} {self.build.describe()}>"


def _operands(signature: Signature, name: str):
    """The kernel's input and output Operands (elements, vectors, uniform tables and textures)."""
    if signature.returns is None:
        raise DSLTypeError(f"kernel '{name}' needs a return annotation (-> Float or -> (Float, Float))")
    returns = signature.returns if isinstance(signature.returns, tuple) else (signature.returns,)
    ins = [operand_of(f"'{name}' parameter '{n}'", p) for n, p in zip(signature.names, signature.params)]
    outs = [operand_of(f"'{name}' result", r) for r in returns]
    if any(o.uniform for o in outs):
        raise DSLTypeError(f"kernel '{name}': a result is one value or vector per element, not a Table or "
                           f"Texture")
    if not any(not o.uniform for o in ins):
        raise DSLTypeError(f"kernel '{name}' needs at least one input that is not a Table or Texture "
                           f"(the elements it runs over)")
    return ins, outs


def build_kernel(body, *, name: str | None = None, args=None, returns=..., signatures=None, **options):
    """Compile ``body`` into a ufunc (see module docstring); options as for Function."""
    import inspect

    name = name or body.__name__
    if signatures:
        sigs = [parse_signature(text, body) for text in signatures]
    else:
        sigs = [Signature.from_function(body, args, inspect.Parameter.empty if returns is ... else returns)]
    base = current_options().merged(**options)
    builds = [_build_for(sig, base, name) for sig in sigs]
    key = (body, name, tuple(sigs), tuple(builds))
    known = _memo.get(key)
    cached = known() if known is not None else None
    if cached is not None and cached.ufunc_ref() is not None and all(k.unchanged() for k in cached.kernels):
        return cached.ufunc_ref()
    kernels = [Kernel(body, name, sig, build) for sig, build in zip(sigs, builds)]
    shapes = {(len(k.in_kinds), len(k.out_kinds), k.gufunc_signature) for k in kernels}
    inputs = [tuple(k.in_kinds) for k in kernels]
    if len(shapes) > 1 or len(set(inputs)) < len(inputs):
        raise DSLTypeError(f"kernel '{name}': its signatures need the same numbers of inputs and outputs "
                           f"and different input types")
    group = Kernels(kernels)
    given = {f.name: getattr(base, f.name) for f in dataclasses.fields(base) if getattr(base, f.name) is not None}
    if "sites" in given:  # a Plan travels as its resolved sites (not with its planned ufunc)
        given["sites"] = builds[0].sites
    group.travel = ("kernel", body, dict(given, name=name, signatures=signatures, args=args,
                                         **({} if returns is ... else {"returns": returns})))
    doc = (body.__doc__ or f"reactor kernel '{name}'").strip() + "\n\nBuilt for " + \
        "; ".join(f"{k.types}: {k.build.describe()}" for k in kernels) + "."
    ref = group.ufunc_ref
    traps = _dtype_traps(name, kernels)  # first: NumPy takes the first loop its operands fit
    after = _wide_traps(name, kernels)  # last: only what no loop takes safely reaches them
    group.traps = [data for _, _, data in traps + after]
    ufunc = make_ufunc(name, doc, [t[0] for t in traps] + [k._loop for k in kernels] + [t[0] for t in after],
                       [t[1] for t in traps] + [k._signature[0] for k in kernels] + [t[1] for t in after],
                       len(kernels[0].in_kinds), len(kernels[0].out_kinds), owner=(group, _UfuncFreed(ref)),
                       data=[ctypes.addressof(t[2]) for t in traps] + [ctypes.addressof(k.config) for k in kernels]
                       + [ctypes.addressof(t[2]) for t in after],
                       signature=kernels[0].gufunc_signature)
    ref._id = id(ufunc)
    for k in kernels:
        k.ufunc_ref = ref
        if getattr(k, "full_compile", None) is not None:
            tiers.submit(k.tier_up)
    with _registry_lock:
        _registry[id(ufunc)] = weakref.ref(group)
        _memo[key] = weakref.ref(group)
    weakref.finalize(group, _forget, id(ufunc), key)
    return ufunc


#: integer dtypes NumPy would convert to a float texture's or table's dtype without a word
_CONVERTIBLE = [np.dtype(t) for t in ("bool", "uint8", "int8", "uint16", "int16", "uint32", "int32")]


def _dtype_traps(name: str, kernels) -> list:
    """Loops that raise for a Table/Texture argument of another dtype, which NumPy would convert
    silently (a uint8 image's 0..255 to float32 0..255): (loop, dtypes, data) each."""
    from ..errors import ArgumentError
    traps = []
    for k in kernels:
        for j, o in enumerate(k.ins):
            if not o.uniform:
                continue
            for dt in _CONVERTIBLE:
                # integers to a float texture: 0..255 would stay 0..255 (value-preserving casts pass)
                if not (o.kind.is_float and dt.kind in "biu") or not np.can_cast(dt, o.dtype, "safe"):
                    continue
                hint = "convert it yourself"
                if dt == np.uint8 and o.kind.is_float:
                    texel = (f"{o.texture.family}[UByte] (codes 0..255)" if o.channels == 1 else
                             f"{o.texture.family}[u8vec{o.channels}] (read as unorm 0..1)")
                    hint = f"declare {texel}, or {hint}"
                message = (f"kernel '{name}': {o.name.split(' ', 1)[-1]} is a {o.texture.name} of {o.dtype}, not "
                           f"{dt}: NumPy would convert the {dt} data silently; {hint} "
                           f"(e.g. array.astype(np.{o.dtype}))")
                loop, data = parallel.error_loop(message, ArgumentError)
                dtypes = list(k._signature[0])
                dtypes[j] = dt
                traps.append((loop, dtypes, data))
    return traps


#: dtypes a float32 argument is given that NumPy will not cast to float32 safely, narrowest first
_WIDE = [np.dtype(t) for t in ("int32", "int64", "float64")]


def _wide_traps(name: str, kernels) -> list:
    """Loops that raise one TypeError naming the argument, its dtype and the two ways on, for
    float64 and 32/64-bit integer data given to float32 arguments (NumPy's own message names
    neither): every combination for up to two such arguments, each alone and all at once for more.
    They come after the kernel's loops, so whatever fits those (float32, or int16 and smaller,
    cast safely as NumPy casts them) never reaches them."""
    import itertools

    from ..errors import ArgumentError
    k = kernels[0]
    if len(kernels) > 1:
        return []
    names = list(k.signature.names)
    floats = [j for j, o in enumerate(k.ins) if not o.uniform and o.dtype == np.float32]
    if not floats:
        return []
    if len(floats) <= 2:
        choices = [c for c in itertools.product([None, *_WIDE], repeat=len(floats)) if any(c)]
    else:
        choices = [tuple(dt if i == j else None for i in range(len(floats))) for j in range(len(floats))
                   for dt in _WIDE] + [tuple([dt] * len(floats)) for dt in _WIDE]
    choices.sort(key=lambda c: [(_WIDE.index(d) + 1) if d is not None else 0 for d in c])
    traps = []
    nin = len(k.ins)
    for choice in choices:
        # outputs of a dtype nobody asks for (complex64): a call with dtype=np.float32 (or float64) is
        # never theirs, and NumPy casts it to the kernel's loop as asked (or says it has none)
        dtypes = list(k._signature[0][:nin]) + [np.dtype(np.complex64) if dt == np.float32 else dt
                                                for dt in k._signature[0][nin:]]
        wide = []
        for j, dt in zip(floats, choice):
            if dt is not None:
                dtypes[j] = dt
                wide.append(f"'{names[j]}' is {dt}" + (" (a Python int is int64 here)" if dt == np.int64 else
                                                        " (a Python float is float64)" if dt == np.float64 else ""))
        message = (f"kernel '{name}' computes in float32, and its argument {' and '.join(wide)}: NumPy will not "
                   f"round them to float32 unasked. Pass arrays of float32 (x.astype(np.float32)), or call with "
                   f"dtype=np.float32, casting='same_kind' to have NumPy round them")
        loop, data = parallel.error_loop(message, ArgumentError)
        traps.append((loop, dtypes, data))
    return traps


def _build_for(sig: Signature, base, name: str) -> Build:
    """The build of one signature: 64-bit elements at half the natural width unless a width is set."""
    build = base.resolved()
    if base.width is None:
        ins, outs = _operands(sig, name)
        if any(o.kind.bits == 64 for o in ins + outs):
            build = build.replace(width=max(4, build.target.natural_width // 2))
    return build


_SIGNATURE = re.compile(r"\s*(\([^()]*\)|\w+)\s*\(([^()]*)\)\s*")


def parse_signature(text, body) -> Signature:
    """A ``Signature`` from numba's form ``"float32(float32, float32)"`` (or ``(a, b)(x)`` for
    several results), naming kinds as NumPy (float32 ...) or reactor (Float ...) does."""
    import inspect

    if not isinstance(text, str):
        raise DSLTypeError(f"a kernel signature is a string such as 'float32(float32)', not {text!r}")
    m = _SIGNATURE.fullmatch(text)
    if m is None:
        raise DSLTypeError(f"kernel signature {text!r} is not of the form 'float32(float32, float32)'")
    ret, args = m.group(1), m.group(2)
    rets = [r for r in ret.strip("()").split(",") if r.strip()]
    params = [value_class(VType(_kind(a, text), 1)) for a in args.split(",") if a.strip()]
    results = [value_class(VType(_kind(r, text), 1)) for r in rets]
    names = tuple(inspect.signature(body).parameters)
    if len(names) != len(params):
        raise DSLTypeError(f"kernel signature {text!r} has {len(params)} input(s), but the body takes "
                           f"{len(names)}")
    return Signature(names, tuple(params), tuple(results) if ret.startswith("(") else results[0])


def _kind(token: str, text: str):
    token = token.strip()
    if token in KINDS:
        return KINDS[token]
    try:
        dtype = np.dtype(token)
    except TypeError:
        dtype = None
    for kind in KINDS.values():
        if kind.dtype == dtype:
            return kind
    names = ", ".join(sorted({str(k.dtype) for k in KINDS.values()} | set(KINDS)))
    raise DSLTypeError(f"kernel signature {text!r}: unknown type {token!r} (one of {names})")


class Kernels:
    """The kernels of one ufunc, one per signature (what the ufunc owns), and how the ufunc
    travels (``reactor.kernels.pickling``: pickled as its recipe)."""

    def __init__(self, kernels: list[Kernel]):
        self.kernels = kernels
        self.ufunc_ref = _UfuncRef()
        self.traps: list = []  # the data of the loops that refuse a dtype (kept with the ufunc)
        self.travel: tuple = ()


def group_of(ufunc) -> "Kernels | None":
    """The Kernels behind a reactor ufunc (None for any other object)."""
    with _registry_lock:
        ref = _registry.get(id(ufunc))
    group = ref() if ref is not None else None
    return group if group is not None and group.ufunc_ref._id == id(ufunc) else None


def _size(body, hoisted) -> int:
    """The instructions of a body as traced that still run per element (with its uniform work split
    off, the body keeps its own copy of that work, unused: ``reactor.ir.hoist``)."""
    return _em.ModuleEmitter.instruction_count(body) - (hoisted.dead if hoisted else 0)


def _body_of(ufunc):
    """A reactor ufunc's body as a call to inline in another kernel's body, at its own precision."""
    group = group_of(ufunc)
    if group is None:
        return None
    first = group.kernels[0]

    def inline(*inputs):
        with precision(first.build.precision):
            return first.body(*inputs)
    return inline


_builtins.set_kernel_bodies(_body_of)


class _UfuncRef:
    """A non-owning handle from a Kernel back to its ufunc (ufuncs have no weakrefs).
    The ufunc owns the Kernel, but the Kernel may outlive it (``kernel_of``), so
    ``_UfuncFreed`` clears the handle when the ufunc is freed; then it gives None."""

    def __init__(self):
        self._id = None

    def __call__(self):
        import ctypes
        return None if self._id is None else ctypes.cast(self._id, ctypes.py_object).value


class _UfuncFreed:
    """Owned by the ufunc alone: freed with it, and then kills the Kernel's handle."""

    def __init__(self, ref):
        self.ref = ref

    def __del__(self):
        self.ref._id = None


def _forget(ufunc_id, key):
    with _registry_lock:
        ref = _registry.get(ufunc_id)
        if ref is not None and ref() is None:  # another live kernel may reuse the id
            del _registry[ufunc_id]
        ref = _memo.get(key)
        if ref is not None and ref() is None:
            del _memo[key]


Body = typing.Callable[..., typing.Any]
Signatures = typing.Union[str, typing.Sequence[str]]


@typing.overload
def kernel(body: Body, signatures: Signatures | None = None, **kwargs: typing.Any) -> np.ufunc: ...
@typing.overload  # noqa: E302
def kernel(body: Signatures | None = None, signatures: Signatures | None = None,
           **kwargs: typing.Any) -> typing.Callable[[Body], np.ufunc]: ...


def kernel(body=None, signatures=None, **kwargs):  # noqa: E302
    """Decorator: ``@kernel``, ``@kernel(width=8, fma=False, name=...)`` or
    ``@kernel(["float32(float32)", "float64(float64)"])``; returns a numpy.ufunc."""
    if isinstance(body, (list, tuple, str)):
        body, signatures = None, body
    if isinstance(signatures, str):
        signatures = [signatures]
    if body is None:
        return lambda b: build_kernel(b, signatures=signatures, **kwargs)
    return build_kernel(body, signatures=signatures, **kwargs)


def kernel_of(ufunc: np.ufunc, types: str | typing.Sequence[typing.Any] | None = None) -> Kernel:
    """The ``Kernel`` behind a ufunc made by reactor (for its IR and assembly): its first loop,
    or the loop for ``types`` (as in ``ufunc.types``, e.g. ``"dd->d"``, or input dtypes)."""
    group = group_of(ufunc)
    if group is None:
        raise ReactorError(f"{ufunc!r} is not a reactor kernel")
    if types is None:
        return group.kernels[0]
    for k in group.kernels:
        if types in (k.types, k.types.split("->")[0]) or (
                isinstance(types, (tuple, list)) and tuple(np.dtype(t) for t in types) ==
                tuple(kind.dtype for kind in k.in_kinds)):
            return k
    raise ReactorError(f"{ufunc.__name__} has no loop for {types!r}; it has {', '.join(ufunc.types)}")

