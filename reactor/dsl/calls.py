"""Which library routines a build called, at which precision: a list on the compiled code.

A routine library (``routines``) emits each routine inside
``with routine_call(name):``; the module being built keeps one ``RoutineCall`` per routine,
precision, FMA setting and user line, in the order of first use. Kernels
(``kernel_of(u).routines``) and compiled Functions (``f.compile().routines``)
show the list, so a scene's author sees what every call site cost.
"""
from __future__ import annotations

import contextlib
import dataclasses
import typing

from ..errors import user_location
from ..ir import emitter as _em


@dataclasses.dataclass(frozen=True)
class RoutineCall:
    """One routine emitted by a build: ``exp2 relaxed fma=on at shade.py:12``."""

    name: str
    precision: str  # "full" or "relaxed"
    fma: bool
    where: str  # the user's "file:line" ("" when unknown)

    def __str__(self) -> str:
        at = f" at {self.where}" if self.where else ""
        return f"{self.name} {self.precision} fma={'on' if self.fma else 'off'}{at}"


@contextlib.contextmanager
def routine_call(name: str) -> typing.Iterator[None]:
    """Emit a library routine ``name`` in the block: recorded with the settings in force, unless
    it is inside another routine (pow's exp2 and log2 belong to pow). No-op outside a build."""
    if not _em.building():
        yield
        return
    em = _em.current()
    module = em.module
    depth = module.routine_depth
    if depth == 0:
        settings = em.settings
        call = RoutineCall(name, settings.precision.value, settings.fma, where_called())
        if call not in module.routine_calls:
            module.routine_calls.append(call)
    module.routine_depth = depth + 1
    outer = module.routine_name
    if depth == 0:
        module.routine_name = name  # source lines group the routine's instructions under its name
    try:
        yield
    finally:
        module.routine_depth = depth
        module.routine_name = outer


def where_called() -> str:
    """The user's "file:line" being built (what ``RoutineCall.where`` and a ``Site`` name): the
    front end's location where it gives one (a shader's line, from SPIR-V's ``OpLine``)."""
    em = _em.current() if _em.building() else None
    loc = (em.locate() if em is not None and em.locate is not None else None) or user_location()
    return f"{loc[0]}:{loc[1]}" if loc else ""


def site_choice(name: str):
    """The ``Site`` a plan chose for routine ``name`` called from the user's current line, or
    None (not building, inside another routine, or no choice for this site)."""
    if not _em.building():
        return None
    em = _em.current()
    if em.module.routine_depth or not em.settings.sites:
        return None
    return em.settings.site(name, where_called())


def calls_of(module) -> list[RoutineCall]:
    """The routines a module's build recorded, in order of first use."""
    return list(module.routine_calls)
