"""A simple stabilising controller for the 6-DOF glider (tests, benchmarks, hold modes).

Holds angle of attack, bank angle and (optionally) heading with surface commands computed from
the aircraft's own current derivatives (read from JSBSim, so the gains follow the fold state):

- pitch: elevator = trim(alpha_cmd) + moment demand for a second-order alpha response
  (``w_alpha`` rad/s, ``z_alpha``) plus integral action on the alpha error;
- roll: aileron from a second-order bank response (``w_phi``, ``z_phi``) with integral action
  (``ki_phi``, trims the propeller torque); with ``psi_cmd`` set,
  the bank command follows the heading error (``k_psi``, limited to ``phi_max``);
- yaw: rudder damps the yaw rate about the coordinated-turn rate and nulls sideslip.

Ground side: a constant :class:`~fdm_awe.groundstation.WinchCommand` (``winch``), or None to
pass None (for stand-in ground stations that ignore it).
"""

from __future__ import annotations

from math import atan2, cos, sin
from dataclasses import dataclass
from typing import Any

from .adapter import JSBSimGlider
from .row import ALPHA, BETA, FOLD, P_RATE, PHI, PSI, Q_RATE, QBAR, R_RATE, THETA, VT
from .state import SixDofState, Surfaces


@dataclass
class StabilizerGains:
    w_alpha: float = 6.0  #: rad/s, alpha loop bandwidth
    z_alpha: float = 0.8
    ki_alpha: float = 0.0  #: 1/s, integral action on the alpha error (0: off; > ~0.3 couples with the phugoid)
    w_phi: float = 5.0  #: rad/s, bank loop bandwidth
    z_phi: float = 0.8
    ki_phi: float = 1.0  #: 1/s, integral action on the bank error (trims propeller torque)
    w_r: float = 3.0  #: rad/s, yaw damper
    k_beta: float = 1.0  #: rudder per sideslip, in units of the weathercock stiffness
    k_psi: float = 1.0  #: bank command per heading error, rad/rad
    phi_max: float = 0.6  #: rad, bank command limit


class Stabilizer:
    """Controller protocol: ``update(t, state, gs_output) -> (Surfaces, WinchCommand)``."""

    def __init__(self, glider: JSBSimGlider, alpha_cmd: float, phi_cmd: float = 0.0,
                 psi_cmd: float | None = None, throttle: float = 0.0, fold_cmd: float = 0.0,
                 winch: Any = None, gains: StabilizerGains | None = None) -> None:
        self.glider = glider
        self.alpha_cmd = alpha_cmd
        self.phi_cmd = phi_cmd
        self.psi_cmd = psi_cmd
        self.throttle = throttle
        self.fold_cmd = fold_cmd
        self.winch = winch
        self.gains = gains or StabilizerGains()
        self.phase = "hold"
        self._int = 0.0
        self._int_phi = 0.0
        self._t_last: float | None = None
        self._coef_fold = -1.0
        S, b, c = glider.reference_geometry()
        self._S, self._b, self._c = S, b, c
        lim = glider.surface_limits_rad
        self._lim_e, self._lim_a, self._lim_r = lim["elevator"], lim["aileron"], lim["rudder"]

    def set_alpha_cmd(self, alpha: float) -> None:
        """New angle-of-attack command, rad (re-computes the trim feed-forward)."""
        self.alpha_cmd = alpha
        self._coef_fold = -1.0

    def _refresh(self, fold: float) -> None:
        """Re-read derivatives and inertia when the fold state moved (cheap otherwise)."""
        if abs(fold - self._coef_fold) < 1e-3:
            return
        g = self.glider
        self._coef_fold = fold
        self._cm_de = float(g.coefficient("aero/coef/Cm_de"))
        self._cl_da = float(g.coefficient("aero/coef/Cl_da"))
        self._cn_dr = float(g.coefficient("aero/coef/Cn_dr"))
        self._cn_beta = float(g.coefficient("aero/coef/Cn_beta"))
        self._de_trim = g.trim_elevator(self.alpha_cmd) * self._lim_e
        J = g.inertia()
        self._ixx, self._iyy, self._izz = float(J[0, 0]), float(J[1, 1]), float(J[2, 2])

    def update(self, t: float, s: SixDofState, gs_output: Any) -> tuple[Surfaces, Any]:
        # written for the co-simulation's hot path: the same arithmetic as the plain form, with
        # max/min spelled out (max(a, b) is ``b if b > a else a``, min(a, b) ``b if b < a else a``)
        gn = self.gains
        # the state's values straight from its raw row (SixDofState's properties written out:
        # the same numbers without a call each)
        rw, kk = s._r, s._k
        fold = rw[FOLD]
        if not abs(fold - self._coef_fold) < 1e-3:
            self._refresh(fold)
        tl = self._t_last
        if tl is None:
            dt = 0.0
        else:
            dt = t - tl
            if not dt > 0.0:
                dt = 0.0
        self._t_last = t
        qbar = rw[QBAR] * kk[QBAR]
        if 1.0 > qbar:
            qbar = 1.0
        p, q, r = rw[P_RATE], rw[Q_RATE], rw[R_RATE]
        S = self._S
        # pitch: alpha second-order response + integral, feed-forward trim
        e_a = self.alpha_cmd - rw[ALPHA]
        ia = self._int + e_a * dt
        ia = ia if ia < 0.2 else 0.2
        ia = ia if ia > -0.2 else -0.2
        self._int = ia
        w = gn.w_alpha
        m_des = self._iyy * (w**2 * (e_a + gn.ki_alpha * ia) - 2 * gn.z_alpha * w * q)
        de = self._de_trim + m_des / (qbar * S * self._c * self._cm_de)
        # roll: bank response
        phi, theta, psi = rw[PHI], rw[THETA], rw[PSI]
        phi_c = self.phi_cmd
        psi_cmd = self.psi_cmd
        if psi_cmd is not None:
            e_psi = atan2(sin(psi_cmd - psi), cos(psi_cmd - psi))
            pm = gn.phi_max
            phi_c = gn.k_psi * e_psi
            phi_c = phi_c if phi_c < pm else pm
            phi_c = phi_c if phi_c > -pm else -pm
        e_phi = phi_c - phi
        ip = self._int_phi + e_phi * dt
        ip = ip if ip < 0.5 else 0.5
        ip = ip if ip > -0.5 else -0.5
        self._int_phi = ip
        w = gn.w_phi
        l_des = self._ixx * (w**2 * (e_phi + gn.ki_phi * ip) - 2 * gn.z_phi * w * p)
        qSb = qbar * S * self._b
        da = l_des / (qSb * self._cl_da)
        # yaw: damp r about the coordinated-turn rate, null sideslip
        v = rw[VT] * kk[VT]
        if 1.0 > v:
            v = 1.0
        r_c = 9.81 * sin(phi) * cos(theta) / v
        n_des = -self._izz * 2 * gn.w_r * (r - r_c) + gn.k_beta * qbar * S * self._b * self._cn_beta * rw[BETA]
        dr = n_des / (qSb * self._cn_dr)
        a, e, rr = da / self._lim_a, de / self._lim_e, dr / self._lim_r
        surf = Surfaces._checked_fast(
            -1.0 if a < -1.0 else 1.0 if a > 1.0 else (a if a == a else 0.0),
            -1.0 if e < -1.0 else 1.0 if e > 1.0 else (e if e == e else 0.0),
            -1.0 if rr < -1.0 else 1.0 if rr > 1.0 else (rr if rr == rr else 0.0),
            self.throttle, self.fold_cmd)
        return surf, self.winch


def _clip(v: float) -> float:
    return -1.0 if v < -1.0 else 1.0 if v > 1.0 else (v if v == v else 0.0)
