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
"""
from __future__ import annotations

import ctypes
import threading
import weakref

from ..build import Build, current_options
from ..dsl.signature import Signature
from ..errors import DSLTypeError, ReactorError
from ..ir import emitter as _em
from ..ir.types import PointerType, VType
from ..jit.compiler import CompiledCode, ShowsCode
from . import parallel
from .loop import LoopEmitter, emit_body, emit_dispatcher, estimated_cycles
from .ufunc_api import make_ufunc

_registry: "dict[int, weakref.ref[Kernel]]" = {}
_registry_lock = threading.Lock()
_memo: "dict[tuple, weakref.ref]" = {}


class Kernel(ShowsCode):
    """A compiled kernel: its ufunc's machine code and how it was made."""

    def __init__(self, body, name: str, signature: Signature, build: Build):
        self.name, self.build = name, build
        ins, outs = _kinds(signature, name)
        self.in_kinds, self.out_kinds = ins, outs
        module = _em.ModuleEmitter(name, build)
        loop_name, entry_name = f"{name}.loop", f"{name}.ufunc"
        vector = emit_body(module, name, body, ins, outs, build.width) if build.width > 1 else None
        scalar = emit_body(module, name, body, ins, outs, 1)
        serial = LoopEmitter(module, loop_name, vector, scalar, ins, outs, build.width).emit()
        emit_dispatcher(module, entry_name, serial)
        self.code = CompiledCode(module.text, build.target, build.opt, (loop_name, entry_name), build.cache,
                                 module.imports)
        self._loop = self.code.address(entry_name)
        self.cycles_per_element = estimated_cycles(vector or scalar, build.width if vector else 1)
        self.config = parallel.make_config(len(ins) + len(outs), self.cycles_per_element)
        self._signature = [[k.dtype for k in ins + outs]]

    def __repr__(self):
        return f"<reactor.Kernel {self.name} {self.build.describe()}>"


def _kinds(signature: Signature, name: str):
    params, returns = signature.resolved(1, f"kernel '{name}'")
    if returns is None:
        raise DSLTypeError(f"kernel '{name}' needs a return annotation (-> Float or -> (Float, Float))")
    outs = returns if isinstance(returns, tuple) else (returns,)
    for what, t in [("parameter", p) for p in params] + [("result", r) for r in outs]:
        if isinstance(t, PointerType) or not isinstance(t, VType) or t.width != 1:
            raise DSLTypeError(f"kernel '{name}': every {what} must be a scalar element type "
                               f"(Float, Int, ...), not {t!r}; the body is vectorized for you")
    if not params:
        raise DSLTypeError(f"kernel '{name}' needs at least one input")
    return [p.kind for p in params], [r.kind for r in outs]


def build_kernel(body, *, name: str | None = None, args=None, returns=..., **options):
    """Compile ``body`` into a ufunc (see module docstring); options as for Function."""
    import inspect

    name = name or body.__name__
    signature = Signature.from_function(body, args, inspect.Parameter.empty if returns is ... else returns)
    build = current_options().merged(**options).resolved()
    key = (body, name, signature, build)
    cached = _memo.get(key)
    cached = cached() if cached is not None else None
    if cached is not None and cached.ufunc_ref() is not None:
        return cached.ufunc_ref()
    kern = Kernel(body, name, signature, build)
    doc = (body.__doc__ or f"reactor kernel '{name}'").strip()
    kern.ufunc_ref = ref = _UfuncRef()
    ufunc = make_ufunc(name, doc, [kern._loop], kern._signature, len(kern.in_kinds),
                       len(kern.out_kinds), owner=(kern, _UfuncFreed(ref)),
                       data=[ctypes.addressof(kern.config)])
    ref._id = id(ufunc)
    with _registry_lock:
        _registry[id(ufunc)] = weakref.ref(kern)
        _memo[key] = weakref.ref(kern)
    weakref.finalize(kern, _forget, id(ufunc), key)
    return ufunc


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


def kernel(body=None, **kwargs):
    """Decorator: ``@kernel`` or ``@kernel(width=8, fma=False, name=...)``; returns a numpy.ufunc."""
    if body is None:
        return lambda b: build_kernel(b, **kwargs)
    return build_kernel(body, **kwargs)


def kernel_of(ufunc) -> Kernel:
    """The ``Kernel`` behind a ufunc made by reactor (for its IR and assembly)."""
    with _registry_lock:
        ref = _registry.get(id(ufunc))
    kern = ref() if ref is not None else None
    if kern is None or kern.ufunc_ref._id != id(ufunc):
        raise ReactorError(f"{ufunc!r} is not a reactor kernel")
    return kern
