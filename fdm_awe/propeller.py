"""Electrical power the glider's propeller drive draws for a thrust (paper eq. 39, corrected).

``physical``: momentum theory with airspeed, ``P = P0 + T (V + v_i) / (eta_prop eta_motor)``,
``v_i = -V/2 + sqrt(V^2/4 + T / (2 rho A_p))``: useful power T V plus induced power T v_i, over
propeller and motor efficiencies, plus a constant avionics/ESC draw. It never lets T V exceed
the electrical power.

``paper``: the paper's static fit ``P = PT0 + PT1 T + PT2 T^2`` (no airspeed dependence). At
airspeeds above a few m/s it delivers T V > P, i.e. a propeller more than 100 % efficient.
"""

from __future__ import annotations

from typing import Any

from . import mathops as mo
from .definitions.aircraft import PropulsionParams

SCENARIOS = ("physical", "paper")


def induced_velocity(T: Any, V: Any, rho: float, disk_area: float) -> Any:
    """Momentum-theory induced velocity [m/s] at thrust ``T`` [N] and airspeed ``V`` [m/s]."""
    return -0.5 * V + mo.sqrt(0.25 * V * V + T / (2.0 * rho * disk_area))


def power_physical(T: Any, V: Any, p: PropulsionParams, rho: float) -> Any:
    """Electrical power [W] for thrust ``T`` [N] at airspeed ``V`` [m/s]."""
    vi = induced_velocity(T, V, rho, p.disk_area)
    return p.P0 + T * (V + vi) / (p.eta_prop * p.eta_motor)


def power_paper(T: Any, p: PropulsionParams) -> Any:
    """The paper's static quadratic P(T) [W] (eq. 39)."""
    return p.PT0 + p.PT1 * T + p.PT2 * T * T


def power(T: Any, V: Any, p: PropulsionParams, rho: float, scenario: str = "physical") -> Any:
    """Propeller drive power [W] in the named scenario (``physical`` or ``paper``)."""
    if scenario == "physical":
        return power_physical(T, V, p, rho)
    if scenario == "paper":
        return power_paper(T, p)
    raise ValueError(f"scenario {scenario!r} unknown (allowed: {', '.join(SCENARIOS)})")
