"""``python -m routines remez``: a LolRemez-compatible command line for :func:`routines.remez.remez`.

Example::

    python -m routines remez -d 4 -r "0:1" "(2^x-x-1)/x" "1/x"

prints LolRemez's comment header, the polynomial in Horner form with the
exact coefficients to 8 significant digits (as LolRemez prints them), the
achieved maximum weighted error and a C function with the coefficients
correctly rounded to binary32.  ``--json`` prints a JSON object instead.

Exit status: 0 on success, 1 if the fit fails (:class:`RemezError`), 2 on
invalid input (bad option, expression, range or degree).
"""

from __future__ import annotations

import argparse
import json
import sys

import numpy as np
from mpmath import mp, mpf

from ..cli import ArgumentParser, int_type, positive_int
from .expr import Expression, ExpressionError, parse
from .fit import RemezError, RemezResult, remez


class _UsageError(Exception):
    """Invalid command-line input (exit status 2)."""


def _checked(parse, what: str):
    """An argparse type: ``parse`` (a :mod:`routines.cli` type) with the message naming ``what``."""
    def check(text: str):
        try:
            return parse(text)
        except argparse.ArgumentTypeError as exc:
            if str(exc).startswith("invalid int value"):
                raise
            rule = str(exc).rsplit(", not ", 1)[0]  # "must be a positive integer"
            raise argparse.ArgumentTypeError(f"invalid {what} {text.strip()}: {rule}") from None
    check.__name__ = parse.__name__
    return check


def _parser() -> argparse.ArgumentParser:
    p = ArgumentParser(
        prog="python -m routines remez",
        description="Minimax polynomial approximation of f(x) on [xmin, xmax], "
        "minimising max |p(x) - f(x)| / |g(x)| (g is a tolerance, as in LolRemez).",
        examples=['python -m routines remez -d 4 -r "0:1" "(2^x-x-1)/x" "1/x"',
                  'python -m routines remez -d 2 -r "-0.5:0.5" "exp(x)" --json',
                  'python -m routines remez -d 5 -r "0:1" "log2(1+x)/x" --dps 60',
                  'python -m routines remez -d 2 -r "0:0.64" "(sin(sqrt(x))-sqrt(x))/x^1.5" "sin(sqrt(x))/x^1.5"'],
        epilog="Expressions use x, numbers, + - * / ^ ( ) and exp exp2 log log2 sqrt erf abs\n"
        "sin cos tan asin acos atan sinh cosh tanh (radians);\n"
        "put -- before an expression that starts with '-'.",
    )
    p.add_argument("-d", "--degree", type=_checked(positive_int, "degree"), default=4,
                   help="degree of the polynomial (default 4)")
    p.add_argument("-r", "--range", default="-1:1", metavar="XMIN:XMAX", help="interval (default -1:1)")
    p.add_argument("--float", action="store_true", help="accepted for LolRemez compatibility (output is binary32)")
    p.add_argument("--json", action="store_true", help="print a JSON object instead of C code")
    p.add_argument("--dps", type=_checked(int_type(15), "precision --dps"), default=50,
                   help="working precision in decimal digits, at least 15 (default 50)")
    p.add_argument("function", help="f(x) to approximate")
    p.add_argument("weight", nargs="?", help="tolerance g(x) (default 1)")
    return p


def _expression(text: str, what: str) -> Expression:
    try:
        return parse(text)
    except ExpressionError as exc:
        caret = f"\n  {exc.text}\n  {' ' * exc.position}^"
        raise _UsageError(f"invalid {what}: {exc}{caret}") from exc


def _bound(text: str, what: str) -> mpf:
    expr = _expression(text.strip(), f"range {what}")
    if expr.uses_x:
        raise _UsageError(f"invalid range: {what} {text.strip()!r} must be a constant")
    try:
        value = expr(0)
    except (ArithmeticError, ValueError) as exc:
        raise _UsageError(f"invalid range: cannot evaluate {what} {text.strip()!r}: {str(exc) or type(exc).__name__}") from exc
    if not mp.isfinite(value):
        raise _UsageError(f"invalid range: {what} {text.strip()!r} is not finite")
    return value


def _number(text: str) -> str:
    """``1.8964611e-03`` -> LolRemez's style ``1.8964611e-3``; no exponent for ``e+00``."""
    mantissa, exponent = text.split("e")
    return mantissa if int(exponent) == 0 else f"{mantissa}e{int(exponent):+d}"


def _exact(c: mpf) -> str:
    """``c`` to 8 significant digits, as LolRemez prints with ``--float``."""
    return mp.nstr(c, 8, min_fixed=0, max_fixed=1)


def _float32(c: np.float32) -> str:
    """Shortest round-trip digits of a binary32 value."""
    return _number(np.format_float_scientific(c, unique=True, trim="0"))


def _text(args: argparse.Namespace, xmin: str, xmax: str, r: RemezResult) -> str:
    coeffs = r.highest_first
    d = r.degree
    horner = "(" * (d - 1) + _exact(coeffs[0])
    for j, c in enumerate(coeffs[1:], start=1):
        horner += (")" if j > 1 else "") + "*x" + ("+" if c >= 0 else "") + _exact(c)
    lines = [f"// Approximation of f(x) = {args.function}"]
    if args.weight is not None:
        lines.append(f"// with weight function g(x) = {args.weight}")
    lines += [
        f"// on interval [ {xmin}, {xmax} ]",
        f"// with a polynomial of degree {d}.",
        f"// p(x)={horner}",
        f"// Max weighted error: {_exact(r.max_error)}",
        "float f(float x)",
        "{",
    ]
    lits = [_float32(c) for c in r.float32[::-1]]
    lines.append(f"    float u = {lits[0]}f;")
    lines += [f"    u = u * x + {c}f;" for c in lits[1:-1]]
    lines += [f"    return u * x + {lits[-1]}f;", "}"]
    return "\n".join(lines)


def _json(args: argparse.Namespace, r: RemezResult) -> str:
    return json.dumps(
        {
            "function": args.function,
            "weight": args.weight,
            "interval": [float(v) for v in r.interval],
            "degree": r.degree,
            "coefficients": list(r.float32_strings[::-1]),
            "coefficients_exact": [mp.nstr(c, 30) for c in r.highest_first],
            "error": float(r.max_error),
            "iterations": r.iterations,
            "reference": [float(x) for x in r.reference],
        },
        indent=2,
    )


def main(argv: list[str]) -> int:
    """Run the command on ``argv`` (without the program name); return the exit status."""
    # "-r -0.5:0.5" would make argparse take "-0.5:0.5" for an option.
    argv = list(argv)
    for i, arg in enumerate(argv[:-1]):
        if arg in ("-r", "--range"):
            argv[i : i + 2] = [f"--range={argv[i + 1]}"]
            break
    try:
        args = _parser().parse_args(argv)
    except SystemExit as exc:
        return int(exc.code or 0)
    try:
        parts = args.range.split(":")
        if len(parts) != 2:
            raise _UsageError(f"invalid range {args.range!r}: expected XMIN:XMAX")
        f = _expression(args.function, "function")
        w = None if args.weight is None else _expression(args.weight, "weight function")
        with mp.workdps(args.dps):
            xmin, xmax = _bound(parts[0], "xmin"), _bound(parts[1], "xmax")
        if not xmin < xmax:
            raise _UsageError(f"invalid range {args.range!r}: xmin must be less than xmax")
        result = remez(f, xmin, xmax, args.degree, w, dps=args.dps)
    except _UsageError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except RemezError as exc:
        print(f"error: fit failed: {exc}", file=sys.stderr)
        return 1
    print(_json(args, result) if args.json else _text(args, parts[0].strip(), parts[1].strip(), result))
    return 0
