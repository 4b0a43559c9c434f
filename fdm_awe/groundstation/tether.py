"""Tether line: geometry, elastic tension, and the line forces the glider carries.

Model (straight line from the winch at the NED origin to the glider attachment point):

- ``length`` l is the unstretched paid-out length, integrated from the drum
  (``l_dot = r_w omega``, see :mod:`fdm_awe.groundstation.drivetrain`).
- Elastic when taut, slack otherwise: ``T = EA (d - l) / l`` for ``d > l``, else ``0``
  (d = |P| the winch-glider distance). Stored energy ``E = 0.5 (EA / l) (d - l)^2`` when taut.
- Line drag (docs/design.md section 5, ``C_D_perp``, diameter ``d_t``): the glider carries the share
  ``drag_share`` (default 1/4) of ``0.5 rho C_D_perp d_t l |v_perp| v_perp`` with ``v_perp`` the
  glider's air velocity normal to the line. For a straight line whose velocity grows linearly
  from 0 at the winch to ``v_perp`` at the glider, 1/4 is exact both for the moment about the
  winch and for the dissipated power (``int_0^l (s/l)^3 ds = l/4``); this is the usual
  ``C_D,t = C_D_perp d_t l / (4 S)`` of AWE point-mass models.
- Line weight: the glider carries ``weight_share`` (default 1/2) of ``mu l g`` (straight line,
  moment balance about the winch), acting down (+z NED).
- The axial mass of the paid-out line ``mu l`` moves with the drum surface and is added to the
  drum inertia (``mu l r_w^2``, :func:`fdm_awe.groundstation.substeps.advance`).

The line's numbers (diameter, mass per length, EA, breaking load) are those of the line selected
from the ground-station definition (:mod:`fdm_awe.groundstation.line`: ``sized`` by default, or
Table 1's ``paper`` line).

The ground station's step computes the drag and weight shares with
:func:`fdm_awe.groundstation.substeps.cross_flow_drag` and ``weight_share``; the functions here give
them from the definition's :class:`TetherParams`.
"""

from __future__ import annotations

import math

from ..errors import InputError
from .definitions import TetherParams
from .substeps import cross_flow_drag

#: allowed line-drag sensitivity factor (``tether_drag_scale`` of the optimiser and of the
#: ground station; 1 = the defined line)
TETHER_DRAG_SCALE_MAX = 10.0


def check_tether_drag_scale(value: float) -> float:
    """``value`` as a float if it is an allowed line-drag factor (0 .. 10), else a one-line
    :class:`~fdm_awe.errors.InputError`."""
    if not (isinstance(value, (int, float)) and math.isfinite(value) and 0.0 <= value <= TETHER_DRAG_SCALE_MAX):
        raise InputError(f"tether_drag_scale = {value!r} out of range (allowed 0 .. {TETHER_DRAG_SCALE_MAX:g})")
    return float(value)


def elastic_tension(p: TetherParams, dist: float, length: float) -> float:
    """Tension of the straight elastic line, N (0 when slack, d <= l)."""
    s = dist - length
    return p.axial_stiffness * s / length if s > 0.0 else 0.0


def elastic_energy(p: TetherParams, dist: float, length: float) -> float:
    """Strain energy stored in the line, J (0 when slack)."""
    s = dist - length
    return 0.5 * p.axial_stiffness * s * s / length if s > 0.0 else 0.0


def line_drag_share(
    p: TetherParams,
    length: float,
    x: float, y: float, z: float,
    vax: float, vay: float, vaz: float,
    scale: float = 1.0,
) -> tuple[float, float, float]:
    """Share of the line drag acting on the glider, NED, N.

    ``(x, y, z)`` glider position (winch at the origin), ``(vax, vay, vaz)`` glider velocity
    relative to the air (ground velocity minus wind), m/s. Only the component normal to the
    line counts: ``F = -scale share 0.5 rho C_D_perp d_t l |v_perp| v_perp``; ``scale`` (-,
    default 1 = the defined line) is the line-drag sensitivity factor of
    :class:`fdm_awe.groundstation.station.GroundStation` (``tether_drag_scale``).
    """
    d = math.sqrt(x * x + y * y + z * z)
    if d <= 0.0 or p.drag_share <= 0.0 or scale <= 0.0:
        return 0.0, 0.0, 0.0
    return cross_flow_drag(x / d, y / d, z / d, vax, vay, vaz, line_drag_coefficient(p, scale) * length)


def line_drag_coefficient(p: TetherParams, scale: float = 1.0) -> float:
    """``-share 0.5 rho C_D_perp d_t scale`` (kg/m^2): times the paid-out length and ``|v_perp|
    v_perp`` the glider's share of the line drag, N."""
    return -0.5 * p.drag_share * p.air_density * p.cd_perpendicular * p.diameter * scale
