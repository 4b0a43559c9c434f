"""PI speed controller of the T1 duty (reel-in phase), with duty limits and anti-windup.

``duty = clip(Kp e + x_I, d_min, d_max)`` with the speed error ``e = omega - omega_ref``
(rad/s; a larger duty pulls harder in the reel-in direction, so a drum turning slower in the
reel-in sense than commanded has e > 0). The integrator ``x_I`` (duty) integrates ``Ki e``
(forward Euler at the ground station's sub-step) only while that does not push further into a
saturated limit (conditional integration) and is itself kept inside the duty limits.
Gains and limits come from the definition file (``speed_controller``).
"""

from __future__ import annotations

from .definitions import SpeedControllerParams


def pi_update(c: SpeedControllerParams, err: float, integ: float, h: float) -> tuple[float, float]:
    """One controller sample: returns ``(duty, new integrator state)``."""
    u = c.kp * err + integ
    if u > c.duty_max:
        duty, hold = c.duty_max, err > 0.0
    elif u < c.duty_min:
        duty, hold = c.duty_min, err < 0.0
    else:
        duty, hold = u, False
    if not hold:
        integ += c.ki * err * h
        if integ > c.duty_max:
            integ = c.duty_max
        elif integ < c.duty_min:
            integ = c.duty_min
    return duty, integ
