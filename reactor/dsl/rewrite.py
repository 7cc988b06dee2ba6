"""The rewrite of a function's syntax tree that :mod:`reactor.dsl.syntax` compiles: expressions that
ask for a truth value made to work on masks (``_Expressions``), and ``if``/``while``/``for``/``with``
statements made into calls of the run time (``_Rewriter``: ``__rt.<name>(...)``, see
``reactor.dsl.syntax._Runtime``), with the analyses they need (names assigned, read, carried by a
loop; exits of a loop body). Pure functions of the tree: nothing here runs user code."""
from __future__ import annotations

import ast
import builtins
import itertools
import typing

from ..source import RUNTIME_BLOCKS

_BUILTIN_NAMES = frozenset(dir(builtins))  # calls left as they are (locals() must stay the caller's)


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
