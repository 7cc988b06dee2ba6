"""Run-time control flow as context managers, as in Reactor.

::

    with If(x < 0.0):
        y.set(-x)
    with Elif(x > 1.0):
        y.set(1.0)
    with Else():
        y.set(x)

    with For(0, n) as i:        # i: Int counter, start <= i < stop, step +1
        ...
    with While(lambda: k < 10): # the condition is re-evaluated every iteration
        k += 1

Conditions are scalar ``Bool`` values (reduce masks with ``Any``/``All``).
Plain Python ``if``/``for`` run at build time and specialize or unroll the
emitted code. ``Return(v)`` returns from the function being built.
"""
from __future__ import annotations

import typing
from typing import Callable

from ..errors import ControlFlowError, DSLTypeError, ScopeError, user_location
from ..ir import emitter as _em
from ..ir import ops
from ..ir import types as T
from ..ir.types import KINDS, VType
from ..source import returns_in_blocks
from .values import Operand, Value, common_type, to_ir, value_class
from .variables import Variable


def _condition(cond, what: str):
    if isinstance(cond, bool):
        raise DSLTypeError(f"{what} got a Python bool: that is decided at build time; "
                           f"use a plain Python 'if' instead")
    if not isinstance(cond, Value) or cond.kind.category != "bool":
        raise DSLTypeError(f"{what} needs a scalar Bool condition, not {cond!r}")
    if cond.width != 1:
        raise DSLTypeError(f"{what} needs a scalar Bool, got a {cond.vtype.name} mask: "
                           f"reduce it with Any(...) or All(...), or use Select for lane-wise choice")
    return cond.ir


class _Block:
    """Common enter/exit protocol: a scope opened on enter, closed on exit."""

    what = "block"

    def _register(self):
        """Note the block as created-but-not-entered (an error if the function ends so)."""
        if _em.building():
            self._created = user_location()
            _em.current().unentered.append(self)

    def _open(self, em):
        if self in em.unentered:
            em.unentered.remove(self)
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
    """``with If(cond):`` runs its body when the scalar Bool ``cond`` is true."""

    what = "If"

    def __init__(self, cond: Value) -> None:
        self._cond = cond
        self._register()

    def __enter__(self) -> None:
        em = _em.current()
        cond = _condition(self._cond, self.what)
        then_block, else_block = em.new_block("if.then"), em.new_block("if.else")
        em.cbranch(cond, then_block, else_block)
        merge = em.new_block("if.end")
        self._enter_branch(em, then_block, else_block, merge)

    def _enter_branch(self, em, then_block, else_block, merge):
        self._else, self._merge = else_block, merge
        em.goto(then_block)
        self._open(em)

    def __exit__(self, exc_type, *rest) -> typing.Literal[False]:
        if exc_type is not None:
            return False
        self._close()
        em = self._em
        em.branch_to(self._merge)
        em.goto(self._else)
        em.branch(self._merge)
        em.goto(self._merge)
        em.pending_chain = (self._else, self._merge, em.mark())
        return False


def _claim_chain(what: str):
    em = _em.current()
    chain = em.pending_chain
    if chain is None or em.block is not chain[1]:
        raise ControlFlowError(f"{what} must directly follow an If or Elif block")
    else_block, merge, mark = chain
    em.claim_since_chain(else_block, merge, mark)
    return em, else_block, merge


class Elif(If):
    """``with Elif(cond):`` directly after an If/Elif block."""

    what = "Elif"

    def __enter__(self) -> None:
        em, prev_else, merge = _claim_chain("Elif")
        em.reopen(prev_else)  # drop its branch to the merge block
        cond = _condition(self._cond, self.what)
        then_block, else_block = em.new_block("elif.then"), em.new_block("elif.else")
        em.cbranch(cond, then_block, else_block)
        self._enter_branch(em, then_block, else_block, merge)
        self._scope.chain = merge


class Else(_Block):
    """``with Else():`` directly after an If/Elif block."""

    what = "Else"

    def __init__(self) -> None:
        self._register()

    def __enter__(self) -> None:
        em, else_block, merge = _claim_chain("Else")
        em.reopen(else_block)
        self._merge = merge
        self._open(em)
        self._scope.chain = merge

    def __exit__(self, exc_type, *rest) -> typing.Literal[False]:
        if exc_type is not None:
            return False
        self._close()
        self._em.branch_to(self._merge)
        self._em.goto(self._merge)
        return False


class While(_Block):
    """``with While(lambda: cond):`` loops while the condition holds.

    The condition must be re-evaluated on every iteration, so it is given as a
    callable returning a scalar Bool (or as a Bool ``Variable``).
    """

    what = "While"

    def __init__(self, cond: Callable[[], Value] | Value) -> None:
        if isinstance(cond, Value) and not hasattr(cond, "_name"):
            raise DSLTypeError("While needs a condition that is re-evaluated every iteration: "
                               "pass a lambda, e.g. While(lambda: i < n), or a Bool Variable")
        self._cond = cond
        self._register()

    def _test(self):
        return self._cond() if callable(self._cond) else self._cond

    def __enter__(self) -> None:
        em = _em.current()
        self._head, body, self._exit = em.new_block("while.cond"), em.new_block("while.body"), em.new_block("while.end")
        em.branch_to(self._head)
        em.goto(self._head)
        em.cbranch(_condition(self._test(), "While"), body, self._exit)
        em.goto(body)
        self._open(em)

    def __exit__(self, exc_type, *rest) -> typing.Literal[False]:
        if exc_type is not None:
            return False
        self._close()
        self._em.branch_to(self._head)
        self._em.goto(self._exit)
        return False


class For(_Block):
    """``with For(start, stop[, step]) as i:`` counts an Int ``i`` from start
    while ``i < stop`` (``i > stop`` for a negative step). ``step`` is a Python
    int; ``start``/``stop`` are ints or scalar Int/UInt values. ``i`` is valid
    only inside the loop."""

    what = "For"

    def __init__(self, start: int | Value, stop: int | Value | None = None, step: int = 1) -> None:
        if stop is None:
            start, stop = 0, start
        if not isinstance(step, int) or isinstance(step, bool) or step == 0:
            raise DSLTypeError(f"For step must be a non-zero Python int, not {step!r}")
        self._start, self._stop, self._step = start, stop, step
        self._register()

    def __enter__(self) -> Value:
        em = _em.current()
        ints = [v for v in (self._start, self._stop) if isinstance(v, Value)]
        vt = common_type(*ints, what="For") if ints else VType(KINDS["Int"], 1)
        if not vt.kind.is_integer or vt.width != 1:
            raise DSLTypeError(f"For bounds must be scalar Int or UInt, not {vt.name}")
        self._counter: typing.Any = Variable(value_class(vt), self._start, name="i")
        stop = to_ir(self._stop, vt)
        self._head, body = em.new_block("for.cond"), em.new_block("for.body")
        self._latch, self._exit = em.new_block("for.next"), em.new_block("for.end")
        em.branch_to(self._head)
        em.goto(self._head)
        cmp = ops.compare(em, vt, "lt" if self._step > 0 else "gt", self._counter.ir, stop)
        em.cbranch(cmp, body, self._exit)
        self._stop_ir, self._vt = stop, vt
        em.goto(body)
        self._open(em)
        # The counter lives in the loop's scope, so using it after the loop is an error.
        self._counter._scope = self._scope
        return self._counter

    def __exit__(self, exc_type, *rest) -> typing.Literal[False]:
        if exc_type is not None:
            return False
        em = self._em
        em.branch_to(self._latch)
        em.goto(self._latch)
        nxt = (self._counter.value + self._step).named("i.next")
        if abs(self._step) > 1:
            # i + step may wrap around past stop (e.g. UInt 9, 7, ..., 1 -> 2**32 - 1):
            # step only while it stays short of stop, else go to stop and leave.
            i, stop, step, vt = self._counter.ir, self._stop_ir, abs(self._step), self._vt
            ahead = ops.compare(em, vt, "lt" if self._step > 0 else "gt", i, stop)
            room = ops.binary(em, "sub", vt, *((stop, i) if self._step > 0 else (i, stop)))
            uvt = vt.with_kind("UInt")
            fits = ops.compare(em, uvt, "gt", room, T.const(uvt, step))
            more = ops.binary(em, "and", VType(KINDS["Bool"], 1), ahead, fits)
            nxt = type(nxt)._wrap(ops.select(em, more, nxt.ir, stop), em)
        self._counter.set(nxt)
        self._close()
        em.branch_to(self._head)
        em.goto(self._exit)
        return False


def Return(value: Operand | None = None) -> None:
    """Return ``value`` (or nothing) from the function being built."""
    em = _em.current()
    fn = em.dsl_function
    if getattr(fn, "is_kernel", False):  # a `ret` would leave the ufunc loop early
        raise ControlFlowError(f"Return in the body of kernel '{fn.name}': a kernel body gives its "
                               f"results with Python 'return' (use Select for per-lane choices)")
    expected = fn.returns
    if expected is None:
        if value is not None:
            raise DSLTypeError(f"Return with a value in '{fn.name}', which returns nothing")
        em.ret(None)
        return
    if value is None:
        raise DSLTypeError(f"Return without a value in '{fn.name}', which returns {expected.name}")
    if isinstance(value, Value) and (value.kind != expected.kind or value.width not in (1, expected.width)):
        raise DSLTypeError(f"Return of a {value.vtype.name} in '{fn.name}', which returns {expected.name}")
    em.ret(to_ir(value, expected))


def check_python_returns(body) -> None:
    """Refuse a Python ``return`` inside a ``with If/Elif/Else/For/While`` block of
    ``body``: it ends the *build* there, so the value is returned on every path
    at run time and the block's condition is silently ignored (``Return(v)``
    returns at run time)."""
    found = returns_in_blocks(getattr(body, "__code__", None))
    if found:
        line, what = found
        raise ControlFlowError(f"Python 'return' inside a '{what}' block returns while building, for every "
                               f"run-time path (the {what} is ignored); use Return(value), or assign a "
                               f"Variable in the block and return after it", location=line)
