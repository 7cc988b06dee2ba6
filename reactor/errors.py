"""Exceptions raised while building, compiling or calling reactor code.

Every error raised because of something the user wrote carries the user's
``file:line`` (the innermost stack frame outside reactor and the builder
libraries registered with ``hide_frames_of``), so the message points at the
offending DSL line rather than at library internals.
"""
from __future__ import annotations

import contextlib
import os
import sys
import types

_LIBRARY_DIRS = [os.path.dirname(os.path.abspath(__file__)) + os.sep]


def hide_frames_of(package_dir: str) -> None:
    """Report errors raised inside ``package_dir`` at the line of its caller, as
    for reactor's own frames (for libraries of DSL builders, such as routines)."""
    path = os.path.abspath(package_dir) + os.sep
    if path not in _LIBRARY_DIRS:
        _LIBRARY_DIRS.append(path)


def library_dirs() -> tuple[str, ...]:
    """reactor's folder and those registered with ``hide_frames_of``."""
    return tuple(_LIBRARY_DIRS)


_CONTEXTLIB = os.path.abspath(contextlib.__file__)  # the library's ``with`` helpers run there


def user_frame(start: types.FrameType | None = None) -> types.FrameType | None:
    """The innermost frame outside the library (the user's code), from ``start`` outwards
    (default: the caller's)."""
    frame: types.FrameType | None = start if start is not None else sys._getframe(1)
    dirs = tuple(_LIBRARY_DIRS)
    while frame is not None:
        name = frame.f_code.co_filename
        filename = os.path.abspath(name)
        if not filename.startswith(dirs) and filename != _CONTEXTLIB and "importlib" not in filename \
                and not name.startswith("<frozen"):
            return frame
        frame = frame.f_back
    return None


def user_location() -> tuple[str, int] | None:
    """Return ``(filename, lineno)`` of the innermost frame outside the library."""
    frame = user_frame()
    return None if frame is None else (frame.f_code.co_filename, frame.f_lineno)


def return_location(body) -> tuple[str, int] | None:
    """Where the DSL body ``body`` returns its value: the line of its only
    ``return <value>`` statement, else its ``def`` line. Used for errors found in
    a returned value after the body's frame is gone."""
    from .source import return_lines

    code = getattr(body, "__code__", None)
    if code is None:
        return None
    found = return_lines(code)
    return (code.co_filename, found[0][0]) if len(found) == 1 else (code.co_filename, code.co_firstlineno)


@contextlib.contextmanager
def at_return_of(body):
    """Report errors raised in the block at ``body``'s return statement."""
    try:
        yield
    except ReactorError as exc:
        raise type(exc)(exc.problem, location=return_location(body)) from None


class ReactorError(Exception):
    """Base class: a mistake in reactor code, reported at the user's line."""

    def __init__(self, message: str, location: tuple[str, int] | None = None):
        self.location = location if location is not None else user_location()
        self.problem = message
        if self.location:
            message = f"{message} (at {self.location[0]}:{self.location[1]})"
        super().__init__(message)


class DSLTypeError(ReactorError, TypeError):
    """Operands of incompatible types, e.g. a Float added to an Int."""


class WidthMismatchError(DSLTypeError):
    """Vector operands of different widths (1 broadcasts; 4 and 8 do not)."""


class ScopeError(ReactorError):
    """A value used outside the function or block that defined it."""


class ControlFlowError(ReactorError):
    """Misplaced Elif/Else/Return, blocks closed out of order, unclosed blocks."""


class MissingReturnError(ControlFlowError):
    """A function with a return type can reach its end without ``Return``."""


class LoopLimitError(ReactorError, RuntimeError):
    """A loop given ``max_iterations=N`` ran N iterations and was stopped (raised by the call)."""


class ArityError(ReactorError, TypeError):
    """A function, routine or intrinsic called with the wrong number of arguments."""


class ArgumentError(ReactorError, TypeError):
    """A routine called with an argument of the wrong dtype, size or kind."""


class FmaDisabledError(ReactorError):
    """``Fma`` requested in a build whose FMA option is off."""


class CompileError(ReactorError):
    """LLVM rejected the generated module (a reactor bug; please report it)."""


class MissingDependencyError(ReactorError, ImportError):
    """An optional dependency a feature needs is not installed (the message names its extra)."""


def require(module: str, extra: str, feature: str) -> types.ModuleType:
    """``module`` imported, or a ``MissingDependencyError`` saying that ``feature`` needs it and
    which extra of reactor-simd installs it."""
    import importlib
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name is None or module.split(".")[0] != exc.name.split(".")[0]:
            raise  # the module is there and imports something missing: its own traceback
        raise MissingDependencyError(f"{feature} needs {exc.name.split('.')[0]}, which is not installed: "
                                     f"pip install 'reactor-simd[{extra}]'") from None


class CacheWarning(UserWarning):
    """The disk cache cannot be used or kept (not this user's, writable by others, a full or
    read-only disk) or an entry was removed; compiling goes on without it."""

