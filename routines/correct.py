"""The last step of the faithful and correct tiers evaluated in float64 lanes: round once, and
for the correct tier decide the rare inputs one float64 evaluation cannot from a table.

A routine of these tiers computes ``y``, float64 lanes approximating f(x) with a relative
error below ``ERROR`` (2^-49) for every float32 x with a finite nonzero result, then calls
``finish(x, y, precision, name)``:

* **faithful**: float32 of y. Its error is below 0.5 + 2^-25 ULP-32.
* **correct**: y is rounded from y(1 - ``WINDOW``) and from y(1 + ``WINDOW``). Where both give
  the same float32, every value within 2^-47 of y, f(x) included, rounds to it: it is the
  correctly rounded result. Where they differ, a float32 rounding boundary (a midpoint of two
  floats, or the overflow threshold) lies within ``WINDOW`` + ``ERROR`` < ``NEAR`` of f(x).
  Those inputs are few (about one in 2^21) and known in advance: ``hard_cases/<name>.npy``
  lists every float32 x whose exact f(x) lies within ``NEAR`` (2^-46) relative of a boundary,
  with its correctly rounded result (``python -m routines hardcases``, an exhaustive sweep of
  the correctly rounded reference ``routines.lab.rounding``, mpmath deciding every one of
  them). A failing lane is looked up there by a binary search on its bits.

So the correct tier holds for any evaluation within ``ERROR``, on every target and FMA
setting, with no second, slower evaluation; ``python -m routines ladder --exhaustive`` checks
the compiled code on all 2^32 inputs all the same.
"""
from __future__ import annotations

import functools
import pathlib
import typing

import numpy as np

import reactor
from reactor import Any, As, ConstantTable, If, Precision, Select, Variable, vector_type

#: The evaluation's relative error bound the tables assume.
ERROR = 2.0 ** -49
#: The rounding test's relative half-width: above ``ERROR``.
WINDOW = 2.0 ** -47
#: How near (relative) a boundary an input's exact result must be to be listed: above
#: WINDOW (1 + ERROR) + ERROR.
NEAR = 2.0 ** -46

TABLES = pathlib.Path(__file__).with_name("hard_cases")
_SENTINEL = -(2 ** 31)  # below every key: the search's start


@functools.lru_cache(maxsize=None)
def table(name: str) -> tuple[np.ndarray, np.ndarray]:
    """(inputs, results) of ``name``'s hard cases as int32 bit patterns, inputs sorted as signed
    integers (empty if the file is missing: the correct tier is then not proved)."""
    path = TABLES / f"{name}.npy"
    if not path.exists():
        return np.zeros(0, np.int32), np.zeros(0, np.int32)
    pairs = np.load(path, allow_pickle=False)
    keys, values = pairs[:, 0].astype(np.int32), pairs[:, 1].astype(np.int32)
    order = np.argsort(keys, kind="stable")
    return keys[order], values[order]


@functools.lru_cache(maxsize=None)
def _search_tables(name: str) -> tuple[ConstantTable, ConstantTable, int]:
    """The sorted inputs behind a sentinel and padded to a power of two (greatest int32), the
    results beside them, and the power of two."""
    keys, values = table(name)
    size = 1
    while size < keys.size + 1:
        size *= 2
    padded = np.full(size, 2 ** 31 - 1, np.int32)
    padded[0] = _SENTINEL
    padded[1:keys.size + 1] = keys
    results = np.zeros(size, np.int32)
    results[1:keys.size + 1] = values
    return ConstantTable(padded, reactor.Int), ConstantTable(results, reactor.Int), size


def lookup(x, name: str):
    """(found, result bits): ``name``'s hard-case table searched for x's bit pattern, per lane."""
    Int_ = vector_type("Int", x.width)
    keys, results, size = _search_tables(name)
    key = As(Int_, x)
    at = Int_(0)
    step = size // 2
    while step >= 1:                     # keys[at] <= key throughout (keys[0] is the sentinel)
        probe = at + step
        at = Select(keys[probe] <= key, probe, at)
        step //= 2
    return (keys[at] == key) & (at > 0), results[at]


def finish(x, y, precision: Precision, name: str):
    """f(x) as float32 from its float64 approximation ``y`` (see the module docstring): rounded
    once for ``faithful``, correctly rounded for ``correct``. NaN lanes of y stay NaN."""
    Float_: typing.Any = vector_type("Float", x.width)  # a Variable of it has ``.value``
    if precision is Precision.FAITHFUL:
        return Float_(y)
    lo, hi = Float_(y * (1.0 - WINDOW)), Float_(y * (1.0 + WINDOW))
    result = Variable(Float_, lo)
    hard = (lo != hi) & (lo == lo)       # a NaN lane is not hard
    with If(Any(hard)):
        found, bits = lookup(x, name)
        result.set(Select(hard & found, As(Float_, bits), result))
    return result.value
