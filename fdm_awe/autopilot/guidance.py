"""Outer loop: track the reference path by point-mass force inversion.

The commanded acceleration ``a_cmd = a_ref + Kp e_p + Kd e_v + Ki int(e_p)`` (errors in NED,
saturated) is turned into the force the air must provide,
``F = m (a_cmd - g) - F_tether`` (the tether force is measured at the ground station and
fed forward), and split along the air velocity (thrust minus drag) and across it (lift).
The lift vector's size gives the lift coefficient and so the angle of attack; its direction
about the air velocity gives the wind-axis bank. The desired body attitude follows from the
air velocity, alpha and bank (no sideslip), and the inner loops fly it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..definitions.aircraft import AeroParams
from .tracking import RefPoint


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
    """Area-weighted polar of the morphing wing at fold state ``fold`` (0 unfolded .. 1 folded),
    on the unfolded reference area: (S, CL0, CLalpha, CLmax, CD0, CDa1, CDa2)-like tuple of
    ``S*coefficient`` values: (S_CL0, S_CLa, S_CLmax, S_CD0, S_CDa1, S_CDa2)."""
    w_u, w_f = (1.0 - fold) * aero_u.S, fold * aero_f.S
    return (
        w_u * aero_u.CL0 + w_f * aero_f.CL0,
        w_u * aero_u.CLalpha + w_f * aero_f.CLalpha,
        w_u * aero_u.CLmax + w_f * aero_f.CLmax,
        w_u * aero_u.CD0 + w_f * aero_f.CD0,
        w_u * aero_u.CDalpha1 + w_f * aero_f.CDalpha1,
        w_u * aero_u.CDalpha2 + w_f * aero_f.CDalpha2,
    )


def norm3(a: np.ndarray) -> float:
    """Length of a 3-vector (``numpy.linalg.norm`` costs ~10x more for single vectors)."""
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """3-vector cross product (``numpy.cross`` costs ~50x more for single vectors)."""
    return np.array((a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]))


class Guidance:
    """Stateful outer loop (holds the position-error integral)."""

    def __init__(self, gains: GuidanceGains, mass: float, aero_u: AeroParams, aero_f: AeroParams, rho: float = 1.225, g: float = 9.81) -> None:
        self.k = gains
        self.m = mass
        self.aero_u, self.aero_f = aero_u, aero_f
        self.rho, self.g = rho, g
        self.integral = np.zeros(3)

    def reset(self) -> None:
        self.integral[:] = 0.0

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
    ) -> GuidanceCommand:
        """``taut``: the line is taut, so the radial motion is the winch's: the position loop
        then acts only on the sphere's tangent plane, and the radial aerodynamic force is the
        reference's (feeding the measured tension back would close a positive loop through
        the line: more pull -> more tension -> more pull)."""
        k = self.k
        e_p = ref.pos - pos
        e_v = ref.vel - vel
        g_vec = np.array([0.0, 0.0, self.g])
        if taut:
            e_r = pos / max(norm3(pos), 1e-6)
            e_p = e_p - float(e_p @ e_r) * e_r
            e_v = e_v - float(e_v @ e_r) * e_r
        self.integral = np.clip(self.integral + e_p * dt, -k.int_max, k.int_max)
        corr = k.kp * e_p + k.kd * e_v + k.ki * self.integral
        n = norm3(corr)
        if n > k.a_max:
            corr *= k.a_max / n
        # feed-forward of the reference acceleration in the path's own axes: its tangential
        # part along the glider's air velocity, its normal (turning) part, same size, across
        # it. Taken in NED as it stands, a heading error would turn the reference's centripetal
        # acceleration (up to 3 g on a pumping loop) into a demand to brake or to accelerate
        # (thrust cut, lift raised by the energy trade, the glider slows and falls behind).
        a_ff = ref.acc
        va_ref = ref.vel - wind
        v_ref = norm3(va_ref)
        va0 = vel - wind
        v0 = norm3(va0)
        if v_ref > 1.0 and v0 > 1.0:
            t_ref = va_ref / v_ref
            t_now = va0 / v0
            a_t = float(a_ff @ t_ref)
            a_n = a_ff - a_t * t_ref
            a_p = a_n - float(a_n @ t_now) * t_now
            n_p, n_n = norm3(a_p), norm3(a_n)
            if n_p > 1e-9:
                # the turn keeps the path's curvature: the glider follows the reference path
                # (its point moves with the glider), so a faster glider needs (v/v_ref)^2 of the
                # reference's centripetal acceleration to fly the same radius (bounded by
                # curv_scale_max; None: the reference's acceleration as it stands). Only scaled
                # up: a slower glider keeps the reference's turn (scaling it down weakened the
                # turn of a glider lagging on a slack line in turbulence)
                scale = 1.0 if k.curv_scale_max is None else min(max((v0 / v_ref) ** 2, 1.0), k.curv_scale_max)
                a_p = a_p * (n_n / n_p * scale)
            a_ff = a_t * t_now + a_p
        a_cmd = a_ff + corr
        F = self.m * (a_cmd - g_vec) - tether_force
        if taut:
            e_rr = ref.pos / max(norm3(ref.pos), 1e-6)
            F_r_ref = float(self.m * (ref.acc - g_vec) @ e_rr) + ref.tension
            if k.overspeed_tension > 0.0 and v_ref > 1.0:
                # overspeed protection: on a taut line the glider sheds speed through the line,
                # not through its drag: pull harder than the reference (more lift, more induced
                # drag) and the winch pays out faster, taking the excess energy at the drum
                F_r_ref += k.overspeed_tension * max(v0 - v_ref - k.overspeed_margin, 0.0)
            F = F - float(F @ e_r) * e_r + F_r_ref * e_r
        va = vel - wind
        V = max(norm3(va), 1.0)
        e1 = va / V
        F_par = float(F @ e1)
        F_perp = F - F_par * e1
        qS_cl0, qS_cla, qS_clmax, qS_cd0, qS_cd1, qS_cd2 = blended_polar(self.aero_u, self.aero_f, fold)
        q = 0.5 * self.rho * V * V
        horiz = math.hypot(e1[0], e1[1])
        if horiz > 1e-6:
            right0 = np.array([-e1[1], e1[0], 0.0]) / horiz
        else:  # vertical flight: any horizontal axis
            right0 = np.array([0.0, 1.0, 0.0])
        up0 = cross(right0, e1)  # = -c3 at zero bank (points up in level flight)
        alpha_stall = (qS_clmax - qS_cl0) / qS_cla
        # energy exchange (TECS-like): an along-path force the propeller cannot give (braking
        # beyond the drag, or more than full thrust) is traded through the flight path: pull up
        # to bleed speed into height, push over to gain speed from height.
        for _ in range(2):
            L = norm3(F_perp)
            alpha = min(max((L / q - qS_cl0) / qS_cla, k.alpha_min), min(k.alpha_max, alpha_stall))
            drag = q * (qS_cd0 + qS_cd1 * alpha + qS_cd2 * alpha * alpha)
            excess = F_par + drag
            if excess < 0.0:
                F_perp = F - F_par * e1 - k.energy_trade * excess * up0
            elif excess > k.thrust_max:
                F_perp = F - F_par * e1 - k.energy_trade * (excess - k.thrust_max) * up0
            else:
                break
        L = norm3(F_perp)
        # bank about the air velocity: lift direction relative to the unbanked "up"
        if L > 1e-6:
            eL = F_perp / L
            mu = math.atan2(float(eL @ right0), float(eL @ up0))
        else:
            eL, mu = up0, 0.0
        if k.negative_lift and abs(mu) > math.pi - k.phi_max:
            # the force points below the horizon, further than the bank limit reaches: push
            # over (negative lift, wings banked the other way) instead of banking past it
            mu -= math.copysign(math.pi, mu)
            L = -L
        # lift -> alpha (linear lift, limited by CLmax and the alpha limits)
        alpha = min(max((L / q - qS_cl0) / qS_cla, k.alpha_min), min(k.alpha_max, alpha_stall))
        drag = q * (qS_cd0 + qS_cd1 * alpha + qS_cd2 * alpha * alpha)
        thrust = min(max(F_par + drag, 0.0), k.thrust_max)
        # the bank limit keeps the lift above the horizon in level flight; climbing or diving
        # steeply the wind-axis bank no longer says where the lift points relative to gravity
        # (vertical flight: any bank is level), so the limit opens towards phi_max_vertical
        phi_lim = k.phi_max
        if k.phi_max_vertical is not None and k.phi_max_vertical > k.phi_max:
            phi_lim += (k.phi_max_vertical - k.phi_max) * (1.0 - horiz * horiz)
        mu = min(max(mu, -phi_lim), phi_lim)
        eL = math.cos(mu) * up0 + math.sin(mu) * right0
        # body axes: x_b = cos a e1 + sin a eL, z_b = sin a e1 - cos a eL
        ca, sa = math.cos(alpha), math.sin(alpha)
        xb = ca * e1 + sa * eL
        zb = sa * e1 - ca * eL
        yb = cross(zb, xb)
        pitch = -math.asin(max(-1.0, min(1.0, float(xb[2]))))
        roll = math.atan2(float(yb[2]), float(zb[2]))
        yaw = math.atan2(float(xb[1]), float(xb[0]))
        return GuidanceCommand(alpha, mu, thrust, roll, pitch, yaw, (qS_cl0 + qS_cla * alpha) / ((1 - fold) * self.aero_u.S + fold * self.aero_f.S), norm3(e_p))
