"""Reference power curves for the same airframe and tether: Loyd's limit and quasi-steady reel-out.

Both are closed-form *reel-out* powers (mechanical, no cycle, no losses), upper references for
the optimised cycle-average net power, evaluated with :func:`fdm_awe.pointmass.performance.loyd_power`
and :func:`fdm_awe.pointmass.performance.quasi_steady_reel_out`:

- Loyd: ``P = (2/27) rho S v_w^3 C_R^3 / C_D^2``;
- quasi-steady (Schmehl et al.): ``F = q S C_R (1 + (L/D)^2) (cos(beta) cos(phi) - f)^2``,
  ``P = F f v_w`` at the optimal reel-out factor ``f = cos(beta) cos(phi) / 3``, with the
  elevation ``beta`` and azimuth ``phi`` of the cycle's start point.

``C_D`` includes the tether's equivalent drag ``C_D,t = C_D_perp d_t l / (4 S)``
(:func:`fdm_awe.pointmass.aero.tether_drag_coefficient`) at the mean reel-out length
``l = (d0 + d_tf) / 2``; the angle of attack maximises ``C_R^3 / C_D^2`` below stall
(``C_L <= C_Lmax``). Units: SI, angles in radians unless named ``_deg``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
from scipy.optimize import minimize_scalar

from ..constants import RHO0
from ..pointmass.aero import drag_coefficient, lift_coefficient, tether_drag_coefficient
from ..definitions.aircraft import AeroParams
from ..pointmass.performance import loyd_power, quasi_steady_reel_out

#: sea-level air density [kg/m^3], the optimiser's value
RHO = RHO0


@dataclass(frozen=True)
class ReferenceCurves:
    """Loyd and quasi-steady reel-out power [W] over ``winds`` [m/s] at one operating point."""

    winds: np.ndarray
    loyd_W: np.ndarray
    quasi_steady_W: np.ndarray
    alpha: float  #: angle of attack used [rad]
    CL: float
    CD: float  #: glider + tether drag coefficient
    CD_tether: float
    tether_length: float  #: [m]
    elevation: float  #: [rad]
    azimuth: float  #: [rad]
    reel_out_factor: float  #: f = v_reel / v_w
    tether_diameter: float = math.nan  #: [m]


def best_loyd_alpha(aero: AeroParams, cd_extra: float) -> float:
    """Angle of attack [rad] maximising ``C_R^3 / C_D^2`` with ``C_D = C_D(alpha) + cd_extra``,
    between zero lift and ``C_Lmax``."""
    lo = -aero.CL0 / aero.CLalpha
    hi = aero.alpha_max_lift

    def neg(a: float) -> float:
        cl, cd = lift_coefficient(a, aero), drag_coefficient(a, aero) + cd_extra
        return -(math.hypot(cl, cd) ** 3) / cd**2

    r = minimize_scalar(neg, bounds=(lo, hi), method="bounded", options={"xatol": 1e-10})
    # the optimum often sits on the stall bound: compare with the end point explicitly
    return hi if neg(hi) <= r.fun else float(r.x)


def reference_curves(winds: Sequence[float], aero: AeroParams, tether_diameter: float, tether_cd_perp: float,
                     d0: float, d_tf: float, elevation_deg: float = 30.0, azimuth_deg: float = 0.0,
                     rho: float = RHO) -> ReferenceCurves:
    """Loyd and quasi-steady curves for the wing ``aero`` on the given tether (see module docstring)."""
    length = 0.5 * (d0 + d_tf)
    cdt = float(tether_drag_coefficient(length, tether_diameter, tether_cd_perp, aero.S))
    a = best_loyd_alpha(aero, cdt)
    CL = float(lift_coefficient(a, aero))
    CD = float(drag_coefficient(a, aero)) + cdt
    el, az = math.radians(elevation_deg), math.radians(azimuth_deg)
    v = np.asarray(winds, float)
    loyd = np.array([loyd_power(rho, aero.S, w, CL, CD) for w in v])
    qs = np.array([quasi_steady_reel_out(rho, aero.S, w, CL, CD, el, az)[1] for w in v])
    f = quasi_steady_reel_out(rho, aero.S, 1.0, CL, CD, el, az)[2]
    return ReferenceCurves(v, loyd, qs, a, CL, CD, cdt, length, el, az, f, float(tether_diameter))


def tether_properties(line: str = "sized", diameter: float | None = None, station: Any = None) -> tuple[float, float]:
    """Tether diameter [m] and normal drag coefficient of the ground-station definition's line
    ``line`` (:data:`fdm_awe.groundstation.line.LINES`), the sized line resized to ``diameter``
    [m] when given (:func:`fdm_awe.sweep.design.line_station`; ``station`` the definition, None:
    the package's): the line a sweep point optimises with."""
    from .design import line_station

    t = line_station(line, diameter, station).tether
    return float(t.diameter), float(t.cd_perpendicular)
