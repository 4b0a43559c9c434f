"""The line's tension in recovery is free (physical scenario): a control >= 0 the winch's motor
holds while it reels in, with the drive's relations (supply power and full-duty speed against
the tension, the same as the ground station's steady motor), pulling only where the line is
taut. The slack glide-back (tension 0) stays admissible, so the free problem's optimum is at
least as good as the slack-only one."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from fdm_awe.definitions.aircraft import load_glider
from fdm_awe.errors import InputError
from fdm_awe.groundstation.steady import motor_max_reel_in_speed, motor_steady
from fdm_awe.ocp.energy import WinchElectrics, motor_supply_power, reel_in_speed_loss
from fdm_awe.ocp.model import CycleModel
from fdm_awe.ocp.problem import CycleProblem, Mesh
from fdm_awe.ocp.solve import solve_cycle

STATE = [120.0, 10.0, -150.0, 14.0, 0.1, 3.0, 200.0]
WIND = (0.0, -8.0)


def _model(recovery_tension: str) -> CycleModel:
    pr = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, recovery_tension=recovery_tension).validate()
    return CycleModel.build(pr, load_glider(), WinchElectrics.from_ground_station(line=pr.line))


def test_the_drive_relations_are_the_ground_stations():
    """Supply power against a tension is the steady motor's; the full-duty speed falls linearly
    with the tension as the steady motor's does."""
    w = WinchElectrics.from_ground_station()
    gs = w.gs_params
    for v in (1.0, 3.0, 5.0):
        for G in (0.0, 5.0, 20.0):
            assert motor_supply_power(-v, w, G) == pytest.approx(motor_steady(v, G, gs).p_supply, rel=1e-12)
    c = reel_in_speed_loss(w)
    assert c > 0
    for G in (0.0, 10.0, 40.0):
        assert w.reel_in_speed_max() - c * G == pytest.approx(motor_max_reel_in_speed(G, gs), rel=1e-12)
    # pulling costs supply power
    assert motor_supply_power(-3.0, w, 10.0) > motor_supply_power(-3.0, w, 0.0) + 10.0 * 3.0 * 0.5


def test_free_tension_pulls_the_glider_and_costs_the_drive():
    """The recovery block with the tension control: 0 is the slack model exactly; a pull
    decelerates a glider flying away from the winch and raises the supply power."""
    free, slack = _model("free"), _model("slack")
    assert free.rec_controls[:5] == ("alpha", "phi", "T", "v_reel", "G")
    assert "G" not in slack.rec_controls
    u = [0.1, 0.2, 1.0, -3.0]
    s_slack = slack.recovery(STATE, u + [1.0], WIND)
    s_zero = free.recovery(STATE, u + [0.0, 1.0], WIND)
    assert list(s_zero["f"]) == list(s_slack["f"]) and s_zero["P_rw"] == s_slack["P_rw"]
    pull = free.recovery(STATE, u + [10.0, 1.0], WIND)
    assert float(pull["G"]) == 10.0
    assert pull["P_rw"] > s_zero["P_rw"] + 10.0 * 3.0 * 0.5
    # the glider at (120, 10, -150) heading psi = 3 rad flies towards the winch; the pull along
    # the line speeds it up (the line's direction has a component along its velocity)
    assert float(pull["f"][3]) > float(s_zero["f"][3])


def test_paper_scenario_keeps_the_slack_line():
    assert CycleProblem(scenario="paper").recovery_tension == "slack"
    with pytest.raises(InputError, match="recovery_tension"):
        CycleProblem(scenario="paper", recovery_tension="free").validate()
    with pytest.raises(InputError, match="recovery_tension"):
        CycleProblem(recovery_tension="taut").validate()


def test_free_recovery_tension_is_at_least_as_good_as_the_slack_line():
    """On the same coarse mesh, warm from the slack-only optimum, the free problem's optimum is
    at least as good (within the solver's tolerance), pulls only where the line is taut, never
    pushes, and the drive's full-duty speed holds against its pull."""
    pr = CycleProblem(scenario="physical", config="foldable", wind_speed=8.0, mesh=Mesh(20, 10, 3),
                      recovery_tension="slack")
    slack = solve_cycle(pr, coarse=None)
    assert slack.ok, slack.reason
    free = solve_cycle(replace(pr, recovery_tension="free"), warm=slack, coarse=None)
    assert free.ok, free.reason
    assert free.P_avg_W >= slack.P_avg_W - 1e-3
    c = free.columns
    rec = c["phase"] == 1
    G = c["tension"][rec]
    assert np.all(G >= -1e-6)
    w = WinchElectrics.from_ground_station()
    slack_len = c["tether_length"][rec] - np.sqrt(c["x"][rec] ** 2 + c["y"][rec] ** 2 + c["z"][rec] ** 2)
    assert np.all(G * slack_len <= 0.01 + 1e-6)
    assert np.all(-c["reel_speed"][rec] + reel_in_speed_loss(w) * G <= w.reel_in_speed_max() + 1e-6)


def test_supply_voltage_is_a_design_value_of_the_drive():
    """A higher supply voltage reels in faster at full duty (the steady motor's speed at that
    voltage), and the NLP's reel-in bound follows it: the definition's 48 V against the 24 V
    supply of before (11.10 against 5.36 m/s on a slack line)."""
    from fdm_awe.ocp.build import get_nlp

    w = WinchElectrics.from_ground_station()
    assert w.V_a == pytest.approx(48.0)
    assert w.reel_in_speed_max() == pytest.approx(motor_max_reel_in_speed(0.0, w.gs_params), rel=1e-12)
    w24 = w.with_supply_voltage(24.0)
    assert w24.reel_in_speed_max() == pytest.approx(motor_max_reel_in_speed(0.0, w24.gs_params), rel=1e-12)
    # twice the volts, a little more than twice the speed (the fixed drops stay)
    assert w.reel_in_speed_max() > 1.9 * w24.reel_in_speed_max()
    base = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, mesh=Mesh(4, 4, 2))
    v48 = get_nlp(base, cache=False)[0].reel_in_speed_max
    v24 = get_nlp(replace(base, supply_voltage=24.0), cache=False)[0].reel_in_speed_max
    assert v48 == pytest.approx(w.reel_in_speed_max()) and v24 == pytest.approx(w24.reel_in_speed_max())
    with pytest.raises(InputError, match="supply_voltage"):
        CycleProblem(supply_voltage=2.0).validate()
