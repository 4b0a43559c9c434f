"""JSBSim's turbulence sampled along a held path: the glider's state frozen at one height and one
ground velocity while JSBSim's atmosphere steps on.

A flight records a few minutes of turbulence, whose longitudinal correlation time ``L_u / V``
(13 s at 100 m and 20 m/s) leaves its sigma uncertain by about ``sqrt(L_u / (2 V T))`` (10 % over
10 minutes). To check the turbulence a form sets against its target over hours of simulated air
in seconds of wall time, :func:`sample_turbulence` runs JSBSim with its integrators switched off
(``simulation/integrator/*`` = 0): the aircraft keeps its position, attitude and ground velocity,
and every step runs the whole model, turbulence included (``FGWinds::Turbulence`` at the
aircraft's height with its airspeed, the flight's inputs), as in a flight at constant height
crosswind to the wind, or downwind with the wind's speed, and so the airspeed, swinging.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from ..units import FT
from .adapter import JSBSimGlider

#: JSBSim's integrator choices; 0 = none (the state holds)
_INTEGRATORS = ("simulation/integrator/rate/rotational", "simulation/integrator/rate/translational",
                "simulation/integrator/position/rotational", "simulation/integrator/position/translational")
_WIND = ("atmosphere/total-wind-north-fps", "atmosphere/total-wind-east-fps", "atmosphere/total-wind-down-fps")


def sample_turbulence(turbulence, wind_ned: Sequence[float], height: float, airspeed: float, duration: float,
                      dt: float = 1.0 / 120.0, heading: float = math.pi / 2,
                      swing: tuple[float, float] | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The total wind [m/s] (n, 3) NED at the glider held at ``height`` [m] with air velocity
    ``airspeed`` [m/s] on ``heading`` [rad] (default east, crosswind to a wind from the south)
    in the steady wind ``wind_ned`` [m/s] and ``turbulence`` (a
    :class:`~fdm_awe.turbulence.TurbulenceSetting` or a named level's ``(level, seed)``), every
    ``dt`` [s] for ``duration`` [s]; the times [s] (n,) and the steady wind of each step (n, 3).

    ``swing = (amplitude, period)`` [m/s, s]: the glider flies downwind instead (heading along
    the wind) and the steady wind's speed swings by ``amplitude sin(2 pi t / period)``, so its
    airspeed swings by the same amount against it while the wind keeps its direction (the
    turbulence's axes stay put): the airspeed changes of a pumping cycle."""
    w0 = np.asarray(wind_ned, float)
    if swing is not None:
        heading = math.atan2(w0[1], w0[0])
    g = JSBSimGlider(dt=dt, wind_ned=tuple(w0), turbulence=turbulence)  # the package's glider: the wind it meets
    g.reset((0.0, 0.0, -float(height)), float(airspeed), psi=float(heading))
    f = g.fdm
    for p in _INTEGRATORS:
        f[p] = 0
    pm = f.get_property_manager()
    gn, ge, gd = (pm.get_node(p, False).get_double_value for p in _WIND)
    run = f.run
    n = int(round(duration / dt))
    out = np.empty((n, 3))
    steady = np.tile(w0, (n, 1))
    if swing is not None:
        amp, period = float(swing[0]), float(swing[1])
        speed = float(np.hypot(w0[0], w0[1]))
        unit = w0 / speed if speed > 0 else np.array([1.0, 0.0, 0.0])
        s = speed + amp * np.sin(2.0 * math.pi * np.arange(n) * dt / period)
        steady = np.outer(s, unit)
        sn, se = pm.get_node("atmosphere/wind-north-fps", False).set_double_value, \
            pm.get_node("atmosphere/wind-east-fps", False).set_double_value
        for k in range(n):
            sn(steady[k, 0] / FT)
            se(steady[k, 1] / FT)
            run()
            out[k] = (gn(), ge(), gd())
    else:
        for k in range(n):
            run()
            out[k] = (gn(), ge(), gd())
    return np.arange(1, n + 1) * dt, out * FT, steady


__all__ = ["sample_turbulence"]
