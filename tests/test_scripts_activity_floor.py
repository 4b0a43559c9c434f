"""scripts/activity_floor.py: the surfaces a perfect autopilot needs to fly a reference lie
below what the real autopilot flies on it; bad input exits 2 with one line."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "scripts"))
import activity_floor  # noqa: E402

from fdm_awe.autopilot.tracking import TrackingReference  # noqa: E402
from fdm_awe.sim.flight import fly  # noqa: E402
from flight_helpers import DATA  # noqa: E402


def test_the_floor_lies_below_the_flown_activity(tmp_path):
    """The demo's nominal cycle (8 m/s, sized line): its floor (0.059 over 2 cycles and over the
    demo's 3) is below the autopilot's own activity on the same cycles (0.140 over 3): the
    flown surfaces do what the floor needs and more (a factor 2.4 measured; asserted: more than
    1.2). The JSON carries the fields the script prints."""
    ref = TrackingReference.from_ocp_file(DATA / "ref_physical_nominal_8mps_sized.json")
    out = tmp_path / "floor.json"
    assert activity_floor.main(["--reference", str(DATA / "ref_physical_nominal_8mps_sized.json"), "--config",
                                "nominal", "--cycles", "2", "--json", str(out)]) == 0
    doc = json.loads(out.read_text())
    assert set(doc) >= {"config", "cycles", "period_s", "aileron_rms", "elevator_rms", "rudder_rms", "total_rms"}
    floor = doc["total_rms"]
    assert 0.01 < floor < 0.2
    rep = fly(ref, config="nominal", cycles=2)
    assert rep.status == "ok", rep.message
    assert rep.control_activity.total > 1.2 * floor, (rep.control_activity.total, floor)


@pytest.mark.parametrize("argv, text", [(["--config", "bogus"], "--config 'bogus'"),
                                        (["--config", "nominal", "--cycles", "0"], "--cycles 0"),
                                        (["--config", "nominal", "--json", "/nonexistent-folder/x.json"], "--json")])
def test_bad_input_exits_2_with_one_line(argv, text, capsys):
    rc = activity_floor.main(["--reference", str(DATA / "ref_physical_nominal_8mps_sized.json"), *argv])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and text in err[0], err
