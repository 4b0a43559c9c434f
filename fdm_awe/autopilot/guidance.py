"""Outer loop: track the reference path by point-mass force inversion.

The commanded acceleration ``a_cmd = a_ref + Kp e_p + Kd e_v + Ki int(e_p)`` (errors in NED,
saturated) is turned into the force the air must provide,
``F = m (a_cmd - g) - F_tether`` (the tether force is measured at the ground station and
fed forward), and split along the air velocity (thrust minus drag) and across it (lift).
The propeller pushes along the body x-axis, alpha above the air velocity: ``T cos(alpha)``
of it acts along the path and ``T sin(alpha)`` across it with the lift, so the wing lifts the
rest (:attr:`~.guidance_loop.GuidanceGains.thrust_on_body_axis`). The wing's lift gives the lift
coefficient and so the angle of attack; the direction of the force across the air velocity
gives the wind-axis bank. The desired body attitude follows from the
air velocity, alpha and bank (no sideslip), and the inner loops fly it.

The arithmetic is one step as pure functions of floats and float64 arrays
(:func:`guidance_step`, :func:`polar_at`): numba compiles them into a compiled loop, or they run
as plain Python (:class:`~.guidance_loop.Guidance` holds the state and calls them), with the
same results.
"""

from __future__ import annotations

import math

import numpy as np

from .. import slots
from ..pointmass.aero import POLAR_FIELDS, blend_coefficient
from ..definitions.aircraft import AeroParams, stall_speed

#: a 3-vector as three floats (the guidance's arithmetic is written on scalars)
Vec3 = tuple[float, float, float]
#: a wing polar as ``S*coefficient`` values (:func:`blended_polar`)
Polar = tuple[float, float, float, float, float, float]
#: a float64 array of the pure functions' arguments (the Python step may pass the same floats as
#: a list or tuple: the same arithmetic)
Floats = np.ndarray | list[float] | tuple[float, ...]

#: layout of the gains vector (:meth:`~.guidance_loop.GuidanceGains.vector`): the fields of
#: :class:`~.guidance_loop.GuidanceGains` in their order; ``curvmax`` and ``phi_max_vert`` NaN for
#: None, ``neglift`` and ``body_axis`` 0.0/1.0; then the underspeed protection's (:mod:`.underspeed`):
#: entry and exit airspeeds in stall speeds, hold time, alpha margin below the stall, speed gain,
#: pull away from the winch, the airspeed in stall speeds up to which the alpha margin acts; then
#: the ground-proximity guard's (:mod:`.ground`): the floor [m], the pull-up acceleration
#: [m/s^2], the climb rate [m/s] at which it stops asking for more; then the lift [in weights]
#: below which the folded wing's bank fades to wings level (:func:`_command`; 0: off)
GK = slots.declare("GuidanceGains", ("kp", "kd", "ki", "amax", "imax", "alpha_min", "alpha_max", "phi_max",
                                     "thrust_max", "etrade", "neglift", "curvmax", "vtens", "vmargin", "phi_max_vert",
                                     "body_axis", "us_enter", "us_exit", "us_hold", "us_amargin", "us_kv", "us_slack",
                                     "us_amargv", "gp_alt", "gp_acc", "gp_climb", "mu_lift"))
#: :func:`guidance_step`'s ``us`` while the ground-proximity guard pulls up
US_PULL_UP = 3.0
#: layout of the position-error integral (NED, m s) that :func:`guidance_step` advances in place
INTEGRAL = slots.declare("GuidanceIntegral", ("x", "y", "z"))
#: layout of a polar (:func:`polar_at`) and of the coefficients it blends (:func:`polar_coefficients`,
#: :data:`fdm_awe.pointmass.aero.POLAR_FIELDS`): CL0, CLalpha, CLmax, CD0, CDalpha1, CDalpha2
POLAR = slots.declare("Polar", ("cl0", "cla", "clmax", "cd0", "cda1", "cda2"))
#: layout of the step's input (:func:`guidance_step`): mass [kg], air density [kg/m^3], gravity
#: [m/s^2], unfolded and folded reference areas [m^2]; the reference's position [m], velocity
#: [m/s], acceleration [m/s^2] and line tension [N]; the glider's position [m] and velocity
#: [m/s], the wind [m/s] and the measured line force on the glider [N], all NED; fold state [-],
#: step [s]; the line taut (1.0/0.0), the thrust available [N], the reference's pull (1.0/0.0),
#: the underspeed protection (``us``)
GIN = slots.declare("GuidanceInput", ("m", "rho", "g", "s_u", "s_f", ("ref_pos", 3), ("ref_vel", 3), ("ref_acc", 3),
                                      "tension", ("pos", 3), ("vel", 3), ("wind", 3), ("line", 3), "fold", "dt", "taut",
                                      "t_max", "ref_pull", "us"))


def polar_coefficients(aero: AeroParams) -> np.ndarray:
    """The polar coefficients of one form of the wing as a float64 array in the layout of
    :data:`POLAR_FIELDS` (``POLAR.cl0`` .. ``POLAR.cda2``: CL0 [-], CLalpha [1/rad], CLmax [-], CD0 [-],
    CDalpha1 [1/rad], CDalpha2 [1/rad^2]): the ``cu``, ``cf`` of :func:`polar_at`."""
    return np.array([getattr(aero, k) for k in POLAR_FIELDS], dtype=np.float64)


def polar_arguments(aero_u: AeroParams, aero_f: AeroParams) -> tuple[np.ndarray, np.ndarray, float, float]:
    """``(cu, cf, ratio, S)`` of :func:`polar_at` for the morphing wing's unfolded and folded
    forms: their coefficients (:func:`polar_coefficients`), the area ratio S_folded / S_unfolded
    [-] and the unfolded reference area [m^2]."""
    return polar_coefficients(aero_u), polar_coefficients(aero_f), aero_f.S / aero_u.S, aero_u.S


def polar_at(cu: Floats, cf: Floats, ratio: float, S: float, fold: float) -> Polar:
    """The polar at fold state ``fold`` (0 unfolded .. 1 folded) as ``S*coefficient`` values,
    (S_CL0, S_CLa, S_CLmax, S_CD0, S_CDa1, S_CDa2) [m^2, m^2/rad, m^2, m^2, m^2/rad, m^2/rad^2],
    layout ``POLAR.cl0`` .. ``POLAR.cda2``: each coefficient blended by
    :func:`fdm_awe.pointmass.aero.blend_coefficient` (the relation of ``fold_blend``) from the
    unfolded and folded coefficients ``cu``, ``cf`` (:func:`polar_coefficients`), area ratio
    ``ratio`` [-], times the unfolded reference area ``S`` [m^2]."""
    return (S * blend_coefficient(cu[POLAR.cl0], cf[POLAR.cl0], ratio, fold),
            S * blend_coefficient(cu[POLAR.cla], cf[POLAR.cla], ratio, fold),
            S * blend_coefficient(cu[POLAR.clmax], cf[POLAR.clmax], ratio, fold),
            S * blend_coefficient(cu[POLAR.cd0], cf[POLAR.cd0], ratio, fold),
            S * blend_coefficient(cu[POLAR.cda1], cf[POLAR.cda1], ratio, fold),
            S * blend_coefficient(cu[POLAR.cda2], cf[POLAR.cda2], ratio, fold))


def blended_polar(aero_u: AeroParams, aero_f: AeroParams, fold: float) -> Polar:
    """Polar of the morphing wing at fold state ``fold`` (0 unfolded .. 1 folded) as
    ``S*coefficient`` values on its reference area (:func:`polar_at`; the blend of the 6-DOF
    model, :func:`fdm_awe.pointmass.aero.fold_blend`), as Python floats."""
    p = polar_at(*polar_arguments(aero_u, aero_f), fold)
    cl0, cla, clmax, cd0, cda1, cda2 = (float(p[i]) for i in POLAR)
    return cl0, cla, clmax, cd0, cda1, cda2


def norm3(a: np.ndarray) -> float:
    """Length of a 3-vector (``numpy.linalg.norm`` costs ~10x more for single vectors)."""
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """3-vector cross product (``numpy.cross`` costs ~50x more for single vectors)."""
    return np.array((a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]))


def _norm(x: float, y: float, z: float) -> float:
    return math.sqrt(x * x + y * y + z * z)


# ------------------------------------------------------------------ the step as pure functions
# Floats, bools and float64 arrays (:data:`Floats`) only: numba compiles them, the Python path
# runs the same code. Written on scalars, every operation as in the vector formulas of the
# comments, in the same order (tests/test_autopilot_guidance.py checks them against the numpy
# form, tests/test_autopilot_guidance_core.py compiled against Python).
def guidance_step(gk: Floats, integral: np.ndarray, polar: Floats, gin: Floats) -> tuple[float, ...]:
    """One guidance step: the command ``(alpha, mu, thrust, roll, pitch, yaw, cl, pos_error)``
    [rad, rad, N, rad, rad, rad, -, m] (the fields of :class:`~.guidance_loop.GuidanceCommand`).

    ``gk``: the gains (:meth:`~.guidance_loop.GuidanceGains.vector`, layout :data:`GK`); ``integral``: the
    position-error integral [m s] (layout :data:`INTEGRAL`), advanced in place; ``polar``: the polar at
    ``fold`` (:func:`polar_at`, layout :data:`POLAR`; a float64 array or a 6-tuple); ``gin``: the
    step's input (layout :data:`GIN`; a float64 array, or run by Python any sequence of floats):
    the mass, air density, gravity and reference areas; the reference's position, velocity,
    acceleration and line tension; the glider's position and velocity, the wind and the
    measured line force on the glider; fold state ``fold``, step ``dt``; ``taut``: the line is
    taut (see :meth:`~.guidance_loop.Guidance.update`); ``t_max``: the thrust available this
    step [N]; ``ref_pull``: on a line that is not taut, the radial part of the measured line
    force is replaced by the reference's ``tension`` (the wing flies the reference's radial
    aerodynamic force, see :func:`_air_force`); ``us``: the underspeed protection
    (:mod:`.underspeed`) acts (0 no, 1 yes, 2 yes on a slack line): the path's acceleration
    demand becomes a speed recovery (:func:`_underspeed_demand`, the integral held) and alpha is
    capped the gains' margin below the stall, the thrust is all there is (``t_max``); ``us``
    :data:`US_PULL_UP`: the ground-proximity guard (:mod:`.ground`) pulls up instead
    (:func:`_pull_up_demand`, the integral held, the alpha margin and the thrust as in
    underspeed). With ``us`` 0 the step is the protection-free one, bit for bit (but for the
    alpha margin where the gains turn the protection on, ``GK.us_enter`` > 0: below
    ``GK.us_amargv`` stall speeds alpha stays ``GK.us_amargin`` below the stall)."""
    m, rho, g, s_u, s_f = gin[GIN.m], gin[GIN.rho], gin[GIN.g], gin[GIN.s_u], gin[GIN.s_f]
    rpx, rpy, rpz = gin[GIN.ref_pos], gin[GIN.ref_pos + 1], gin[GIN.ref_pos + 2]
    rvx, rvy, rvz = gin[GIN.ref_vel], gin[GIN.ref_vel + 1], gin[GIN.ref_vel + 2]
    rax, ray, raz = gin[GIN.ref_acc], gin[GIN.ref_acc + 1], gin[GIN.ref_acc + 2]
    px, py, pz = gin[GIN.pos], gin[GIN.pos + 1], gin[GIN.pos + 2]
    vx, vy, vz = gin[GIN.vel], gin[GIN.vel + 1], gin[GIN.vel + 2]
    wx, wy, wz = gin[GIN.wind], gin[GIN.wind + 1], gin[GIN.wind + 2]
    tx, ty, tz = gin[GIN.line], gin[GIN.line + 1], gin[GIN.line + 2]
    fold, dt, t_max, us = gin[GIN.fold], gin[GIN.dt], gin[GIN.t_max], gin[GIN.us]
    taut = gin[GIN.taut] != 0.0
    # e_p = p_ref - p, e_v = v_ref - v
    epx, epy, epz = rpx - px, rpy - py, rpz - pz
    evx, evy, evz = rvx - vx, rvy - vy, rvz - vz
    erx, ery, erz = 0.0, 0.0, 0.0
    if taut:
        # position loop on the sphere's tangent plane: e -= (e . e_r) e_r
        dn = max(_norm(px, py, pz), 1e-6)
        erx, ery, erz = px / dn, py / dn, pz / dn
        c = epx * erx + epy * ery + epz * erz
        epx, epy, epz = epx - c * erx, epy - c * ery, epz - c * erz
        c = evx * erx + evy * ery + evz * erz
        evx, evy, evz = evx - c * erx, evy - c * ery, evz - c * erz
    cx, cy, cz = _correction(gk, integral, epx, epy, epz, evx, evy, evz, dt if us == 0.0 else 0.0)
    vrx, vry, vrz = rvx - wx, rvy - wy, rvz - wz  # reference air velocity
    vax, vay, vaz = vx - wx, vy - wy, vz - wz  # air velocity
    v_ref, v0 = _norm(vrx, vry, vrz), _norm(vax, vay, vaz)
    afx, afy, afz = _path_feed_forward(rax, ray, raz, vrx, vry, vrz, v_ref, vax, vay, vaz, v0, gk[GK.curvmax])
    margin = 0.0
    if gk[GK.us_enter] > 0.0:
        v_stall = stall_speed(m, rho, g, polar[POLAR.clmax])
        if v0 < gk[GK.us_amargv] * v_stall:
            margin = gk[GK.us_amargin]
    pull = us == US_PULL_UP
    if pull:
        afx, afy, afz = _pull_up_demand(gk, afx + cx, afy + cy, afz + cz, vax, vay, vaz, vz)
        cx, cy, cz = 0.0, 0.0, 0.0
        # wings level: the line's horizontal pull is not flown against (it banked the lift away
        # from the pull-up); the energy trade never pushes over (_command)
        tx, ty = 0.0, 0.0
    elif us != 0.0:
        v_stall = stall_speed(m, rho, g, polar[POLAR.clmax])
        afx, afy, afz = _underspeed_demand(gk, afx + cx, afy + cy, afz + cz, vax, vay, vaz, v0, v_stall, us == 2.0,
                                           px, py)
        cx, cy, cz = 0.0, 0.0, 0.0
    Fx, Fy, Fz = _air_force(gk, gin, afx + cx, afy + cy, afz + cz, tx, ty, tz, erx, ery, erz, v_ref, v0)
    alpha, mu, thrust, roll, pitch, yaw, cl = _command(gk, polar, rho, Fx, Fy, Fz, vax, vay, vaz, fold, s_u, s_f, t_max,
                                                       margin, us != 0.0, pull, m * g)
    return alpha, mu, thrust, roll, pitch, yaw, cl, _norm(epx, epy, epz)


def _pull_up_demand(gk: Floats, ax: float, ay: float, az: float, vax: float, vay: float, vaz: float,
                    vz: float) -> Vec3:
    """The acceleration demand [m/s^2, NED] of the ground-proximity guard (:mod:`.ground`) from the
    path's demand ``a`` (feed-forward plus correction) for the air velocity ``va`` [m/s] and the
    glider's vertical speed ``vz`` [m/s, down]: the path's along the air velocity, across it
    nothing sideways (wings level) and up in its vertical plane at least ``GP_ACC`` while the
    glider sinks (the path bends up; a vertical upward demand would lie along a steep dive, where
    the wing cannot give it), that floor falling linearly to nothing at a climb of ``GP_CLIMB``
    (no zoom climb into a stall). A path that pulls up harder keeps its pull."""
    climb = gk[GK.gp_climb]
    share = 1.0 if vz >= 0.0 else (max(1.0 + vz / climb, 0.0) if climb > 0.0 else 0.0)
    V = max(_norm(vax, vay, vaz), 1.0)
    e1x, e1y, e1z = vax / V, vay / V, vaz / V
    horiz = math.sqrt(e1x * e1x + e1y * e1y)
    if horiz > 1e-6:
        r0x, r0y = -e1y / horiz, e1x / horiz
    else:  # vertical flight: any horizontal axis
        r0x, r0y = 0.0, 1.0
    # up0 = right0 x e1 (right0 horizontal): up across the air velocity
    u0x, u0y, u0z = r0y * e1z, -r0x * e1z, r0x * e1y - r0y * e1x
    a_t = ax * e1x + ay * e1y + az * e1z
    a_u = max(ax * u0x + ay * u0y + az * u0z, gk[GK.gp_acc] * share)
    return a_t * e1x + a_u * u0x, a_t * e1y + a_u * u0y, a_t * e1z + a_u * u0z


def _underspeed_demand(gk: Floats, ax: float, ay: float, az: float, vax: float, vay: float, vaz: float, v0: float,
                       v_stall: float, slack: bool, px: float, py: float) -> Vec3:
    """The acceleration demand [m/s^2] under the underspeed protection (TECS's speed priority)
    from the path's demand ``a`` (feed-forward plus correction, NED): along the air velocity
    ``va`` (airspeed ``v0`` [m/s]) ``US_KV (US_V_EXIT v_stall - v0)`` (>= 0; ``v_stall`` [m/s]
    the stall speed of the fold state) instead of the path's; across it the path's; on a
    ``slack`` line plus ``US_SLACK_A`` horizontally away from the winch (the glider at ``p*``
    [m] from it) to take up the slack; then no upward part: height is given for speed, never
    asked for. What the propeller cannot give of the along-path demand the energy trade takes
    from height (:func:`_traded_lift`: the flight path bends down)."""
    V = max(v0, 1.0)
    e1x, e1y, e1z = vax / V, vay / V, vaz / V
    c = max(gk[GK.us_kv] * (gk[GK.us_exit] * v_stall - v0), 0.0) - (ax * e1x + ay * e1y + az * e1z)
    ax, ay, az = ax + c * e1x, ay + c * e1y, az + c * e1z
    h = math.sqrt(px * px + py * py)
    if slack and h > 1e-6:
        ax, ay = ax + gk[GK.us_slack] * px / h, ay + gk[GK.us_slack] * py / h
    return ax, ay, max(az, 0.0)


def _correction(gk: Floats, integral: np.ndarray, epx: float, epy: float, epz: float, evx: float, evy: float,
                evz: float, dt: float) -> Vec3:
    """The feedback acceleration [m/s^2] ``kp e_p + kd e_v + ki int(e_p)``, saturated at
    ``a_max``, for position error ``e_p`` [m] and velocity error ``e_v`` [m/s]; the integral
    [m s] advances in place by ``e_p dt`` (``dt`` [s]), clipped to +-``int_max``."""
    im = gk[GK.imax]
    ix = min(max(float(integral[INTEGRAL.x]) + epx * dt, -im), im)
    iy = min(max(float(integral[INTEGRAL.y]) + epy * dt, -im), im)
    iz = min(max(float(integral[INTEGRAL.z]) + epz * dt, -im), im)
    integral[INTEGRAL.x], integral[INTEGRAL.y], integral[INTEGRAL.z] = ix, iy, iz
    kp, kd, ki = gk[GK.kp], gk[GK.kd], gk[GK.ki]
    cx = kp * epx + kd * evx + ki * ix
    cy = kp * epy + kd * evy + ki * iy
    cz = kp * epz + kd * evz + ki * iz
    n = _norm(cx, cy, cz)
    if n > gk[GK.amax]:
        c = gk[GK.amax] / n
        cx, cy, cz = cx * c, cy * c, cz * c
    return cx, cy, cz


def _air_force(gk: Floats, gin: Floats, ax: float, ay: float, az: float, tx: float, ty: float, tz: float,
               erx: float, ery: float, erz: float, v_ref: float, v0: float) -> Vec3:
    """The force [N] the air (and the propeller) must provide, ``F = m (a_cmd - g) - F_tether``
    with ``a_cmd = a_ff + corr`` [m/s^2] (``a``) and the line force ``t*`` [N] (the measured one,
    or none where the guard pulls up), the mass ``m`` and gravity ``g`` of the step's input
    ``gin`` (:data:`GIN`); on a taut line (``taut``, ``e_r``: the glider's radial unit vector)
    its radial part is the reference's (from its position, acceleration and ``tension`` in
    ``gin``, plus the overspeed term; airspeeds ``v_ref``, ``v0`` [m/s] of reference and glider).

    On a line that is not taut with ``ref_pull``, the radial part of the measured line force is
    replaced by the reference's ``tension`` along the reference's radial direction: the wing
    flies the reference's radial aerodynamic force whatever the line does, and the position
    loop (not projected: nothing else holds the radius) corrects the radius. The cycle uses it
    in recovery, where a line pulled taut by the reel-in would otherwise close the positive
    loop of the taut line (more pull -> more tension -> more pull) through the winch's speed
    loop, and while generation's slack line is being caught: the reference's tension, shaped
    across the phase switch, then rises smoothly where the measured one jumps from nothing to
    the generator's within a fraction of a second, and the wing's force no longer steps at
    the catch."""
    m, g, tension = gin[GIN.m], gin[GIN.g], gin[GIN.tension]
    rpx, rpy, rpz = gin[GIN.ref_pos], gin[GIN.ref_pos + 1], gin[GIN.ref_pos + 2]
    Fx = m * (ax - 0.0) - tx
    Fy = m * (ay - 0.0) - ty
    Fz = m * (az - g) - tz
    if gin[GIN.taut] == 0.0:
        if gin[GIN.ref_pull] != 0.0:
            # F + (tension + t . e_r) e_r: the measured radial pull out, the reference's in
            dn = max(_norm(rpx, rpy, rpz), 1e-6)
            ex, ey, ez = rpx / dn, rpy / dn, rpz / dn
            c = tension + (tx * ex + ty * ey + tz * ez)
            return Fx + c * ex, Fy + c * ey, Fz + c * ez
        return Fx, Fy, Fz
    dn = max(_norm(rpx, rpy, rpz), 1e-6)
    rax, ray, raz = gin[GIN.ref_acc], gin[GIN.ref_acc + 1], gin[GIN.ref_acc + 2]
    F_r_ref = (m * (rax - 0.0) * (rpx / dn) + m * (ray - 0.0) * (rpy / dn)
               + m * (raz - g) * (rpz / dn)) + tension
    if gk[GK.vtens] > 0.0 and v_ref > 1.0:
        # overspeed protection: on a taut line the glider sheds speed through the line,
        # not through its drag: pull harder than the reference (more lift, more induced
        # drag) and the winch pays out faster, taking the excess energy at the drum
        F_r_ref += gk[GK.vtens] * max(v0 - v_ref - gk[GK.vmargin], 0.0)
    # radial component replaced by the reference's: F - (F . e_r) e_r + F_r_ref e_r
    c = Fx * erx + Fy * ery + Fz * erz
    return (Fx - c * erx + F_r_ref * erx, Fy - c * ery + F_r_ref * ery, Fz - c * erz + F_r_ref * erz)


def _command(gk: Floats, polar: Floats, rho: float, Fx: float, Fy: float, Fz: float, vax: float,
             vay: float, vaz: float, fold: float, s_u: float, s_f: float, t_max: float, margin: float,
             full: bool, climb_only: bool, weight: float) -> tuple[float, float, float, float, float, float, float]:
    """The command ``(alpha, mu, thrust, roll, pitch, yaw, cl)`` flying force ``F`` [N]: split
    along the air velocity ``va`` [m/s] (thrust minus drag, at most ``t_max`` [N] of thrust) and
    across it (lift), with ``polar`` (:func:`polar_at` at fold state ``fold``) and air density
    ``rho`` [kg/m^3]; the attitude follows from the air velocity, alpha and bank (no sideslip);
    ``cl`` on the blended reference area of ``s_u``, ``s_f`` [m^2]. Alpha stays ``margin`` [rad]
    below the polar's stall; ``full``: all the thrust there is (TECS's full throttle in
    underspeed); ``climb_only``: the energy trade never pushes over (the ground-proximity
    guard's pull-up: no dive for the line's drag or the speed). Below a lift of ``GK.mu_lift``
    times ``weight`` [N] times the fold state the bank fades to wings level: ``mu`` times
    ``L^2 / (L^2 + L0^2)``, a lateral force error of at most ``|mu| L0 / 2``, none at zero lift
    (the open wing, fold 0, flies the bank as asked)."""
    V = max(_norm(vax, vay, vaz), 1.0)
    e1x, e1y, e1z = vax / V, vay / V, vaz / V
    F_par = Fx * e1x + Fy * e1y + Fz * e1z
    q = 0.5 * rho * V * V
    horiz = math.sqrt(e1x * e1x + e1y * e1y)
    if horiz > 1e-6:
        r0x, r0y, r0z = -e1y / horiz, e1x / horiz, 0.0 / horiz
    else:  # vertical flight: any horizontal axis
        r0x, r0y, r0z = 0.0, 1.0, 0.0
    # up0 = right0 x e1 (= -c3 at zero bank: points up in level flight)
    u0x, u0y, u0z = r0y * e1z - r0z * e1y, r0z * e1x - r0x * e1z, r0x * e1y - r0y * e1x
    alpha_stall = (polar[POLAR.clmax] - polar[POLAR.cl0]) / polar[POLAR.cla] - margin
    Qx, Qy, Qz = _traded_lift(gk, Fx, Fy, Fz, F_par, e1x, e1y, e1z, u0x, u0y, u0z, q, polar, t_max, alpha_stall,
                              climb_only)
    L = _norm(Qx, Qy, Qz)
    # bank about the air velocity: lift direction relative to the unbanked "up"
    if L > 1e-6:
        eLx, eLy, eLz = Qx / L, Qy / L, Qz / L
        mu = math.atan2(eLx * r0x + eLy * r0y + eLz * r0z, eLx * u0x + eLy * u0y + eLz * u0z)
    else:
        mu = 0.0
    if gk[GK.neglift] != 0.0 and abs(mu) > math.pi - gk[GK.phi_max]:
        # the force points below the horizon, further than the bank limit reaches: push
        # over (negative lift, wings banked the other way) instead of banking past it
        mu -= math.copysign(math.pi, mu)
        L = -L
    alpha, thrust = _alpha_and_thrust(gk, L, F_par, q, polar, t_max, min(gk[GK.alpha_max], alpha_stall), full)
    # near zero lift the bank says little about the force flown and its direction swings (the
    # folded glider's dive at a fraction of 1 g), faster than the folded wing's ailerons can
    # follow: folded, it fades to wings level as L^2 / (L^2 + L0^2), L0 growing with the fold
    L0 = gk[GK.mu_lift] * weight * fold
    if L0 > 0.0:
        mu = mu * (L * L / (L * L + L0 * L0))
    # the bank limit keeps the lift above the horizon in level flight; climbing or diving
    # steeply the wind-axis bank no longer says where the lift points relative to gravity
    # (vertical flight: any bank is level), so the limit opens towards phi_max_vertical (NaN: off)
    phi_lim = gk[GK.phi_max]
    if not math.isnan(gk[GK.phi_max_vert]) and gk[GK.phi_max_vert] > gk[GK.phi_max]:
        phi_lim += (gk[GK.phi_max_vert] - gk[GK.phi_max]) * (1.0 - horiz * horiz)
    mu = min(max(mu, -phi_lim), phi_lim)
    roll, pitch, yaw = _body_euler(e1x, e1y, e1z, r0x, r0y, r0z, u0x, u0y, u0z, mu, alpha)
    cl = (polar[POLAR.cl0] + polar[POLAR.cla] * alpha) / ((1 - fold) * s_u + fold * s_f)
    return alpha, mu, thrust, roll, pitch, yaw, cl


def _path_feed_forward(afx: float, afy: float, afz: float, vrx: float, vry: float, vrz: float, v_ref: float,
                       vax: float, vay: float, vaz: float, v0: float, curv_scale_max: float) -> Vec3:
    """Feed-forward of the reference acceleration ``a_ref`` [m/s^2] in the path's own axes: its
    tangential part (along the reference air velocity ``vr``, of size ``v_ref`` [m/s]) along
    the glider's air velocity ``va`` (size ``v0``), its normal (turning) part, same size, across
    it. Taken in NED as it stands, a heading error would turn the reference's centripetal
    acceleration (up to 3 g on a pumping loop) into a demand to brake or to accelerate (thrust
    cut, lift raised by the energy trade, the glider slows and falls behind)."""
    if not (v_ref > 1.0 and v0 > 1.0):
        return afx, afy, afz
    trx, try_, trz = vrx / v_ref, vry / v_ref, vrz / v_ref
    tnx, tny, tnz = vax / v0, vay / v0, vaz / v0
    a_t = afx * trx + afy * try_ + afz * trz
    anx, any_, anz = afx - a_t * trx, afy - a_t * try_, afz - a_t * trz
    c = anx * tnx + any_ * tny + anz * tnz
    apx, apy, apz = anx - c * tnx, any_ - c * tny, anz - c * tnz
    n_p, n_n = _norm(apx, apy, apz), _norm(anx, any_, anz)
    if n_p > 1e-9:
        # the turn keeps the path's curvature: the glider follows the reference path
        # (its point moves with the glider), so a faster glider needs (v/v_ref)^2 of the
        # reference's centripetal acceleration to fly the same radius (bounded by
        # curv_scale_max; NaN: the reference's acceleration as it stands). Only scaled
        # up: a slower glider keeps the reference's turn (scaling it down weakened the
        # turn of a glider lagging on a slack line in turbulence)
        scale = 1.0 if math.isnan(curv_scale_max) else min(max((v0 / v_ref) * (v0 / v_ref), 1.0), curv_scale_max)
        c = n_n / n_p * scale
        apx, apy, apz = apx * c, apy * c, apz * c
    return a_t * tnx + apx, a_t * tny + apy, a_t * tnz + apz


def _traded_lift(gk: Floats, Fx: float, Fy: float, Fz: float, F_par: float, e1x: float, e1y: float,
                 e1z: float, u0x: float, u0y: float, u0z: float, q: float, polar: Floats, t_max: float,
                 alpha_stall: float, climb_only: bool) -> Vec3:
    """The force across the air velocity (the lift's share of ``F`` [N], ``F_par`` [N] of it along
    ``e1``) after the energy exchange (TECS-like): an along-path force the propeller cannot give
    (braking beyond the drag, or more than the ``t_max`` [N] of thrust) is traded through the
    flight path: pull up (along ``up0``) to bleed speed into height, push over to gain speed
    from height (not with ``climb_only``). ``q`` [Pa]: dynamic pressure; ``polar``: :func:`polar_at`."""
    qS_cl0, qS_cla = polar[POLAR.cl0], polar[POLAR.cla]
    qS_cd0, qS_cd1, qS_cd2 = polar[POLAR.cd0], polar[POLAR.cda1], polar[POLAR.cda2]
    Qx, Qy, Qz = Fx - F_par * e1x, Fy - F_par * e1y, Fz - F_par * e1z  # F_perp
    for _ in range(2):
        L = _norm(Qx, Qy, Qz)
        alpha = min(max((L / q - qS_cl0) / qS_cla, gk[GK.alpha_min]), min(gk[GK.alpha_max], alpha_stall))
        drag = q * (qS_cd0 + qS_cd1 * alpha + qS_cd2 * alpha * alpha)
        excess = F_par + drag
        # the propeller pushes along the body x-axis: at most t_max cos(alpha) along the path
        t_par = t_max * math.cos(alpha) if gk[GK.body_axis] != 0.0 else t_max
        if excess < 0.0:
            c = gk[GK.etrade] * excess
        elif excess > t_par and not climb_only:
            c = gk[GK.etrade] * (excess - t_par)
        else:
            break
        # F_perp = F - F_par e1 - c up0
        Qx, Qy, Qz = Fx - F_par * e1x - c * u0x, Fy - F_par * e1y - c * u0y, Fz - F_par * e1z - c * u0z
    return Qx, Qy, Qz


def _alpha_and_thrust(gk: Floats, L: float, F_par: float, q: float, polar: Floats, t_max: float,
                      a_hi: float, full: bool) -> tuple[float, float]:
    """Angle of attack [rad] for lift ``L`` [N] (linear lift, between ``alpha_min`` and ``a_hi``)
    and the thrust [N] (0 .. ``t_max``) for the along-path force ``F_par`` [N] against the drag at
    dynamic pressure ``q`` [Pa]. With the thrust on the body x-axis, alpha above the air velocity,
    ``T cos(alpha)`` acts along the path (against the drag) and ``T sin(alpha)`` along the lift,
    so the wing lifts only ``L - T sin(alpha)`` (fixed-point passes: ``T sin(alpha)`` is a few
    percent of L, each pass shrinks the error by about that share). ``full``: the thrust is
    ``t_max`` whatever the along-path force asks."""
    qS_cl0, qS_cla = polar[POLAR.cl0], polar[POLAR.cla]
    qS_cd0, qS_cd1, qS_cd2 = polar[POLAR.cd0], polar[POLAR.cda1], polar[POLAR.cda2]
    alpha = min(max((L / q - qS_cl0) / qS_cla, gk[GK.alpha_min]), a_hi)
    drag = q * (qS_cd0 + qS_cd1 * alpha + qS_cd2 * alpha * alpha)
    if gk[GK.body_axis] == 0.0:
        return alpha, t_max if full else min(max(F_par + drag, 0.0), t_max)
    for _ in range(3):
        thrust = t_max if full else min(max((F_par + drag) / math.cos(alpha), 0.0), t_max)
        alpha = min(max(((L - thrust * math.sin(alpha)) / q - qS_cl0) / qS_cla, gk[GK.alpha_min]), a_hi)
        drag = q * (qS_cd0 + qS_cd1 * alpha + qS_cd2 * alpha * alpha)
    return alpha, t_max if full else min(max((F_par + drag) / math.cos(alpha), 0.0), t_max)


def _body_euler(e1x: float, e1y: float, e1z: float, r0x: float, r0y: float, r0z: float, u0x: float, u0y: float,
                u0z: float, mu: float, alpha: float) -> tuple[float, float, float]:
    """Body roll, pitch, yaw (Euler angles, rad) of the attitude with the air velocity along
    ``e1``, wind-axis bank ``mu`` from the unbanked axes ``right0``, ``up0``, angle of attack
    ``alpha`` and no sideslip: x_b = cos a e1 + sin a eL, z_b = sin a e1 - cos a eL,
    y_b = z_b x x_b (eL the banked lift direction)."""
    cm, sm = math.cos(mu), math.sin(mu)
    eLx, eLy, eLz = cm * u0x + sm * r0x, cm * u0y + sm * r0y, cm * u0z + sm * r0z
    ca, sa = math.cos(alpha), math.sin(alpha)
    xbx, xby, xbz = ca * e1x + sa * eLx, ca * e1y + sa * eLy, ca * e1z + sa * eLz
    zbx, zby, zbz = sa * e1x - ca * eLx, sa * e1y - ca * eLy, sa * e1z - ca * eLz
    ybz = zbx * xby - zby * xbx
    pitch = -math.asin(max(-1.0, min(1.0, xbz)))
    roll = math.atan2(ybz, zbz)
    yaw = math.atan2(xby, xbx)
    return roll, pitch, yaw


#: the functions :func:`guidance_step` and :func:`polar_at` call (register them with numba's
#: ``register_jitable`` before compiling either, e.g. through :func:`fdm_awe.jitcache.compile_cached`)
CALLED = (blend_coefficient, stall_speed, _norm, _correction, _air_force, _path_feed_forward, _pull_up_demand,
          _underspeed_demand, _traded_lift, _alpha_and_thrust, _body_euler, _command)
