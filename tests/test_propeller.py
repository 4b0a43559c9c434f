"""Propeller power models: momentum theory limits and the paper's static fit."""

import math

import numpy as np
import pytest

from fdm_awe.definitions.aircraft import load_airframe
from fdm_awe.propeller import induced_velocity, power, power_paper, power_physical


@pytest.fixture(scope="module")
def prop():
    return load_airframe("unfolded").propulsion


def test_static_power_is_momentum_theory(prop):
    rho = 1.225
    for T in (0.5, 2.0, 8.0):
        ideal = T * math.sqrt(T / (2 * rho * prop.disk_area))  # T^1.5 / sqrt(2 rho A)
        assert power_physical(T, 0.0, prop, rho) == pytest.approx(prop.P0 + ideal / (prop.eta_prop * prop.eta_motor), rel=1e-12)


def test_induced_velocity_satisfies_momentum_equation(prop):
    rho = 1.225
    for V in (0.0, 5.0, 20.0):
        for T in (0.1, 4.0, 8.0):
            vi = induced_velocity(T, V, rho, prop.disk_area)
            assert T == pytest.approx(2 * rho * prop.disk_area * (V + vi) * vi, rel=1e-10)


def test_physical_model_never_exceeds_100_percent(prop):
    rho = 1.225
    for V in np.linspace(0, 25, 11):
        for T in np.linspace(0.1, 8, 9):
            assert T * V <= (power_physical(T, V, prop, rho) - prop.P0) * prop.eta_prop * prop.eta_motor + 1e-12


def test_paper_fit_is_static_and_more_than_100_percent_in_flight(prop):
    """The paper's P(T) ignores airspeed: at 2 N and 15 m/s it claims less power than T V."""
    assert power_paper(2.0, prop) == power(2.0, 15.0, prop, 1.225, "paper")
    assert 2.0 * 15.0 > power_paper(2.0, prop)
    # and the fit is close to the static momentum curve it was fitted to (within 3 W on 0..8 N)
    for T in np.linspace(0, 8, 17):
        assert abs(power_paper(T, prop) - power_physical(T, 0.0, prop, 1.225)) < 3.0


def test_unknown_scenario(prop):
    with pytest.raises(ValueError, match="scenario"):
        power(1.0, 1.0, prop, 1.225, "magic")


def test_thrust_available_matches_the_jsbsim_propeller_at_full_throttle(prop):
    """The point-mass T_avail(V) fit against the 6-DOF motor + 9x5 propeller (JSBSim) at full
    throttle: within 0.1 N (the fit's own error is 0.01 N; the rest is the transient)."""
    from fdm_awe.sixdof import JSBSimGlider
    from fdm_awe.sixdof.state import Surfaces

    g = JSBSimGlider("glider_unfolded", dt=1 / 120)
    for V0 in (12.0, 16.0, 20.0):
        g.reset([0, 0, -300], V0, alpha=0.05, throttle=1.0)
        for _ in range(120):  # 1 s: the motor reaches its speed
            g.set_controls(Surfaces(0.0, g.controls.elevator, 0.0, 1.0, 0.0))
            g.step()
        s = g.state()
        assert prop.thrust_available(s.airspeed) == pytest.approx(s.thrust_N, abs=0.1)
    assert prop.thrust_available(0.0) == pytest.approx(prop.T_max)
