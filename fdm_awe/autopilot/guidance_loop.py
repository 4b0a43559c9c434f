"""The guidance as the autopilot holds it: its gains and limits (definition file
``autopilot.xml``, :class:`GuidanceGains`), its command (:class:`GuidanceCommand`) and its
state, the position-error integral (:class:`Guidance`), stepping the pure arithmetic of
:mod:`.guidance` (:func:`~.guidance.guidance_step`) on Python floats.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..constants import G0, RHO0
from ..definitions.aircraft import AeroParams
from .guidance import GK, Polar, blended_polar, guidance_step
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
    #: the thrust acts along the body x-axis (the 6-DOF propeller and the paper plant's ideal
    #: thruster), alpha above the air velocity: it is inverted as such (False: along the air
    #: velocity, the point-mass model's thrust)
    thrust_on_body_axis: bool = True
    #: underspeed protection (:mod:`.underspeed`): entered below this times the stall speed of
    #: the current fold state [-] (0: off)
    us_enter: float = 0.0
    us_exit: float = 1.3  #: left above this times the stall speed [-] ...
    us_hold: float = 2.0  #: ... at the earliest this long after the airspeed was last below the entry speed [s]
    us_alpha_margin: float = 0.04  #: while protected, alpha is capped this far below the stall [rad]
    us_speed_gain: float = 1.0  #: while protected, along-path acceleration per m/s below the exit speed [1/s]
    us_slack_acc: float = 2.0  #: while protected on a slack line, horizontal acceleration away from the winch [m/s^2]
    #: with the protection on, alpha stays us_alpha_margin below the stall up to this airspeed in
    #: stall speeds [-] (faster, a pull-out needs the whole lift and an overshoot past the stall is brief)
    us_margin_speed: float = 2.0
    #: ground-proximity guard (:mod:`.ground`): pull up where the glider, sinking as it does, would
    #: cross this height above the ground [m] before a pull-out at ``gp_acc`` (0: off)
    gp_alt: float = 0.0
    gp_acc: float = 25.0  #: the pull-out's acceleration across the path, predicted and asked at least [m/s^2]
    gp_climb: float = 2.0  #: climbing faster than this [m/s] the guard asks for no more upward acceleration
    #: lift [in weights, -] below which the folded wing's bank command fades to wings level, as
    #: L^2 / (L^2 + L0^2) with L0 this times the weight times the fold state (0: off): near zero
    #: lift the lift's direction, the bank, swings with little force behind it
    bank_lift: float = 0.0

    def vector(self) -> np.ndarray:
        """The gains as a float64 array in the layout :data:`~.guidance.GK` (the field
        order; None as NaN, the flags as 0.0/1.0), the ``gk`` of :func:`~.guidance.guidance_step`."""
        nan = math.nan
        return np.array((self.kp, self.kd, self.ki, self.a_max, self.int_max, self.alpha_min, self.alpha_max,
                         self.phi_max, self.thrust_max, self.energy_trade, float(self.negative_lift),
                         nan if self.curv_scale_max is None else self.curv_scale_max, self.overspeed_tension,
                         self.overspeed_margin, nan if self.phi_max_vertical is None else self.phi_max_vertical,
                         float(self.thrust_on_body_axis), self.us_enter, self.us_exit, self.us_hold,
                         self.us_alpha_margin, self.us_speed_gain, self.us_slack_acc, self.us_margin_speed,
                         self.gp_alt, self.gp_acc, self.gp_climb, self.bank_lift),
                        dtype=np.float64)


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


def _xyz(v) -> tuple[float, float, float]:
    """Three Python floats of a 3-vector (array, list or tuple)."""
    if type(v) is np.ndarray:
        v = v.tolist()
    return v[0], v[1], v[2]


class Guidance:
    """Stateful outer loop (holds the position-error integral); its arithmetic is
    :func:`~.guidance.guidance_step`."""

    def __init__(self, gains: GuidanceGains, mass: float, aero_u: AeroParams, aero_f: AeroParams, rho: float = RHO0, g: float = G0) -> None:
        self.k = gains  #: the gains (may be replaced by new ones between steps)
        self.m = mass
        self.aero_u, self.aero_f = aero_u, aero_f
        self.rho, self.g = rho, g
        #: position-error integral, NED [m s], layout :data:`~.guidance.INTEGRAL` (updated in place)
        self.integral = np.zeros(3)
        self._polar: tuple[float, Polar] | None = None  # (fold state, blended_polar) of the last step
        self._gk: tuple[GuidanceGains, list[float]] | None = None  # (gains, their vector as floats)

    def polar(self, fold: float) -> Polar:
        """:func:`~.guidance.blended_polar` at fold state ``fold``, kept while the fold state does not move."""
        c = self._polar
        if c is None or c[0] != fold:
            c = self._polar = (fold, blended_polar(self.aero_u, self.aero_f, fold))
        return c[1]

    def gains_vector(self) -> list[float]:
        """:meth:`GuidanceGains.vector` of the current gains :attr:`k` as Python floats (the
        Python step's arithmetic stays on floats), rebuilt when :attr:`k` is replaced."""
        c = self._gk
        if c is None or c[0] is not self.k:
            c = self._gk = (self.k, self.k.vector().tolist())
        return c[1]

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
        thrust_max: float | None = None,
        ref_pull: bool = False,
        underspeed: float = 0.0,
    ) -> GuidanceCommand:
        """``taut``: the line is taut, so the radial motion is the winch's: the position loop
        then acts only on the sphere's tangent plane, and the radial aerodynamic force is the
        reference's (feeding the measured tension back would close a positive loop through
        the line: more pull -> more tension -> more pull). ``thrust_max`` [N]: the thrust
        available this step (None: the gains' ``thrust_max``; 0 with the motor stopped, so an
        along-path force the glider lacks is traded through the flight path). ``ref_pull``: on a
        line that is not taut, the line's radial pull in the force balance is the reference's
        tension, not the measured one (see :func:`~.guidance.guidance_step`). ``underspeed``: the underspeed
        protection acts (0 no, 1 yes, 2 yes on a slack line, :data:`~.guidance.US_PULL_UP` the ground-proximity
        guard pulls up; :func:`~.guidance.guidance_step`'s ``us``)."""
        gk = self.gains_vector()
        t_max = gk[GK.thrust_max] if thrust_max is None else thrust_max
        # the step's input (layout GIN) as Python floats: the Python step's arithmetic stays on floats
        gin = [self.m, self.rho, self.g, self.aero_u.S, self.aero_f.S, *_xyz(ref.pos), *_xyz(ref.vel), *_xyz(ref.acc),
               ref.tension, *_xyz(pos), *_xyz(vel), *_xyz(wind), *_xyz(tether_force), fold, dt, taut, t_max, ref_pull,
               underspeed]
        return GuidanceCommand(*guidance_step(gk, self.integral, self.polar(fold), gin))
