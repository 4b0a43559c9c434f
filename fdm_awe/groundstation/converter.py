"""Asymmetric half-bridge converter, averaged-switch model (paper Fig. 3, eqs. 15, 18, 19).

Topology: the armature sits between the mid points of two legs; T1 (top) and T2 (bottom)
switches, D1/D2 the opposite diodes. One current direction only.

Generator mode (T1 off). The DC link is the capacitor ``C_Link`` in parallel with ``R_L``:
- T2 off: current through D1, D2 into the link -- a passive rectifier (eq. 15):
  ``e = u_L + R i + L di/dt + 2 U_d``, ``i = u_L / R_L + C du_L/dt``.
- T2 on: armature short-circuited through T2 and D2 (eq. 18), the current builds up (boost
  stage). Averaged with T2 duty ``d2``: the link sees ``(1 - d2) u_L`` in the armature loop and
  receives ``(1 - d2) i``.
Motor mode (T2 on, T1 PWM with duty ``d1``), fed from the supply ``V_a``:
- T1 on: eq. 19, ``V_a = e + R i + L di/dt + 2 U_d``; T1 off: freewheeling through T2 and D2.
  Averaged: source ``d1 V_a``; the supply delivers ``d1 V_a i``. The link capacitor stays on
  ``R_L`` and discharges into it.

:func:`link_coefficients` (:mod:`.substeps`) gives the link's terms of one backward-Euler
sub-step; the step takes ``v_src = d1 V_a, s = 0`` in motor mode and ``v_src = 0, s = 1 - d2``
in generator mode.
"""

from __future__ import annotations

from .substeps import link_coefficients

GENERATOR = "generator"
MOTOR = "motor"
MODES = (GENERATOR, MOTOR)

__all__ = ["GENERATOR", "MODES", "MOTOR", "link_coefficients"]
