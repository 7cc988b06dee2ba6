"""Functions, modules and their compiled routines.

A ``Function`` is a Python body plus a typed signature. Calling it while
another function is being built emits an LLVM call (the callee is built into
the same module on first use, so several functions share a module and may
call each other, recursively too). Calling it from plain Python compiles it
(once per set of build options) and runs the machine code::

    @reactor.function
    def dot4(a: Pointer[Float4], b: Pointer[Float4]) -> Float:
        p = a[0] * b[0]
        return Extract(p, 0) + Extract(p, 1) + Extract(p, 2) + Extract(p, 3)

    dot4(np.ones(4, np.float32), np.arange(4, dtype=np.float32))   # -> 6.0
    dot4.compile().assembly                                        # machine code
"""
from __future__ import annotations

import ctypes
import functools
import threading

import numpy as np
from llvmlite import ir

from ..errors import (ArgumentError, ArityError, DSLTypeError, MissingReturnError, ReactorError,
                      at_return_of)
from ..ir import emitter as _em
from ..options import BuildOptions, current_options
from .signature import Signature
from .types import PointerType, VType
from .values import Value, to_ir, value_class
from .variables import PointerValue

ENTRY_SUFFIX = ".entry"


class Function:
    """A DSL function: ``Function(body, args=None, returns=..., name=None, **options)``.

    Types come from the body's annotations unless ``args``/``returns`` are given.
    Build options (fma, width, opt, target, cache) default to the enclosing
    ``reactor.options`` context at compile time.
    """

    def __init__(self, body, args=None, returns=..., name: str | None = None, **options):
        import inspect
        self.body = body
        self.name = name or body.__name__
        self.signature = Signature.from_function(
            body, args, inspect.Parameter.empty if returns is ... else returns)
        self.options = BuildOptions().merged(**options) if options else None
        self._option_overrides = {k: v for k, v in options.items() if v is not None}
        self._compiled: dict[BuildOptions, Routine] = {}
        self._lock = threading.Lock()
        code = getattr(body, "__code__", None)
        self.location = (code.co_filename, code.co_firstlineno) if code else None
        functools.update_wrapper(self, body)

    def __repr__(self):
        return f"<reactor.Function {self.name}>"

    # -- options ----------------------------------------------------------
    def build_options(self, **overrides) -> BuildOptions:
        base = current_options()
        if self._option_overrides:  # only the options given, not BuildOptions' defaults
            base = base.merged(**self._option_overrides)
        return base.merged(**overrides).resolved()

    # -- building ---------------------------------------------------------
    def declare_in(self, module: _em.ModuleEmitter, width: int) -> ir.Function:
        """The LLVM function for this definition in ``module`` (built on first use)."""
        key = (self, width)
        if key in module.functions:
            return module.functions[key]
        params, returns = self.signature.resolved(width, f"'{self.name}'")
        ret_ir = _return_ir(returns)
        em = _em.FunctionEmitter(module, module.unique_name(self.name), ret_ir,
                                 [p.ir for p in params], list(self.signature.names), width=width)
        em.dsl_function = _Built(self.name, returns, params)
        module.functions[key] = em.function
        with em:
            from .control import check_python_returns
            check_python_returns(self.body)
            args = [PointerValue(p, a, em) if isinstance(p, PointerType) else value_class(p)._wrap(a, em)
                    for p, a in zip(params, em.function.args)]
            result = self.body(*args)
            if result is not None and not em.terminated():
                from .control import Return
                with at_return_of(self.body):
                    Return(result)
            for block in em.finish():
                if returns is not None:
                    raise MissingReturnError(
                        f"function '{self.name}' returns {returns.name} but can reach its end "
                        f"without Return", location=self.location)
                em.position_at(block)
                em.ret(None)
            em.finish()
        module.written[key] = frozenset(k for k, a in enumerate(args) if isinstance(a, PointerValue) and a.written)
        return em.function

    def __call__(self, *args):
        if _em.building():
            return self._emit_call(args)
        return self.compile()(*args)

    def _emit_call(self, args):
        em = _em.current()
        if len(args) != len(self.signature.names):
            raise ArityError(f"'{self.name}' takes {len(self.signature.names)} argument(s), got {len(args)}")
        params, returns = self.signature.resolved(em.width, f"'{self.name}'")
        fn = self.declare_in(em.module, em.width)
        written = em.module.written.get((self, em.width))  # None: still being built (recursion)
        irs = []
        for k, (name, p, a) in enumerate(zip(self.signature.names, params, args)):
            if isinstance(p, PointerType):
                if not isinstance(a, PointerValue) or a.ptype.pointee != p.pointee:
                    raise DSLTypeError(f"'{self.name}' parameter '{name}' needs a {p.name}, got {a!r}")
                if written is None or k in written:
                    a.written = True
                irs.append(a._ptr()[1])
            else:
                if isinstance(a, Value) and (a.kind != p.kind or a.width not in (1, p.width)):
                    raise DSLTypeError(f"'{self.name}' parameter '{name}' needs a {p.name}, got a {a.vtype.name}")
                irs.append(to_ir(a, p))
        result = em.call(fn, irs, name=self.name if returns is not None else "")
        return None if returns is None else value_class(returns)._wrap(result, em)

    # -- compiling --------------------------------------------------------
    def compile(self, **options) -> "Routine":
        """The routine for these build options (compiled once, then cached)."""
        opts = self.build_options(**options)
        with self._lock:
            routine = self._compiled.get(opts)
            if routine is None:
                routine = self._compiled[opts] = Module([self]).compile(**vars(opts))[self.name]
        return routine


class _Built:
    """What a function body's emitter knows about the function (for Return)."""

    def __init__(self, name, returns, params):
        self.name, self.returns, self.params = name, returns, params


def _return_ir(returns) -> ir.Type:
    if returns is None:
        return ir.VoidType()
    if isinstance(returns, tuple) or not isinstance(returns, VType):
        raise DSLTypeError(f"a function returns one value type, not {returns!r}")
    return returns.ir


def function(body=None, **kwargs):
    """Decorator form of ``Function``: ``@function`` or ``@function(fma=False)``."""
    if body is None:
        return lambda b: Function(b, **kwargs)
    return Function(body, **kwargs)


class Module:
    """Several functions compiled together into one piece of machine code."""

    def __init__(self, functions=()):
        self.functions: list[Function] = list(functions)

    def function(self, body=None, **kwargs):
        """Decorator that defines a Function and adds it to this module."""
        def add(b):
            fn = Function(b, **kwargs)
            self.functions.append(fn)
            return fn
        return add(body) if body is not None else add

    def build(self, **options) -> tuple[_em.ModuleEmitter, BuildOptions]:
        opts = current_options().merged(**options).resolved()
        names = [f.name for f in self.functions]
        dupes = {n for n in names if names.count(n) > 1}
        if dupes:
            raise ReactorError(f"module has several functions named {', '.join(sorted(dupes))}")
        mod = _em.ModuleEmitter(self.functions[0].name if self.functions else "module", opts)
        for fn in self.functions:
            irfn = fn.declare_in(mod, opts.width)
            params, returns = fn.signature.resolved(opts.width, f"'{fn.name}'")
            _emit_entry(mod, fn.name, irfn, params, returns)
        return mod, opts

    def compile(self, **options) -> "Library":
        from ..jit.compiler import CompiledCode
        from ..jit.target import get_target
        mod, opts = self.build(**options)
        code = CompiledCode(str(mod.module), get_target(opts.target), opts.opt,
                            tuple(f.name + ENTRY_SUFFIX for f in self.functions), opts.cache, mod.imports)
        return Library(code, {f.name: Routine(f, code, opts, mod.written.get((f, opts.width), frozenset()))
                              for f in self.functions})


class Library(dict):
    """Compiled routines of a module, by name (also as attributes)."""

    def __init__(self, code, routines):
        super().__init__(routines)
        self.code = code

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None


def _emit_entry(mod, name, irfn, params, returns):
    """``void name.entry(i8** argv, i8* ret)``: a uniform C entry point. ``argv[k]``
    is the address of argument k's value (scalars, vectors) or the pointer
    argument itself; the result is stored at ``ret``."""
    i8p = ir.IntType(8).as_pointer()
    em = _em.FunctionEmitter(mod, name + ENTRY_SUFFIX, ir.VoidType(), [i8p.as_pointer(), i8p], ["argv", "ret"])
    argv, retp = em.function.args
    args = []
    for k, p in enumerate(params):
        pname = irfn.args[k].name  # the parameter's name in the DSL function
        slot = em.emit("load", em.emit("gep", argv, [ir.Constant(ir.IntType(64), k)], name=f"{pname}.argv"),
                       name=f"{pname}.arg")
        if isinstance(p, PointerType):
            args.append(em.emit("bitcast", slot, p.ir, name=pname))
        else:
            typed = em.emit("bitcast", slot, p.mem_ir.as_pointer(), name=f"{pname}.slot")
            val = em.emit("load", typed, name=pname, align=p.kind.mem_bytes)
            if p.kind.category == "bool":
                val = em.emit("trunc", val, p.ir, name=f"{pname}.bool")
            args.append(val)
    result = em.call(irfn, args, name="result" if returns is not None else "")
    if returns is not None:
        out = em.emit("bitcast", retp, returns.mem_ir.as_pointer(), name="retslot")
        if returns.kind.category == "bool":
            result = em.emit("zext", result, returns.mem_ir, name="byte")
        em.emit("store", result, out, align=returns.kind.mem_bytes)
    em.ret(None)
    em.finish()


_ENTRY = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_void_p)


class Routine:
    """A compiled Function, callable from Python with numbers and NumPy arrays.

    Scalars are range-checked and converted; pointer arguments must be
    C-contiguous NumPy arrays of the pointee's dtype, holding at least the
    declared number of elements; vector arguments are arrays of ``width``
    elements. Vector results come back as NumPy arrays.
    """

    def __init__(self, fn: Function, code, options: BuildOptions, written: frozenset = frozenset()):
        self.function, self.code, self.options = fn, code, options
        self.written = written  # indices of the pointer arguments the routine stores to
        self.name = fn.name
        self.params, self.returns = fn.signature.resolved(options.width, f"'{fn.name}'")
        self._entry = None

    def __repr__(self):
        return f"<reactor.Routine {self.name} {self.options}>"

    @property
    def ir(self) -> str:
        """The module's LLVM IR as built (before optimization)."""
        return self.code.ir_text

    @property
    def optimized_ir(self) -> str:
        return self.code.optimized_ir

    @property
    def assembly(self) -> str:
        return self.code.assembly

    @property
    def address(self) -> int:
        """Address of the C entry point ``void entry(void **argv, void *ret)``."""
        return self.code.address(self.name + ENTRY_SUFFIX)

    def __call__(self, *args):
        names = self.function.signature.names
        if len(args) != len(self.params):
            raise ArityError(f"routine '{self.name}' takes {len(self.params)} argument(s) "
                             f"({', '.join(names)}), got {len(args)}")
        if self._entry is None:
            self._entry = _ENTRY(self.address)
        keep, ptrs = [], (ctypes.c_void_p * max(1, len(args)))()
        scalars = {}
        for k, (name, p, a) in enumerate(zip(names, self.params, args)):
            if isinstance(p, VType) and p.width == 1:
                scalars[name] = a
        for k, (name, p, a) in enumerate(zip(names, self.params, args)):
            buf = _argument(self.name, name, p, a, scalars, k in self.written)
            keep.append(buf)  # the arrays must outlive the call
            ptrs[k] = buf.ctypes.data
        ret = None
        if self.returns is not None:
            ret = np.zeros(self.returns.width, self.returns.kind.dtype)
        self._entry(ctypes.addressof(ptrs), None if ret is None else ret.ctypes.data)
        if ret is None:
            return None
        return ret[0].item() if self.returns.width == 1 else ret


def _argument(routine: str, name: str, p, a, scalars, written: bool = False) -> np.ndarray:
    """The NumPy array whose data ``argv[k]`` points to for parameter type ``p``:
    the argument's own array for pointers, a one-element copy for scalars."""
    where = f"routine '{routine}' argument '{name}'"
    if isinstance(p, PointerType):
        vt = p.pointee
        if not isinstance(a, np.ndarray):
            raise ArgumentError(f"{where} must be a NumPy array of {vt.kind.dtype}, not {type(a).__name__}")
        if a.dtype != vt.kind.dtype:
            raise ArgumentError(f"{where} must have dtype {vt.kind.dtype}, not {a.dtype}")
        if not a.flags.c_contiguous:
            raise ArgumentError(f"{where} must be C-contiguous (use np.ascontiguousarray)")
        if written and not a.flags.writeable:
            raise ArgumentError(f"{where} is read-only, but the routine stores to it")
        count = p.length if isinstance(p.length, int) else 1
        if isinstance(p.length, str):
            try:
                count = int(scalars[p.length])
            except (TypeError, ValueError):  # not a number: the scalar's own check reports it
                count = 0
        need = max(count, 0) * vt.width
        if a.size < need:
            raise ArgumentError(f"{where} has {a.size} element(s) but the routine may access "
                                f"{need} ({p.name})")
        return a
    if p.width > 1:
        arr = np.asarray(a)
        if arr.dtype != p.kind.dtype or arr.shape != (p.width,):
            raise ArgumentError(f"{where} must be a {p.name}: an array of {p.width} {p.kind.dtype}, "
                                f"got {arr.dtype} with shape {arr.shape}")
        return np.ascontiguousarray(arr)
    return np.array([_scalar(where, p, a)], dtype=p.kind.dtype)


def _scalar(where: str, p: VType, a):
    cat = p.kind.category
    if isinstance(a, np.ndarray) and a.ndim == 0:
        a = a.item()
    if isinstance(a, np.generic):
        a = a.item()
    if cat == "bool":
        if not isinstance(a, (bool, np.bool_)):
            raise ArgumentError(f"{where} must be a bool, not {a!r}")
        return bool(a)
    if cat == "float":
        if isinstance(a, bool) or not isinstance(a, (int, float)):
            raise ArgumentError(f"{where} must be a number, not {a!r}")
        return float(a)
    if isinstance(a, bool) or not isinstance(a, int):
        raise ArgumentError(f"{where} must be an int, not {a!r}")
    lo, hi = (-(2**31), 2**31) if cat == "int" else (0, 2**32)
    if not lo <= a < hi:
        raise ArgumentError(f"{where} = {a} is out of range for {p.name} [{lo}, {hi - 1}]")
    return a
