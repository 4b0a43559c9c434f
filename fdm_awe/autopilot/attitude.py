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

The arithmetic is pure functions of floats and float64 vectors (numba compiles them for the
co-simulation kernel, Python runs the same source): :func:`path_rate` and
:func:`attitude_commands`, which composes it with the bank error's wrap and the law
(:func:`fdm_awe.sixdof.attitude_law.wrap_angle`, :func:`~fdm_awe.sixdof.attitude_law.law_commands`)
as :meth:`AttitudeLoops.update` does.
"""

from __future__ import annotations

import math
from typing import Any

from ..constants import G0
from ..sixdof.adapter import JSBSimGlider
from ..sixdof.attitude_law import AttitudeLaw, StabilizerGains, law_commands, surface_deflections, wrap_angle
from ..sixdof.row import ROW
from ..sixdof.state import SixDofState


def path_rate(g: float, phi: float, theta: float, fx: float, fy: float, fz: float, V: float, alpha: float,
              beta: float) -> tuple[float, float, float]:
    """Rotation rate (rad/s, body axes) of the air-velocity vector on its path,
    ``omega_path = v_b x a_b / V^2`` with ``a_b`` the specific force ``fx, fy, fz`` (m/s^2, body
    axes) plus gravity ``g`` (m/s^2) at bank ``phi`` and pitch ``theta`` (rad); ``V`` the
    airspeed (m/s, limited to >= 1 here), ``alpha``, ``beta`` rad."""
    gbx, gby, gbz = g * -math.sin(theta), g * (math.sin(phi) * math.cos(theta)), g * (math.cos(phi) * math.cos(theta))
    ax, ay, az = fx + gbx, fy + gby, fz + gbz
    if 1.0 > V:
        V = 1.0
    ca, sa, cb, sb = math.cos(alpha), math.sin(alpha), math.cos(beta), math.sin(beta)
    vx, vy, vz = V * (ca * cb), V * sb, V * (sa * cb)
    V2 = V * V
    return (vy * az - vz * ay) / V2, (vz * ax - vx * az) / V2, (vx * ay - vy * ax) / V2


def attitude_commands(c: Any, gains: Any, g: float, qbar: float, vt: float, phi: float, theta: float, alpha: float,
                      beta: float, p: float, q: float, r: float, fx: float, fy: float, fz: float, alpha_cmd: float,
                      roll_cmd: float, dt: float, integ: Any) -> tuple[float, float, float]:
    """The autopilot's attitude loops: ``(aileron, elevator, rudder)`` normalised, for angle of
    attack ``alpha_cmd`` and bank ``roll_cmd`` (rad), the rate damping relative to
    :func:`path_rate`, the bank error wrapped (:func:`wrap_angle`), the law with the free moments
    inverted and no bank integral. ``c``, ``gains``, ``integ``: the law's coefficient vector,
    gain vector and integrators (layouts ``C_*``, ``G_*``, ``I_*`` of
    :mod:`fdm_awe.sixdof.attitude_law`; ``integ`` updated in place); ``g`` m/s^2; ``qbar`` Pa;
    ``vt`` airspeed m/s; angles rad; ``p, q, r`` rad/s; ``fx, fy, fz`` the specific force
    (m/s^2, body axes); ``dt`` s since the last update."""
    wp, wq, wr = path_rate(g, phi, theta, fx, fy, fz, vt, alpha, beta)
    return law_commands(c, gains, qbar, vt, alpha, beta, p, q, r, alpha_cmd, wrap_angle(roll_cmd - phi), wp, wq, wr,
                        dt, integ, True, False)


def attitude_from_row(row: Any, scale: Any, alpha_cmd: float, roll_cmd: float, dt: float, c: Any, gains: Any,
                      g: float, integ: Any) -> tuple[float, float, float]:
    """:func:`attitude_commands` at the glider's raw JSBSim row ``row`` (SI by ``scale``, as
    :class:`~fdm_awe.sixdof.state.SixDofState` converts it: dynamic pressure, airspeed, the
    specific force from the body forces over the mass), for angle of attack ``alpha_cmd`` and bank
    ``roll_cmd`` [rad] after ``dt`` [s]; ``c``, ``gains``, ``integ`` the law's vectors (``integ``
    updated), ``g`` [m/s^2] the loops' gravity."""
    m = row[ROW.mass] * scale[ROW.mass]
    return attitude_commands(c, gains, g, row[ROW.qbar] * scale[ROW.qbar], row[ROW.vt] * scale[ROW.vt], row[ROW.phi],
                             row[ROW.theta], row[ROW.alpha], row[ROW.beta], row[ROW.p_rate], row[ROW.q_rate],
                             row[ROW.r_rate], row[ROW.fbx] * scale[ROW.fbx] / m, row[ROW.fby] * scale[ROW.fby] / m,
                             row[ROW.fbz] * scale[ROW.fbz] / m, alpha_cmd, roll_cmd, dt, integ)


#: the pure functions :func:`attitude_commands` and :func:`attitude_from_row` call (a compiled
#: caller registers them with ``numba.extending.register_jitable``)
CALLED = (path_rate, wrap_angle, surface_deflections, law_commands, attitude_commands)


class AttitudeLoops:
    """``update(s, alpha_cmd, roll_cmd, dt) -> (aileron, elevator, rudder)`` normalised."""

    def __init__(self, glider: JSBSimGlider, gains: StabilizerGains, g: float = G0) -> None:
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

    def update(self, s: SixDofState, alpha_cmd: float, roll_cmd: float, dt: float) -> tuple[float, float, float]:
        """Surface commands for angle of attack ``alpha_cmd`` and bank ``roll_cmd`` (rad), ``dt``
        (s) since the last update; damping relative to the path's rotation."""
        law = self.law
        return attitude_from_row(s.raw, s.scale, alpha_cmd, roll_cmd, dt, law.coefficients(s.fold, alpha_cmd),
                                 law.gains.law_gains(), self.g, law.integ)
