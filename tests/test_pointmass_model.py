"""Point-mass glider against analytic references (docs/design.md section 6) and physics checks."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from fdm_awe.definitions.aircraft import load_glider
from fdm_awe.pointmass.performance import steady_glide
from fdm_awe.pointmass.model import Environment, PointMassModel, wind_vector


@pytest.fixture(scope="module")
def glider():
    return load_glider()


@pytest.fixture(scope="module")
def model(glider):
    af = glider.unfolded
    return PointMassModel(af.mass.mass, af.aero)


def test_steady_glide_matches_design_reference(glider):
    """docs/design.md section 6 values, computed by hand from the section-5 formulas (rel 1e-3)."""
    sg = steady_glide(glider.unfolded.aero, glider.unfolded.mass.mass, rho=1.225, g=9.81)
    ref = {"alpha": 0.10436, "CL": 0.70898, "CD": 0.05000, "L_over_D": 14.180, "V": 10.4859, "gamma": -0.07041}
    for k, v in ref.items():
        assert getattr(sg, k) == pytest.approx(v, rel=1e-3), k


def test_long_integration_converges_to_steady_glide(model, glider):
    """From V=14, gamma=0 at fixed alpha*, the phugoid (damping ratio ~ 1/(sqrt2 L/D)) decays
    by ~exp(-8) in 120 s: state within 1e-3 of the steady glide."""
    sg = steady_glide(glider.unfolded.aero, glider.unfolded.mass.mass)
    u = (sg.alpha, 0.0, 0.0, 0.0)
    sol = solve_ivp(lambda t, x: model.f(x, u), (0, 120), [100.0, 0, -300.0, 14.0, 0.0, 0.0], rtol=1e-10, atol=1e-10)
    V, gamma = sol.y[3, -1], sol.y[4, -1]
    assert V == pytest.approx(sg.V, rel=1e-3)
    assert gamma == pytest.approx(sg.gamma, rel=1e-3)


def test_energy_decreases_at_exactly_the_drag_power(model):
    """No wind, thrust or tether: E(t) - E(0) = -int D V dt (integrated alongside)."""
    def rhs(t, s):
        x = s[:6]
        u = (0.08 + 0.05 * math.sin(t), 0.3 * math.sin(0.5 * t), 0.0, 0.0)
        f = model.f(x, u)
        _, D = model.forces(x, u)["L"], model.forces(x, u)["D"]
        return np.r_[f, -D * x[3]]

    s0 = [50.0, 10.0, -200.0, 13.0, 0.05, 0.3, 0.0]
    sol = solve_ivp(rhs, (0, 30), s0, rtol=1e-11, atol=1e-11, dense_output=True)
    for t in np.linspace(1, 30, 7):
        s = sol.sol(t)
        dE = model.total_energy(s[:6]) - model.total_energy(s0[:6])
        assert dE == pytest.approx(s[6], rel=1e-7, abs=1e-9)
        assert dE < 0


def test_power_balance_closes_with_wind_thrust_and_tether(glider):
    """dE/dt equals thrust + aerodynamic + tether power at random states (finite difference)."""
    af = glider.unfolded
    m = PointMassModel(af.mass.mass, af.aero, Environment(wind_ned=wind_vector(6.0, 200.0)))
    rng = np.random.default_rng(3)
    for _ in range(10):
        x = np.r_[rng.uniform(50, 150, 2), -rng.uniform(50, 150), rng.uniform(8, 20), rng.uniform(-0.4, 0.4), rng.uniform(-3, 3)]
        u = (rng.uniform(0, 0.2), rng.uniform(-1, 1), rng.uniform(0, 8), rng.uniform(0, 40))
        f = m.f(x, u)
        h = 1e-6
        dE = (m.total_energy(x + h * f) - m.total_energy(x - h * f)) / (2 * h)
        pb = m.power_balance(x, u)
        assert dE == pytest.approx(pb["thrust"] + pb["aero"] + pb["tether"], rel=1e-6, abs=1e-6)


def test_free_glider_drifts_with_the_wind(glider):
    af = glider.unfolded
    vw = wind_vector(5.0, 135.0)  # from the south-east
    still = PointMassModel(af.mass.mass, af.aero)
    windy = PointMassModel(af.mass.mass, af.aero, Environment(wind_ned=vw))
    u = (0.1, 0.2, 0.0, 0.0)
    x0 = [0.0, 0.0, -500.0, 12.0, -0.05, 1.0]
    a = solve_ivp(lambda t, x: still.f(x, u), (0, 40), x0, rtol=1e-11, atol=1e-11)
    b = solve_ivp(lambda t, x: windy.f(x, u), (0, 40), x0, rtol=1e-11, atol=1e-11)
    np.testing.assert_allclose(b.y[:, -1] - a.y[:, -1], [40 * vw[0], 40 * vw[1], 0, 0, 0, 0], atol=1e-6)
    assert vw[0] > 0 and vw[1] < 0  # blowing towards the north-west (north +x, west -y)


def test_wind_from_south_blows_north():
    assert wind_vector(3.0, 180.0) == pytest.approx((3.0, 0.0, 0.0))


def test_numpy_and_casadi_agree(glider):
    import casadi as ca

    af = glider.folded
    m = PointMassModel(af.mass.mass, af.aero, Environment(wind_ned=(4.0, -1.0, 0.0)))
    xs, us, cs = ca.SX.sym("x", 6), ca.SX.sym("u", 4), ca.SX.sym("cd")
    F = ca.Function("f", [xs, us, cs], [m.f([xs[i] for i in range(6)], [us[i] for i in range(4)], cs)])
    rng = np.random.default_rng(7)
    for _ in range(20):
        x = np.r_[rng.uniform(20, 200, 2), -rng.uniform(20, 200), rng.uniform(5, 25), rng.uniform(-1, 1), rng.uniform(-4, 4)]
        u = np.r_[rng.uniform(-0.35, 0.35), rng.uniform(-1, 1), rng.uniform(0, 8), rng.uniform(0, 50)]
        cd = rng.uniform(0, 0.3)
        a = m.f(x, u, cd)
        b = np.array(F(x, u, cd)).ravel()
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)


def test_tether_pull_points_to_winch(model):
    x = [100.0, 0.0, -100.0, 15.0, 0.0, 0.0]
    g = model.forces(x, (0.1, 0.0, 0.0, 10.0))["G_n"]
    np.testing.assert_allclose(g, [-10 / math.sqrt(2), 0, 10 / math.sqrt(2)], atol=1e-12)
