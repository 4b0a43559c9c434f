"""Design variants of the glider for sweeps, derived from the aircraft definitions.

The definitions (``aircraft/glider_unfolded``, ``aircraft/glider_folded``) stay the single
source of truth: every variant starts from :func:`fdm_awe.definitions.aircraft.load_glider`
and changes only what the swept parameter changes, with the formulas of docs/design.md section 5:

- lift slope (Helmbold): ``C_La = 2 pi A / (2 + sqrt(A^2 / 0.81 + 4))``;
- zero-lift angle ``alpha_0L`` kept: ``C_L0 = -C_La alpha_0L``;
- drag ``C_D = C_Dmin + k C_L^2``, ``k = 1 / (pi e A)``, expanded in alpha:
  ``C_D0 = C_Dmin + k C_L0^2``, ``C_Da1 = 2 k C_L0 C_La``, ``C_Da2 = k C_La^2``.

The Oswald factor ``e``, the zero-lift angle, ``C_Dmin`` (drag area ``C_Dmin S``) and ``C_Lmax``
of each configuration are recovered from its definition's coefficients
(:func:`polar_constants`), not typed in here.

Swept parameters (SI):

- ``folded_span`` ``b_f`` [m]: folded area ``S_f = b_f c`` (same chord), ``A_f = b_f / c``;
- ``folded_drag_area`` [m^2]: ``C_Dmin,f S_f`` (default: the folded definition's);
- ``wing_area`` ``S_u`` [m^2] of the unfolded wing at the definition's aspect ratio
  (``c = sqrt(S_u / A_u)``, ``b_u = A_u c``); the unfolded polar is unchanged (same aspect
  ratio), the folded wing keeps ``b_f`` and the new chord. Mass, inertia and propulsion are
  kept: a larger wing of the same weight is an optimistic simplification, stated in outputs.
- ``line_diameter`` ``d`` [m] of the ``sized`` tether line (:func:`resized_line`): the line is
  sized again from its material, for the rated tension at which the sizing function
  (:func:`fdm_awe.groundstation.line.size_line`) gives the diameter ``d``. The section is
  ``mu / (rho_f phi)`` and ``mu``, the breaking load and EA are proportional to it, so all
  three scale with ``(d / d_0)^2`` from the defined line's ``d_0``; the safety factor, the
  material (drag coefficient included) and the rated tension of the system stay.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

from ..definitions.aircraft import AeroParams, Glider
from ..errors import InputError


def helmbold_lift_slope(aspect_ratio: float) -> float:
    """Helmbold's lift-curve slope [1/rad] of a straight wing of aspect ratio ``A``."""
    A = aspect_ratio
    return 2 * math.pi * A / (2 + math.sqrt(A * A / 0.81 + 4))


@dataclass(frozen=True)
class PolarConstants:
    """Constants behind a configuration's polynomial polar (see the module docstring)."""

    alpha_0L: float  #: zero-lift angle of attack [rad]
    CD_min: float  #: minimum (zero-lift) drag coefficient [-]
    oswald: float  #: Oswald factor e [-]
    CLmax: float  #: stall lift coefficient [-]


def polar_constants(aero: AeroParams) -> PolarConstants:
    """Recover ``alpha_0L``, ``C_Dmin``, ``e``, ``C_Lmax`` from a definition's coefficients.

    ``k = C_Da2 / C_La^2``, ``e = 1 / (pi A k)``, ``C_Dmin = C_D0 - k C_L0^2``.
    """
    k = aero.CDalpha2 / aero.CLalpha**2
    return PolarConstants(alpha_0L=-aero.CL0 / aero.CLalpha, CD_min=aero.CD0 - k * aero.CL0**2,
                          oswald=1.0 / (math.pi * aero.aspect_ratio * k), CLmax=aero.CLmax)


def wing_aero(span: float, chord: float, pc: PolarConstants) -> AeroParams:
    """Aerodynamics of a rectangular wing ``span`` x ``chord`` [m] with the polar constants ``pc``."""
    S = span * chord
    A = span / chord
    CLa = helmbold_lift_slope(A)
    CL0 = -CLa * pc.alpha_0L
    k = 1.0 / (math.pi * pc.oswald * A)
    return AeroParams(S=S, b=span, c=chord, CL0=CL0, CLalpha=CLa, CLmax=pc.CLmax, CD0=pc.CD_min + k * CL0 * CL0,
                      CDalpha1=2 * k * CL0 * CLa, CDalpha2=k * CLa * CLa)


#: allowed unfolded wing areas ``S_u`` [m^2] of a design (inclusive)
WING_AREA_RANGE = (0.01, 2.0)
#: folded drag areas ``C_Dmin,f S_f`` [m^2] of a design: above 0 and below this
FOLDED_DRAG_AREA_MAX = 0.1


def unfolded_span(base: Glider, wing_area: float | None) -> float:
    """The unfolded span [m] of ``base`` with the wing area ``wing_area`` [m^2] at the
    definition's aspect ratio (``b_u = sqrt(S_u A_u)``; ``None``: the definition's span)."""
    return base.unfolded.aero.b if wing_area is None else math.sqrt(wing_area * base.unfolded.aero.aspect_ratio)


@dataclass(frozen=True)
class Design:
    """Design parameters of one sweep point; ``None`` = as in the aircraft definitions."""

    folded_span: float | None = None  #: b_f [m]
    folded_drag_area: float | None = None  #: C_Dmin,f S_f [m^2]
    wing_area: float | None = None  #: S_u [m^2]

    def validate(self, base: Glider) -> "Design":
        lo, hi = WING_AREA_RANGE
        if self.wing_area is not None and not (math.isfinite(self.wing_area) and lo <= self.wing_area <= hi):
            raise InputError(f"wing area {self.wing_area!r} m2 out of range (allowed {lo:g}..{hi:g} m2)")
        b_u = unfolded_span(base, self.wing_area)
        if self.folded_span is not None and not (math.isfinite(self.folded_span) and 0 < self.folded_span <= b_u):
            raise InputError(f"folded span {self.folded_span!r} m out of range (allowed 0 < b_f <= unfolded span {b_u:.4g} m)")
        if self.folded_drag_area is not None and not (
                math.isfinite(self.folded_drag_area) and 0 < self.folded_drag_area < FOLDED_DRAG_AREA_MAX):
            raise InputError(f"folded drag area {self.folded_drag_area!r} m2 out of range (allowed 0 < C_Dmin S_f < "
                             f"{FOLDED_DRAG_AREA_MAX:g} m2)")
        return self


def design_glider(base: Glider, design: Design) -> Glider:
    """The glider ``base`` changed by ``design`` (``base`` itself when nothing changes)."""
    design.validate(base)
    u, f = base.unfolded, base.folded
    if design.wing_area is None and design.folded_span is None and design.folded_drag_area is None:
        return base
    pu, pf = polar_constants(u.aero), polar_constants(f.aero)
    if design.wing_area is not None:
        A_u = u.aero.aspect_ratio
        c = math.sqrt(design.wing_area / A_u)
        u_aero = wing_aero(A_u * c, c, pu)
        # same aspect ratio: keep the definition's coefficients exactly, change only the geometry
        u_aero = replace(u.aero, S=u_aero.S, b=u_aero.b, c=c)
    else:
        u_aero = u.aero
        c = u.aero.c
    b_f = f.aero.b if design.folded_span is None else design.folded_span
    drag_area = pf.CD_min * f.aero.S if design.folded_drag_area is None else design.folded_drag_area
    f_aero = wing_aero(b_f, c, replace(pf, CD_min=drag_area / (b_f * c)))
    return Glider(replace(u, aero=u_aero, aircraft=u.aircraft + "-variant"),
                  replace(f, aero=f_aero, aircraft=f.aircraft + "-variant"))


def resized_line(tether: Any, diameter: float) -> Any:
    """The sized line ``tether`` (:class:`~fdm_awe.groundstation.definitions.TetherParams` with
    material and sizing) resized to ``diameter`` [m] (see the module docstring).

    Raises :class:`~fdm_awe.errors.InputError` (one line) for a line without material (a stated
    section such as Table 1's) and for a diameter whose breaking load falls below the line's
    rated tension (the line would break inside the optimiser's tension bound)."""
    from ..groundstation.line import LineSizing, size_line

    if tether.material is None or tether.sizing is None:
        raise InputError(f"line diameter: the {tether.name!r} line states its section (no material to resize it "
                         "from); only a sized line is resized")
    if not (math.isfinite(diameter) and diameter > 0.0):
        raise InputError(f"line diameter {diameter!r} m out of range (allowed > 0)")
    z = tether.sizing
    # F_b = SF T_rated, mu = F_b / tenacity and d^2 ~ mu: the diameter d asks for (d / d_0)^2 times the tension
    rated = z.rated_tension * (diameter / tether.diameter) ** 2
    sec = size_line(tether.material, LineSizing(rated_tension=rated, safety_factor=z.safety_factor))
    if sec.breaking_load < z.rated_tension:
        d_min = tether.diameter * math.sqrt(z.rated_tension / tether.breaking_load)
        raise InputError(f"line diameter {diameter * 1e3:.4g} mm out of range: breaking load {sec.breaking_load:.3g} N "
                         f"below the rated tension {z.rated_tension:g} N (allowed >= {d_min * 1e3:.3g} mm)")
    return replace(tether, mass_per_length=sec.mass_per_length, diameter=sec.diameter,
                   axial_stiffness=sec.axial_stiffness, breaking_load=sec.breaking_load,
                   sizing=LineSizing(rated_tension=rated, safety_factor=z.safety_factor))


def line_station(line: str, diameter: float | None = None, station: Any = None) -> Any:
    """Ground-station parameters with the tether line ``line`` of the definition ``station``
    (:func:`~fdm_awe.groundstation.source.resolve_ground_station`; None: the package's), the
    sized line resized to ``diameter`` [m] when given (:func:`resized_line`)."""
    from ..groundstation.source import station_params

    gs = station_params(station, line)
    return gs if diameter is None else replace(gs, tether=resized_line(gs.tether, diameter))


def describe_line(tether: Any) -> dict[str, float]:
    """Key numbers of a tether line (for tables): diameter, mass per length, breaking load."""
    return {"line_d_m": tether.diameter, "line_mu_kg_per_m": tether.mass_per_length,
            "line_breaking_load_N": tether.breaking_load}


def describe(glider: Glider) -> dict[str, float]:
    """Key numbers of a glider variant (for tables): areas, spans, aspect ratios, polars."""
    u, f = glider.unfolded.aero, glider.folded.aero
    pf = polar_constants(f)
    return {"S_u_m2": u.S, "b_u_m": u.b, "chord_m": u.c, "S_f_m2": f.S, "b_f_m": f.b, "AR_f": f.aspect_ratio,
            "CLalpha_f": f.CLalpha, "CD0_f": f.CD0, "drag_area_f_m2": pf.CD_min * f.S}
