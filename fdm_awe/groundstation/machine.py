"""Permanent-magnet DC machine (paper eqs. 15-19) and the operating-mode sign rule (eq. 17).

The armature loop seen through the asymmetric half-bridge, averaged over a PWM period, with
the current ``i >= 0`` (the converter conducts one current direction; the machine torque
``K_t i`` always pulls the drum in the reel-in direction) and ``e = K_e omega`` (omega > 0 =
reel-out, so e drives the current while reeling out and opposes it while reeling in)::

    L_a di/dt = v_src + K_e omega - R i - 2 U_d - s u_L,      i >= 0 (diodes block)

``v_src`` and ``s`` come from the converter (:mod:`fdm_awe.groundstation.converter`):
generator mode ``v_src = 0, s = 1 - d_T2`` (eq. 15 with T2 off: s = 1; eq. 18 for the T2-on
share), motor mode ``v_src = d_T1 V_a, s = 0`` (eq. 19 for the T1-on share, freewheeling through
T2 and D2 for the rest). Every path holds two devices: ``2 U_d``.

The electrical time constants (L_a / R ~ 0.4 ms, R_L C ~ 1.5 ms) are integrated with backward
Euler inside the ground station's sub-steps: L-stable, exact in steady state, and the current
at the end of a sub-step is affine in the unknown drum speed (:func:`armature_coefficients`,
in :mod:`.substeps`), which lets the drum, line and armature be solved together without iteration.
"""

from __future__ import annotations

from .substeps import MACHINE_MODES, machine_mode_code

__all__ = ["load_torques", "machine_mode"]


def machine_mode(omega: float, current: float, tension: float, K: float, r: float) -> str:
    """Operating mode by the sign rule of eq. 17.

    In the paper's rotation-referenced torques (positive along the sense of rotation),
    ``T_e`` is the machine torque and ``T_L`` the load torque of the line:
    ``T_e, T_L < 0`` -> ``"generator"``, ``T_e, T_L > 0`` -> ``"motor"``. With our signs
    (machine torque ``-K i`` and line torque ``+r T`` on the reel-out axis)
    ``T_e = -sgn(omega) K i`` and ``T_L = -sgn(omega) r T``. The machine power decides a case
    the rule leaves open (line slack, or braking against the rotation): ``T_e < 0`` ->
    generator, ``T_e > 0`` -> motor; ``"idle"`` when no torque or no rotation.
    """
    return MACHINE_MODES[machine_mode_code(omega, current, K)]


def load_torques(omega: float, current: float, tension: float, K: float, r: float) -> tuple[float, float]:
    """``(T_e, T_L)`` of eq. 16/17 in the rotation-referenced sign convention, N m."""
    sg = 1.0 if omega >= 0.0 else -1.0
    return -sg * K * current, -sg * r * tension
