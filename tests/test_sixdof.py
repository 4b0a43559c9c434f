"""6-DOF glider in JSBSim: frames and units, steady flight against the point-mass model, folding
in flight, turbulence.

Point-mass references are computed here from the aircraft XML's aero/pm values with scipy
(the point-mass equations of docs/design.md), with the density and gravity of JSBSim's
atmosphere at the flight altitude; they never use the 6-DOF model's own numbers.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq, fsolve, minimize_scalar

from fdm_awe import ROOT, slots
from fdm_awe.definitions.xmlutil import XmlDoc
from fdm_awe.sixdof import JSBSimGlider, Stabilizer, Surfaces
from fdm_awe.units import FT, SLUG

pytestmark = pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")

DT = 1.0 / 120.0
TABLE2 = {
    "unfolded": np.array([[0.0194, 0.0, -0.001454], [0.0, 0.01762, 0.0], [-0.001454, 0.0, 0.03499]]),
    "folded": np.array([[0.009606, 0.0, -0.0007104], [0.0, 0.02077, 0.0], [-0.0007104, 0.0, 0.02204]]),
}


def _pm(name: str) -> dict[str, float]:
    doc = XmlDoc.load(ROOT / "aircraft" / name / f"{name}.xml")
    out = {k: doc.property_value(f"aero/pm/{k}") for k in ("CL0", "CLalpha", "CLmax", "CD0", "CDalpha1", "CDalpha2")}
    out["S"] = doc.number("metrics/wingarea")
    out["m"] = doc.number("mass_balance/emptywt")
    return out


def _cl(p, a):
    return p["CL0"] + p["CLalpha"] * a


def _cd(p, a):
    return p["CD0"] + p["CDalpha1"] * a + p["CDalpha2"] * a * a


def _environment(g: JSBSimGlider) -> tuple[float, float]:
    """Air density kg/m^3 and gravity m/s^2 of JSBSim at the glider's current position."""
    return g.fdm["atmosphere/rho-slugs_ft3"] * SLUG / FT**3, g.fdm["accelerations/gravity-ft_sec2"] * FT


def _fly(g: JSBSimGlider, ctrl, seconds: float):
    rows = []
    for _ in range(int(round(seconds / DT))):
        s = g.state()
        surf, _ = ctrl.update(s.t, s, None)
        g.set_controls(surf)
        g.step()
        s = g.state()
        v = s.vel_ned
        rows.append((s.t, s.airspeed, s.alpha, math.hypot(v[0], v[1]), v[2], s.thrust_N, s.phi, s.altitude))
    return np.array(rows)


# ---------------------------------------------------------------------------------------------
def test_reset_places_the_glider_as_requested_in_ned_with_wind():
    wind = (3.0, -1.0, 0.0)
    g = JSBSimGlider("glider_unfolded", wind_ned=wind)
    pos = (120.0, -35.0, -80.0)
    V, gam, psi, alpha = 12.0, -0.05, 0.7, 0.09
    s = g.reset(pos, V, gamma=gam, psi=psi, alpha=alpha)
    # linear geodetic mapping round trip: sub-millimetre
    np.testing.assert_allclose(s.pos_ned, pos, atol=1e-6)
    assert s.airspeed == pytest.approx(V, rel=1e-9)
    assert s.alpha == pytest.approx(alpha, abs=1e-9)
    assert s.beta == pytest.approx(0.0, abs=1e-9)
    v_air = V * np.array([math.cos(gam) * math.cos(psi), math.cos(gam) * math.sin(psi), -math.sin(gam)])
    np.testing.assert_allclose(s.vel_air_ned, v_air, atol=1e-9)
    np.testing.assert_allclose(s.vel_ned, v_air + np.array(wind), atol=1e-9)
    # the quaternion rotates the air velocity into body axes: (V cos a, 0, V sin a)
    w, x, y, z = s.quat
    assert w * w + x * x + y * y + z * z == pytest.approx(1.0, abs=1e-12)
    R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)],
                  [2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x)],
                  [2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)]])
    np.testing.assert_allclose(R @ v_air, [V * math.cos(alpha), 0.0, V * math.sin(alpha)], atol=1e-9)


def test_tether_hook_force_is_newtons_in_ned():
    """Two identical gliders flying north, one pulled 4 N north at the hook: the north velocity
    difference grows at F/m (the extra drag of the 0.4 m/s faster glider is below 1 %)."""
    runs = []
    for force in ((0.0, 0.0, 0.0), (4.0, 0.0, 0.0)):
        g = JSBSimGlider("glider_unfolded")
        g.reset((0.0, 0.0, -100.0), 12.0, gamma=-0.07, psi=0.0)
        ve = []
        for _ in range(13):
            g.set_tether_force(force)
            g.step()
            ve.append(g.state().vel_ned[0])
        runs.append(np.array(ve))
    dv = runs[1] - runs[0]
    m = 0.738
    rate = (dv[12] - dv[2]) / (10 * DT)
    assert rate == pytest.approx(4.0 / m, rel=0.02)


def test_hook_is_below_the_cg_and_moves_with_the_attitude():
    g = JSBSimGlider("glider_unfolded")
    assert g.hook_offset_body[2] > 0.0 and np.linalg.norm(g.hook_offset_body) < 0.02  # below, near the CG
    s = g.reset((10.0, 0.0, -50.0), 12.0, gamma=0.0, psi=0.0, phi=0.5)
    R = np.array([[1, 0, 0], [0, math.cos(s.phi), -math.sin(s.phi)], [0, math.sin(s.phi), math.cos(s.phi)]])
    R = np.array([[math.cos(s.theta), 0, math.sin(s.theta)], [0, 1, 0], [-math.sin(s.theta), 0, math.cos(s.theta)]]) @ R
    R = np.array([[math.cos(s.psi), -math.sin(s.psi), 0], [math.sin(s.psi), math.cos(s.psi), 0], [0, 0, 1]]) @ R
    np.testing.assert_allclose(s.hook_pos_ned - s.pos_ned, R @ g.hook_offset_body, atol=1e-9)


# ---------------------------------------------------------------------------------------------
def test_unfolded_trimmed_glide_matches_the_point_mass_glide():
    p = _pm("glider_unfolded")
    a_star = minimize_scalar(lambda a: -_cl(p, a) / _cd(p, a), bounds=(0.0, 0.3), method="bounded",
                             options={"xatol": 1e-10}).x
    assert a_star == pytest.approx(0.10436, abs=1e-4)  # docs/design.md section 6
    g = JSBSimGlider("glider_unfolded")
    g.reset((0.0, 0.0, -150.0), 10.5, gamma=-0.07, psi=0.0, alpha=a_star)
    rec = _fly(g, Stabilizer(g, alpha_cmd=a_star), 110.0)
    last = rec[-120 * 30:]  # mean over the last 30 s: several phugoid periods (~4.6 s)
    v6, gr6 = last[:, 1].mean(), (last[:, 3] / last[:, 4]).mean()
    rho, grav = _environment(g)
    cl, cd = _cl(p, a_star), _cd(p, a_star)
    gam = -math.atan(cd / cl)
    v_pm = math.sqrt(2 * p["m"] * grav * math.cos(gam) / (rho * p["S"] * cl))
    # 3 % is the acceptance tolerance; the residual is the mean phugoid and alpha-hold error
    assert gr6 == pytest.approx(cl / cd, rel=0.03)
    assert v6 == pytest.approx(v_pm, rel=0.03)
    # the design-note reference (rho 1.225, g 9.81) scaled to this density and gravity
    assert v6 == pytest.approx(10.4859 * math.sqrt(1.225 / rho * grav / 9.81), rel=0.03)
    assert cl / cd == pytest.approx(14.180, rel=1e-3)
    assert np.abs(last[:, 6]).max() < 0.01  # wings level


def test_folded_powered_flight_matches_the_point_mass_steady_state():
    """Folded glider, full throttle, alpha held at 0.30 rad: steady climb. Point-mass steady state
    for the same alpha and the same (measured) thrust, with the thrust along the body axis:
    T cos(a) - D - W sin(g) = 0,  L + T sin(a) - W cos(g) = 0."""
    p = _pm("glider_folded")
    alpha = 0.30
    g = JSBSimGlider("glider_folded")
    g.reset((0.0, 0.0, -300.0), 21.0, gamma=0.0, psi=0.0, alpha=alpha, throttle=1.0)
    rec = _fly(g, Stabilizer(g, alpha_cmd=alpha, throttle=1.0), 40.0)
    last = rec[-120 * 10:]
    v6 = last[:, 1].mean()
    gam6 = math.atan2(-last[:, 4].mean(), last[:, 3].mean())
    thrust = last[:, 5].mean()
    assert thrust > 1.0  # the propeller works
    rho, grav = _environment(g)
    W = p["m"] * grav
    cl, cd = _cl(p, alpha), _cd(p, alpha)

    def residual(x):
        V, gm = x
        q = 0.5 * rho * V * V * p["S"]
        return [thrust * math.cos(alpha) - q * cd - W * math.sin(gm), q * cl + thrust * math.sin(alpha) - W * math.cos(gm)]

    V_pm, gam_pm = fsolve(residual, [20.0, 0.0], xtol=1e-12)
    assert v6 == pytest.approx(V_pm, rel=0.03)
    # climb angle: 3 % of the speed-like scale (sin(gamma) ~ (T - D)/W is a small difference)
    assert gam6 == pytest.approx(gam_pm, abs=0.03 * 1.0 * max(abs(gam_pm), 0.1) + 0.003)
    assert np.abs(last[:, 6]).max() < 0.01  # propeller torque trimmed out by the aileron integral


# ---------------------------------------------------------------------------------------------
def test_folding_in_flight_is_continuous_and_ends_at_table2_mass_properties():
    """Fold at 22 m/s with full throttle, the alpha command blended from the unfolded trim to the
    folded cruise angle (0.30 rad) with the fold state."""
    g = JSBSimGlider("glider_foldable")
    g.reset((0.0, 0.0, -200.0), 22.0, gamma=0.0, psi=0.0, throttle=1.0)
    np.testing.assert_allclose(g.inertia(), TABLE2["unfolded"], rtol=1e-3, atol=2e-6)
    cg0 = g.cg_structural()
    alpha_u, alpha_f = g.state().alpha, 0.30
    ctrl = Stabilizer(g, alpha_cmd=alpha_u, throttle=1.0)
    pos, vel, fold, acc, omega = [], [], [], [], []
    t_fold = 1.0
    for k in range(int(round((t_fold + g.fold_time_s + 1.0) / DT))):
        s = g.state()
        if s.t >= t_fold:
            ctrl.fold_cmd = 1.0
            ctrl.set_alpha_cmd(alpha_u + s.fold * (alpha_f - alpha_u))
        surf, _ = ctrl.update(s.t, s, None)
        g.set_controls(surf)
        g.step()
        s = g.state()
        pos.append(s.pos_ned)
        vel.append(s.vel_ned)
        fold.append(s.fold)
        acc.append(s.accel_body)
        omega.append(s.omega_body)
    pos, vel, fold, acc, omega = map(np.array, (pos, vel, fold, acc, omega))
    assert fold[0] == 0.0 and fold[-1] == pytest.approx(1.0)
    assert np.all(np.diff(fold) >= -1e-12)  # monotonic travel
    assert np.all(np.diff(fold) <= DT / g.fold_time_s + 1e-9)  # rate limited: no jump
    # no jump in position: each step moves by the mean velocity (trapezoid), to 1 mm
    step_err = np.abs(np.diff(pos, axis=0) - 0.5 * (vel[1:] + vel[:-1]) * DT).max()
    assert step_err < 1e-3
    # finite, bounded accelerations: velocity changes stay below 5 g per step, specific force < 8 g
    dv = np.linalg.norm(np.diff(vel, axis=0), axis=1) / DT
    assert np.isfinite(dv).all() and dv.max() < 5 * 9.81
    assert np.isfinite(acc).all() and np.linalg.norm(acc, axis=1).max() < 8 * 9.81
    assert np.isfinite(omega).all() and np.abs(omega).max() < 3.0
    np.testing.assert_allclose(g.inertia(), TABLE2["folded"], rtol=1e-3, atol=2e-6)
    np.testing.assert_allclose(g.cg_structural(), cg0, atol=1e-9)
    assert g.state().mass == pytest.approx(0.738, rel=1e-6)


def test_static_forms_ignore_nothing_and_reject_fold():
    g = JSBSimGlider("glider_unfolded")
    assert not g.foldable
    with pytest.raises(Exception, match="fold"):
        g.reset((0.0, 0.0, -50.0), 12.0, fold=1.0)


def test_surfaces_validate_their_ranges():
    with pytest.raises(Exception, match="Surfaces.throttle"):
        Surfaces(throttle=1.5)
    with pytest.raises(Exception, match="Surfaces.aileron"):
        Surfaces(aileron=float("nan"))
    assert Surfaces.saturated(aileron=3.0, throttle=-1.0, rudder=float("nan")) == Surfaces(aileron=1.0)


# ---------------------------------------------------------------------------------------------
def _turbulent_track(seed: int) -> np.ndarray:
    g = JSBSimGlider("glider_unfolded", wind_ned=(5.0, 0.0, 0.0), turbulence=("moderate", seed))
    g.reset((0.0, 0.0, -150.0), 12.0, gamma=-0.07, psi=0.0)
    ctrl = Stabilizer(g, alpha_cmd=g.state().alpha)
    out = []
    for _ in range(240):
        s = g.state()
        surf, _ = ctrl.update(s.t, s, None)
        g.set_controls(surf)
        g.step()
        s = g.state()
        out.append(np.concatenate((s.pos_ned, s.vel_air_ned - s.vel_ned)))
    return np.array(out)


def test_turbulence_is_seeded_and_reproducible():
    a, b, c = _turbulent_track(7), _turbulent_track(7), _turbulent_track(8)
    np.testing.assert_array_equal(a, b)
    assert np.abs(a - c).max() > 1e-3
    gust = -a[:, 3:] - np.array([5.0, 0.0, 0.0])  # total wind minus the steady wind
    assert np.abs(gust).max() > 0.05  # turbulence is on


def test_reset_starts_the_actuators_at_their_commands():
    g = JSBSimGlider("glider_foldable")
    s = g.reset((0.0, 0.0, -100.0), 22.0, fold=1.0)
    assert s.fold == 1.0  # no rate-limited travel from the previous state
    np.testing.assert_allclose(g.inertia(), TABLE2["folded"], rtol=1e-3, atol=2e-6)
    assert g.fdm["fcs/elevator-pos-rad"] == pytest.approx(g.controls.elevator * g.surface_limits_rad["elevator"])
    # steady-flight alpha for the folded coefficients: lift = weight at 22 m/s
    p = _pm("glider_folded")
    rho, grav = _environment(g)
    cl = p["m"] * grav / (0.5 * rho * 22.0**2 * p["S"])
    assert s.alpha == pytest.approx((cl - p["CL0"]) / p["CLalpha"], rel=1e-6)
    s = g.reset((0.0, 0.0, -100.0), 12.0, fold=0.0)
    assert s.fold == 0.0
    np.testing.assert_allclose(g.inertia(), TABLE2["unfolded"], rtol=1e-3, atol=2e-6)


def test_advance_is_force_step_and_state_and_reads_every_property():
    """advance(fx, fy, fz) (the co-simulation's hot path) gives exactly set_tether_force + step +
    state, and its one-call property reader gives each property's own value."""
    a, b = JSBSimGlider("glider_foldable"), JSBSimGlider("glider_foldable")
    for g in (a, b):
        g.reset((40.0, 0.0, -60.0), 14.0, psi=math.pi)
        g.set_controls(Surfaces(elevator=0.1, aileron=0.05, fold_cmd=1.0))
    for k in range(120):
        f = (-3.0 - 0.01 * k, 0.5, 4.0)
        sa = a.advance(*f)
        b.set_tether_force(f)
        b.step()
        sb = b.state()
        assert sa._r == sb._r and sa._hook == sb._hook and sa._force == sb._force
        assert sa is a.state()
    assert a.raw() == [get() for get in a._get] and a.state().fold > 0.4


def test_raw_row_positions_read_their_named_properties_and_give_the_hook():
    """Each named position of the raw row (fdm_awe.sixdof.row) holds its JSBSim property; the
    hook follows the CG by the body offset rotated to NED (velocity: v + C_bn (omega x o))."""
    from fdm_awe.sixdof import dcm_body_to_ned
    from fdm_awe.sixdof import row as R

    for name in ("glider_foldable", "glider_unfolded"):
        g = JSBSimGlider(name)
        g.reset((40.0, 5.0, -60.0), 14.0, psi=2.0, phi=0.3)
        g.set_controls(Surfaces(aileron=0.3, elevator=-0.2))
        for _ in range(30):
            g.advance(-2.0, 0.5, 3.0)
        r = g.raw()
        assert len(r) == slots.size(R.ROW) == len(R.PROPERTIES)
        for i, prop in R.PROPERTIES.items():
            if i == R.ROW.fold:
                assert r[i] == (g.fdm[R.FOLD_PROPERTY] if g.foldable else 0.0)
            else:
                assert r[i] == g.fdm[prop], prop
        s = g.state()
        c = dcm_body_to_ned(s.phi, s.theta, s.psi)
        o = g.hook_offset_body
        hp, hv = g.hook_kinematics()
        np.testing.assert_allclose(hp, s.pos_ned + c @ o, rtol=0, atol=1e-9)
        np.testing.assert_allclose(hv, s.vel_ned + c @ np.cross(s.omega_body, o), rtol=0, atol=1e-9)
        assert abs(s.omega_body[0]) > 0.01  # the rates take part
