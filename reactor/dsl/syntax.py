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
import builtins
import dis
import hashlib
import marshal
import os
import sys
import sysconfig
import types
import functools
import inspect
import itertools
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
from .values import Value

RUNTIME_BLOCKS = ("If", "Elif", "Else", "For", "While")
_BUILTIN_NAMES = frozenset(dir(builtins))  # calls left as they are (locals() must stay the caller's)


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


def _users(fn) -> bool:
    """Whether ``fn`` is a plain function of the user's (not a library's, not a lambda)."""
    return type(fn) is types.FunctionType and fn.__name__ != "<lambda>" and \
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
        end = first + 1
        while end < len(lines) and (not lines[end].strip() or len(lines[end]) - len(lines[end].lstrip()) > indent
                                    or lines[end].lstrip().startswith((")", "]", "}"))):
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


class _Expressions(ast.NodeTransformer):
    """Python's expressions that ask for a truth value, made to work on masks too: ``a and b``,
    ``a or b``, ``not a``, ``x if c else y`` and ``a < b < c`` become calls that keep Python's
    meaning (and its short circuit) for Python values and work per lane on DSL Bools (``&``, ``|``,
    ``~``, ``Select``; both arms then computed, as ``Select`` computes them)."""

    def visit_FunctionDef(self, node):
        return node  # another scope

    visit_AsyncFunctionDef = visit_ClassDef = visit_Lambda = visit_FunctionDef

    @staticmethod
    def _thunk(expr) -> ast.Lambda:
        return ast.Lambda(ast.arguments(posonlyargs=[], args=[], kwonlyargs=[], kw_defaults=[], defaults=[]), expr)

    def visit_BoolOp(self, node):
        self.generic_visit(node)
        what = "bool_and" if isinstance(node.op, ast.And) else "bool_or"
        call = _call(what, node.values[0], *[self._thunk(v) for v in node.values[1:]])
        return ast.copy_location(call, node)

    def visit_UnaryOp(self, node):
        self.generic_visit(node)
        if not isinstance(node.op, ast.Not):
            return node
        return ast.copy_location(_call("bool_not", node.operand), node)

    def visit_IfExp(self, node):
        self.generic_visit(node)
        call = _call("choose", node.test, self._thunk(node.body), self._thunk(node.orelse))
        return ast.copy_location(call, node)

    def visit_Call(self, node):
        """``f(...)`` -> ``__rt.call(f, ...)``: a helper of the user's is called as written too."""
        self.generic_visit(node)
        f = node.func
        name = f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else None
        if name in _BUILTIN_NAMES or name in RUNTIME_BLOCKS or isinstance(f, ast.Attribute) and \
                isinstance(f.value, ast.Name) and f.value.id == "__rt":
            return node
        call = ast.Call(ast.Attribute(ast.Name("__rt", ast.Load()), "call", ast.Load()), [f] + node.args,
                        node.keywords)
        return ast.copy_location(call, node)

    def visit_Compare(self, node):
        self.generic_visit(node)
        if len(node.ops) == 1:
            return node
        operands = [node.left] + node.comparators
        pairs = [ast.Compare(_copy(operands[k]), [op], [_copy(operands[k + 1])])
                 for k, op in enumerate(node.ops)]
        call = _call("bool_and", pairs[0], *[self._thunk(pair) for pair in pairs[1:]])
        return ast.copy_location(call, node)


def _own_nodes(node):
    """The nodes of ``node``'s own scope (not of nested functions, lambdas or classes)."""
    for child in ast.iter_child_nodes(node):
        if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda, ast.ClassDef)):
            continue
        yield child, node
        yield from _own_nodes(child)


def _assigned(statements) -> list[str]:
    """Names a list of statements assigns (their own scope), in order of first assignment."""
    names: dict[str, None] = {}
    for stmt in statements:
        for node in itertools.chain([stmt], (n for n, _ in _own_nodes(stmt))):
            if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
                names.setdefault(node.id, None)
            elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                names.setdefault(node.name, None)
            elif isinstance(node, (ast.Import, ast.ImportFrom)):
                for alias in node.names:
                    names.setdefault((alias.asname or alias.name).split(".")[0], None)
    return [n for n in names if not n.startswith("__rx")]


def _with_kind(node) -> str | None:
    """The run-time block a ``with`` statement of one item opens ("If", "For", ...), else None."""
    if not isinstance(node, ast.With) or len(node.items) != 1:
        return None
    expr = node.items[0].context_expr
    f = expr.func if isinstance(expr, ast.Call) else None
    name = f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else None
    return name if name in RUNTIME_BLOCKS else None


def _with_groups(statements):
    """``statements`` with each run-time ``with`` chain (``with If`` and the ``with Elif``/``with
    Else`` right after it; a ``with For``/``While``) as one list."""
    out: list = []
    for stmt in statements:
        kind = _with_kind(stmt)
        if kind in ("Elif", "Else") and out and isinstance(out[-1], list) and out[-1][0][0] == "If" \
                and out[-1][-1][0] != "Else":
            out[-1].append((kind, stmt))
        elif kind is not None:
            out.append([(kind, stmt)])
        else:
            out.append(stmt)
    return out


class _Region(list):
    """The names a run-time branch or loop body assigns, and where they are kept: ``state``, the
    name of its state in the rewritten code; ``inline``: a ``with`` block's body, written in
    place (a branch or loop body of the rewrite is a function of its own, left by ``return``)."""

    def __init__(self, names, state: str = "__rx_st", inline: bool = False) -> None:
        super().__init__(names)
        self.state, self.inline = state, inline


class _SlotLoads(ast.NodeTransformer):
    """In the lambdas of a ``with`` block's call (``While(lambda: v < 1.0)``), each read of a name
    the block assigns reads its variable where the lambda runs (the loop's head)."""

    def __init__(self, names, state: str) -> None:
        self.names, self.state, self.depth = set(names), state, 0

    def visit_Lambda(self, node):
        self.depth += 1
        self.generic_visit(node)
        self.depth -= 1
        return node

    def visit_Name(self, node):
        if self.depth == 0 or node.id not in self.names or not isinstance(node.ctx, ast.Load):
            return node
        st = ast.Name(self.state, ast.Load())
        load = ast.IfExp(_call("slotted", st, ast.Constant(node.id)),
                         _call("slot_value", ast.Name(self.state, ast.Load()), ast.Constant(node.id)), node)
        return ast.copy_location(load, node)


def _def(name: str, params: list[str], body: list) -> ast.FunctionDef:
    """A ``def`` node (the fields every supported Python needs)."""
    fields: dict[str, typing.Any] = dict(
        name=name, args=ast.arguments(posonlyargs=[], args=[ast.arg(p) for p in params], kwonlyargs=[],
                                      kw_defaults=[], defaults=[]),
        body=body, decorator_list=[], returns=None, type_comment=None)
    if "type_params" in ast.FunctionDef._fields:
        fields["type_params"] = []
    return ast.FunctionDef(**fields)


def _copy(node):
    """A deep copy of an AST (its nodes and lists; constants and contexts shared): what
    ``copy.deepcopy`` gives, several times faster."""
    if isinstance(node, list):
        return [_copy(item) for item in node]
    if not isinstance(node, ast.AST) or isinstance(node, ast.expr_context):
        return node
    new = node.__class__.__new__(node.__class__)
    new.__dict__.update({k: _copy(v) for k, v in node.__dict__.items()})
    return new


_LOCATION = ("lineno", "col_offset", "end_lineno", "end_col_offset")


def _located_all(tree):
    """``ast.fix_missing_locations``: each node without a location takes its parent's (one pass,
    without the generic walkers)."""
    stack = [(tree, (1, 0, 1, 0))]
    pop, push = stack.pop, stack.append
    AST = ast.AST
    while stack:
        node, here = pop()
        fields = node.__dict__
        if "lineno" in node._attributes:
            line = fields.get("lineno")
            if line is None:
                fields["lineno"], fields["col_offset"], fields["end_lineno"], fields["end_col_offset"] = here
            else:
                here = (line, fields["col_offset"], fields.get("end_lineno") or line,
                        fields.get("end_col_offset") or 0)
        for value in fields.values():
            if isinstance(value, list):
                for item in value:
                    if isinstance(item, AST):
                        push((item, here))
            elif isinstance(value, AST):
                push((value, here))
    return tree


def _located(node, where):
    """``node`` (new) given ``where``'s source location."""
    return ast.copy_location(node, where)


def _call(name: str, *args) -> ast.Call:
    return ast.Call(ast.Attribute(ast.Name("__rt", ast.Load()), name, ast.Load()), list(args), [])


def _names(names, ctx) -> ast.Tuple:
    return ast.Tuple([ast.Name(n, ctx()) for n in names], ctx())


class _Rewriter:
    """The rewrite of one function. ``region`` is the names a run-time branch or loop body being
    written assigns (None at the function's own level): there each assignment of one of them is
    also kept in its state (``__rt.keep``: stored where it runs), and a ``return`` becomes the
    core's Return, the branch or body ending there. ``loop`` is the innermost loop around, within
    the region: "python" (it runs while building), "run" (a run-time loop: ``break`` and
    ``continue`` become the core's, per lane) or None."""

    def __init__(self, owner: str) -> None:
        self.count = itertools.count()  # numbers the rewritten statements' names
        self.owner = owner  # names this function's variables apart from another's (a helper's)
        self.returns_per_lane = False  # whether a return stands under run-time control flow

    def function(self, tree):
        self.loads = _loads(tree.body)
        new = _def(tree.name, [], self.block(tree.body, None, None, False))
        new.args, new.returns = tree.args, tree.returns
        return ast.copy_location(new, tree)

    def block(self, statements, region, loop, in_with: bool) -> list:
        """``statements`` rewritten (their nodes are changed in place: pass a copy to use them
        twice); ``in_with``: inside a run-time ``with`` block."""
        out: list = []
        for item in _with_groups(statements):
            out.extend(self.with_group(item, region, loop) if isinstance(item, list)
                       else self.statement(item, region, loop, in_with))
        return out or [ast.Pass()]

    def statement(self, stmt, region, loop, in_with) -> list:
        if isinstance(stmt, ast.If):
            return self.if_statement(stmt, region, loop, in_with)
        if isinstance(stmt, ast.While) and not stmt.orelse:
            return self.while_statement(stmt, region, loop, in_with)
        if isinstance(stmt, ast.For) and _range_call(stmt) is not None:
            return self.for_statement(stmt, region, loop, in_with)
        if isinstance(stmt, ast.Return) and (region is not None or in_with):
            return self.leave(stmt, region)
        if isinstance(stmt, (ast.Break, ast.Continue)) and loop == "run":
            what = "loop_break" if isinstance(stmt, ast.Break) else "loop_continue"
            return [ast.copy_location(ast.Expr(_call(what)), stmt)]
        if isinstance(stmt, (ast.Break, ast.Continue)) and loop is None and region is not None:
            word = "break" if isinstance(stmt, ast.Break) else "continue"
            return [ast.copy_location(ast.Expr(_call("python_loop_exit",
                                                                                 ast.Constant(word))), stmt)]
        if isinstance(stmt, (ast.For, ast.AsyncFor)):
            stmt.body = self.keep(region, _target_names(stmt.target), stmt) + \
                self.block(stmt.body, region, "python", in_with)
            stmt.orelse = self.block(stmt.orelse, region, loop, in_with) if stmt.orelse else []
            return [stmt]
        if isinstance(stmt, ast.While):
            stmt.body = self.block(stmt.body, region, "python", in_with)
            stmt.orelse = self.block(stmt.orelse, region, loop, in_with) if stmt.orelse else []
            return [stmt]
        if isinstance(stmt, (ast.With, ast.AsyncWith)):  # not a run-time block's (see with_group)
            bound = [n for item in stmt.items if item.optional_vars is not None
                     for n in _target_names(item.optional_vars)]
            stmt.body = self.keep(region, bound, stmt) + self.block(stmt.body, region, loop, in_with)
            return [stmt]
        if isinstance(stmt, ast.Try):
            for field in ("body", "orelse", "finalbody"):
                setattr(stmt, field, self.block(getattr(stmt, field), region, loop, in_with)
                        if getattr(stmt, field) else [])
            for handler in stmt.handlers:
                handler.body = self.block(handler.body, region, loop, in_with)
            return [stmt]
        if region is None:
            return [stmt]
        if isinstance(stmt, (ast.Import, ast.ImportFrom, ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            bound = [(a.asname or a.name).split(".")[0] for a in stmt.names] \
                if isinstance(stmt, (ast.Import, ast.ImportFrom)) else [stmt.name]
            return [stmt] + self.keep(region, bound, stmt)
        targets = stmt.targets if isinstance(stmt, ast.Assign) else [stmt.target] \
            if isinstance(stmt, (ast.AugAssign, ast.AnnAssign)) and getattr(stmt, "value", None) else []
        state = ast.Name(getattr(region, "state", "__rx_st"), ast.Load())
        guards = [_located(ast.Expr(_call("check_store", state, t.value, ast.Constant(ast.unparse(t)))), stmt)
                  for t in targets if isinstance(t, (ast.Attribute, ast.Subscript))]
        return guards + [stmt] + self.keep(region, [n for t in targets for n in _target_names(t)], stmt)

    def keep(self, region, names, where) -> list:
        """``__rt.keep(state, name, value)`` for the names of ``region`` just assigned."""
        if region is None:
            return []
        state = getattr(region, "state", "__rx_st")
        calls = [ast.Expr(_call("keep", ast.Name(state, ast.Load()), ast.Constant(n), ast.Name(n, ast.Load())))
                 for n in names if n in region]
        return [ast.copy_location(c, where) for c in calls]

    def leave(self, stmt, region) -> list:
        """``return`` at run time: the core's Return (for the lanes that reach it); in a branch or
        loop body, it ends there."""
        self.returns_per_lane = True
        out: list[ast.stmt] = [ast.Expr(_call("return_value", ast.Constant(self.owner),
                                               stmt.value or ast.Constant(None)))]
        if region is not None and not getattr(region, "inline", False):
            out.append(ast.Return(ast.Attribute(ast.Name("__rt", ast.Load()), "RETURNED", ast.Load())))
        return [ast.copy_location(s, stmt) for s in out]

    def with_group(self, group, region, loop) -> list:
        """A run-time ``with`` chain (If, Elif..., Else) or loop (For, While), its bodies written
        in place: the names they assign live in variables as a plain ``if`` or loop's do (state
        ``__rx_wst<k>``), each body starts from the values before (a loop body: this iteration's),
        and after the chain or loop each name holds what the lanes left in it."""
        k = next(self.count)
        state, kind = f"__rx_wst{k}", group[0][0]
        bound = [n for _, w in group if w.items[0].optional_vars is not None
                 for n in _target_names(w.items[0].optional_vars)]
        names = [n for n in _assigned([s for _, w in group for s in w.body]) if n not in bound]
        bodies = [s for _, w in group for s in w.body]
        later = self.later(names, bodies, None if kind == "If" else bodies)
        inner = _Region(names, state, inline=True)
        first = group[0][1]
        begin = ast.Assign([ast.Name(state, ast.Store())], _call(
            "with_state", ast.Constant(self.owner), ast.Constant(kind), ast.Constant(group[-1][0] == "Else"),
            ast.Tuple([ast.Constant(n) for n in names], ast.Load()), ast.Tuple([ast.Constant(n) for n in later],
                                                                               ast.Load()),
            ast.Tuple([_call("current", _call_locals(), ast.Constant(n)) for n in names], ast.Load())))
        out: list[ast.stmt] = [_located(begin, first)]
        for which, w in group:
            item = w.items[0]
            item.context_expr = _SlotLoads(names, state).visit(item.context_expr)
            branch = _call("with_branch", ast.Name(state, ast.Load()))
            start = ast.Assign([_names(names, ast.Store)], branch) if names else ast.Expr(branch)
            inner_loop = "run" if kind != "If" or loop == "run" else None
            w.body = self.keep(region, bound, w) + [_located(start, w)] + self.block(w.body, inner, inner_loop, True)
            out.append(w)
        end = _call("with_end", ast.Name(state, ast.Load()))
        out.append(_located(ast.Assign([_names(names, ast.Store)], end) if names else ast.Expr(end), group[-1][1]))
        return out + self.keep(region, names, first)

    def later(self, names, inside: list, loop_body: list | None = None) -> list[str]:
        """Of ``names`` (assigned in the statements ``inside``), those that need a variable: read
        elsewhere in the function, or (a loop's) carried from one iteration to the next. The
        others are only used where they are assigned: no variable, no store per lane."""
        counts = _loads(inside)
        needed = {n for n in names if self.loads.get(n, 0) > counts.get(n, 0)}
        if loop_body is not None:
            needed |= _carried(loop_body)
        return [n for n in names if n in needed]

    def run_time(self, stmt, region, kind: str, test_name: str, names: list, fns: list, later: list,
                 extra=(), last=()) -> list:
        """The run-time path: the nested functions, then ``names = __rt.<kind>_stmt(...)`` and what
        it left kept in the region around."""
        before = ast.Tuple([_call("current", _call_locals(), ast.Constant(n)) for n in names], ast.Load())
        merge = _call(f"{kind}_stmt", ast.Constant(self.owner), ast.Name(test_name, ast.Load()), *extra,
                      ast.Tuple([ast.Constant(n) for n in names], ast.Load()),
                      ast.Tuple([ast.Constant(n) for n in later], ast.Load()), before,
                      *[ast.Name(f.name, ast.Load()) for f in fns], *last)
        out: list[ast.stmt] = list(fns)
        out.append(ast.Assign([_names(names, ast.Store)], merge) if names else ast.Expr(merge))
        return out + self.keep(region, names, stmt)

    def if_statement(self, stmt: ast.If, region, loop, in_with) -> list:
        """``if test:`` -- its branches as functions, called for a Python test as Python would
        (one of them) and traced both for a DSL one; a branch that can leave (``return``,
        ``break``, ``continue``) also keeps a copy written in place for a Python test."""
        k = next(self.count)
        cond = f"__rx_cond{k}"
        names = _assigned(stmt.body + stmt.orelse)
        later = self.later(names, stmt.body + stmt.orelse)
        leaves = _leaves_early(stmt.body + stmt.orelse)
        then_copy, else_copy = (_copy(stmt.body), _copy(stmt.orelse)) if leaves else (stmt.body, stmt.orelse)
        static = ast.If(ast.Name(cond, ast.Load()), self.block(stmt.body, region, loop, in_with),
                        self.block(stmt.orelse, region, loop, in_with) if stmt.orelse else []) if leaves else None
        fns = [_def(f"__rx_{which}{k}", ["__rx_st"] + names,
                    self.block(body, names, "run" if loop == "run" else None, in_with) if body else [ast.Pass()])
               for which, body in (("then", then_copy), ("else", else_copy))]
        outer = ast.Name(getattr(region, "state", "__rx_st"), ast.Load()) if region is not None else ast.Constant(None)
        run = self.run_time(stmt, region, "if", cond, names, fns, later, last=(outer,))
        out: list[ast.stmt] = [ast.Assign([ast.Name(cond, ast.Store())], stmt.test)]
        out += [ast.If(_call("static", ast.Name(cond, ast.Load())), [typing.cast(ast.stmt, static)], run)] \
            if leaves else run
        return [ast.copy_location(s, stmt) for s in out]

    def while_statement(self, stmt: ast.While, region, loop, in_with) -> list:
        """``while test:`` -- Python's loop while ``test`` is a Python value, else a run-time loop
        whose names assigned in the body are carried from one iteration to the next per lane."""
        k = next(self.count)
        cond, first = f"__rx_cond{k}", f"__rx_first{k}"
        names = _assigned(stmt.body)
        test = ast.Expr(stmt.test)  # read at every iteration: what it reads is carried
        later = self.later(names, stmt.body + [test], [test] + stmt.body)
        body_copy = _copy(stmt.body)
        # Python's own loop, the test evaluated once per iteration (continue included)
        static = [ast.Assign([ast.Name(first, ast.Store())], ast.Constant(True)),
                  ast.While(ast.Constant(True), [
                      ast.If(ast.UnaryOp(ast.Not(), ast.Name(first, ast.Load())),
                             [ast.Assign([ast.Name(cond, ast.Store())], _copy(stmt.test))], []),
                      ast.Assign([ast.Name(first, ast.Store())], ast.Constant(False)),
                      ast.If(ast.UnaryOp(ast.Not(), ast.Name(cond, ast.Load())), [ast.Break()], []),
                  ] + self.block(stmt.body, region, "python", in_with), [])]
        fns = [_def(f"__rx_test{k}", ["__rx_st"] + names, [ast.Return(_copy(stmt.test))]),
               _def(f"__rx_body{k}", ["__rx_st"] + names, self.block(body_copy, names, "run", in_with))]
        out = [ast.Assign([ast.Name(cond, ast.Store())], stmt.test),
               ast.If(_call("static", ast.Name(cond, ast.Load())), static,
                      self.run_time(stmt, region, "while", cond, names, fns, later))]
        return [ast.copy_location(s, stmt) for s in out]

    def for_statement(self, stmt: ast.For, region, loop, in_with) -> list:
        """``for i in range(...)`` -- Python's loop over Python ints, else a run-time For (its
        counter per lane where a bound is)."""
        k = next(self.count)
        bounds = f"__rx_range{k}"
        target = typing.cast(ast.Name, stmt.target).id
        call = typing.cast(ast.Call, _range_call(stmt))
        names = [n for n in _assigned(stmt.body) if n != target]
        later = self.later(names, stmt.body, stmt.body)
        leaves = _leaves_early(stmt.body)
        body_copy = stmt.body if leaves else _copy(stmt.body)  # a loop that can leave early is never Python's
        static = ast.For(ast.Name(target, ast.Store()),
                         ast.Call(ast.Name("range", ast.Load()), [ast.Starred(ast.Name(bounds, ast.Load()),
                                                                              ast.Load())], []),
                         [ast.Pass()] if leaves else
                         self.keep(region, [target], stmt) + self.block(stmt.body, region, "python", in_with), [])
        fns = [_def(f"__rx_body{k}", ["__rx_st", target] + names, self.block(body_copy, names, "run", in_with))]
        gone = ast.Assign([ast.Name(target, ast.Store())], _call("counter_after_loop", ast.Constant(target)))
        exits = ast.Constant(leaves)
        out = [ast.Assign([ast.Name(bounds, ast.Store())], ast.Tuple(call.args, ast.Load())),
               ast.If(_call("static_range", ast.Name(bounds, ast.Load()), exits), [static],
                      self.run_time(stmt, region, "for", bounds, names, fns, later) + [gone]
                      + self.keep(region, [target], stmt))]
        return [ast.copy_location(s, stmt) for s in out]


def _range_call(stmt: ast.For) -> ast.Call | None:
    """The ``range(...)`` call of ``for name in range(...):`` (no else, no keywords), else None."""
    it = stmt.iter
    if (isinstance(it, ast.Call) and isinstance(it.func, ast.Name) and it.func.id == "range" and not it.keywords
            and 1 <= len(it.args) <= 3 and not any(isinstance(a, ast.Starred) for a in it.args)
            and isinstance(stmt.target, ast.Name) and not stmt.orelse):
        return it
    return None


def _leaves_early(statements, nested: bool = False) -> bool:
    """Whether a loop body can leave its loop early: a ``return``, or a ``break``/``continue`` of
    its own (``nested``: inside a loop of the body, where only a ``return`` leaves this one)."""
    for stmt in statements:
        if isinstance(stmt, ast.Return) or isinstance(stmt, (ast.Break, ast.Continue)) and not nested:
            return True
        if isinstance(stmt, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            continue
        inner_nested = nested or isinstance(stmt, (ast.For, ast.AsyncFor, ast.While))
        for field in ("body", "orelse", "finalbody", "handlers"):
            inner = getattr(stmt, field, None) or []
            if field == "handlers":
                inner = [s for h in inner for s in h.body]
            if _leaves_early(inner, inner_nested):
                return True
    return False


def _loads(statements) -> dict[str, int]:
    """How many times each name is read in ``statements`` (nested scopes included)."""
    counts: dict[str, int] = {}
    stack = list(statements)
    Name, AugAssign, Load, AST = ast.Name, ast.AugAssign, ast.Load, ast.AST
    while stack:
        node = stack.pop()
        if type(node) is Name:
            if type(node.ctx) is Load:
                counts[node.id] = counts.get(node.id, 0) + 1
            continue
        if type(node) is AugAssign and type(node.target) is Name:  # reads it first
            counts[node.target.id] = counts.get(node.target.id, 0) + 1
        for value in node.__dict__.values():
            if isinstance(value, list):
                stack.extend(item for item in value if isinstance(item, AST))
            elif isinstance(value, AST):
                stack.append(value)
    return counts


def _carried(statements) -> set[str]:
    """The names a loop body reads before it assigns them on every path (at its top level): what
    one iteration hands the next."""
    assigned: set[str] = set()
    carried: set[str] = set()
    for stmt in statements:
        carried |= set(_loads([stmt])) - assigned
        if isinstance(stmt, ast.Assign):
            assigned.update(n for t in stmt.targets for n in _target_names(t))
        elif isinstance(stmt, ast.AnnAssign) and stmt.value is not None:
            assigned.update(_target_names(stmt.target))
    return carried


def _target_names(target) -> list[str]:
    """The names an assignment target binds (``a``, ``a, (b, c)``, ``*rest``)."""
    if isinstance(target, ast.Name):
        return [target.id]
    if isinstance(target, (ast.Tuple, ast.List)):
        return [n for t in target.elts for n in _target_names(t)]
    if isinstance(target, ast.Starred):
        return _target_names(target.value)
    return []


def _call_locals() -> ast.Call:
    return ast.Call(ast.Name("locals", ast.Load()), [], [])


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
