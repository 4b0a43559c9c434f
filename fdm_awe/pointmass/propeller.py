"""Electrical power the glider's propeller drive draws for a thrust (paper eq. 39, corrected).

``physical``: momentum theory with airspeed, ``P = P0 + T (V + v_i) / (eta_prop eta_motor)``,
``v_i = -V/2 + sqrt(V^2/4 + T / (2 rho A_p))``: useful power T V plus induced power T v_i, over
propeller and motor efficiencies, plus a constant avionics/ESC draw. It never lets T V exceed
the electrical power.

``paper``: the paper's static fit ``P = PT0 + PT1 T + PT2 T^2`` (no airspeed dependence). At
airspeeds above a few m/s it delivers T V > P, i.e. a propeller more than 100 % efficient.

``engine``: the 6-DOF glider's own drive (:mod:`fdm_awe.definitions.engine`: the 9x5 propeller's
C_T(J), C_P(J) and the brushless motor of the JSBSim engine files) in closed form, the motor
running: the propeller speed n that gives T at V (C_T quadratic in J = V/(n D)), its shaft
power C_P rho n^3 D^5, the motor current I = Q/K_t + I0 and voltage U = I R + 60 n/Kv, and
P = P0 + U I. At T = 0 the propeller turns at its zero-thrust advance ratio and still draws
power (about 10 W at 13 m/s): that is how the autopilot flies zero thrust.
"""

from __future__ import annotations

import math
from typing import Any

from . import mathops as mo
from ..definitions.aircraft import PropulsionParams
from ..definitions.engine import ElectricDrive

SCENARIOS = ("physical", "paper")
MODELS = ("physical", "paper", "engine")


def induced_velocity(T: Any, V: Any, rho: float, disk_area: float) -> Any:
    """Momentum-theory induced velocity [m/s] at thrust ``T`` [N] and airspeed ``V`` [m/s]."""
    return -0.5 * V + mo.sqrt(0.25 * V * V + T / (2.0 * rho * disk_area))


def power_physical(T: Any, V: Any, p: PropulsionParams, rho: float) -> Any:
    """Electrical power [W] for thrust ``T`` [N] at airspeed ``V`` [m/s]."""
    vi = induced_velocity(T, V, rho, p.disk_area)
    return p.P0 + T * (V + vi) / (p.eta_prop * p.eta_motor)


def engine_speed(T: Any, V: Any, e: ElectricDrive, rho: float) -> Any:
    """Propeller speed n [rev/s] that gives thrust ``T`` >= 0 [N] at airspeed ``V`` [m/s]:
    ``T = rho n^2 D^4 C_T(V / (n D))`` solved for n (the root with J below zero thrust)."""
    c0, c1, c2 = e.ct
    D = e.diameter
    b = c1 * V / D
    c = c2 * V * V / (D * D) - T / (rho * D**4)
    return (-b + mo.sqrt(b * b - 4.0 * c0 * c)) / (2.0 * c0)


def engine_operating_point(T: Any, V: Any, e: ElectricDrive, rho: float) -> dict[str, Any]:
    """The drive at thrust ``T`` [N] and airspeed ``V`` [m/s], motor running: ``n`` rev/s,
    ``J``, ``shaft_power`` W, ``current`` A, ``voltage`` V (the throttle is voltage / max_volts),
    ``power`` W electrical (without P0)."""
    n = engine_speed(T, V, e, rho)
    D = e.diameter
    J = V / (n * D)
    c0, c1, c2 = e.cp
    p_shaft = (c0 + c1 * J + c2 * J * J) * rho * n**3 * D**5
    torque = p_shaft / (2.0 * math.pi * n)
    current = torque / e.torque_constant + e.no_load_current
    voltage = current * e.resistance + 60.0 * n / e.kv
    return {"n": n, "J": J, "shaft_power": p_shaft, "current": current, "voltage": voltage,
            "power": voltage * current}


def power_engine(T: Any, V: Any, p: PropulsionParams, e: ElectricDrive, rho: float) -> Any:
    """Electrical power [W] of the 6-DOF glider's drive for thrust ``T`` >= 0 [N] at airspeed
    ``V`` [m/s], motor running, plus the constant draw ``P0``."""
    return p.P0 + engine_operating_point(T, V, e, rho)["power"]


def power_paper(T: Any, p: PropulsionParams) -> Any:
    """The paper's static quadratic P(T) [W] (eq. 39)."""
    return p.PT0 + p.PT1 * T + p.PT2 * T * T


def power(T: Any, V: Any, p: PropulsionParams, rho: float, scenario: str = "physical",
          drive: ElectricDrive | None = None) -> Any:
    """Propeller drive power [W] of the named model (``physical``, ``paper`` or ``engine``;
    ``engine`` needs ``drive``)."""
    if scenario == "physical":
        return power_physical(T, V, p, rho)
    if scenario == "paper":
        return power_paper(T, p)
    if scenario == "engine":
        if drive is None:
            raise ValueError("propeller model 'engine' needs the electric drive (definitions.engine)")
        return power_engine(T, V, p, drive, rho)
    raise ValueError(f"propeller scenario {scenario!r} unknown (allowed: {', '.join(MODELS)})")
