"""The rejoin segment of AUTO: after FBWA, a restart of the cycling or a new mission, the glider
returns to its path over RJ_TIME along a reference that starts at its own position and velocity
(:class:`Rejoin`)."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .tracking import RefPoint


@dataclass(frozen=True)
class Rejoin:
    """A rejoin segment begun at time ``t0`` [s] with the glider ``dp`` [m] and ``dv`` [m/s] off
    the path's point (position and velocity, NED)."""

    t0: float
    dp: np.ndarray
    dv: np.ndarray

    def point(self, r: RefPoint, t: float, T: float) -> RefPoint | None:
        """The reference point at time ``t`` [s] of a segment lasting ``T`` [s] (RJ_TIME): the
        path's point ``r`` plus an offset that starts at (dp, dv) and vanishes with its first
        two derivatives after ``T``: (1 - w(tau)) dp + e(t) dv, w the quintic smoothstep,
        e = (t - t0) (1 - tau)^3. None once the segment is over (the path's point itself)."""
        t0, dp, dv = self.t0, self.dp, self.dv
        tau = (t - t0) / T if T > 0.0 else 1.0
        if tau >= 1.0:
            return None
        w = tau ** 3 * (10.0 - 15.0 * tau + 6.0 * tau * tau)
        w1 = 30.0 * tau * tau * (1.0 - tau) ** 2 / T
        w2 = 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau) / (T * T)
        e = (t - t0) * (1.0 - tau) ** 3
        e1 = (1.0 - tau) ** 2 * (1.0 - 4.0 * tau)
        e2 = (1.0 - tau) * (12.0 * tau - 6.0) / T
        return replace(r, pos=r.pos + (1.0 - w) * dp + e * dv, vel=r.vel - w1 * dp + e1 * dv,
                       acc=r.acc - w2 * dp + e2 * dv)
