"""The motor-off mode: the optimiser chooses the motor's on-fraction s per interval (thrust
s T_on, power s P_on(T_on, V) + (1 - s) P_off).

Checked against the 6-DOF drive (at zero throttle the JSBSim motor stops the propeller: no
thrust, no motor power, so the stopped glider draws only P0), against the model without the
mode (s = 1 is the running drive exactly), and on a solved cycle: where the optimiser stops the
motor, the duty cycle draws no more than the running drive would for the same mean thrust.
"""

from __future__ import annotations

import numpy as np
import pytest

from fdm_awe.definitions.aircraft import load_glider
from fdm_awe.ocp.energy import WinchElectrics, duty_cycled_power, motor_off_power, thrust_power
from fdm_awe.ocp.model import ON_FRACTION, CycleModel
from fdm_awe.ocp.problem import Bounds, CycleProblem, Mesh
from fdm_awe.ocp.build import get_nlp
from fdm_awe.ocp.solve import solve_cycle
from fdm_awe.sixdof import JSBSimGlider
from fdm_awe.sixdof.state import Surfaces

COARSE = Mesh(20, 12, 3)
WIND = (8.0, 0.0)
STATE = [120.0, 10.0, -150.0, 14.0, 0.1, 3.0]


def _model(**kw) -> CycleModel:
    pr = CycleProblem(scenario="physical", wind_speed=8.0, **kw).validate()
    return CycleModel.build(pr, load_glider(), WinchElectrics.from_ground_station(line=pr.line))


def test_stopped_6dof_motor_gives_no_thrust_and_draws_no_power():
    """The off state is the 6-DOF model's: after the throttle is cut the propeller stops within
    a second (the ESC brakes it), then thrust and motor power are exactly zero."""
    g = JSBSimGlider("glider_foldable")
    g.reset((0.0, 0.0, -300.0), 18.0, gamma=-0.1, throttle=1.0)
    el = g.controls.elevator
    for k in range(int(round(1.0 / g.dt))):
        g.set_controls(Surfaces(elevator=el, throttle=1.0))
        g.step()
    assert g.state().thrust_N > 1.0
    g.set_controls(Surfaces(elevator=el, throttle=0.0))
    for k in range(int(round(1.5 / g.dt))):
        g.step()
    for k in range(int(round(1.0 / g.dt))):
        g.step()
        s = g.state()
        assert s.thrust_N == 0.0 and s.prop_power_W == 0.0


def test_on_fraction_one_is_the_running_drive():
    """s = 1 gives exactly the model without the mode (dynamics and power); s = 0 flies no
    thrust and draws P_off = P0."""
    m = _model(config="nominal")
    assert m.motor_off and m.gen_controls[-1] == ON_FRACTION and m.rec_controls[-1] == ON_FRACTION
    P0 = m.gen_airframe.propulsion.P0
    assert motor_off_power(m.gen_airframe.propulsion) == P0
    for T in (0.0, 1.5, 4.0):
        gen_old = m.generation(STATE, [0.1, 0.2, T], WIND)
        gen_on = m.generation(STATE, [0.1, 0.2, T, 1.0], WIND)
        rec_old = m.recovery(STATE + [210.0], [0.1, 0.2, T, -3.0], WIND)
        rec_on = m.recovery(STATE + [210.0], [0.1, 0.2, T, -3.0, 1.0], WIND)
        for old, on in ((gen_old, gen_on), (rec_old, rec_on)):
            assert list(on["f"]) == list(old["f"])
            assert on["P_thr"] == old["P_thr"]
        gen_off = m.generation(STATE, [0.1, 0.2, T, 0.0], WIND)
        assert gen_off["P_thr"] == P0
        assert list(gen_off["f"]) == list(m.generation(STATE, [0.1, 0.2, 0.0], WIND)["f"])
        half = m.recovery(STATE + [210.0], [0.1, 0.2, T, -3.0, 0.5], WIND)
        assert half["P_thr"] == pytest.approx(0.5 * rec_old["P_thr"] + 0.5 * P0, rel=1e-12)


def test_mode_exists_only_where_stopping_saves_power():
    """The running engine drive draws more than P_off at zero thrust at every airspeed the
    optimiser allows, so stopping it can pay; momentum theory draws exactly P_off there and is
    convex in thrust (stopping never pays), so it has no on-fraction control."""
    m = _model(config="nominal")
    prop = m.gen_airframe.propulsion
    b = Bounds()
    V = np.linspace(b.V_min, b.V_max, 41)
    p_on0 = np.asarray(thrust_power(0.0, V, prop, m.rho, "engine", m.drive), float)
    assert np.all(p_on0 > motor_off_power(prop) + 0.5)
    mm = _model(config="nominal", propeller="momentum")
    assert not mm.motor_off and ON_FRACTION not in mm.gen_controls + mm.rec_controls
    assert np.allclose(np.asarray(thrust_power(0.0, V, prop, mm.rho, "physical"), float), motor_off_power(prop))
    # momentum theory: the running drive at the mean thrust never costs more than the duty cycle
    for s in (0.2, 0.5, 0.8):
        for T_on in (1.0, 4.0, 8.0):
            duty = duty_cycled_power(T_on, s, V, prop, mm.rho, "physical")
            cont = thrust_power(s * T_on, V, prop, mm.rho, "physical")
            assert np.all(cont <= duty + 1e-12)


@pytest.fixture(scope="module")
def nominal8():
    pr = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, mesh=COARSE)
    res = solve_cycle(pr)
    return pr, res


def test_optimiser_stops_the_motor_only_where_it_saves(nominal8):
    """On the solved cycle every interval's duty cycle (quadrature over its collocation points)
    draws at most what the running drive would draw for the same mean thrust (a local optimum
    of the convex perspective along s T_on = const; 0.05 W of slack for the tolerances and the
    control smoothing), the mean thrust is within what the propeller gives, and the on-fraction
    is below 1 only where the running drive at zero thrust exceeds P_off."""
    pr, res = nominal8
    assert res.ok, res.reason
    nlp = get_nlp(pr)[0]
    m = nlp.model
    prop = m.gen_airframe.propulsion
    d = nlp.d
    P0 = motor_off_power(prop)
    for ip, ph in enumerate(res.phases):
        X, U = ph["X"], ph["U"]
        assert ph["controls"][-1] == ON_FRACTION
        for k, u in enumerate(U):
            s, T_on = float(u[-1]), float(u[2])
            assert -1e-8 <= s <= 1 + 1e-8
            V = X[k * d + 1:(k + 1) * d + 1, 3]
            w = nlp.B[1:]
            duty = float(np.sum(w * duty_cycled_power(T_on, s, V, prop, m.rho, "engine", m.drive)))
            cont = float(np.sum(w * thrust_power(s * T_on, V, prop, m.rho, "engine", m.drive)))
            assert duty <= cont + 0.05, (ip, k, s, T_on)
            assert s * T_on <= float(np.min(prop.thrust_available(V))) + 1e-6
            if s < 0.999:
                assert np.all(np.asarray(thrust_power(0.0, V, prop, m.rho, "engine", m.drive)) > P0)
    # the booked thrust energy is at least the idle draw of the whole cycle
    assert res.E_thrust_J >= P0 * (res.T1_s + res.T2_s) * (1 - 1e-6)
    # the reference's thrust column is the mean thrust s T_on of each row's interval
    c = res.columns
    for ip, ph in enumerate(res.phases):
        U = ph["U"]
        T_col = c["T"][c["phase"] == ip]
        k = np.minimum(np.arange(len(T_col)) // d, len(U) - 1)
        assert np.array_equal(T_col, U[k, -1] * U[k, 2])
