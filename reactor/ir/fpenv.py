"""The floating-point environment of a kernel call, per architecture.

A kernel saves the status on entry and restores it on exit, so the exception
flags its code raises (the routines' special-value paths compute on values
whose flags mean nothing) never reach NumPy's ``errstate``: MXCSR on x86
(flags and controls), FPSR on AArch64 (the flags; FPCR, the controls, is never
changed by reactor code, so it needs no restoring).
"""
from __future__ import annotations

from llvmlite import ir

_I8P = ir.IntType(8).as_pointer()


def save_status(em):
    """Save the status in a stack slot (or an SSA value); None on an architecture without one here."""
    arch = em.module.build.target.arch
    if arch == "x86_64":
        slot = em.alloca(ir.IntType(32), "mxcsr")
        em.call(em.intrinsic("llvm.x86.sse.stmxcsr", None, [_I8P]), [em.bitcast(slot, _I8P, name="mxcsr.p")])
        return slot
    if arch == "aarch64":
        return em.call(em.intrinsic("llvm.aarch64.get.fpsr", ir.IntType(64), []), [], name="fpsr")
    return None


def restore_status(em, saved) -> None:
    """Restore what ``save_status`` saved (the flags raised in between are dropped)."""
    if saved is None:
        return
    if em.module.build.target.arch == "x86_64":
        em.call(em.intrinsic("llvm.x86.sse.ldmxcsr", None, [_I8P]), [em.bitcast(saved, _I8P, name="mxcsr.p")])
    else:
        em.call(em.intrinsic("llvm.aarch64.set.fpsr", None, [ir.IntType(64)]), [saved])
