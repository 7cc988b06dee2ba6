"""Minimax polynomial fitting (weighted Remez exchange) for float32 routines.

``remez(f, a, b, degree, weight)`` returns the polynomial minimising
``max |p(x) - f(x)| / |w(x)|`` on ``[a, b]`` (LolRemez's convention: the
weight is a tolerance), with exact and binary32-rounded coefficients;
``retune`` nudges binary32 coefficients against a caller-measured error.
"""

from .expr import Expression, ExpressionError, parse
from .fit import RemezError, RemezResult, RetuneResult, evaluate, remez, retune, to_float32

__all__ = [
    "Expression",
    "ExpressionError",
    "RemezError",
    "RemezResult",
    "RetuneResult",
    "evaluate",
    "parse",
    "remez",
    "retune",
    "to_float32",
]
