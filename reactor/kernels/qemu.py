"""Run kernels built for AArch64 on this x86 machine: linked with a C driver, run under qemu-user.

A kernel built with ``target="aarch64"`` is real AArch64 object code, but its ufunc
refuses to run in an x86 process. ``Emulator([ufunc, ...])`` links the object code
of each kernel (its loop over elements, ``<name>.loop``, which the driver calls as the
dispatcher would, on one thread) with reactor's runtime
built for the same target (``reactor_prepare``) and a small C driver, using the
cross toolchain (``aarch64-linux-gnu-gcc``); calling it runs the executable under
``qemu-aarch64`` and returns the outputs as NumPy arrays. It runs the very object
code the build emitted, through the same loop (vector loop, scalar tail, strided
path) NumPy would drive on an ARM machine, with one thread.

The driver reads one file of calls (which kernel, how many elements, each operand's
step and bytes) and writes every output back. Inputs are 1-D arrays of the kernel's
dtypes, all of one length, or 0-d arrays (broadcast: step 0); ``strided=True`` lays
each array operand out with twice its item size between elements, which drives the
scalar loop.

``missing()`` says which tool is absent (None when all are there): Debian's
``qemu-user``, ``gcc-aarch64-linux-gnu`` and ``libc6-dev-arm64-cross``.
"""
from __future__ import annotations

import os
import shutil
import struct
import subprocess
import tempfile
import typing

import numpy as np

from ..errors import ReactorError
from . import abi, parallel

TARGET = "aarch64"
TRIPLE_PREFIX = "aarch64-linux-gnu"
SYSROOT = "/usr/aarch64-linux-gnu"
TOOLS = ("qemu-aarch64", f"{TRIPLE_PREFIX}-gcc", f"{TRIPLE_PREFIX}-objcopy")

_DRIVER = r"""
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

typedef void (*loop_fn)(char **, int64_t *, int64_t *, void *);
%(structs)s
extern char reactor_prepare[], reactor_move[];
%(externs)s
static loop_fn kernels[] = {%(table)s};
static int runaway;
static int gil_ensure(void) { return 0; }
static void gil_release(int state) { (void)state; }
static void err_set(void *exc, const char *message) { (void)exc; fprintf(stderr, "%%s\n", message); runaway = 1; }
static const char *no_messages[] = {"a loop of the kernel ran out of iterations"};

static int64_t get(FILE *f) {
    int64_t v;
    if (fread(&v, sizeof v, 1, f) != 1) { fprintf(stderr, "driver: truncated input\n"); exit(2); }
    return v;
}

int main(int argc, char **argv) {
    if (argc != 3) { fprintf(stderr, "usage: %%s calls.bin results.bin\n", argv[0]); return 2; }
    FILE *in = fopen(argv[1], "rb"), *out = fopen(argv[2], "wb");
    if (!in || !out) { perror("driver"); return 2; }
    struct settings settings = {.threads = 1, .threshold = INT64_MAX, .min_work = INT64_MAX,
                                .prepare = reactor_prepare, .gil_ensure = (void *)gil_ensure,
                                .err_set = (void *)err_set, .gil_release = (void *)gil_release,
                                .move = reactor_move};
    int64_t calls = get(in);
    for (int64_t c = 0; c < calls; c++) {
        int64_t which = get(in), nargs = get(in), nin = get(in), n = get(in);
        char *args[64]; int64_t steps[64], bytes[64], dims[1] = {n};
        for (int64_t k = 0; k < nargs; k++) {
            steps[k] = get(in); bytes[k] = get(in);
            args[k] = aligned_alloc(64, (size_t)((bytes[k] + 127) / 64 * 64));
            if (k < nin && fread(args[k], 1, (size_t)bytes[k], in) != (size_t)bytes[k]) {
                fprintf(stderr, "driver: truncated operand\n"); return 2;
            }
        }
        struct config config = {.settings = &settings, .nargs = nargs, .cycles_per_element = 256,
                                .messages = no_messages, .ndims = 1};
        kernels[which](args, dims, steps, &config);
        for (int64_t k = nin; k < nargs; k++) fwrite(args[k], 1, (size_t)bytes[k], out);
        for (int64_t k = 0; k < nargs; k++) free(args[k]);
    }
    fclose(out);
    return runaway ? 3 : 0;
}
"""


def missing() -> str | None:
    """The first cross tool this machine lacks (None: kernels can be run under emulation)."""
    for tool in TOOLS:
        if shutil.which(tool) is None:
            return tool
    if not os.path.isdir(SYSROOT):
        return f"the AArch64 C library ({SYSROOT})"
    return None


def _kernel(ufunc):
    from .kernel import kernel_of

    kern = kernel_of(ufunc)
    if kern.build.target.arch != TARGET:
        raise ReactorError(f"kernel {kern.name!r} was built for {kern.build.target.arch}, not {TARGET}: "
                           f"build it with target='{TARGET}' to run it under emulation")
    if kern.gufunc_signature or any(o.uniform or o.channels != 1 for o in kern.ins + kern.outs):
        raise ReactorError(f"kernel {kern.name!r}: only elementwise kernels of scalar operands run under "
                           f"emulation")
    return kern


def _run(command: list[str], what: str, timeout: float) -> None:
    done = subprocess.run(command, capture_output=True, text=True, timeout=timeout)
    if done.returncode:
        raise ReactorError(f"{what} failed (exit {done.returncode}): {(done.stderr or done.stdout).strip()[:2000]}")


class Emulator:
    """An AArch64 executable holding the kernels of ``ufuncs`` (each built with
    ``target="aarch64"``); ``emulator(calls)`` runs a batch of calls under qemu-user."""

    def __init__(self, ufuncs: typing.Sequence[np.ufunc]):
        lacking = missing()
        if lacking is not None:
            raise ReactorError(f"running AArch64 code needs {lacking} (Debian: qemu-user, gcc-aarch64-linux-gnu, "
                               f"libc6-dev-arm64-cross)")
        self.kernels = [_kernel(u) for u in ufuncs]
        self._dir = tempfile.mkdtemp(prefix="reactor-aarch64-")
        self.executable = os.path.join(self._dir, "kernels")
        objects = [self._write("runtime.o", parallel.runtime(TARGET).object)]
        for i, kern in enumerate(self.kernels):
            # each kernel's own symbols made local, its entry renamed: kernels of one name may be linked together
            path = self._write(f"k{i}.o", kern.code.object)
            _run([f"{TRIPLE_PREFIX}-objcopy", f"--redefine-sym={kern.name}.loop=reactor_kernel{i}",
                  f"--keep-global-symbol=reactor_kernel{i}", path], "objcopy", 60)
            objects.append(path)
        count = len(self.kernels)
        driver = _DRIVER % {
            "structs": "\n".join(s.c for s in (abi.SETTINGS, abi.LOOP_CONFIG)),
            "externs": "\n".join(f"extern void reactor_kernel{i}(char **, int64_t *, int64_t *, void *);"
                                 for i in range(count)),
            "table": ", ".join(f"reactor_kernel{i}" for i in range(count))}
        source = self._write("driver.c", driver.encode())
        _run([f"{TRIPLE_PREFIX}-gcc", "-O1", "-o", self.executable, source] + objects + ["-lpthread", "-lm"],
             "linking the AArch64 driver", 120)

    def _write(self, name: str, data: bytes) -> str:
        path = os.path.join(self._dir, name)
        with open(path, "wb") as f:
            f.write(data)
        return path

    def __call__(self, calls: typing.Sequence[tuple[int, typing.Sequence[np.ndarray]]], *, strided: bool = False,
                 timeout: float = 600) -> list[tuple[np.ndarray, ...]]:
        """Run ``calls`` (kernel index, inputs) in order; each gives its outputs as a tuple."""
        request, shapes = [struct.pack("<q", len(calls))], []
        for which, inputs in calls:
            kern = self.kernels[which]
            if len(inputs) != len(kern.ins):
                raise ReactorError(f"kernel {kern.name!r} takes {len(kern.ins)} inputs, not {len(inputs)}")
            arrays = [np.asarray(x, dtype=o.dtype) for x, o in zip(inputs, kern.ins)]
            lengths = {a.shape[0] for a in arrays if a.ndim == 1}
            if any(a.ndim > 1 for a in arrays) or len(lengths) > 1:
                raise ReactorError("inputs must be 1-D arrays of one length, or 0-d (broadcast)")
            n = lengths.pop() if lengths else 1
            head = [which, len(kern.ins) + len(kern.outs), len(kern.ins), n]
            body = []
            for a in arrays:
                size = a.dtype.itemsize
                if a.ndim == 0:
                    head += [0, size]
                    body.append(a.tobytes())
                    continue
                step = 2 * size if strided else size
                laid = np.zeros(n * step // size, a.dtype)
                laid[::step // size] = a
                head += [step, laid.nbytes]
                body.append(laid.tobytes())
            outs = []
            for o in kern.outs:
                size = o.dtype.itemsize
                step = 2 * size if strided else size
                head += [step, n * step]
                outs.append((o.dtype, n, step // size))
            # header fields interleave with each input's bytes, as the driver reads them
            request.append(struct.pack("<4q", *head[:4]))
            fields = head[4:]
            for k in range(len(kern.ins) + len(kern.outs)):
                request.append(struct.pack("<2q", *fields[2 * k:2 * k + 2]))
                if k < len(kern.ins):
                    request.append(body[k])
            shapes.append(outs)
        calls_path = self._write("calls.bin", b"".join(request))
        results_path = os.path.join(self._dir, "results.bin")
        _run(["qemu-aarch64", "-L", SYSROOT, self.executable, calls_path, results_path],
             "running the AArch64 kernels under qemu", timeout)
        data = np.fromfile(results_path, np.uint8)
        results, at = [], 0
        for outs in shapes:
            got = []
            for dtype, n, every in outs:
                nbytes = n * every * np.dtype(dtype).itemsize
                got.append(data[at:at + nbytes].view(dtype)[::every].copy())
                at += nbytes
            results.append(tuple(got))
        return results

    def close(self) -> None:
        shutil.rmtree(self._dir, ignore_errors=True)

    def __enter__(self) -> "Emulator":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self):
        self.close()


def run(ufunc: np.ufunc, *inputs: np.ndarray, strided: bool = False) -> np.ndarray | tuple[np.ndarray, ...]:
    """``ufunc(*inputs)`` for a kernel built with ``target="aarch64"``, run under qemu-user."""
    with Emulator([ufunc]) as emulator:
        outs = emulator([(0, inputs)], strided=strided)[0]
    return outs[0] if len(outs) == 1 else outs
