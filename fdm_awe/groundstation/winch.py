"""Winch drum dynamics (paper eq. 14) with the implicit, set-valued Coulomb friction.

Drum equation (reel-out positive, omega = reel speed / r_w):

    (J + mu l r_w^2) domega/dt = r_w T - K_t i - B omega - M_c sgn(omega)

- ``J`` is Table 1's total inertia (drum + rotor); the paid-out line adds ``mu l r_w^2``.
- ``M_c`` is Table 1's Coulomb friction, counted once (docs/design.md 4.8: eq. 14's M_c and eq. 16's
  T_f are the same term); ``B`` the viscous friction; ``K_t i`` the machine torque, which acts in
  the reel-in direction only (the asymmetric half-bridge carries one current direction).
- Stick-slip without chattering: friction is the set-valued law ``M_f in M_c Sign(omega)``
  solved implicitly (backward Euler) every sub-step. When the driving torque cannot overcome
  M_c the drum sticks exactly (omega = 0, friction = whatever holds it, |M_f| <= M_c): no
  switching at zero speed, no smoothing velocity (equivalent to Karnopp's stick band shrunk to
  the exact stick condition).
"""

from __future__ import annotations

from .substeps import drum_speed

#: One backward-Euler step of the drum speed with set-valued Coulomb friction:
#: ``solve_drum_speed(J, w0, h, B, Mc, r, tA, tB, K, iA, iB) -> (w rad/s, M_f N m)``
#: (:func:`fdm_awe.groundstation.substeps.drum_speed`).
solve_drum_speed = drum_speed

__all__ = ["solve_drum_speed"]
