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

from reactor import (Bool, Extract, Float, Float4, For, Int, Int16, Pointer, Select, Table, Texture2D,
                     function, kernel, vec4)

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


HOSTILE_INDICES = np.array([-2**31, -2**31 + 1, -1000000, -65, -64, -63, -17, -16, -15, -2, -1, 0, 1, 2, 14,
                            15, 16, 17, 62, 63, 64, 65, 1000000, 2**31 - 2, 2**31 - 1], np.int32)
HOSTILE_COORDS = np.float32([np.nan, np.inf, -np.inf, -1e30, 1e30, -3e9, 3e9, -1.5, -0.5, 0, 0.5, 0.999999,
                             1, 1.5, 17.25, -17.25, 2**24, -2**24])


def check_tables_and_textures(rng) -> int:
    """Per-lane reads of guarded tables and textures at hostile indices and coordinates, every
    wrap mode and filter, sizes 1..65: a read outside the array faults or shows as a wrong value."""
    checks = 0
    for mode in ("clamp", "repeat", "mirror", "border"):
        look = kernel(lambda i, t: t[i], args=[Int, Table[Float, mode]], returns=Float, name=f"gt_{mode}",
                      cache=False)
        samp = kernel(lambda u, v, t: t.sample(u, v), args=[Float, Float, Texture2D[vec4, mode, "linear"]],
                      returns=vec4, name=f"gs_{mode}", cache=False)
        for n in (1, 2, 3, 15, 16, 17, 64, 65):
            for at in ("end", "start"):
                g = Guarded(n, np.float32, at)
                g.array[:] = np.arange(n, dtype=np.float32) + 1
                got = look(HOSTILE_INDICES, g.array)
                assert np.all((got == 0) | ((got >= 1) & (got <= n))), (mode, n, at)  # a table value or border 0
                tex = Guarded(n * 3 * 4, np.float32, at)
                tex.array[:] = 0.5
                img = tex.array.reshape(n, 3, 4)
                u = np.repeat(HOSTILE_COORDS, len(HOSTILE_COORDS))
                v = np.tile(HOSTILE_COORDS, len(HOSTILE_COORDS))
                out = samp(u, v, img)
                assert np.all(np.isnan(out) | ((out >= 0) & (out <= 0.5000001))), (mode, n, at)
                assert g.canaries_intact() and tex.canaries_intact()
                g.free()
                tex.free()
                checks += 2
    return checks


@function
def gather_scatter(p: Pointer[Float, "n"], n: Int, i: Int16, out: Pointer[Float, "n"]) -> Float:
    """Per-lane indices into guarded pointers: lanes outside [0, n) read 0 and write nothing."""
    v = p[i]
    out[i] = v + 1.0
    return Extract(v, 0)


def check_pointer_lanes(rng) -> int:
    checks = 0
    for n in range(1, 40):
        for at in ("end", "start"):
            p, out = Guarded(n, np.float32, at), Guarded(n, np.float32, at)
            p.array[:] = np.arange(n, dtype=np.float32)
            out.array[:] = -7
            idx = rng.choice(HOSTILE_INDICES, 16).astype(np.int32)
            gather_scatter(p.array, n, idx, out.array)
            inside = (idx >= 0) & (idx < n)
            expect = np.full(n, -7, np.float32)
            expect[idx[inside]] = idx[inside] + 1
            assert np.array_equal(out.array, expect), (n, idx)
            assert p.canaries_intact() and out.canaries_intact()
            p.free()
            out.free()
            checks += 1
    return checks


def main() -> int:
    rng = np.random.default_rng(5)
    checks = check_tables_and_textures(rng) + check_pointer_lanes(rng)
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
