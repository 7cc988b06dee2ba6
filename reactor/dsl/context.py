"""The DSL's state of each function it builds, kept on the DSL's side of the seam.

The emitter (``reactor.ir.emitter``) keeps only what LLVM needs; what tracing a Python body
adds lives here, in one typed :class:`Body` per function being built: what is built (a
Function's ``Built`` or a kernel's ``KernelBody``: its name and results, for ``Return``), the
code object of the traced body, the execution mask (``reactor.dsl.lanes``, made on first
use), the blocks created but not yet entered, and the source location of code emitted after
the body returned. The emitter asks the front end for the user's ``(file, line)`` through the
provider :func:`begin` installs (a Python frame here; another front end installs its own).
"""
from __future__ import annotations

import dataclasses
import typing

from ..errors import ControlFlowError, user_location
from ..ir import emitter as _em

if typing.TYPE_CHECKING:
    from .lanes import Lanes
    from .values import Value


@dataclasses.dataclass(eq=False)
class Body:
    """The DSL's state of one function being built."""

    function: typing.Any  # what is built: dsl.definition.Built or kernels.loop.KernelBody
    is_kernel: bool  # a kernel's per-element body (Variables per lane, Return per lane)
    code: typing.Any = None  # the code object of the body being traced (Return's home)
    lanes: "Lanes | None" = None  # the execution-mask state, made on first use
    unentered: list = dataclasses.field(default_factory=list)  # blocks created, never entered with 'with'
    after_return: tuple[str, int] | None = None  # where code emitted after the body returned belongs
    named: dict = dataclasses.field(default_factory=dict)  # @syntax's variables: (function, name) -> Variable

    def location(self) -> tuple[str, int] | None:
        """The user's ``(file, line)`` of what is being emitted now."""
        return self.after_return or user_location()


def begin(em, function, body_callable=None, *, is_kernel: bool = False) -> Body:
    """Start tracing ``body_callable`` into the FunctionEmitter ``em``: its DSL state, and the
    emitter's source locations from the user's frames."""
    body = Body(function, is_kernel, getattr(body_callable, "__code__", None))
    em.front = body
    em.locate = body.location
    return body


def body_of(em=None) -> Body | None:
    """The DSL state of ``em`` (default: the function being built); None for plumbing."""
    front = (em or _em.current()).front
    return front if isinstance(front, Body) else None


def is_kernel_body(em=None) -> bool:
    """Whether ``em`` (default: the function being built) traces a kernel's per-element body."""
    body = body_of(em)
    return body is not None and body.is_kernel


def check_entered(em) -> None:
    """Raise if a block (If, For, ...) was created in ``em``'s body but never entered."""
    body = body_of(em)
    if body is not None and body.unentered:
        blk = body.unentered[0]
        name = type(blk).__name__
        raise ControlFlowError(f"{name}(...) was created but never entered, so it has no effect: "
                               f"write 'with {name}(...):'", location=getattr(blk, "_created", None))


def active_mask() -> Value | None:
    """The active lanes at the cursor (None: all of them, uniform control)."""
    body = body_of()
    return None if body is None or body.lanes is None else body.lanes.active()
