"""Propeller power models: momentum theory limits and the paper's static fit."""

import math

import numpy as np
import pytest

from fdm_awe.definitions.aircraft import load_airframe
from fdm_awe.pointmass.propeller import induced_velocity, power, power_paper, power_physical


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


def test_engine_model_is_the_jsbsim_drive(prop):
    """The closed-form drive of the engine files (definitions.engine + propeller.engine_*)
    against JSBSim's motor and 9x5 propeller themselves, at part and full throttle, piece by
    piece on the same instant: fed the measured thrust and the propeller's axial airspeed, the
    model gives JSBSim's propeller speed and the power its propeller absorbs within 0.3 %
    (the tables are the fitted quadratics rounded to 1e-4); JSBSim's motor obeys the model's
    U = I R + 60 n / Kv and shaft power (I - I0) K_t 2 pi n to 1e-3 (the motor takes the rotor
    speed at the start of the step, the property holds the speed at its end). The electrical power of
    the whole chain agrees within 3 %: the glider still changes speed and the rotor follows
    (engine and propeller powers differ by the rotor's acceleration)."""
    from fdm_awe.definitions.engine import load_electric_drive
    from fdm_awe.pointmass.propeller import engine_operating_point, power_engine
    from fdm_awe.sixdof import JSBSimGlider
    from fdm_awe.sixdof.state import Surfaces
    from fdm_awe.units import FT, LBF

    drive = load_electric_drive()
    assert drive.ct == pytest.approx((0.110, -0.035, -0.170), abs=2e-4)  # the files' own quadratics
    assert drive.cp == pytest.approx((0.046, 0.010, -0.070), abs=2e-4)
    g = JSBSimGlider("glider_unfolded", dt=1 / 120)
    pm = g.fdm.get_property_manager()
    rpm = pm.get_node("propulsion/engine[0]/propeller-rpm", False)
    p_req = pm.get_node("propulsion/engine[0]/propeller-power-ftlbps", False)
    for V0, thr in ((12.0, 0.55), (16.0, 0.7), (20.0, 0.85), (14.0, 1.0), (18.0, 0.8)):
        g.reset([0, 0, -300], V0, alpha=0.05, throttle=thr)
        for _ in range(240):
            g.set_controls(Surfaces(0.0, g.controls.elevator, 0.0, thr, 0.0))
            g.step()
        s = g.state()
        assert s.thrust_N > 0.5
        n = rpm.get_double_value() / 60.0
        v_axial = s.airspeed * math.cos(s.alpha) * math.cos(s.beta)
        op = engine_operating_point(s.thrust_N, v_axial, drive, s.rho)
        assert op["n"] == pytest.approx(n, rel=3e-3)
        assert op["shaft_power"] == pytest.approx(p_req.get_double_value() * LBF * FT, rel=3e-3)
        i = s.current_A
        assert i * drive.resistance + 60.0 * n / drive.kv == pytest.approx(thr * drive.max_volts, rel=1e-3)
        assert (i - drive.no_load_current) * drive.torque_constant * 2 * math.pi * n == pytest.approx(s.shaft_power_W, rel=1e-3)
        assert power_engine(s.thrust_N, v_axial, prop, drive, s.rho) == pytest.approx(s.prop_power_W + prop.P0, rel=3e-2)
