"""Calling C functions in shared libraries from DSL code.

::

    exp2f16 = External("_ZGVeN16v_exp2f", returns=Float16, args=(Float16,), library="libmvec.so.1")

    @kernel(width=16)
    def peer(x: Float) -> Float:
        return exp2f16(x)

Arguments and results are passed by value in the C calling convention of the
target, so vector types map to SIMD registers (the x86 vector-function ABI of
glibc's libmvec and SLEEF). The symbol is resolved when the module is
compiled; ``available`` says whether the library and symbol exist here.
"""
from __future__ import annotations

import ctypes
import ctypes.util
import functools

from ..errors import ArityError, DSLTypeError, ReactorError
from ..ir import emitter as _em
from .signature import resolve
from ..ir.types import VType
from .values import Value, shown, to_ir, value_class


@functools.cache
def _library(name: str | None):
    if name is None:
        return ctypes.CDLL(None)
    path = name if "/" in name or ".so" in name else (ctypes.util.find_library(name) or name)
    return ctypes.CDLL(path, mode=ctypes.RTLD_GLOBAL)


class External:
    """A typed C function ``symbol`` from ``library`` (None: the process itself)."""

    def __init__(self, symbol: str, returns, args, library: str | None = None):
        self.symbol, self.library = symbol, library
        self.returns = resolve(returns, 1, f"External '{symbol}' result")
        self.args = tuple(resolve(a, 1, f"External '{symbol}' argument") for a in args)
        if not isinstance(self.returns, VType) or not all(isinstance(a, VType) for a in self.args):
            raise DSLTypeError(f"External '{symbol}': arguments and result must be value types")

    @functools.cached_property
    def address(self) -> int | None:
        """The symbol's address, or None if the library or symbol is missing."""
        return self.resolve(self.symbol, self.library)

    @staticmethod
    def resolve(symbol: str, library: str | None) -> int | None:
        """The address of ``symbol`` in ``library`` (None: the process), or None if missing."""
        try:
            return ctypes.cast(getattr(_library(library), symbol), ctypes.c_void_p).value
        except (OSError, AttributeError):
            return None

    @property
    def available(self) -> bool:
        return self.address is not None

    def __call__(self, *args):
        if len(args) != len(self.args):
            raise ArityError(f"'{self.symbol}' takes {len(self.args)} argument(s), got {len(args)}")
        if self.address is None:
            raise ReactorError(f"'{self.symbol}' is not available (library {self.library!r} missing "
                               f"or lacks the symbol)")
        em = _em.current()
        irs = []
        for want, a in zip(self.args, args):
            if isinstance(a, Value) and (a.kind != want.kind or a.width not in (1, want.width)):
                raise DSLTypeError(f"'{self.symbol}' needs a {want.name}, got a {shown(a.vtype)}")
            irs.append(to_ir(a, want))
        fn = em.module.declare(self.symbol, self.returns, self.args)
        em.module.imports[self.symbol] = self.address
        em.module.import_libraries[self.symbol] = self.library
        result = em.call(fn, irs, name=self.symbol.lower())
        scalar_call = all(not isinstance(a, Value) or a.width == 1 for a in args)
        if scalar_call and self.returns.width > 1:
            # Scalars were broadcast into the vector function; lane 0 is the answer
            # (this is how a kernel's strided path calls a vector-only function).
            result = em.extract(result, 0, name="lane0")
            return value_class(self.returns.with_width(1))._wrap(result, em)
        return value_class(self.returns)._wrap(result, em)

    def __repr__(self):
        return f"<External {self.symbol} from {self.library}>"
