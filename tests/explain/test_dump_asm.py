"""``python -m routines dump NAME --what asm``: the routine's core (the vector loop) first, every constant
it reads shown by value, the algorithm's steps named from the instructions and routines' own polynomial
tables; the whole function after it, and the listing as LLVM wrote it with --raw."""
import re

import numpy as np
import pytest

import reactor
from routines import polynomials
from routines.cli import annotate
from routines.cli.dump import main

CORE_END = ": the whole function"


def _dump(capsys, *args):
    assert main(list(args)) == 0
    return capsys.readouterr().out


def _core(out):
    return out.split(CORE_END, 1)[0].rsplit("\n", 1)[0]


def _instructions(core):
    return [line for line in core.splitlines() if line.startswith(" ") and line.strip()]


@pytest.mark.parametrize("target", [None, "avx2", "sse4", "aarch64"])
def test_the_core_comes_first_with_its_constants_and_steps(capsys, target):
    args = ["exp2", "--what", "asm"] + (["--target", target] if target else [])
    try:
        out = _dump(capsys, *args)
    except reactor.ReactorError as exc:  # a target this LLVM cannot build
        pytest.skip(str(exc))
    assert out.startswith("# exp2_full_") and CORE_END in out
    core = _core(out)
    body = _instructions(core)
    assert body and not any(re.match(r"\s*(push|pop|ret|stp|ldp)\b", line) for line in body)  # no prologue
    assert any(re.search(r"%[xyz]mm\d+|v\d+\.4s", line) for line in body)
    for line in body:  # every pool reference in the core carries its value
        for ref in set(re.findall(r"\.LCPI\d+_\d+", line.split("#")[0])):
            assert re.search(re.escape(ref) + r" = [-{\d0]", line.split("#", 1)[1]), line
    # the polynomial of routines' table, recognised by its coefficients, each shown by value
    assert "polynomial exp2.full (Horner, degree 5)" in core
    for c in polynomials.EXP2_FULL.values:
        assert str(np.float32(c)) + "f" in core
    assert "range reduction" in core
    # the whole function follows: its prologue and the tail are there
    assert len(out.split(CORE_END, 1)[1].splitlines()) > len(body)


def test_raw_and_all_are_the_listing_as_llvm_wrote_it(capsys):
    raw = _dump(capsys, "exp2", "--what", "asm", "--raw")
    assert raw.startswith("# exp2_full_fma.loop: the loop with the body inlined") and "# polynomial" not in raw
    everything = _dump(capsys, "exp2", "--what", "asm", "--all")
    assert ".LCPI0_0:" in everything and "# polynomial" not in everything
    ir = _dump(capsys, "exp2", "--what", "ir")
    assert "define" in ir and "# polynomial" not in ir


def test_a_register_holding_a_constant_is_annotated_where_it_is_read(capsys):
    out = _dump(capsys, "log2", "--what", "asm")
    core = _core(out)
    assert "polynomial log2.full (Horner, degree 6)" in core
    held = re.findall(r"^#   (%\w+|v\d+\S*) = (\S+)", core, re.M)
    assert held
    for reg, value in held:
        readers = [line for line in _instructions(core) if reg in line.split("#")[0].split()[-1:] or
                   re.search(re.escape(reg) + r"\b,", line.split("#")[0])]
        assert all(f"{reg} = {value}" in line for line in readers), readers


def test_constant_pool_and_values():
    asm = (".LCPI0_0:\n\t.long\t0x3fb8aa3b\n.LCPI0_1:\n\t.quad\t0x3ff0000000000000\n"
           ".LCPI0_2:\n\t.long\t1065353216\n\t.long\t1065353216\n.LCPI0_3:\n\t.byte\t1\n\t.byte\t2\n\t.zero\t2\n"
           "\t.text\nf:\n\tretq\n")
    pool = annotate.constant_pool(asm)
    assert pool[".LCPI0_0"] == bytes.fromhex("3baab83f")
    assert annotate.value_text(pool[".LCPI0_0"], "f32") == "1.442695f (0x3fb8aa3b)"
    assert annotate.value_text(pool[".LCPI0_1"], "f64") == "1.0 (0x3ff0000000000000)"
    assert annotate.value_text(pool[".LCPI0_2"], "f32") == "{2 x 1.0f (0x3f800000)}"
    assert pool[".LCPI0_3"] == b"\x01\x02\x00\x00"
    assert annotate.value_text(pool[".LCPI0_3"], "i32") == "0x00000201 (513)"
    assert annotate.element_kind("vpbroadcastd") == "i32" and annotate.element_kind("vfmadd213ps") == "f32"
    assert annotate.element_kind("vbroadcastsd") == "f64" and annotate.element_kind("vpaddq") == "i64"


def test_a_polynomial_not_in_the_tables_is_not_named():
    """Steps come from what the code does: without routines' tables no polynomial is named."""
    import routines
    u = reactor.kernel_of(routines.jit("exp2"))
    lines = annotate.function_lines(u.assembly, f"{u.name}.loop")
    found = annotate.annotate(lines, annotate.constant_pool(u.assembly), [])
    assert found is not None
    core, _summary = found
    assert not any(line.step.startswith("polynomial") for line in core)
    assert any(line.step == "range reduction" for line in core)
