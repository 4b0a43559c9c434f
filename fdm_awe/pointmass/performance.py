"""Closed-form performance references: steady glide, Loyd's crosswind limit, quasi-steady
reel-out power. They are independent of the optimiser and serve as checks and plot overlays.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from scipy.optimize import brentq

from ..constants import G0, RHO0
from .aero import drag_coefficient, lift_coefficient
from ..definitions.aircraft import AeroParams


@dataclass(frozen=True)
class SteadyGlide:
    """Unpowered, untethered steady glide at best L/D in still air."""

    alpha: float  #: angle of attack [rad]
    CL: float
    CD: float
    L_over_D: float
    V: float  #: airspeed [m/s]
    gamma: float  #: flight-path angle [rad] (negative = descending)

    @property
    def sink_rate(self) -> float:
        """Sink rate [m/s] (positive down)."""
        return -self.V * math.sin(self.gamma)


def best_glide_alpha(aero: AeroParams) -> float:
    """Angle of attack [rad] of maximum C_L/C_D for the polynomial polar.

    Solves ``C_La C_D - C_L dC_D/dalpha = 0`` on (-alpha_0L, alpha at CLmax].
    """
    def g(a: float) -> float:
        return aero.CLalpha * drag_coefficient(a, aero) - lift_coefficient(a, aero) * (aero.CDalpha1 + 2 * aero.CDalpha2 * a)

    a0 = -aero.CL0 / aero.CLalpha + 1e-9
    return brentq(g, a0, max(aero.alpha_max_lift, a0 + 1.0), xtol=1e-14)


def steady_glide(aero: AeroParams, mass: float, rho: float = RHO0, g: float = G0, alpha: float | None = None) -> SteadyGlide:
    """Steady straight glide at ``alpha`` (default: best L/D): ``tan gamma = -D/L``,
    ``V^2 = 2 m g cos gamma / (rho S C_L)``."""
    a = best_glide_alpha(aero) if alpha is None else alpha
    CL, CD = lift_coefficient(a, aero), drag_coefficient(a, aero)
    gamma = -math.atan2(CD, CL)
    V = math.sqrt(2 * mass * g * math.cos(gamma) / (rho * aero.S * CL))
    return SteadyGlide(a, CL, CD, CL / CD, V, gamma)


def loyd_power(rho: float, S: float, v_wind: float, CL: float, CD: float) -> float:
    """Loyd's crosswind limit [W]: ``P = (2/27) rho S v_w^3 C_R^3 / C_D^2``, C_R = |(C_L, C_D)|.

    ``CD`` should include the tether's equivalent drag for a tethered system.
    """
    CR = math.hypot(CL, CD)
    return 2.0 / 27.0 * rho * S * v_wind**3 * CR**3 / CD**2


def quasi_steady_reel_out(
    rho: float, S: float, v_wind: float, CL: float, CD: float, elevation: float, azimuth: float, f: float | None = None
) -> tuple[float, float, float]:
    """Quasi-steady reel-out (Schmehl et al.): tension ``F = q S C_R (1 + (L/D)^2)
    (cos b cos p - f)^2`` and power ``P = F f v_w``, with ``q = rho v_w^2 / 2``.

    ``f`` is the reel-out factor v_reel / v_w; by default the optimum ``cos b cos p / 3``.
    Returns (tension [N], power [W], f).
    """
    c = math.cos(elevation) * math.cos(azimuth)
    if f is None:
        f = c / 3.0
    CR = math.hypot(CL, CD)
    q = 0.5 * rho * v_wind**2
    F = q * S * CR * (1 + (CL / CD) ** 2) * (c - f) ** 2
    return F, F * f * v_wind, f
