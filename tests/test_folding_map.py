"""scripts/folding_map.py: reads sweep outputs, pairs each foldable point with its nominal
counterpart, marks failed points, and signs the difference as ``P_foldable - P_nominal``.

The stores are fake (no optimisation) but made of real records: :data:`NOMINAL` and
:data:`FOLDABLE` are records a physical sweep wrote (reel-out 200-250 m, sized line resized to
0.3 mm, 8 m/s), changed only in the fields each test names.
"""

from __future__ import annotations

import hashlib
import importlib.util
import json
import sys
from pathlib import Path
from typing import Any

import pytest

from fdm_awe.errors import InputError

REPO = Path(__file__).resolve().parent.parent
_spec = importlib.util.spec_from_file_location("folding_map", REPO / "scripts" / "folding_map.py")
fm = importlib.util.module_from_spec(_spec)
sys.modules.setdefault("folding_map", fm)  # dataclasses look their module up there
_spec.loader.exec_module(fm)

#: a nominal point's record as a physical sweep wrote it
NOMINAL: dict[str, Any] = {
    "id": "f841c0ea5e0d2293", "scenario": "physical", "config": "nominal", "wind_mps": 8.0, "d0_m": 200.0,
    "d_tf_m": 250.0, "folded_span_m": None, "folded_drag_area_m2": None, "wing_area_m2": None, "fold_time_s": 0.0,
    "mesh": "60x20x4", "max_iter": 1000, "max_iter_total": 3000, "warm_fallback": "all", "propeller": "engine",
    "line_weight": True, "line": "sized", "line_diameter_m": 0.0003, "status": "ok", "reason": "Solve_Succeeded",
    "P_avg_W": 11.057607744014435, "E_net_J": 408.82945041838883, "E_generated_J": 855.2104170802988,
    "E_thrust_J": 176.88390133048054, "E_reel_in_J": 269.4970653314295, "T1_s": 27.103001869299423,
    "T2_s": 9.869683351849902, "iterations": 640, "solve_s": 62.58773931500035, "build_s": 32.65571065599943,
    "wall_s": 96.5111, "cpu_s": 17.2719, "worker": "vm:22863", "warm_from": None,
    "start": "loop +1/-1: loops T1=18.8s T2=12s n=1 r1=59.7m r2=30m turns=+1/-1, refined from mesh 20/10/3, polished",
    "max_violation": 8.854917155076692e-10, "S_u_m2": 0.15125, "b_u_m": 1.1, "chord_m": 0.1375, "S_f_m2": None,
    "b_f_m": None, "AR_f": None, "CLalpha_f": None, "CD0_f": None, "drag_area_f_m2": None, "line_d_m": 0.0003,
    "line_mu_kg_per_m": 5.485220773167778e-05, "line_breaking_load_N": 100.37954014897034, "cold_check": True,
    "kept": None, "P_warm_W": None, "P_cold_W": None, "family": "loop +1/-1", "cold_family": None,
}
#: a foldable point's record of the same sweep (folded span 0.44 m, 2 s fold)
FOLDABLE: dict[str, Any] = {
    **NOMINAL, "id": "0a1b2c3d4e5f6071", "config": "foldable", "folded_span_m": 0.44, "fold_time_s": 2.0,
    "P_avg_W": -20.0, "S_f_m2": 0.0605, "b_f_m": 0.44, "AR_f": 3.2, "CLalpha_f": 3.3, "CD0_f": 0.05,
    "drag_area_f_m2": 0.0025, "family": "loop +1/-1",
}


def rec(base: dict[str, Any], **changes: Any) -> dict[str, Any]:
    """``base`` with ``changes``; a new id (a hash of the record) unless one is given."""
    r = {**base, **changes}
    if "id" not in changes:
        r["id"] = hashlib.sha256(json.dumps(r, sort_keys=True).encode()).hexdigest()[:16]
    return r


def store(folder: Path, records: list[dict[str, Any]]) -> Path:
    """A sweep output folder holding ``records`` as ``points/<id>.json``."""
    (folder / "points").mkdir(parents=True)
    for r in records:
        (folder / "points" / f"{r['id']}.json").write_text(json.dumps(r, indent=1))
    return folder


def failed(base: dict[str, Any], **changes: Any) -> dict[str, Any]:
    return rec(base, status="failed", reason="Maximum_Iterations_Exceeded", P_avg_W=None, E_net_J=None, **changes)


def test_reads_pairs_and_signs(tmp_path):
    nom = [rec(NOMINAL, wind_mps=w, P_avg_W=p) for w, p in ((6.0, -10.0), (8.0, 11.0), (10.0, 30.0))]
    fold = [rec(FOLDABLE, wind_mps=6.0, P_avg_W=-4.0),  # 6 W better than nominal: pays
            rec(FOLDABLE, wind_mps=8.0, P_avg_W=-20.0),  # 31 W worse: loses
            rec(FOLDABLE, wind_mps=10.0, P_avg_W=30.2)]  # 0.2 W: even
    src = store(tmp_path / "sweep", nom + fold)
    recs = fm.read_records(src)
    assert len(recs) == 6
    prs = fm.pairs(recs)
    assert [p.wind_mps for p in prs] == [6.0, 8.0, 10.0]
    by_w = {p.wind_mps: p for p in prs}
    for w, n in zip((6.0, 8.0, 10.0), nom):
        assert by_w[w].id_nominal == n["id"]
        assert by_w[w].dP_W == pytest.approx(by_w[w].P_foldable_W - by_w[w].P_nominal_W)
    assert by_w[6.0].dP_W == pytest.approx(6.0) and by_w[6.0].verdict() == "pays"
    assert by_w[8.0].dP_W == pytest.approx(-31.0) and by_w[8.0].verdict() == "loses"
    assert by_w[10.0].verdict() == "even"
    ans = fm.answer(prs)
    assert [p["wind_mps"] for p in ans["pays"]] == [6.0]
    assert ans["best"]["wind_mps"] == 6.0 and ans["worst"]["wind_mps"] == 8.0
    assert ans["verdicts"] == {"pays": 1, "loses": 1, "even": 1}
    assert "Folding pays (gain > 0.5 W) in 1 of 3" in fm.answer_text(ans)
    md = fm.markdown(prs, ans, [str(src)])
    assert "| 200-250 | 0.3 | 0.44 | 6 | -10.0 | -4.0 | +6.0 | pays |" in md
    assert "Where the difference comes from" in md  # both converged: the energy split is listed


def test_matches_line_diameter_and_reel_out_range(tmp_path):
    thick = dict(line_diameter_m=0.00072, line_d_m=0.00072)
    nom = [rec(NOMINAL, P_avg_W=11.0), rec(NOMINAL, P_avg_W=-3.0, **thick), rec(NOMINAL, P_avg_W=40.0, d0_m=100.0, d_tf_m=150.0)]
    fold = [rec(FOLDABLE, P_avg_W=-5.0, **thick), rec(FOLDABLE, P_avg_W=-5.0, d0_m=100.0, d_tf_m=150.0)]
    prs = fm.pairs(fm.read_records(store(tmp_path / "s", nom + fold)))
    got = {(p.d0_m, p.line_d_m): p for p in prs}
    assert got[(200.0, 0.00072)].id_nominal == nom[1]["id"] and got[(200.0, 0.00072)].dP_W == pytest.approx(-2.0)
    assert got[(100.0, 0.0003)].id_nominal == nom[2]["id"] and got[(100.0, 0.0003)].dP_W == pytest.approx(-45.0)


def test_marks_failed_and_missing(tmp_path):
    nom = [rec(NOMINAL, wind_mps=6.0, P_avg_W=-10.0), failed(NOMINAL, wind_mps=8.0), rec(NOMINAL, wind_mps=10.0, P_avg_W=30.0)]
    fold = [failed(FOLDABLE, wind_mps=6.0), rec(FOLDABLE, wind_mps=8.0, P_avg_W=-2.0), failed(FOLDABLE, wind_mps=10.0),
            rec(FOLDABLE, wind_mps=12.0, P_avg_W=5.0)]
    out = tmp_path / "map"
    assert fm.main([str(store(tmp_path / "s", nom + fold)), "--out", str(out)]) == 0
    doc = json.loads((out / "folding_map.json").read_text())
    v = {p["wind_mps"]: p for p in doc["pairs"]}
    assert v[6.0]["verdict"] == "foldable failed" and v[6.0]["dP_W"] is None and v[6.0]["P_nominal_W"] == -10.0
    assert v[8.0]["verdict"] == "nominal failed" and v[8.0]["P_foldable_W"] == -2.0 and v[8.0]["P_nominal_W"] is None
    assert v[10.0]["verdict"] == "foldable failed"
    assert v[12.0]["verdict"] == "no nominal" and v[12.0]["status_nominal"] == "missing"
    assert doc["answer"]["n_comparable"] == 0 and [p["wind_mps"] for p in doc["answer"]["only_foldable"]] == [8.0]
    md = (out / "folding_map.md").read_text()
    assert "nominal failed" in md and "foldable failed" in md and "| fail |" in md
    assert (out / "folding_map_200-250m.png").stat().st_size > 1000


def test_same_point_twice_keeps_the_better_solution(tmp_path):
    a = store(tmp_path / "a", [rec(NOMINAL, P_avg_W=5.0), rec(FOLDABLE, P_avg_W=-9.0)])
    b = store(tmp_path / "b", [rec(NOMINAL, P_avg_W=7.0, max_iter_total=6000), failed(FOLDABLE)])
    prs = fm.pairs(fm.read_records(a) + fm.read_records(b))
    assert len(prs) == 1
    assert prs[0].P_nominal_W == 7.0 and prs[0].P_foldable_W == -9.0 and prs[0].dP_W == pytest.approx(-16.0)


def test_sweep_json_source_and_bad_inputs(tmp_path, capsys):
    good = [rec(NOMINAL), rec(FOLDABLE)]
    j = tmp_path / "sweep.json"
    j.write_text(json.dumps({"scenario": "physical", "points": good + [{"id": "x"}]}))
    assert len(fm.read_records(j)) == 2  # the broken record is skipped with a warning
    assert "points[2] skipped" in capsys.readouterr().err
    s = store(tmp_path / "s", good)
    (s / "points" / "deadbeefdeadbeef.json").write_text("{ torn")
    assert len(fm.read_records(s)) == 2
    with pytest.raises(InputError, match="source .*does not exist"):
        fm.read_records(tmp_path / "nowhere")
    (tmp_path / "empty").mkdir()
    with pytest.raises(InputError, match="no points/"):
        fm.read_records(tmp_path / "empty")
    assert fm.main([str(s), "--out", str(tmp_path / "o"), "--min-gain", "-1"]) == 2
    assert "--min-gain" in capsys.readouterr().err


def test_no_foldable_points(tmp_path, capsys):
    out = tmp_path / "o"
    assert fm.main([str(store(tmp_path / "s", [rec(NOMINAL)])), "--out", str(out)]) == 0
    assert "nothing to compare" in capsys.readouterr().out
    assert json.loads((out / "folding_map.json").read_text())["pairs"] == []
