"""Aerodynamic coefficients and forces of one configuration (paper eqs. 32/33, 46/47).

Forces use the airspeed V of the air-relative state (the paper's ``V_r = V - V_w`` would count
the wind twice, docs/design.md section 4.3).
"""

from __future__ import annotations

from dataclasses import fields
from typing import Any

from ..definitions.aircraft import AeroParams

#: Polar coefficients that scale with the wing area when the morphing wing blends its two forms
#: (every :class:`AeroParams` field except the geometry S, b, c).
POLAR_FIELDS = tuple(f.name for f in fields(AeroParams) if f.name not in ("S", "b", "c"))


def lift_coefficient(alpha: Any, aero: AeroParams) -> Any:
    """C_L = C_L0 + C_La alpha (linear; the optimiser bounds it by ``CLmax``)."""
    return aero.CL0 + aero.CLalpha * alpha


def drag_coefficient(alpha: Any, aero: AeroParams) -> Any:
    """C_D = C_D0 + C_Da1 alpha + C_Da2 alpha^2."""
    return aero.CD0 + aero.CDalpha1 * alpha + aero.CDalpha2 * alpha * alpha


def lift_drag(V: Any, alpha: Any, aero: AeroParams, rho: float, cd_extra: Any = 0.0) -> tuple[Any, Any]:
    """Lift and drag [N] at airspeed ``V`` [m/s] and angle of attack ``alpha`` [rad].

    ``cd_extra`` is an additional drag coefficient on the same reference area (e.g. the
    equivalent tether drag, :func:`tether_drag_coefficient`).
    """
    q_s = 0.5 * rho * V * V * aero.S
    return q_s * lift_coefficient(alpha, aero), q_s * (drag_coefficient(alpha, aero) + cd_extra)


def blend_coefficient(unfolded: Any, folded: Any, ratio: Any, fold: Any) -> Any:
    """One coefficient of the morphing wing at fold state ``fold`` (0 unfolded .. 1 folded) on
    the unfolded reference area: ``(1 - f) C_unfolded + f C_folded S_ratio`` (``ratio`` the
    area ratio S_folded / S_unfolded [-]), the relation of :func:`fold_blend`. Plain arithmetic:
    works on floats, CasADi symbols and inside code compiled by numba."""
    return (1 - fold) * unfolded + fold * folded * ratio


def fold_blend(unfolded: AeroParams, folded: AeroParams, fold: Any) -> AeroParams:
    """The morphing wing at fold state ``fold`` (0 unfolded .. 1 folded) as the 6-DOF model
    flies it (``aircraft/glider_foldable``: ``C = (1 - f) C_unfolded + f C_folded S_ratio`` on
    the unfolded reference area, ``S_ratio = S_folded / S_unfolded``, the file's
    ``aero/fold/S-ratio``): each force coefficient times area is linear in ``fold``, lift
    slope, ``CLmax`` and the drag polar alike. Geometry S, b, c stay the unfolded form's.

    Works on floats and CasADi symbols (``folded`` may itself be a blend, e.g. a homotopy).
    At ``fold`` 1 the forces equal the folded form's (the same products ``C S``).
    """
    ratio = folded.S / unfolded.S
    vals = {k: blend_coefficient(getattr(unfolded, k), getattr(folded, k), ratio, fold) for k in POLAR_FIELDS}
    return AeroParams(S=unfolded.S, b=unfolded.b, c=unfolded.c, **vals)


def tether_drag_coefficient(length: Any, diameter: float, cd_perp: float, S: float) -> Any:
    """Equivalent tether drag coefficient on the wing area: ``C_D,t = C_D_perp d l / (4 S)``.

    A straight line whose normal velocity grows linearly from winch to glider produces a drag
    whose moment about the winch equals that of a quarter of its drag applied at the glider.
    """
    return cd_perp * diameter * length / (4.0 * S)
