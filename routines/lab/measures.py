"""Error measures for float32 results against a float64 reference.

Contracts (all functions are vectorised over NumPy arrays and accept an
optional ``out`` float64 buffer so the sweep engine can run without
temporaries):

* ``ulp32(r)`` -- binary32 spacing at ``r``: ``2**(floor(log2|r|) - 23)`` for
  ``|r| >= 2**-126``, ``2**-149`` below (subnormals and zero).  Above the
  float32 range it keeps growing (``2**(e - 23)``); such references are
  special cases (see :func:`classify`) and never scored in ULPs.
* ``ulp16(r)`` -- binary16 *spacing* of a float32 result:
  ``2**(floor(log2|r|) - 10)`` for ``|r| >= 2**-14``, ``2**-24`` below (the
  binary16 subnormal spacing).  There is no upper range limit: relaxed
  results are float32 values scored with binary16 precision.
* ``spec_ulp32(r)`` / ``spec_ulp16(r)`` -- Vulkan's ``ulp(x)`` ("the minimum
  distance between non-equal finite floats a <= x <= b"): equal to
  ``ulp32``/``ulp16`` except at an exact power of two, where it is the
  spacing *below* (half as large).  Tolerances are expressed in these units;
  reported ULP errors use ``ulp32``/``ulp16``.
* ``abs_error(got, ref) = |got - ref|`` in float64 (NaN if either is NaN).
* ``ulp_error(got, ref, bits)`` -- ``abs_error / ulp{bits}(ref)``.
* ``margin(error, allowed) = error / allowed``; an input conforms iff
  ``margin < 1``.  ``allowed = inf`` (no bound) gives 0 for finite errors.

Special values are not ULP numbers.  :func:`classify` sorts the inputs whose
reference or result is special into the categories of :data:`CATEGORIES`:

``scored``        an ordinary error, counted in the ULP and margin statistics;
``match``         the exact special value was expected and returned
                  (NaN for NaN, the same-signed infinity, or any result at a
                  non-finite input that equals the reference exactly);
``flush``         a zero of the right sign where the correctly rounded result
                  is a nonzero subnormal (``2**-150 < |ref| < 2**-126``).
                  Vulkan lets implementations flush denormals unless
                  ``DenormPreserve`` is declared, so flushes are counted
                  apart and neither scored nor mismatches;
``nan``           NaN expected but not returned, or returned but not expected;
``inf``           +-inf expected (the exact result is infinite, or an operand is
                  non-finite and the result overflows) and anything else
                  returned. Where finite operands give a finite reference whose
                  float32 rounding overflows (``|ref| >= 2**128 - 2**103``), a
                  same-signed infinity is a match and a finite result is
                  scored against the reference like any other value, as the
                  spec's tolerance allows (the bit-exact overflow thresholds
                  are tested separately, in tests/routines/test_specials.py);
``spurious_inf``  +-inf returned for a finite float32 result, unless the
                  allowed range reaches beyond FLT_MAX (the spec then permits
                  an infinity of the right sign, which is scored as if it were
                  +-FLT_MAX);
``zero_sign``     a zero whose sign differs from the reference, when the
                  reference is zero or below ``2**-126`` (e.g. -0 from exp2,
                  whose results are never negative);
``special_value`` at a non-finite input (+-inf, NaN) the result must be
                  the IEEE-754 result (the float32 rounding of the reference,
                  exact for every routine here); any other finite value.

The last five are *special-value mismatches*.  A zero returned for a normal
reference is an ordinary (scored) error, so an absolute tolerance near a root
(log2 near 1) is not turned into a sign test.
"""

from __future__ import annotations

import numpy as np

F32_MAX = float(np.finfo(np.float32).max)
#: Smallest |r| whose float32 rounding (to nearest even) is infinite.
OVERFLOW32 = 2.0**128 - 2.0**103
MIN_NORMAL32 = 2.0**-126
#: Largest |r| that rounds to zero in float32 (ties to even: 2**-150 -> 0).
HALF_MIN_SUBNORMAL32 = 2.0**-150

CATEGORIES = ("scored", "match", "flush", "nan", "inf", "spurious_inf",
              "zero_sign", "special_value")
SCORED, MATCH, FLUSH, NAN, INF, SPURIOUS_INF, ZERO_SIGN, SPECIAL_VALUE = range(8)
#: Category codes that are special-value mismatches.
MISMATCHES = (NAN, INF, SPURIOUS_INF, ZERO_SIGN, SPECIAL_VALUE)
#: Category ``spurious_inf`` when the spec permits the infinity; scored.
INF_ALLOWED = 8

_EXP_MASK = np.uint64(0x7FF0000000000000)
_BELOW_ONE = 1.0 - 2.0**-52


def _f64(a):
    return np.asarray(a, dtype=np.float64)


def _spacing(r, mantissa_bits, floor, out, spec):
    """max(2**(floor(log2|r|) - mantissa_bits), floor) via the exponent bits."""
    r = _f64(r)
    out = np.empty(r.shape) if out is None else out
    if spec:  # an exact power of two drops to the binade below
        r = np.multiply(r, _BELOW_ONE, out=out)
    np.bitwise_and(r.view(np.uint64), _EXP_MASK, out=out.view(np.uint64))
    np.multiply(out, 2.0**-mantissa_bits, out=out)
    return np.fmax(out, floor, out=out)


def ulp32(r, out=None):
    """Binary32 spacing at ``r`` (binade spacing; ``2**-149`` below 2**-126)."""
    return _spacing(r, 23, 2.0**-149, out, spec=False)


def ulp16(r, out=None):
    """Binary16 spacing at ``r`` (binade spacing; ``2**-24`` below 2**-14)."""
    return _spacing(r, 10, 2.0**-24, out, spec=False)


def spec_ulp32(r, out=None):
    """Vulkan ``ulp()`` in binary32: ``ulp32`` but the spacing below at 2**k."""
    return _spacing(r, 23, 2.0**-149, out, spec=True)


def spec_ulp16(r, out=None):
    """Vulkan ``ulp()`` in binary16 spacing: ``ulp16`` but below at 2**k."""
    return _spacing(r, 10, 2.0**-24, out, spec=True)


def abs_error(got, ref, out=None):
    """``|got - ref|`` in float64."""
    out = np.subtract(got, ref, out=out, dtype=np.float64)
    return np.abs(out, out=out)


def ulp_error(got, ref, bits=32):
    """Error of ``got`` in ULP-32 (``bits=32``) or ULP-16 (``bits=16``)."""
    unit = {32: ulp32, 16: ulp16}[bits](ref)
    return np.divide(abs_error(got, ref), unit, out=unit)


def margin(error, allowed, out=None):
    """``error / allowed``; conforming iff < 1 (0 where allowed is inf)."""
    return np.divide(error, allowed, out=out)


def classify(x_finite, got, ref, allowed):
    """Category codes (uint8, see module doc) for each (input, got, ref).

    ``x_finite`` -- True where every operand is finite; ``got`` -- float32
    results; ``ref`` -- float64 references; ``allowed`` -- absolute allowed
    error (only used to decide whether an infinite result is permitted); all
    of one shape.  Returns codes from :data:`CATEGORIES` plus
    :data:`INF_ALLOWED`.  Creates no full-size float64 temporaries.
    """
    got, ref = np.asarray(got), _f64(ref)
    g_nan, r_nan, g_inf = np.isnan(got), np.isnan(ref), np.isinf(got)
    same_sign = np.signbit(got) == np.signbit(ref)
    nonfinite_input = ~np.asarray(x_finite, dtype=bool)
    overflows = (ref >= OVERFLOW32) | (ref <= -OVERFLOW32)
    expect_inf = np.isinf(ref) | (overflows & nonfinite_input)
    overflow_match = overflows & ~expect_inf & g_inf & same_sign
    tiny_zero = (got == 0) & (ref < MIN_NORMAL32) & (ref > -MIN_NORMAL32)
    flushed = tiny_zero & ((ref > HALF_MIN_SUBNORMAL32) | (ref < -HALF_MIN_SUBNORMAL32))
    # inf for a finite reference is permitted if ref + allowed > FLT_MAX
    inf_ok = g_inf & same_sign & ~nonfinite_input & ~overflows & ~r_nan
    where = np.flatnonzero(inf_ok)
    inf_ok.flat[where] = np.abs(ref.flat[where]) + _f64(allowed).flat[where] > F32_MAX
    with np.errstate(over="ignore"):
        ref32 = ref.astype(np.float32)
    # Highest priority first: NaN rules first, so later rules see no NaN.
    rules = [
        (g_nan & r_nan, MATCH),
        (g_nan | r_nan, NAN),
        (expect_inf & g_inf & same_sign, MATCH),
        (expect_inf, INF),
        (overflow_match, MATCH),
        (inf_ok, INF_ALLOWED),
        (g_inf, SPURIOUS_INF),
        (tiny_zero & ~same_sign, ZERO_SIGN),
        (nonfinite_input & (got == ref32) & same_sign, MATCH),
        (nonfinite_input, SPECIAL_VALUE),
        (flushed, FLUSH),
    ]
    cat = np.zeros(np.broadcast(got, ref).shape, dtype=np.uint8)
    for cond, code in reversed(rules):  # higher priority overwrites lower
        np.copyto(cat, code, where=cond)
    return cat
