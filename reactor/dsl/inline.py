"""``@inline`` helpers: a shader's functions, with ``Return`` returning from the helper.

A plain Python helper called from a body is inlined by tracing, and a
``Return`` inside it would return from the whole kernel or Function. A GLSL
function returns to its caller; ``@reactor.inline`` gives that meaning::

    @reactor.inline
    def shadow(ro: vec3, rd: vec3) -> Float:
        t = Variable(Float, 0.02)
        with For(0, 32):
            h = scene(ro + rd * t)
            with If(h < 0.001):
                Return(0.0)                  # these lanes leave shadow(), not the kernel
            t += h
        return 1.0                           # the others' result

Per lane: lanes that execute ``Return`` in the helper stop running its code
(they leave the loops opened inside it) and take that value as the call's
result; the others take the helper's Python ``return``. On a uniform path (a
scalar condition, or a width-1 body) ``Return`` branches to the end of the
call. The helper's parameters and result are DSL values, vectors or tuples of
them; it is traced at each call (no run-time call, no separate compile).
"""
from __future__ import annotations

import functools
import typing

from ..errors import DSLTypeError
from ..ir import emitter as _em
from .lanes import CallFrame, lanes_of
from .values import Value, value_class
from .variables import per_lane

F = typing.TypeVar("F", bound=typing.Callable[..., typing.Any])


def inline(fn: F, prepare: typing.Callable | None = None) -> F:
    """Make ``fn`` a helper whose ``Return`` returns from it (see the module docstring);
    ``prepare(fn)``, called at each call, gives what is traced (``reactor.inline`` passes the
    rewrite of Python's control flow, :func:`reactor.dsl.syntax.as_written`)."""
    @functools.wraps(fn)
    def call(*args, **kwargs):
        if not _em.building():
            raise DSLTypeError(f"@inline helper '{fn.__name__}' is called while building a body "
                               f"(from a kernel or a Function), not directly")
        written = prepare(fn) if prepare is not None else fn
        em = _em.current()
        lanes = lanes_of(em)
        frame = CallFrame(depth=len(lanes.frames), exit_block=em.new_block(f"{fn.__name__}.return"),
                          code=getattr(written, "__code__", None))
        lanes.calls.append(frame)
        try:
            result = written(*args, **kwargs)
            return _finish(em, frame, result, fn.__name__)
        finally:
            lanes.calls.remove(frame)

    call.__reactor_inline__ = fn.__code__  # type: ignore[attr-defined]
    return typing.cast(F, call)


def flatten(value) -> tuple[list, typing.Callable[[list], typing.Any]]:
    """A result's component values, and how to rebuild it from new ones."""
    from .vectors import Vec

    if isinstance(value, tuple):
        parts = [flatten(v) for v in value]
        sizes = [len(p[0]) for p in parts]

        def rebuild(flat):
            out, at = [], 0
            for (_, again), n in zip(parts, sizes):
                out.append(again(flat[at:at + n]))
                at += n
            return tuple(out)
        return [c for p in parts for c in p[0]], rebuild
    if isinstance(value, Vec):
        cls = type(value)
        return list(value._c), lambda flat: cls._of(flat)
    return [value], lambda flat: flat[0]


def record_return(em, frame: CallFrame, value, active) -> None:
    """``Return(value)`` inside the helper of ``frame``: the ``active`` lanes (None: every lane of
    this path) take ``value`` as the call's result and stop running the helper."""
    lanes = lanes_of(em)
    flat, _ = flatten(value)
    if value is None:
        flat = []
    _ensure_results(frame, lanes, flat)
    frame.any_return = True
    if active is None:
        for var, v in zip(frame.results, flat):
            var.set_all(v)
        em.branch_to(frame.exit_block)
        em.goto(em.new_block("after.return"))
        return
    from .intrinsics import Select
    for var, v in zip(frame.results, flat):
        var.set_all(Select(active, v, var.value))
    if frame.returned is None:
        frame.returned = lanes.entry_variable(lanes.mask_type(), False, "returned.call")
    frame.returned.set_all(frame.returned | active)
    for loop_frame in lanes.frames[frame.depth:]:  # the lanes leave the loops opened in the helper
        if loop_frame.loop is not None:
            loop_frame.loop.alive.set_all(loop_frame.loop.alive & ~active)


def _ensure_results(frame: CallFrame, lanes, flat) -> None:
    if frame.results is not None:
        if len(flat) != len(frame.results):
            raise DSLTypeError(f"Return of {len(flat)} component(s) in a helper whose other Returns give "
                               f"{len(frame.results)}")
        return
    results = []
    for k, v in enumerate(flat):
        if not isinstance(v, Value):
            v = value_class(_python_type(v))(v)
        vt = per_lane(v.vtype)
        if lanes.width and vt.width == 1 and lanes.width > 1:
            vt = vt.with_width(lanes.width)
        results.append(lanes.entry_variable(vt, False if vt.kind.category == "bool" else 0, f"result.call{k}"))
    frame.results = results


def _python_type(v):
    from ..ir.types import KINDS, VType
    kind = "Bool" if isinstance(v, bool) else "Int" if isinstance(v, int) else "Float"
    return VType(KINDS[kind], 1)


def _finish(em, frame: CallFrame, result, name: str):
    """The call's value: the Returns' results for the lanes that returned, ``result`` for the others."""
    if not frame.any_return:
        return result
    flat, rebuild = flatten(result) if result is not None else ([], None)
    if result is not None:
        _ensure_results(frame, lanes_of(em), flat)
        if not em.terminated():
            for var, v in zip(frame.results, flat):
                var.set(v)  # masked: the lanes still running the helper
    em.branch_to(frame.exit_block)
    em.goto(frame.exit_block)
    values = [var.value for var in frame.results]
    if frame.returned is not None:
        frame.returned.set_all(False)  # the next run of this code (a loop around the call) starts afresh
    if rebuild is None:
        return tuple(values) if len(values) != 1 else values[0]
    return rebuild(values)
