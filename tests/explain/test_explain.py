"""reactor.explain: every instruction tied to the Python line that emitted it, routines as their own
groups, costs per line, diffs of two builds, and the HTML page (checked in headless Chromium)."""
import inspect
import os
import shutil
import subprocess

import numpy as np
import pytest

import reactor
import routines
from reactor import Float, Function, Select, kernel
from reactor.explain.html import selftest_result
from reactor.explain.listing import parse_asm


@kernel
def falloff(d: Float, r: Float) -> Float:
    t = 1.0 - d / r
    g = routines.exp2(-8.0 * d * d)
    return Select(t > 0.0, t * g, 0.0)


_SOURCE, _FIRST = inspect.getsourcelines(reactor.kernel_of(falloff).body)
LINES = {text.split()[0]: _FIRST + k for k, text in enumerate(_SOURCE) if text.strip()}  # "t", "g", "return"


def _line(name):
    return LINES[name]


def test_each_line_has_its_ir_and_machine_instructions_and_routines_are_groups():
    e = reactor.explain(falloff)
    assert e.name == "falloff" and "width=" in e.settings
    keys = {(row.line, row.group) for row in e.lines}
    t, g, ret = _line("t"), _line("g"), _line("return")
    assert {(t, ""), (g, ""), (g, "exp2"), (ret, "")} <= keys
    assert all(row.file == __file__ for row in e.lines)
    division = e.line(t)
    assert any("fdiv" in i.text for i in division.ir) and any("div" in i.text for i in division.asm)
    exp2 = e.line(g, "exp2")
    assert len(exp2.asm) >= 8 and not any("fdiv" in i.text for i in exp2.ir)
    assert not any(i.tail for row in e.lines for i in row.ir + row.asm)  # the vector loop only
    text = e.text()
    assert "t = 1.0 - d / r" in text and "[exp2]" in text


def test_plumbing_is_shown_on_request():
    lean, full = reactor.explain(falloff), reactor.explain(falloff, plumbing=True)
    assert all(row.line for row in lean.lines)
    assert any(row.line == 0 for row in full.lines)
    assert any(i.tail for row in full.lines for i in row.asm)


def test_source_lines_do_not_change_the_machine_code():
    e = reactor.explain(falloff, plumbing=True)
    plain = [i.text for i in parse_asm(reactor.kernel_of(falloff).assembly)["falloff.loop"]]
    lined = [i.text for i in parse_asm(e.assembly)["falloff.loop"]]
    assert plain == lined


def test_costs_per_line_from_the_dataflow_model():
    e = reactor.explain(falloff)
    if not e.costs:
        pytest.skip("no cost model registered (pip install -e . registers routines' model)")
    exp2 = e.line(_line("g"), "exp2")
    assert exp2.cost["ops"].get("fma", 0) + exp2.cost["ops"].get("fmul", 0) >= 4
    assert 0 < exp2.cost["share"] < 1 and exp2.cost["critical"]
    assert sum(row.cost.get("share", 0) for row in e.lines) <= 1.0 + 1e-9
    assert e.costs["bound"] > 0 and e.costs["critical_path"] > 0


@pytest.mark.skipif("avx512f" not in reactor.get_target("host").feature_set
                    and "fma" not in reactor.get_target("host").feature_set, reason="needs FMA")
def test_a_diff_of_fma_on_and_off_marks_the_routine_that_changed():
    a, b = reactor.explain(falloff, fma=True), reactor.explain(falloff, fma=False)
    diff = a.diff(b)
    changed = {(x or y).group for x, y in diff.changed()}
    assert changed == {"exp2"}
    assert "vfmadd" in diff.text() and "≠" in diff.text()


def test_a_function_is_explained_too():
    def body(x: Float) -> Float:
        y = x * 2.0
        return routines.sqrt(y) + 1.0

    e = reactor.explain(Function(body, name="explained"))
    first = inspect.getsourcelines(body)[1]
    assert {(first + 1, ""), (first + 2, ""), (first + 2, "sqrt")} <= {(r.line, r.group) for r in e.lines}


def test_explain_refuses_what_it_cannot_explain():
    with pytest.raises(reactor.ReactorError, match="kernel .* or a Function"):
        reactor.explain(np.add)


def test_the_page_has_three_linked_columns(tmp_path):
    e = reactor.explain(falloff)
    page = e.write_html(str(tmp_path / "falloff.html"), e.diff(reactor.explain(falloff, precision="relaxed")))
    text = open(page, encoding="utf-8").read()
    assert text.count('class="col"') == 3 and "<script>" in text and "http" not in text.split("<body>")[1]
    assert 't = 1.0 - d / r' in text and 'id="diff"' in text


def _chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        if shutil.which(name):
            return shutil.which(name)
    return None


@pytest.mark.skipif(_chromium() is None, reason="no headless Chromium (apt-get install chromium)")
def test_the_page_works_in_a_real_browser(tmp_path):
    """Loaded in headless Chromium: no script error, three columns, and hovering the first source
    line lights exactly its IR and machine instructions (the page's own #selftest), then clears."""
    page = reactor.explain(falloff).write_html(str(tmp_path / "falloff.html"))
    run = subprocess.run([_chromium(), "--headless", "--no-sandbox", "--disable-gpu", "--dump-dom",
                          f"file://{page}#selftest"], capture_output=True, text=True, timeout=120,
                         env=dict(os.environ, HOME=str(tmp_path)))
    result = selftest_result(run.stdout)
    assert result["errors"] == [] and result["columns"] == 3
    assert result["ir"] == result["ir_total"] > 0 and result["asm"] == result["asm_total"] > 0
    assert result["after"] == 0


def test_the_command_line(tmp_path, capsys):
    from reactor.__main__ import main
    src = tmp_path / "shade.py"
    src.write_text("import routines\nfrom reactor import Float, kernel\n\n@kernel\ndef shade(x: Float) -> Float:\n"
                   "    return routines.pow(x, 2.2)\n")
    out = tmp_path / "shade.html"
    assert main(["explain", f"{src}:shade", "--diff", "precision=relaxed", "--brief"]) == 0
    printed = capsys.readouterr().out
    assert "shade.py:6 [pow]" in printed and "B: target=" in printed
    assert main(["explain", f"{src}:shade", "--diff", "precision=relaxed", "--html", str(out)]) == 0
    assert capsys.readouterr().out == f"wrote {out}\n"  # the page only, and where it went
    page = out.read_text(encoding="utf-8")
    assert "shade.py:6 [pow]" in page and "B: target=" in page
    assert main(["explain", f"{src}:shade", "--diff", "fma"]) == 2


def test_explain_takes_a_target_and_diffs_see_operands_and_widths():
    """target= is a build option like the others; a width change is a difference even where the
    operations are the same (only the register class changes)."""
    from reactor import Float
    import reactor

    def body(x: Float) -> Float:
        return x * 3.0 + 1.0
    k = reactor.kernel(body, name="explain_width_probe")
    a = reactor.explain(k, target="sse4")
    assert "sse4" in a.settings
    diff = reactor.explain(k, width=8).diff(reactor.explain(k, width=4))
    assert diff.changed() and "operands or registers differ" in diff.text()
    assert not reactor.explain(k).diff(reactor.explain(k)).changed()


def test_dump_shows_the_body_first_and_all_on_request(tmp_path):
    import subprocess
    import sys
    src = tmp_path / "shade.py"
    src.write_text("import reactor\nfrom reactor import Float\n\n@reactor.kernel\n"
                   "def falloff(d: Float) -> Float:\n    return d * 2.0 + 1.0\n")
    run = lambda *a: subprocess.run([sys.executable, "-m", "reactor", "dump", f"{src}:falloff", *a],  # noqa: E731
                                    capture_output=True, text=True).stdout
    body_ir, loop_asm, everything = run("--what", "ir"), run("--what", "asm"), run("--what", "asm", "--all")
    assert body_ir.startswith("; falloff.body") and "falloff.ufunc" not in body_ir
    assert loop_asm.startswith("# falloff.loop") and "falloff.ufunc:" not in loop_asm
    assert "falloff.loop:" in everything and len(everything) > len(loop_asm)  # with the module's directives
