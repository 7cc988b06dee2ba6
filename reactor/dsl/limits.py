"""Loops that run out of iterations: a clear error after the call instead of a hang.

A loop given ``max_iterations=N`` leaves after N iterations and stores its
number (1-based) in its module's status counter (``reactor.status``). The
caller turns that into an error naming the loop's line: a compiled Function
after its call (``reactor.runtime``), a kernel's dispatcher on the caller's
thread once every chunk has run (it sets the error through the Python C API
and NumPy raises it when the ufunc returns). Both raise ``LoopLimitError``.
Concurrent calls of one compiled module share its counter: a runaway in
one may be reported by the other.
"""
from __future__ import annotations

from ..ir import types as T
from ..ir.types import KINDS, VType

STATUS = "reactor.status"
_I32 = VType(KINDS["Int"], 1)


def report_runaway(em, loop) -> None:
    """Emit: the loop ``loop`` ran out of iterations (at the cursor)."""
    module = em.module
    messages = module.runaway_messages
    where = getattr(loop, "_created", None)
    at = f" at {where[0]}:{where[1]}" if where else ""
    messages.append(f"{loop.what} loop{at} ran {loop._max} iterations (its max_iterations) and was stopped: "
                    f"some lane never left it")
    em.store(T.const(_I32, len(messages)), module.counter(STATUS))


def messages_of(module) -> list[str]:
    """The messages of the module's limited loops, by status number - 1."""
    return list(module.runaway_messages)
