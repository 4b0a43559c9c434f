"""Outer loop: track the reference path by point-mass force inversion.

The commanded acceleration ``a_cmd = a_ref + Kp e_p + Kd e_v + Ki int(e_p)`` (errors in NED,
saturated) is turned into the force the air must provide,
``F = m (a_cmd - g) - F_tether`` (the tether force is measured at the ground station and
fed forward), and split along the air velocity (thrust minus drag) and across it (lift).
The propeller pushes along the body x-axis, alpha above the air velocity: ``T cos(alpha)``
of it acts along the path and ``T sin(alpha)`` across it with the lift, so the wing lifts the
rest (:attr:`GuidanceGains.thrust_on_body_axis`). The wing's lift gives the lift
coefficient and so the angle of attack; the direction of the force across the air velocity
gives the wind-axis bank. The desired body attitude follows from the
air velocity, alpha and bank (no sideslip), and the inner loops fly it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..pointmass.aero import fold_blend
from ..definitions.aircraft import AeroParams
from .tracking import RefPoint

#: a 3-vector as three floats (the guidance's arithmetic is written on scalars)
Vec3 = tuple[float, float, float]
#: a wing polar as ``S*coefficient`` values (:func:`blended_polar`)
Polar = tuple[float, float, float, float, float, float]


@dataclass(frozen=True)
class GuidanceGains:
    """Outer-loop gains and limits (definition file ``autopilot.xml``)."""

    kp: float  #: position gain [1/s^2]
    kd: float  #: velocity gain [1/s]
    ki: float  #: position integral gain [1/s^3]
    a_max: float  #: correction acceleration limit [m/s^2]
    int_max: float  #: integral state limit [m s]
    alpha_min: float  #: [rad]
    alpha_max: float  #: [rad] (also limited by CLmax)
    phi_max: float  #: wind-axis bank limit [rad]
    thrust_max: float  #: [N]
    energy_trade: float = 1.0  #: share of an unachievable along-path force turned into climb/dive [-]
    negative_lift: bool = False  #: fly a lift demand pointing below the horizon with negative lift (push-over) instead of banking past the limit
    curv_scale_max: float | None = None  #: bound of the feed-forward turn's (v/v_ref)^2 scaling [-] (None: no scaling)
    overspeed_tension: float = 0.0  #: taut line: extra radial force per m/s of airspeed above the reference's plus the margin [N s/m]
    overspeed_margin: float = 3.0  #: airspeed excess over the reference's tolerated before overspeed_tension acts [m/s]
    phi_max_vertical: float | None = None  #: wind-axis bank limit in vertical flight [rad] (None = phi_max); blended with sin^2 of the flight-path angle
    #: the thrust acts along the body x-axis (the 6-DOF propeller and the paper plant's ideal
    #: thruster), alpha above the air velocity: it is inverted as such (False: along the air
    #: velocity, the point-mass model's thrust)
    thrust_on_body_axis: bool = True


@dataclass(frozen=True)
class GuidanceCommand:
    alpha: float  #: angle of attack [rad]
    mu: float  #: wind-axis bank [rad]
    thrust: float  #: [N]
    roll: float  #: desired body roll (Euler phi) [rad]
    pitch: float  #: desired body pitch (Euler theta) [rad]
    yaw: float  #: desired body heading (Euler psi) [rad]
    lift_coefficient: float
    pos_error: float  #: |p_ref - p| [m]


def blended_polar(aero_u: AeroParams, aero_f: AeroParams, fold: float) -> tuple[float, float, float, float, float, float]:
    """Polar of the morphing wing at fold state ``fold`` (0 unfolded .. 1 folded) as
    ``S*coefficient`` values on its reference area, (S_CL0, S_CLa, S_CLmax, S_CD0, S_CDa1,
    S_CDa2) [m^2, m^2/rad, m^2, m^2, m^2/rad, m^2/rad^2]: the blend of the 6-DOF model
    (:func:`fdm_awe.pointmass.aero.fold_blend`, the one source of it)."""
    a = fold_blend(aero_u, aero_f, fold)
    S = a.S
    return (S * a.CL0, S * a.CLalpha, S * a.CLmax, S * a.CD0, S * a.CDalpha1, S * a.CDalpha2)


def norm3(a: np.ndarray) -> float:
    """Length of a 3-vector (``numpy.linalg.norm`` costs ~10x more for single vectors)."""
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """3-vector cross product (``numpy.cross`` costs ~50x more for single vectors)."""
    return np.array((a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]))


def _xyz(v) -> tuple[float, float, float]:
    """Three Python floats of a 3-vector (array, list or tuple)."""
    if type(v) is np.ndarray:
        v = v.tolist()
    return v[0], v[1], v[2]


def _norm(x: float, y: float, z: float) -> float:
    return math.sqrt(x * x + y * y + z * z)


class Guidance:
    """Stateful outer loop (holds the position-error integral)."""

    def __init__(self, gains: GuidanceGains, mass: float, aero_u: AeroParams, aero_f: AeroParams, rho: float = 1.225, g: float = 9.81) -> None:
        self.k = gains
        self.m = mass
        self.aero_u, self.aero_f = aero_u, aero_f
        self.rho, self.g = rho, g
        self.integral = [0.0, 0.0, 0.0]  #: position-error integral, NED [m s]
        self._polar: tuple[float, tuple[float, ...]] | None = None  # (fold state, blended_polar) of the last step

    def polar(self, fold: float) -> tuple[float, float, float, float, float, float]:
        """:func:`blended_polar` at fold state ``fold``, kept while the fold state does not move."""
        c = self._polar
        if c is None or c[0] != fold:
            c = self._polar = (fold, blended_polar(self.aero_u, self.aero_f, fold))
        return c[1]  # type: ignore[return-value]

    def reset(self) -> None:
        self.integral = [0.0, 0.0, 0.0]

    def update(
        self,
        ref: RefPoint,
        pos: np.ndarray,
        vel: np.ndarray,
        wind: np.ndarray,
        tether_force: np.ndarray,
        fold: float,
        dt: float,
        taut: bool = False,
        thrust_max: float | None = None,
    ) -> GuidanceCommand:
        """``taut``: the line is taut, so the radial motion is the winch's: the position loop
        then acts only on the sphere's tangent plane, and the radial aerodynamic force is the
        reference's (feeding the measured tension back would close a positive loop through
        the line: more pull -> more tension -> more pull). ``thrust_max`` [N]: the thrust
        available this step (None: the gains' ``thrust_max``; 0 with the motor stopped, so an
        along-path force the glider lacks is traded through the flight path)."""
        # written on scalars and 3-tuples of floats (numpy on 3-vectors cost ~100 us a call):
        # every operation as in the vector formulas of the comments, in the same order, so the
        # results are those of the numpy form (tests/test_autopilot_guidance.py)
        k = self.k
        px, py, pz = _xyz(pos)
        vx, vy, vz = _xyz(vel)
        wx, wy, wz = _xyz(wind)
        rp = _xyz(ref.pos)
        rvx, rvy, rvz = _xyz(ref.vel)
        # e_p = p_ref - p, e_v = v_ref - v
        epx, epy, epz = rp[0] - px, rp[1] - py, rp[2] - pz
        evx, evy, evz = rvx - vx, rvy - vy, rvz - vz
        e_r = None
        if taut:
            # position loop on the sphere's tangent plane: e -= (e . e_r) e_r
            dn = max(_norm(px, py, pz), 1e-6)
            erx, ery, erz = e_r = (px / dn, py / dn, pz / dn)
            c = epx * erx + epy * ery + epz * erz
            epx, epy, epz = epx - c * erx, epy - c * ery, epz - c * erz
            c = evx * erx + evy * ery + evz * erz
            evx, evy, evz = evx - c * erx, evy - c * ery, evz - c * erz
        corr = self._correction(epx, epy, epz, evx, evy, evz, dt)
        va_ref = (rvx - wx, rvy - wy, rvz - wz)  # reference air velocity
        va = (vx - wx, vy - wy, vz - wz)  # air velocity
        v_ref, v0 = _norm(va_ref[0], va_ref[1], va_ref[2]), _norm(va[0], va[1], va[2])
        ra = _xyz(ref.acc)
        a_ff = _path_feed_forward(ra, va_ref, v_ref, va, v0, k.curv_scale_max)
        F = self._air_force(a_ff, corr, _xyz(tether_force), rp, ra, ref.tension, e_r, v_ref, v0)
        return self._command(F, va, fold, k.thrust_max if thrust_max is None else thrust_max, _norm(epx, epy, epz))

    def _correction(self, epx: float, epy: float, epz: float, evx: float, evy: float, evz: float,
                    dt: float) -> Vec3:
        """The feedback acceleration [m/s^2] ``kp e_p + kd e_v + ki int(e_p)``, saturated at
        ``a_max``, for position error ``e_p`` [m] and velocity error ``e_v`` [m/s]; the integral
        [m s] advances by ``e_p dt`` (``dt`` [s]), clipped to +-``int_max``."""
        k = self.k
        im = k.int_max
        ix, iy, iz = self.integral
        self.integral = [min(max(ix + epx * dt, -im), im), min(max(iy + epy * dt, -im), im),
                         min(max(iz + epz * dt, -im), im)]
        ix, iy, iz = self.integral
        kp, kd, ki = k.kp, k.kd, k.ki
        cx = kp * epx + kd * evx + ki * ix
        cy = kp * epy + kd * evy + ki * iy
        cz = kp * epz + kd * evz + ki * iz
        n = _norm(cx, cy, cz)
        if n > k.a_max:
            c = k.a_max / n
            cx, cy, cz = cx * c, cy * c, cz * c
        return cx, cy, cz

    def _air_force(self, a_ff: Vec3, corr: Vec3, tether: Vec3, rp: Vec3, ra: Vec3, tension: float,
                   e_r: Vec3 | None, v_ref: float, v0: float) -> Vec3:
        """The force [N] the air (and the propeller) must provide, ``F = m (a_cmd - g) - F_tether``
        with ``a_cmd = a_ff + corr`` [m/s^2] and the measured line force ``tether`` [N]; on a taut
        line (``e_r``: the glider's radial unit vector) its radial part is the reference's (from
        its position ``rp`` [m], acceleration ``ra`` [m/s^2] and ``tension`` [N], plus the
        overspeed term; airspeeds ``v_ref``, ``v0`` [m/s] of reference and glider)."""
        k, m, g = self.k, self.m, self.g
        afx, afy, afz = a_ff
        cx, cy, cz = corr
        tx, ty, tz = tether
        Fx = m * ((afx + cx) - 0.0) - tx
        Fy = m * ((afy + cy) - 0.0) - ty
        Fz = m * ((afz + cz) - g) - tz
        if e_r is None:
            return Fx, Fy, Fz
        rpx, rpy, rpz = rp
        rax, ray, raz = ra
        dn = max(_norm(rpx, rpy, rpz), 1e-6)
        F_r_ref = (m * (rax - 0.0) * (rpx / dn) + m * (ray - 0.0) * (rpy / dn)
                   + m * (raz - g) * (rpz / dn)) + tension
        if k.overspeed_tension > 0.0 and v_ref > 1.0:
            # overspeed protection: on a taut line the glider sheds speed through the line,
            # not through its drag: pull harder than the reference (more lift, more induced
            # drag) and the winch pays out faster, taking the excess energy at the drum
            F_r_ref += k.overspeed_tension * max(v0 - v_ref - k.overspeed_margin, 0.0)
        # radial component replaced by the reference's: F - (F . e_r) e_r + F_r_ref e_r
        erx, ery, erz = e_r
        c = Fx * erx + Fy * ery + Fz * erz
        return (Fx - c * erx + F_r_ref * erx, Fy - c * ery + F_r_ref * ery, Fz - c * erz + F_r_ref * erz)

    def _command(self, F: Vec3, va: Vec3, fold: float, t_max: float, pos_error: float) -> GuidanceCommand:
        """The command flying force ``F`` [N]: split along the air velocity ``va`` [m/s] (thrust
        minus drag, at most ``t_max`` [N] of thrust) and across it (lift), at fold state
        ``fold``; the attitude follows from the air velocity, alpha and bank (no sideslip).
        ``pos_error`` [m]: the position error it carries."""
        k = self.k
        V = max(_norm(va[0], va[1], va[2]), 1.0)
        e1x, e1y, e1z = e1 = (va[0] / V, va[1] / V, va[2] / V)
        Fx, Fy, Fz = F
        F_par = Fx * e1x + Fy * e1y + Fz * e1z
        polar = self.polar(fold)
        q = 0.5 * self.rho * V * V
        horiz = math.sqrt(e1x * e1x + e1y * e1y)
        if horiz > 1e-6:
            r0x, r0y, r0z = -e1y / horiz, e1x / horiz, 0.0 / horiz
        else:  # vertical flight: any horizontal axis
            r0x, r0y, r0z = 0.0, 1.0, 0.0
        right0 = (r0x, r0y, r0z)
        # up0 = right0 x e1 (= -c3 at zero bank: points up in level flight)
        up0 = (r0y * e1z - r0z * e1y, r0z * e1x - r0x * e1z, r0x * e1y - r0y * e1x)
        alpha_stall = (polar[2] - polar[0]) / polar[1]
        Q = _traded_lift(F, F_par, e1, up0, q, polar, t_max, k, alpha_stall)
        L = _norm(Q[0], Q[1], Q[2])
        # bank about the air velocity: lift direction relative to the unbanked "up"
        if L > 1e-6:
            eLx, eLy, eLz = Q[0] / L, Q[1] / L, Q[2] / L
            mu = math.atan2(eLx * r0x + eLy * r0y + eLz * r0z, eLx * up0[0] + eLy * up0[1] + eLz * up0[2])
        else:
            mu = 0.0
        if k.negative_lift and abs(mu) > math.pi - k.phi_max:
            # the force points below the horizon, further than the bank limit reaches: push
            # over (negative lift, wings banked the other way) instead of banking past it
            mu -= math.copysign(math.pi, mu)
            L = -L
        alpha, thrust = _alpha_and_thrust(L, F_par, q, polar, t_max, k, min(k.alpha_max, alpha_stall))
        # the bank limit keeps the lift above the horizon in level flight; climbing or diving
        # steeply the wind-axis bank no longer says where the lift points relative to gravity
        # (vertical flight: any bank is level), so the limit opens towards phi_max_vertical
        phi_lim = k.phi_max
        if k.phi_max_vertical is not None and k.phi_max_vertical > k.phi_max:
            phi_lim += (k.phi_max_vertical - k.phi_max) * (1.0 - horiz * horiz)
        mu = min(max(mu, -phi_lim), phi_lim)
        roll, pitch, yaw = _body_euler(e1, right0, up0, mu, alpha)
        cl = (polar[0] + polar[1] * alpha) / ((1 - fold) * self.aero_u.S + fold * self.aero_f.S)
        return GuidanceCommand(alpha, mu, thrust, roll, pitch, yaw, cl, pos_error)


def _path_feed_forward(a_ref: Vec3, va_ref: Vec3, v_ref: float, va: Vec3, v0: float,
                       curv_scale_max: float | None) -> Vec3:
    """Feed-forward of the reference acceleration ``a_ref`` [m/s^2] in the path's own axes: its
    tangential part (along the reference air velocity ``va_ref``, of size ``v_ref`` [m/s]) along
    the glider's air velocity ``va`` (size ``v0``), its normal (turning) part, same size, across
    it. Taken in NED as it stands, a heading error would turn the reference's centripetal
    acceleration (up to 3 g on a pumping loop) into a demand to brake or to accelerate (thrust
    cut, lift raised by the energy trade, the glider slows and falls behind)."""
    afx, afy, afz = a_ref
    if not (v_ref > 1.0 and v0 > 1.0):
        return a_ref
    trx, try_, trz = va_ref[0] / v_ref, va_ref[1] / v_ref, va_ref[2] / v_ref
    tnx, tny, tnz = va[0] / v0, va[1] / v0, va[2] / v0
    a_t = afx * trx + afy * try_ + afz * trz
    anx, any_, anz = afx - a_t * trx, afy - a_t * try_, afz - a_t * trz
    c = anx * tnx + any_ * tny + anz * tnz
    apx, apy, apz = anx - c * tnx, any_ - c * tny, anz - c * tnz
    n_p, n_n = _norm(apx, apy, apz), _norm(anx, any_, anz)
    if n_p > 1e-9:
        # the turn keeps the path's curvature: the glider follows the reference path
        # (its point moves with the glider), so a faster glider needs (v/v_ref)^2 of the
        # reference's centripetal acceleration to fly the same radius (bounded by
        # curv_scale_max; None: the reference's acceleration as it stands). Only scaled
        # up: a slower glider keeps the reference's turn (scaling it down weakened the
        # turn of a glider lagging on a slack line in turbulence)
        scale = 1.0 if curv_scale_max is None else min(max((v0 / v_ref) * (v0 / v_ref), 1.0), curv_scale_max)
        c = n_n / n_p * scale
        apx, apy, apz = apx * c, apy * c, apz * c
    return a_t * tnx + apx, a_t * tny + apy, a_t * tnz + apz


def _traded_lift(F: Vec3, F_par: float, e1: Vec3, up0: Vec3, q: float, polar: Polar, t_max: float,
                 k: GuidanceGains, alpha_stall: float) -> Vec3:
    """The force across the air velocity (the lift's share of ``F`` [N], ``F_par`` [N] of it along
    ``e1``) after the energy exchange (TECS-like): an along-path force the propeller cannot give
    (braking beyond the drag, or more than the ``t_max`` [N] of thrust) is traded through the
    flight path: pull up (along ``up0``) to bleed speed into height, push over to gain speed
    from height. ``q`` [Pa]: dynamic pressure; ``polar``: :func:`blended_polar`."""
    Fx, Fy, Fz = F
    e1x, e1y, e1z = e1
    u0x, u0y, u0z = up0
    qS_cl0, qS_cla, _, qS_cd0, qS_cd1, qS_cd2 = polar
    Qx, Qy, Qz = Fx - F_par * e1x, Fy - F_par * e1y, Fz - F_par * e1z  # F_perp
    for _ in range(2):
        L = _norm(Qx, Qy, Qz)
        alpha = min(max((L / q - qS_cl0) / qS_cla, k.alpha_min), min(k.alpha_max, alpha_stall))
        drag = q * (qS_cd0 + qS_cd1 * alpha + qS_cd2 * alpha * alpha)
        excess = F_par + drag
        # the propeller pushes along the body x-axis: at most t_max cos(alpha) along the path
        t_par = t_max * math.cos(alpha) if k.thrust_on_body_axis else t_max
        if excess < 0.0:
            c = k.energy_trade * excess
        elif excess > t_par:
            c = k.energy_trade * (excess - t_par)
        else:
            break
        # F_perp = F - F_par e1 - c up0
        Qx, Qy, Qz = Fx - F_par * e1x - c * u0x, Fy - F_par * e1y - c * u0y, Fz - F_par * e1z - c * u0z
    return Qx, Qy, Qz


def _alpha_and_thrust(L: float, F_par: float, q: float, polar: Polar, t_max: float, k: GuidanceGains,
                      a_hi: float) -> tuple[float, float]:
    """Angle of attack [rad] for lift ``L`` [N] (linear lift, between ``alpha_min`` and ``a_hi``)
    and the thrust [N] (0 .. ``t_max``) for the along-path force ``F_par`` [N] against the drag at
    dynamic pressure ``q`` [Pa]. With the thrust on the body x-axis, alpha above the air velocity,
    ``T cos(alpha)`` acts along the path (against the drag) and ``T sin(alpha)`` along the lift,
    so the wing lifts only ``L - T sin(alpha)`` (fixed-point passes: ``T sin(alpha)`` is a few
    percent of L, each pass shrinks the error by about that share)."""
    qS_cl0, qS_cla, _, qS_cd0, qS_cd1, qS_cd2 = polar
    alpha = min(max((L / q - qS_cl0) / qS_cla, k.alpha_min), a_hi)
    drag = q * (qS_cd0 + qS_cd1 * alpha + qS_cd2 * alpha * alpha)
    if not k.thrust_on_body_axis:
        return alpha, min(max(F_par + drag, 0.0), t_max)
    for _ in range(3):
        thrust = min(max((F_par + drag) / math.cos(alpha), 0.0), t_max)
        alpha = min(max(((L - thrust * math.sin(alpha)) / q - qS_cl0) / qS_cla, k.alpha_min), a_hi)
        drag = q * (qS_cd0 + qS_cd1 * alpha + qS_cd2 * alpha * alpha)
    return alpha, min(max((F_par + drag) / math.cos(alpha), 0.0), t_max)


def _body_euler(e1: Vec3, right0: Vec3, up0: Vec3, mu: float, alpha: float) -> tuple[float, float, float]:
    """Body roll, pitch, yaw (Euler angles, rad) of the attitude with the air velocity along
    ``e1``, wind-axis bank ``mu`` from the unbanked axes ``right0``, ``up0``, angle of attack
    ``alpha`` and no sideslip: x_b = cos a e1 + sin a eL, z_b = sin a e1 - cos a eL,
    y_b = z_b x x_b (eL the banked lift direction)."""
    e1x, e1y, e1z = e1
    r0x, r0y, r0z = right0
    u0x, u0y, u0z = up0
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
