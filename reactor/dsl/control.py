"""Run-time control flow as context managers, as in Reactor, uniform or per lane.

::

    with If(x < 0.0):            # a scalar Bool: a branch; a mask: per lane
        y.set(-x)
    with Elif(x > 1.0):
        y.set(1.0)
    with Else():
        y.set(x)

    with For(0, n) as i:        # i: Int counter, start <= i < stop, step +1
        ...
        with If(done):
            Break()             # per lane when `done` is a mask
    with While(lambda: k < 10): # the condition is re-evaluated every iteration
        k += 1

A scalar ``Bool`` condition branches. A mask (a Bool of several lanes) runs
the block for the lanes whose bit is set (ISPC's execution mask; see
``reactor.dsl.lanes``): Variables change only in those lanes, a block no lane
enters is skipped, a loop runs while any lane is in it, ``Break``,
``Continue`` and ``Return`` act per lane, and ``max_iterations=`` stops a
loop that some lane never leaves. Plain Python ``if``/``for`` run at build
time and specialize or unroll the emitted code.
"""
from __future__ import annotations

import abc
import typing
from typing import Callable

from ..errors import ControlFlowError, DSLTypeError, ScopeError, user_frame, user_location
from ..ir import emitter as _em
from ..ir import ops
from ..ir import types as T
from ..ir.types import KINDS, VType
from ..source import returns_in_blocks, with_block_calls
from .intrinsics import Any, Select
from .context import body_of, is_kernel_body
from .lanes import Frame, LoopLanes, is_varying, lanes_of
from .values import Operand, Value, common_type, shown, to_ir, value_class
from .variables import Variable

_LANE_EXITS = {"Break", "Continue", "Return"}


def _condition(cond, what: str):
    if isinstance(cond, bool):
        raise DSLTypeError(f"{what} got a Python bool: that is decided at build time; "
                           f"use a plain Python 'if' instead")
    if not isinstance(cond, Value) or cond.kind.category != "bool":
        raise DSLTypeError(f"{what} needs a Bool condition (a scalar, or a mask of the body's lanes), "
                           f"not {cond!r}")
    if cond.width != 1:
        em = _em.current()
        raise DSLTypeError(f"{what} got a {shown(cond.vtype)} mask in a body of {em.width} lane(s): "
                           f"reduce it with Any(...) or All(...)")
    return cond.ir


def _mask(cond, what: str) -> Value:
    """A per-lane condition as a mask of the lanes' width (scalar conditions are broadcast)."""
    if isinstance(cond, bool) or not isinstance(cond, Value) or cond.kind.category != "bool":
        raise DSLTypeError(f"{what} needs a Bool condition, not {cond!r}")
    lanes = lanes_of()
    lanes.adopt(cond.width, what)
    width = lanes.width or 1
    return cond if cond.width == width else value_class(VType(KINDS["Bool"], width))(cond)


class _Block(abc.ABC):
    """A block of the control-flow core: ``begin()`` opens it (a scope, blocks and branches, the
    lanes it runs for), ``end()`` closes it; ``with`` calls the two (and, when the body raised,
    leaves the block open: the build is failing anyway). ``reactor.dsl.flow`` calls them too."""

    what = "block"

    @abc.abstractmethod
    def begin(self) -> typing.Any:
        """Open the block where the cursor is; what ``with ... as`` gives (For: its counter)."""

    @abc.abstractmethod
    def end(self) -> None:
        """Close the block: code continues after it."""

    def __enter__(self) -> typing.Any:
        return self.begin()

    def __exit__(self, exc_type, *rest) -> typing.Literal[False]:
        if exc_type is None:
            self.end()
        return False

    def _register(self):
        """Note the block as created-but-not-entered (an error if the function ends so)."""
        if _em.building():
            self._created = user_location()
            body = body_of()
            if body is not None:
                body.unentered.append(self)

    def _open(self, em):
        body = body_of(em)
        if body is not None and self in body.unentered:
            body.unentered.remove(self)
        self._em = em
        self._scope = em.push_scope(self.what)
        self._scope.where = user_location()
        em.pending_chain = None

    def _close(self):
        em = self._em
        if em is not _em.current():
            raise ScopeError(f"{self.what} block closed while building another function")
        em.pop_scope(self._scope)


class If(_Block):
    """``with If(cond):`` runs its body when the scalar Bool ``cond`` is true, or for the
    lanes where the mask ``cond`` is set."""

    what = "If"
    _varying = False

    def __init__(self, cond: Value) -> None:
        self._cond = cond
        self._register()

    def begin(self) -> None:
        em = _em.current()
        if is_varying(self._cond):
            self._taken = _mask(self._cond, self.what)
            self._enter_lanes(em, self._taken)
            return
        cond = _condition(self._cond, self.what)
        then_block, else_block = em.new_block("if.then"), em.new_block("if.else")
        em.cbranch(cond, then_block, else_block)
        merge = em.new_block("if.end")
        self._enter_branch(em, then_block, else_block, merge)

    def _enter_branch(self, em, then_block, else_block, merge):
        self._else, self._merge = else_block, merge
        em.goto(then_block)
        self._open(em)

    def _enter_lanes(self, em, mask):
        """Enter the block for the lanes of ``mask`` (and skip it when none of them is active)."""
        self._varying = True
        lanes = lanes_of(em)
        lanes.frame.conds.append(mask)
        body, self._merge = em.new_block("lanes.if"), em.new_block("lanes.end")
        self._guard = (em.cbranch(Any(lanes.active()).ir, body, self._merge), body)
        em.goto(body)
        self._open(em)

    def end(self) -> None:
        self._close()
        em = self._em
        if self._varying:
            lanes_of(em).frame.conds.pop()
            _unguard_if_cheap(em, self._guard)
            em.branch_to(self._merge)
            em.goto(self._merge)
            em.pending_chain = ("lanes", self, self._merge)
            return
        em.branch_to(self._merge)
        em.goto(self._else)
        em.branch(self._merge)
        em.goto(self._merge)
        em.pending_chain = (self._else, self._merge, em.mark())


#: A per-lane block of at most this many straight-line instructions runs for every lane (its
#: assignments are masked anyway): below this, testing whether any lane is active (a reduction and a
#: branch, ~2-3 cycles a vector) costs more than it saves (benchmarks/bench_masks.py measures both sides).
CHEAP_BLOCK = 40


def _unguard_if_cheap(em, guard) -> None:
    """Drop the "any lane active?" test of a per-lane block whose body is one cheap block."""
    branch, body = guard
    if em.block is body and em.straight_and_cheap(body, CHEAP_BLOCK):
        em.always_take(branch)


def _claim_chain(what: str):
    em = _em.current()
    chain = em.pending_chain
    if chain is None or em.block is not chain[-1 if chain[0] == "lanes" else 1]:
        raise ControlFlowError(f"{what} must directly follow an If or Elif block")
    if chain[0] == "lanes":
        return em, chain[1], None
    else_block, merge, mark = chain
    em.claim_since_chain(else_block, merge, mark)
    return em, else_block, merge


class Elif(If):
    """``with Elif(cond):`` directly after an If/Elif block (per lane after a per-lane one)."""

    what = "Elif"

    def begin(self) -> None:
        em, prev, merge = _claim_chain("Elif")
        if merge is None:  # the chain is per lane: the lanes no earlier condition took
            cond = _mask(self._cond, self.what)
            self._taken = prev._taken | cond
            self._enter_lanes(em, ~prev._taken & cond)
            return
        if is_varying(self._cond):
            raise ControlFlowError("Elif with a mask after a uniform If: an If chain is uniform (scalar "
                                   "conditions) or per lane (masks) throughout")
        em.reopen(prev)  # drop its branch to the merge block
        cond = _condition(self._cond, self.what)
        then_block, else_block = em.new_block("elif.then"), em.new_block("elif.else")
        em.cbranch(cond, then_block, else_block)
        self._enter_branch(em, then_block, else_block, merge)
        self._scope.chain = merge


class Else(_Block):
    """``with Else():`` directly after an If/Elif block."""

    what = "Else"
    _varying = False

    def __init__(self) -> None:
        self._register()

    def begin(self) -> None:
        em, prev, merge = _claim_chain("Else")
        if merge is None:
            self._varying = True
            lanes = lanes_of(em)
            lanes.frame.conds.append(~prev._taken)
            body, self._merge = em.new_block("lanes.else"), em.new_block("lanes.end")
            self._guard = (em.cbranch(Any(typing.cast(Value, lanes.active())).ir, body, self._merge), body)
            em.goto(body)
            self._open(em)
            return
        em.reopen(prev)
        self._merge = merge
        self._open(em)
        self._scope.chain = merge

    def end(self) -> None:
        self._close()
        if self._varying:
            lanes_of(self._em).frame.conds.pop()
            _unguard_if_cheap(self._em, self._guard)
        self._em.branch_to(self._merge)
        self._em.goto(self._merge)


class _Loop(_Block):
    """What While and For share: the loop's frame, its lane masks, Break/Continue targets and
    the iteration limit."""

    _max: int | None = None
    _lane_exits: bool | None = None

    def _tracks_lanes(self, em, varying: bool) -> bool:
        """Whether the loop keeps per-lane masks: its condition is per lane, or its body may leave
        it per lane (it calls Break/Continue/Return and the function has several lanes)."""
        if varying:
            return True
        if not is_kernel_body(em) or em.width == 1:
            return False  # a function's scalar code branches (masks come only from mask conditions)
        if self._lane_exits is not None:  # the front end says whether the body leaves per lane
            return self._lane_exits
        frame = user_frame()
        calls = with_block_calls(frame.f_code, frame.f_lineno) if frame is not None else None
        return calls is None or bool(calls & _LANE_EXITS)

    def _begin(self, em, tracked: bool):
        lanes = lanes_of(em)
        self._head, self._body = em.new_block(f"{self.what.lower()}.cond"), em.new_block(f"{self.what.lower()}.body")
        self._latch, self._exit = em.new_block(f"{self.what.lower()}.next"), em.new_block(f"{self.what.lower()}.end")
        loop = None
        if tracked:
            entry = lanes.active()
            bools = lanes.mask_type()
            alive = Variable(value_class(bools), entry if entry is not None else True, name="alive")
            skip = Variable(value_class(bools), False, name="skip")
            loop = LoopLanes(alive, skip)
        self._frame = Frame(loop=loop, exit_block=self._exit, next_block=self._latch)
        self._count = None
        if self._max is not None:
            self._count = Variable(value_class(T.INDEX), 0, name="iterations", uniform=True)
        return loop

    def _to_head(self, em):
        em.branch_to(self._head)
        em.goto(self._head)

    def _enter_body(self, em, go):
        """Branch on ``go`` (a scalar Bool IR value) into the body, and open it."""
        if self._count is not None:
            within = ops.compare(em, T.INDEX, "lt", self._count.ir, T.const(T.INDEX, self._max))
            over, fine = em.new_block("loop.over"), em.new_block("loop.within")
            em.cbranch(go, fine, self._exit)
            em.goto(fine)
            em.cbranch(within, self._body, over)
            em.goto(over)
            _report_runaway(em, self)
            em.branch(self._exit)
        else:
            em.cbranch(go, self._body, self._exit)
        em.goto(self._body)
        lanes_of(em).frames.append(self._frame)
        self._open(em)
        if self._count is not None:
            self._count.set_all(self._count + 1)

    def _end(self, em, step=None):
        """Close the body: the latch (``step()`` there), then back to the head."""
        lanes = lanes_of(em)
        em.branch_to(self._latch)
        em.goto(self._latch)
        if step is not None:
            step()
        if self._frame.loop is not None:
            self._frame.loop.skip.set_all(False)
        self._close()
        lanes.frames.pop()
        em.branch_to(self._head)
        em.goto(self._exit)


class While(_Loop):
    """``with While(lambda: cond):`` loops while the condition holds: a scalar Bool, or a mask
    (the loop runs while any lane's condition has held every iteration).

    The condition must be re-evaluated on every iteration, so it is given as a callable (or as
    a Bool ``Variable``). ``max_iterations=N`` makes more than N iterations an error.
    """

    what = "While"

    def __init__(self, cond: Callable[[], Value] | Value, max_iterations: int | None = None, *,
                 lane_exits: bool | None = None) -> None:
        self._lane_exits = lane_exits
        if isinstance(cond, Value) and not hasattr(cond, "_name"):
            raise DSLTypeError("While needs a condition that is re-evaluated every iteration: "
                               "pass a lambda, e.g. While(lambda: i < n), or a Bool Variable")
        self._cond = cond
        self._max = _check_max(max_iterations)
        self._register()

    def _test(self):
        return self._cond() if callable(self._cond) else self._cond

    def begin(self) -> None:
        em = _em.current()
        loop = self._begin(em, tracked=self._tracks_lanes(em, False) or self._declared_varying(em))
        self._to_head(em)
        cond = self._test()
        probe_varying = is_varying(cond)
        if probe_varying and loop is None:
            raise ControlFlowError("While with a mask condition in a one-lane body")  # pragma: no cover
        if loop is None:
            go = _condition(cond, "While")
        elif probe_varying:
            loop.alive.set_all(loop.alive & _mask(cond, "While"))
            go = Any(loop.alive.value).ir
        else:
            go = ops.binary(em, "and", VType(KINDS["Bool"], 1), _condition(cond, "While"), Any(loop.alive.value).ir)
        self._enter_body(em, go)

    def _declared_varying(self, em) -> bool:
        """Whether the condition is per lane: evaluated once, aside, to know its type."""
        scratch = em.new_block("while.probe")
        here = em.block
        em.goto(scratch)
        try:
            varying = is_varying(self._test())
        finally:
            em.goto(here)
            scratch.parent.blocks.remove(scratch)
        return varying

    def end(self) -> None:
        self._end(self._em)


class For(_Loop):
    """``with For(start, stop[, step]) as i:`` counts an Int ``i`` from start while ``i < stop``
    (``i > stop`` for a negative step). ``step`` is a Python int; ``start``/``stop`` are ints or
    Int/UInt values: scalars (one counter for all lanes) or per lane (a counter per lane, the
    loop running while any lane's counter is short of its stop). ``i`` is valid only inside the
    loop. ``max_iterations=N`` makes more than N iterations an error."""

    what = "For"

    def __init__(self, start: int | Value, stop: int | Value | None = None, step: int = 1,
                 max_iterations: int | None = None, *, lane_exits: bool | None = None) -> None:
        self._lane_exits = lane_exits
        if stop is None:
            start, stop = 0, start
        if not isinstance(step, int) or isinstance(step, bool) or step == 0:
            raise DSLTypeError(f"For step must be a non-zero Python int, not {step!r}")
        self._start, self._stop, self._step = start, stop, step
        self._max = _check_max(max_iterations)
        self._register()

    def __enter__(self) -> Value:  # the counter, typed for editors
        return self.begin()

    def begin(self) -> Value:
        em = _em.current()
        ints = [v for v in (self._start, self._stop) if isinstance(v, Value)]
        vt = common_type(*ints, what="For") if ints else VType(KINDS["Int"], 1)
        if not vt.kind.is_integer:
            raise DSLTypeError(f"For bounds must be Int or UInt values, not {shown(vt)}")
        varying = vt.width > 1
        if varying:
            lanes_of(em).adopt(vt.width, "For")
        loop = self._begin(em, tracked=self._tracks_lanes(em, varying))
        self._counter: typing.Any = Variable(value_class(vt), self._start, name="i", uniform=True)
        self._to_head(em)
        stop = to_ir(self._stop, vt)
        cmp = value_class(vt.with_kind("Bool"))._wrap(
            ops.compare(em, vt, "lt" if self._step > 0 else "gt", self._counter.ir, stop), em)
        self._stop_ir, self._vt = stop, vt
        if loop is None:
            go = cmp.ir
        elif varying:
            loop.alive.set_all(loop.alive & cmp)
            go = Any(loop.alive.value).ir
        else:
            go = ops.binary(em, "and", VType(KINDS["Bool"], 1), cmp.ir, Any(loop.alive.value).ir)
        self._enter_body(em, go)
        # The counter lives in the loop's scope, so using it after the loop is an error.
        self._counter._scope = self._scope
        return self._counter

    def end(self) -> None:
        self._end(self._em, self._step_counter)

    def _step_counter(self):
        em = self._em
        nxt = (self._counter.value + self._step).named("i.next")
        if abs(self._step) > 1:
            # i + step may wrap around past stop (e.g. UInt 9, 7, ..., 1 -> 2**32 - 1):
            # step only while it stays short of stop, else go to stop and leave.
            i, stop, step, vt = self._counter.ir, self._stop_ir, abs(self._step), self._vt
            ahead = ops.compare(em, vt, "lt" if self._step > 0 else "gt", i, stop)
            room = ops.binary(em, "sub", vt, *((stop, i) if self._step > 0 else (i, stop)))
            uvt = vt.with_kind("UInt")
            fits = ops.compare(em, uvt, "gt", room, T.const(uvt, step))
            more = ops.binary(em, "and", vt.with_kind("Bool"), ahead, fits)
            nxt = type(nxt)._wrap(ops.select(em, more, nxt.ir, stop), em)
        self._counter.set_all(nxt)


def _check_max(n):
    if n is not None and (not isinstance(n, int) or isinstance(n, bool) or n < 1):
        raise DSLTypeError(f"max_iterations must be a positive int, not {n!r}")
    return n


def _innermost_loop(what: str) -> Frame:
    frame = lanes_of().loop_frame()
    if frame is None:
        raise ControlFlowError(f"{what}() outside a For or While loop")
    return frame


def Break() -> None:
    """Leave the innermost loop: for every lane when the code runs for all of them, else for the
    active lanes (the others go on)."""
    em = _em.current()
    frame = _innermost_loop("Break")
    lanes = lanes_of(em)
    active = lanes.active()
    if frame.loop is None:
        if active is not None:
            raise _untracked("Break")
        em.branch(frame.exit_block)
        em.goto(em.new_block("after.break"))
        return
    alive = frame.loop.alive
    alive.set_all(alive & ~active if active is not None else False)


def Continue() -> None:
    """Go to the innermost loop's next iteration (for the active lanes)."""
    em = _em.current()
    frame = _innermost_loop("Continue")
    lanes = lanes_of(em)
    active = lanes.active()
    if frame.loop is None:
        if active is not None:
            raise _untracked("Continue")
        em.branch(frame.next_block)
        em.goto(em.new_block("after.continue"))
        return
    skip = frame.loop.skip
    skip.set_all(skip | active if active is not None else True)


def _untracked(what: str) -> ControlFlowError:
    return ControlFlowError(f"{what}() under a per-lane condition in a loop that does not track lanes: call "
                            f"{what}() in the loop's own body (not in a function it calls), so the loop "
                            f"sees it and keeps a mask of the lanes still in it")


def Return(value: typing.Any = None, *, body: bool = False) -> None:
    """Return ``value`` (or nothing) from the function being built; in a kernel's body, or under a
    per-lane condition, for the active lanes (the others go on; a kernel's result for a lane is the
    value of its first Return, else the body's Python ``return``). Inside an ``@inline`` helper it
    returns from the helper; in a plain Python helper it is an error unless ``body=True`` (return
    from the body that called the helper)."""
    return_value(value, from_user=not body)


def return_value(value: typing.Any, from_user: bool) -> None:
    """``Return(value)``; ``from_user`` False for the body's own Python ``return`` (and
    ``Return(v, body=True)``), which may come from anywhere."""
    em = _em.current()
    body = body_of(em)
    if body is None:
        raise ControlFlowError("Return outside a traced body")
    fn = body.function
    lanes = lanes_of(em)
    active = lanes.active()
    if lanes.calls and from_user:  # inside an @inline helper: return from it
        from .inline import record_return
        record_return(em, lanes.calls[-1], value, active)
        return
    if from_user:
        _check_not_in_helper(body)
    kernel = body.is_kernel
    expected = fn.returns
    if not kernel:
        if expected is None and value is not None:
            raise DSLTypeError(f"Return with a value in '{fn.name}', which returns nothing")
        if expected is not None and value is None:
            raise DSLTypeError(f"Return without a value in '{fn.name}', which returns {expected.name}")
        if isinstance(value, Value) and (value.kind != expected.kind or value.width not in (1, expected.width)):
            raise DSLTypeError(f"Return of a {shown(value.vtype)} in '{fn.name}', which returns {expected.name}")
    if kernel and active is None:  # every lane of this path returns: a real return
        _return_from_kernel(em, fn, value)
        return
    if not kernel and active is None:  # every lane returns here
        if expected is None:
            em.ret(None)
        else:
            result = to_ir(value, expected)
            if lanes.returned is not None:
                result = Select(lanes.returned.value, lanes.results[0].value,
                                value_class(expected)._wrap(result, em)).ir
            em.ret(result)
        return
    record_lane_results(em, fn, value, active)


def _check_not_in_helper(body) -> None:
    """Refuse ``Return`` in a plain Python helper: it would return from the whole body."""
    fn = body.function
    frame = user_frame()
    while frame is not None and frame.f_code.co_name.startswith("__rx_"):
        frame = user_frame(frame.f_back)  # a branch or loop body of a rewritten body: the body itself
    if body.code is None or frame is None or frame.f_code is body.code:
        return
    raise ControlFlowError(
        f"Return inside '{frame.f_code.co_name}', a Python helper called from '{fn.name}': it would return "
        f"from '{fn.name}' itself. Decorate the helper with @reactor.inline to make its Return return from "
        f"it (as a GLSL function's return), or write Return(value, body=True) if '{fn.name}' should return")


def record_lane_results(em, fn, value, active) -> None:
    """Store ``value`` as the result of the ``active`` lanes (None: all) and mark them returned."""
    lanes = lanes_of(em)
    kernel = is_kernel_body(em)
    outs = list(fn.outputs) if kernel else ([] if fn.returns is None else [fn.returns])
    values = list(value) if isinstance(value, tuple) else ([] if value is None else [value])
    values = _split(fn, values)
    if len(values) != len(outs):
        raise DSLTypeError(f"Return of {len(values)} value(s) in '{fn.name}', which gives {len(outs)}")
    if lanes.returned is None:
        lanes.returned = lanes.entry_variable(lanes.mask_type(), False, "returned")
        lanes.results = [lanes.entry_variable(t, False if t.kind.category == "bool" else 0, f"result{k}")
                         for k, t in enumerate(outs)]
    mask = active if active is not None else lanes.all_lanes()
    for var, v in zip(lanes.results, values):
        var.set_all(Select(mask, v, var.value))
    lanes.returned.set_all(lanes.returned | mask)
    for frame in lanes.frames:  # the lanes leave every loop they are in
        if frame.loop is not None:
            frame.loop.alive.set_all(frame.loop.alive & ~mask)


def _return_from_kernel(em, fn, value) -> None:
    """Return ``value`` from a kernel's body for every lane on this path (lanes that returned
    earlier keep their results)."""
    values = value if isinstance(value, tuple) else ((value,) if value is not None else ())
    outs = list(fn.outputs)
    flat = _split(fn, list(values))
    if len(flat) != len(outs):
        raise DSLTypeError(f"Return of {len(values)} value(s) in '{fn.name}', which gives {len(outs)}")
    results = final_results(em, fn, _join(fn, [value_class(t)._wrap(to_ir(v, t), em) for v, t in zip(flat, outs)]))
    irs = [r.ir for r in _split(fn, list(results))]
    em.ret(irs[0] if len(irs) == 1 else em.pack(T.StructType(tuple(outs)), irs))


def _split(fn, values: list) -> list:
    """A kernel's results as its flat component values (a vector result: its components)."""
    split = getattr(fn, "split", None)
    return split(values) if split is not None else values


def _join(fn, flat: list) -> tuple:
    join = getattr(fn, "join", None)
    return join(flat) if join is not None else tuple(flat)


def final_results(em, fn, values):
    """The body's results: its Python return values, where no lane returned earlier."""
    body = body_of(em)
    lanes = None if body is None else body.lanes
    if lanes is None or lanes.returned is None:
        return values
    if values is None:
        return _join(fn, [var.value for var in lanes.results])
    flat = _split(fn, list(values))
    return _join(fn, [Select(lanes.returned.value, var.value, v) for var, v in zip(lanes.results, flat)])


def _report_runaway(em, loop) -> None:
    """Record that ``loop`` ran out of iterations (the kernel or routine raises it after the call)."""
    from .limits import report_runaway
    report_runaway(em, loop)


def check_python_returns(body) -> None:
    """Refuse a Python ``return`` inside a ``with If/Elif/Else/For/While`` block of
    ``body``: it ends the *build* there, so the value is returned on every path
    at run time and the block's condition is silently ignored (``Return(v)``
    returns at run time)."""
    if getattr(body, "__reactor_syntax__", False):
        return  # @syntax made each such return a run-time Return
    found = returns_in_blocks(getattr(body, "__code__", None))
    if found:
        line, what = found
        raise ControlFlowError(f"Python 'return' inside a '{what}' block returns while building, for every "
                               f"run-time path (the {what} is ignored); use Return(value), or assign a "
                               f"Variable in the block and return after it", location=line)
