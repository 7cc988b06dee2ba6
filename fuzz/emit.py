"""Emit a fuzz ``Program`` as DSL code, by calling reactor's operations.

Function mode: ``prog(x0, ..., o1, ..., i) -> out0`` is a DSL function of the
input vectors (it stores outputs 1.. through pointers at vector ``i``, returns
output 0, and may return early); ``drive(p0, ..., out0, ..., n)`` loops over
``n`` vectors and calls it. Kernel mode: a ``@kernel`` body over the inputs
returning the outputs.
"""
from __future__ import annotations

import inspect

import reactor
from reactor import SIMD, Pointer, vector_type

from .ast import Arg, Const, For, If, Lanes, Let, Op, Program, Ref, Return, Set, Ty, Var, While
from .ops import OPS


def dsl_type(ty: Ty, width: int | None = None):
    """The DSL class for ``ty`` in the function being built (or at ``width``)."""
    return vector_type(ty.kind, 1 if ty.scalar else (width or SIMD.width))


def snapshot(value):
    """``value`` as an immutable value: `t = var` in Python would alias a Variable, so a
    Let binds a copy of its current value (for any other value, the same IR value)."""
    if isinstance(value, reactor.Value):
        return vector_type(type(value), value.width)(value)
    return value  # a Python number


class Emitter:
    def __init__(self, program: Program, inputs, on_return=None):
        self.p, self.inputs, self.on_return = program, inputs, on_return
        self.env: dict[str, object] = {}

    def expr(self, e):
        if isinstance(e, Arg):
            return self.inputs[e.index]
        if isinstance(e, Ref):
            return self.env[e.name]
        if isinstance(e, Const):
            return e.value if e.literal else dsl_type(e.ty)(e.value)
        if isinstance(e, Lanes):
            W = 1 if e.ty.scalar else SIMD.width
            T = dsl_type(e.ty, W)
            return T(*e.values[:W]) if W > 1 else T(e.values[0])
        if isinstance(e, Op):
            return OPS[e.name].emit(e, *[self.expr(a) for a in e.args])
        raise TypeError(f"unknown expression {e!r}")

    def block(self, stmts):
        for s in stmts:
            if isinstance(s, Let):
                self.env[s.name] = snapshot(self.expr(s.expr))
            elif isinstance(s, Var):
                self.env[s.name] = reactor.Variable(dsl_type(s.ty), self.expr(s.init), name=s.name,
                                                    uniform=s.ty.scalar)
            elif isinstance(s, Set):
                self.env[s.name].set(self.expr(s.expr))
            elif isinstance(s, If):
                with reactor.If(self.expr(s.cond)):
                    self.block(s.then)
                for cond, body in s.elifs:
                    with reactor.Elif(self.expr(cond)):
                        self.block(body)
                if s.orelse is not None:
                    with reactor.Else():
                        self.block(s.orelse)
            elif isinstance(s, For):
                with reactor.For(self.expr(s.start), self.expr(s.stop), s.step) as i:
                    self.env[s.name] = i
                    self.block(s.body)
            elif isinstance(s, While):
                k = self.env[s.counter] = reactor.Variable(reactor.Int, 0, name=s.counter, uniform=True)

                def test(s=s, k=k):
                    c = k < self.expr(s.bound)
                    return c if s.extra is None else c & self.expr(s.extra)

                with reactor.While(test):
                    self.block(s.body)
                    k += 1
            elif isinstance(s, Return):
                self.on_return(self)
            else:
                raise TypeError(f"unknown statement {s!r}")

    def outputs(self):
        return [self.expr(o) for o in self.p.outputs]


def _with_signature(fn, names):
    fn.__signature__ = inspect.Signature(
        [inspect.Parameter(n, inspect.Parameter.POSITIONAL_OR_KEYWORD) for n in names])
    return fn


def _generic(kind: str):
    return getattr(SIMD, kind)


def function_of(program: Program, name: str = "fuzz") -> reactor.Function:
    """The ``drive`` Function of a function-mode program (compile it at any width)."""
    nin, nout = len(program.inputs), len(program.outputs)
    out_kinds = [o.ty.kind for o in program.outputs]

    def store_and_return(em: Emitter):
        vals = em.outputs()
        for ptr, v in zip(em.optrs, vals[1:]):
            ptr[em.index] = v
        reactor.Return(vals[0], body=True)  # from the fuzzed function, though called in this helper

    def prog_body(*params):
        em = Emitter(program, params[:nin], store_and_return)
        em.optrs, em.index = params[nin:nin + nout - 1], params[-1]
        em.block(program.body)
        store_and_return(em)

    prog_names = [f"x{k}" for k in range(nin)] + [f"o{k}" for k in range(1, nout)] + ["i"]
    prog = reactor.Function(
        _with_signature(prog_body, prog_names),
        args=[_generic(t.kind) for t in program.inputs] + [Pointer[_generic(k)] for k in out_kinds[1:]]
        + [reactor.Int],
        returns=_generic(out_kinds[0]), name=f"{name}_prog")

    def drive_body(*params):
        ptrs, outs, n = params[:nin], params[nin:nin + nout], params[-1]
        with reactor.For(0, n) as i:
            outs[0][i] = prog(*[p[i] for p in ptrs], *outs[1:], i)

    drive_names = [f"p{k}" for k in range(nin)] + [f"out{k}" for k in range(nout)] + ["n"]
    return reactor.Function(
        _with_signature(drive_body, drive_names),
        args=[Pointer[_generic(t.kind), "n"] for t in program.inputs]
        + [Pointer[_generic(k), "n"] for k in out_kinds] + [reactor.Int],
        returns=None, name=name, fma=build_fma(program), opt=program.opt, target=program.target, cache=False)


def kernel_of_program(program: Program, width: int, name: str = "fuzz"):
    """The ufunc of a kernel-mode program at ``width``."""
    nin = len(program.inputs)
    out_kinds = [o.ty.kind for o in program.outputs]

    def body(*xs):
        em = Emitter(program, xs)
        em.block(program.body)
        outs = em.outputs()
        return tuple(outs) if len(outs) > 1 else outs[0]

    ret = tuple(vector_type(k, 1) for k in out_kinds)
    return reactor.kernel(
        _with_signature(body, [f"x{k}" for k in range(nin)]),
        args=[vector_type(t.kind, 1) for t in program.inputs], returns=ret if len(ret) > 1 else ret[0],
        name=name, width=width, fma=build_fma(program), opt=program.opt, target=program.target, cache=False)


def build_fma(program) -> bool | str:
    """The program's FMA setting as a build option: fused where the target has no FMA is the
    exact software emulation (fma=True would be refused there)."""
    if program.fma and not reactor.get_target(program.target).has_fma:
        return "emulate"
    return program.fma

