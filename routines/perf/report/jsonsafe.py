"""JSON-safe numbers.

Contract: ``to_json(report)`` returns a copy of a report dict made only of
JSON types (dict keys as strings, tuples as lists, NumPy scalars as Python
numbers, non-finite floats as the strings ``"nan"``/``"inf"``/``"-inf"``,
anything else as its ``str``); :func:`json_number` does that for one number
and :func:`as_float` reads such a number back (``None`` as NaN). Pure
functions: nothing is measured or modified in place.
"""
from __future__ import annotations

import math

import numpy as np


def json_number(v):
    """A JSON-safe number (non-finite floats as strings, None kept)."""
    if v is None:
        return None
    v = float(v)
    return v if math.isfinite(v) else str(v)


def as_float(v) -> float:
    """The inverse of json_number (strings back to floats)."""
    return float(v) if v is not None else float("nan")


def to_json(report) -> dict:
    """``report`` with every float JSON-safe."""
    def clean(o):
        if isinstance(o, dict):
            return {str(k): clean(v) for k, v in o.items()}
        if isinstance(o, (list, tuple)):
            return [clean(v) for v in o]
        if isinstance(o, (bool, str)) or o is None:
            return o
        if isinstance(o, (int, np.integer)):
            return int(o)
        if isinstance(o, (float, np.floating)):
            return json_number(o)
        return str(o)
    return clean(report)
