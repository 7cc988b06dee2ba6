"""The dataflow model's machine tables: every required core has a complete table, the host's
is chosen through cpus.py (generic, with its reason, for an unknown core), predictions differ
between tables as the cores do, and every result names the table it used. Nothing is timed."""
from __future__ import annotations

import pytest

from reactor.cost import cpus, lines as linecost, model as M

REQUIRED = {  # table: (native vector bits, slot bits)
    "zen3": (256, 256), "zen4": (512, 256), "zen5": (512, 512), "goldencove": (512, 256),
    "sunnycove": (512, 256), "skylakex": (512, 256), "haswell": (256, 256), "neoversev1": (128, 128),
    "generic": (256, 256),
}


def _loop_ir(body: list[str], lanes: int = 16, ty: str = "float") -> str:
    """A function ``k.loop`` whose ``vec.body`` loads ``%x`` (<lanes x ty>), runs ``body``
    (its last value ``%r``) and stores ``%r``: the shape of a reactor kernel's vector loop."""
    v = f"<{lanes} x {ty}>"
    lines = "\n".join("  " + b.replace("V", v) for b in body)
    return f"""
define void @k.loop(ptr %src, ptr %dst, i64 %n) {{
entry:
  br label %vec.body
vec.body:
  %i = phi i64 [ 0, %entry ], [ %i.next, %vec.body ]
  %p = getelementptr {ty}, ptr %src, i64 %i
  %q = getelementptr {ty}, ptr %dst, i64 %i
  %x = load {v}, ptr %p, align 4
{lines}
  store {v} %r, ptr %q, align 4
  %i.next = add i64 %i, {lanes}
  %c = icmp slt i64 %i.next, %n
  br i1 %c, label %vec.body, label %done
done:
  ret void
}}
declare <16 x float> @llvm.fma.v16f32(<16 x float>, <16 x float>, <16 x float>)
declare <8 x float> @llvm.fma.v8f32(<8 x float>, <8 x float>, <8 x float>)
"""


def _fmas(n: int, lanes: int) -> str:
    """``n`` independent FMAs on <lanes x float>, summed pairwise into %r by FMAs too."""
    f = f"@llvm.fma.v{lanes}f32"
    body = [f"%a{k} = call V {f}(V %x, V %x, V %x)" for k in range(n - 1)]
    body.append(f"%r = call V {f}(V %a0, V %a1, V %a{n - 2})")
    return _loop_ir(body, lanes)


def _fadd_chain(n: int) -> str:
    body = ["%s0 = fadd V %x, %x"] + [f"%s{k} = fadd V %s{k - 1}, %x" for k in range(1, n)]
    body.append(f"%r = fadd V %s{n - 1}, %x")
    return _loop_ir(body, 8)


# -- the tables ---------------------------------------------------------------------------------

@pytest.mark.parametrize("name", sorted(REQUIRED))
def test_every_required_table_exists_and_is_complete(name):
    m = M.MACHINES[name]
    assert m.name == name and m.source and m.title
    assert set(m.ops) == set(M.ZEN4), set(m.ops) ^ set(M.ZEN4)
    assert (m.vector_bits, m.slot_bits) == REQUIRED[name]
    assert m.split in M._SPLITS and m.issue_width > 0 and m.dispatch > 0 and m.fp_scheduler > 0
    assert m.known == (name != "generic")
    for table in (m.ops, m.wide_ops):
        for cls, op in table.items():
            assert op.latency > 0 and op.per_cycle > 0 and op.what, (name, cls)
    if m.wide_ops:  # the Intel AVX-512 cores: 512-bit operations on their own ports
        assert m.split == "fused ports" and set(m.wide_ops) == set(M.ZEN4)
    # every class the classifier can name is in every table
    named = ({c for _, c in M._INTRINSIC_CLASSES if c} | set(M._OPCODE_CLASSES.values())
             | set(M._VECTOR_OPS.values()) | {"fminmax", "call", "int"})
    assert named <= set(m.ops)


def test_zen4_keeps_its_names_and_numbers():
    zen4 = M.MACHINES["zen4"]
    assert zen4.ops == M.ZEN4 and M.as_machine(M.ZEN4) is zen4 and M.as_machine("zen4") is zen4
    assert zen4.issue_width == M.ISSUE_WIDTH == 4 and zen4.split == "halves"
    assert M.ZEN4["fma"] == M.OpClass(4, 2, "fused multiply-add (FP0/FP1)", ("FP0", "FP1"))
    assert M.ZEN4["sqrt"].latency == 15 and M.ZEN4["sqrt"].per_cycle == 0.2
    # the pipe-sharing bound reads a Machine and its bare class table alike
    for slots in ({"fma": 10, "fmul": 10}, {"fma": 10, "fadd": 10}, {"sqrt": 2}):
        assert M._pipe_bounds(slots, M.ZEN4) == M._pipe_bounds(slots, zen4)


def test_every_cpus_row_has_a_model_table():
    for name, row in cpus.TABLE.items():
        assert M.machine_for(name).name == name and M.machine_for(name).known == row.known


def test_tables_by_llvm_cpu_name():
    assert M.machine_for("znver3").name == "zen3" and M.machine_for("znver4").name == "zen4"
    assert M.machine_for("znver5").name == "zen5"
    assert M.machine_for("sapphirerapids").name == "goldencove"
    assert M.machine_for("icelake-server").name == "sunnycove"
    assert M.machine_for("skylake-avx512").name == "skylakex"
    assert M.machine_for("neoverse-v1").name == "neoversev1"
    # parts whose AVX-512 is absent: 256-bit vectors, a 512-bit vector of the IR is two instructions
    for name in ("skylake", "alderlake"):
        m = M.machine_for(name)
        assert m.vector_bits == 256 and not m.wide_ops and "without AVX-512" in m.label
        assert m.cost("fma", 512)[2] == 2


def test_unknown_core_gets_the_generic_table_with_its_reason():
    m = M.machine_for("mystery-core-9000")
    assert m.name == "generic" and not m.known
    assert m.label.startswith("generic table (unknown core 'mystery-core-9000': assumed ")
    assert "256-bit" in m.label and "FMA 4" in m.label  # the assumption is stated


def test_host_machine_on_an_unknown_cpu(monkeypatch):
    unknown = {"vendor": "HygonGenuine", "family": 24, "model": 0, "name": "?", "llvm_cpu": "mystery"}
    monkeypatch.setattr(M.cpus, "cpu_model", lambda: dict(unknown))
    m = M.host_machine.__wrapped__()  # uncached: the real host's choice stays cached
    assert m.name == "generic" and not m.known
    assert "unknown core" in m.label and "'mystery'" in m.label and "assumed" in m.label


def test_host_machine_is_this_cpus_table():
    host, row = M.host_machine(), cpus.host()
    assert host is M.host_machine()  # chosen once
    assert host.known == row.known
    if row.known:
        assert host.name.partition("-")[0] == row.name  # "-avx2": the same core without AVX-512
        assert host.label.endswith(" table") and "generic" not in host.label
    if cpus.cpu_model().get("llvm_cpu") == "znver3":  # the machine these tests were written on
        assert host.name == "zen3" and host.label == "Zen 3 table"
    assert M.as_machine(None) is host


# -- how a wider-than-native operation is costed -------------------------------------------------

def test_slots_of_wide_operations():
    z3, z4, z5, skx, v1 = (M.MACHINES[n] for n in ("zen3", "zen4", "zen5", "skylakex", "neoversev1"))
    assert [m.cost("fma", 32)[2] for m in (z3, z4, z5, skx, v1)] == [1, 1, 1, 1, 1]  # scalar
    assert [m.cost("fma", 256)[2] for m in (z3, z4, z5, skx, v1)] == [1, 1, 1, 1, 2]
    assert [m.cost("fma", 512)[2] for m in (z3, z4, z5, skx, v1)] == [2, 2, 1, 1, 4]
    # Intel AVX-512: a zmm operation is one operation on p0 (p0+p1 fused) and p5
    key, op, n = skx.cost("fma", 512)
    assert key == "fma@512" and op.pipes == ("p0", "p5") and n == 1
    assert skx.cost("fma", 256)[1].pipes == ("p0", "p1")


# -- predictions ------------------------------------------------------------------------------------

def test_512_bit_fmas_cost_two_slots_on_zen4_and_one_on_zen5():
    zmm, ymm = _fmas(8, 16), _fmas(8, 8)
    p = {(name, w): M.predict(ir, "k.loop", w, name)
         for name in ("zen3", "zen4", "zen5", "skylakex", "goldencove", "haswell", "neoversev1", "generic")
         for w, ir in ((16, zmm), (8, ymm))}
    assert p["zen4", 16].counts["fma"] == p["zen5", 16].counts["fma"] == 8
    assert p["zen4", 16].slots["fma"] == 16 and p["zen5", 16].slots["fma"] == 8
    assert p["zen4", 16].throughput_bound == pytest.approx(8.0)   # 16 halves on FP0/FP1
    assert p["zen5", 16].throughput_bound == pytest.approx(4.0)   # 8 full-width ops on FP0/FP1
    assert p["zen4", 8].throughput_bound == p["zen5", 8].throughput_bound == pytest.approx(4.0)
    assert p["zen4", 16].bottleneck == "FP0/FP1 (fma)"
    # Skylake-X and Golden Cove: zmm FMAs on p0/p5, ymm on p0/p1, two a cycle either way
    assert p["skylakex", 16].throughput_bound == pytest.approx(4.0) and p["skylakex", 16].bottleneck == "p0/p5 (fma)"
    assert p["skylakex", 8].bottleneck == "p0/p1 (fma)" and p["goldencove", 16].throughput_bound == pytest.approx(4.0)
    # no 512-bit registers: the IR's zmm FMA is two ymm (Zen 3, Haswell) or four NEON FMLAs
    assert p["zen3", 16].throughput_bound == p["haswell", 16].throughput_bound == pytest.approx(8.0)
    assert p["neoversev1", 16].slots["fma"] == 32 and p["neoversev1", 16].throughput_bound == pytest.approx(8.0)
    # latency: FMA 4 cycles on all of these but Haswell (5)
    assert p["haswell", 8].critical_path - p["zen4", 8].critical_path == pytest.approx(2)  # two FMAs deep
    assert p["generic", 16].throughput_bound == p["zen3", 16].throughput_bound


def test_fadd_latency_differs_between_tables():
    ir, n = _fadd_chain(10), 11  # 11 dependent FADDs between a load (7 cycles) and a store (1)
    cp = {name: M.predict(ir, "k.loop", 8, name).critical_path for name in ("zen4", "zen5", "skylakex", "goldencove")}
    assert cp == {"zen4": 8 + 3 * n, "zen5": 8 + 2 * n, "skylakex": 8 + 4 * n, "goldencove": 8 + 2 * n}


def test_results_name_the_table():
    ir = _fmas(4, 16)
    for name in ("zen3", "zen4", "zen5", "goldencove", "sunnycove", "skylakex", "haswell", "neoversev1"):
        pred = M.predict(ir, "k.loop", 16, name)
        assert pred.machine == name and pred.machine_label == M.MACHINES[name].label
        assert pred.explain().endswith(f"; model: {M.MACHINES[name].label}")
    pred = M.predict(ir, "k.loop", 16, M.machine_for("nonesuch"))
    assert pred.machine == "generic" and "model: generic table (unknown core 'nonesuch': assumed" in pred.explain()
    default = M.predict(ir, "k.loop", 16)  # the host's table
    assert default.machine_label == M.host_machine().label and default.explain().endswith(default.machine_label)
    assert M.predict(ir, "k.loop", 16, M.ZEN4).machine_label == "Zen 4 table"
    custom = dict(M.ZEN4)
    assert M.predict(ir, "k.loop", 16, custom).machine_label == "given table"


def test_line_costs_use_and_name_the_table():
    ir = _fmas(4, 16)
    rows, summary = linecost.line_costs(ir, "k.loop", 16, "zen5")
    assert summary["machine"] == "Zen 5 table" and summary["table"] == "zen5"
    fma = [c for _, c in rows if c["class"] == "fma"]
    assert len(fma) == 4 and all(c["slots"] == 1 for c in fma)
    rows4, summary4 = linecost.line_costs(ir, "k.loop", 16, "zen4")
    assert summary4["machine"] == "Zen 4 table" and all(c["slots"] == 2 for _, c in rows4 if c["class"] == "fma")
    assert summary4["bound"] == pytest.approx(2 * summary["bound"])
    assert linecost.line_costs(ir, "k.loop", 16)[1]["machine"] == M.host_machine().label


def test_window_bound_uses_and_names_the_table():
    import routines
    from routines.perf import report
    from routines.perf.report import bounds

    assert bounds.MACHINE is M.host_machine()
    assert report.FP_SCHEDULER == M.host_machine().fp_scheduler and report.DISPATCH == M.host_machine().dispatch
    u = routines.jit("exp2", "full", True, 8)
    w = {name: report.window_bound(u, name) for name in ("zen4", "zen5", "skylakex")}
    assert w["zen4"]["machine"] == "Zen 4 table" and w["zen4"]["fp_scheduler"] == 64
    assert w["zen5"]["fp_scheduler"] > w["zen4"]["fp_scheduler"]
    assert all(v["fp_ops"] == w["zen4"]["fp_ops"] > 5 for v in w.values())  # ymm: one instruction each
    assert report.window_bound(u)["machine"] == M.host_machine().label
