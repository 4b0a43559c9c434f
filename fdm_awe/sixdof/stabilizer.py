"""A simple stabilising controller for the 6-DOF glider (tests, benchmarks, hold modes).

Holds angle of attack, bank angle and (optionally) heading with the attitude law
(:mod:`fdm_awe.sixdof.attitude_law`: surface commands from the aircraft's own current
derivatives, read from JSBSim, so the gains follow the fold state):

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

from math import cos, sin
from typing import Any

from .. import slots
from ..constants import G0
from .adapter import JSBSimGlider
from .attitude_law import AttitudeLaw, StabilizerGains, wrap_angle
from .row import ROW
from .state import SixDofState, Surfaces

__all__ = ["Stabilizer"]

#: m/s^2, gravity of the coordinated-turn yaw rate
_G_TURN = G0
#: the raw row's values :meth:`Stabilizer.update` reads
_STAB_ROW = slots.reader(ROW, "phi", "theta", "psi", "vt")


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
        self.law = AttitudeLaw(glider, gains or StabilizerGains(), invert_free_moments=False, bank_integral=True)
        self.phase = "hold"
        self._t_last: float | None = None

    @property
    def gains(self) -> StabilizerGains:
        """The attitude law's gains (changes to their fields act at the next update)."""
        return self.law.gains

    def set_alpha_cmd(self, alpha: float) -> None:
        """New angle-of-attack command, rad (re-computes the trim feed-forward)."""
        self.alpha_cmd = alpha
        self.law.invalidate()

    def update(self, t: float, s: SixDofState, gs_output: Any) -> tuple[Surfaces, Any]:
        # the co-simulation's hot path: the state's values straight from its raw row, max/min
        # and clipping spelled out (see AttitudeLaw.commands)
        tl = self._t_last
        if tl is None:
            dt = 0.0
        else:
            dt = t - tl
            if not dt > 0.0:
                dt = 0.0
        self._t_last = t
        rw = s.raw
        phi, theta, psi, vt = _STAB_ROW(rw)
        # bank command, from the heading error when a heading is held
        phi_c = self.phi_cmd
        psi_cmd = self.psi_cmd
        if psi_cmd is not None:
            gn = self.law.gains
            e_psi = wrap_angle(psi_cmd - psi)
            pm = gn.phi_max
            phi_c = gn.k_psi * e_psi
            phi_c = phi_c if phi_c < pm else pm
            phi_c = phi_c if phi_c > -pm else -pm
        # yaw damping about the coordinated-turn rate
        v = vt * s.scale[ROW.vt]
        if 1.0 > v:
            v = 1.0
        r_c = _G_TURN * sin(phi) * cos(theta) / v
        a, e, r = self.law.commands(s, self.alpha_cmd, phi_c - phi, 0.0, 0.0, r_c, dt)
        return Surfaces.fast(a, e, r, self.throttle, self.fold_cmd), self.winch
