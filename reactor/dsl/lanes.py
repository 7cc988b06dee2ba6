"""Per-lane control flow: the execution mask (ISPC's model).

A block entered with a per-lane condition (``with If(mask):``, a While whose
condition is a mask, a loop left by some lanes with ``Break``) runs for the
lanes whose bit is set: every lane computes, but assignments to Variables
change only the *active* lanes (``Variable.set`` stores ``Select(active, new,
old)``), and a block no lane enters is skipped by a branch. The active mask is
always derived from the state kept here, per function being built:

* the conditions of the enclosing per-lane If/Elif/Else blocks (``Frame.conds``);
* for the innermost loop that tracks lanes: the lanes still in it (``alive``:
  those whose condition held every iteration and that did not ``Break``) and
  those that skip the rest of this iteration (``skip``: ``Continue``);
* the lanes that already executed ``Return`` (``returned``), and those that
  returned from an ``@inline`` helper being traced (``calls``: until it ends).

A loop tracks lanes when its condition or bounds are per lane, or when its
body calls Break, Continue or Return in a function of more than one lane (the
body's source is read to know). Uniform (scalar) Variables cannot be assigned
under a per-lane condition: which lane's value would they take?
"""
from __future__ import annotations

import dataclasses
import typing

from ..errors import ControlFlowError
from ..ir import emitter as _em
from ..ir.types import KINDS, VType
from .context import body_of, is_kernel_body
from .values import Value, value_class

BOOL = KINDS["Bool"]


@dataclasses.dataclass
class LoopLanes:
    """The lane masks of a loop that tracks lanes (Variables of Bool at the body's width)."""

    alive: typing.Any  # Variable of Bool
    skip: typing.Any


@dataclasses.dataclass
class CallFrame:
    """A call of an ``@inline`` helper: where its Returns go. ``depth`` is the number of loop
    frames outside it (its Returns leave only the loops opened inside it)."""

    depth: int
    exit_block: object
    returned: typing.Any = None  # Variable of Bool: lanes that returned from the helper
    results: typing.Any = None  # Variables: one per component of its result
    any_return: bool = False  # a Return was traced (per lane or on a uniform path)
    code: typing.Any = None  # the helper's code object (@syntax's returns find their function by it)


@dataclasses.dataclass
class Frame:
    """A loop level: the per-lane conditions entered since the loop began, and the loop."""

    conds: list = dataclasses.field(default_factory=list)
    loop: LoopLanes | None = None
    exit_block: object = None  # where Break goes in a loop that does not track lanes
    next_block: object = None  # where Continue goes


class Lanes:
    """The execution-mask state of one function being built."""

    def __init__(self, em):
        self.em = em
        self.width = em.width if is_kernel_body(em) else None
        self.frames = [Frame()]
        self.returned: typing.Any = None  # Variable: lanes done (Return), once a per-lane Return was traced
        self.results = None  # Variables: their results
        self.calls: list[CallFrame] = []  # the @inline helpers being traced, innermost last
        self.pushed: list[tuple] = []  # flow.push_mask's: (frame, depth of its conds) each, innermost last

    @property
    def frame(self) -> Frame:
        return self.frames[-1]

    def loop_frame(self) -> Frame | None:
        """The innermost loop's frame (None outside loops)."""
        for f in reversed(self.frames):
            if f.exit_block is not None or f.loop is not None:
                return f
        return None

    def active(self) -> Value | None:
        """The mask of the lanes the code being emitted runs for, or None where every lane does."""
        mask = None

        def both(a, b):
            return b if a is None else a & b
        f = self.frame
        if f.loop is not None:
            mask = both(mask, f.loop.alive.value & ~f.loop.skip.value)
        for c in f.conds:
            mask = both(mask, c)
        if self.returned is not None:
            mask = both(mask, ~self.returned.value)
        inner = len(self.frames) - 1  # the current loop level
        for call in self.calls:
            if call.returned is not None and not (f.loop is not None and inner >= call.depth):
                mask = both(mask, ~call.returned.value)  # (a loop opened in the call: its alive has it)
        return mask

    def returns_only(self, depth: int) -> bool:
        """Whether the lanes left out here are only lanes that returned from the function traced at
        inline ``depth`` (0: the body, k: ``calls[k - 1]``) or from a function around it: none of
        them reads that function's locals again, so a store to one may ignore them."""
        f = self.frame
        return len(self.frames) == 1 and f.loop is None and not f.conds and len(self.calls) == depth

    def mask_type(self) -> VType:
        return VType(BOOL, self.width or 1)

    def adopt(self, width: int, what: str) -> None:
        """The lane count of a function's per-lane control flow: its first mask's (a kernel's: its
        body's); every other mask must match."""
        if self.width is None:
            self.width = width
        elif width not in (1, self.width):
            raise ControlFlowError(f"{what}: a mask of {width} lanes where the per-lane control flow has "
                                   f"{self.width}")

    def all_lanes(self) -> Value:
        return value_class(self.mask_type())(True)

    def entry_variable(self, vtype: VType, init, name: str):
        """A Variable whose initial value is stored at the function's entry (it dominates every use)."""
        from .variables import entry_variable
        return entry_variable(vtype, init, name)


def lanes_of(em=None) -> Lanes:
    """The lane state of the function being built (made on first use)."""
    em = em or _em.current()
    body = body_of(em)
    if body is None:
        raise ControlFlowError("per-lane control flow outside a traced body")
    if body.lanes is None:
        body.lanes = Lanes(em)
    return body.lanes


def is_varying(cond) -> bool:
    """Whether a condition is a per-lane mask (a Bool of more than one lane)."""
    return isinstance(cond, Value) and cond.kind.category == "bool" and cond.width > 1


def none_of(mask) -> Value:
    """``~mask`` (None, all lanes: no lane)."""
    lanes = lanes_of()
    return value_class(lanes.mask_type())(False) if mask is None else ~mask

