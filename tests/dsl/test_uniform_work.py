"""Uniform work out of the vector loop (reactor.ir.hoist): what depends only on some inputs is
computed once per call when they are broadcast, per iteration otherwise; the bits never change."""
import re

import numpy as np
import pytest

import reactor
from reactor import Float, kernel
from reactor.kernels import kernel as kernel_module
from reactor.kernels import loop
from routines import glsl as gl

RNG = np.random.default_rng(7)
X = RNG.uniform(-4, 4, 1000).astype(np.float32)
T = RNG.uniform(-40, 40, 1000).astype(np.float32)


def both(body, **options):
    """The kernel built with its uniform work split off, and without."""
    built = {}
    for flag in (True, False):
        previous, loop.UNIFORM_WORK = loop.UNIFORM_WORK, flag
        try:
            kernel_module._memo.clear()
            built[flag] = kernel(body, cache=False, **options)
        finally:
            loop.UNIFORM_WORK = previous
    return built[True], built[False]


def wave(x: Float, t: Float) -> Float:
    return x * gl.cos(t * 0.3) + gl.exp2(t * 0.01)


def mixed(x: Float, a: Float, b: Float) -> Float:
    return x * gl.cos(a) * gl.sin(b * 0.5) + gl.log2(gl.abs(a) + 1.0) - gl.sqrt(gl.abs(b))


def _blocks(ir_text: str, function: str) -> dict:
    """The optimized IR of ``function`` by basic block: name -> its instructions."""
    text = ir_text[ir_text.index(f"@{function}("):]
    text = text[:text.index("\n}")]
    blocks, name = {}, "entry"
    for line in text.splitlines()[1:]:
        label = re.match(r"^([\w.$-]+):", line)
        if label:
            name = label.group(1)
        blocks[name] = blocks.get(name, "") + line + "\n"
    return blocks


def gain(x: Float, t: Float) -> Float:
    return x * gl.exp2(t * 0.3) + gl.log2(gl.abs(t) + 1.0)


def test_the_work_on_a_uniform_moves_to_a_group_of_its_own():
    split, whole = both(gain)
    code = reactor.kernel_of(split)
    assert '@"gain.body.pre0"' in code.ir and ".pre0" not in reactor.kernel_of(whole).ir
    blocks = _blocks(code.optimized_ir, "gain.loop")
    # the exp2 and log2 run once per call when t is broadcast: their polynomials (fma chains) sit
    # in the block that runs before the vector loop, not in the loop's own
    assert blocks["uniform.then"].count("llvm.fma") >= 8 and blocks["vec.body"].count("llvm.fma") == 0
    for t in (np.float32(0.7), T):
        assert np.array_equal(split(X, t), whole(X, t), equal_nan=True)


def test_a_cosine_behind_its_rare_path_branch_is_still_computed_once():
    split, _ = both(wave)
    blocks = _blocks(reactor.kernel_of(split).optimized_ir, "wave.loop")
    # sin/cos/tan end their common path before the large-argument branch: the whole cosine (its
    # polynomial's fused multiply-adds) runs before the loop; the large-argument reduction, where
    # some lane needs it, is computed again in the loop, off the common path
    assert blocks["uniform.then"].count("llvm.fma") >= 6 and blocks["vec.body"].count("llvm.fma") == 0


@pytest.mark.parametrize("t", [np.float32(0.7), np.float32(123456.0), np.float32(np.inf), np.float32(np.nan), T],
                         ids=["scalar", "huge", "inf", "nan", "array"])
@pytest.mark.parametrize("body", [wave, gain])
def test_the_same_bits_broadcast_or_not(body, t):
    split, whole = both(body)
    assert np.array_equal(split(X, t), whole(X, t), equal_nan=True)
    assert np.array_equal(split(X, t), split(X, np.broadcast_to(t, X.shape).copy()), equal_nan=True)


@pytest.mark.parametrize("body", [wave, gain])
def test_every_layout_numpy_gives_the_loop(body):
    split, whole = both(body)
    grid_x, grid_t = X[:40][None, :], T[:30][:, None]  # a row and a column: per row, t is broadcast
    assert np.array_equal(split(grid_x, grid_t), whole(grid_x, grid_t))
    assert np.array_equal(split(X[::3], T[::3]), whole(X[::3], T[::3]))  # strided: the element loop
    for n in (0, 1, 5, 17, 33):
        assert np.array_equal(split(X[:n], np.float32(2.5)), whole(X[:n], np.float32(2.5)))
    out = np.zeros_like(X)
    where = X > 0
    split(X, np.float32(1.5), out=out, where=where)
    assert np.array_equal(out[where], whole(X, np.float32(1.5))[where]) and not out[~where].any()


@pytest.mark.parametrize("a, b", [(np.float32(0.3), np.float32(-2.0)), (np.float32(0.3), T), (T, np.float32(5.0)),
                                  (T, T[::-1].copy())], ids=["both scalar", "a scalar", "b scalar", "arrays"])
def test_two_groups_each_once_or_per_element(a, b):
    split, whole = both(mixed)
    assert np.array_equal(split(X, a, b), whole(X, a, b), equal_nan=True)


def test_a_one_input_kernel_is_left_alone():
    split, _ = both(lambda x: gl.cos(x) * 2.0, args=[Float], returns=Float)
    assert ".pre0" not in reactor.kernel_of(split).ir


def _random_body(rng, depth):
    """A random expression of x, t, u: routines, selects and arithmetic (a seeded generator)."""
    leaves = ["x", "t", "u", "1.5", "0.25"]
    unary = ["gl.sin({})", "gl.exp2({})", "gl.log2(gl.abs({}) + 1.0)", "gl.sqrt(gl.abs({}))", "gl.cos({} * 0.3)",
             "gl.floor({})", "gl.normalize(reactor.vec2({}, 1.0)).x"]
    binary = ["({} + {})", "({} * {})", "gl.max({}, {})", "gl.pow(gl.abs({}) + 0.5, {} * 0.1)",
              "Select({} > x, {}, {})"]
    if depth == 0 or rng.random() < 0.2:
        return rng.choice(leaves)
    form = rng.choice(unary if rng.random() < 0.5 else binary)
    return form.format(*[_random_body(rng, depth - 1) for _ in range(form.count("{}"))])


def test_random_bodies_give_the_same_bits_for_every_broadcast_pattern():
    import random
    from reactor import Select
    rng, split_off = random.Random(11), 0
    arr = np.random.default_rng(1).uniform(-5, 5, X.size).astype(np.float32)
    for n in range(24):
        namespace = {"Float": Float, "gl": gl, "Select": Select, "reactor": reactor}
        exec(f"def body{n}(x: Float, t: Float, u: Float) -> Float:\n    return {_random_body(rng, 4)}\n", namespace)
        split, whole = both(namespace[f"body{n}"])
        split_off += ".pre0" in reactor.kernel_of(split).ir
        for t, u in [(np.float32(0.7), np.float32(-2.5)), (arr, np.float32(3.0)), (np.float32(1.25), arr),
                     (arr, arr[::-1].copy())]:
            assert np.array_equal(split(X, t, u), whole(X, t, u), equal_nan=True), namespace[f"body{n}"]
    assert split_off >= 6  # the generator makes bodies with uniform work
