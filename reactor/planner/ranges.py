"""What each call site sees: the range of its operands over the rows a plan is checked on.

For a site (the user's line, a routine), a probe kernel is built from the same body and settings as
the reference: at that site (``reactor.site_probe``, which the routine library calls with each
call's operands) it folds every operand into three per-lane variables, the least and the greatest
non-NaN value and whether a NaN came, and returns them instead of the body's result. Lanes where
the site does not run (a branch not taken for that element, a loop that ended) keep +inf / -inf, so
a site inside an ``if`` sees only the elements that take it, and one inside a loop every iteration.
Run on the check rows, the probes give each operand's exact range over them: a proof over the
domain when the check is exhaustive, a measurement on the sample otherwise. They are the
reference build's values (a site below full upstream may move a value by a few ULP).
"""
from __future__ import annotations

import dataclasses
import inspect
import math

import numpy as np

from ..dsl.calls import probing

#: operands a site can have (pow and atan2: two)
MAX_OPERANDS = 2
_UNKNOWN = 2.0  # the "nan" variable's value where an operand was not a Float of the body's width


@dataclasses.dataclass(frozen=True)
class OperandRange:
    """An operand's values at a site over the check rows: [lo, hi] of the non-NaN ones (``seen``:
    whether any row reached the site), ``nan``: whether a NaN came; ``known``: False where the
    operand is not a per-lane Float (a vector, a table), which the probe does not follow."""

    lo: float
    hi: float
    nan: bool
    seen: bool
    known: bool = True

    @property
    def unbounded(self) -> bool:
        """Whether it says nothing (any value, NaN included)."""
        return self.lo == -math.inf and self.hi == math.inf and self.nan

    def widened(self) -> OperandRange:
        """A little wider (2^-20 relative, zero kept): measured on the reference build, a range
        moves by a few ULP where a site upstream is planned below it."""
        def out(v, up):
            return v * (1 + 2 ** -20) if (v > 0) == up else v * (1 - 2 ** -20)
        return dataclasses.replace(self, lo=out(self.lo, False), hi=out(self.hi, True))

    def holds(self, other: OperandRange) -> bool:
        """Whether every value ``other`` saw lies in this range (a bound checked on rows run)."""
        if not (self.known and other.known) or not other.seen:
            return True
        inside = other.lo > other.hi or (self.lo <= other.lo and other.hi <= self.hi)
        return inside and (self.nan or not other.nan)

    def text(self) -> str:
        if not self.known:
            return "?"
        if not self.seen:
            return "never reached"
        span = f"{_g(self.lo)}" if self.lo == self.hi else f"[{_g(self.lo)}, {_g(self.hi)}]"
        return span + (" and NaN" if self.nan else "")


def _g(v: float) -> str:
    return f"{v:.9g}" if math.isfinite(v) else ("inf" if v > 0 else "-inf")


def probe_body(body, where: str, routine: str, width: int):
    """``body`` with the same parameters, returning (lo, hi, nan) per operand of ``routine`` at
    ``where`` (see the module docstring)."""
    def probe(*params):
        from ..dsl.intrinsics import IsNan, Max, Min, Select
        from ..dsl.values import Value, vector_type
        from ..dsl.variables import Variable
        float_ = vector_type("Float", width)
        slots = [(Variable(float_, math.inf), Variable(float_, -math.inf), Variable(float_, 0.0))
                 for _ in range(MAX_OPERANDS)]

        def record(args):
            for k, a in enumerate(args[:MAX_OPERANDS]):
                lo, hi, nan = slots[k]
                if isinstance(a, (int, float)) and not isinstance(a, bool):
                    a = float_(float(a))
                if not isinstance(a, Value) or a.kind.name != "Float" or a.width not in (1, width):
                    nan.set(_UNKNOWN)
                    continue
                a = a if a.width == width else float_(a)
                bad = IsNan(a)
                lo.set(Select(bad, lo.value, Min(lo.value, a)))
                hi.set(Select(bad, hi.value, Max(hi.value, a)))
                nan.set(Max(nan.value, Select(bad, 1.0, 0.0)))
        with probing(where, routine, record):
            body(*params)
        return tuple(v.value for slot in slots for v in slot)
    setattr(probe, "__signature__", inspect.signature(body))  # the body's parameter names
    probe.__name__ = f"{getattr(body, '__name__', 'body')}_probe"
    return probe


def site_ranges(search) -> dict[tuple[str, str], tuple[OperandRange, ...]]:
    """Per site of ``search`` (a ``search.Search``): its operands' ranges over the check rows."""
    from ..dsl.values import vector_type
    from ..kernels.kernel import build_kernel
    Float = vector_type("Float", 1)
    k = search.kernel
    b = k.build
    found = {}
    for where, routine in search.sites:
        ufunc = build_kernel(probe_body(k.body, where, routine, b.width), name=f"{k.name}_probe",
                             args=list(k.signature.params), returns=tuple([Float] * (3 * MAX_OPERANDS)),
                             fma=b.fma if search.fma is None else search.fma, width=b.width, opt=b.opt,
                             target=b.target.name, cache=b.cache, precision=search.top,
                             sites=search.pinned(()))
        out = search.run(ufunc, search.check)
        ranges = []
        for j in range(MAX_OPERANDS):
            lo, hi, nan = (np.asarray(out[3 * j + i], np.float64) for i in range(3))
            if not lo.size:
                continue
            if np.any(nan == _UNKNOWN):
                ranges.append(OperandRange(math.nan, math.nan, False, True, known=False))
                continue
            seen = bool(np.any(lo <= hi)) or bool(np.any(nan > 0))
            ranges.append(OperandRange(float(lo.min()), float(hi.max()), bool(np.any(nan > 0)), seen))
        found[(where, routine)] = tuple(_operands(routine, ranges))
    return found


def _operands(routine: str, ranges: list[OperandRange]) -> list[OperandRange]:
    """The ranges of the operands ``routine`` has (its unused slots dropped)."""
    return ranges[:2] if routine in ("pow", "atan2") else ranges[:1]
