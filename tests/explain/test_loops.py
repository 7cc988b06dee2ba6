"""reactor.explain weighs each line by how often it runs: a loop's body by its trip count, measured on
sample inputs (a counting build of the loop) or estimated (a constant bound, else a stated assumption),
and says which."""
import inspect

import numpy as np
import pytest

import reactor
from reactor import Float, Int, kernel
from reactor.cost import lines as cost_lines


@kernel
def mandel(px: Float, py: Float) -> Float:
    cx = px * 3.0 - 2.25
    cy = py * 2.5 - 1.25
    x = cx
    y = cy
    n = Int(0)
    while n < 64:
        x2 = x * x
        y2 = y * y
        if x2 + y2 > 4.0:
            break
        y = 2.0 * x * y + cy
        x = x2 - y2 + cx
        n = n + 1
    return Float(n)


@kernel
def series(x: Float) -> Float:
    s = x * 0.5
    for i in range(8):
        if s > 1e30:
            break
        s = s * x + 1.0
    return s


@kernel
def halve(x: Float) -> Float:
    y = x * 1.5
    while y > 1.0:
        y = y * 0.5
    return y


def _lines(k):
    source, first = inspect.getsourcelines(reactor.kernel_of(k).body)
    return {text.strip(): first + i for i, text in enumerate(source) if text.strip()}


def _grid(size=64):
    px, py = np.meshgrid(np.linspace(0, 1, size, dtype=np.float32), np.linspace(0, 1, size, dtype=np.float32))
    return px, py


def _share(e, number):
    return sum(row.cost.get("share", 0.0) for row in e.lines if row.line == number)


def test_the_loop_body_outweighs_the_setup_measured_on_inputs():
    px, py = _grid()
    e = reactor.explain(mandel, inputs=(px, py))
    src = _lines(mandel)
    setup = _share(e, src["cx = px * 3.0 - 2.25"]) + _share(e, src["cy = py * 2.5 - 1.25"])
    body = sum(_share(e, src[t]) for t in ("x2 = x * x", "y2 = y * y", "y = 2.0 * x * y + cy", "x = x2 - y2 + cx"))
    assert body > 10 * setup > 0  # one pass each, the body would weigh about 2.5 times the setup
    (loop,) = e.loops
    assert loop.how == "measured" and loop.first == src["while n < 64:"] and loop.last >= src["n = n + 1"]
    # the loop runs while any lane does: per vector, the most passes any of its lanes needs (n + 1 for a
    # lane that escaped after n steps, 64 for one that never did), from the kernel's own results
    n = mandel(px, py).ravel().reshape(-1, e.loops[0].width)
    passes = np.where(n < 64, n + 1, 64).max(axis=1)
    assert loop.trips == pytest.approx(passes.mean())
    text = e.text(instructions=False)
    assert f"{loop.trips:.1f} iterations a vector" in text and "measured on the given inputs (4096 elements)" in text
    assert e.line(src["x2 = x * x"]).cost["runs"] == pytest.approx(loop.trips)


def test_without_inputs_a_constant_bound_is_the_estimate_and_is_labelled_so():
    e = reactor.explain(mandel)
    (loop,) = e.loops
    assert loop.how == "estimated" and loop.trips == 64.0 and "against 64" in loop.detail
    assert "estimated: " in e.text() and "measured" not in e.text()
    src = _lines(mandel)
    assert _share(e, src["y = 2.0 * x * y + cy"]) > _share(e, src["cx = px * 3.0 - 2.25"])


def test_a_constant_bound_for_loop_is_weighted_by_its_trip_count():
    e = reactor.explain(series)
    src = _lines(series)
    (loop,) = e.loops
    assert loop.how == "estimated" and loop.trips == 8.0
    step = e.line(src["s = s * x + 1.0"])
    assert step.cost["runs"] == 8.0
    # the same kernel measured where every lane leaves at once: one pass, an eighth of the weight
    once = reactor.explain(series, inputs=[np.full(64, 1e31, np.float32)])
    assert once.loops[0].how == "measured" and once.loops[0].trips == 1.0
    assert step.cost["busy"] == pytest.approx(8 * once.line(src["s = s * x + 1.0"]).cost["busy"])
    assert e.line(src["s = x * 0.5"]).cost.get("runs", 1.0) == 1.0


def test_an_unknown_trip_count_is_a_stated_assumption_and_a_guarded_loop_still_counts():
    e = reactor.explain(halve)
    (loop,) = e.loops
    assert loop.how == "estimated" and loop.trips == cost_lines.ASSUMED_TRIPS and "assumed" in loop.detail
    src = _lines(halve)
    assert _share(e, src["y = y * 0.5"]) > _share(e, src["y = x * 1.5"])
    x = np.float32(2.0) ** np.arange(64, dtype=np.float32) / 1000
    measured = reactor.explain(halve, inputs={"x": x})
    needed = np.ceil(np.log2(np.maximum(x * 1.5, 1.0))).reshape(-1, measured.loops[0].width).max(axis=1)
    assert measured.loops[0].trips == pytest.approx(needed.mean())


def test_a_kernel_without_loops_has_none_and_weights_of_one():
    @kernel
    def plain(x: Float) -> Float:
        return x * 2.0 + 1.0
    e = reactor.explain(plain, inputs=[np.ones(64, np.float32)])
    assert e.loops == [] and all(row.cost.get("runs", 1.0) == 1.0 for row in e.lines)
    assert 0 < sum(row.cost.get("share", 0) for row in e.lines) <= 1.0 + 1e-9


def test_inputs_are_checked():
    with pytest.raises(reactor.ReactorError, match="no values for py"):
        reactor.explain(mandel, inputs={"px": np.zeros(64, np.float32)})
    with pytest.raises(reactor.ReactorError, match="has no input 'q'"):
        reactor.explain(mandel, inputs={"px": 0.0, "py": 0.0, "q": 1.0})
    with pytest.raises(reactor.ReactorError, match="takes 2 inputs, 1 given"):
        reactor.explain(mandel, inputs=[np.zeros(64, np.float32)])
    with pytest.raises(reactor.ReactorError, match="at least"):
        reactor.explain(mandel, inputs=(np.float32(0.5), np.float32(0.5)))


def test_the_counting_build_counts_every_block_of_the_region():
    from reactor.explain.profile import instrument
    k = reactor.kernel_of(mandel)
    blocks = cost_lines.region_blocks(k.optimized_ir, "mandel.loop")
    assert "vec.body" in blocks and len(blocks) >= 2
    text = instrument(k.optimized_ir, "mandel.loop", blocks, 4096)
    assert text.count("add i64 %__count") == len(blocks)
    for k_, name in enumerate(blocks):  # each increment sits after its block's phis
        block = text.split(f"\n{name}:", 1)[1].split("\n\n", 1)[0].splitlines()[1:]
        first = next(i for i, line in enumerate(block) if " = phi " not in line)
        assert f"%__count{k_} = load i64, ptr inttoptr (i64 {4096 + 8 * k_} to ptr)" in block[first]


def test_the_command_line_measures_with_inputs_and_writes_only_the_page(tmp_path, capsys):
    from reactor.__main__ import main
    src = tmp_path / "shade.py"
    src.write_text("from reactor import Float, Int, kernel\n\n" + inspect.getsource(reactor.kernel_of(mandel).body))
    assert main(["explain", f"{src}:mandel", "--input", "px=0:1", "--input", "py=0:1", "--samples", "2048",
                 "--brief"]) == 0
    printed = capsys.readouterr().out
    assert "measured on the given inputs (2048 elements)" in printed and "run " in printed
    page = tmp_path / "mandel.html"
    assert main(["explain", f"{src}:mandel", "--html", str(page)]) == 0
    printed = capsys.readouterr().out
    assert printed.strip() == f"wrote {page}" and page.exists()
    html = page.read_text()
    assert "iterations a vector" in html and "estimated: " in html and "x2 = x * x" in html
    assert main(["explain", f"{src}:mandel", "--input", "px"]) == 2
