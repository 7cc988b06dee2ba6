"""Every polynomial the routines evaluate, with its provenance.

Each ``Polynomial`` records what it approximates, on which interval, with
which weight (LolRemez's convention: the weight is the *tolerance*, larger
means less accurate there), its coefficients as float32 decimals (highest
degree first, exactly as they appear in the emitted IR), where they came from,
and the error measured on the compiled routine that uses it.

The coefficients below are those of the reference write-up
(``shared/refs/000_84390b1a4f8484b8.txt``, produced there by LolRemez); our own
fitter reproduces each to within one float32 ulp
(``python -m routines remez ...``, see docs/remez.md).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from reactor import MulAdd


@dataclasses.dataclass(frozen=True)
class Polynomial:
    """A float32 polynomial and its provenance (coefficients highest degree first)."""

    name: str
    function: str
    weight: str
    interval: tuple[str, str]
    coefficients: tuple[str, ...]
    provenance: str
    measured: str = ""

    @property
    def degree(self) -> int:
        return len(self.coefficients) - 1

    @property
    def values(self) -> tuple[float, ...]:
        """The coefficients as the float32 values the code uses."""
        return tuple(float(np.float32(c)) for c in self.coefficients)

    def remez_command(self) -> str:
        lo, hi = self.interval
        w = f' "{self.weight}"' if self.weight else ""
        return f'python -m routines remez -d {self.degree} -r "{lo}:{hi}" "{self.function}"{w}'

    def __call__(self, x):
        """Emit Horner's scheme in ``x`` with ``MulAdd`` (fused iff FMA is on)."""
        c = self.values
        acc = MulAdd(x, c[0], c[1])
        for coeff in c[2:]:
            acc = MulAdd(acc, x, coeff)
        return acc


EXP2_FULL = Polynomial(
    name="exp2.full",
    function="(2^x-x-1)/x", weight="1/x", interval=("0", "1"),
    coefficients=("1.8852974e-3", "8.9733787e-3", "5.5835927e-2", "2.4015281e-1", "-3.0684753e-1"),
    provenance="reference write-up, section 'Gaining Significance' (LolRemez --float -d 4 -r 0:1 "
               "\"(2^x-x-1)/x\" \"1/x\"); our fitter's 8-digit p(x) line matches these digits exactly "
               "(rounded straight to float32, one coefficient is 1 ulp away: LolRemez's double rounding)",
    measured='exhaustive, all 2^32 inputs, compiled kernel: max margin 0.632 (FMA on) / 0.662 (off), max ULP-32 33.09 (at x = 96.76, where the tolerance is 196.5 ULP), 0 non-conforming; `python -m routines accuracy exp2 --precision full --fma on --exhaustive`'
)

EXP2_RELAXED = Polynomial(
    name="exp2.relaxed",
    function="(2^x-x-1)/x", weight="1/x", interval=("0", "1"),
    coefficients=("7.8145574e-2", "2.2617357e-1", "-3.0444314e-1"),
    provenance="reference write-up, section 'Relaxing with a Halfling': the degree-2 fit of "
               "(2^x-1)/x with weight 1/x, constant term minus 1 (exact in decimal)",
    measured='exhaustive, all 2^32 inputs: max margin 0.131 (FMA on) / 0.127 (off), max ULP-16 0.139 / 0.131, 0 non-conforming; `python -m routines accuracy exp2 --precision relaxed --fma on --exhaustive`'
)

LOG2_FULL = Polynomial(
    name="log2.full",
    function="(log2(x+1)-x)/x", weight="1/x", interval=("0", "1"),
    coefficients=("-9.3091638e-3", "5.2059003e-2", "-1.3752135e-1", "2.4186478e-1",
                  "-3.4730109e-1", "4.786837e-1", "-7.2116581e-1", "4.4268988e-1"),
    provenance="reference write-up, section 'Second Try' (LolRemez --float -d 7 -r 0:1 "
               "\"(log2(x+1)-x)/x\" \"1/x\"); our fitter's 8-digit p(x) line matches these digits exactly "
               "(rounded straight to float32, three coefficients are 1 ulp away: LolRemez's double rounding)",
    measured='exhaustive, all 2^32 inputs: max margin 0.502 (FMA on) / 0.565 (off), 0 non-conforming, 0 special mismatches; `python -m routines accuracy log2 --precision full --fma on --exhaustive`'
)

LOG2_RELAXED = Polynomial(
    name="log2.relaxed",
    function="(log2(x+1)-x)/(x*(1-x))", weight="1/(x*(1-x))", interval=("0", "1"),
    coefficients=("-0.15922019", "0.42286536"),
    provenance="our Remez fitter (python -m routines remez -d 1 -r 0:1 \"(log2(x+1)-x)/(x*(1-x))\" "
               "\"1/(x*(1-x))\"). Evaluated as m*(1-m)*P(m), the correction vanishes at both ends of "
               "the mantissa interval, so relaxed log2 is exact at powers of two and has the right sign "
               "just below them (the reference's degree-2 fit is 7.7e-4 off at m = 1, which made "
               "log2(0.99999994) positive and pow(0.99999994, -inf) = +0). Same 3 FMAs; weighted "
               "error 8.8e-4 (absolute, the product) against the reference's 7.7e-4",
    measured='exhaustive, all 2^32 inputs: max margin 0.300 (FMA on and off), max ULP-16 42.6 near x = 1 (absolute tolerance there), 0 non-conforming; `python -m routines accuracy log2 --precision relaxed --fma on --exhaustive`'
)

LOG2_RELAXED_REFERENCE = Polynomial(
    name="log2.relaxed.reference",
    function="(log2(x+1)-x)/x", weight="1/x", interval=("0", "1"),
    # The reference's un-normalized fit on [0, 2^23] (2.8017103e-22, -8.373131e-15,
    # 5.0615534e-8) with x scaled by 2^-23: coefficient k times 2^(23(k+1)), exact.
    coefficients=("0.16538379", "-0.5892067", "0.42459387"),
    provenance="reference write-up, section 'The Vanishingly Small and Unfathomably Large', "
               "rescaled exactly by powers of two to the normalized mantissa in [0, 1)",
)

ALL = (EXP2_FULL, EXP2_RELAXED, LOG2_FULL, LOG2_RELAXED, LOG2_RELAXED_REFERENCE)
