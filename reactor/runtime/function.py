"""Functions you can also call from Python, the modules they compile in, and their routines.

::

    @reactor.function
    def dot4(a: Pointer[Float4], b: Pointer[Float4]) -> Float:
        p = a[0] * b[0]
        return Extract(p, 0) + Extract(p, 1) + Extract(p, 2) + Extract(p, 3)

    dot4(np.ones(4, np.float32), np.arange(4, dtype=np.float32))   # -> 6.0
    dot4.compile().assembly                                        # machine code

A ``Function`` called while another function is being built emits a call; called
from Python it compiles (once per set of build settings) and runs the machine code.
"""
from __future__ import annotations

import ctypes
import threading
import typing

import numpy as np

from ..travel import arrive, reduce_body
from ..build import Build, current_options
from ..dsl.definition import FunctionDef
from ..dsl.calls import RoutineCall, calls_of
from ..dsl.limits import STATUS, messages_of
from ..errors import ArityError, LoopLimitError, ReactorError
from ..ir import emitter as _em
from ..jit.compiler import CompiledCode, ShowsCode
from . import entry


class Function(FunctionDef):
    """A DSL function: ``Function(body, args=None, returns=..., name=None, **options)``.

    Types come from the body's annotations unless ``args``/``returns`` are given.
    Build options (fma, width, opt, target, cache, precision) default to the
    enclosing ``reactor.options`` context at compile time.
    """

    def __init__(self, body: typing.Callable[..., typing.Any], args: typing.Sequence[typing.Any] | None = None,
                 returns: typing.Any = ..., name: str | None = None, **options: typing.Any) -> None:
        super().__init__(body, args, returns, name, **options)
        self._compiled: dict[tuple, Routine] = {}
        self._lock = threading.Lock()

    def build_settings(self, **overrides) -> Build:
        """The resolved settings of a build of this function (context, then its own options, then ``overrides``)."""
        return current_options().merged(**self.option_overrides).merged(**overrides).resolved()

    def __call__(self, *args: typing.Any) -> typing.Any:
        if _em.building():
            return self.emit_call(args)
        return self.compile()(*args)

    def __reduce__(self):
        """Pickled as its recipe (where it lives, or its body; its options), never its machine code."""
        where, payload = reduce_body(self, self.body, f"function '{self.name}'")
        return _rebuild_function, (where, payload, self.name, list(self.signature.params), self.signature.returns,
                                   dict(self.option_overrides))

    def compile(self, **options: typing.Any) -> "Routine":
        """The routine for these build options (compiled once, then cached)."""
        build = self.build_settings(**options)
        with self._lock:
            routine = self._compiled.get(build.key())
            if routine is None:
                routine = self._compiled[build.key()] = Module([self]).compile_with(build)[self.name]
        return routine


def _rebuild_function(where, payload, name, args, returns, options) -> "Function":
    """The Function pickled by ``Function.__reduce__``, found or built on this side."""
    return arrive(where, payload, lambda f: isinstance(f, Function),
                  lambda body: Function(body, args=args, returns=returns, name=name, **options), "function")


@typing.overload
def function(body: typing.Callable[..., typing.Any], **kwargs: typing.Any) -> Function: ...
@typing.overload  # noqa: E302
def function(body: None = None, **kwargs: typing.Any) -> typing.Callable[[typing.Callable[..., typing.Any]], Function]: ...


def function(body=None, **kwargs):  # noqa: E302
    """Decorator form of ``Function``: ``@function`` or ``@function(fma=False)``."""
    if body is None:
        return lambda b: Function(b, **kwargs)
    return Function(body, **kwargs)


class Module:
    """Several functions compiled together into one piece of machine code."""

    def __init__(self, functions=()):
        self.functions: list[FunctionDef] = list(functions)

    def function(self, body=None, **kwargs):
        """Decorator that defines a Function and adds it to this module."""
        def add(b):
            fn = Function(b, **kwargs)
            self.functions.append(fn)
            return fn
        return add(body) if body is not None else add

    def build(self, build: Build, lines: bool = False) -> _em.ModuleEmitter:
        """The module's IR: every function and its C entry point (with the user's source line on
        every instruction if ``lines``: see ``reactor.explain``)."""
        names = [f.name for f in self.functions]
        dupes = {n for n in names if names.count(n) > 1}
        if dupes:
            raise ReactorError(f"module has several functions named {', '.join(sorted(dupes))}")
        mod = _em.ModuleEmitter(self.functions[0].name if self.functions else "module", build, lines=lines)
        for fn in self.functions:
            irfn = fn.declare_in(mod, build.width)
            params, returns = fn.signature.resolved(build.width, f"'{fn.name}'")
            entry.emit_entry(mod, fn.name, irfn, params, returns)
        return mod

    def compile(self, **options) -> "CompiledModule":
        return self.compile_with(current_options().merged(**options).resolved())

    def compile_with(self, build: Build) -> "CompiledModule":
        mod = self.build(build)
        messages, calls = messages_of(mod), calls_of(mod)
        exports = tuple(f.name + entry.SUFFIX for f in self.functions) + ((STATUS,) if messages else ())
        code = CompiledCode(mod.text, build.target, build.opt, exports, build.cache, mod.imports)
        return CompiledModule(code, {f.name: Routine(f, code, build, mod.written.get((f, build.width), frozenset()),
                                              messages, calls) for f in self.functions})


class CompiledModule(dict):
    """Compiled routines of a module, by name (also as attributes)."""

    def __init__(self, code, routines):
        super().__init__(routines)
        self.code = code

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None


Library = CompiledModule  # its former name ("library" now means only the routines' collection)


_ENTRY = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_void_p)


class Routine(ShowsCode):
    """A compiled Function, callable from Python with numbers and NumPy arrays.

    Scalars are range-checked and converted; pointer arguments must be
    C-contiguous NumPy arrays of the pointee's dtype, holding at least the
    declared number of elements; vector arguments are arrays of ``width``
    elements. Vector results come back as NumPy arrays.
    """

    def __init__(self, fn: FunctionDef, code, build: Build, written: frozenset = frozenset(),
                 messages: typing.Sequence[str] = (), calls: typing.Sequence[RoutineCall] = ()):
        self.function, self.code, self.build = fn, code, build
        self.written = written  # indices of the pointer arguments the routine stores to
        self.messages = list(messages)  # of the module's loops with max_iterations, by status - 1
        self.routines = list(calls)  # the library routines the module calls (RoutineCall)
        self.name = fn.name
        self.params, self.returns = fn.signature.resolved(build.width, f"'{fn.name}'")
        self._entry = None

    def __repr__(self):
        return f"<reactor.Routine {self.name} {self.build.describe()}>"

    @property
    def address(self) -> int:
        """Address of the C entry point ``void entry(void **argv, void *ret)``."""
        return self.code.address(self.name + entry.SUFFIX)

    def __call__(self, *args):
        names = self.function.signature.names
        if len(args) != len(self.params):
            raise ArityError(f"routine '{self.name}' takes {len(self.params)} argument(s) "
                             f"({', '.join(names)}), got {len(args)}")
        if self._entry is None:
            self._entry = _ENTRY(self.address)
        keep = entry.arguments(self.name, names, self.params, args, self.written)  # alive during the call
        ptrs = (ctypes.c_void_p * max(1, len(args)))(*[buf.ctypes.data for buf in keep])
        ret = None
        if self.returns is not None:
            ret = np.zeros(self.returns.width, self.returns.kind.dtype)
        self._entry(ctypes.addressof(ptrs), None if ret is None else ret.ctypes.data)
        if self.messages:
            self._check_loops()
        if ret is None:
            return None
        return ret[0].item() if self.returns.width == 1 else ret

    def _check_loops(self) -> None:
        """Raise if a loop with ``max_iterations`` ran out during the call (the module's status,
        reset for the next call; concurrent calls of one module share it)."""
        status = ctypes.c_int32.from_address(self.code.address(STATUS))
        number, status.value = status.value, 0
        if number:
            raise LoopLimitError(self.messages[number - 1])
