"""The control-flow core as plain calls, for front ends that are not Python ``with`` blocks.

The core's blocks (``reactor.dsl.control``: If, Elif, Else, While, For, over the execution mask of
``reactor.dsl.lanes``) open with ``begin()`` and close with ``end()``; ``with If(...):`` calls the
two, and a front end that rewrites Python's ``if``/``while`` or translates SPIR-V's structured
control flow calls them through these functions; each ``*_begin`` returns the open block, which
:func:`end` closes (blocks nest: close the innermost first)::

    b = flow.if_begin(x < 0.0)       # a scalar Bool branches; a mask runs the block per lane
    flow.assign(y, -x)               # a Variable changes in the active lanes only
    flow.end(b)
    b = flow.else_begin()            # right after the If's end
    flow.assign(y, x)
    flow.end(b)

    loop, i = flow.for_begin(0, n, lane_exits=True)  # the body may Break/Continue/Return per lane
    ...
    flow.loop_break()
    flow.end(loop)

``lane_exits`` tells a loop whether its body leaves it per lane (Break, Continue or Return
under a per-lane condition); None lets the Python front end read the body's source.
:func:`push_mask`/:func:`pop_mask` run code for a subset of the lanes without a block (as
SPIR-V code after a divergent merge, or a ``?:`` whose arms have effects), and
:func:`active_mask` says which lanes are active.
"""
from __future__ import annotations

import typing

from ..errors import ControlFlowError, DSLTypeError
from .context import active_mask
from .control import Break, Continue, Elif, Else, For, If, Return, While, _mask
from .lanes import lanes_of
from .values import Value
from .variables import is_variable

__all__ = ["active_mask", "assign", "else_begin", "elif_begin", "end", "for_begin", "if_begin", "loop_break",
           "loop_continue", "pop_mask", "push_mask", "return_value", "while_begin"]


def _opened(block):
    """Enter ``block``, noting the push_mask's outstanding (``end`` checks none is left)."""
    pushes = len(lanes_of().pushed)
    result = block.begin()
    block._pushes = pushes
    return result


def if_begin(cond: Value) -> If:
    """Open ``if (cond)``: a scalar Bool branches, a mask runs the block for its lanes."""
    block = If(cond)
    _opened(block)
    return block


def elif_begin(cond: Value) -> Elif:
    """Open ``else if (cond)`` right after ending an If or Elif block (``cond`` computed after
    that end, as the else branch computes it)."""
    block = Elif(cond)
    _opened(block)
    return block


def else_begin() -> Else:
    """Open the ``else`` of the If or Elif block just ended."""
    block = Else()
    _opened(block)
    return block


def while_begin(cond: typing.Callable[[], Value], *, max_iterations: int | None = None,
                lane_exits: bool | None = None) -> While:
    """Open ``while (cond())``: ``cond`` is called to emit the test at the loop's head."""
    block = While(cond, max_iterations, lane_exits=lane_exits)
    _opened(block)
    return block


def for_begin(start, stop, step: int = 1, *, max_iterations: int | None = None,
              lane_exits: bool | None = None) -> tuple[For, Value]:
    """Open ``for (i = start; i < stop; i += step)``; returns the block and its counter ``i``."""
    block = For(start, stop, step, max_iterations, lane_exits=lane_exits)
    return block, _opened(block)


def end(block) -> None:
    """Close an open block (the innermost; every push_mask made in it undone first)."""
    if len(lanes_of().pushed) > getattr(block, "_pushes", 0):
        raise ControlFlowError(f"{block.what} block ended with a push_mask of its own not popped")
    block.end()


def loop_break() -> None:
    """``break`` out of the innermost loop (for the active lanes)."""
    Break()


def loop_continue() -> None:
    """``continue`` with the innermost loop's next iteration (for the active lanes)."""
    Continue()


def return_value(value: typing.Any = None) -> None:
    """``return value`` from the function being built (for the active lanes)."""
    Return(value, body=True)


def assign(variable, value) -> None:
    """``variable = value`` in the active lanes (the others keep theirs)."""
    if not is_variable(variable):
        raise DSLTypeError(f"assign needs a Variable to store into, not {variable!r}")
    variable.set(value)


def push_mask(mask: Value) -> None:
    """Narrow the active lanes to those of ``mask`` (a Bool of the body's width) until
    :func:`pop_mask` in the same block; no branch is emitted, so every lane computes and only
    stores are masked."""
    lanes = lanes_of()
    lanes.frame.conds.append(_mask(mask, "push_mask"))
    lanes.pushed.append((lanes.frame, len(lanes.frame.conds)))


def pop_mask() -> None:
    """Undo the innermost :func:`push_mask` (in the block that pushed it)."""
    lanes = lanes_of()
    if not lanes.pushed or lanes.pushed[-1][0] is not lanes.frame or lanes.pushed[-1][1] != len(lanes.frame.conds):
        raise ControlFlowError("pop_mask must undo the innermost push_mask of the same block (a block "
                               "entered since must end first)")
    lanes.pushed.pop()
    lanes.frame.conds.pop()
