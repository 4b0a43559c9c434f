"""Attitude loops of the autopilot: angle of attack, bank and sideslip for a manoeuvring,
tethered glider.

The attitude law of the 6-DOF glider (:mod:`fdm_awe.sixdof.attitude_law`, which the stabiliser
:class:`fdm_awe.sixdof.Stabilizer` uses too: surface commands from the aircraft's current
derivatives and inertia, so the loops follow the fold state), with the aircraft's free static
and damping moments inverted (far from trim) and no integral on the bank error. What matters on
a pumping-cycle path: the rate damping acts on the body rates *relative to the rotation of the
air-velocity vector*. On a curved path (loops at 3 g, a tether pulling) the velocity vector
turns at ``omega_path = v x a / |v|^2``; holding alpha and sideslip means rotating the body at
that rate, and damping the raw rates would fight it (a steady error of several degrees of
alpha). ``a`` is the measured specific force plus gravity, in body axes.
"""

from __future__ import annotations

import math


from ..sixdof.adapter import JSBSimGlider
from ..sixdof.attitude_law import AttitudeLaw, StabilizerGains
from ..sixdof.state import SixDofState


class AttitudeLoops:
    """``update(s, alpha_cmd, roll_cmd, dt) -> (aileron, elevator, rudder)`` normalised."""

    def __init__(self, glider: JSBSimGlider, gains: StabilizerGains, g: float = 9.80665) -> None:
        self.glider = glider
        self.g = g  #: m/s^2, gravity of the path's acceleration
        self.law = AttitudeLaw(glider, gains, invert_free_moments=True, bank_integral=False)

    @property
    def gains(self) -> StabilizerGains:
        """The attitude law's gains (changes to their fields act at the next update)."""
        return self.law.gains

    def reset(self) -> None:
        """Zero the integrator."""
        self.law.reset()

    def _path_rate(self, s: SixDofState) -> tuple[float, float, float]:
        # omega_path = v_b x a_b / V^2, a_b = specific force + gravity (body axes), on scalars
        phi, theta = s.phi, s.theta
        g = self.g
        gbx, gby, gbz = g * -math.sin(theta), g * (math.sin(phi) * math.cos(theta)), g * (math.cos(phi) * math.cos(theta))
        ax, ay, az = s.accel_body.tolist()
        ax, ay, az = ax + gbx, ay + gby, az + gbz
        V = max(s.airspeed, 1.0)
        alpha, beta = s.alpha, s.beta
        ca, sa, cb, sb = math.cos(alpha), math.sin(alpha), math.cos(beta), math.sin(beta)
        vx, vy, vz = V * (ca * cb), V * sb, V * (sa * cb)
        V2 = V * V
        return (vy * az - vz * ay) / V2, (vz * ax - vx * az) / V2, (vx * ay - vy * ax) / V2

    def update(self, s: SixDofState, alpha_cmd: float, roll_cmd: float, dt: float) -> tuple[float, float, float]:
        """Surface commands for angle of attack ``alpha_cmd`` and bank ``roll_cmd`` (rad), ``dt``
        (s) since the last update; damping relative to the path's rotation."""
        wp, wq, wr = self._path_rate(s)
        e_phi = roll_cmd - s.phi
        return self.law.commands(s, alpha_cmd, math.atan2(math.sin(e_phi), math.cos(e_phi)), wp, wq, wr, dt)
