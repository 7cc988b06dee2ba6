"""The precision continuum (routines.continuum): full's form with shorter polynomials, between the tiers."""
from __future__ import annotations

import re

import numpy as np
import pytest

import reactor
import routines
from reactor import Float, Site
from reactor.errors import ReactorError
from routines import continuum
from routines.cli.continuum import _floats, _ulp

VARIANTS = [(name, v) for name in ("exp2", "exp", "log2", "log", "pow", "sin", "cos", "tan", "atan", "asin", "acos",
                                   "sinh", "cosh", "tanh")
            for v in continuum.VARIANTS[name]]


def _bound(text: str) -> float:
    return float(re.search(r"max ([0-9.e+-]+)", text).group(1))


@pytest.mark.parametrize("degree", sorted(continuum.EXP2_DEGREES)[:-1])
def test_exp2_variants_keep_their_stated_error(degree):
    u = routines.jit("exp2", precision=f"full-d{degree}")
    x = _floats(0.5, 8.0, 7)
    x = np.concatenate([x, -x])
    assert _ulp(u(x), np.exp2(x.astype(np.float64))) <= _bound(continuum.EXP2_DEGREES[degree].measured)


@pytest.mark.parametrize("degree", sorted(continuum.LOG2_DEGREES)[:-1])
def test_log2_variants_keep_their_stated_error(degree):
    u = routines.jit("log2", precision=f"full-d{degree}")
    x = _floats(1 / 16, 16.0, 7)
    got, want = u(x).astype(np.float64), np.log2(x.astype(np.float64))
    assert np.max(np.abs(got - want)) <= _bound(continuum.LOG2_DEGREES[degree].measured)


@pytest.mark.parametrize("name,bound", [("sin", 1.3610e-6), ("cos", 1.3732e-6), ("tan", 2.269e-6)])
def test_sin_cos_tan_variant_keeps_its_stated_error_between_relaxed_and_full(name, bound):
    half = _floats(2.0 ** -20, float(np.float32(np.pi)), 29)
    x = np.concatenate([half, -half])
    want = getattr(np, name)(x.astype(np.float64))
    errors = {}
    for p in ("relaxed", "full-d6", "full"):
        err = np.abs(routines.jit(name, precision=p)(x).astype(np.float64) - want)
        errors[p] = np.max(err / np.abs(want)) if name == "tan" else np.max(err)
    assert errors["full-d6"] <= bound and errors["full"] < errors["full-d6"] < errors["relaxed"]


@pytest.mark.parametrize("name,kind,hi", [("atan", "atan", 4.0), ("asin", "asin", 1.0), ("acos", "asin", 1.0)])
def test_inverse_trig_variants_keep_their_stated_error_in_order(name, kind, hi):
    half = _floats(2.0 ** -20, hi, 29)
    x = np.concatenate([half, -half])
    want = getattr(np, "arc" + name[1:])(x.astype(np.float64))
    table = continuum.ATAN_DEGREES if kind == "atan" else continuum.ASIN_DEGREES
    errors = []
    for degree in sorted(table)[:-1]:
        err = _ulp(routines.jit(name, precision=f"full-d{degree}")(x), want)
        text = table[degree].measured
        stated = float(re.search(r"acos ([0-9.]+)", text).group(1)) if name == "acos" else _bound(text)
        assert err <= stated, (name, degree)
        errors.append(err)
    errors.append(_ulp(routines.jit(name)(x), want))
    assert errors == sorted(errors, reverse=True)


@pytest.mark.parametrize("name", ["sinh", "cosh", "tanh"])
def test_hyperbolic_variants_keep_their_stated_error_in_order(name):
    half = _floats(2.0 ** -20, 10.0, 7 * 8)  # every 8th of the stated measurement's floats
    x = np.concatenate([half, -half])
    want = getattr(np, name)(x.astype(np.float64))
    stated = dict(re.findall(rf"{name} full-d2 ([0-9.]+), full-d3 ([0-9.]+)",
                             " ".join(continuum.__doc__.split()) + " " + _hyperbolic_comment()))
    (d2, d3), = stated.items()
    errors = [_ulp(routines.jit(name, precision=p)(x), want) for p in ("relaxed", "full-d2", "full-d3", "full")]
    assert errors[1] <= float(d2) and errors[2] <= float(d3)
    assert errors == sorted(errors, reverse=True)


def _hyperbolic_comment() -> str:
    """The comment above HYPERBOLIC_VARIANTS, where the variants' errors are stated."""
    import inspect
    source = inspect.getsource(continuum)
    block = source[:source.index("HYPERBOLIC_VARIANTS = {")].rsplit("\n\n", 1)[-1]
    return " ".join(line.lstrip("#: ").strip() for line in block.splitlines())


def test_atan2_takes_atans_variants():
    y = np.linspace(-1, 1, 4097, dtype=np.float32)
    for v in continuum.VARIANTS["atan2"]:
        got = routines.jit("atan2", precision=v)(y, np.ones_like(y))
        assert np.array_equal(got, routines.jit("atan", precision=v)(y)), v
    assert list(continuum.VARIANTS["atan2"]) == list(continuum.VARIANTS["atan"])


TABLE_FORMS = [("t", q, p) for q, p in continuum.LOG2_TABLE_DEGREES.items()] + \
    [("s", q, p) for q, p in continuum.LOG2_FOLD_DEGREES.items()]


@pytest.mark.parametrize("form,degree,poly", TABLE_FORMS)
def test_log2_table_variants_keep_their_stated_error_and_bits_across_x86_levels(form, degree, poly):
    """The table form: its stated error, and the same bits built for AVX-512 (VPERMI2PS), AVX2
    (VPERMPS and selects) and without AVX-512 the integer-bit reduction; SSE4 (no FMA, tables
    gathered from memory) within the same bound."""
    x = _floats(1 / 16, 16.0, 7)
    want = np.log2(x.astype(np.float64))
    bound = _bound(poly.measured)
    got = {t: routines.jit("log2", precision=f"full-{form}{degree}", target=t)(x) for t in ("host", "avx2", "sse4")}
    for t, y in got.items():
        assert np.max(np.abs(y.astype(np.float64) - want)) <= bound * (1.5 if t == "sse4" else 1.0), t
    assert np.array_equal(got["host"].view(np.uint32), got["avx2"].view(np.uint32))


def test_log2_tables_are_correctly_rounded():
    mpmath = pytest.importorskip("mpmath")
    mpmath.mp.prec = 100
    assert len(continuum.LOG2_INVC) == len(continuum.LOG2_LOGC) == 1 << continuum.LOG2_TABLE_BITS
    assert len(continuum.LOG2_FOLD_INVC) == len(continuum.LOG2_FOLD_LOGC) == 1 << continuum.LOG2_FOLD_BITS
    assert np.uint32(continuum.LOG2_FOLD_OFFSET).view(np.float32) == np.float32(1 - 1 / 32)
    for middle, invc, logcs in ((lambda i: 1 + (i + 0.5) / 32, continuum.LOG2_INVC, continuum.LOG2_LOGC),
                                (lambda i: 1 + i / 8, continuum.LOG2_FOLD_INVC, continuum.LOG2_FOLD_LOGC)):
        assert invc[0] == 1.0 and logcs[0] == 0.0
        for i, (inv, logc) in enumerate(zip(invc, logcs)):
            assert inv == float(np.float32(inv)) and logc == float(np.float32(logc))
            exact = -mpmath.log(mpmath.mpf(inv), 2)
            below, above = sorted((logc, float(np.nextafter(np.float32(logc), np.float32(exact)))))
            assert abs(exact - logc) <= abs(exact - (above if logc == below else below)), i
            if i:  # 1/c_i, c_i the middle of its subinterval, rounded to float32
                assert inv == float(np.float32(1 / middle(i)))


def test_the_table_form_is_cheaper_than_full_by_the_model_at_full_accuracy():
    from reactor.cost.model import kernel_cycles
    t2, full = (kernel_cycles(reactor.kernel_of(routines.jit("log2", precision=p))) for p in ("full-t2", "full"))
    assert t2 < full
    x = _floats(1 / 16, 16.0, 13)
    want = np.log2(x.astype(np.float64))
    big = np.abs(want) >= 1
    assert _ulp(routines.jit("log2", precision="full-t2")(x)[big], want[big]) < 1.5


def test_each_degree_is_between_its_neighbours_in_error_and_cost():
    x = _floats(0.5, 8.0, 31)
    errors = [_ulp(routines.jit("exp2", precision=p)(x), np.exp2(x.astype(np.float64)))
              for p in ("full-d2", "full-d3", "full-d4", "full")]
    assert errors == sorted(errors, reverse=True) and errors[-1] < 1.0
    from reactor.cost.model import kernel_cycles
    cycles = [kernel_cycles(reactor.kernel_of(routines.jit("log2", precision=p)))
              for p in ("full-d2", "full-d3", "full-d4", "full-d5", "full")]
    assert cycles == sorted(cycles) and cycles[0] < cycles[-1]


SPECIALS = np.float32([np.nan, np.inf, -np.inf, 0.0, -0.0, 1.0, 2.0, 0.5, 128.0, -126.0, -149.0, -150.0, -200.0,
                       1e-45, 1e-40, 3.0e38, -1.0, 4.0, 0.25])


@pytest.mark.parametrize("name,variant", VARIANTS)
def test_every_variant_has_fulls_special_values_and_exact_points(name, variant):
    """Only the polynomial changes: NaN, infinities, zeros, subnormals, overflow, and the exact
    points (exp2 of whole numbers, log2 of powers of two) are full's, bit for bit."""
    full, ours = routines.jit(name, precision="full"), routines.jit(name, precision=variant)
    if name == "pow":
        x, y = (a.ravel() for a in np.meshgrid(SPECIALS, np.float32([0.0, 1.0, 2.0, -1.0, 2.2, np.inf, -np.inf, np.nan])))
        a, b = full(x, y), ours(x, y)
        keep = ~np.isfinite(a) | (a == 0) | np.isin(x, [1.0, 0.0]) | np.isin(y, [0.0])
    else:
        a, b = full(SPECIALS), ours(SPECIALS)
        whole = (SPECIALS == np.round(SPECIALS)) if name == "exp2" else np.isin(SPECIALS, [1.0, 2.0, 0.5, 4.0, 0.25])
        keep = ~np.isfinite(a) | (a == 0) | (whole if name in ("exp2", "log2") else False)
    assert np.array_equal(a[keep].view(np.uint32), b[keep].view(np.uint32)), (name, variant)


def test_a_variant_is_other_machine_code_and_recorded_at_its_line():
    @reactor.kernel
    def two(x: Float) -> Float:
        return routines.exp2(x, precision="full-d3") + routines.exp2(x)  # not one pure call: two settings
    calls = reactor.kernel_of(two).routines
    assert [c.precision for c in calls] == ["full-d3", "full"]
    x = np.linspace(-3, 3, 1001, dtype=np.float32)
    want = routines.jit("exp2", precision="full-d3")(x) + routines.jit("exp2")(x)
    assert np.array_equal(two(x), want)
    assert reactor.kernel_of(routines.jit("exp2", precision="full-d3")).code.key != \
        reactor.kernel_of(routines.jit("exp2")).code.key


def test_variant_names_are_checked_with_the_names_there_are():
    assert Site("a.py:1", "exp2", "full-d3").precision == "full-d3"
    with pytest.raises(ReactorError, match="exp2 has no precision variant 'full-d9'.*'full-d2'"):
        Site("a.py:1", "exp2", "full-d9")
    with pytest.raises(ReactorError, match="precision must be one of"):
        Site("a.py:1", "exp2", "fast-d3")
    with pytest.raises(ReactorError, match="rsqrt has no precision variants"):
        routines.jit("rsqrt", precision="full-d3")
    with pytest.raises(ReactorError, match="sinh has no precision variant 'full-d4'; its variants are 'full-d2', 'full-d3'"):
        routines.jit("sinh", precision="full-d4")
    with pytest.raises(ReactorError, match="sin has no precision variant 'full-d3'; its variants are 'full-d6'"):
        routines.jit("sin", precision="full-d3")
    with pytest.raises(ReactorError, match="pow has no precision variant 'full-d3'"):
        routines.jit("pow", precision="full-d3")
