"""Kernels that travel: a reactor ufunc pickles as the recipe to build it, never as machine code.

A reactor ufunc pickles (``pickle``, ``cloudpickle``, ``copy.deepcopy``) as how it was made,
and is built again on the receiving side, through that side's caches and for that side's CPU
(a kernel pickled on an AVX-512 host runs at 8 lanes on an AVX2 worker):

* one made by a library (``routines.jit``) as the call that makes it (``travels_as``);
* a ``@kernel`` by a reference to where it lives and, where that cannot be imported on the
  other side, by its body (``reactor.travel``), with the options it was built with.

A kernel that cannot travel (a body in ``__main__`` reading a value that is neither plain nor
importable, without cloudpickle) raises ``pickle.PicklingError`` saying why.
"""
from __future__ import annotations

import copyreg

import numpy as np

from ..travel import arrive, reduce_body
from ..errors import ReactorError

_numpy_reduce = copyreg.dispatch_table.get(np.ufunc)


def travels_as(ufunc: np.ufunc, rebuild, *args) -> np.ufunc:
    """Pickle the reactor ufunc ``ufunc`` as the call ``rebuild(*args)`` (an importable function,
    e.g. ``routines.jit``, and picklable arguments); returns ``ufunc``."""
    from .kernel import group_of
    group = group_of(ufunc)
    if group is None:
        raise ReactorError(f"{ufunc!r} is not a reactor kernel")
    group.travel = ("call", rebuild, args)
    return ufunc


def reduce_kernel(group, ufunc):
    """The pickle reduction of a reactor ufunc (``group``: its Kernels)."""
    spec = group.travel
    if spec[0] == "call":
        return spec[1], spec[2]
    _, body, kwargs = spec
    where, payload = reduce_body(ufunc, body, f"kernel '{ufunc.__name__}'")
    return rebuild_kernel, (where, payload, kwargs)


def rebuild_kernel(where, payload, kwargs):
    """The kernel pickled by ``reduce_kernel``, found or built on this side."""
    from .kernel import build_kernel, group_of
    return arrive(where, payload, lambda u: isinstance(u, np.ufunc) and group_of(u) is not None,
                  lambda body: build_kernel(body, **kwargs), "kernel")


def _reduce_ufunc(ufunc):
    from .kernel import group_of
    group = group_of(ufunc)
    if group is None:
        return _numpy_reduce(ufunc) if _numpy_reduce is not None else ufunc.__name__
    return reduce_kernel(group, ufunc)


copyreg.pickle(np.ufunc, _reduce_ufunc)
