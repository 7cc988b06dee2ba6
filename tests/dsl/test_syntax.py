"""@reactor.syntax: Python's own ``if``/``elif``/``else`` on per-lane values, checked lane by lane
against NumPy; a condition that is a Python value stays Python's; what cannot be honoured is an
error naming the user's line."""
import numpy as np
import pytest

import reactor
from reactor import Break, ControlFlowError, DSLTypeError, Float, For, Int, Variable, kernel, syntax, vec3

X = np.linspace(-3, 3, 1003, dtype=np.float32)  # a tail after the vector loop too


@kernel
@syntax
def branches(x: Float) -> Float:
    if x < -1.0:
        r = 2.0                      # a Python number, in the lanes of this branch only
    elif x > 1.0:
        r = x * x
        if x > 2.5:
            return x * 10.0          # these lanes' result
    else:
        return x                     # per lane
    return r + 1.0


def test_if_elif_else_per_lane_as_numpy():
    want = np.where(X < -1, 3.0, np.where(X > 2.5, X * 10, np.where(X > 1, X * X + 1, X))).astype(np.float32)
    assert np.array_equal(branches(X), want)


WIDE = True


@kernel
@syntax
def python_condition(x: Float) -> Float:
    if WIDE:                         # a Python value: decided while building, one branch traced
        y = x * 2.0
    else:
        y = x
    return y


def test_a_python_condition_stays_pythons():
    assert np.array_equal(python_condition(X), X * 2)


@kernel
@syntax
def walk(x: Float) -> Float:
    t = Variable(Float, x)
    with For(0, 40):
        if t > 2.0:
            Break()                  # per lane, in the run-time loop around
        t.set(t + 0.25)
    return t


def test_an_if_in_a_run_time_loop_breaks_per_lane():
    t = X.copy()
    for _ in range(40):
        t = np.where(t > 2.0, t, t + np.float32(0.25))
    assert np.array_equal(walk(X), t)


@kernel
@syntax
def colour(x: Float) -> vec3:
    if x > 0.0:
        c = vec3(x, 1.0, 0.0)
    else:
        c = vec3(0.0, -x, 1.0)
    return c


def test_vectors_differ_per_lane():
    got = colour(X)
    want = np.where((X > 0)[:, None], np.stack([X, np.ones_like(X), np.zeros_like(X)], -1),
                    np.stack([np.zeros_like(X), -X, np.ones_like(X)], -1))
    assert np.array_equal(got, want.astype(np.float32))


@reactor.function
@syntax
def clamp_up(k: Int) -> Int:
    if k < 10:                       # a scalar Bool in a Function: a real branch
        k = k + 100
    return k * 2


def test_a_scalar_condition_branches():
    assert [clamp_up(k) for k in (3, 10, 42)] == [206, 20, 84]


def _build(body):
    return kernel(syntax(body), name=body.__name__)


def test_a_name_set_on_one_path_only_is_an_error_naming_it():
    def one_path(x: Float) -> Float:
        if x > 0.0:
            y = x
        return y * 2.0

    with pytest.raises(DSLTypeError, match="'y' is assigned on some paths of a run-time 'if' only") as err:
        _build(one_path)
    assert err.value.location[0] == __file__


def test_a_python_object_assigned_per_lane_is_an_error_when_used():
    def listed(x: Float) -> Float:
        parts = []
        if x > 0.0:
            parts = [x, x]
        return parts[0]

    with pytest.raises(DSLTypeError, match="'parts' was assigned a list under a run-time condition"):
        _build(listed)


def test_mutating_a_value_under_a_run_time_condition_is_refused():
    def mutate(x: Float) -> vec3:
        c = vec3(x, x, x)
        if x > 0.0:
            c.x = 1.0
        return c

    with pytest.raises(DSLTypeError, match="'c.x = ...' under a run-time condition"):
        _build(mutate)


def test_a_range_loop_that_breaks_runs_at_run_time_and_a_python_loop_that_breaks_per_lane_is_refused():
    @kernel
    def doubling(x: Float) -> Float:
        y = x
        for _ in range(3):           # a break of its own: a run-time loop over 0..2, as GLSL's
            if y > 1.0:
                break
            y = y * 2.0
        return y

    def twice(v):
        for _ in range(3):
            if v > 1:
                break
            v = np.float32(v * 2)
        return v
    assert np.array_equal(doubling(X), np.array([twice(v) for v in X], np.float32))

    def over_a_list(x: Float) -> Float:
        y = x
        for scale in (2.0, 3.0):     # Python's loop over Python values: it runs while building
            if y > 1.0:
                break
            y = y * scale
        return y

    with pytest.raises(ControlFlowError, match="'break' under a run-time condition leaves a Python loop"):
        _build(over_a_list)


def test_every_body_is_traced_as_written():
    """Kernels and Functions rewrite their bodies' control flow without the decorator."""
    def plain(x: Float) -> Float:
        if x > 0.0:
            return x
        return -x

    assert np.array_equal(kernel(plain, name="plain")(X), np.abs(X))


@kernel
@syntax
def halvings(x: Float) -> Float:
    v = x
    n = 0.0
    while v > 1.0:                   # a run-time loop, per lane
        v = v * 0.5
        n += 1.0
        if n > 3.0:
            break                    # per lane
        if v < 1.5:
            continue
        v = v - 0.125
    return v + n * 100.0


def test_a_while_loop_with_break_and_continue_per_lane():
    v = np.abs(X) * 3
    want = []
    for x0 in v:
        w, n = np.float32(x0), np.float32(0)
        while w > 1:
            w, n = w * np.float32(0.5), n + 1
            if n > 3:
                break
            if w < 1.5:
                continue
            w = w - np.float32(0.125)
        want.append(w + n * np.float32(100))
    assert np.array_equal(halvings(v), np.array(want, np.float32))


@kernel
@syntax
def sum_to(x: Float, k: Int) -> Float:
    total = 0.0
    for i in range(k):               # a per-lane bound: a run-time For
        if i == 5:
            continue
        total += x * Float(i)
    for j in range(3):               # Python ints: unrolled while building
        total = total + 1.0
    return total


def test_for_range_with_a_per_lane_bound():
    k = (np.arange(X.size) % 9).astype(np.int32)
    want = np.array([x * sum(i for i in range(n) if i != 5) + 3 for x, n in zip(X, k)], np.float32)
    assert np.allclose(sum_to(X, k), want, rtol=1e-6, atol=1e-5)


@kernel
@syntax
def first_above(x: Float) -> Float:
    v = x
    while v < 100.0:
        v = v * 2.0 + 1.0
        if v > 50.0:
            return -v                # per lane, from inside the loop
    return v


def test_a_return_inside_a_run_time_loop():
    want = []
    for x0 in np.abs(X):
        v = np.float32(x0)
        out = None
        while v < 100:
            v = v * np.float32(2) + np.float32(1)
            if v > 50:
                out = -v
                break
        want.append(v if out is None else out)
    assert np.array_equal(first_above(np.abs(X)), np.array(want, np.float32))


def test_a_name_first_assigned_in_a_run_time_loop_is_an_error_after_it():
    def late(x: Float) -> Float:
        v = x
        while v < 10.0:
            step = v * 0.5
            v = v + step + 1.0
        return step

    with pytest.raises(DSLTypeError, match="'step' is first assigned in a run-time loop"):
        _build(late)


def test_a_run_time_loops_counter_has_no_value_after_it():
    def counter(x: Float, k: Int) -> Float:
        i = 0
        for i in range(k):
            x = x + 1.0
        return x * Float(i)

    with pytest.raises(DSLTypeError, match="'i' is the counter of a run-time loop"):
        _build(counter)


@reactor.inline
@syntax
def _soft_sign(v):
    if v < 0.0:
        return v * 0.5              # returns from the helper, per lane
    return v * 2.0


@kernel
@syntax
def uses_inline_helper(x: Float) -> Float:
    y = _soft_sign(x)
    if y > 3.0:
        return y - 100.0
    return y + 1.0


def test_an_inline_helpers_return_returns_from_the_helper():
    y = np.where(X < 0, X * np.float32(0.5), X * np.float32(2))
    assert np.array_equal(uses_inline_helper(X), np.where(y > 3, y - 100, y + 1).astype(np.float32))


@syntax
def _plain_helper(v):
    if v < 0.0:
        return v * 0.5
    return v


def _glsl_like_helper(v, w):          # a plain function, as a GLSL author writes one
    for _ in range(4):
        if v > w:
            return v                 # per lane: these lanes leave the helper with v
        v = v * 2.0
    return -v


def test_a_plain_helpers_returns_return_from_it_per_lane():
    @kernel
    def calls_plain(x: Float) -> Float:
        return _glsl_like_helper(x, 1.0) + _plain_helper(x)

    def want(v):
        for _ in range(4):
            if v > 1:
                return v
            v = np.float32(v * 2)
        return -v
    expected = np.array([want(v) for v in X], np.float32) + np.where(X < 0, X * np.float32(0.5), X)
    assert np.array_equal(calls_plain(X), expected)


def test_a_helpers_run_time_return_where_the_call_is_not_rewritten_is_refused():
    def calls_in_a_lambda(x: Float) -> Float:
        return (lambda v: _plain_helper(v))(x) + 1.0  # a lambda's calls are not rewritten

    with pytest.raises(ControlFlowError, match="decorate '_plain_helper' with @reactor.inline"):
        kernel(calls_in_a_lambda, name="calls_in_a_lambda")


@kernel
def logic(x: Float, y: Float) -> Float:
    inside = x > -1.0 and x < 1.0            # a mask: both sides, per lane
    r = 2.0 if inside else -2.0              # per lane
    if not inside or y > 2.0:
        r = r * 10.0
    if -0.5 < y < 0.5:                       # a chained comparison, per lane
        r = r + 1000.0
    return r + (1.0 if WIDE and True else 0.0)   # Python values: Python's meaning


def test_and_or_not_conditional_expressions_and_chains_per_lane():
    y = X[::-1].copy()
    inside = (X > -1) & (X < 1)
    r = np.where(inside, 2.0, -2.0)
    r = np.where(~inside | (y > 2), r * 10, r)
    r = np.where((y > -0.5) & (y < 0.5), r + 1000, r) + 1
    assert np.array_equal(logic(X, y), r.astype(np.float32))


# -- the with forms: names assigned in a with If/For/While block are per lane too -----------------

from reactor import Elif, Else, If, While  # noqa: E402


@kernel
def march_with_for(x: Float) -> Float:
    alpha = 1.0                      # a Python float before the loop
    with For(0, 4):
        alpha *= 0.5                 # runs per iteration, not once at build time
    return alpha * x


@kernel
def set_in_with_if(x: Float) -> Float:
    r = 1.0
    with If(x < 0.0):
        r = 2.0                      # the lanes of the If only
    return r


@kernel
def with_chain(x: Float) -> Float:
    with If(x < 0.0):
        r = 2.0
    with Elif(x > 1.0):
        r = x * x
    with Else():
        r = x                        # every branch assigns r: it has a value after the chain
    hit = False
    with If(x > 2.5):
        hit = True                   # a Python bool: a Bool per lane
    with If(hit):
        r = r + 100.0
    return r + 1.0


@kernel
def with_while(x: Float) -> Float:
    v = x
    with While(lambda: v < 100.0):   # the lambda reads v's value at each test
        v = v * 2.0 + 1.0
    return v


@kernel
def with_for_break(x: Float) -> Float:
    s = 0.0
    with For(0, 10):
        s = s + x
        with If(s > 3.0):
            Break()
    return s


@kernel
def variable_in_with_while(x: Float) -> Float:
    k = Variable(Float, 0.0)
    with While(lambda: k < x):
        k += 1.0                     # a Variable changed in place, as before
    return k


def test_names_assigned_in_with_blocks_are_per_lane():
    x = np.linspace(0.5, 60.0, 37, dtype=np.float32)
    assert np.array_equal(march_with_for(x), x * np.float32(0.0625))
    signed = np.linspace(-3, 3, 37, dtype=np.float32)
    assert np.array_equal(set_in_with_if(signed), np.where(signed < 0, 2.0, 1.0).astype(np.float32))
    r = np.where(signed < 0, 2.0, np.where(signed > 1, signed * signed, signed)).astype(np.float32)
    want = np.where(signed > 2.5, r + np.float32(100), r) + np.float32(1)
    assert np.array_equal(with_chain(signed), want.astype(np.float32))

    def doubled(v):
        while v < 100:
            v = np.float32(v * np.float32(2) + np.float32(1))
        return v
    assert np.array_equal(with_while(x), np.array([doubled(v) for v in x], np.float32))

    def summed(v):
        s = np.float32(0)
        for _ in range(10):
            s = np.float32(s + v)
            if s > 3:
                break
        return s
    assert np.array_equal(with_for_break(x), np.array([summed(v) for v in x], np.float32))
    assert np.array_equal(variable_in_with_while(x), np.ceil(x))


def test_a_name_set_in_some_branches_of_a_with_chain_is_an_error_naming_it():
    def f(x: Float) -> Float:
        with If(x < 0.0):
            r = 2.0
        with Elif(x > 1.0):
            r = x
        return r  # no Else: r has no value in the other lanes

    with pytest.raises(DSLTypeError, match="'r' is assigned on some paths of a run-time 'if' only") as info:
        kernel(f)
    assert "test_syntax.py" in str(info.value)


def test_rebinding_a_variables_name_under_a_run_time_condition_says_set():
    def f(x: Float) -> Float:
        v = Variable(Float, 0.0)
        with For(0, 3):
            v = v + x  # rebinds the name: the Variable would not change
        return v

    with pytest.raises(DSLTypeError, match=r"write 'v.set\(...\)'"):
        kernel(f)

    def g(x: Float) -> Float:
        v = Variable(Float, 0.0)
        if x > 0.0:
            v = x
        return v

    with pytest.raises(DSLTypeError, match=r"rebinds the name of a Variable"):
        kernel(g)


def test_a_recursive_function_with_run_time_blocks_calls_itself():
    from reactor import Module

    mod = Module()

    @mod.function
    def fact(n: Int) -> Int:
        if n <= 1:
            return 1
        return n * fact(n - 1)

    assert mod.compile().fact(10) == 3628800


@kernel
def halve_until_small(x: Float) -> Float:
    while reactor.hint(x > 1.0, max_iterations=8):  # Dr.Jit's spelling of a bound
        x = x * 0.5
    return x


def test_a_plain_while_bounded_by_hint_stops_with_a_message_naming_its_line():
    x = np.array([0.5, 3.0, 200.0], np.float32)
    assert np.array_equal(halve_until_small(x), np.array([0.5, 0.75, 0.78125], np.float32))
    with pytest.raises(reactor.LoopLimitError, match=r"test_syntax.py:\d+.*8 iterations"):
        halve_until_small(np.array([1e6], np.float32))  # 20 halvings needed
    with pytest.raises(DSLTypeError, match="max_iterations must be a positive int"):
        reactor.hint(True, max_iterations=0)


SCALE = 3.0


@kernel
def python_branch_objects(x: Float) -> Float:
    if SCALE > 2.0:                  # Python's condition: its branch runs as Python runs it
        import math
        factors = [SCALE, 0.5]
        factors.append(2.0)          # a Python object changed under a Python condition: fine
    else:
        factors = []
    return x * (factors[0] * factors[2]) + math.sqrt(4.0)


def test_a_python_conditions_branch_binds_and_changes_python_objects():
    assert np.array_equal(python_branch_objects(X), X * np.float32(6) + np.float32(2))


def test_a_planted_rewrite_in_the_disk_cache_is_never_run(tmp_path, monkeypatch):
    """The rewrite is kept in the disk cache (authenticated, as compiled kernels are): an entry
    replaced by other code is a miss, rewritten anew, never executed."""
    import importlib.util
    import marshal

    from reactor.dsl import syntax as written
    from reactor.jit import cache

    monkeypatch.setenv("REACTOR_CACHE_DIR", str(tmp_path / "cache"))
    source = tmp_path / "planted_body.py"
    source.write_text("from reactor import Float\n\n\ndef body(x: Float) -> Float:\n"
                      "    if x > 1.0:\n        return x * 2.0\n    return x\n")
    spec = importlib.util.spec_from_file_location("planted_body", source)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    x = np.array([0.5, 3.0], np.float32)
    assert np.array_equal(kernel(module.body, name="planted", cache=True)(x), [0.5, 6.0])
    entries = list((tmp_path / "cache").glob("*.w"))
    assert len(entries) == 1
    evil = compile("import sys\nsys.modules[__name__].PLANTED = True\n", "evil", "exec")
    entries[0].write_bytes(entries[0].read_bytes()[:40] + marshal.dumps((evil, False, "owner")))
    written._REWRITES.clear()
    written._WRITTEN.clear()
    cache._recipes.clear()
    cache.memory_clear()
    for entry in (tmp_path / "cache").glob("*.[or]"):
        entry.unlink()
    assert np.array_equal(kernel(module.body, name="planted", cache=True)(x), [0.5, 6.0])
    assert not getattr(module, "PLANTED", False)


def _pairs(v):                       # a generator helper: called as Python calls it, never rewritten
    for k in range(2):
        if k == 1:
            yield v * 2.0
        else:
            yield v


def test_a_generator_helper_is_left_as_python_wrote_it():
    @kernel
    def uses_generator(x: Float) -> Float:
        a, b = _pairs(x)
        return a + b if x > 0.0 else a - b

    assert np.array_equal(uses_generator(X), np.where(X > 0, X * np.float32(3), -X))


def test_a_decorated_bodys_edit_is_never_served_an_old_rewrite(tmp_path, monkeypatch):
    """The rewrite's key covers the whole ``def``: a decorated body edited in place (same lines,
    same decorator) is rewritten anew in a fresh process, not read back from the disk cache."""
    import subprocess
    import sys

    cache_dir = tmp_path / "cache"
    source = tmp_path / "edited_body.py"
    program = ("import numpy as np, reactor\nfrom reactor import Float\n\n\n@reactor.kernel\n"
               "def body(x: Float) -> Float:\n    if x > 1.0:\n        return x * {}\n    return x\n\n\n"
               "print(body(np.array([3.0], np.float32))[0])\n")
    env = {**__import__("os").environ, "REACTOR_CACHE_DIR": str(cache_dir)}
    for factor, want in (("2.0", "6.0"), ("5.0", "15.0")):
        source.write_text(program.format(factor))
        run = subprocess.run([sys.executable, str(source)], env=env, capture_output=True, text=True, timeout=300)
        assert run.stdout.strip() == want, run.stderr
