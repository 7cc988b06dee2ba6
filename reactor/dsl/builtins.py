"""The GLSL built-ins a library installs (GLSL name -> function over DSL scalars and vectors):
what SPIR-V's GLSL.std.450 instructions call, and what NumPy's functions on DSL values dispatch
to (``np.sin(x)`` in a kernel body is GLSL's ``sin``). ``routines`` installs ``routines.glsl``'s
when imported, and declares them under the entry point group ``reactor.glsl_builtins``."""
from __future__ import annotations

import typing

_BUILTINS: dict[str, typing.Callable] = {}
#: ufunc -> its kernel's body as a call to inline (at the kernel's precision), or None for a ufunc
#: reactor did not make; set by the kernels layer (reactor.kernels.kernel), which this layer does not import
_kernel_body: typing.Callable[[typing.Any], "typing.Callable | None"] = lambda ufunc: None

#: NumPy's ufuncs and functions -> GLSL's built-ins of the same meaning
NUMPY_TO_GLSL = {
    "sin": "sin", "cos": "cos", "tan": "tan", "arcsin": "asin", "arccos": "acos", "arctan": "atan",
    "arctan2": "atan", "sinh": "sinh", "cosh": "cosh", "tanh": "tanh", "exp": "exp", "exp2": "exp2",
    "log": "log", "log2": "log2", "sqrt": "sqrt", "power": "pow", "absolute": "abs", "fabs": "abs",
    "floor": "floor", "ceil": "ceil", "trunc": "trunc", "rint": "roundEven", "sign": "sign",
    "minimum": "min", "maximum": "max", "fmin": "min", "fmax": "max", "clip": "clamp",
}


def set_builtins(table: dict[str, typing.Callable]) -> None:
    """Install the GLSL built-ins (GLSL name -> function over DSL scalars and vectors)."""
    _BUILTINS.update(table)


def builtins_table() -> dict[str, typing.Callable]:
    """The GLSL built-ins installed; if none yet, those a package declares under the entry point
    group ``reactor.glsl_builtins`` (``routines`` declares its own), loaded."""
    if not _BUILTINS:
        from importlib.metadata import entry_points
        for point in entry_points(group="reactor.glsl_builtins"):
            set_builtins(point.load())
    return _BUILTINS


def set_kernel_bodies(resolver: typing.Callable[[typing.Any], "typing.Callable | None"]) -> None:
    """Install how a reactor ufunc called in a kernel body finds its body (a call to inline)."""
    global _kernel_body
    _kernel_body = resolver


def inline_kernel(ufunc, inputs: tuple, kwargs: dict):
    """A reactor kernel called in another kernel's body, inlined as GLSL inlines a function call:
    its body on the caller's values, at its own precision and the caller's FMA setting; None for a
    ufunc reactor did not make."""
    found = _kernel_body(ufunc)
    if found is None:
        return None
    if kwargs:
        from ..errors import DSLTypeError
        raise DSLTypeError(f"kernel {ufunc.__name__} called in a kernel body with NumPy's options "
                           f"({', '.join(kwargs)}=): they have no meaning there; call it with the values alone")
    return found(*inputs)


def numpy_call(name: str, args: tuple, kwargs: dict):
    """NumPy's ``name(*args)`` on DSL values, as GLSL's built-in of the same meaning; a clear
    error where there is none (or where NumPy's options, ``out=`` and the like, are asked)."""
    from ..errors import DSLTypeError
    glsl = NUMPY_TO_GLSL.get(name)
    table = builtins_table()
    if glsl is None or kwargs or glsl not in table:
        hint = f"routines.glsl.{glsl}" if glsl else "the operators, reactor's intrinsics or routines.glsl's built-ins"
        why = "NumPy's options (out=, where=, dtype=) have no meaning there" if glsl and kwargs else \
            "import routines to install the GLSL built-ins" if glsl else "NumPy's functions take arrays"
        raise DSLTypeError(f"np.{name} on a DSL value in a kernel body: {why}; use {hint}")
    return table[glsl](*args)


def array_ufunc(self, ufunc, method, *inputs, **kwargs):
    """``__array_ufunc__`` of the DSL's values and vectors: ``np.sin(x)`` is GLSL's ``sin``
    (``np.power`` its ``pow`` ...); another ufunc, a ufunc method, or NumPy's options: an error."""
    if method != "__call__":
        from ..errors import DSLTypeError
        raise DSLTypeError(f"np.{ufunc.__name__}.{method} on a DSL value: NumPy's ufunc methods take arrays")
    inlined = inline_kernel(ufunc, inputs, kwargs)
    if inlined is not None:
        return inlined
    return numpy_call(ufunc.__name__, inputs, kwargs)


def array_function(self, func, types, args, kwargs):
    """``__array_function__`` of the DSL's values and vectors: ``np.clip`` is GLSL's ``clamp``;
    ``np.where`` says to write ``Select`` (or an ``if``)."""
    if func.__name__ == "where":
        from ..errors import DSLTypeError
        raise DSLTypeError("np.where on DSL values: write reactor.Select(cond, a, b), or an if statement")
    return numpy_call(func.__name__, args, kwargs)
