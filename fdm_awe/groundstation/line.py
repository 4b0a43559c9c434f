"""Tether lines: a line sized for its load from its material, Table 1's line, and the summary.

The ground-station definition (``tether/ground_station.xml``) names its lines (:data:`LINES`):

- ``sized`` (the default, :data:`DEFAULT_LINE`): a braided UHMWPE line sized for the system's
  rated tension with a safety factor. The file gives the MATERIAL (:class:`LineMaterial`) and the
  SIZING (:class:`LineSizing`); :func:`size_line` derives the line's section from them:

  - breaking load ``F_b = SF T_rated``;
  - mass per length ``mu = F_b / tenacity`` (the braid's rated breaking tenacity, N/tex = N per
    g/km, i.e. per 1e-6 kg/m);
  - diameter ``d = sqrt(4 A / pi)`` of the round envelope whose area ``A = mu / (rho_f phi)``
    holds the fibre cross-section ``mu / rho_f`` at the braid's fill factor ``phi``;
  - axial stiffness ``EA = k_braid E_f mu`` with the fibre's specific modulus ``E_f`` (N/tex)
    and the braid's stiffness factor ``k_braid`` (helix angle and construction stretch).

- ``paper``: Table 1's line (0.4 g/m Dyneema, 0.72 mm, EA 22.6 kN, 700 N) with its numbers as
  the paper and the earlier estimates give them (not derived), so that every number computed
  with it stays reproducible.

:func:`line_summary` gives what ``fdm-awe info`` shows of a line: sizing, section and the
equivalent line drag coefficient ``C_D,t = C_D_perp d l / (4 S)``
(:func:`fdm_awe.pointmass.aero.tether_drag_coefficient`) at the shortest and longest working line length.

SI throughout (kg/m, m, N, N m/kg for the specific strengths: 1 N/tex = 1e6 N m/kg).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Sequence

from ..definitions.aircraft import load_airframe
from ..errors import InputError
from ..pointmass.aero import tether_drag_coefficient

if TYPE_CHECKING:  # pragma: no cover - typing only (definitions imports this module)
    from .definitions import GroundStationParams, TetherParams

#: the optimiser's models of the line force on the glider (``CycleProblem.line_model``):
#: ``straight``, the straight line's shares (the glider carries 1/4 of the drag of the whole
#: line moving like it, from its own air velocity, and 1/2 of the line's weight: the ground
#: station's straight line); ``calibrated``, the shares fitted to flights on the lumped line,
#: with the share of the drag of the still line in the wind that the straight line leaves out
#: (``tether/calibrated`` of the ground-station definition, its provenance there)
LINE_MODELS = ("straight", "calibrated")
#: the glider's share of the line drag in the straight line model (the ``4`` of ``C_D,t``)
STRAIGHT_DRAG_SHARE = 0.25

#: line names a ground-station definition holds and a caller may select
LINES = ("sized", "paper")
#: the line of :func:`fdm_awe.groundstation.load_ground_station` when none is named
DEFAULT_LINE = "sized"
#: kg/m per tex (1 tex = 1 g per km of line)
TEX = 1e-6
#: N m/kg per N/tex (specific strength and modulus: 1 N/tex = 1 N / TEX)
N_PER_TEX = 1e6


def check_line_model(model: object, what: str = "line_model") -> str:
    """``model`` if it names a line model of :data:`LINE_MODELS`, else a one-line
    :class:`~fdm_awe.errors.InputError` naming the field ``what`` and the allowed names."""
    if not isinstance(model, str) or model not in LINE_MODELS:
        raise InputError(f"{what} {model!r} unknown (allowed: {', '.join(LINE_MODELS)})")
    return model


def check_line(line: object, what: str = "line") -> str:
    """``line`` if it names a line of :data:`LINES`, else a one-line
    :class:`~fdm_awe.errors.InputError` naming the field ``what`` and the allowed names."""
    if not isinstance(line, str) or line not in LINES:
        raise InputError(f"{what} {line!r} unknown (allowed: {', '.join(LINES)})")
    return line


@dataclass(frozen=True)
class LineMaterial:
    """What the line is made of (SI)."""

    fibre_density: float  #: rho_f of the fibre, kg/m^3
    rated_tenacity: float  #: rated breaking force per linear density of the braid, N m/kg (1 N/tex = 1e6)
    fill_factor: float  #: fibre cross-section / round envelope of the braid, -
    fibre_modulus: float  #: specific modulus of the fibre, N m/kg (1 N/tex = 1e6)
    stiffness_factor: float  #: braid's effective modulus / fibre modulus, -
    cd_perpendicular: float  #: C_D of the line in cross flow, -


@dataclass(frozen=True)
class LineSizing:
    """What the line must carry (SI)."""

    rated_tension: float  #: working tension the line is rated for, N
    safety_factor: float  #: breaking load / rated tension, -


@dataclass(frozen=True)
class LineSection:
    """The line's numbers the tether model uses (SI)."""

    mass_per_length: float  #: mu, kg/m
    diameter: float  #: d_t, m
    axial_stiffness: float  #: EA, N
    breaking_load: float  #: F_b, N
    cd_perpendicular: float  #: C_D of the line in cross flow, -


def size_line(material: LineMaterial, sizing: LineSizing) -> LineSection:
    """The section of a line of ``material`` sized for ``sizing`` (see the module docstring).

    Breaking load ``SF T_rated`` [N]; mass per length ``F_b / tenacity`` [kg/m]; diameter of the
    round envelope ``sqrt(4 mu / (pi rho_f phi))`` [m]; ``EA = k_braid E_f mu`` [N].
    """
    breaking = sizing.safety_factor * sizing.rated_tension
    mu = breaking / material.rated_tenacity
    envelope = mu / (material.fibre_density * material.fill_factor)
    return LineSection(
        mass_per_length=mu,
        diameter=math.sqrt(4.0 * envelope / math.pi),
        axial_stiffness=material.stiffness_factor * material.fibre_modulus * mu,
        breaking_load=breaking,
        cd_perpendicular=material.cd_perpendicular,
    )


@dataclass(frozen=True)
class LineSummary:
    """A line as ``fdm-awe info`` shows it (SI). Drag numbers per entry of ``lengths_m``."""

    name: str  #: line name (:data:`LINES`)
    rated_tension: float | None  #: N
    safety_factor: float | None  #: breaking load / rated tension, -
    breaking_load: float  #: N
    diameter: float  #: m
    mass_per_length: float  #: kg/m
    axial_stiffness: float  #: EA, N
    cd_perpendicular: float  #: -
    wing_area: float  #: S of the unfolded glider, m^2
    lengths_m: tuple[float, ...]  #: line lengths l, m
    #: equivalent drag area on the glider C_D_perp d l / 4 = C_D,t S, m^2
    drag_area_m2: tuple[float, ...]
    cd_t: tuple[float, ...]  #: equivalent line drag coefficient C_D,t on S, -

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready record (units in the keys)."""
        return {
            "name": self.name, "rated_tension_N": self.rated_tension, "safety_factor": self.safety_factor,
            "breaking_load_N": self.breaking_load, "diameter_m": self.diameter,
            "mass_per_length_kg_per_m": self.mass_per_length, "axial_stiffness_N": self.axial_stiffness,
            "cd_perpendicular": self.cd_perpendicular, "wing_area_m2": self.wing_area,
            "lengths_m": list(self.lengths_m), "drag_area_m2": list(self.drag_area_m2), "cd_t": list(self.cd_t),
        }

    def text(self) -> str:
        """One line of text (mm, g/m, kN for reading)."""
        rated = "rated tension -" if self.rated_tension is None else (
            f"rated {self.rated_tension:g} N x SF {self.safety_factor:.3g}")
        drag = ", ".join(f"{l:g} m: C_D,t {c:.3f} (drag area {a:.4f} m2)"
                         for l, c, a in zip(self.lengths_m, self.cd_t, self.drag_area_m2))
        return (f"line {self.name}: {rated} = breaking load {self.breaking_load:.0f} N, d {self.diameter * 1e3:.3f} mm, "
                f"{self.mass_per_length * 1e3:.4g} g/m, EA {self.axial_stiffness / 1e3:.3g} kN, "
                f"C_D_perp {self.cd_perpendicular:g}; on S {self.wing_area:g} m2 at {drag}")


def line_summary(params: "GroundStationParams | TetherParams", lengths: Sequence[float],
                 wing_area: float | None = None) -> LineSummary:
    """Sizing, section and equivalent drag of the line in ``params`` (ground-station or tether
    parameters).

    ``lengths`` m (``fdm-awe info``: :func:`fdm_awe.ocp.problem.working_lengths`, the optimiser's
    d0 and d_tf);
    ``wing_area`` m^2 (default: S of the unfolded glider's aircraft definition).
    """
    t = getattr(params, "tether", params)
    ls = tuple(float(v) for v in lengths)
    for v in ls:
        if not (math.isfinite(v) and v > 0.0):
            raise InputError(f"line length {v!r} m out of range (allowed > 0)")
    if wing_area is None:
        wing_area = load_airframe("unfolded").aero.S
    if not (math.isfinite(wing_area) and wing_area > 0.0):
        raise InputError(f"wing area {wing_area!r} m2 out of range (allowed > 0)")
    cdt = tuple(float(tether_drag_coefficient(v, t.diameter, t.cd_perpendicular, wing_area)) for v in ls)
    return LineSummary(
        name=t.name, rated_tension=t.rated_tension, safety_factor=t.safety_factor,
        breaking_load=t.breaking_load, diameter=t.diameter, mass_per_length=t.mass_per_length,
        axial_stiffness=t.axial_stiffness, cd_perpendicular=t.cd_perpendicular, wing_area=float(wing_area),
        lengths_m=ls, drag_area_m2=tuple(c * wing_area for c in cdt), cd_t=cdt,
    )
