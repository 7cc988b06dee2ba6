"""Run kernels and routines on arrays placed right against inaccessible (PROT_NONE)
pages, with canary bytes filling the rest of their pages: any read or write past
either end of an operand faults (killing this process) or changes a canary.

Run as a script (test_hostile.py runs it in a subprocess, so that a crash is a
test failure rather than the end of the test run). Prints ``ok <checks>``.
"""
from __future__ import annotations

import ctypes
import mmap
import sys

import numpy as np

from reactor import Bool, Float, Float4, For, Int, Pointer, Select, function, kernel

PAGE = mmap.PAGESIZE
CANARY = 0xA5
_libc = ctypes.CDLL(None, use_errno=True)
_libc.mmap.restype = ctypes.c_void_p
_libc.mmap.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int, ctypes.c_int, ctypes.c_int, ctypes.c_long]
_libc.mprotect.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int]
_libc.munmap.argtypes = [ctypes.c_void_p, ctypes.c_size_t]
PROT_NONE, PROT_RW = 0, 3
MAP_PRIVATE, MAP_ANONYMOUS = 0x02, 0x20


class Guarded:
    """``n`` elements of ``dtype`` against a guard page: at the end of their pages
    (``at="end"``) or at the start (``at="start"``); the other bytes are canaries."""

    def __init__(self, n: int, dtype, at: str = "end"):
        dtype = np.dtype(dtype)
        nbytes = n * dtype.itemsize
        self.pages = max(1, -(-nbytes // PAGE))
        self.size = (self.pages + 2) * PAGE
        base = _libc.mmap(None, self.size, PROT_RW, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0)
        if base in (None, ctypes.c_void_p(-1).value):
            raise OSError(ctypes.get_errno(), "mmap failed")
        self.base = base
        for guard in (base, base + (self.pages + 1) * PAGE):
            if _libc.mprotect(guard, PAGE, PROT_NONE) != 0:
                raise OSError(ctypes.get_errno(), "mprotect failed")
        self.data = base + PAGE
        self.span = self.pages * PAGE
        ctypes.memset(self.data, CANARY, self.span)
        addr = self.data + self.span - nbytes if at == "end" else self.data
        self.offset = addr - self.data
        self.nbytes = nbytes
        buf = (ctypes.c_char * max(nbytes, 1)).from_address(addr)
        self.array = np.frombuffer(buf, dtype=dtype, count=n)

    def canaries_intact(self) -> bool:
        raw = np.frombuffer((ctypes.c_char * self.span).from_address(self.data), np.uint8)
        outside = np.concatenate([raw[:self.offset], raw[self.offset + self.nbytes:]])
        return bool(np.all(outside == CANARY))

    def free(self):
        _libc.munmap(self.base, self.size)


def body(a: Float, b: Float) -> (Float, Bool):
    return a * b + 1.0, a < b


def check_kernel(uf, n: int, rng) -> int:
    """Every layout of one call of length n; returns the number of checks."""
    checks = 0
    a_val = rng.standard_normal(max(n, 1)).astype(np.float32)[:n]
    b_val = rng.standard_normal(max(n, 1)).astype(np.float32)[:n]
    want0, want1 = a_val * b_val + np.float32(1), a_val < b_val
    for at in ("end", "start"):
        ins = [Guarded(n, np.float32, at) for _ in range(2)]
        outs = [Guarded(n, np.float32, at), Guarded(n, np.bool_, at)]
        ins[0].array[:], ins[1].array[:] = a_val, b_val
        uf(ins[0].array, ins[1].array, out=(outs[0].array, outs[1].array))
        assert np.array_equal(outs[0].array, want0) and np.array_equal(outs[1].array, want1), (n, at)
        # reversed views: negative strides walk toward the other end
        uf(ins[0].array[::-1], ins[1].array[::-1], out=(outs[0].array[::-1], outs[1].array[::-1]))
        assert np.array_equal(outs[0].array, want0) and np.array_equal(outs[1].array, want1), (n, at)
        # one input broadcast from a single guarded element
        one = Guarded(1, np.float32, at)
        one.array[0] = 2.0
        uf(one.array[0:1].reshape(()), ins[1].array, out=(outs[0].array, outs[1].array))
        assert np.array_equal(outs[0].array, np.float32(2) * b_val + np.float32(1)), (n, at)
        assert all(g.canaries_intact() for g in ins + outs + [one]), (n, at)
        for g in ins + outs + [one]:
            g.free()
        checks += 3
    # strided: every other element of a guarded buffer of 2n - 1 elements
    if n:
        a2, o2 = Guarded(2 * n - 1, np.float32), Guarded(2 * n - 1, np.float32)
        a2.array[::2] = a_val
        o2.array[:] = 7
        uf(a2.array[::2], b_val, out=(o2.array[::2], None))
        assert np.array_equal(o2.array[::2], want0) and np.all(o2.array[1::2] == 7), n
        assert a2.canaries_intact() and o2.canaries_intact()
        a2.free()
        o2.free()
        checks += 1
    return checks


@function
def scale4(p: Pointer[Float4, "n"], n: Int):
    with For(0, n) as i:
        p[i] = p[i] * 2.0


@function
def fill_tail(p: Pointer[Float, "n"], n: Int):
    """A vector loop over whole Float4s, then the scalar tail: within n elements."""
    m = Int(0) + (n >> 2)
    with For(0, m) as i:
        p.store(i * 4, p.load(i * 4, 4) + 1.0)
    with For(m * 4, n) as j:
        p[j] = Select(p[j] > -1e30, p[j] + 1.0, p[j])


def main() -> int:
    rng = np.random.default_rng(5)
    checks = 0
    for target in ("host", "avx2", "sse4"):
        for width in (1, 4, 8, 16):
            uf = kernel(body, name=f"guard_{target}_{width}", width=width, target=target, fma=False, cache=False)
            for n in range(0, 71):
                checks += check_kernel(uf, n, rng)
    for n in range(0, 40):
        g = Guarded(4 * n, np.float32)
        g.array[:] = np.arange(4 * n, dtype=np.float32)
        scale4(g.array, n)
        assert np.array_equal(g.array, 2 * np.arange(4 * n, dtype=np.float32)) and g.canaries_intact()
        g.free()
        h = Guarded(n, np.float32)
        h.array[:] = np.arange(n, dtype=np.float32)
        fill_tail(h.array, n)
        assert np.array_equal(h.array, np.arange(n, dtype=np.float32) + 1) and h.canaries_intact()
        h.free()
        checks += 2
    print(f"ok {checks}")
    return 0


def selftest() -> int:
    """Write one element past a guarded array: must die with SIGSEGV (proves the guard works)."""
    g = Guarded(3, np.float32)
    ctypes.c_float.from_address(g.array.ctypes.data + 3 * 4).value = 1.0
    print("not reached")
    return 0


if __name__ == "__main__":
    sys.exit(selftest() if sys.argv[1:] == ["--selftest"] else main())
