"""Which library routines a build called, at which precision: a list on the compiled code.

A routine library (``routines``) emits each routine inside
``with routine_call(name):``; the module being built keeps one ``RoutineCall`` per routine,
precision, FMA setting and user line, in the order of first use. Kernels
(``kernel_of(u).routines``) and compiled Functions (``f.compile().routines``)
show the list, so a scene's author sees what every call site cost.
"""
from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import typing

from ..errors import user_location
from ..ir import emitter as _em


@dataclasses.dataclass(frozen=True)
class RoutineCall:
    """One routine emitted by a build: ``exp2 relaxed fma=on at shade.py:12``."""

    name: str
    precision: str  # a tier ("full", "relaxed" ...) or a continuum variant ("full-d3")
    fma: bool
    where: str  # the user's "file:line" ("" when unknown)

    def __str__(self) -> str:
        at = f" at {self.where}" if self.where else ""
        return f"{self.name} {self.precision} fma={'on' if self.fma else 'off'}{at}"


@contextlib.contextmanager
def routine_call(name: str, variant: str | None = None) -> typing.Iterator[None]:
    """Emit a library routine ``name`` in the block: recorded with the settings in force (its
    precision as the continuum ``variant``'s name where one is given: ``"full-d3"``), unless it
    is inside another routine (pow's exp2 and log2 belong to pow). No-op outside a build."""
    if not _em.building():
        yield
        return
    em = _em.current()
    module = em.module
    depth = module.routine_depth
    if depth == 0:
        settings = em.settings
        precision = variant or settings.precision.value
        call = RoutineCall(name, precision, settings.fma, where_called())
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


# -- the same pure call, emitted once ------------------------------------------------------------

def call_key(name: str, settings: tuple, args: tuple, options: dict) -> tuple | None:
    """What identifies a pure call while building: the routine, its settings, each DSL operand by
    its IR value (the same SSA value) and each Python operand by its value; None where an operand
    is neither (the call is then emitted as usual)."""
    from .values import Value
    if not _em.building():
        return None
    parts: list[tuple] = []
    for a in (*args, *sorted(options.items())):
        a = a[1] if isinstance(a, tuple) and len(a) == 2 and isinstance(a[0], str) else a
        if isinstance(a, Value):
            parts.append(("v", id(a._ir)))
        elif isinstance(a, (bool, int, float, str, type(None))):
            parts.append(("n", type(a).__name__, repr(a)))
        else:
            return None
    return (name, settings, tuple(sorted(options)), tuple(parts))


def reuse(key: tuple | None):
    """The result of the call ``key`` emitted earlier in this function where that result is still
    visible here (its block has not ended, it dominates this point), else None. Inside another
    routine, nothing is reused."""
    if key is None or not _em.building():
        return None
    em = _em.current()
    if em.module.routine_depth:
        return None
    found = em.pure_calls.get(key)
    if found is None:
        return None
    result = found[0]
    values = result if isinstance(result, tuple) else (result,)
    if all(v._emitter is em and not v._scope.closed and em.in_chain(v._ir) for v in values):
        return result
    del em.pure_calls[key]
    return None


def remember(key: tuple | None, result, args: tuple) -> None:
    """Keep ``result`` for :func:`reuse` (``args`` kept alive, so their ids stay theirs)."""
    from .values import Value
    if key is None or not _em.building():
        return
    em = _em.current()
    values = result if isinstance(result, tuple) else (result,)
    if em.module.routine_depth == 0 and all(isinstance(v, Value) for v in values):
        em.pure_calls[key] = (result, args)


def pure_call(name: str, settings: tuple, args: tuple, options: dict, emit: typing.Callable[[], typing.Any]):
    """``emit()``'s result (it emits the routine inside ``routine_call(name)``); where the same pure call (routine ``name`` with ``settings`` on the same
    operands) was emitted earlier in this function and its result is visible here, that result
    (``cos(x) + cos(x)`` computes one cosine)."""
    key = call_key(name, settings, args, options)
    found = reuse(key)
    if found is not None:
        _report(name, args, found)
        with routine_call(name):  # recorded all the same: a plan lists (and may set) this site too
            return found
    result = emit()
    remember(key, result, args)
    _report(name, args, result)
    return result


def calls_of(module) -> list[RoutineCall]:
    """The routines a module's build recorded, in order of first use."""
    return list(module.routine_calls)


# -- what a call site sees: reactor.plan's value ranges ------------------------------------------

_probe: contextvars.ContextVar = contextvars.ContextVar("reactor_site_probe", default=None)


@contextlib.contextmanager
def probing(where: str, routine: str, record: typing.Callable[[tuple], None]) -> typing.Iterator[None]:
    """While building in the block, call ``record(operands)`` at every call of ``routine`` from the
    user's line ``where`` (``reactor.plan`` measures the values each site sees this way)."""
    token = _probe.set((where, routine, record))
    try:
        yield
    finally:
        _probe.reset(token)


def site_probe(name: str, args: tuple) -> None:
    """A routine library calls this with a call's operands before emitting it: a no-op unless a
    plan is probing this site (``probing``). Calls inside another routine are not sites."""
    probe = _probe.get()
    if probe is None or not _em.building() or _em.current().module.routine_depth:
        return
    where, routine, record = probe
    if name == routine and where_called() == where:
        record(args)


# -- what each call computed from what: reactor.plan's interval analysis -------------------------

_results: contextvars.ContextVar = contextvars.ContextVar("reactor_routine_results", default=None)


@dataclasses.dataclass(frozen=True)
class CallResult:
    """A routine call a trace emitted: ``name`` at the user's line ``where``, its operands (DSL
    values or Python numbers) and its result."""

    name: str
    where: str
    args: tuple
    result: typing.Any
    block: typing.Any = None  # the IR block the call was emitted in


@contextlib.contextmanager
def recording_results(found: list) -> typing.Iterator[None]:
    """While building in the block, append a ``CallResult`` to ``found`` for every routine call
    made outside another routine (``reactor.plan`` summarizes each by the routine's function)."""
    token = _results.set(found)
    try:
        yield
    finally:
        _results.reset(token)


def _report(name: str, args: tuple, result) -> None:
    found = _results.get()
    if found is None or not _em.building() or _em.current().module.routine_depth:
        return
    found.append(CallResult(name, where_called(), tuple(args), result, _em.current().block))
