"""The whole system flying: autopilot + 6-DOF JSBSim + ground station, on an optimised cycle."""

import json

import numpy as np
import pytest

from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.flight import LAND_SINK_MAX, fly


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """A physical-scenario cycle at 8 m/s for the nominal glider (real CasADi/IPOPT)."""
    from fdm_awe.ocp.problem import Bounds, CycleProblem
    from fdm_awe.ocp.result import write_reference
    from fdm_awe.ocp.solve import solve_cycle

    res = solve_cycle(CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, bounds=Bounds(alpha_max=0.17, phi_max=0.8)))
    assert res.ok, res.status
    path = tmp_path_factory.mktemp("ref") / "ref.json"
    write_reference(res, path)
    return TrackingReference.from_ocp_file(str(path))


def test_one_cycle_flies_without_event_and_ledger_closes(reference):
    rep = fly(reference, config="nominal", cycles=1)
    assert rep.status == "ok", rep.message
    assert len(rep.cycles) == 1 and rep.cycles[0].complete
    c = rep.cycles[0]
    # the generator delivered energy and the recovery drew from the supply
    assert c.E_generated_J > 0 and c.E_reel_in_J > 0 and c.E_thrust_J > 0
    assert c.E_net_J == pytest.approx(c.E_generated_J - c.E_thrust_J - c.E_reel_in_J)
    # both ledgers close within 1 % of their largest term
    assert rep.ledger_residual_rel < 0.01
    t = rep.ledger
    assert abs(t["glider_residual_J"]) < 0.01 * max(abs(t["glider_aero_work_J"]), abs(t["glider_tether_work_J"]))
    assert np.isfinite(c.track_rms_m)


def test_same_inputs_give_identical_json(reference):
    """Deterministic: the same flight twice gives the same JSON except the wall-clock timing."""
    a = fly(reference, config="nominal", cycles=1, t_end=6.0).as_json()
    b = fly(reference, config="nominal", cycles=1, t_end=6.0).as_json()
    for d in (a, b):
        d.pop("wall_s")
        d.pop("realtime_factor")
    assert json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)


def test_losing_the_reference_recovers_and_lands_near_the_winch(reference):
    """Mission cleared 10 s into the flight: RECOVER reels in, circles down and lands."""
    holder = {}

    def setup(ap, sim):
        holder["ap"] = ap

    def on_step(k, s, o):
        if k == 1200:
            holder["ap"].clear_mission()

    rep = fly(reference, config="nominal", cycles=1, t_end=300.0, setup=setup, on_step=on_step)
    assert holder["ap"].mode == "RECOVER"
    assert rep.status == "landed", rep.message
    r = rep.result
    assert rep.sim_time_s < 300.0
    horizontal = float(np.hypot(r.pos[-1][0], r.pos[-1][1]))
    assert horizontal < 100.0  # on the 60 m recovery circle, give or take the wind drift
    assert float(r.vel[-1][2]) < LAND_SINK_MAX
    from fdm_awe.groundstation import load_ground_station

    assert np.nanmax(r.tension) < 0.5 * load_ground_station().tether.breaking_load  # line intact, with margin
