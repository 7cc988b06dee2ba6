"""What a plan keeps unchanged: the kernel's output in the format the scene writes.

``output`` is one of

* ``"unorm8"``, ``"unorm10"``, ``"unorm16"``: the code GLSL's ``packUnorm`` writes,
  ``round_to_nearest_even(clamp(x, 0, 1) * (2^b - 1))`` (computed in float64, where the product
  is exact), NaN as 0;
* ``"float16"``: the half a float32 rounds to (round to nearest even), compared bit for bit, every
  NaN one NaN;
* ``"float32"``: the float32 itself, bit for bit, every NaN one NaN;
* ``{"ulp": n}``: float32 results within n units in the last place of the reference's (``n = 0``
  is ``"float32"`` with -0 == +0); ``{"abs": e}``: within e of it. NaN matches only NaN.

An output "changes" when its quantized value differs from the reference build's. A kernel with
several results, or a vector result, changes on an element when any of them does.
"""
from __future__ import annotations

import typing

import numpy as np

from ..errors import ReactorError
from .domains import UNORM_BITS

FORMATS = tuple(UNORM_BITS) + ("float16", "float32")


class Output:
    """A quantizer: ``changed(reference, candidate)`` per element, and ``margin(reference)``, how
    close each reference value is to changing (in codes, or ULPs), for the worst-input search."""

    def __init__(self, spec: typing.Any):
        self.spec = spec
        if isinstance(spec, str) and spec in FORMATS:
            self.name = spec
        elif isinstance(spec, dict) and len(spec) == 1 and next(iter(spec)) in ("ulp", "abs"):
            (kind, bound), = spec.items()
            if not (isinstance(bound, (int, float)) and bound >= 0):
                raise ReactorError(f"output {spec!r}: the tolerance must be a number >= 0")
            self.name = f"within {bound:g} {'ULP' if kind == 'ulp' else '(absolute)'}"
        else:
            raise ReactorError(f"output must be one of {', '.join(map(repr, FORMATS))}, {{'ulp': n}} or "
                               f"{{'abs': e}}, not {spec!r}")

    def quantize(self, x: np.ndarray) -> np.ndarray:
        """The values the scene stores (for a format; the float32 bits for a tolerance)."""
        x = np.asarray(x, np.float32)
        if self.name in UNORM_BITS:
            top = (1 << UNORM_BITS[self.name]) - 1
            with np.errstate(invalid="ignore"):
                scaled = np.clip(np.nan_to_num(x.astype(np.float64), nan=0.0), 0.0, 1.0) * top
            return np.rint(scaled).astype(np.uint32)
        if self.name == "float16":
            with np.errstate(over="ignore", invalid="ignore"):
                h = x.astype(np.float16)
            half_bits = h.view(np.uint16).copy()
            half_bits[np.isnan(h)] = 0x7E00
            return half_bits
        bits = x.view(np.uint32).copy()
        bits[np.isnan(x)] = 0x7FC00000
        return bits

    def changed(self, reference: np.ndarray, candidate: np.ndarray) -> np.ndarray:
        """A bool per element: the candidate's stored value differs from the reference's."""
        if isinstance(self.spec, dict):
            (kind, bound), = self.spec.items()
            a, b = np.asarray(reference, np.float32), np.asarray(candidate, np.float32)
            nan_a, nan_b = np.isnan(a), np.isnan(b)
            with np.errstate(invalid="ignore", over="ignore"):
                if kind == "abs":
                    far = ~(np.abs(a.astype(np.float64) - b.astype(np.float64)) <= bound)
                else:
                    far = _ulps(a, b) > bound
            return np.where(nan_a | nan_b, nan_a != nan_b, far)
        return self.quantize(reference) != self.quantize(candidate)

    def margin(self, reference: np.ndarray) -> np.ndarray:
        """How far each reference value is from the nearest point where its stored value changes
        (codes for unorm, ULPs of the stored format otherwise): small is risky."""
        x = np.asarray(reference, np.float32).astype(np.float64)
        if self.name in UNORM_BITS:
            top = (1 << UNORM_BITS[self.name]) - 1
            scaled = np.clip(np.nan_to_num(x, nan=0.0), 0.0, 1.0) * top
            return np.abs(scaled - np.floor(scaled) - 0.5)
        if self.name == "float16":
            with np.errstate(over="ignore", invalid="ignore"):
                h = x.astype(np.float16).astype(np.float64)
                up = np.abs(np.nextafter(h.astype(np.float16), np.float16(np.inf)).astype(np.float64) - h)
                return np.nan_to_num(np.abs(np.abs(x - h) / np.where(up > 0, up, 1.0) - 0.5), nan=1.0)
        return np.ones(x.shape)  # float32 and tolerances: no boundary to rank by


def _ulps(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Units in the last place of float32 between a and b (on the ordered integer line)."""
    def ordered(x):
        i = x.view(np.int32).astype(np.int64)
        return np.where(i < 0, -(i & 0x7FFFFFFF), i)
    return np.abs(ordered(a) - ordered(b))


def changed_rows(output: Output, reference: tuple, candidate: tuple) -> np.ndarray:
    """Per row of the check: any result (any component of a vector result) changed."""
    rows: typing.Any = None
    for r, c in zip(reference, candidate):
        ch: typing.Any = output.changed(r, c)
        ch = ch.reshape(ch.shape[0], -1).any(axis=1) if ch.ndim > 1 else ch
        rows = ch if rows is None else rows | ch
    assert rows is not None
    return rows


def row_margin(output: Output, reference: tuple) -> np.ndarray:
    """Per row, the smallest margin of any of its results."""
    rows: typing.Any = None
    for r in reference:
        m: typing.Any = output.margin(r)
        m = m.reshape(m.shape[0], -1).min(axis=1) if m.ndim > 1 else m
        rows = m if rows is None else np.minimum(rows, m)
    assert rows is not None
    return rows
