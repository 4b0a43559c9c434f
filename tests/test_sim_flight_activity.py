"""A flight reports its control activity (surface motion above 0.5 Hz) in its JSON and markdown."""

from __future__ import annotations

import math

from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.recording.report import flight_markdown
from fdm_awe.sim.activity import control_activity
from fdm_awe.sim.flight import fly
from flight_helpers import DATA


def test_a_flown_cycle_reports_its_control_activity():
    ref = TrackingReference.from_ocp_file(DATA / "ref_paper_foldable_3mps.json")
    rep = fly(ref, config="foldable", cycles=1, plant="paper")
    assert rep.status == "ok", rep.message
    doc = rep.as_json()["control_activity"]
    assert set(doc) == {"f_cut_hz", "aileron_rms", "elevator_rms", "rudder_rms", "total_rms"}
    assert doc["f_cut_hz"] == 0.5
    # the flight's own surface commands, measured as fdm_awe.sim.activity measures them
    c = rep.result.controls
    expect = control_activity(c[:, 0], c[:, 1], c[:, 2], rep.result.dt)
    assert doc["total_rms"] == round(expect.total, 6) and 0.0 < doc["total_rms"] < 1.0
    assert math.isclose(doc["total_rms"] ** 2, doc["aileron_rms"] ** 2 + doc["elevator_rms"] ** 2 + doc["rudder_rms"] ** 2,
                        rel_tol=1e-4)
    assert f"total {expect.total:.3f}" in flight_markdown(rep)
