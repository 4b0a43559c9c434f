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
- Current limit (``converter/current_limit``, :func:`.substeps.hold_current`): where the
  sub-step's current would exceed it, the converter lowers the T1 duty until the current is
  the limit (the current is affine in the source voltage in the backward-Euler step, so the
  duty follows exactly). A drum paying out fast drives the current by its EMF even with T1
  off; then T2 opens too for a share of the period (a duty below 0, down to -1 with both
  switches open): the armature sees ``-V_a`` through D1 and D2 and the current returns to the
  supply bus. The supply is taken to take no energy back: a brake chopper on the bus holds it
  at ``V_a`` and burns that energy in its resistor (the ledger's ``brake``). Where even both
  switches open pass more than the limit (the line pulling the drum out beyond what the
  machine can brake at ``-V_a``), the current is the EMF's and the flight logs the rating.

:func:`link_coefficients` (:mod:`.substeps`) gives the link's terms of one backward-Euler
sub-step; the step takes ``v_src = d1 V_a, s = 0`` in motor mode and ``v_src = 0, s = 1 - d2``
in generator mode. In generator mode the same current limit acts through the link
(:func:`.substeps.hold_generator`): the converter draws less load current than ``R_L`` would,
the link charges to the voltage that holds the current (or, where it cannot charge that
fast, the load is off). Above the line's tension limit (``converter/tension_limit``, on the
tension measured every sub-step) the generator's limit falls to 0 A over
``converter/tension_limit_band`` (:func:`.substeps.force_limited_current`): the upper-force
controller, the drum pays out instead of braking (docs/design.md 5).
"""

from __future__ import annotations

GENERATOR = "generator"
MOTOR = "motor"
MODES = (GENERATOR, MOTOR)

__all__ = ["GENERATOR", "MODES", "MOTOR"]
