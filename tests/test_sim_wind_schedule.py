"""Flights with the onboard wind estimate: against JSBSim's true wind at the glider in calm air
and in turbulence, and a reference set whose 12 m/s cycle the autopilot takes after one cycle
of the 8 m/s one in a 12 m/s wind (compiled blocks and the per-step Python autopilot alike)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fdm_awe.autopilot.schedule import ReferenceSet, scheduled
from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.cli import main
from fdm_awe.sim.flight import fly

DATA = Path(__file__).parent / "data"
REF8 = "ref_physical_nominal_8mps_sized.json"
REF12 = "ref_physical_nominal_12mps_sized.json"


def _ref(name: str) -> TrackingReference:
    return TrackingReference.from_ocp_file(DATA / name)


@pytest.mark.parametrize("turbulence, bound", [(None, 0.02), (("light", 1), 0.06)])
def test_the_cycles_wind_estimate_meets_the_true_mean_wind_at_the_glider(turbulence, bound):
    """One cycle of the 8 m/s reference. Calm: measured 0.4 % off (7.97 against 8.00 m/s); what
    is left is the synthetic sideslip's model error (the yaw damper holds the sideslip near, not
    at, zero), so 2 %, a fifth of the issue's 10 %. Light turbulence (seed 1): 2.0 % off; the
    gusts add what the estimate's model leaves out, vertical wind in the airspeed and a sideslip
    the damper has not yet taken out, so 6 %, three times the measured and still inside 10 %."""
    rep = fly(_ref(REF8), config="nominal", cycles=1, turbulence=turbulence)
    assert rep.status == "ok"
    (rec,) = rep.wind_estimates
    assert rec["cycle"] == 0 and rec["complete"] and rec["samples"] > 500
    true = rec["true_at_glider"]["speed_mps"]
    assert true == pytest.approx(8.0, abs=1e-9 if turbulence is None else 1.5)
    assert abs(rec["vector_error_rel"]) < bound and abs(rec["speed_error_rel"]) < bound
    assert rec["estimated"]["sigma_mps"] < 0.05  # a cycle's samples pin the two unknowns down
    assert rep.as_json()["wind_estimates"][0]["cycle"] == 0


def _switch_flight(per_step: bool) -> tuple[object, dict]:
    refs = ReferenceSet([scheduled(_ref(REF8), REF8), scheduled(_ref(REF12), REF12)])
    start = refs.entries[0].reference
    rep = fly(start, config="nominal", cycles=2, references=refs,
              flight_wind={"wind_ned_mps": [12.0, 0.0, 0.0], "wind_mps": 12.0},
              on_step=(lambda k, s, o: None) if per_step else None)
    return rep, rep.as_json()


def test_a_set_of_8_and_12_ms_cycles_in_12_ms_switches_after_the_first_cycle_and_completes():
    rep, doc = _switch_flight(per_step=False)
    assert rep.status == "ok" and doc["wind_mps"] == 12.0
    assert [c.complete for c in rep.cycles] == [True, True]
    first, second = rep.wind_estimates
    assert first["reference_wind_mps"] == 8.0 and second["reference_wind_mps"] == 12.0
    for rec in (first, second):  # the wind the glider met, whichever cycle it flew
        assert rec["estimated"]["speed_mps"] == pytest.approx(12.0, rel=0.10)
        assert abs(rec["vector_error_rel"]) < 0.10
    notes = [text for _, text in rep.autopilot_log]
    assert any(text.startswith("wind estimate cycle 0: ") for text in notes)
    assert "reference switched at cycle 1: 8 -> 12 m/s" in notes
    # the second cycle flew the 12 m/s cycle's period (22 s), not the 8 m/s one's (60 s)
    period12 = _ref(REF12).period
    assert rep.cycles[1].T1_s + rep.cycles[1].T2_s == pytest.approx(period12, rel=0.2)
    assert rep.cycles[0].T1_s + rep.cycles[0].T2_s > 1.5 * period12
    # the switch is flown like a rejoin: the new cycle's path is caught within its generation
    assert "rejoin: on the path" in notes[notes.index("reference switched at cycle 1: 8 -> 12 m/s"):]
    if doc["loop"]["autopilot_compiled_steps"]:  # the Python autopilot at every step: the same bits
        per_step, _ = _switch_flight(per_step=True)
        assert np.array_equal(rep.result.data, per_step.result.data, equal_nan=True)
        assert rep.autopilot_log == per_step.autopilot_log and rep.wind_estimates == per_step.wind_estimates


def test_fly_refuses_bad_reference_set_options_with_one_line_and_exit_2(tmp_path, capsys):
    for argv, words in ((["--references", str(tmp_path / "none")], ("--references", "folder")),
                        (["--references", str(tmp_path)], ("--references", "no reference file")),
                        (["--start-wind", "8"], ("--start-wind", "only with --references")),
                        (["--references", str(tmp_path), "--reference", str(DATA / REF8)],
                         ("--references", "--reference")),
                        (["--references", str(tmp_path), "--start-wind", "30"], ("--start-wind", "0..25")),
                        (["--references", str(tmp_path), "--gamma-max", "0.5"], ("--gamma-max", "--references"))):
        assert main(["fly", *argv]) == 2, argv
        err = capsys.readouterr().err.strip()
        assert "\n" not in err and all(w in err for w in words), (argv, err)


REF10 = "ref_physical_nominal_10mps_sized.json"


@pytest.mark.parametrize("wind", [{"wind_ned_mps": [8.0, 0.0, 0.0], "wind_mps": 8.0,
                                   "wind_profile": {"kind": "log", "ref_height_m": 10.0, "z0_m": 0.1}},
                                  {"wind_ned_mps": [12.0, 0.0, 0.0], "wind_mps": 12.0}],
                         ids=["log-8-at-10m", "uniform-12"])
def test_the_8_ms_cycle_in_a_stronger_wind_takes_the_sets_12_ms_cycle_and_flies_three(wind):
    """Issue 27's acceptance: the cycle optimised for uniform 8 m/s, flown in a log profile
    (open country, z0 0.1 m) with 8 m/s at 10 m height (12.4 m/s measured at the glider's mean
    height) and in uniform 12 m/s, with the set of 8, 10 and 12 m/s cycles: every one of 3
    cycles complete, the second and third on the 12 m/s cycle, and each cycle's onboard wind
    estimate within 10 % of the true mean wind at the glider (measured 0.0-1.2 % off)."""
    refs = ReferenceSet([scheduled(_ref(n), n) for n in (REF8, REF10, REF12)])
    rep = fly(refs.entries[0].reference, config="nominal", cycles=3, references=refs, flight_wind=wind)
    assert rep.status == "ok", rep.message
    assert [c.complete for c in rep.cycles] == [True, True, True]
    recs = rep.wind_estimates
    assert [r["reference_wind_mps"] for r in recs] == [8.0, 12.0, 12.0]
    for rec in recs:
        true = rec["true_at_glider"]["speed_mps"]
        assert 11.0 < true < 14.0  # the stronger wind the 8 m/s cycle was not made for
        assert abs(rec["speed_error_rel"]) < 0.10 and abs(rec["vector_error_rel"]) < 0.10
    assert not [text for _, text in rep.autopilot_log if text.startswith("failsafe")]
