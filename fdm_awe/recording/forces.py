"""The forces on the glider during a flight: lift, drag, side force, tether and thrust (N, NED).

A flight logs the tether force (``tether_force``, the ground station's force on the glider)
and the thrust magnitude (``thrust``, along the body x axis: the propeller's thrust line, or
the paper plant's ideal thruster), but not the aerodynamic force. That one follows from
Newton's second law applied to the logged motion::

    F_aero = m (dv/dt - g) - F_tether - T x_body

with ``m`` the glider's mass (aircraft files), ``v`` the logged NED velocity differentiated
by central differences, ``g = (0, 0, g0)`` and ``F_tether`` the mean of the two steps around
the row (the central difference spans both). It is then split in wind axes, built from the
logged attitude and the flow angles alpha, beta (so it holds in gusts and turbulence too):
drag along the air velocity, lift perpendicular to it in the glider's plane of symmetry, side
force the rest (lift + drag + side = F_aero exactly). While the glider touches the ground the
residual also holds the contact forces. No number is assumed beyond the mass and g0: the
body-z component of the sum of the forces agrees with JSBSim's own load factor (the logged
``load_factor``) to about 0.01 g on the nominal cycle.

The first row has no ground-station step yet (tether force NaN): its aerodynamic force is NaN.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

#: names of the force vectors, in drawing order
FORCE_NAMES: tuple[str, ...] = ("lift", "drag", "tether", "thrust")


@dataclass
class GliderForces:
    """Forces on the glider over the rows of a flight: vectors (n, 3) NED [N] ``lift``, ``drag``,
    ``side``, ``tether``, ``thrust``; the aerodynamic components signed in wind axes [N]: ``L``
    (lift, > 0 towards -z_w), ``D`` (drag, > 0 against the air velocity), ``C`` (side force,
    > 0 towards +y_w); ``t`` [s] from the first row."""

    t: np.ndarray
    lift: np.ndarray
    drag: np.ndarray
    side: np.ndarray
    tether: np.ndarray
    thrust: np.ndarray
    L: np.ndarray
    D: np.ndarray
    C: np.ndarray
    mass: float  #: glider mass used [kg]

    def __getitem__(self, name: str) -> np.ndarray:
        return getattr(self, name)

    def magnitude(self, name: str) -> np.ndarray:
        """|force| [N] per row (NaN where the force is unknown)."""
        return np.linalg.norm(self[name], axis=1)


def glider_mass(aircraft: Any = None) -> float:
    """Mass of the glider [kg] from the files of ``aircraft`` (None: the package's glider; both
    forms weigh the same)."""
    from ..definitions.aircraft import load_glider

    return float(load_glider(aircraft).unfolded.mass.mass)


def body_axes(euler: np.ndarray) -> np.ndarray:
    """(n, 3, 3) rotation matrices body -> NED of ZYX Euler angles (n, 3) [rad]
    (:func:`fdm_awe.sixdof.state.dcm_body_to_ned` per row); column i is body axis i in NED."""
    from ..sixdof.state import dcm_body_to_ned

    e = np.asarray(euler, float).reshape(-1, 3)
    return np.array([dcm_body_to_ned(*row) for row in e.tolist()]).reshape(-1, 3, 3)


def wind_axes(dcm: np.ndarray, alpha: np.ndarray, beta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit vectors (x_w, y_w, z_w), each (n, 3) NED, of the wind axes: x_w along the air
    velocity, z_w = (-sin a, 0, cos a) in body axes, y_w = z_w x x_w; ``dcm`` body -> NED
    (n, 3, 3), flow angles ``alpha``, ``beta`` [rad]."""
    ca, sa, cb, sb = np.cos(alpha), np.sin(alpha), np.cos(beta), np.sin(beta)
    xw = np.einsum("nij,nj->ni", dcm, np.stack((ca * cb, sb, sa * cb), axis=1))
    zw = np.einsum("nij,nj->ni", dcm, np.stack((-sa, np.zeros_like(sa), ca), axis=1))
    return xw, np.cross(zw, xw), zw


def flight_forces(flight: Any, mass: float | None = None) -> GliderForces:
    """The forces of a flight (FlightReport or FlightResult) per logged row; ``mass`` [kg]
    defaults to the mass the report records (``aircraft.mass_kg``), else :func:`glider_mass`.
    Fewer than two rows: every force NaN but the logged ones."""
    from ..constants import G0

    res = getattr(flight, "result", None) or flight
    t = np.asarray(res.t, float)
    n = len(t)
    if mass is None:
        rec = getattr(flight, "aircraft", None)
        mass = rec.get("mass_kg") if isinstance(rec, dict) else None
    m = glider_mass() if mass is None else float(mass)
    dcm = body_axes(res.euler)
    tether = np.asarray(res.tether_force, float)
    thrust = np.asarray(res.thrust, float)[:, None] * dcm[:, :, 0]
    f_aero = np.full((n, 3), np.nan)
    if n >= 2:
        accel = np.gradient(np.asarray(res.vel, float), t, axis=0)
        mean_tether = tether.copy()
        mean_tether[:-1] = 0.5 * (tether[:-1] + tether[1:])
        f_aero = m * (accel - np.array([0.0, 0.0, G0])) - mean_tether - thrust
    xw, yw, zw = wind_axes(dcm, np.asarray(res.alpha, float), np.asarray(res.beta, float))
    L, D, C = (-np.sum(f_aero * zw, axis=1), -np.sum(f_aero * xw, axis=1), np.sum(f_aero * yw, axis=1))
    return GliderForces(t=t - t[0] if n else t, lift=-L[:, None] * zw, drag=-D[:, None] * xw, side=C[:, None] * yw,
                        tether=tether, thrust=thrust, L=L, D=D, C=C, mass=m)


__all__ = ["FORCE_NAMES", "GliderForces", "body_axes", "flight_forces", "glider_mass", "wind_axes"]
