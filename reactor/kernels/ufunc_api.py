"""NumPy's ufunc C API from Python, through ctypes and the ``_UFUNC_API`` capsule.

``make_ufunc`` wraps machine-code inner loops (``void loop(char **args,
npy_intp const *dims, npy_intp const *steps, void *data)``) in a real
``numpy.ufunc`` made by ``PyUFunc_FromFuncAndData``; no C compiler involved.
The object passed as ``owner`` is stored in the ufunc's ``obj`` slot (the slot
``numpy.frompyfunc`` uses for the same purpose), so everything the loops need
(their machine code, the type and pointer tables) lives exactly as long as the
ufunc itself.
"""
from __future__ import annotations

import ctypes
import functools

import numpy as np

# Indices in the API table (numpy/_core/code_generators/numpy_api.py; the same in NumPy 1.x and 2.x).
_FROM_FUNC_AND_DATA = 1
_FROM_FUNC_AND_DATA_AND_SIGNATURE = 31
_IDENTITY_NONE = -1  # PyUFunc_None: no identity, so no reductions are implied


@functools.cache
def _api_table():
    try:
        from numpy._core import _multiarray_umath as umath
    except ImportError:  # NumPy 1.x
        from numpy.core import _multiarray_umath as umath
    get_pointer = ctypes.pythonapi.PyCapsule_GetPointer
    get_pointer.restype = ctypes.c_void_p
    get_pointer.argtypes = [ctypes.py_object, ctypes.c_char_p]
    return ctypes.cast(get_pointer(umath._UFUNC_API, None), ctypes.POINTER(ctypes.c_void_p))


@functools.cache
def _from_func_and_data():
    proto = ctypes.PYFUNCTYPE(
        ctypes.py_object, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int,
        ctypes.c_int, ctypes.c_int, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_int)
    return proto(_api_table()[_FROM_FUNC_AND_DATA])


@functools.cache
def _from_func_and_data_and_signature():
    proto = ctypes.PYFUNCTYPE(
        ctypes.py_object, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int,
        ctypes.c_int, ctypes.c_int, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p)
    return proto(_api_table()[_FROM_FUNC_AND_DATA_AND_SIGNATURE])


@functools.cache
def _obj_offset() -> int:
    """Byte offset of ``PyUFuncObject.obj``, found (not assumed) by probing a
    ``frompyfunc`` ufunc, whose ``obj`` slot holds the wrapped callable."""
    def probe():
        pass

    u = np.frompyfunc(probe, 1, 1)
    base = id(u)
    for offset in range(16, 256, 8):
        if ctypes.c_void_p.from_address(base + offset).value == id(probe):
            return offset
    raise RuntimeError("cannot locate PyUFuncObject.obj in this NumPy build")


def make_ufunc(name: str, doc: str, loops: list[int], signatures: list[list[np.dtype]],
               nin: int, nout: int, owner: object, data: list[int] | None = None,
               signature: str | None = None) -> np.ufunc:
    """A ufunc with one machine-code inner loop per signature (dtypes of inputs then outputs);
    with a gufunc ``signature`` (``"(3),()->(4)"``) a generalized ufunc.

    ``data[i]`` is passed to loop i as its last argument. ``owner`` must hold
    the loops' machine code and whatever ``data`` points to; the ufunc keeps it alive.
    """
    if len(loops) != len(signatures) or not loops:
        raise ValueError("need one loop per signature")
    ntypes = len(loops)
    funcs = (ctypes.c_void_p * ntypes)(*loops)
    data_array = (ctypes.c_void_p * ntypes)(*(data or [0] * ntypes))
    types = ctypes.create_string_buffer(bytes(np.dtype(t).num for sig in signatures for t in sig),
                                        ntypes * (nin + nout))
    name_b, doc_b = ctypes.create_string_buffer(name.encode()), ctypes.create_string_buffer(doc.encode())
    common = (ctypes.addressof(funcs), ctypes.addressof(data_array), ctypes.cast(types, ctypes.c_char_p),
              ntypes, nin, nout, _IDENTITY_NONE, ctypes.cast(name_b, ctypes.c_char_p),
              ctypes.cast(doc_b, ctypes.c_char_p), 0)
    sig_b = None
    if signature is None:
        ufunc = _from_func_and_data()(*common)
    else:
        sig_b = ctypes.create_string_buffer(signature.encode())
        ufunc = _from_func_and_data_and_signature()(*common, ctypes.cast(sig_b, ctypes.c_char_p))
    keep = (owner, funcs, data_array, types, name_b, doc_b, sig_b)
    slot = ctypes.c_void_p.from_address(id(ufunc) + _obj_offset())
    if slot.value is not None:
        raise RuntimeError("new ufunc unexpectedly has an obj")
    ctypes.pythonapi.Py_IncRef(ctypes.py_object(keep))
    slot.value = id(keep)
    return ufunc

