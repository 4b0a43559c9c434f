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
