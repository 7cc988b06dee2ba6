"""pow(x, y) = exp2(y * log2(x)), with IEEE 754 ``powr`` semantics.

``powr`` is what a shader's pow means (GLSL/SPIR-V define pow through
exp2(y * log2(x)) and leave x < 0 undefined). The specials need no extra code:
they follow from log2's and exp2's own specials through the product:

    x < 0 (incl. -inf)          NaN           log2(x) = NaN
    ±0 ^ y>0, ±0 ^ +inf         +0            y * -inf = -inf, exp2(-inf) = +0
    ±0 ^ y<0, ±0 ^ -inf         +inf          y * -inf = +inf
    ±0 ^ ±0                     NaN           0 * -inf
    +inf ^ y>0                  +inf
    +inf ^ y<0                  +0
    +inf ^ ±0                   NaN           0 * inf
    1 ^ finite y                1 exactly     log2(1) = 0, exp2(0) = 1
    1 ^ ±inf                    NaN           inf * 0
    finite x > 0 ^ ±0           1
    x in (0,1) ^ +inf, x>1 ^ -inf   +0
    x in (0,1) ^ -inf, x>1 ^ +inf   +inf
    NaN in either argument      NaN           (powr: even 1^NaN and NaN^0)

NaN bits (``base.nan_rule``, the same on every target): a NaN x gives x quieted, then x < 0
gives the default NaN 0xffc00000, then a NaN y gives y quieted; every other NaN above (0 * inf)
is the default NaN.

Accuracy: Vulkan inherits pow's tolerance from exp2(y * log2(x)); see
docs/accuracy.md for the derivation used by the accuracy lab.
"""
from __future__ import annotations

import math

import reactor
from reactor import Precision

from . import accurate, continuum
from .base import float_value, nan_rule, routine
from .exponential import exp2
from .logarithm import log2


#: Whole-number constant exponents computed by multiplication (as Dr.Jit and compilers do), those
#: whose chains stay within the full-precision tolerance (3 ULP + 2|y log2 x|) with margin, x near 1
#: included (6M samples, 2M of them in 1 +- 1e-3): max error 0.5 / 1.28 / 1.89 / 2.91 / 3.43 ULP for
#: y = 2..6, min margin 0.89 ULP (y = 6); 1/x^2: 4.2 ULP, margin 1.6. From y = -3 down the margin goes
#: (y = -5: -0.9), so those take exp2(y log2 x).
WHOLE_EXPONENTS = range(-2, 7)


def _whole_power(x, n: int):
    """|x|^n by multiplications (n != 0), NaN for x < 0 (powr): the specials come out as pow's."""
    a = reactor.Abs(x)
    result: reactor.Value | None = None
    base, k = a, abs(n)
    while k:
        if k & 1:
            result = base if result is None else result * base
        k >>= 1
        if k:
            base = base * base
    assert result is not None  # n != 0
    if n < 0:
        result = 1.0 / result
    return reactor.Select(x < 0.0, float("nan"), result)


@routine
def pow(x, y, precision: Precision = Precision.FULL):  # noqa: A001 - the routine's public name
    """x^y with powr semantics; x and y are Float values (a scalar broadcasts). A constant
    whole-number ``y`` in ``WHOLE_EXPONENTS`` (``pow(x, 5.0)``) is a chain of multiplications."""
    x = float_value(x, "pow", "x")
    if precision in (Precision.FAITHFUL, Precision.CORRECT):
        return accurate.pow(x, float_value(y, "pow", "y"), precision).named("pow")
    if isinstance(y, (int, float)) and not isinstance(y, bool) and float(y).is_integer() \
            and int(y) in WHOLE_EXPONENTS and int(y) != 0:
        return _whole_power(x, int(y)).named("pow")
    y = float_value(y, "pow", "y")
    rx, ry = continuum.operand_range("pow", 0), continuum.operand_range("pow", 1)  # a plan's proved ranges
    with continuum.operand_ranges("log2", (rx,) if rx else None):
        lx = log2(x, precision=precision)                  # NaN for a NaN x (quieted) or x < 0 (0xffc00000)
    t = y * lx
    if not (rx is not None and rx.within(0.0, math.inf)):  # where x is proved >= 0 and no NaN, lx is no NaN
        t = reactor.Select(reactor.IsNan(lx), lx, t)       # x's NaN first, whatever order the multiply has
    with continuum.operand_ranges("exp2", continuum.product_of_log2(rx, ry)):
        return nan_rule(exp2(t, precision=precision), lx, y).named("pow")


reactor.set_power(pow)  # x ** y in the DSL, for a y other than a small whole number
