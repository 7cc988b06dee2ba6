"""The accuracy ladder's lab and report pieces: the command line, the dominance rule, SVML's
absence reported as such."""
import json

import numpy as np

from routines.cli import ladder as ladder_cli
from routines.perf import frontier as ladder, peers


def test_the_ladder_command_checks_a_tier_and_writes_json(tmp_path, capsys):
    out = tmp_path / "ladder.json"
    assert ladder_cli.main(["exp2", "--precisions", "correct", "--fma", "on", "--json", str(out), "-q"]) == 0
    rows = json.loads(out.read_text())
    assert len(rows) == 1 and rows[0]["misrounded"] == 0 and rows[0]["inputs"] == 2 ** 24
    assert "misrounded 0" in capsys.readouterr().out


def test_a_peer_is_dominated_only_by_a_point_at_most_its_time_and_error():
    pts = [ladder.Point("ours f a", "f", "ours", "a", ns=1.0, max_ulp=0.9),
           ladder.Point("ours f b", "f", "ours", "b", ns=2.0, max_ulp=0.5),
           ladder.Point("p1", "f", "numpy", "p1", ns=1.5, max_ulp=1.0),    # a: cheaper and better
           ladder.Point("p2", "f", "libmvec", "p2", ns=0.9, max_ulp=2.0),  # faster than every point
           ladder.Point("p3", "f", "sleef", "p3", ns=3.0, max_ulp=0.4),    # more accurate than every point
           ladder.Point("p4", "f", "svml", "p4", ns=2.5, max_ulp=0.5),     # b: cheaper, as accurate
           ladder.Point("p5", "f", "svml", "p5", present=False, reason="not installed")]
    ladder.dominance(pts)
    assert [p.dominated_by for p in pts[2:]] == ["a", None, None, "b", None]
    lines = ladder.statements(pts)
    assert "dominated by ours a" in lines[0] and "NOT dominated" in lines[1] and "absent (not installed)" in lines[4]
    assert "no point of ours is as accurate" in lines[2]


def test_svml_absent_is_reported_absent():
    ps = peers.peers(["exp2"], {"svml": "/no/such/libsvml.so"}, families=("svml",))
    assert [p.key.split()[-1] for p in ps] == ["la", "ha", "ep", "br", "cr"]
    assert all(not p.present for p in ps) and all("/no/such/libsvml.so" in p.reason for p in ps)


def test_svml_tiers_measure_where_installed():
    if peers.svml_library() is None:
        import pytest
        pytest.skip("intel-cmplr-lib-rt not installed (the svml extra)")
    ps = {p.key: p for p in peers.peers(["exp2"], families=("svml",))}
    x = np.linspace(-10, 10, 1001, dtype=np.float32)
    got = peers.as_array_function(ps["svml exp2 cr"].fn)(x)
    assert (got == np.exp2(x.astype(np.float64)).astype(np.float32)).all()
