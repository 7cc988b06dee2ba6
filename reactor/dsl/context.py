"""The DSL's state at the cursor of the function being built, for the modules that read it but
do not own it: which lanes are active (``reactor.dsl.lanes`` keeps the execution mask; a
Variable, a pointer or a texture stores only in the active lanes)."""
from __future__ import annotations

import typing

from ..ir import emitter as _em

if typing.TYPE_CHECKING:
    from .values import Value


def active_mask() -> Value | None:
    """The active lanes at the cursor (None: all of them, uniform control)."""
    em = _em.current()
    return None if em.lanes is None else em.lanes.active()
