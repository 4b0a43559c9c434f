"""Attitude loops of the autopilot: angle of attack, bank and sideslip for a manoeuvring,
tethered glider.

Model-based like :class:`fdm_awe.sixdof.Stabilizer` (surface commands from the aircraft's
current derivatives and inertia, so the loops follow the fold state), with one difference that
matters on a pumping-cycle path: the rate damping acts on the body rates *relative to the
rotation of the air-velocity vector*. On a curved path (loops at 3 g, a tether pulling) the
velocity vector turns at ``omega_path = v x a / |v|^2``; holding alpha and sideslip means
rotating the body at that rate, and damping the raw rates would fight it (a steady error of
several degrees of alpha). ``a`` is the measured specific force plus gravity, in body axes.
"""

from __future__ import annotations

import math

import numpy as np

from ..sixdof.adapter import JSBSimGlider
from ..sixdof.stabilizer import StabilizerGains
from ..sixdof.state import SixDofState


def _clip(v: float) -> float:
    return -1.0 if v < -1.0 else 1.0 if v > 1.0 else (v if v == v else 0.0)


class AttitudeLoops:
    """``update(s, alpha_cmd, roll_cmd, dt) -> (aileron, elevator, rudder)`` normalised."""

    def __init__(self, glider: JSBSimGlider, gains: StabilizerGains, g: float = 9.80665) -> None:
        self.glider = glider
        self.gains = gains
        self.g = g
        S, b, c = glider.reference_geometry()
        self._S, self._b, self._c = S, b, c
        lim = glider.surface_limits_rad
        self._lim_e, self._lim_a, self._lim_r = lim["elevator"], lim["aileron"], lim["rudder"]
        self._coef_fold = -1.0
        self._int = 0.0

    def reset(self) -> None:
        self._int = 0.0

    def _refresh(self, fold: float) -> None:
        if abs(fold - self._coef_fold) < 1e-3:
            return
        gl = self.glider
        self._coef_fold = fold
        self._cm_de = gl.coefficient("aero/coef/Cm_de")
        self._cl_da = gl.coefficient("aero/coef/Cl_da")
        self._cn_dr = gl.coefficient("aero/coef/Cn_dr")
        self._cn_beta = gl.coefficient("aero/coef/Cn_beta")
        self._cm0 = gl.coefficient("aero/coef/Cm0")
        self._cm_a = gl.coefficient("aero/coef/Cm_alpha")
        self._cm_q = gl.coefficient("aero/coef/Cm_q")
        self._cl_p = gl.coefficient("aero/coef/Cl_p")
        self._cl_r = gl.coefficient("aero/coef/Cl_r")
        self._cl_b = gl.coefficient("aero/coef/Cl_beta")
        J = gl.inertia()
        self._ixx, self._iyy, self._izz = J[0, 0], J[1, 1], J[2, 2]

    def path_rate_body(self, s: SixDofState) -> np.ndarray:
        """Rotation rate of the air-velocity vector, body axes [rad/s]."""
        return np.array(self._path_rate(s))

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
        gn = self.gains
        self._refresh(s.fold)
        qbar = max(s.qbar, 1.0)
        p, q, r = s.p, s.q, s.r
        wp0, wp1, wp2 = self._path_rate(s)
        alpha = s.alpha
        e_a = alpha_cmd - alpha
        self._int = max(-0.2, min(0.2, self._int + e_a * dt))
        V = max(s.airspeed, 1.0)
        # pitch: dynamic inversion of the static, damping and control moments
        m_des = self._iyy * (gn.w_alpha**2 * (e_a + gn.ki_alpha * self._int) - 2 * gn.z_alpha * gn.w_alpha * (q - wp1))
        cm_free = self._cm0 + self._cm_a * alpha + self._cm_q * q * self._c / (2 * V)
        de = (m_des / (qbar * self._S * self._c) - cm_free) / self._cm_de
        phi = s.phi
        e_phi = math.atan2(math.sin(roll_cmd - phi), math.cos(roll_cmd - phi))
        l_des = self._ixx * (gn.w_phi**2 * e_phi - 2 * gn.z_phi * gn.w_phi * (p - wp0))
        beta = s.beta
        cl_free = self._cl_b * beta + (self._cl_p * p + self._cl_r * r) * self._b / (2 * V)
        da = (l_des / (qbar * self._S * self._b) - cl_free) / self._cl_da
        n_des = -self._izz * 2 * gn.w_r * (r - wp2) + gn.k_beta * qbar * self._S * self._b * self._cn_beta * beta
        dr = n_des / (qbar * self._S * self._b * self._cn_dr)
        return _clip(da / self._lim_a), _clip(de / self._lim_e), _clip(dr / self._lim_r)
