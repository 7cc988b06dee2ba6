"""Independent NumPy evaluation of a fuzz ``Program``.

Function-mode programs run once per vector (a *row* of ``W`` lanes), so the
evaluator is predicated: every statement runs for all rows under a row mask
(``If`` branches, loop iterations, rows not yet returned). Kernel-mode programs
are lane-wise and are evaluated with ``W = 1``, one row per element.

Taint (see ``ops.py``) marks lanes the contract leaves open. A condition that
is tainted in a row makes the whole row's results open (its control path is).
"""
from __future__ import annotations

import types

import numpy as np

from .ast import DTYPES, Arg, Const, For, If, Lanes, Let, Op, Program, Ref, Return, Set, Ty, Var, While
from .ops import OPS

MAX_ITERATIONS = 10_000


class EvaluatorError(AssertionError):
    """The evaluator met something it does not model (a fuzzer bug, not a reactor bug)."""


def const_array(value, ty: Ty) -> np.ndarray:
    dt = DTYPES[ty.kind]
    if ty.kind in ("Int", "UInt"):
        return np.array(int(value) & 0xFFFFFFFF, np.uint32).astype(dt)
    if ty.kind == "Bool":
        return np.array(bool(value))
    return np.array(value, dt)


class _Eval:
    def __init__(self, program: Program, inputs: list[np.ndarray], W: int, nan_choice: bool = False):
        self.p, self.W = program, W
        self.nan_choice = nan_choice
        self.rows = inputs[0].shape[0] if inputs else 1
        self.ctx = types.SimpleNamespace(W=W, fma=program.fma)
        self.inputs = inputs
        self.env: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self.alive = np.ones((self.rows, 1), bool)
        self.row_taint = np.zeros((self.rows, 1), bool)
        self.outs = [None] * len(program.outputs)
        self.out_taints = [None] * len(program.outputs)

    # -- expressions ------------------------------------------------------------------
    def expr(self, e):
        if isinstance(e, Arg):
            return self.inputs[e.index], False
        if isinstance(e, Ref):
            return self.env[e.name]
        if isinstance(e, Const):
            return const_array(e.value, e.ty).reshape(1, 1), False
        if isinstance(e, Lanes):
            vals = e.values[: self.W]
            return np.stack([const_array(v, e.ty) for v in vals]).reshape(1, self.W), False
        if isinstance(e, Op):
            spec = OPS[e.name]
            evs = [self.expr(a) for a in e.args]
            vals = [v for v, _ in evs]
            value, extra = spec.ev(vals, [a.ty for a in e.args], e, self.ctx)
            value = np.asarray(value)
            if value.dtype != e.ty.dtype:
                raise EvaluatorError(f"{e.name} gave {value.dtype}, expected {e.ty.dtype}")
            if e.name == "select":  # the taint of the operand chosen (and the mask's)
                (_, tm), (_, ta), (_, tb) = evs
                taint = tm | (np.where(vals[0], ta, tb) if not (ta is False and tb is False) else False)
            else:
                taint = False
                for _, t in evs:
                    taint = taint | t
            if extra is not None:
                taint = taint | extra
            if self.nan_choice and e.name != "select" and value.dtype.kind == "f":
                taint = taint | _two_nans(vals)
            if spec.cross_lane and e.ty.scalar and not isinstance(taint, bool):
                taint = np.any(taint, axis=1, keepdims=True)  # conservatively, the whole row
            return value, taint
        raise EvaluatorError(f"unknown expression {e!r}")

    def shaped(self, value, taint, ty: Ty):
        shape = (self.rows, 1 if ty.scalar else self.W)
        value = np.broadcast_to(value, shape).astype(ty.dtype, copy=True)
        taint = np.broadcast_to(np.asarray(taint, bool), shape).copy()
        return value, taint

    def cond(self, e, act):
        value, taint = self.expr(e)
        value = np.broadcast_to(value, (self.rows, 1))
        self.row_taint |= np.broadcast_to(taint, (self.rows, 1)) & act
        return value

    # -- statements -------------------------------------------------------------------
    def block(self, stmts, active):
        for s in stmts:
            act = active & self.alive
            if isinstance(s, Let):
                self.env[s.name] = self.expr(s.expr)
            elif isinstance(s, Var):
                self.env[s.name] = self.shaped(*self.expr(s.init), s.ty)
            elif isinstance(s, Set):
                old, old_t = self.env[s.name]
                new, new_t = self.expr(s.expr)
                new = np.broadcast_to(new, old.shape)
                new_t = np.broadcast_to(np.asarray(new_t, bool), old.shape)
                self.env[s.name] = (np.where(act, new, old), np.where(act, new_t, old_t))
            elif isinstance(s, If):
                taken = np.zeros((self.rows, 1), bool)
                for cond, body in ((s.cond, s.then),) + tuple(s.elifs):
                    c = self.cond(cond, act & ~taken)
                    self.block(body, act & ~taken & c)
                    taken |= c
                if s.orelse is not None:
                    self.block(s.orelse, act & ~taken)
            elif isinstance(s, For):
                self.for_loop(s, act)
            elif isinstance(s, While):
                self.while_loop(s, act)
            elif isinstance(s, Return):
                self.record(act)
                self.alive &= ~act
            else:
                raise EvaluatorError(f"unknown statement {s!r}")

    def for_loop(self, s: For, act):
        kind = "UInt" if "UInt" in (s.start.ty.kind, s.stop.ty.kind) and not (
            _literal(s.start) and _literal(s.stop)) else "Int"
        ends = []
        for e in (s.start, s.stop):
            v, t = self.expr(e)
            self.row_taint |= np.broadcast_to(t, (self.rows, 1)) & act
            v = np.broadcast_to(v, (self.rows, 1))
            ends.append(v.astype(np.uint32).astype(np.int64) if kind == "UInt" else v.astype(np.int64))
        start, stop = ends
        step = s.step
        span = (stop - start) if step > 0 else (start - stop)
        trips = np.where(span > 0, -(-span // abs(step)), 0)
        most = int(trips[act].max()) if act.any() else 0
        if most > MAX_ITERATIONS:
            raise EvaluatorError(f"loop of {most} iterations")
        for t in range(most):
            act_t = act & self.alive & (t < trips)
            if not act_t.any():
                break
            i = (start + t * step) & 0xFFFFFFFF
            self.env[s.name] = (i.astype(np.uint32).astype(DTYPES[kind]), False)
            self.block(s.body, act_t)

    def while_loop(self, s: While, act):
        k = np.zeros((self.rows, 1), np.int32)
        self.env[s.counter] = (k, np.zeros((self.rows, 1), bool))
        act_t = act.copy()
        for _ in range(MAX_ITERATIONS):
            act_t &= self.alive
            k, kt = self.env[s.counter]
            bound, bt = self.expr(s.bound)
            c = np.broadcast_to(k < bound, (self.rows, 1))
            self.row_taint |= np.broadcast_to(bt, (self.rows, 1)) & act_t
            if s.extra is not None:
                c = c & self.cond(s.extra, act_t & c)
            act_t &= c
            if not act_t.any():
                return
            self.block(s.body, act_t)
            k, kt = self.env[s.counter]
            self.env[s.counter] = (np.where(act_t & self.alive, k + np.int32(1), k), kt)
        raise EvaluatorError("while loop did not finish")

    def record(self, rows):
        for j, e in enumerate(self.p.outputs):
            value, taint = self.shaped(*self.expr(e), e.ty.vector())
            if self.outs[j] is None:
                self.outs[j], self.out_taints[j] = np.zeros_like(value), np.zeros_like(taint)
            self.outs[j] = np.where(rows, value, self.outs[j])
            self.out_taints[j] = np.where(rows, taint, self.out_taints[j])

    def run(self):
        with np.errstate(all="ignore"):
            self.block(self.p.body, np.ones((self.rows, 1), bool))
            self.record(self.alive.copy())
        return ([o.reshape(-1) for o in self.outs],
                [(t | self.row_taint).reshape(-1) for t in self.out_taints])


def _two_nans(vals):
    """Lanes where two or more float operands are NaN: which one an operation returns is the
    hardware's choice (IEEE 754 leaves it open; x86 takes the first operand of the instruction
    form LLVM picked, AArch64 the addend of a fused multiply-add first)."""
    count = 0
    for v in vals:
        v = np.asarray(v)
        if v.dtype.kind == "f":
            count = count + np.isnan(v).astype(np.int8)
    return np.asarray(count) >= 2 if not isinstance(count, int) else False


def _literal(e) -> bool:
    return isinstance(e, Const) and e.literal


def evaluate(program: Program, inputs: list[np.ndarray], W: int, nan_choice: bool = False):
    """Outputs and taint masks (flat arrays of ``len(inputs[k])`` lanes) of ``program``
    on the flat ``inputs`` at width ``W`` (function mode) or lane-wise (kernel mode).
    ``nan_choice`` also taints the lanes where an operation met two NaNs (for comparing
    NaN bits between targets)."""
    width = W if program.mode == "function" else 1
    shaped = [np.ascontiguousarray(x).reshape(-1, width) for x in inputs]
    return _Eval(program, shaped, width, nan_choice).run()
