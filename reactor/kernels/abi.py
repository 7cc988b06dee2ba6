"""The native runtime's C ABI, written once.

The kernels' ufunc loops and the runtime (``reactor.kernels.parallel``) share a few structures
and function signatures with Python (ctypes) and with the qemu driver's C code
(``reactor.kernels.qemu``). Each is declared here once, its fields by name; the IR type
(:attr:`Struct.ir`), the ctypes class (:attr:`Struct.ctype`) and the C declaration
(:attr:`Struct.c`) are derived from that declaration, and emitted code reaches a field by its
name (:meth:`Struct.load`), so that a reordered field changes every side at once.

A field's kind is one of :data:`KINDS` (``"i64"``, ``"ptr"`` ...) or another :class:`Struct`
(a pointer to it).
"""
from __future__ import annotations

import ctypes
import functools

from ..ir import types as T
from ..ir.types import INDEX

#: kind -> (IR type, ctypes type, C declaration of a field named {})
KINDS = {
    "i64": (INDEX, ctypes.c_int64, "int64_t {}"),
    "ptr": (T.BYTES, ctypes.c_void_p, "void *{}"),
    "str": (T.BYTES, ctypes.c_char_p, "const char *{}"),
    "str[]": (T.BYTES_ARRAY, ctypes.POINTER(ctypes.c_char_p), "const char **{}"),
    "ptr[]": (T.BYTES_ARRAY, ctypes.POINTER(ctypes.c_void_p), "char **{}"),
    "i64*": (T.PointerType(INDEX), ctypes.POINTER(ctypes.c_int64), "int64_t *{}"),
}
#: LoopConfig.cycles_per_element is fixed point: 1/256 cycle
CYCLES_SCALE = 256


class Struct:
    """A C structure of the runtime: ``fields`` are (name, kind) in memory order."""

    def __init__(self, name: str, fields: list, doc: str = "") -> None:
        self.name, self.fields, self.doc = name, tuple(fields), doc
        self.names = tuple(f for f, _ in self.fields)

    def index(self, field: str) -> int:
        return self.names.index(field)

    @functools.cached_property
    def ir(self) -> T.StructType:
        return T.StructType(tuple(T.Address(k.ir) if isinstance(k, Struct) else KINDS[k][0] for _, k in self.fields))

    @functools.cached_property
    def ctype(self) -> type:
        fields = [(f, ctypes.POINTER(k.ctype) if isinstance(k, Struct) else KINDS[k][1]) for f, k in self.fields]
        return type(self.name.title().replace("_", ""), (ctypes.Structure,), {"_fields_": fields, "__doc__": self.doc})

    @property
    def c(self) -> str:
        """The C declaration (``struct name { ... };``)."""
        decls = [f"struct {k.name} *{f}" if isinstance(k, Struct) else KINDS[k][2].format(f) for f, k in self.fields]
        return f"struct {self.name} {{ " + "; ".join(decls) + "; };"

    def field(self, em, ptr, field: str):
        """The address of ``ptr->field`` (``ptr`` a pointer to this structure)."""
        return em.field(ptr, self.index(field), name=f"{self.name}.{field}")

    def load(self, em, ptr, *fields: str):
        """``ptr->field`` for each field named (one value, or a list for several)."""
        values = [em.load(self.field(em, ptr, f), name=f) for f in fields]
        return values[0] if len(values) == 1 else values

    def store(self, em, ptr, **values) -> None:
        for f, v in values.items():
            em.store(v, self.field(em, ptr, f))

    def of(self, em, address, name: str | None = None):
        """``address`` (an untyped pointer) as a pointer to this structure."""
        return em.cast_pointer(address, self.ir, name=name or self.name)


class Signature:
    """A C function of the runtime or a kernel: ``params`` are (name, kind); ``ret`` a kind or None."""

    def __init__(self, name: str, ret: str | None, params: list) -> None:
        self.name, self.ret_kind, self.parameters = name, ret, tuple(params)

    @property
    def names(self) -> list[str]:
        return [n for n, _ in self.parameters]

    @property
    def params(self) -> list:
        """The parameters' IR types."""
        return [KINDS[k][0] for _, k in self.parameters]

    @property
    def ret(self):
        return None if self.ret_kind is None else KINDS[self.ret_kind][0]


POOL = Struct("pool", [
    # the workers' side: a new job's generation (a futex word: its low 32 bits, both targets being
    # little-endian), and how many workers sleep on it (the caller wakes them only then)
    ("gen", "i64"), ("sleepers", "i64"),
    # the current job: participations still open (``seats``), taken or open and not finished
    # (``remaining``: the caller sleeps on its low 32 bits when ``waiting``), and its TASK
    ("seats", "i64"), ("remaining", "i64"), ("waiting", "i64"), ("task", "ptr"),
    # ownership: 1 while a split call uses the pool; workers started, by this process (pid); 1 once
    # stopped (at exit); the workers' pthread ids; how long an idle thread spins before sleeping
    ("busy", "i64"), ("workers", "i64"), ("pid", "i64"), ("quit", "i64"), ("tids", "i64*"),
    ("spin_ns", "i64"),
], "The persistent worker threads of the thread split (one per process; ``reactor.kernels.parallel``).")

SETTINGS = Struct("settings", [
    ("threads", "i64"), ("threshold", "i64"), ("min_work", "i64"),
    ("parallel_for", "ptr"), ("prepare", "ptr"),
    # how a kernel's loop raises a Python error (a loop out of iterations)
    ("gil_ensure", "ptr"), ("err_set", "ptr"), ("gil_release", "ptr"), ("runtime_error", "ptr"),
    ("move", "ptr"),  # reactor_move: a kernel's elements in and out of its vector body
    ("pool", POOL),  # the worker threads reactor_parallel_for wakes (NULL: every call runs serially)
], "What every dispatcher reads at each call (one per process).")

CODE = Struct("code", [
    ("loop", "ptr"),  # the kernel's loop over elements (``<name>.loop``)
    ("status", "ptr"),  # its module's int32 status (a loop out of iterations: message number), or NULL
], "A kernel's machine code, as one pointer: a tiered kernel's optimized code replaces it whole.")

LOOP_CONFIG = Struct("config", [
    ("settings", SETTINGS), ("nargs", "i64"), ("cycles_per_element", "i64"), ("messages", "str[]"),
    ("ndims", "i64"),  # entries of NumPy's dims: 1 + a gufunc's core dimensions
    ("code", CODE),
], "What the dispatcher (``reactor_dispatch``) reads through NumPy's per-loop ``data`` pointer.")

ERROR_LOOP = Struct("error_loop", [("settings", SETTINGS), ("message", "str"), ("exception", "ptr")],
                    "The ``data`` of a loop that only raises (``reactor_raise``).")

TASK = Struct("task", [
    ("loop", "ptr"), ("args", "ptr[]"), ("steps", "i64*"), ("data", "ptr"), ("nargs", "i64"), ("n", "i64"),
    ("chunk", "i64"), ("next", "i64"), ("dims", "i64*"), ("ndims", "i64"), ("parts", "i64"),
    ("fpcr", "i64"),  # the caller's floating-point controls (MXCSR, FPCR), which the workers take on
], "One split call, shared by its threads (``parts`` of them): they take chunks by their index, ``next``.")

#: void loop(char **args, int64_t *dims, int64_t *steps, void *data): NumPy's inner loop
LOOP = Signature("loop", None, [("args", "ptr[]"), ("dims", "i64*"), ("steps", "i64*"), ("data", "ptr")])
#: void reactor_dispatch(args, dims, steps, data): every kernel's ufunc loop (its code from ``data``)
DISPATCH = Signature("reactor_dispatch", None, list(LOOP.parameters))
#: void reactor_parallel_for(loop, args, dims, steps, data, nargs, threads, ndims)
PARALLEL_FOR = Signature("reactor_parallel_for", None,
                         [("loop", "ptr")] + list(LOOP.parameters) + [("nargs", "i64"), ("threads", "i64"),
                                                                  ("ndims", "i64")])
#: void reactor_pool_stop(pool): the workers told to leave and joined (at exit); later calls run serially
POOL_STOP = Signature("reactor_pool_stop", None, [("pool", "ptr")])
#: i64 reactor_prepare(args, dims, steps, nin, nargs, sizes, width, srcs, incs, splats, lane_bytes)
PREPARE = Signature("reactor_prepare", "i64", [
    ("args", "ptr[]"), ("dims", "i64*"), ("steps", "i64*"), ("nin", "i64"), ("nargs", "i64"), ("sizes", "i64*"),
    ("width", "i64"), ("srcs", "ptr[]"), ("incs", "i64*"), ("splats", "ptr"), ("lane_bytes", "i64")])
#: i64 reactor_move(scatter, ptrs, steps, cstrides, channels, kbytes, ncols, nin, i, n, k, width, buf, slot_bytes)
MOVE = Signature("reactor_move", "i64", [
    ("scatter", "i64"), ("ptrs", "ptr[]"), ("steps", "i64*"), ("cstrides", "i64*"), ("channels", "i64*"),
    ("kbytes", "i64*"), ("ncols", "i64"), ("nin", "i64"), ("i", "i64"), ("n", "i64"), ("k", "i64"),
    ("width", "i64"), ("buf", "ptr"), ("slot_bytes", "i64")])
#: void reactor_raise(args, dims, steps, data): a loop that sets Python's error from its ErrorLoop
RAISE = Signature("reactor_raise", None, list(LOOP.parameters))


def raise_python_error(em, settings, exc, message) -> None:
    """Emit: take the GIL, ``PyErr_SetString(exc, message)``, release it (through the addresses
    in ``settings``: compiled code links no Python symbol)."""
    i32 = T.VType(T.KINDS["Int"], 1)
    ensure, set_error, release = SETTINGS.load(em, settings, "gil_ensure", "err_set", "gil_release")
    state = em.call_pointer(ensure, i32, [], [], name="gil")
    em.call_pointer(set_error, None, [T.BYTES, T.BYTES], [exc, message])
    em.call_pointer(release, None, [i32], [state])
