"""Every row and exactness rule of routines/specials.py, on the compiled kernels,
for both precisions, FMA on and off, and every SIMD width."""
import itertools
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import routines
from routines.base import tiers
from routines.specials import ROWS, RULES, same

VARIANTS = list(itertools.product(routines.NAMES, ("full", "relaxed"), (True, False), (1, 4, 8, 16)))
# The faithful and correct tiers (C99 Annex F) of the routines that have them.
VARIANTS += [(name, tier, fma, width) for name in routines.NAMES for tier in tiers(name)[2:]
             for fma in (True, False) for width in (1, 8, 16)]


@pytest.mark.parametrize("name,precision,fma,width", VARIANTS)
def test_special_rows_and_rules(name, precision, fma, width):
    ufunc = routines.jit(name, precision, fma, width)
    rows = [r for r in ROWS if r.function == name and precision in r.precisions]
    assert rows, f"no special rows for {name}"
    args = [np.array([r.args[i] for r in rows], np.float32) for i in range(len(rows[0].args))]
    got = ufunc(*args)
    expected = np.array([r.expected for r in rows], np.float32)
    bad = [(r.case, r.args, g) for r, g, ok in zip(rows, got, same(got, expected)) if not ok]
    assert not bad, bad
    for rule in RULES:
        if rule.function == name and precision in rule.precisions:
            inputs, expected = rule.inputs()
            ok = same(ufunc(*inputs), expected)
            assert ok.all(), (rule.text, inputs[0][~ok][:5])


def test_rows_cover_the_required_cases():
    for name in ("exp2", "exp", "log2", "log", "rcp", "rsqrt", "sqrt"):
        cases = " ".join(r.case for r in ROWS if r.function == name)
        for needed in ("+0", "-0", "+inf", "-inf", "NaN"):
            assert needed in cases, (name, needed)
    pow_cases = " ".join(r.case for r in ROWS if r.function == "pow")
    for needed in ("+0 ^ y>0", "^ 0 = NaN", "1 ^ finite", "+inf ^ y<0", "x < 0", "NaN ^", "x ^ NaN"):
        assert needed in pow_cases, needed


def test_exp2_is_monotone_and_never_negative_through_underflow():
    x = np.linspace(-130, -120, 200001, dtype=np.float32)
    for precision, fma in itertools.product(("full", "relaxed"), (True, False)):
        y = routines.jit("exp2", precision, fma)(x)
        assert (y >= 0).all() and not np.signbit(y).any()
        assert (np.diff(y.astype(np.float64)) >= 0).all()
        if precision == "relaxed":  # full rounds subnormal results (VSCALEFPS's rounding)
            assert (y[x < -126] == 0).all()
        else:
            want = np.exp2(x.astype(np.float64)).astype(np.float32)
            assert (np.abs(y - want) <= 2.0 ** -149)[x < -126].all()


def test_docs_specials_is_generated_from_the_table():
    doc = Path(__file__).resolve().parents[2] / "docs" / "specials.md"
    out = subprocess.run([sys.executable, "-m", "routines", "specials"], capture_output=True, text=True, check=True)
    assert doc.read_text() == out.stdout, "regenerate: python -m routines specials > docs/specials.md"
