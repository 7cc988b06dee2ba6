"""Measure every zoo variant on its compiled kernel and compare with the reference.

For each :class:`~routines.zoo.methods.Variant`:

* **domain** (where the reference's figures are read: exp2 ``[-1,1)``, log2
  ``[2,4)``): every float32 in it, swept with :func:`routines.lab.sweep`.
  For exp2 the ~1.9e9 tiny inputs ``|x| < 2^-28`` are not swept: there every
  variant returns one constant per sign (``f`` and ``P(f)`` no longer depend
  on x; ``tests/zoo`` checks this), so the error is monotone in x and its
  supremum is at the ends of that range, which are evaluated together with
  every power of two in it and a random sample.
* **wide** (where the method's conformance is judged: exp2 ``[-126,128)``,
  every x with a normal result; log2 ``[1/16,16)``): the domain's result
  merged with a sweep of the rest.

``--quick`` sweeps only the binades of the variant's ``peaks`` (where the
exhaustive run found its maxima and failures) and a random sample of the
rest (plus the end points): the figures equal the exhaustive ones as long
as the peaks have not moved, and are lower bounds in any case.

A stated figure is *reproduced* when the measured one is within
:data:`AGREE` (relative) of it, or within one unit of its last printed digit
if that is more: the reference quotes 2 to 5 digits, and truncates some.
"""
from __future__ import annotations

import dataclasses
import decimal
import textwrap
import time

import numpy as np

from ..lab import SweepResult, evaluate, sweep
from .methods import REFERENCE, VARIANTS, Variant, _bits, binade

AGREE = 0.02
TINY = 2.0 ** -28
MEASURES = ("ulp32", "ulp16", "margin")
LABELS = {"ulp32": "ULP-32", "ulp16": "ULP-16", "margin": "margin"}
QUICK_DOMAIN = 2 ** 23   # sampled inputs per variant in --quick mode
QUICK_WIDE = 2 ** 22


# --------------------------------------------------------------------------
# Bit-pattern range arithmetic

def split_tiny(ranges, cut: float = TINY):
    """(big, tiny): ``ranges`` split at magnitude ``cut`` (|x| >= cut vs |x| < cut)."""
    c = _bits(cut)
    big, tiny = [], []
    for a, b in ranges:
        base = 0x80000000 if a >= 0x80000000 else 0
        lo, hi = a - base, b - base
        if lo < min(hi, c):
            tiny.append((base + lo, base + min(hi, c)))
        if max(lo, c) < hi:
            big.append((base + max(lo, c), base + hi))
    return big, tiny


def subtract(ranges, minus):
    """The bit patterns of ``ranges`` not in ``minus`` (both lists of half-open ranges)."""
    out = []
    for a, b in ranges:
        pieces = [(a, b)]
        for c, d in minus:
            pieces = [p for lo, hi in pieces
                      for p in ((lo, min(hi, c)), (max(lo, d), hi)) if p[0] < p[1]]
        out += pieces
    return out


def tiny_sample(ranges, n: int = 2 ** 14, seed: int = 0) -> np.ndarray:
    """End points, every power of two and ``n`` random patterns of each tiny range."""
    rng = np.random.default_rng(seed)
    parts = []
    for a, b in ranges:
        parts += [np.array([a, b - 1], np.uint32),
                  np.arange(a, b, 1 << 23, dtype=np.uint64).astype(np.uint32),
                  rng.integers(a, b, n, dtype=np.uint64).astype(np.uint32)]
    return np.sort(np.concatenate(parts))


def range_sample(ranges, n: int, seed: int = 0) -> np.ndarray:
    """``n`` random patterns spread over ``ranges`` (by size) plus their end points
    (duplicates are kept: they cannot change a maximum)."""
    rng = np.random.default_rng(seed)
    total = sum(b - a for a, b in ranges)
    parts = []
    for a, b in ranges:
        k = max(16, int(n * (b - a) / total))
        parts += [np.array([a, b - 1], np.uint32),
                  rng.integers(a, b, k, dtype=np.uint64).astype(np.uint32)]
    return np.concatenate(parts)


# --------------------------------------------------------------------------
# Measurement

@dataclasses.dataclass
class Comparison:
    """A stated figure beside ours; ``slack``: how far apart they may be."""

    measure: str
    text: str        # the figure as the reference prints it
    measured: float

    @property
    def stated(self) -> float:
        return float(self.text)

    @property
    def slack(self) -> float:
        """AGREE relative, or one unit in the last printed digit if larger
        ("0.13" and "2.56" are quoted with 2-3 digits, sometimes truncated)."""
        unit = 10.0 ** decimal.Decimal(self.text).as_tuple().exponent
        return max(AGREE * abs(self.stated), unit)

    @property
    def agrees(self) -> bool:
        return abs(self.measured - self.stated) <= self.slack

    def to_json(self) -> dict:
        return {"measure": self.measure, "stated": self.text, "measured": self.measured,
                "agrees": self.agrees}


@dataclasses.dataclass
class Measurement:
    variant: Variant
    domain: SweepResult
    wide: SweepResult
    exhaustive: bool
    seconds: float

    @property
    def comparisons(self) -> list[Comparison]:
        s = self.variant.stated
        return [Comparison(m, getattr(s, m), getattr(self.domain, f"max_{m}"))
                for m in MEASURES if getattr(s, m) is not None]

    @property
    def reproduced(self) -> bool | None:
        """All stated figures reproduced (None: the reference states none)."""
        c = self.comparisons
        return None if not c else all(x.agrees for x in c)

    @property
    def conforms(self) -> bool:
        """Our verdict: margin < 1 and no special-value mismatch over the wide domain."""
        return self.wide.conforming

    @property
    def verdict_agrees(self) -> bool:
        return self.conforms == self.variant.verdict

    def to_json(self) -> dict:
        v = self.variant
        return {
            "name": v.name, "function": v.function, "precision": v.precision, "fma": v.fma,
            "section": v.section, "description": v.description,
            "polynomials": [{"name": p.name, "function": p.function, "weight": p.weight,
                             "interval": list(p.interval), "coefficients": list(p.coefficients),
                             "provenance": p.provenance} for p in v.polynomials],
            "stated": dataclasses.asdict(v.stated),
            "domain": str(v.domain), "wide": str(v.wide), "exhaustive": self.exhaustive,
            "comparisons": [c.to_json() for c in self.comparisons],
            "reproduced": self.reproduced,
            "reference_verdict": "conforms" if v.verdict else "fails: " + v.failure,
            "conforms": self.conforms, "verdict_agrees": self.verdict_agrees,
            "explanation": v.explain, "seconds": round(self.seconds, 2),
            "measured_domain": self.domain.to_json(), "measured_wide": self.wide.to_json(),
        }


def intersect(ranges, other):
    """The bit patterns in both ``ranges`` and ``other``."""
    return subtract(ranges, subtract(ranges, other))


def _run(kernel, v: Variant, ranges, peaks, quick, workers, n, seed, inputs) -> SweepResult:
    """Sweep ``ranges`` (quick: sweep their part in ``peaks``, sample the rest)."""
    total = SweepResult(v.function, v.precision, inputs)
    swept = intersect(ranges, peaks) if quick else ranges
    for a, b in swept:
        total.merge(sweep(kernel, v.function, v.precision, start=a, stop=b,
                          workers=workers, progress=False))
    rest = subtract(ranges, swept)
    if rest:
        total.merge(evaluate(kernel, v.function, v.precision, range_sample(rest, n, seed)))
    return total


def measure(v: Variant, *, quick: bool = False, workers: int = 2, seed: int = 0) -> Measurement:
    """Measure ``v`` on its domain and wide domain (see the module docstring)."""
    t0 = time.perf_counter()
    k = v.kernel()
    ranges = list(v.domain.ranges)
    peaks = sorted({r for x in v.peaks for r in binade(x).ranges})
    big, tiny = split_tiny(ranges) if v.function == "exp2" else (ranges, [])
    how = "peak binades swept, rest sampled" if quick else "exhaustive"
    label = f"float32 in {v.domain}, {how}" + (", |x| < 2^-28 sampled (constant)" if tiny else "")
    dom = _run(k, v, big, peaks, quick, workers, QUICK_DOMAIN, seed, label)
    if tiny:
        dom.merge(evaluate(k, v.function, v.precision, tiny_sample(tiny, seed=seed)))
    wide = SweepResult(v.function, v.precision, f"float32 in {v.wide}, {how}")
    wide.merge(dom)
    wide.merge(_run(k, v, subtract(list(v.wide.ranges), ranges), peaks, quick, workers,
                    QUICK_WIDE, seed + 1, ""))
    return Measurement(v, dom, wide, not quick, time.perf_counter() - t0)


def measure_all(variants=VARIANTS, *, quick: bool = False, workers: int = 2, log=None):
    """Measure every variant; ``log(text)`` is called after each one."""
    out = []
    for v in variants:
        m = measure(v, quick=quick, workers=workers)
        out.append(m)
        if log:
            log(f"{v.name:<22} {m.seconds:6.1f} s")
    return out


# --------------------------------------------------------------------------
# Output

def _fmt(x) -> str:
    if x is None:
        return "-"
    if x == 0:
        return "0"
    if abs(x) >= 100:
        return f"{x:.2f}"
    if abs(x) >= 10:
        return f"{x:.3f}"
    if abs(x) >= 0.01:
        return f"{x:.4g}"
    return f"{x:.3g}"


def _rows(measurements):
    for m in measurements:
        v, d, s = m.variant, m.domain, m.variant.stated
        ref = [getattr(s, k) or "-" for k in MEASURES]
        marks = {c.measure: "=" if c.agrees else "*" for c in m.comparisons}
        ours = [_fmt(getattr(d, f"max_{k}")) + marks.get(k, "") for k in MEASURES]
        repro = {None: "-", True: "yes", False: "NO"}[m.reproduced]
        verdict = ("conforms" if v.verdict else "fails")
        w = m.wide
        bad = w.nonconforming + w.mismatches
        our = (f"conforms ({_fmt(w.max_margin)})" if m.conforms else
               f"fails ({_fmt(w.max_margin)}, {bad} bad)")
        yield [v.name, v.precision, "on" if v.fma else "off", str(v.domain), *ref, *ours, repro,
               verdict, str(v.wide), our, "" if m.verdict_agrees else "DISAGREE"]


HEADER = ["variant", "prec", "FMA", "domain", "ref ULP-32", "ref ULP-16", "ref margin",
          "ULP-32", "ULP-16", "margin", "reproduced", "ref verdict", "wide", "ours over wide",
          ""]


def table(measurements) -> str:
    """The text table: the reference's figures, ours on the same domain, verdicts, notes."""
    rows = [HEADER] + list(_rows(measurements))
    widths = [max(len(r[i]) for r in rows) for i in range(len(HEADER))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
    lines.insert(1, "-" * len(lines[0]))
    mode = ("exhaustive" if all(m.exhaustive for m in measurements)
            else "--quick: peak binades swept, the rest sampled")
    lines += ["", f"Measured on the compiled kernels ({mode}); '=' reproduces the reference's "
              f"figure (within {AGREE:.0%} or one unit of its last digit), '*' does not.",
              "Margin = error / Vulkan tolerance (conforms iff < 1); 'bad' = inputs with "
              "margin >= 1 or a wrong special value (e.g. a spurious inf).", "", "Notes:"]
    for m in measurements:
        lines += textwrap.wrap(m.variant.explain, 120, initial_indent=f"  {m.variant.name:<22} ",
                               subsequent_indent=" " * 25)
    n_rep = sum(1 for m in measurements if m.reproduced)
    n_fig = sum(1 for m in measurements if m.reproduced is not None)
    n_ver = sum(1 for m in measurements if m.verdict_agrees)
    lines += ["", f"{n_rep}/{n_fig} variants with stated figures reproduce them; "
              f"{n_ver}/{len(measurements)} verdicts agree with the reference."]
    return "\n".join(lines)


def markdown(measurements) -> str:
    """The same table in Markdown (docs/zoo.md)."""
    rows = list(_rows(measurements))
    head = HEADER[:-1]
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    out += ["| " + " | ".join(c.replace("|", "\\|") for c in r[:-1]) + " |" for r in rows]
    return "\n".join(out)


def to_json(measurements, **meta) -> dict:
    return {"reference": REFERENCE, "agree_tolerance": AGREE,
            **meta, "variants": [m.to_json() for m in measurements]}
