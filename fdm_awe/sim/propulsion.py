"""What a flight logs as the glider's propulsion, one rule for the flight's log and the live view.

The physical plant logs the propeller's thrust and the motor's electrical input (JSBSim:
throttle x battery voltage x current) plus the constant draw ``P0`` (ESC and avionics) that the
optimiser's propulsion model books, so that flight and optimiser count the same consumers. The
paper plant logs its ideal thruster: the commanded thrust and the power the paper's P(T) fit
books for it (:class:`fdm_awe.sim.paper_plant.IdealThruster`).
"""

from __future__ import annotations

from typing import Any


def logged_propulsion(thrust_N: Any, motor_power_W: Any, P0: float,
                      thruster: Any = None, ideal_thrust_N: Any = None) -> tuple[Any, Any]:
    """``(thrust N, power W)`` logged for a step (scalars) or a series (arrays): the ideal
    thruster's at ``ideal_thrust_N`` (default its current thrust) when ``thruster`` is given,
    else the propeller's thrust and the motor's input plus ``P0``."""
    if thruster is None:
        return thrust_N, motor_power_W + P0
    if ideal_thrust_N is None:
        return thruster.thrust, thruster.power()
    return ideal_thrust_N, thruster.power(ideal_thrust_N)  # the fit is a polynomial: arrays too
