"""Python as it is written: ``if``/``elif``/``else``, ``while``, ``for i in range(...)``, ``and``,
``or``, ``not``, conditional expressions and chained comparisons on per-lane values.

``@reactor.syntax`` rewrites a function's ``if``, ``while`` and ``for ... in range(...)``
statements once (the abstract syntax tree of its source, line numbers kept); every kernel and
Function body is rewritten so when it is first traced (:func:`as_written`), a helper when it is
decorated. Each statement decides when it runs whether it is Python's or the kernel's. A condition that is a Python
value (a bool, a number, a build setting) is Python's: one branch is traced, as before. A condition that is a DSL
``Bool`` (a scalar: a branch; a mask: per lane) is the kernel's: both branches are traced
through the control-flow core (``reactor.dsl.flow``), and every name either branch assigns
becomes a variable of the function (stored where the branch runs, per lane under a mask), so
after the ``if`` a name holds, in each lane, what that lane's branch gave it::

    @reactor.kernel
    def shade(x: Float) -> Float:
        if x < 0.0:
            r = 2.0          # a Python number: a Float in the lanes that take this branch
        elif x > 1.0:
            r = x * x
        else:
            return x         # per lane: these lanes' result is x
        return r + 1.0

A ``while`` or ``for`` over DSL values is a run-time loop (per lane where its test or bound is): the
names its body assigns are carried from one iteration to the next, per lane, and after it hold
their last values (a name first assigned inside has none: the loop may not have run). Inside a
run-time branch or loop, ``return v`` returns for the lanes that reach it (the others go on), and
``break``/``continue`` act per lane on the innermost run-time loop (``Break()``/``Continue()`` on a
``with For``/``While``). What cannot be honoured is an error at the user's line, never a silent
wrong answer: a name assigned on one path only and read afterwards (it names it); a Python object
other than a number assigned, or mutated, under a run-time condition; ``break`` under a run-time
condition out of a Python loop (which runs at build time).
"""
from __future__ import annotations

import ast
import dis
import hashlib
import marshal
import os
import sys
import sysconfig
import types
import functools
import inspect
import linecache
import numbers
import textwrap
import typing
import weakref

from ..errors import ControlFlowError, DSLTypeError
from ..ir import emitter as _em
from ..source import AST_LOCK
from . import flow
from .control import Return
from .inline import inline as _inline
from .rewrite import _def, _Expressions, _located_all, _Rewriter
from .values import Value


def syntax(fn, *, use_disk: bool = False):
    """Rewrite ``fn``'s ``if``, ``while`` and ``for ... in range(...)`` statements so that a DSL
    condition runs them at run time (see the module docstring); the result is a plain function
    with ``fn``'s name, signature and lines (``fn`` itself where there is nothing to rewrite).
    Closure variables are read when ``fn`` is decorated. The rewritten code is kept per source
    text (in memory; with ``use_disk``, in reactor's authenticated disk cache too, as Python
    keeps ``.pyc`` files), so the same ``def`` is rewritten once."""
    code = getattr(fn, "__code__", None)
    if code is None:
        raise DSLTypeError(f"@syntax needs a Python function (a def in a file), not {fn!r}")
    if type(fn) is types.FunctionType and not _needs_rewrite(fn):
        return fn  # nothing to rewrite, read from its bytecode
    compiled, returns, owner = _rewritten(fn, code, use_disk)
    namespace: dict = {}
    exec(compiled, fn.__globals__, namespace)  # noqa: S102 - the user's own code, rewritten
    cells = [c.cell_contents for c in (fn.__closure__ or ())]
    rewritten = namespace["__reactor_make"](_Runtime, *cells)
    rewritten.__code__ = rewritten.__code__.replace(co_name=code.co_name, **(
        {"co_qualname": code.co_qualname} if hasattr(code, "co_qualname") else {}))  # tracebacks name the user's
    rewritten.__defaults__, rewritten.__kwdefaults__ = fn.__defaults__, fn.__kwdefaults__
    functools.update_wrapper(rewritten, fn)
    del rewritten.__wrapped__  # its own code is what runs (and what errors point into)
    rewritten.__reactor_syntax__ = True
    rewritten.__reactor_returns__ = returns  # a return that may act per lane
    _OWNERS[owner] = rewritten.__code__
    return rewritten


_REWRITE_FORMAT = 4  # changes when the rewrite does: entries of another format are never read
_REWRITES: dict = {}  # source key -> (module code, returns per lane, owner)


def _rewritten(fn, code, use_disk: bool):
    """The compiled rewrite of ``fn``'s ``def`` (a module defining ``__reactor_make``), whether
    a return of it may act per lane, and its owner name: from memory, the disk cache, or made."""
    from ..jit import cache

    found = _def_lines(code)
    if found is None:
        raise DSLTypeError(f"@syntax needs the source of {getattr(fn, '__name__', fn)!r} (a def in a file)")
    lines, start = found
    key = "w" + hashlib.sha256(repr((_REWRITE_FORMAT, sys.version, code.co_filename, start, code.co_name,
                                     code.co_freevars, "".join(lines))).encode()).hexdigest()[:40]
    made = _REWRITES.get(key)
    if made is None and use_disk:
        raw = cache.disk_get(key, ".w")
        if raw is not None:
            try:
                made = marshal.loads(raw)
            except (ValueError, EOFError, TypeError):
                made = None
    if made is None:
        made = _rewrite(fn, code, lines, start)
        if use_disk:
            cache.disk_put(key, marshal.dumps(made), ".w")
    _REWRITES[key] = made
    return made


def _rewrite(fn, code, lines, start):
    tree = _parse_def(lines, start) or _fresh_tree(code)
    if tree is None:
        raise DSLTypeError(f"@syntax needs the source of {getattr(fn, '__name__', fn)!r} (a def in a file)")
    text = "".join(lines)
    if ("global" in text or "nonlocal" in text) and any(isinstance(n, (ast.Global, ast.Nonlocal))
                                                        for n in ast.walk(tree)):
        raise DSLTypeError(f"@syntax: '{tree.name}' declares global or nonlocal names; pass values in and "
                           f"return them instead")
    tree.body = [_Expressions().visit(stmt) for stmt in tree.body]
    owner = f"{code.co_filename}:{tree.lineno}:{tree.name}"
    rewriter = _Rewriter(owner)
    new = rewriter.function(tree)
    new.name = "__rx_written"  # not the user's name: the body may call what that name holds (recursion)
    factory = _def("__reactor_make", ["__rt"] + list(code.co_freevars),
                   [new, ast.Return(ast.Name(new.name, ast.Load()))])
    for node in [factory, factory.body[1], factory.body[1].value] + factory.args.args:  # the only new nodes here
        ast.copy_location(node, tree)
    module = _located_all(ast.Module(body=[factory], type_ignores=[]))  # once: new nodes, their parents'
    with AST_LOCK:
        compiled = compile(module, code.co_filename, "exec")
    return compiled, rewriter.returns_per_lane, owner


#: a rewritten function's name in the code it calls -> its code object (where a return returns from)
_OWNERS: dict[str, typing.Any] = {}


_WRITTEN: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def as_written(body, use_disk: bool = False):
    """What kernels and Functions trace: ``body`` with its Python control flow rewritten (as
    ``@syntax`` does) where it has any, else ``body`` itself; a body that cannot be rewritten (no
    source, ``global``/``nonlocal``, a closure cell not yet filled) is traced as it is, where
    Python's truth of a DSL value is the error it always was. Rewritten once per function object."""
    if getattr(body, "__reactor_syntax__", False) or getattr(body, "__code__", None) is None:
        return body
    try:
        return _WRITTEN[body]
    except (KeyError, TypeError):
        pass
    try:
        written = syntax(body, use_disk=use_disk) if _needs_rewrite(body) else body
    except (DSLTypeError, ValueError):  # ValueError: an empty closure cell
        written = body
    try:
        _WRITTEN[body] = written
    except TypeError:  # not weakly referenceable
        pass
    return written


_HELPERS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()
#: the opcodes of code that needs the rewrite: a branch, a loop, ``not``, a ``with`` block
_REWRITTEN_OPS = frozenset(op for name, op in dis.opmap.items()
                           if "JUMP" in name and "IF" in name
                           or name in ("FOR_ITER", "UNARY_NOT", "SETUP_WITH", "BEFORE_WITH"))
_LIBRARY_DIRS = tuple(os.path.realpath(p) + os.sep for p in {
    os.path.dirname(os.path.dirname(os.path.abspath(__file__))),  # reactor
    os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "routines"),
    *(sysconfig.get_paths()[k] for k in ("stdlib", "purelib", "platlib"))})
_NEEDS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


_NOT_PLAIN = inspect.CO_GENERATOR | inspect.CO_COROUTINE | inspect.CO_ASYNC_GENERATOR


def _users(fn) -> bool:
    """Whether ``fn`` is a plain function of the user's (not a library's, not a lambda, not a
    generator or coroutine, whose ``yield`` a branch function could not keep)."""
    return type(fn) is types.FunctionType and fn.__name__ != "<lambda>" and \
        not fn.__code__.co_flags & _NOT_PLAIN and \
        not os.path.realpath(fn.__code__.co_filename).startswith(_LIBRARY_DIRS)


def _needs_rewrite(fn) -> bool:
    """Whether ``fn``'s code has control flow to rewrite (a branch, a loop, ``not``, ``with``), or
    calls a function of the user's that has (found by name: a global, a closure variable, an
    attribute of a module of the user's), read from its bytecode: no parse where none is needed."""
    try:
        return _NEEDS[fn]
    except (KeyError, TypeError):
        pass
    _NEEDS[fn] = False  # while deciding: a recursive call adds nothing
    code = fn.__code__
    needed = bool(set(code.co_code[::2]) & _REWRITTEN_OPS) or any(
        _users(callee) and _needs_rewrite(callee) for callee in _callees(fn))
    _NEEDS[fn] = needed
    return needed


def _callees(fn):
    """The objects ``fn``'s code may call by name: its globals and closure variables, and the
    attributes it names of modules of the user's among them."""
    code = fn.__code__
    names = set(code.co_names)
    found = [fn.__globals__[n] for n in names if n in fn.__globals__]
    for cell in fn.__closure__ or ():
        try:
            found.append(cell.cell_contents)
        except ValueError:  # empty
            pass
    for module in [m for m in found if isinstance(m, types.ModuleType)]:
        if not os.path.realpath(getattr(module, "__file__", None) or os.sep).startswith(_LIBRARY_DIRS):
            found += [getattr(module, n) for n in names if n in vars(module)]
    return found


def helper(fn):
    """What a rewritten body calls for ``fn``: a plain function of the user's (not a library's)
    whose code branches, rewritten as written and, if a ``return`` of it may act per lane, made
    an inline helper (the return returns from it, per lane); anything else, ``fn`` itself."""
    if type(fn) is not types.FunctionType or getattr(fn, "__reactor_inline__", None) is not None:
        return fn
    try:
        return _HELPERS[fn]
    except KeyError:
        pass
    made = fn
    if getattr(fn, "__reactor_syntax__", False) or _users(fn) and _needs_rewrite(fn):
        made = as_written(fn, _em.building() and _em.current().module.build.cache)
        if getattr(made, "__reactor_returns__", False):
            made = _inline(made)
    _HELPERS[fn] = made
    return made


def _def_lines(code) -> tuple[list[str], int] | None:
    """The lines of a code object's ``def`` (decorators included) and its first line's number;
    None without source. The block is cut from the file by indentation (a tokenizer, as
    ``inspect`` uses, costs more than the whole rewrite), ``inspect``'s way if that fails."""
    if code is None:
        return None
    lines = linecache.getlines(code.co_filename)
    first = code.co_firstlineno - 1
    if 0 <= first < len(lines):
        indent = len(lines[first]) - len(lines[first].lstrip())
        header = lines[first].lstrip().startswith("@")  # decorators first: the def follows them
        end = first + 1
        while end < len(lines):
            text = lines[end].lstrip()
            deeper = not lines[end].strip() or len(lines[end]) - len(text) > indent or text.startswith((")", "]", "}"))
            if not deeper and not (header and text.startswith(("@", "def ", "async def "))):
                break
            if not deeper:
                header = text.startswith("@")
            end += 1
        return lines[first:end], first + 1
    try:
        block, start = inspect.getsourcelines(code)
    except (OSError, TypeError):
        return None
    return block, start


def _fresh_tree(code) -> ast.FunctionDef | None:
    """The ``def`` of a code object, parsed anew (the rewrite changes it), with the file's line
    numbers; None without source (``inspect``'s way where the cut of :func:`_def_lines` fails)."""
    found = _def_lines(code)
    tree = _parse_def(*found) if found else None
    if tree is not None or code is None:
        return tree
    try:
        block, start = inspect.getsourcelines(code)
    except (OSError, TypeError):
        return None
    return _parse_def(block, start)


def _parse_def(lines: list[str], start: int) -> ast.FunctionDef | None:
    try:
        with AST_LOCK:
            tree = ast.parse("\n" * (start - 1) + textwrap.dedent("".join(lines)))
    except (SyntaxError, IndentationError, ValueError):
        return None
    fn = tree.body[0] if len(tree.body) == 1 else None
    return fn if isinstance(fn, ast.FunctionDef) else None
def inline(fn):
    """``@reactor.inline``: ``fn`` is a helper whose ``return`` (and ``Return``) under per-lane
    control flow returns from it, for the lanes that reach it (``reactor.dsl.inline``), its
    Python control flow as written. A plain helper a body calls is made so by itself where
    it needs to be; decorating says it, and covers calls the rewrite does not see."""
    return _inline(fn, as_written)


def hint(cond, *, max_iterations: int | None = None) -> "Hint":
    """``while hint(cond, max_iterations=N):`` -- a run-time ``while`` (``cond`` a DSL Bool) that
    stops after N iterations, the call then raising ``LoopLimitError`` naming the loop's line,
    as ``While(..., max_iterations=N)`` does (Dr.Jit's ``dr.hint`` spelling). On a Python
    condition, or in an ``if``, it is ``cond`` itself."""
    from .control import _check_max
    return Hint(cond, _check_max(max_iterations))


class Hint:
    """A condition with what :func:`hint` said of its loop."""

    __slots__ = ("cond", "max_iterations")

    def __init__(self, cond, max_iterations: int | None) -> None:
        self.cond, self.max_iterations = cond, max_iterations

    def __bool__(self) -> bool:
        return bool(self.cond)


def _unhinted(cond):
    return cond.cond if isinstance(cond, Hint) else cond


# -- what the rewritten code calls ----------------------------------------------------------------

class _Unset:
    """A name assigned on some paths of a run-time ``if`` only: any use is an error naming it."""

    def __init__(self, name: str, why: str = "") -> None:
        object.__setattr__(self, "_name", name)
        object.__setattr__(self, "_why", why or "is assigned on some paths of a run-time 'if' only: give it a "
                                                "value before the 'if' (or in every branch)")

    def _refuse(self, *args, **kwargs):
        raise DSLTypeError(f"'{self._name}' {self._why}")

    def __getattr__(self, name):
        self._refuse()

    def __repr__(self) -> str:
        return f"<'{self._name}': not set on every path>"


for _op in ("add", "sub", "mul", "truediv", "floordiv", "mod", "pow", "and", "or", "xor", "lshift", "rshift",
            "matmul"):
    setattr(_Unset, f"__{_op}__", _Unset._refuse)
    setattr(_Unset, f"__r{_op}__", _Unset._refuse)
for _op in ("neg", "pos", "abs", "invert", "bool", "float", "int", "index", "lt", "le", "gt", "ge", "eq", "ne",
            "getitem", "iter", "len", "call"):
    setattr(_Unset, f"__{_op}__", _Unset._refuse)

class _Runtime:
    """The functions the rewritten code calls (bound to ``__rt``)."""

    RETURNED = ("returned",)  # what a branch gives when it ended with return: its lanes are done

    @staticmethod
    def call(fn, *args, **kwargs):
        """A call in a rewritten body: a helper of the user's runs as written (its ``if``/``while``
        rewritten; inlined as with ``@reactor.inline`` where a ``return`` may act per lane)."""
        return helper(fn)(*args, **kwargs)

    @staticmethod
    def static(cond) -> bool:
        """Whether ``cond`` is Python's (decided while building) rather than a DSL Bool."""
        cond = _unhinted(cond)
        if isinstance(cond, _Unset):
            cond._refuse()
        return not isinstance(cond, Value)

    @staticmethod
    def current(scope: dict, name: str):
        return scope[name] if name in scope else _Unset(name)

    @staticmethod
    def if_stmt(owner, cond, names, later, before, then_fn, else_fn, outer=None):
        """An ``if``: for a Python condition, the branch it picks, run as Python runs it (the
        names it assigns are what it left); for a DSL one, both traced (:func:`_if_stmt`)."""
        cond = _unhinted(cond)
        if isinstance(cond, _Unset):
            cond._refuse()
        if isinstance(cond, Value):
            return _if_stmt(owner, cond, names, later, before, then_fn, else_fn)
        state = _PythonState(names, before, outer)
        (then_fn if cond else else_fn)(state, *before)
        return tuple(state.values.get(n, old) for n, old in zip(names, before))

    @staticmethod
    def keep(state, name: str, value) -> None:
        state.keep(name, value)

    @staticmethod
    def return_value(owner: str, value) -> None:
        """``return value`` under run-time control flow: from the body being built, or from the
        ``@inline`` helper being traced; a plain helper's cannot be honoured per lane."""
        from .context import body_of
        from .lanes import lanes_of
        code, lanes, body = _OWNERS.get(owner), lanes_of(), body_of()
        if lanes.calls and lanes.calls[-1].code is code:
            Return(value)  # returns from the @inline helper (for the lanes that reach it)
        elif not lanes.calls and body is not None and body.code is code:
            Return(value, body=True)
        else:
            name = owner.rsplit(":", 1)[-1]
            raise ControlFlowError(f"'return' under a run-time condition in '{name}', a helper called from the body, "
                                   f"would return from the body: decorate '{name}' with @reactor.inline (over "
                                   f"@reactor.syntax) so that it returns from '{name}', per lane")
    loop_break = staticmethod(flow.loop_break)
    loop_continue = staticmethod(flow.loop_continue)

    @staticmethod
    def bool_and(first, *rest):
        """``first and rest...``: Python's for Python values (short circuit), ``&`` per lane."""
        value = first
        for thunk in rest:
            if not isinstance(value, Value):
                if not value:
                    return value
                value = thunk()
            else:
                value = value & _Runtime._mask_like(value, thunk())
        return value

    @staticmethod
    def bool_or(first, *rest):
        """``first or rest...``: Python's for Python values (short circuit), ``|`` per lane."""
        value = first
        for thunk in rest:
            if not isinstance(value, Value):
                if value:
                    return value
                value = thunk()
            else:
                value = value | _Runtime._mask_like(value, thunk())
        return value

    @staticmethod
    def _mask_like(mask, other):
        """``other`` as a Bool to combine with the mask ``mask`` (a Python bool: all lanes or none)."""
        if isinstance(other, Value):
            return other
        if isinstance(other, _Unset):
            other._refuse()
        return mask | True if other else mask & False

    @staticmethod
    def bool_not(value):
        if isinstance(value, _Unset):
            value._refuse()
        return ~value if isinstance(value, Value) else not value

    @staticmethod
    def choose(cond, then_thunk, else_thunk):
        """``then if cond else other``: one arm for a Python condition, per lane on a mask."""
        if not isinstance(cond, Value):
            return then_thunk() if cond else else_thunk()
        from .intrinsics import Select
        return Select(cond, then_thunk(), else_thunk())

    @staticmethod
    def counter_after_loop(name: str):
        return _Unset(name, "is the counter of a run-time loop: it has no value after the loop (keep what "
                            "you need in a name assigned in the body)")

    @staticmethod
    def static_range(bounds, leaves_early: bool) -> bool:
        """Whether ``range(*bounds)`` is Python's, unrolled while building: every bound a Python
        int and a body that cannot leave early (a ``return``, ``break`` or ``continue`` may act
        per lane: such a loop runs at run time over the same counts, as GLSL's ``for`` does)."""
        for b in bounds:
            if isinstance(b, _Unset):
                b._refuse()
        return not leaves_early and not any(isinstance(b, Value) for b in bounds)

    @staticmethod
    def while_stmt(owner, first_test, names, later, before, test_fn, body_fn):
        limit = first_test.max_iterations if isinstance(first_test, Hint) else None
        return _loop(owner, names, later, before, lambda state, values: flow.while_begin(
            lambda: _unhinted(test_fn(state, *values())), max_iterations=limit, lane_exits=True), body_fn)

    @staticmethod
    def for_stmt(owner, bounds, names, later, before, body_fn):
        start, stop, step = (0, bounds[0], 1) if len(bounds) == 1 else (bounds[0], bounds[1], 1) \
            if len(bounds) == 2 else bounds
        if not isinstance(step, int) or isinstance(step, bool):
            raise DSLTypeError(f"range(...)'s step must be a Python int in a run-time loop, not {step!r}")
        opened = {}

        def begin(state, values):
            block, opened["i"] = flow.for_begin(start, stop, step, lane_exits=True)
            return block
        return _loop(owner, names, later, before, begin, lambda state, *vals: body_fn(state, opened["i"], *vals))

    @staticmethod
    def with_state(owner, kind: str, complete: bool, names, later, before):
        """Before a run-time ``with`` chain or loop: the state of the names its bodies assign
        (a name with no value before gets a variable only if in ``later``: read after an If chain)."""
        state = _State(owner, names, before, later)
        state.kind, state.complete, state.assigned = kind, complete, set()
        state.entered = False
        return state

    @staticmethod
    def with_branch(state):
        """At the top of a ``with`` body: the names' values there (a loop's: this iteration's)."""
        if state.entered:
            state.branches.append(state.assigned)
        state.assigned, state.entered = set(), True
        if state.kind == "If":
            return tuple(state.before.values())
        return tuple(state.slots[n].value if n in state.slots else old for n, old in state.before.items())

    @staticmethod
    def with_end(state):
        """After a ``with`` chain or loop: what each name holds (see :func:`_if_stmt`, :func:`_loop`)."""
        if state.entered:
            state.branches.append(state.assigned)
        if state.kind != "If":
            return _after_loop(state)
        out = []
        for name, old in state.before.items():
            refused = state.refused(name, "under a run-time condition")
            everywhere = state.complete and all(name in assigned for assigned in state.branches)
            if refused is not None:
                out.append(refused)
            elif name in state.slots and (everywhere or _storable(old) and _usable(old)):
                out.append(state.slots[name].value)
            elif name in state.slots or isinstance(old, _Unset):
                out.append(_Unset(name))
            else:
                out.append(old)
        return tuple(out)

    @staticmethod
    def slotted(state, name: str) -> bool:
        return name in state.slots

    @staticmethod
    def slot_value(state, name: str):
        return state.slots[name].value

    @staticmethod
    def python_loop_exit(what: str) -> None:
        raise ControlFlowError(f"'{what}' under a run-time condition leaves a Python loop, which runs while "
                               f"building: write the loop 'with For(...)' or 'with While(...)' so that it runs "
                               f"per lane")

    @staticmethod
    def check_store(state, obj, target: str) -> None:
        if isinstance(state, _PythonState) and not state.guard:
            return  # under Python's conditions only: Python's mutation
        from .variables import PointerValue, is_variable
        from .vectors import _VecVariable
        if is_variable(obj) or isinstance(obj, (PointerValue, _VecVariable)):
            return
        raise DSLTypeError(f"'{target} = ...' under a run-time condition changes a {type(obj).__name__} for every "
                           f"lane: assign a name instead (it becomes a per-lane variable), or use a Variable")


class _PythonState:
    """The names of an ``if`` on a Python condition, as its branch leaves them. ``guard``: under
    a run-time condition further out (a Python object mutated there changes every lane)."""

    def __init__(self, names, before, outer) -> None:
        self.values: dict = {}
        self.guard: bool = outer is not None and (not isinstance(outer, _PythonState) or outer.guard)

    def keep(self, name: str, value) -> None:
        self.values[name] = value


class _State:
    """The names of one run-time ``if`` or loop. Each name lives in one variable of the function
    (declared at its entry, so it exists on every path), shared by every construct of the body
    that assigns it: an assignment stores there at once, where it runs (per lane under a mask),
    so what a branch assigned before a ``break`` or ``continue`` is not lost."""

    def __init__(self, owner: str, names, before, later=None) -> None:
        from .context import body_of
        body = body_of()
        if body is None:
            raise ControlFlowError("@syntax code runs outside a body being built")
        self.owner, self.shared = owner, body.named
        self.slots: dict = {}  # the names this construct touched -> their variable
        self.objects: dict = {}  # name -> the Python object a branch assigned (it cannot differ per lane)
        self.assigned: set = set()  # names the branch being traced assigned
        self.before = dict(zip(names, before))  # what each name held before the construct
        # the names that may get a variable (None: all): read later, or already one of the body's
        self.fresh: set | None = None if later is None else \
            set(later) | {n for n in names if (owner, n) in self.shared}
        self.kind, self.complete = "", False  # a with block's: "If" or a loop; an If chain with Else
        self.branches: list[set] = []  # a with If chain's: the names each branch ended assigned
        self.entered = False  # a with block's: whether a body began
        for name, old in zip(names, before):
            if (self.fresh is None or name in self.fresh) and _storable(old) and _usable(old):
                self.store(name, old, fresh_if_other_type=True)

    def store(self, name: str, value, fresh_if_other_type: bool = False) -> None:
        key = (self.owner, name)
        slot = self.shared.get(key)
        if slot is not None and fresh_if_other_type and not _same_type(slot, value):
            slot = None  # the name was rebound to another type since: a variable of its own from here
        if slot is None:
            slot = self.shared[key] = _slot_for(name, value)
        self.slots[name] = slot
        try:
            slot.set(value)
        except (DSLTypeError, TypeError) as exc:
            raise DSLTypeError(f"'{name}' is given values of different types under run-time control flow "
                               f"({exc})") from None

    def refused(self, name: str, where: str):
        """What ``name`` holds after the construct if a branch left it unusable (an ``_Unset``
        saying why), else None."""
        if name not in self.objects:
            return None
        obj = self.objects[name]
        if isinstance(obj, _Unset):
            return obj
        return _Unset(name, f"was assigned a {type(obj).__name__} {where} (only numbers and DSL values can "
                            f"differ per lane)")

    def keep(self, name: str, value) -> None:
        self.assigned.add(name)
        old = self.before.get(name)
        if _is_variable(value) and value is old:
            return  # a Variable updated in place (``v += 1``): it is per lane already
        if _is_variable(old):
            raise DSLTypeError(f"'{name} = ...' under a run-time condition rebinds the name of a "
                               f"{type(old).__name__}: write '{name}.set(...)' to change it in the lanes that run "
                               f"this (or drop the Variable and assign the name: it becomes per lane by itself)")
        if isinstance(value, _Unset) or not _storable(value) or not _usable(value):
            self.objects[name] = value  # not storable, or a value of a block that ended in the branch
            return
        self.objects.pop(name, None)
        if self.fresh is None or name in self.slots or name in self.fresh:
            self.store(name, value)


def _same_type(slot, value) -> bool:
    from .variables import per_lane
    if _is_vector(value) or _is_vector(slot):
        return type(slot).__mro__[2] is type(value) if _is_vector(slot) and _is_vector(value) else False
    if isinstance(value, Value):
        return per_lane(value.vtype) == slot.vtype
    kind = "Bool" if isinstance(value, bool) else "Float" if isinstance(value, float) else "Int"
    return slot.vtype.kind.name == kind


def _if_stmt(owner, cond, names, later, before, then_fn, else_fn):
    """Trace both branches of a run-time ``if``; each name then holds, per lane, what that lane's
    branch left in it."""
    state = _State(owner, names, before, later)
    unset: set = set()
    for which, fn in (("then", then_fn), ("else", else_fn)):
        block = flow.if_begin(cond) if which == "then" else flow.else_begin()
        state.assigned = set()
        if fn(state, *before) is not _Runtime.RETURNED:  # a branch that returned leaves nothing to merge
            unset |= {n for n, old in zip(names, before) if n not in state.assigned and n not in state.slots
                      and not _storable(old)}
            unset |= {n for n in names if n not in state.assigned and isinstance(dict(zip(names, before))[n],
                                                                                     _Unset)}
        flow.end(block)
    out = []
    for name, old in zip(names, before):
        refused = state.refused(name, "under a run-time condition")
        if refused is not None:
            out.append(refused)
        elif name in unset:
            out.append(_Unset(name))
        elif name in state.slots:
            out.append(state.slots[name].value)
        else:
            out.append(old)
    return tuple(out)


def _loop(owner, names, later, before, begin, body_fn):
    """A run-time loop: the names its body assigns live in variables declared before it (those
    with a value there), read at the top of each iteration and stored where they are assigned,
    per lane; after the loop each holds its last value (a name first assigned in the body has
    none: the loop may not have run)."""
    state = _State(owner, names, before, later)

    def values():
        return [state.slots[n].value if n in state.slots else old for n, old in zip(names, before)]
    block = begin(state, values)
    state.assigned = set()
    body_fn(state, *values())
    flow.end(block)
    return _after_loop(state)


def _after_loop(state) -> tuple:
    """What each name holds after a run-time loop: its last value, per lane (a name first assigned
    in the body has none: the loop may not have run)."""
    out = []
    for name, old in state.before.items():
        refused = state.refused(name, "in a run-time loop")
        if refused is not None:
            out.append(refused)
        elif name in state.slots and (_storable(old) and _usable(old)):
            out.append(state.slots[name].value)
        elif name in state.slots or isinstance(old, _Unset):
            out.append(_Unset(name, "is first assigned in a run-time loop, which may not run: give it a value "
                                    "before the loop"))
        else:
            out.append(old)
    return tuple(out)


def _is_variable(v) -> bool:
    from .variables import PointerValue, is_variable
    from .vectors import _VecVariable
    return is_variable(v) or isinstance(v, (PointerValue, _VecVariable))


def _storable(v) -> bool:
    """Whether ``v`` can live in a per-lane variable of the rewrite (a Variable is one already)."""
    return (isinstance(v, (bool, numbers.Number, Value)) or _is_vector(v)) and not _is_variable(v)


def _usable(v) -> bool:
    """Whether ``v`` may be used here (a DSL value made inside a block that ended may not)."""
    from ..errors import ScopeError
    try:
        for part in (v._c if _is_vector(v) else [v]):
            if isinstance(part, Value):
                part.ir  # noqa: B018 - raises if its block ended
    except ScopeError:
        return False
    return True


def _is_vector(v) -> bool:
    from .vectors import Vec
    return isinstance(v, Vec)


def _slot_for(name: str, value) -> typing.Any:
    """A variable declared at the function's entry with ``value``'s type (one value per lane in a
    kernel's body), so that it exists on every path."""
    from .lanes import lanes_of
    from .values import value_class
    from .variables import per_lane
    lanes = lanes_of()
    if _is_vector(value):
        from .vectors import entry_vector_variable
        return entry_vector_variable(type(value), name)
    if isinstance(value, Value):
        vtype = per_lane(value.vtype)
    else:
        kind = "Bool" if isinstance(value, bool) else "Float" if isinstance(value, float) else "Int"
        vtype = per_lane(value_class(_kind_type(kind)).vtype)
    return lanes.entry_variable(vtype, False if vtype.kind.category == "bool" else 0, name)


def _kind_type(kind: str):
    from ..ir.types import KINDS, VType
    return VType(KINDS[kind], 1)
