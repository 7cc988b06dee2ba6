"""DSL function definitions: a Python body plus a typed signature, built into a module.

Calling a definition while another function is being built emits an LLVM call;
the callee is built into the same module on first use (at the caller's width),
so several functions share a module and may call each other, recursively too.
Compiling a definition and calling it from Python is the runtime's job
(``reactor.runtime``: ``reactor.Function`` adds ``compile()`` and Python calls).
"""
from __future__ import annotations

import functools

from ..build import BuildOptions
from ..errors import ArityError, DSLTypeError, MissingReturnError, at_return_of, return_location
from ..ir import emitter as _em
from ..ir import types as T
from ..ir.types import PointerType, VType
from .signature import Signature
from .values import Value, shown, to_ir, value_class
from .context import begin, check_entered
from .syntax import as_written
from .variables import PointerValue


class FunctionDef:
    """A DSL function: ``FunctionDef(body, args=None, returns=..., name=None, **options)``.

    Types come from the body's annotations unless ``args``/``returns`` are given.
    ``options`` (fma, width, opt, target, cache, precision) are kept for the runtime,
    which merges them over the enclosing ``reactor.options`` context at compile time.
    """

    def __init__(self, body, args=None, returns=..., name: str | None = None, **options):
        import inspect
        self.body = body
        self.name = name or body.__name__
        self.signature = Signature.from_function(
            body, args, inspect.Parameter.empty if returns is ... else returns)
        BuildOptions().merged(**options)  # unknown names are an error now, not at compile time
        self.option_overrides = {k: v for k, v in options.items() if v is not None}
        code = getattr(body, "__code__", None)
        self.location = (code.co_filename, code.co_firstlineno) if code else None
        functools.update_wrapper(self, body)

    def __repr__(self):
        return f"<reactor.Function {self.name}>"

    def declare_in(self, module: _em.ModuleEmitter, width: int):
        """The LLVM function for this definition in ``module`` (built on first use)."""
        key = (self, width)
        if key in module.functions:
            return module.functions[key]
        params, returns = self.signature.resolved(width, f"'{self.name}'")
        if returns is not None and not isinstance(returns, VType):
            raise DSLTypeError(f"a function returns one value type, not {returns!r}")
        em = _em.FunctionEmitter(module, module.unique_name(self.name), returns, params,
                                 list(self.signature.names), width=width)
        written = as_written(self.body, module.build.cache)  # Python's if/while/for on DSL values run at run time
        body = begin(em, Built(self.name, returns, params), written)
        module.functions[key] = em.function
        with em:
            from .control import check_python_returns, return_value
            check_python_returns(written)
            names = list(self.signature.names)

            def length_of(p):  # a pointer's declared length: (type, IR value), converted where used
                if isinstance(p.length, int):
                    return (T.INDEX, T.const(T.INDEX, p.length))
                if isinstance(p.length, str) and p.length in names:
                    k = names.index(p.length)
                    if isinstance(params[k], VType) and params[k].width == 1 and params[k].kind.is_integer:
                        return (params[k], em.params[k])
                return None
            args = [PointerValue(p, a, em, length_of(p)) if isinstance(p, PointerType)
                    else value_class(p)._wrap(a, em) for p, a in zip(params, em.params)]
            result = written(*args)
            if result is not None and not em.terminated():
                with at_return_of(self.body):
                    body.after_return = return_location(self.body)
                    return_value(result, from_user=False)
            check_entered(em)
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
        return self.emit_call(args)

    def emit_call(self, args):
        """Emit a call of this function in the function being built (built at its width)."""
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
                    raise DSLTypeError(f"'{self.name}' parameter '{name}' needs a {p.name}, got a {shown(a.vtype)}")
                irs.append(to_ir(a, p))
        result = em.call(fn, irs, name=self.name if returns is not None else "")
        return None if returns is None else value_class(returns)._wrap(result, em)


class Built:
    """What a body's emitter knows about the function it builds (for ``Return``)."""

    is_kernel = False

    def __init__(self, name, returns, params):
        self.name, self.returns, self.params = name, returns, params
