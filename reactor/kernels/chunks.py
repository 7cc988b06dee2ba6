"""Reactor kernels on dask arrays, chunk by chunk.

An elementwise kernel with one result needs nothing: ``kernel(dask_array)`` goes through dask's
``__array_ufunc__`` and gives a lazy dask array that computes, chunk by chunk, the same bits as
on a NumPy array (threads, processes or a ``distributed`` cluster: kernels pickle as their
recipe, ``reactor.kernels.pickling``). ``map_blocks`` covers what dask's own path cannot: kernels
with vector operands (NumPy gufuncs whose core dimensions have fixed sizes such as
``(3),()->(4)``, which dask's ``apply_gufunc`` cannot parse) and kernels with several results.
"""
from __future__ import annotations

import re

import numpy as np

from ..errors import ReactorError, require


def _core_dims(ufunc) -> tuple[list[tuple[int, ...]], list[tuple[int, ...]]]:
    """The fixed core shapes of each input and output (``()`` for an element)."""
    if ufunc.signature is None:
        return [()] * ufunc.nin, [()] * ufunc.nout
    ins, outs = ufunc.signature.split("->")

    def parse(part):
        return [tuple(int(d) for d in g.split(",") if d.strip()) for g in re.findall(r"\(([^()]*)\)", part)]
    return parse(ins), parse(outs)


def _check_dtypes(ufunc, args) -> None:
    """What NumPy would refuse in every chunk, refused now, in the kernel's terms: an operand whose
    dtype the kernel's loop does not take safely (a float64 dask array for a float32 kernel)."""
    from ..errors import ArgumentError
    wanted = [np.dtype(c) for c in ufunc.types[0].split("->")[0]]
    try:
        from .kernel import kernel_of
        names = list(kernel_of(ufunc).signature.names)
    except ReactorError:
        names = [f"#{j}" for j in range(len(args))]
    for j, (a, want) in enumerate(zip(args, wanted)):
        if isinstance(a, (bool, int, float)):  # a Python number adapts to the array beside it
            continue
        dt = getattr(a, "dtype", None)
        dt = np.asarray(a).dtype if dt is None else np.dtype(dt)
        if not np.can_cast(dt, want, "safe"):
            raise ArgumentError(f"map_blocks: argument '{names[j]}' of '{ufunc.__name__}' is {dt}, and the kernel "
                                f"computes in {want}: pass it as {want} (a.astype(np.{want}))")


def map_blocks(ufunc, *args):
    """``ufunc(*args)`` as lazy dask arrays, chunk by chunk: one dask array per result (a tuple
    for several). Operands broadcast as in NumPy; vector operands' trailing axes are kept whole in
    every chunk; NumPy arrays are chunked like the dask operands, scalars go to every chunk."""
    da = require("dask.array", "distributed", "reactor.map_blocks")
    if not isinstance(ufunc, np.ufunc) or ufunc.nin != len(args):
        raise ReactorError(f"map_blocks takes a kernel and its {getattr(ufunc, 'nin', '?')} operands")
    _check_dtypes(ufunc, args)
    ins, outs = _core_dims(ufunc)
    shapes = [np.shape(a)[:np.ndim(a) - len(core)] for a, core in zip(args, ins)]
    lead = np.broadcast_shapes(*shapes)
    if not any(isinstance(a, da.Array) for a in args):
        raise ReactorError("map_blocks needs at least one dask array operand")
    letters = iter("abcdefghijklmnopqrstuvwxyz")
    lead_idx = "".join(next(letters) for _ in lead)
    pairs: list = []
    for a, core in zip(args, ins):
        if np.ndim(a) == len(core) and not isinstance(a, da.Array):
            pairs += [a, None]  # one element or one vector: the same in every chunk
            continue
        a = da.broadcast_to(da.asarray(a), lead + tuple(core))
        pairs += [a, lead_idx + "".join(next(letters) for _ in core)]
    dtypes = [np.dtype(t) for t in ufunc.types[0].split("->")[1]]

    def block(*blocks, index):
        result = ufunc(*blocks)
        return result[index] if ufunc.nout > 1 else result

    results = []
    for i, core in enumerate(outs):
        new = {next(letters): n for n in core}
        results.append(da.blockwise(block, lead_idx + "".join(new), *pairs, new_axes=new, concatenate=True,
                                    dtype=dtypes[i], index=i,
                                    meta=np.empty((0,) * (len(lead) + len(core)), dtypes[i])))
    return tuple(results) if ufunc.nout > 1 else results[0]
