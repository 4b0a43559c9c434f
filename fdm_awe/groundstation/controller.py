"""PI speed controller of the T1 duty (reel-in phase), with duty limits and anti-windup.

``duty = clip(Kp e + x_I, d_min, d_max)`` with the speed error ``e = omega - omega_ref``
(rad/s; a larger duty pulls harder in the reel-in direction, so a drum turning slower in the
reel-in sense than commanded has e > 0). The integrator ``x_I`` (duty) integrates ``Ki e``
(forward Euler at the ground station's sub-step) only while that does not push further into a
saturated limit (conditional integration) and is itself kept inside the duty limits. The
converter's current limit lowers the duty below the PI's output (:func:`.substeps.hold_current`):
in a sub-step where it does, the integrator keeps its value while the error would raise it
further (the same conditional integration, decided after the sub-step's current is known).
Gains and limits come from the definition file (``speed_controller``). The law is
:func:`fdm_awe.groundstation.substeps.pi_step` (the ground station's step calls it there).
"""

from __future__ import annotations

from .definitions import SpeedControllerParams
from .substeps import pi_step


def pi_update(c: SpeedControllerParams, err: float, integ: float, h: float) -> tuple[float, float]:
    """One controller sample (speed error ``err`` rad/s, sample ``h`` s): returns ``(duty, new
    integrator state)`` (:func:`.substeps.pi_step` with the gains and limits of ``c``)."""
    return pi_step(c.kp, c.ki, c.duty_min, c.duty_max, err, integ, h)
