"""The C entry ABI of compiled functions, and the Python side of it.

Every function of a compiled module gets ``void <name>.entry(i8** argv, i8* ret)``:
``argv[k]`` is the address of argument k's value (scalars, vectors) or the
pointer argument itself; the result is stored at ``ret``. Values travel in
their memory form (a Bool is one byte; any nonzero byte is True, as in NumPy).
``arguments`` turns Python numbers and NumPy arrays into what ``argv`` points to,
checking kinds, ranges, sizes and writability.
"""
from __future__ import annotations

import numpy as np

from ..errors import ArgumentError
from ..ir import emitter as _em
from ..ir import ops
from ..ir import types as T
from ..ir.types import PointerType, VType

SUFFIX = ".entry"


def emit_entry(mod: _em.ModuleEmitter, name: str, irfn, params, returns) -> None:
    """Emit ``name.entry`` calling ``irfn`` (the function's parameters ``params``)."""
    em = _em.FunctionEmitter(mod, name + SUFFIX, None, [T.BYTES_ARRAY, T.BYTES], ["argv", "ret"])
    with em:
        argv, retp = em.params
        args = []
        for k, p in enumerate(params):
            pname = irfn.args[k].name  # the parameter's name in the DSL function
            slot = em.load(em.address(argv, k, name=f"{pname}.argv"), name=f"{pname}.arg")
            if isinstance(p, PointerType):
                args.append(em.cast_pointer(slot, T.memory(p.pointee), name=pname))
            else:
                args.append(ops.load(em, p, slot, name=pname))
        result = em.call(irfn, args, name="result" if returns is not None else "")
        if returns is not None:
            ops.store(em, returns, result, retp, name="ret")
        em.ret(None)
        em.finish()


def arguments(routine: str, names, params, args, written) -> list[np.ndarray]:
    """The NumPy arrays whose data ``argv`` points to, one per argument (keep them alive)."""
    scalars = {name: a for name, p, a in zip(names, params, args) if isinstance(p, VType) and p.width == 1}
    return [_argument(routine, name, p, a, scalars, k in written)
            for k, (name, p, a) in enumerate(zip(names, params, args))]


def _argument(routine: str, name: str, p, a, scalars, written: bool = False) -> np.ndarray:
    """The array for parameter type ``p``: the argument's own array for pointers,
    a copy for scalars and vectors."""
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
