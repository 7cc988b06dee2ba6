"""A small arithmetic expression language in one variable ``x``.

Grammar (LolRemez-compatible subset)::

    expr    := term (('+' | '-') term)*
    term    := unary (('*' | '/') unary)*
    unary   := ('+' | '-') unary | power
    power   := primary ('^' unary)?          # right-associative
    primary := NUMBER | 'x' | FUNC '(' expr ')' | '(' expr ')'

so ``-x^2`` is ``-(x^2)`` and ``2^-x^2`` is ``2^(-(x^2))``.  Numbers are
decimal (``3``, ``.5``, ``1e-3``); ``FUNC`` is one of :data:`FUNCTIONS`:
``exp exp2 log log2 sqrt erf abs``, the trigonometric ``sin cos tan asin acos
atan`` (radians) and the hyperbolic ``sinh cosh tanh``, so that the fits of
routines/trig.py are commands too, e.g. ``"(sin(sqrt(x))-sqrt(x))/x^1.5"``.

:func:`parse` never evaluates Python code: it builds a tree of closures that
evaluate with :mod:`mpmath` at the precision current at call time.  Domain
errors (``log(-1)``, ``sqrt(-1)``, negative base to a fractional power)
raise :class:`ValueError`, division by zero raises :class:`ZeroDivisionError`;
``asin``/``acos`` outside [-1, 1] raise :class:`ValueError` too; results are
always real :class:`mpmath.mpf` values.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass

from mpmath import mp, mpf

__all__ = ["FUNCTIONS", "Expression", "ExpressionError", "parse"]

Node = Callable[[mpf], mpf]


class ExpressionError(ValueError):
    """A syntax error in an expression; ``position`` is the 0-based offset."""

    def __init__(self, message: str, text: str, position: int):
        super().__init__(f"{message} at position {position} in {text!r}")
        self.text = text
        self.position = position


def _power(base: mpf, exponent: mpf) -> mpf:
    value = mp.power(base, exponent)
    if not isinstance(value, mpf):
        raise ValueError("negative number to a fractional power")
    return value


def _log(v: mpf) -> mpf:
    if v <= 0:
        raise ValueError("log of a non-positive number")
    return mp.log(v)


def _sqrt(v: mpf) -> mpf:
    if v < 0:
        raise ValueError("sqrt of a negative number")
    return mp.sqrt(v)


def _arc(fn: Callable[[mpf], mpf], name: str) -> Node:
    """asin/acos: a real result only on [-1, 1] (mpmath would go complex outside)."""
    def arc(v: mpf) -> mpf:
        if not -1 <= v <= 1:
            raise ValueError(f"{name} of a number outside [-1, 1]")
        return fn(v)
    arc.__name__ = name
    return arc


FUNCTIONS: dict[str, Node] = {
    "exp": mp.exp,
    "exp2": lambda v: mp.power(2, v),
    "log": _log,
    "log2": lambda v: _log(v) / mp.ln2,
    "sqrt": _sqrt,
    "erf": mp.erf,
    "abs": abs,
    "sin": mp.sin,
    "cos": mp.cos,
    "tan": mp.tan,
    "asin": _arc(mp.asin, "asin"),
    "acos": _arc(mp.acos, "acos"),
    "atan": mp.atan,
    "sinh": mp.sinh,
    "cosh": mp.cosh,
    "tanh": mp.tanh,
}

_TOKEN = re.compile(
    r"\s*(?:(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)"
    r"|(?P<name>[A-Za-z_]\w*)|(?P<op>[-+*/^(),]))"
)


@dataclass(frozen=True)
class Expression:
    """A parsed expression; call it with an ``mpf`` to evaluate at ``x``."""

    text: str
    uses_x: bool
    _node: Node

    def __call__(self, x) -> mpf:
        return self._node(mpf(x))

    def __str__(self) -> str:
        return self.text


def parse(text: str) -> Expression:
    """Parse ``text``; raise :class:`ExpressionError` on any syntax error."""
    return _Parser(text).parse()


class _Parser:
    def __init__(self, text: str):
        self.text = text
        self.tokens: list[tuple[str, str, int]] = []
        pos = 0
        while text[pos:].strip():
            m = _TOKEN.match(text, pos)
            if m is None:
                at = len(text) - len(text[pos:].lstrip())
                raise ExpressionError(f"unexpected character {text[at]!r}", text, at)
            kind = m.lastgroup
            self.tokens.append((kind, m.group(kind), m.start(kind)))
            pos = m.end()
        self.i = 0
        self.uses_x = False

    def error(self, message: str, position: int | None = None) -> ExpressionError:
        if position is None:
            position = self.tokens[self.i][2] if self.i < len(self.tokens) else len(self.text)
        return ExpressionError(message, self.text, position)

    def peek(self) -> str | None:
        return self.tokens[self.i][1] if self.i < len(self.tokens) else None

    def take(self) -> tuple[str, str, int]:
        if self.i >= len(self.tokens):
            raise self.error("unexpected end of expression")
        self.i += 1
        return self.tokens[self.i - 1]

    def parse(self) -> Expression:
        if not self.tokens:
            raise self.error("empty expression", 0)
        node = self.expr()
        if self.i < len(self.tokens):
            _, tok, pos = self.tokens[self.i]
            if tok == ")":
                raise self.error("unbalanced parenthesis: unexpected ')'", pos)
            raise self.error(f"unexpected {tok!r}", pos)
        return Expression(self.text, self.uses_x, node)

    def expr(self) -> Node:
        node = self.term()
        while self.peek() in ("+", "-"):
            op = self.take()[1]
            node = _binary(op, node, self.term())
        return node

    def term(self) -> Node:
        node = self.unary()
        while self.peek() in ("*", "/"):
            op = self.take()[1]
            node = _binary(op, node, self.unary())
        return node

    def unary(self) -> Node:
        if self.peek() in ("+", "-"):
            op = self.take()[1]
            inner = self.unary()
            return inner if op == "+" else (lambda x: -inner(x))
        return self.power()

    def power(self) -> Node:
        base = self.primary()
        if self.peek() == "^":
            self.take()
            return _binary("^", base, self.unary())
        return base

    def primary(self) -> Node:
        kind, tok, pos = self.take()
        if kind == "num":
            return lambda x: mpf(tok)
        if tok == "(":
            node = self.expr()
            self.close(pos)
            return node
        if kind == "name":
            if tok == "x":
                self.uses_x = True
                return lambda x: x
            fn = FUNCTIONS.get(tok)
            if fn is None:
                known = ", ".join(sorted(FUNCTIONS))
                raise self.error(f"unknown name {tok!r} (the variable is 'x'; functions: {known})", pos)
            if self.peek() != "(":
                raise self.error(f"expected '(' after function {tok!r}")
            open_pos = self.take()[2]
            arg = self.expr()
            if self.peek() == ",":
                raise self.error(f"function {tok!r} takes exactly one argument")
            self.close(open_pos)
            return lambda x: fn(arg(x))
        if tok == ")":
            raise self.error("unbalanced parenthesis: unexpected ')'", pos)
        raise self.error(f"unexpected {tok!r}", pos)

    def close(self, open_pos: int) -> None:
        if self.peek() != ")":
            if self.i >= len(self.tokens):
                raise self.error("unbalanced parenthesis: '(' never closed", open_pos)
            raise self.error(f"unexpected {self.peek()!r}, expected ')'")
        self.take()


def _binary(op: str, left: Node, right: Node) -> Node:
    if op == "+":
        return lambda x: left(x) + right(x)
    if op == "-":
        return lambda x: left(x) - right(x)
    if op == "*":
        return lambda x: left(x) * right(x)
    if op == "/":
        return lambda x: left(x) / right(x)
    return lambda x: _power(left(x), right(x))
