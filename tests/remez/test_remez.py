"""Tests for routines.remez: expression parser, Remez exchange, CLI, retune."""

from __future__ import annotations

import functools
import json

import numpy as np
import pytest
from mpmath import mp, mpf

from routines.remez import (
    ExpressionError,
    RemezError,
    evaluate,
    parse,
    remez,
    retune,
    to_float32,
)
from routines.remez.cli import main

# --- expression parser -------------------------------------------------------


@pytest.mark.parametrize(
    "text, x, expected",
    [
        ("-x^2", 3, "-9"),
        ("2^3^2", 0, "512"),
        ("2^-1", 0, "0.5"),
        ("-2^-x^2", 1, "-0.5"),
        ("1e-3 + .5 + 2.", 0, "2.501"),
        ("(2^x - x - 1) / x", 2, "0.5"),
        ("exp2(x) - exp(log(2) * x)", 0.75, "0"),
        ("log2(8) + sqrt(x) * abs(-2) + erf(0)", 9, "9"),
        ("x/2^23*-4", 2**23, "-4"),
        ("sin(x)^2 + cos(x)^2", 0.7, "1"),
        ("tan(x) - sin(x)/cos(x)", -1.3, "0"),
        ("asin(sin(x)) + acos(cos(x)) + atan(tan(x))", 0.25, "0.75"),
        ("sinh(x) + cosh(x) - exp(x) + tanh(x) - sinh(x)/cosh(x)", 2, "0"),
        ("atan(1)*4 - acos(-1) + asin(1)*2", 0, "3.1415926535897932384626433832795"),
        ("(sin(sqrt(x))-sqrt(x))/x^1.5", 0.25, "-0.164595691166375997813696518275"),
    ],
)
def test_parse_evaluates(text, x, expected):
    with mp.workdps(30):
        assert abs(parse(text)(x) - mpf(expected)) < mpf(10) ** -25


@pytest.mark.parametrize(
    "text, position, fragment",
    [
        ("sec(x)", 0, "unknown name 'sec'"),
        ("atan2(x, 1)", 0, "unknown name 'atan2'"),
        ("(2^x-1/x", 0, "'(' never closed"),
        ("exp((x)", 3, "'(' never closed"),
        ("2^x)", 3, "unexpected ')'"),
        ("x +", 3, "unexpected end"),
        ("2**x", 2, "unexpected '*'"),
        ("exp x", 4, "expected '(' after function 'exp'"),
        ("exp(x, 2)", 5, "exactly one argument"),
        ("__import__('os')", 11, "unexpected character \"'\""),
        ("__import__(x)", 0, "unknown name '__import__'"),
        ("x % 2", 2, "unexpected character '%'"),
        ("   ", 0, "empty expression"),
    ],
)
def test_parse_errors_name_problem_and_position(text, position, fragment):
    with pytest.raises(ExpressionError) as info:
        parse(text)
    assert info.value.position == position
    assert fragment in str(info.value) and f"at position {position}" in str(info.value)
    assert isinstance(info.value, ValueError)


@pytest.mark.parametrize("text, x", [("log(x)", -1), ("sqrt(x)", -1), ("x^0.5", -4), ("log2(x)", 0),
                                     ("asin(x)", 1.5), ("acos(x)", -2), ("asin(x+1)", 0.001)])
def test_domain_errors_raise_instead_of_going_complex(text, x):
    with pytest.raises(ValueError):
        parse(text)(x)


# --- singular points ------------------------------------------------------------


def test_removable_singularities_evaluate_to_their_limit():
    with mp.workdps(50):
        tol = mpf(10) ** -45
        with pytest.raises(ZeroDivisionError):
            parse("(2^x-1)/x")(0)
        assert abs(evaluate(parse("(2^x-1)/x"), mpf(0), mpf(0), mpf(1)) - mp.ln2) < tol
        assert abs(evaluate(parse("(2^x-1)/x"), mpf(0), mpf(-0.5), mpf(0.5)) - mp.ln2) < tol
        assert abs(evaluate(parse("log2(x+1)/x"), mpf(0), mpf(0), mpf(1)) - 1 / mp.ln2) < tol
        assert abs(evaluate(parse("log2(x)/(x-1)"), mpf(1), mpf(1), mpf(2)) - 1 / mp.ln2) < tol
        assert evaluate(parse("1/x"), mpf(0), mpf(0), mpf(1)) == mp.inf
        assert evaluate(parse("log(x)"), mpf(0), mpf(0), mpf(1)) == -mp.inf


def test_singular_function_fit_keeps_the_endpoint_in_the_reference():
    r = remez("(2^x - 1) / x", 0, 1, 4)
    with mp.workdps(50):
        assert r.reference[0] == 0
        assert abs(abs(r(0) - mp.ln2) - r.error) < mpf(10) ** -30


# --- closed forms -----------------------------------------------------------------


def test_degree_one_minimax_of_exp_matches_closed_form():
    r = remez("exp(x)", 0, 1, 1)
    with mp.workdps(50):
        slope = mp.e - 1
        c = mp.log(slope)  # tangent point: exp(c) = slope
        intercept = (1 + slope - slope * c) / 2
        assert abs(r.coefficients[1] - slope) < mpf(10) ** -20
        assert abs(r.coefficients[0] - intercept) < mpf(10) ** -20
        assert abs(r.error - (1 - intercept)) < mpf(10) ** -20  # p(0) - exp(0) = -E
        assert [abs(x - y) < mpf(10) ** -15 for x, y in zip(r.reference, (0, c, 1))] == [True] * 3


@pytest.mark.parametrize("n", [3, 4, 6])
def test_chebyshev_equioscillation(n):
    r = remez(f"x^{n + 1}", -1, 1, n)
    with mp.workdps(50):
        assert abs(r.error - mpf(2) ** -n) < mpf(10) ** -30
        extrema = sorted(mp.cos(k * mp.pi / (n + 1)) for k in range(n + 2))
        assert max(abs(x - y) for x, y in zip(r.reference, extrema)) < mpf(10) ** -15
        # p = x^(n+1) - T_(n+1)(x) / 2^n
        cheb = mp.taylor(lambda x: mp.chebyt(n + 1, x), 0, n + 1)
        for k in range(n + 1):
            assert abs(r.coefficients[k] + cheb[k] / mpf(2) ** n) < mpf(10) ** -30
        signs = [mp.sign(r(x) - x ** (n + 1)) for x in extrema]
        assert all(s * t == -1 for s, t in zip(signs, signs[1:]))


# --- weights -------------------------------------------------------------------


def test_weight_is_a_tolerance_that_shapes_the_error():
    w = "1.5 + 0.5*erf(50*(x - 0.5))"  # ~1 on [0, 0.45], ~2 on [0.55, 1]
    weighted = remez("exp(x)", 0, 1, 3, w)
    plain = remez("exp(x)", 0, 1, 3)
    with mp.workdps(50):
        wf = parse(w)
        e = [(weighted(x) - mp.exp(x)) / wf(x) for x in weighted.reference]
        assert all(abs(abs(v) - weighted.error) < mpf(10) ** -30 for v in e)
        assert all(s * t < 0 for s, t in zip(e, e[1:]))
        grid = [mpf(k) / 400 for k in range(401)]
        left = max(abs(weighted(x) - mp.exp(x)) for x in grid if x <= 0.4)
        right = max(abs(weighted(x) - mp.exp(x)) for x in grid if x >= 0.6)
        assert abs(left / weighted.error - 1) < 1e-3
        assert abs(right / (2 * weighted.error) - 1) < 1e-3
        assert weighted.error < plain.error < 2 * weighted.error


def test_pole_of_the_weight_equioscillates_relative_to_the_weight():
    r = remez("(2^x-1)/x", -0.5, 0.5, 4, "1/x")  # the weight's pole is inside
    with mp.workdps(50):
        e = [(r(x) - (2**x - 1) / x) * abs(x) for x in r.reference]
        assert all(abs(abs(v) - r.error) < mpf(10) ** -30 for v in e)
        assert all(s * t < 0 for s, t in zip(e, e[1:]))
        grid = [mpf(k) / 1000 - mpf(0.5) for k in range(1001) if k != 500]
        assert max(abs(r(x) * x - (2**x - 1)) for x in grid) <= r.error * (1 + mpf(10) ** -20)


# --- failures ------------------------------------------------------------------


@pytest.mark.parametrize(
    "args, kwargs, fragment",
    [
        (("1/(x-0.3)", 0, 1, 3), {"max_iter": 15}, "no convergence after 15 iterations"),
        (("1/(x-0.5)", 0, 1, 3), {}, "pole or non-removable singularity at x = 0.5"),
        (("log(x)", 0, 1, 3), {}, "pole or non-removable singularity at x = 0.0"),
        (("2^x", 0, 1, 5), {"max_iter": 1}, "no convergence after 1 iterations"),
        (("exp(x)", -1, 1, 30), {"dps": 30}, "noise level of dps=30"),
        (("x^2", -1, 1, 2), {}, "noise level"),
        (("exp(x)", 0, 1, 3, "x - 0.5"), {}, "weight x - 0.5 is zero at x = 0.5"),
        (("log(x)", -1, 1, 3), {}, "cannot evaluate log(x)"),
    ],
)
def test_failures_raise_remez_error(args, kwargs, fragment):
    with pytest.raises(RemezError, match=fragment.replace("(", r"\(").replace(")", r"\)")):
        remez(*args, **kwargs)
    assert issubclass(RemezError, ValueError)


# --- result object ---------------------------------------------------------------


def test_result_helpers_and_float32_rounding():
    r = remez("2^x", 0, 1, 5)
    assert r.degree == 5 and r.highest_first == r.coefficients[::-1]
    assert r.float32.dtype == np.float32
    assert [np.float32(s) for s in r.float32_strings] == list(r.float32)
    assert r.float32_strings[::-1] == ("0.0018964611", "0.008942829", "0.055866245", "0.24013971", "0.69315475", "0.9999999")
    assert abs(r.max_error / r.error - 1) < 1e-6 and len(r.reference) == 7
    with mp.workdps(50):
        # 1 + 2^-24 + 2^-60 rounds up, although via a double it would tie down to 1
        assert to_float32(1 + mpf(2) ** -24 + mpf(2) ** -60) == np.float32(1 + 2.0**-23)
        assert to_float32(mpf(3) * mpf(2) ** -150) == np.float32(2.0**-148)  # subnormal, ties to even


# --- the reference document's LolRemez commands ------------------------------------

# (degree, range, f, weight, quoted coefficients highest degree first,
#  binary32 ulps of (ours - quoted) per coefficient).  LolRemez printed its
#  exact coefficients to 8 significant digits and the C compiler rounded those
#  decimals to binary32: the digits match ours exactly, and the double
#  rounding (exact -> 8 digits -> binary32) is 1 ulp off correct rounding
#  where the ulps column is nonzero.
REFERENCE = [
    (5, "0:1", "2^x", None,
     "1.8964611e-3 8.942829e-3 5.5866246e-2 2.4013971e-1 6.9315475e-1 9.9999989e-1", [0, 0, 0, 0, 0, 0]),
    (4, "0:1", "(2^x - 1) / x", None,
     "1.7909619e-3 9.1942073e-3 5.5660287e-2 2.4020655e-1 6.9314759e-1", [0, 0, -1, 0, 0]),
    (4, "0:1", "(2^x-1)/x", "1/x",
     "1.8852974e-3 8.9733787e-3 5.5835927e-2 2.4015281e-1 6.9315247e-1", [0, 0, -1, 0, 0]),
    (4, "-0.5:0.5", "(2^x-1)/x", "1/x",
     "1.3407259e-3 9.6718751e-3 5.5503084e-2 2.4022235e-1 6.9314721e-1", [0, 0, 0, 0, 1]),
    (2, "0:1", "(2^x-1)/x", "1/x",
     "7.8145574e-2 2.2617357e-1 6.9555686e-1", [0, 1, 0]),
    # exp2_relaxed's constants: the same fit as the previous row minus 1
    (2, "0:1", "(2^x-x-1)/x", "1/x",
     "7.8145574e-2 2.2617357e-1 -3.0444314e-1", [0, 1, 0]),
    (4, "0:1", "(2^x-x-1)/x", "1/x",
     "1.8852974e-3 8.9733787e-3 5.5835927e-2 2.4015281e-1 -3.0684753e-1", [0, 0, -1, 0, 0]),
    (5, "1:2", "log2(x)/(x-1)", "1/(x-1)",
     "-2.645745e-2 2.5573874e-1 -1.0379186 2.3021687 -3.0995312 3.048553", [0, 0, 0, 0, 0, 0]),
    (6, "0:1", "(log2(x+1)-x)/x", "1/x",
     "1.5529917e-2 -7.9557731e-2 1.9429432e-1 -3.2590197e-1 4.7355341e-1 -7.2058547e-1 4.4266783e-1",
     [1, 0, 0, -1, 0, 0, 0]),
    (7, "0:1", "(log2(x+1)-x)/x", "1/x",
     "-9.3091638e-3 5.2059003e-2 -1.3752135e-1 2.4186478e-1 -3.4730109e-1 4.786837e-1 -7.2116581e-1 4.4268988e-1",
     [1, 0, 0, 0, 0, 0, 1, 1]),
    (2, "0:2^23", "(log2(x/2^23+1)-x/2^23)/x", "1/x",
     "2.8017103e-22 -8.373131e-15 5.0615534e-8", [0, 0, 0]),
]


@functools.cache
def _fit(degree, interval, f, weight):
    lo, hi = (parse(s)(0) for s in interval.split(":"))
    return remez(f, lo, hi, degree, weight)


def _ulps(a: np.float32, b: np.float32) -> int:
    ia, ib = (int(np.array([v], np.float32).view(np.int32)[0]) for v in (a, b))
    return (ia if ia >= 0 else -(ia & 0x7FFFFFFF)) - (ib if ib >= 0 else -(ib & 0x7FFFFFFF))


@pytest.mark.parametrize("degree, interval, f, weight, quoted, ulps", REFERENCE)
def test_reference_commands_reproduce_lolremez(degree, interval, f, weight, quoted, ulps):
    r = _fit(degree, interval, f, weight)
    quoted = quoted.split()
    assert [mp.nstr(c, 8, min_fixed=0, max_fixed=1) for c in r.highest_first] == quoted
    assert [_ulps(ours, np.float32(q)) for ours, q in zip(r.float32[::-1], quoted)] == ulps


def test_relaxed_exp2_constant_is_the_exp2_fit_minus_one():
    a = _fit(2, "0:1", "(2^x-1)/x", "1/x")
    b = _fit(2, "0:1", "(2^x-x-1)/x", "1/x")
    with mp.workdps(50):
        assert abs(b.coefficients[0] - (a.coefficients[0] - 1)) < mpf(10) ** -40
        assert all(abs(x - y) < mpf(10) ** -40 for x, y in zip(a.coefficients[1:], b.coefficients[1:]))


# --- command line ----------------------------------------------------------------

EXPECTED_TEXT = """\
// Approximation of f(x) = (2^x-x-1)/x
// with weight function g(x) = 1/x
// on interval [ 0, 1 ]
// with a polynomial of degree 4.
// p(x)=(((1.8852974e-3*x+8.9733787e-3)*x+5.5835927e-2)*x+2.4015281e-1)*x-3.0684753e-1
// Max weighted error: 1.1799807e-7
float f(float x)
{
    float u = 1.8852974e-3f;
    u = u * x + 8.973379e-3f;
    u = u * x + 5.5835925e-2f;
    u = u * x + 2.401528e-1f;
    return u * x + -3.0684754e-1f;
}
"""


def test_cli_prints_lolremez_style_c_code(capsys):
    assert main(["-d", "4", "-r", "0:1", "(2^x-x-1)/x", "1/x"]) == 0
    assert capsys.readouterr().out == EXPECTED_TEXT


def test_cli_without_weight_and_negative_range(capsys):
    assert main(["--float", "-d", "2", "-r", "-0.5:0.5", "exp(x)"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[:3] == ["// Approximation of f(x) = exp(x)", "// on interval [ -0.5, 0.5 ]", "// with a polynomial of degree 2."]
    assert out[3].startswith("// p(x)=(") and out[-1] == "}" and out[-2].startswith("    return u * x + ")


def test_cli_json(capsys):
    assert main(["-d", "2", "-r", "0:2^23", "(log2(x/2^23+1)-x/2^23)/x", "1/x", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["coefficients"] == ["2.8017103e-22", "-8.373131e-15", "5.0615533e-08"]
    assert [np.float32(c) for c in data["coefficients"]] == list(_fit(2, "0:2^23", data["function"], "1/x").float32[::-1])
    assert data["error"] == pytest.approx(7.7095112e-4, rel=1e-7)
    assert data["degree"] == 2 and data["interval"] == [0.0, 2.0**23] and data["weight"] == "1/x"
    assert len(data["coefficients_exact"]) == 3 and len(data["reference"]) == 4


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["-d", "4", "-r", "0:1", "sec(x)"], "invalid function: unknown name 'sec'"),
        (["-d", "4", "-r", "0:1", "(2^x-1/x"], "unbalanced parenthesis: '(' never closed at position 0"),
        (["-d", "4", "-r", "0:1", "exp(x)", "1/(x"], "invalid weight function: unbalanced parenthesis"),
        (["-d", "0", "-r", "0:1", "x"], "invalid degree 0"),
        (["-d", "4", "-r", "1:0", "x"], "xmin must be less than xmax"),
        (["-d", "4", "-r", "0;1", "x"], "expected XMIN:XMAX"),
        (["-d", "4", "-r", "0:x", "exp(x)"], "xmax 'x' must be a constant"),
        (["-d", "4", "-r", "0:1/0", "exp(x)"], "cannot evaluate xmax '1/0'"),
        (["-d", "4", "-r", "0:(1", "exp(x)"], "invalid range xmax"),
        (["-d", "four", "exp(x)"], "invalid int value"),
        ([], "required: function"),
    ],
)
def test_cli_bad_input_exits_2_with_a_message(argv, fragment, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert fragment in err and "Traceback" not in err


def test_cli_fit_failure_exits_1(capsys):
    assert main(["-d", "3", "-r", "0:1", "1/(x-0.5)"]) == 1
    assert "pole or non-removable singularity" in capsys.readouterr().err
    assert main(["-d", "2", "-r", "0:2", "asin(x)"]) == 1  # outside asin's domain past x = 1
    assert "cannot evaluate" in capsys.readouterr().err


def test_cli_fits_the_trig_polynomials_in_z(capsys):
    """The odd functions of routines/trig.py in z = r^2, as their recorded commands state
    (tests/routines/test_trig.py reruns every one): sin's relaxed polynomial."""
    from routines import polynomials as P

    poly = P.SIN_RELAXED
    assert poly.remez_command() in poly.provenance
    lo, hi = poly.interval
    assert main(["-d", str(poly.degree), "-r", f"{lo}:{hi}", poly.function, poly.weight, "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert tuple(data["coefficients"]) == poly.coefficients
    assert data["error"] == pytest.approx(2.1e-6, rel=0.05)  # 2^-18.9, as the provenance says


# --- retune -----------------------------------------------------------------------


def _nudge(v: float, ulps: int) -> np.float32:
    v = np.float32(v)
    for _ in range(abs(ulps)):
        v = np.nextafter(v, np.float32(np.inf if ulps > 0 else -np.inf))
    return v


def test_retune_walks_to_the_minimum_in_ulp_steps():
    start = np.array([1.0, 0.5, -0.25], dtype=np.float32)
    target = np.array([_nudge(1.0, 3), _nudge(0.5, -2), _nudge(-0.25, 0)], dtype=np.float32)

    def err(c):
        return float(sum(abs(_ulps(x, y)) for x, y in zip(c, target)))

    result = retune(start, err)
    assert result.initial_error == 5 and result.error == 0
    assert list(result.coefficients) == list(target) and result.coefficients.dtype == np.float32
    capped = retune(start, err, max_ulps=1)
    assert capped.error == 3


def test_retune_with_float32_horner_error():
    fit = remez("2^x", 0, 1, 5)
    xs = np.linspace(0, 1, 2049, dtype=np.float32)
    exact = np.exp2(xs.astype(np.float64))

    def err(c):  # c: lowest degree first; max error in ulps of [1, 2)
        u = np.full_like(xs, c[-1])
        for k in c[-2::-1]:
            u = u * xs + k
        return float(np.max(np.abs(u.astype(np.float64) - exact)) / 2.0**-23)

    result = retune(fit.float32, err, max_evals=150)
    assert result.error <= result.initial_error < 3
    assert result.evaluations <= 150
    assert max(abs(_ulps(a, b)) for a, b in zip(result.coefficients, fit.float32)) <= 64
