"""Outer-loop guidance flying the point-mass model (perfect inner loops) along a feasible path."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from fdm_awe.autopilot.guidance_loop import Guidance, GuidanceGains
from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.constants import G0, RHO0
from fdm_awe.definitions.aircraft import load_glider
from fdm_awe.pointmass.model import Environment, PointMassModel

GAINS = GuidanceGains(kp=0.6, kd=1.4, ki=0.02, a_max=15.0, int_max=20.0, alpha_min=-0.2, alpha_max=0.35, phi_max=1.2, thrust_max=8.0)


def _reference(model, T=30.0):
    """A feasible, manoeuvring path: integrate the point mass under smooth controls."""
    def u(t):
        return (0.045 + 0.01 * math.sin(0.3 * t), 0.4 * math.sin(0.25 * t), 0.8 + 0.2 * math.cos(0.2 * t), 0.0)

    x0 = [80.0, 0.0, -100.0, 14.0, 0.0, 0.5]
    sol = solve_ivp(lambda t, x: model.f(x, u(t)), (0, T), x0, rtol=1e-10, atol=1e-10, dense_output=True)
    ts = np.linspace(0, T, 601)
    X = sol.sol(ts).T
    U = np.array([u(t) for t in ts])
    return TrackingReference.from_point_mass(ts, X, U, np.zeros(len(ts), int), np.full(len(ts), 150.0), np.zeros(len(ts)), {0: model}, T, 1e-3)


def test_reference_acceleration_matches_finite_differences():
    g = load_glider()
    model = PointMassModel(g.unfolded.mass.mass, g.unfolded.aero, Environment(wind_ned=(5.0, 0.0, 0.0)))
    ref = _reference(model)
    fd = np.gradient(ref.vel, ref.t, axis=0)
    np.testing.assert_allclose(ref.acc[5:-5], fd[5:-5], atol=2e-2)  # O(h^2) central differences, h = 0.05 s
    fdp = np.gradient(ref.pos, ref.t, axis=0)
    np.testing.assert_allclose(ref.vel[5:-5], fdp[5:-5], atol=2e-2)


@pytest.mark.parametrize("wind", [0.0, 6.0])
def test_guidance_converges_onto_a_feasible_path(wind):
    g = load_glider()
    env = Environment(wind_ned=(wind, 0.0, 0.0))
    model = PointMassModel(g.unfolded.mass.mass, g.unfolded.aero, env)
    ref = _reference(model)
    gd = Guidance(GAINS, g.unfolded.mass.mass, g.unfolded.aero, g.folded.aero, env.rho, env.g)
    # start 10 m off the path and 1 m/s slow
    r0 = ref.sample(0.0)
    x = np.array([r0.pos[0] + 6.0, r0.pos[1] - 8.0, r0.pos[2], r0.airspeed - 1.0, 0.0, 0.5])
    dt, errs = 0.01, []
    w = np.array(env.wind_ned)
    for i in range(int(30 / dt)):
        t = i * dt
        r = ref.sample(t)
        vel = np.array(model.ground_velocity(x))
        cmd = gd.update(r, x[:3], vel, w, np.zeros(3), 0.0, dt)
        u = (cmd.alpha, cmd.mu, cmd.thrust, 0.0)
        # RK4 step with the commanded controls held
        k1 = model.f(x, u); k2 = model.f(x + dt / 2 * k1, u); k3 = model.f(x + dt / 2 * k2, u); k4 = model.f(x + dt * k3, u)
        x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        errs.append(np.linalg.norm(ref.sample(t + dt).pos - x[:3]))
    errs = np.array(errs)
    assert errs[0] > 9.0
    assert errs[-500:].max() < 0.5  # converged within 25 s to well under a metre


def test_periodic_sampling_and_phase():
    g = load_glider()
    model = PointMassModel(g.unfolded.mass.mass, g.unfolded.aero)
    ts = np.linspace(0, 10, 11)
    X = np.tile([100.0, 0, -50, 12, 0, 0], (11, 1))
    U = np.tile([0.1, 0, 0, 0], (11, 1))
    ph = (ts >= 6).astype(int)
    ref = TrackingReference.from_point_mass(ts, X, U, ph, np.full(11, 200.0), np.zeros(11), {0: model, 1: model}, 6.0, 4.0)
    assert ref.sample(3.0).phase == 0 and ref.sample(7.0).phase == 1
    s = ref.sample(23.0)
    assert s.cycle == 2 and s.t_cycle == pytest.approx(3.0) and s.phase == 0


def test_a_heading_error_does_not_turn_the_turn_into_a_brake():
    """Reference: a level 2 g turn at constant speed. With the glider's velocity 20 deg off the
    reference heading (same speed, on the path), the centripetal acceleration is fed forward
    across the glider's velocity: the thrust asked for stays that of the turn itself (drag),
    instead of the brake a NED feed-forward would ask for (|a| sin 20 deg ~ 6.7 m/s^2)."""
    g = load_glider()
    gains = GuidanceGains(kp=0.0, kd=0.0, ki=0.0, a_max=15.0, int_max=20.0, alpha_min=-0.2, alpha_max=0.35,
                          phi_max=1.4, thrust_max=8.0, energy_trade=0.0)
    gd = Guidance(gains, g.unfolded.mass.mass, g.unfolded.aero, g.folded.aero)
    from fdm_awe.autopilot.tracking import RefPoint

    V, a = 20.0, 2.0 * G0
    ref = RefPoint(0.0, 0, 0, np.array([0.0, 0.0, -100.0]), np.array([V, 0.0, 0.0]), np.array([0.0, a, 0.0]),
                   V, 0.0, 0.0, 0.0, 0.0, 100.0, 0.0)
    wind = np.zeros(3)
    on = gd.update(ref, ref.pos, ref.vel, wind, np.zeros(3), 0.0, 0.0)
    c, s = math.cos(math.radians(20.0)), math.sin(math.radians(20.0))
    off = gd.update(ref, ref.pos, np.array([V * c, -V * s, 0.0]), wind, np.zeros(3), 0.0, 0.0)
    assert on.thrust > 0.5  # the drag of a 2 g turn at 20 m/s
    assert off.thrust == pytest.approx(on.thrust, rel=1e-6)
    assert off.alpha == pytest.approx(on.alpha, rel=1e-6)


@pytest.mark.parametrize("negative_lift", [False, True])
def test_a_push_over_is_flown_with_negative_lift(negative_lift):
    """Level flight at 20 m/s, reference accelerating down at 1.5 g: the air must push the
    glider down (0.5 g net). With negative lift the wings stay level at a negative angle of
    attack; without it the guidance can only bank to its limit."""
    from fdm_awe.autopilot.tracking import RefPoint

    g = load_glider()
    aero = g.unfolded.aero
    gains = GuidanceGains(kp=0.0, kd=0.0, ki=0.0, a_max=15.0, int_max=20.0, alpha_min=-0.3, alpha_max=0.35,
                          phi_max=1.1, thrust_max=8.0, negative_lift=negative_lift)
    gd = Guidance(gains, g.unfolded.mass.mass, aero, g.folded.aero)
    V = 20.0
    ref = RefPoint(0.0, 0, 0, np.array([0.0, 0.0, -100.0]), np.array([V, 0.0, 0.0]), np.array([0.0, 0.0, 1.5 * G0]),
                   V, 0.0, 0.0, 0.0, 0.0, 100.0, 0.0)
    c = gd.update(ref, ref.pos, ref.vel, np.zeros(3), np.zeros(3), 0.0, 0.0)
    down_force = g.unfolded.mass.mass * 0.5 * G0
    if negative_lift:
        assert c.mu == pytest.approx(0.0, abs=1e-9)
        # the wing's (negative) lift and the propeller's share along the lift axis (thrust on
        # the body x-axis, alpha below the air velocity) push down together
        qS = 0.5 * RHO0 * V * V * aero.S
        assert c.alpha < 0.0 and c.thrust > 0.0
        assert c.lift_coefficient == pytest.approx(aero.CL0 + aero.CLalpha * c.alpha, rel=1e-9)
        assert qS * c.lift_coefficient + c.thrust * math.sin(c.alpha) == pytest.approx(-down_force, rel=1e-4)
    else:
        assert abs(c.mu) == pytest.approx(1.1)


def _lift_vector(gd, cmd, vel, wind=np.zeros(3)):
    """Force across the air velocity [N, NED] the command asks for (fold 0): the wing's lift
    q S CL and the thrust's share T sin(alpha) (thrust on the body x-axis) along the banked lift
    axis."""
    va = vel - wind
    V = float(np.linalg.norm(va))
    e1 = va / V
    h = math.hypot(e1[0], e1[1])
    right0 = np.array([-e1[1], e1[0], 0.0]) / h
    up0 = np.cross(right0, e1)
    eL = math.cos(cmd.mu) * up0 + math.sin(cmd.mu) * right0
    prop = cmd.thrust * math.sin(cmd.alpha) if gd.k.thrust_on_body_axis else 0.0
    return (0.5 * RHO0 * V * V * gd.aero_u.S * cmd.lift_coefficient + prop) * eL


def test_a_faster_glider_turns_on_the_paths_radius():
    """Level 2 g turn of the reference at 20 m/s, the glider on the path at 26 m/s: with the
    curvature scaling the turn asks (26/20)^2 of the reference's centripetal acceleration (the
    path's radius at the glider's speed); without it, the reference's acceleration as it stands.
    A slower glider keeps the reference's acceleration (only scaled up: a lagging glider, e.g. on
    a slack line, keeps the full turn)."""
    from fdm_awe.autopilot.tracking import RefPoint

    g = load_glider()
    m = g.unfolded.mass.mass
    V, a = 20.0, 2.0 * G0
    ref = RefPoint(0.0, 0, 0, np.array([0.0, 0.0, -100.0]), np.array([V, 0.0, 0.0]), np.array([0.0, a, 0.0]),
                   V, 0.0, 0.0, 0.0, 0.0, 100.0, 0.0)
    for Vg, scale_max, factor in ((26.0, 2.25, (26.0 / V) ** 2), (26.0, None, 1.0), (26.0, 1.2, 1.2), (16.0, 2.25, 1.0)):
        vel = np.array([Vg, 0.0, 0.0])
        gains = GuidanceGains(kp=0.0, kd=0.0, ki=0.0, a_max=15.0, int_max=20.0, alpha_min=-0.2, alpha_max=0.35,
                              phi_max=1.4, thrust_max=8.0, energy_trade=0.0, curv_scale_max=scale_max)
        gd = Guidance(gains, m, g.unfolded.aero, g.folded.aero)
        c = gd.update(ref, ref.pos, vel, np.zeros(3), np.zeros(3), 0.0, 0.0)
        lift = _lift_vector(gd, c, vel)
        assert lift[1] == pytest.approx(m * a * factor, rel=1e-6)
        assert -lift[2] == pytest.approx(m * G0, rel=1e-6)


def test_the_bank_limit_opens_in_a_steep_dive():
    """A 3 g turn to the east asked in a 60 deg dive needs 81 deg of wind-axis bank: the level
    flight limit (63 deg) would tilt the lift away from the turn; LIM_BANK_VERT lets it bank
    there, while the same demand in level flight stays at the level-flight limit."""
    from fdm_awe.autopilot.tracking import RefPoint

    g = load_glider()
    m = g.unfolded.mass.mass
    gains = GuidanceGains(kp=0.0, kd=0.0, ki=0.0, a_max=15.0, int_max=20.0, alpha_min=-0.2, alpha_max=0.35,
                          phi_max=1.1, thrust_max=8.0, energy_trade=0.0, phi_max_vertical=2.2)
    V, a = 25.0, 3.0 * G0
    gam = math.radians(-60.0)
    vel = V * np.array([math.cos(gam), 0.0, -math.sin(gam)])
    for v, expect in ((vel, None), (np.array([V, 0.0, 0.0]), 1.1)):
        gd = Guidance(gains, m, g.unfolded.aero, g.folded.aero)
        ref = RefPoint(0.0, 0, 0, np.array([0.0, 0.0, -100.0]), v, np.array([0.0, a, 0.0]), V, 0.0, 0.0, 0.0, 0.0, 100.0, 0.0)
        c = gd.update(ref, ref.pos, v, np.zeros(3), np.zeros(3), 0.0, 0.0)
        if expect is None:
            e1 = v / V
            F = m * (np.array([0.0, a, 0.0]) - np.array([0.0, 0.0, G0]))
            F_perp = F - float(F @ e1) * e1
            assert c.mu > 1.3  # past the level-flight limit, inside 1.1 + 1.1 * sin^2(60 deg)
            np.testing.assert_allclose(_lift_vector(gd, c, v), F_perp, rtol=1e-6, atol=1e-9)
        else:
            assert c.mu == pytest.approx(expect)


def test_overspeed_on_a_taut_line_pulls_harder():
    """Taut line, glider 10 m/s faster than its reference: GUID_VTENS = 8 N s/m over a 3 m/s
    margin asks 8 * 7 = 56 N more radial (lift) force than the reference's; at the reference's
    speed it asks nothing more."""
    from fdm_awe.autopilot.tracking import RefPoint

    g = load_glider()
    m = g.unfolded.mass.mass
    pos = np.array([100.0, 0.0, -173.2])
    e_r = pos / np.linalg.norm(pos)
    V = 22.0
    ref = RefPoint(0.0, 0, 0, pos, np.array([0.0, V, 0.0]), np.zeros(3), V, 0.0, 0.0, 0.0, 50.0, 200.0, 0.0)
    tf = -50.0 * e_r
    radial = {}
    for k_v in (0.0, 8.0):
        gains = GuidanceGains(kp=0.0, kd=0.0, ki=0.0, a_max=15.0, int_max=20.0, alpha_min=-0.2, alpha_max=0.35,
                              phi_max=1.1, thrust_max=8.0, energy_trade=0.0, overspeed_tension=k_v, overspeed_margin=3.0)
        for dv in (0.0, 10.0):
            gd = Guidance(gains, m, g.unfolded.aero, g.folded.aero)
            vel = np.array([0.0, V + dv, 0.0])
            c = gd.update(ref, pos, vel, np.zeros(3), tf, 0.0, 0.0, taut=True)
            radial[k_v, dv] = float(_lift_vector(gd, c, vel) @ e_r)
    assert radial[8.0, 0.0] == pytest.approx(radial[0.0, 0.0], rel=1e-9)
    assert radial[8.0, 10.0] - radial[0.0, 10.0] == pytest.approx(56.0, rel=1e-6)


def test_reference_pull_on_a_slack_line_flies_the_references_radial_force():
    """GUID_REFPULL, line not taut: the wing's force does not answer the measured radial line
    pull (0 N or 30 N give the same command) and is the force of the measured-pull inversion
    with the reference's tension in place of the measured one: the lift vector differs from the
    plain inversion's (measured 0 N) by exactly the reference tension along the radius. A
    measured force across the radius still counts."""
    from fdm_awe.autopilot.tracking import RefPoint

    g = load_glider()
    m = g.unfolded.mass.mass
    pos = np.array([80.0, 20.0, -120.0])
    e_r = pos / np.linalg.norm(pos)
    V = 14.0
    vel = np.array([0.0, V, 0.0])
    gains = GuidanceGains(kp=0.0, kd=0.0, ki=0.0, a_max=15.0, int_max=20.0, alpha_min=-0.2, alpha_max=0.35,
                          phi_max=1.1, thrust_max=0.0, energy_trade=0.0)
    T_ref = 6.0
    ref = RefPoint(0.0, 1, 0, pos, vel, np.zeros(3), V, 0.0, 0.0, 0.0, T_ref, 150.0, -2.0)

    def lift(tf, pull):
        gd = Guidance(gains, m, g.unfolded.aero, g.folded.aero)
        c = gd.update(ref, pos, vel, np.zeros(3), tf, 0.0, 0.0, taut=False, ref_pull=pull)
        return c, _lift_vector(gd, c, vel)

    c0, l0 = lift(np.zeros(3), True)
    c30, l30 = lift(-30.0 * e_r, True)
    assert (c0.alpha, c0.mu) == pytest.approx((c30.alpha, c30.mu), abs=1e-12)
    _, plain = lift(np.zeros(3), False)
    e1 = vel / V
    want = plain + T_ref * (e_r - float(e_r @ e1) * e1)  # the tension's part across the air velocity
    np.testing.assert_allclose(l0, want, rtol=1e-6, atol=1e-9)
    _, side = lift(np.array([0.0, 0.0, 5.0]) - float(np.array([0.0, 0.0, 5.0]) @ e_r) * e_r, True)
    assert float(np.linalg.norm(side - l0)) > 1.0  # a tangential line force is still fed forward


# ------------------------------------------------------------------ the scalar form vs the vectors
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _vector_guidance(gd, ref, pos, vel, wind, tf, fold, dt, taut, ref_pull=False):
    """Guidance.update in its vector formulas (numpy on 3-vectors, dots summed left to right):
    the specification the scalar implementation follows operation by operation."""
    from fdm_awe.autopilot.guidance import blended_polar, cross, norm3

    k = gd.k
    e_p, e_v = ref.pos - pos, ref.vel - vel
    g_vec = np.array([0.0, 0.0, gd.g])
    if taut:
        e_r = pos / max(norm3(pos), 1e-6)
        e_p = e_p - _dot(e_p, e_r) * e_r
        e_v = e_v - _dot(e_v, e_r) * e_r
    integral = np.clip(np.array(gd.integral) + e_p * dt, -k.int_max, k.int_max)
    corr = k.kp * e_p + k.kd * e_v + k.ki * integral
    n = norm3(corr)
    if n > k.a_max:
        corr = corr * (k.a_max / n)
    a_ff = ref.acc
    va_ref, va0 = ref.vel - wind, vel - wind
    v_ref, v0 = norm3(va_ref), norm3(va0)
    if v_ref > 1.0 and v0 > 1.0:
        t_ref, t_now = va_ref / v_ref, va0 / v0
        a_t = _dot(a_ff, t_ref)
        a_n = a_ff - a_t * t_ref
        a_p = a_n - _dot(a_n, t_now) * t_now
        n_p, n_n = norm3(a_p), norm3(a_n)
        if n_p > 1e-9:
            scale = 1.0 if k.curv_scale_max is None else min(max((v0 / v_ref) * (v0 / v_ref), 1.0), k.curv_scale_max)
            a_p = a_p * (n_n / n_p * scale)
        a_ff = a_t * t_now + a_p
    F = gd.m * ((a_ff + corr) - g_vec) - tf
    if taut:
        e_rr = ref.pos / max(norm3(ref.pos), 1e-6)
        F_r = _dot(gd.m * (ref.acc - g_vec), e_rr) + ref.tension
        if k.overspeed_tension > 0.0 and v_ref > 1.0:
            F_r += k.overspeed_tension * max(v0 - v_ref - k.overspeed_margin, 0.0)
        F = F - _dot(F, e_r) * e_r + F_r * e_r
    elif ref_pull:
        e_rr = ref.pos / max(norm3(ref.pos), 1e-6)
        F = F + (ref.tension + _dot(tf, e_rr)) * e_rr
    va = vel - wind
    V = max(norm3(va), 1.0)
    e1 = va / V
    F_par = _dot(F, e1)
    F_perp = F - F_par * e1
    cl0, cla, clmax, cd0, cd1, cd2 = blended_polar(gd.aero_u, gd.aero_f, fold)
    q = 0.5 * gd.rho * V * V
    horiz = math.sqrt(e1[0] * e1[0] + e1[1] * e1[1])
    right0 = np.array([-e1[1], e1[0], 0.0]) / horiz if horiz > 1e-6 else np.array([0.0, 1.0, 0.0])
    up0 = cross(right0, e1)
    a_stall = (clmax - cl0) / cla
    for _ in range(2):
        alpha = min(max((norm3(F_perp) / q - cl0) / cla, k.alpha_min), min(k.alpha_max, a_stall))
        excess = F_par + q * (cd0 + cd1 * alpha + cd2 * alpha * alpha)
        t_par = k.thrust_max * math.cos(alpha) if k.thrust_on_body_axis else k.thrust_max
        if excess < 0.0:
            F_perp = F - F_par * e1 - k.energy_trade * excess * up0
        elif excess > t_par:
            F_perp = F - F_par * e1 - k.energy_trade * (excess - t_par) * up0
        else:
            break
    L = norm3(F_perp)
    mu = math.atan2(_dot(F_perp / L, right0), _dot(F_perp / L, up0)) if L > 1e-6 else 0.0
    if k.negative_lift and abs(mu) > math.pi - k.phi_max:
        mu -= math.copysign(math.pi, mu)
        L = -L
    a_hi = min(k.alpha_max, a_stall)
    alpha = min(max((L / q - cl0) / cla, k.alpha_min), a_hi)
    if k.thrust_on_body_axis:
        # thrust along the body x-axis: T cos(alpha) - D = F_par, L_wing + T sin(alpha) = L
        drag = q * (cd0 + cd1 * alpha + cd2 * alpha * alpha)
        for _ in range(3):
            thrust = min(max((F_par + drag) / math.cos(alpha), 0.0), k.thrust_max)
            alpha = min(max(((L - thrust * math.sin(alpha)) / q - cl0) / cla, k.alpha_min), a_hi)
            drag = q * (cd0 + cd1 * alpha + cd2 * alpha * alpha)
        thrust = min(max((F_par + drag) / math.cos(alpha), 0.0), k.thrust_max)
    else:
        thrust = min(max(F_par + q * (cd0 + cd1 * alpha + cd2 * alpha * alpha), 0.0), k.thrust_max)
    phi_lim = k.phi_max
    if k.phi_max_vertical is not None and k.phi_max_vertical > k.phi_max:
        phi_lim += (k.phi_max_vertical - k.phi_max) * (1.0 - horiz * horiz)
    mu = min(max(mu, -phi_lim), phi_lim)
    eL = math.cos(mu) * up0 + math.sin(mu) * right0
    ca, sa = math.cos(alpha), math.sin(alpha)
    xb, zb = ca * e1 + sa * eL, sa * e1 - ca * eL
    yb = cross(zb, xb)
    return (alpha, mu, thrust, math.atan2(float(yb[2]), float(zb[2])), -math.asin(max(-1.0, min(1.0, float(xb[2])))),
            math.atan2(float(xb[1]), float(xb[0])),
            (cl0 + cla * alpha) / ((1 - fold) * gd.aero_u.S + fold * gd.aero_f.S), norm3(e_p), integral.tolist())


@pytest.mark.parametrize("variant", ["plain", "curvature", "negative_lift", "vertical_bank", "thrust_on_velocity"])
def test_scalar_guidance_is_the_vector_formulas_bit_for_bit(variant):
    """The scalar implementation (written out for speed) gives exactly the numbers of the vector
    formulas, over random states covering taut/slack line, energy trade both ways, saturated
    correction, vertical flight and the fold range."""
    from dataclasses import replace

    from fdm_awe.autopilot.tracking import RefPoint

    g = load_glider()
    gains = replace(GAINS, overspeed_tension=8.0, overspeed_margin=3.0, energy_trade=1.0,
                    curv_scale_max=2.25 if variant == "curvature" else None,
                    negative_lift=variant == "negative_lift",
                    phi_max_vertical=2.2 if variant == "vertical_bank" else None,
                    thrust_on_body_axis=variant != "thrust_on_velocity")
    gd = Guidance(gains, g.unfolded.mass.mass, g.unfolded.aero, g.folded.aero)
    rng = np.random.default_rng({"plain": 1, "curvature": 2, "negative_lift": 3, "vertical_bank": 4,
                                 "thrust_on_velocity": 5}[variant])
    for i in range(400):
        pos = rng.normal(0.0, 80.0, 3) + np.array([0.0, 0.0, -60.0])
        vel = rng.normal(0.0, 12.0, 3)
        if i % 50 == 7:
            vel = np.array([0.0, 0.0, rng.choice([-15.0, 15.0])])  # vertical flight
        ref = RefPoint(t_cycle=0.0, cycle=0, phase=0, pos=pos + rng.normal(0.0, 5.0 if i % 3 else 40.0, 3),
                       vel=vel + rng.normal(0.0, 3.0, 3), acc=rng.normal(0.0, 15.0, 3), airspeed=15.0, alpha=0.1,
                       phi=0.0, thrust=1.0, tension=float(rng.uniform(0.0, 60.0)), length=100.0, reel_speed=1.0)
        wind = np.array([rng.uniform(0.0, 12.0), rng.normal(0.0, 1.0), 0.0])
        tf = rng.normal(0.0, 30.0, 3)
        fold, dt, taut, pull = float(rng.uniform(0.0, 1.0)), 1.0 / 120.0, bool(i % 2), bool(i % 4 in (0, 3))
        want = _vector_guidance(gd, ref, pos, vel, wind, tf, fold, dt, taut, pull)
        c = gd.update(ref, pos, vel, wind, tf, fold, dt, taut=taut, ref_pull=pull)
        got = (c.alpha, c.mu, c.thrust, c.roll, c.pitch, c.yaw, c.lift_coefficient, c.pos_error, list(gd.integral))
        assert got == want, (i, got, want)


def test_guidance_polar_is_the_6dof_models_fold_blend():
    """The guidance inverts the polar the 6-DOF model flies: aero.fold_blend (C S linear in the
    fold state on the unfolded area), the unfolded and folded forms at its ends."""
    from fdm_awe.pointmass.aero import fold_blend
    from fdm_awe.autopilot.guidance import blended_polar

    g = load_glider()
    u, f = g.unfolded.aero, g.folded.aero
    gd = Guidance(GAINS, g.unfolded.mass.mass, u, f)
    for fold in (0.0, 0.25, 0.5, 0.8, 1.0):
        a = fold_blend(u, f, fold)
        want = (a.S * a.CL0, a.S * a.CLalpha, a.S * a.CLmax, a.S * a.CD0, a.S * a.CDalpha1, a.S * a.CDalpha2)
        assert gd.polar(fold) == want == blended_polar(u, f, fold)
    assert blended_polar(u, f, 0.0) == (u.S * u.CL0, u.S * u.CLalpha, u.S * u.CLmax, u.S * u.CD0, u.S * u.CDalpha1,
                                        u.S * u.CDalpha2)
    np.testing.assert_allclose(blended_polar(u, f, 1.0), (f.S * f.CL0, f.S * f.CLalpha, f.S * f.CLmax, f.S * f.CD0,
                                                          f.S * f.CDalpha1, f.S * f.CDalpha2), rtol=1e-13)


def test_thrust_limit_of_a_step():
    """The thrust available this step: None is the gains' limit exactly; with the motor stopped
    (0) the guidance commands no thrust and trades the along-path force it lacks through the
    flight path (nose lower: height into speed)."""
    from fdm_awe.autopilot.tracking import RefPoint

    g = load_glider()
    pos, vel = np.array([100.0, 0.0, -100.0]), np.array([0.0, 12.0, 0.0])
    ref = RefPoint(0.0, 0, 0, pos + np.array([0.0, 6.0, 0.0]), np.array([0.0, 15.0, 0.0]), np.zeros(3), 15.0, 0.1, 0.0,
                   1.0, 0.0, 150.0, 0.0)
    cmds = {}
    for limit in (None, GAINS.thrust_max, 0.0):
        gd = Guidance(GAINS, g.unfolded.mass.mass, g.unfolded.aero, g.folded.aero)
        cmds[limit] = gd.update(ref, pos, vel, np.zeros(3), np.zeros(3), 0.0, 0.01, thrust_max=limit)
    assert cmds[None] == cmds[GAINS.thrust_max]
    assert cmds[None].thrust > 0.5
    assert cmds[0.0].thrust == 0.0 and cmds[0.0].pitch < cmds[None].pitch - 0.01
