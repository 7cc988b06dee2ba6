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

Accuracy: Vulkan inherits pow's tolerance from exp2(y * log2(x)); see
docs/accuracy.md for the derivation used by the accuracy lab.
"""
from __future__ import annotations

import reactor
from reactor import Precision

from .base import float_value, routine
from .exponential import exp2
from .logarithm import log2


@routine
def pow(x, y, precision: Precision = Precision.FULL):  # noqa: A001 - the routine's public name
    """x^y with powr semantics; x and y are Float values (a scalar broadcasts)."""
    x = float_value(x, "pow", "x")
    y = float_value(y, "pow", "y")
    return exp2(y * log2(x, precision=precision), precision=precision).named("pow")


reactor.set_power(pow)  # x ** y in the DSL, for a y other than a small whole number
