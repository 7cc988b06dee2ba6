"""What a plan is proved on: each input's domain, and the rows a kernel is checked on.

An input's domain is one of

* a **format** (``"unorm8"``, ``"unorm10"``, ``"unorm16"``: every code k as the float32
  ``k / (2^b - 1)``, what GLSL's ``unpackUnorm`` and a UNORM texture give; ``"float16"``: every
  finite half value as float32): finite, enumerated;
* **values** (a list or 1-D array, e.g. a 1024-step gradient, or one number): finite, enumerated;
* a **range** ``Range(lo, hi, samples)`` (or a ``(lo, hi)`` tuple): sampled, uniformly, with both
  ends;
* **rows** ``Rows(x=..., y=...)``: a finite set of *joint* values (one per pixel of a scene, the
  inputs of one element side by side), enumerated as given.

The inputs' domains combine as a Cartesian product (rows are one factor). When every factor is
finite and the product has at most ``max_rows`` elements, the check is **exhaustive**; otherwise
it is a **sample** of ``samples`` rows (finite factors drawn from their values), which the plan
extends with a search around its riskiest rows (``search.py``) and reports as a sample.
"""
from __future__ import annotations

import dataclasses
import math
import typing

import numpy as np

from ..errors import ReactorError

UNORM_BITS = {"unorm8": 8, "unorm10": 10, "unorm16": 16}
MAX_ROWS = 1 << 24  # the largest product checked exhaustively (by default)


@dataclasses.dataclass(frozen=True)
class Range:
    """Values in [lo, hi], sampled (``samples``: None, the plan's sample size)."""

    lo: float
    hi: float
    samples: int | None = None

    def __post_init__(self):
        if not (math.isfinite(self.lo) and math.isfinite(self.hi) and self.lo <= self.hi):
            raise ReactorError(f"Range({self.lo!r}, {self.hi!r}): the ends must be finite, lo <= hi")

    def describe(self) -> str:
        return f"[{self.lo:g}, {self.hi:g}] sampled"


class Rows:
    """Joint values of several inputs (``Rows(x=xs, y=ys)``: element i is (xs[i], ys[i]))."""

    def __init__(self, **columns: typing.Any):
        if not columns:
            raise ReactorError("Rows() needs at least one column: Rows(x=..., y=...)")
        self.columns = {k: np.asarray(v) for k, v in columns.items()}  # (n,) or (n, C) for a vector input
        lengths = {len(v) for v in self.columns.values()}
        if len(lengths) != 1:
            raise ReactorError(f"Rows: every column needs the same length, not {sorted(lengths)}")
        self.size = lengths.pop()

    def describe(self) -> str:
        return f"{self.size:,} rows of ({', '.join(self.columns)})"


@dataclasses.dataclass
class Finite:
    """An enumerated domain: ``values`` (float32 or the input's dtype) and how it was named."""

    values: np.ndarray
    name: str

    def describe(self) -> str:
        return self.name


def format_values(name: str) -> np.ndarray:
    """Every value of the format ``name`` as float32 (see the module docstring)."""
    if name in UNORM_BITS:
        top = (1 << UNORM_BITS[name]) - 1
        return (np.arange(top + 1, dtype=np.float64) / top).astype(np.float32)
    if name == "float16":
        half = np.arange(1 << 16, dtype=np.uint32).astype(np.uint16).view(np.float16)
        return half[np.isfinite(half)].astype(np.float32)
    raise ReactorError(f"unknown input format {name!r}: one of {', '.join(UNORM_BITS)}, float16")


def domain_of(name: str, spec: typing.Any):
    """The domain of input ``name`` from what the user declared (see the module docstring)."""
    if isinstance(spec, (Range, Finite)):
        return spec
    if isinstance(spec, str):
        return Finite(format_values(spec), spec)
    if isinstance(spec, tuple) and len(spec) == 2 and all(isinstance(v, (int, float)) for v in spec):
        return Range(float(spec[0]), float(spec[1]))
    if isinstance(spec, (int, float, np.number)) and not isinstance(spec, bool):
        return Finite(np.array([spec]), f"{spec!r}")
    values = np.asarray(spec)
    if values.ndim == 1 and values.size and values.dtype.kind in "fiub":
        return Finite(np.unique(values), f"{values.size:,} values")
    raise ReactorError(f"input '{name}': a domain is a format ('unorm8', 'unorm10', 'unorm16', 'float16'), "
                       f"a list or 1-D array of values, a number, Range(lo, hi) or (lo, hi), not {spec!r}")


class Check:
    """The rows a plan checks: one array per input (``columns``), and whether that is exhaustive."""

    def __init__(self, columns: dict[str, np.ndarray], exhaustive: bool, description: str):
        self.columns, self.exhaustive, self.description = columns, exhaustive, description
        self.size = len(next(iter(columns.values())))

    def take(self, index: np.ndarray) -> dict[str, np.ndarray]:
        return {k: v[index] for k, v in self.columns.items()}


def rows_to_check(names: list[str], declared: dict[str, typing.Any], samples: int, seed: int,
                  max_rows: int = MAX_ROWS) -> Check:
    """The check rows for the kernel inputs ``names`` (element operands, in order) from the
    declared domains (a Rows value under the key ``"rows"`` gives several at once)."""
    rows = declared.get("rows")
    if rows is not None and not isinstance(rows, Rows):
        raise ReactorError("inputs['rows'] must be a Rows(...) of joint input values")
    joint = set(rows.columns) if rows is not None else set()
    unknown = (set(declared) - {"rows"} | joint) - set(names)
    if unknown:
        raise ReactorError(f"inputs name {', '.join(sorted(unknown))}, which the kernel does not take "
                           f"(its element inputs: {', '.join(names)})")
    factors: list[tuple[list[str], typing.Any]] = []
    if rows is not None:
        factors.append((list(rows.columns), rows))
    for n in names:
        if n in joint:
            continue
        if n not in declared:
            raise ReactorError(f"input '{n}' has no domain: declare it (inputs={{'{n}': 'unorm8'}}, a list of "
                               f"values, a number, or Range(lo, hi))")
        factors.append(([n], domain_of(n, declared[n])))
    finite = all(not isinstance(d, Range) for _, d in factors)
    sizes = [d.size if isinstance(d, Rows) else len(d.values) for _, d in factors if not isinstance(d, Range)]
    total = math.prod(sizes) if finite else None
    description = " x ".join(f"{'/'.join(ns)}: {d.describe()}" for ns, d in factors)
    if finite and total is not None and total <= max_rows:
        grids = np.meshgrid(*[np.arange(s) for s in sizes], indexing="ij")
        return Check(_columns(factors, [g.ravel() for g in grids]), True, f"{description} = {total:,} rows, every one")
    rng = np.random.default_rng(seed)
    declared_counts = [d.samples for _, d in factors if isinstance(d, Range) and d.samples]
    count = max(declared_counts) if declared_counts else samples  # a Range's own sample size wins
    picks: list[np.ndarray] = []
    for _, d in factors:
        if isinstance(d, Range):
            x = rng.uniform(d.lo, d.hi, count).astype(np.float32)
            x[:2] = (d.lo, d.hi)
            picks.append(x)
        else:
            size = d.size if isinstance(d, Rows) else len(d.values)
            picks.append(rng.integers(0, size, count))
    return Check(_columns(factors, picks), False, f"{description}: {count:,} sampled rows")


def _columns(factors, picks) -> dict[str, np.ndarray]:
    columns = {}
    for (names, d), pick in zip(factors, picks):
        if isinstance(d, Range):
            columns[names[0]] = pick
        elif isinstance(d, Rows):
            for n in names:
                columns[n] = d.columns[n][pick]
        else:
            columns[names[0]] = d.values[pick]
    return columns


def hulls(names: list[str], declared: dict[str, typing.Any]) -> dict[str, tuple[float, float, bool]]:
    """Per element input of ``names`` that ``declared`` gives a domain: (lo, hi, nan), every value
    it can take (a Range's ends; a finite domain's least and greatest values, a vector input's over
    its channels; whether a NaN is among them), as an input stores them (the check
    rows are stored as float32 or float16: as each rounds them)."""
    found: dict[str, tuple[float, float, bool]] = {}
    rows = declared.get("rows")
    columns: dict[str, typing.Any] = dict(rows.columns) if isinstance(rows, Rows) else {}
    for n in names:
        if n in columns:
            values = np.asarray(columns[n], np.float64)
        elif n in declared:
            d = domain_of(n, declared[n])
            values = np.array([d.lo, d.hi]) if isinstance(d, Range) else np.asarray(d.values, np.float64)
        else:
            continue
        ok = values[~np.isnan(values)]
        lo, hi = (float(ok.min()), float(ok.max())) if ok.size else (math.inf, -math.inf)
        found[n] = (_stored(lo, min), _stored(hi, max), bool(np.isnan(values).any()))
    return found


def _stored(v: float, pick) -> float:
    """The end ``v``, or as float32 or float16 round it (nearest: monotone, so every stored value of a
    domain lies between its stored ends), the outer of the two (``pick``: min or max)."""
    if not math.isfinite(v):
        return v
    with np.errstate(over="ignore"):
        return pick(v, float(np.float32(v)), float(np.float16(v)))
