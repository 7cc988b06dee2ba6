"""The DSL misuse catalogue: each mistake, the exception it gets, its message, and
that the message points at the offending line of the user's code.

``python tests/reliability/test_misuse.py`` prints the catalogue as the Markdown
table of docs/reliability.md.
"""
import os

import numpy as np
import pytest

import reactor
from reactor import (
    Any, ArgumentError, ArityError, As, ControlFlowError, DSLTypeError, Elif, Else, Extract, Float,
    Bool, Float4, Float8, Fma, FmaDisabledError, For, Function, If, Int, Int8, MissingReturnError, Pointer,
    ReactorError, Return, ScopeError, Select, Variable, WidthMismatchError, While, kernel,
)

CATALOGUE = []


def case(mistake: str, exc: type, *words: str):
    """Register a mistake: running the function must raise exactly ``exc`` with ``words``
    in its message, located at the line of this file ending with ``# <function name>``."""
    def register(fn):
        CATALOGUE.append((mistake, exc, words, fn))
        return fn
    return register


# -- types and widths -------------------------------------------------------------------------

@case("mixing Float with Int", DSLTypeError, "operator '+'", "Float and Int", "Float(i)")
def m_float_plus_int():
    def f(x: Float, i: Int) -> Float:
        return x + i  # m_float_plus_int
    Function(f).compile()


@case("mixing vector widths", WidthMismatchError, "Min", "Float4 and Float8")
def m_mixed_widths():
    def f(x: Float4, y: Float8) -> Float4:
        return reactor.Min(x, y)  # m_mixed_widths
    Function(f).compile()


@case("a float constant in integer arithmetic", DSLTypeError, "float 1.5", "Int")
def m_float_constant_in_int():
    def f(i: Int) -> Int:
        return i + 1.5  # m_float_constant_in_int
    Function(f).compile()


@case("an integer constant wider than 32 bits", DSLTypeError, "does not fit in 32 bits")
def m_wide_constant():
    def f(i: Int) -> Int:
        return i * 2**40  # m_wide_constant
    Function(f).compile()


@case("an operator the kind lacks (% on Bool)", DSLTypeError, "not defined for Bool")
def m_bool_remainder():
    def f(x: Float) -> Bool:
        m = x > 0.0
        return m % m  # m_bool_remainder
    Function(f).compile()


@case("ordering masks", DSLTypeError, "ordering comparison '<' of masks")
def m_mask_order():
    def f(x: Float4) -> Float4:
        m = x > 0.0
        return Select(m < m, x, -x)  # m_mask_order
    Function(f).compile()


@case("a bit cast between different sizes", DSLTypeError, "sizes differ", "256 vs 128")
def m_bitcast_size():
    def f(x: Float4) -> Float4:
        return As(Int8, x)  # m_bitcast_size
    Function(f).compile()


@case("Select without a mask", DSLTypeError, "Select needs a Bool mask")
def m_select_without_mask():
    def f(x: Float) -> Float:
        return Select(x, x, -x)  # m_select_without_mask
    Function(f).compile()


@case("a lane index out of range", DSLTypeError, "lane index 4 out of range for Float4")
def m_lane_out_of_range():
    def f(x: Float4) -> Float:
        return Extract(x, 4)  # m_lane_out_of_range
    Function(f).compile()


@case("Fma in a build without FMA", FmaDisabledError, "fma=False", "MulAdd")
def m_fma_disabled():
    def f(x: Float) -> Float:
        return Fma(x, x, 1.0)  # m_fma_disabled
    Function(f, fma=False).compile()


# -- values and variables ---------------------------------------------------------------------

@case("assigning to a value (an argument or constant)", DSLTypeError, "cannot be assigned", "Variable(Float")
def m_assign_to_value():
    def f(x: Float) -> Float:
        c = Float(1.0)
        c.set(x)  # m_assign_to_value
        return c
    Function(f).compile()


@case("changing a lane of a value in place", DSLTypeError, "cannot be changed in place", "Insert(v, x, 0)")
def m_lane_assignment():
    def f(x: Float4) -> Float4:
        x[0] = 1.0  # m_lane_assignment
        return x
    Function(f).compile()


@case("storing another kind into a Variable", DSLTypeError, "expected Float, got Int")
def m_variable_kind():
    def f(x: Float, i: Int) -> Float:
        v = Variable(Float, 0.0)
        v.set(i)  # m_variable_kind
        return v
    Function(f).compile()


@case("storing a vector into a scalar Variable", WidthMismatchError, "Float4 cannot become a Float")
def m_variable_width():
    def f(x: Float4) -> Float:
        v = Variable(Float, 0.0)
        v.set(x)  # m_variable_width
        return v
    Function(f).compile()


@case("a Python number as a Variable's type", DSLTypeError, "Variable needs a DSL type or value")
def m_variable_of_number():
    def f(x: Float) -> Float:
        v = Variable(3.0)  # m_variable_of_number
        return x + v
    Function(f).compile()


@case("a value as a Python list index", DSLTypeError, "cannot index a Python list or tuple, or count a range")
def m_value_as_index():
    def f(i: Int) -> Float:
        return [1.0, 2.0][i]  # m_value_as_index
    Function(f).compile()


@case("a non-integer pointer index", DSLTypeError, "pointer index must be an int or an Int value")
def m_pointer_index():
    def f(p: Pointer[Float]) -> Float:
        return p[1.5]  # m_pointer_index
    Function(f).compile()


# -- scopes -------------------------------------------------------------------------------------

@case("a value from another function", ScopeError, "from function 'g'", "while building 'h'")
def m_value_from_other_function():
    leaked = []

    def g(x: Float) -> Float:
        leaked.append(x * 2.0)
        return x

    def h(x: Float) -> Float:
        return leaked[0] + x  # m_value_from_other_function

    Function(g).compile()
    Function(h).compile()


@case("a DSL operation outside any function", ScopeError, "outside a function being built")
def m_operation_outside_function():
    Float(1.0)  # m_operation_outside_function


@case("a loop variable used after its loop", ScopeError, "inside a 'For' block", "after that block ended")
def m_counter_after_loop():
    def f(n: Int) -> Int:
        with For(0, n) as i:
            pass
        return i + 1  # m_counter_after_loop
    Function(f).compile()


@case("a value from inside an If used after it", DSLTypeError, "'y' is assigned on some paths", "give it a value before")
def m_value_after_if():
    def f(x: Float) -> Float:
        with If(x > 0.0):
            y = x * 2.0
        return y  # m_value_after_if
    Function(f).compile()


@case("a value computed between If and Elif used after the chain", ScopeError,
      "between the blocks of an If/Elif chain")
def m_value_between_if_and_elif():
    def f(x: Float) -> Float:
        r = Variable(Float, 0.0)
        with If(x < 0.0):
            r.set(1.0)
        big = x > 10.0
        with Elif(big):
            r.set(2.0)
        return Select(big, r, 0.0)  # m_value_between_if_and_elif
    Function(f).compile()


# -- control flow -------------------------------------------------------------------------------

@case("a block created without 'with' (If(c) alone)", ControlFlowError, "never entered", "with If(...)")
def m_unentered_block():
    def f(x: Float) -> Float:
        If(x > 0.0)  # m_unentered_block
        return x
    Function(f).compile()


@case("an unclosed block (entered, never exited)", ControlFlowError, "'For' block entered but never closed")
def m_unclosed_block():
    def f(n: Int) -> Int:
        For(0, n).__enter__()  # m_unclosed_block
        return n
    Function(f).compile()


@case("blocks closed out of order", ControlFlowError, "closed out of order", "opened at line")
def m_blocks_out_of_order():
    def f(x: Float) -> Float:
        outer, inner = If(x > 0.0), If(x > 1.0)
        outer.__enter__()
        inner.__enter__()
        outer.__exit__(None, None, None)  # m_blocks_out_of_order
        return x
    Function(f).compile()


@case("Else without If", ControlFlowError, "Else must directly follow an If")
def m_orphan_else():
    def f(x: Float) -> Float:
        with Else():  # m_orphan_else
            pass
        return x
    Function(f).compile()


@case("a Python bool as a condition", DSLTypeError, "Python bool", "plain Python 'if'")
def m_python_bool_condition():
    def f(x: Float) -> Float:
        with If(True):  # m_python_bool_condition
            pass
        return x
    Function(f).compile()


@case("a uniform Variable assigned under a per-lane If", ControlFlowError, "per-lane condition of 4 lanes",
      "Variable(Float4")
def m_uniform_under_mask():
    def f(x: Float4) -> Float4:
        total = Variable(Float, 0.0)
        with If(x > 0.0):
            total.set(1.0)  # m_uniform_under_mask
        return x
    Function(f).compile()


@case("Python's max on DSL values", DSLTypeError, "no Python truth value", "reactor.Max")
def m_python_max():
    def f(x: Float) -> Float:
        return max(x, 1.0)  # m_python_max
    Function(f).compile()


@case("a name set on one path of a run-time 'if', read after it", DSLTypeError,
      "'y' is assigned on some paths of a run-time 'if' only")
def m_one_path():
    def f(x: Float) -> Float:
        if x > 0.0:
            y = x
        return y  # m_one_path
    Function(f).compile()


@case("a While condition evaluated once", DSLTypeError, "re-evaluated every iteration", "lambda")
def m_while_value():
    def f(i: Int) -> Int:
        with While(i < 3):  # m_while_value
            pass
        return i
    Function(f).compile()


@case("a For step of zero", DSLTypeError, "For step must be a non-zero Python int")
def m_for_step_zero():
    def f(n: Int) -> Int:
        with For(0, n, 0):  # m_for_step_zero
            pass
        return n
    Function(f).compile()


@case("float For bounds", DSLTypeError, "float 0.5 used where an integer Int is expected")
def m_for_float_bounds():
    def f(n: Int) -> Int:
        with For(0.5, n):  # m_for_float_bounds
            pass
        return n
    Function(f).compile()


# -- returns ------------------------------------------------------------------------------------

@case("Return of the wrong type", DSLTypeError, "Return of a Float8", "returns Float4")
def m_return_wrong_type():
    def f(x: Float) -> Float4:
        Return(Float8(x))  # m_return_wrong_type
    Function(f).compile()


@case("Python return of the wrong kind", DSLTypeError, "Return of a Float", "returns Int")
def m_python_return_kind():
    def f(x: Float) -> Int:
        return x * 2.0  # m_python_return_kind
    Function(f).compile()


@case("Return without a value where one is due", DSLTypeError, "Return without a value", "returns Float")
def m_return_nothing():
    def f(x: Float) -> Float:
        Return()  # m_return_nothing
    Function(f).compile()


@case("Return with a value in a function returning nothing", DSLTypeError, "Return with a value")
def m_return_value_from_void():
    def f(x: Float):
        Return(x)  # m_return_value_from_void
    Function(f, returns=None).compile()


@case("a path without Return", MissingReturnError, "returns Float", "without Return")
def m_missing_return():
    def f(x: Float) -> Float:  # m_missing_return
        with If(x > 0.0):
            Return(x)
    Function(f).compile()


def _helper_returning(x):
    if x > 0.0:
        return x * 2.0  # m_helper_return
    return x


@case("a run-time return in a helper called where the rewrite does not see the call (in a lambda)",
      ControlFlowError, "a helper called from the body", "@reactor.inline")
def m_helper_return():
    def f(x: Float) -> Float:
        return (lambda v: reactor.syntax(_helper_returning)(v))(x)
    Function(f).compile()


@case("a kernel Return with too few results", DSLTypeError, "Return of 1 value(s)", "gives 2")
def m_return_in_kernel():
    def body(x: Float) -> (Float, Float):
        with If(x < 0.0):
            Return(x)  # m_return_in_kernel
        return x, x
    kernel(body, name="misuse_return")


@case("a kernel returning too few results", DSLTypeError, "returned 1 value(s)", "2 output(s)")
def m_kernel_outputs():
    def body(x: Float) -> (Float, Float):
        return x  # m_kernel_outputs
    kernel(body, name="misuse_outs")


# -- calls and options ------------------------------------------------------------------------

@case("calling a function with the wrong number of arguments", ArityError, "takes 2 argument(s), got 1")
def m_dsl_arity():
    def add(x: Float, y: Float) -> Float:
        return x + y
    g = Function(add)

    def caller(x: Float) -> Float:
        return g(x)  # m_dsl_arity
    Function(caller).compile()


@case("calling a routine with the wrong number of arguments", ArityError, "takes 2 argument(s) (x, y), got 3")
def m_routine_arity():
    def add(x: Float, y: Float) -> Float:
        return x + y
    Function(add)(1.0, 2.0, 3.0)  # m_routine_arity


@case("a routine argument of the wrong dtype", ArgumentError, "dtype float32, not float64")
def m_routine_dtype():
    def first(p: Pointer[Float]) -> Float:
        return p[0]
    Function(first)(np.zeros(4))  # m_routine_dtype


@case("a vector width that does not exist", ReactorError, "SIMD width must be 1, 4, 8 or 16")
def m_bad_width():
    def f(x: Float) -> Float:
        return x
    Function(f, width=3).compile()  # m_bad_width


@case("an unknown build option", ReactorError, "unknown build option(s): fast")
def m_unknown_option():
    def f(x: Float) -> Float:
        return x
    Function(f, fast=True).compile()  # m_unknown_option


# -- the tests ------------------------------------------------------------------------------------

def _line(marker: str) -> int:
    lines = open(__file__).read().splitlines()
    hits = [k + 1 for k, line in enumerate(lines) if line.rstrip().endswith(f"# {marker}")]
    assert len(hits) == 1, (marker, hits)
    return hits[0]


@pytest.mark.parametrize("mistake, exc, words, fn", CATALOGUE, ids=[c[3].__name__ for c in CATALOGUE])
def test_misuse(mistake, exc, words, fn):
    with pytest.raises(ReactorError) as info:
        fn()
    err = info.value
    assert type(err) is exc, f"{mistake}: {type(err).__name__}: {err}"
    for word in words:
        assert word in str(err), (word, str(err))
    line = _line(fn.__name__)
    assert err.location == (__file__, line), (err.location, line)
    assert f"{os.path.basename(__file__)}:{line}" in str(err)


def test_catalogue_is_large_and_distinct():
    assert len(CATALOGUE) >= 40
    assert len({c[0] for c in CATALOGUE}) == len(CATALOGUE)


def test_failed_builds_leave_no_state_behind():
    """After every mistake, building and running correct code on the same thread works
    (no emitter left on the thread's stack, no half-built function cached)."""
    for _, _, _, fn in CATALOGUE:
        with pytest.raises(ReactorError):
            fn()
    assert not reactor.ir.emitter.building()

    def ok(x: Float) -> Float:
        return x + 1.0
    assert Function(ok)(2.0) == 3.0


def markdown_table() -> str:
    rows = ["| mistake | exception | message |", "|---|---|---|"]
    for mistake, exc, _, fn in CATALOGUE:
        try:
            fn()
        except ReactorError as err:
            msg = err.problem.replace("|", "\\|")
            rows.append(f"| {mistake} | `{type(err).__name__}` | {msg} |")
    return "\n".join(rows)


if __name__ == "__main__":
    print(markdown_table())
