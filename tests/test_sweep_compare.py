"""The sweep reproduces itself: the cold check's records and summary, and the point-by-point
comparison of two sweep folders (``fdm-awe sweep --compare``, ``scripts/compare_sweeps.py``).

Real sweep stores on a coarse mesh (20/12 intervals, degree 3), two nominal winds (8 m/s, the
cold anchor, and 9 m/s, warm-started from it and cold-checked): compared with themselves
(no difference), with a doctored copy (flagged; explained only when the records hold a
reason) and with a ``--cold`` run (matched by physical identity although the ids differ).
"""

from __future__ import annotations

import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from fdm_awe.ocp.strategy import TIE_W
from fdm_awe.sweep.compare import compare_folders, physical_key
from fdm_awe.sweep.spec import Point, SweepSpec

ARGS = ["sweep", "--wind", "8,9", "--config", "nominal", "--mesh", "20,12,3", "--workers", "1", "--no-progress"]
ROOT = Path(__file__).resolve().parents[1]


def _sweep(out: Path, *extra: str) -> dict:
    from fdm_awe.cli import main

    assert main(ARGS + ["--out", str(out), "--json", str(out / "sweep.json"), *extra]) == 0
    return json.loads((out / "sweep.json").read_text())


@pytest.fixture(scope="module")
def warm_store(tmp_path_factory):
    out = tmp_path_factory.mktemp("scan_warm")
    return out, _sweep(out)


@pytest.fixture(scope="module")
def cold_store(tmp_path_factory):
    out = tmp_path_factory.mktemp("scan_cold")
    return out, _sweep(out, "--cold")


def _records(out: Path) -> dict[float, dict]:
    return {r["wind_mps"]: r for r in (json.loads(p.read_text()) for p in (out / "points").glob("*.json"))}


def test_cold_check_is_part_of_the_point_id_only_when_on():
    p = Point("physical", "nominal", 5.0, 200.0, 250.0)
    assert p.id == "2ff779eebc59646d"  # the id from before the cold check existed (tests/test_sweep.py)
    assert Point(**{**p.__dict__, "cold_check": True}).id != p.id
    plain = SweepSpec(winds=(8.0, 9.0), configs=("nominal",)).points()
    checked = SweepSpec(winds=(8.0, 9.0), configs=("nominal",), cold_check=True).points()
    assert all(c.cold_check for c in checked) and not any(c.cold_check for c in plain)
    assert not {p.id for p in plain} & {p.id for p in checked}
    # the physical identity does not see the check
    from fdm_awe.sweep.runner import base_record

    assert [physical_key(base_record(p)) for p in plain] == [physical_key(base_record(p)) for p in checked]


@pytest.mark.timeout(600)
def test_warm_points_keep_the_better_of_warm_and_cold(warm_store):
    out, doc = warm_store
    recs = _records(out)
    anchor, warm = recs[8.0], recs[9.0]
    assert anchor["status"] == warm["status"] == "ok"
    assert anchor["warm_from"] is None and anchor["kept"] is None and anchor["cold_check"] is True
    assert anchor["family"] in ("loop +1/+1", "loop +1/-1", "eight +1/+1", "eight +1/-1")
    assert warm["warm_from"] == anchor["id"] and warm["kept"] in ("warm", "cold")
    pw, pc = warm["P_warm_W"], warm["P_cold_W"]
    assert pw is not None or pc is not None
    kept = pw if warm["kept"] == "warm" else pc
    assert kept is not None and math.isclose(warm["P_avg_W"], kept, abs_tol=1e-5)
    other = pc if warm["kept"] == "warm" else pw
    if other is not None:  # the better one is kept (a tie within TIE_W keeps the warm one)
        assert warm["P_avg_W"] >= other - TIE_W - 1e-5
    assert warm["family"] is not None
    if warm["kept"] == "cold":
        assert warm["cold_family"] == warm["family"]
    # the summary and the JSON list the point exactly when the two differ by more than 0.5 W
    differ = pw is None or pc is None or abs(pw - pc) > 0.5
    listed = [d["wind_mps"] for d in doc["cold_check"]["different"]]
    assert doc["cold_check"]["n_checked"] == 1 and listed == ([9.0] if differ else [])
    md = (out / "summary.md").read_text()
    assert "Warm start vs cold solve" in md
    assert ("| 9 |" in md) == differ


@pytest.mark.timeout(600)
def test_a_store_compared_with_itself_agrees(warm_store, tmp_path, capsys):
    out, _ = warm_store
    from fdm_awe.cli import main

    rc = main(["sweep", "--out", str(out), "--compare", str(out), "--json", str(tmp_path / "cmp.json")])
    doc = json.loads((tmp_path / "cmp.json").read_text())
    assert rc == 0 and doc["ok"] and doc["n_matched"] == 2 and doc["max_abs_diff_W"] == 0.0
    assert doc["n_flagged"] == 0 and not doc["only_in_a"] and not doc["only_in_b"]
    assert "reproduced" in capsys.readouterr().out


@pytest.mark.timeout(600)
def test_a_doctored_copy_is_flagged(warm_store, tmp_path):
    out, _ = warm_store
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    path = next(p for p in (copy / "points").glob("*.json") if json.loads(p.read_text())["wind_mps"] == 9.0)
    rec = json.loads(path.read_text())
    rec["P_avg_W"] += 2.0
    path.write_text(json.dumps(rec))
    doc = compare_folders(out, copy)
    row = next(r for r in doc["points"] if r["wind_mps"] == 9.0)
    assert row["flagged"] and math.isclose(row["diff_W"], 2.0, abs_tol=1e-9)
    assert not row["explained"] and not doc["ok"]  # nothing in the records says why
    # the script says the same, exit 1, and writes its JSON
    script = [sys.executable, str(ROOT / "scripts" / "compare_sweeps.py"), str(out), str(copy), "--json",
              str(tmp_path / "c.json")]
    res = subprocess.run(script, capture_output=True, text=True, timeout=120)
    assert res.returncode == 1 and "UNEXPLAINED" in res.stdout and "NOT reproduced" in res.stdout
    assert json.loads((tmp_path / "c.json").read_text())["n_unexplained"] == 1
    # another start family in the copy's record: the difference is explained
    rec["family"] = "eight +1/-1" if rec["family"] != "eight +1/-1" else "loop +1/+1"
    path.write_text(json.dumps(rec))
    doc = compare_folders(out, copy)
    row = next(r for r in doc["points"] if r["wind_mps"] == 9.0)
    assert row["explained"] and any("start families" in w for w in row["explanation"]) and doc["ok"]
    # a failed point is flagged and explained by its reason; a missing point has no partner
    rec.update(status="failed", P_avg_W=None, reason="Maximum_Iterations_Exceeded")
    path.write_text(json.dumps(rec))
    row = next(r for r in compare_folders(out, copy)["points"] if r["wind_mps"] == 9.0)
    assert row["flagged"] and row["explained"] and any("iteration limit" in w for w in row["explanation"])
    path.unlink()
    doc = compare_folders(out, copy)
    assert doc["n_matched"] == 1 and len(doc["only_in_a"]) == 1 and not doc["ok"]


@pytest.mark.timeout(900)
def test_warm_and_cold_runs_match_by_physical_identity(warm_store, cold_store):
    (wa, _), (co, _) = warm_store, cold_store
    doc = compare_folders(wa, co)
    assert doc["n_matched"] == 2 and not doc["only_in_a"] and not doc["only_in_b"]
    rows = {r["wind_mps"]: r for r in doc["points"]}
    assert rows[9.0]["id_a"] != rows[9.0]["id_b"]  # the cold check is in the warm run's ids only
    # the anchor is a cold solve in both runs: the same problem, the same start, the same numbers
    assert rows[8.0]["diff_W"] is not None and abs(rows[8.0]["diff_W"]) < 1e-6
    for r in doc["points"]:  # a flagged point names what differs between the two runs
        assert not r["flagged"] or r["explanation"]
