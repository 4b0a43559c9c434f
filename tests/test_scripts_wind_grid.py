"""scripts/wind_grid.py: the flights in real wind, run short (one reference, calm and light
turbulence, one seed, one cycle, one worker): every flight completes within the ratings, and bad
input exits 2 with one line."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))

import wind_grid  # noqa: E402

REF = str(ROOT / "tests" / "data" / "ref_physical_nominal_8mps_sized.json")


def test_short_grid_flies_within_the_ratings(tmp_path, capsys):
    out = tmp_path / "grid.json"
    rc = wind_grid.main(["--refs", REF, "--air", "calm,light", "--seeds", "1", "--cycles", "1", "--workers", "1",
                         "--json", str(out), "--report", str(tmp_path / "grid.md")])
    assert rc == 0
    rows = json.loads(out.read_text())["rows"]
    assert [r["air"] for r in rows] == ["calm", "light"]
    for r in rows:
        assert r["status"] == "ok" and r["cycles_complete"] == 1, r["message"]
        assert r["peak_tension_N"] <= 1.2 * 50.0  # the line's rating x 1.2 in calm and light air
        assert r["peak_current_A"] <= 24.2  # the machine's peak rating
    calm, light = rows
    assert calm["track_rms_m"] < 2.0 and light["E_net_J"] < calm["E_net_J"] + 50.0  # gusts cost, never pay much
    assert "| ref_physical_nominal_8mps_sized.json | calm | 1 of 1 |" in capsys.readouterr().out


def test_the_grid_flies_the_line_model_asked_for(tmp_path):
    """``--tether lumped:10``: the flight runs on the lumped line (its own line ledger in the
    row's flight, a different flight from the straight line's), and the JSON names the model."""
    rows = {}
    for tether in ("straight", "lumped:10"):
        out = tmp_path / f"{tether.replace(':', '_')}.json"
        assert wind_grid.main(["--refs", REF, "--air", "calm", "--cycles", "1", "--workers", "1", "--tether", tether,
                               "--json", str(out)]) == 0
        doc = json.loads(out.read_text())
        assert doc["tether"] == tether
        rows[tether] = doc["rows"][0]
    assert rows["lumped:10"]["status"] == "ok" and rows["lumped:10"]["cycles_complete"] == 1
    assert rows["lumped:10"]["E_net_J"] != rows["straight"]["E_net_J"]


@pytest.mark.parametrize("args, word", [
    (["--seeds", "0"], "--seeds"), (["--air", "calm,stormy"], "--air"), (["--refs", "nothere.json"], "--refs"),
    (["--workers", "100"], "--workers"), (["--tether", "lumped:x"], "--tether")])
def test_bad_input_exits_2_with_one_line(args, word, capsys):
    assert wind_grid.main(args) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and word in err
