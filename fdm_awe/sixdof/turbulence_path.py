"""JSBSim's turbulence sampled along a held path: the glider's state frozen at one height and one
ground velocity while JSBSim's atmosphere steps on.

A flight records a few minutes of turbulence, whose longitudinal correlation time ``L_u / V``
(13 s at 100 m and 20 m/s) leaves its sigma uncertain by about ``sqrt(L_u / (2 V T))`` (10 % over
10 minutes). To check the turbulence a form sets against its target over hours of simulated air
in seconds of wall time, :func:`sample_turbulence` runs JSBSim with its integrators switched off
(``simulation/integrator/*`` = 0): the aircraft keeps its position, attitude and ground velocity,
and every step runs the whole model, turbulence included (``FGWinds::Turbulence`` at the
aircraft's height with its airspeed, the flight's inputs), as in a flight at constant height
crosswind to the wind.
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
                      dt: float = 1.0 / 120.0, heading: float = math.pi / 2) -> tuple[np.ndarray, np.ndarray]:
    """The total wind [m/s] (n, 3) NED at the glider held at ``height`` [m] with air velocity
    ``airspeed`` [m/s] on ``heading`` [rad] (default east, crosswind to a wind from the south)
    in the steady wind ``wind_ned`` [m/s] and ``turbulence`` (a
    :class:`~fdm_awe.turbulence.TurbulenceSetting` or a named level's ``(level, seed)``), every
    ``dt`` [s] for ``duration`` [s]; and the times [s] (n,)."""
    g = JSBSimGlider("glider_foldable", dt=dt, wind_ned=wind_ned, turbulence=turbulence)
    g.reset((0.0, 0.0, -float(height)), float(airspeed), psi=float(heading))
    f = g.fdm
    for p in _INTEGRATORS:
        f[p] = 0
    pm = f.get_property_manager()
    get = [pm.get_node(p, False).get_double_value for p in _WIND]
    gn, ge, gd = get
    run = f.run
    n = int(round(duration / dt))
    out = np.empty((n, 3))
    for k in range(n):
        run()
        out[k] = (gn(), ge(), gd())
    return (np.arange(1, n + 1) * dt, out * FT)


__all__ = ["sample_turbulence"]
