"""The rejoin segment of AUTO: after FBWA, a restart of the cycling or a new mission, the glider
returns to its path over RJ_TIME along a reference that starts at its own position and velocity
(:func:`rejoin_weights`, run in the AUTO step :func:`fdm_awe.autopilot.auto_step.auto_guide`).
Where the glider has lost its path (farther than RJ_TRK_ERR from its reference point, a missed
turn in a gust, a lull), the rejoin begins at the path's point nearest the glider in the phase
under way (:func:`nearest_on_phase`), at most RJ_TRK_MAX times a cycle; the lost-path failsafe
(FS_TRK_ERR) stays the last resort."""

from __future__ import annotations

import math


def rejoin_weights(t: float, t0: float, T: float) -> tuple[float, float, float, float, float, float, float]:
    """The offset of a rejoin segment begun at ``t0`` [s] and lasting ``T`` [s], at time ``t``
    [s]: ``(done, w, w1, w2, e, e1, e2)`` such that the reference is the path's point plus
    ``(1 - w) dp + e dv`` (position), ``-w1 dp + e1 dv`` (velocity), ``-w2 dp + e2 dv``
    (acceleration) for the offsets ``dp``, ``dv`` at the start: an offset that vanishes with its
    first two derivatives after ``T`` (w the quintic smoothstep of tau = (t - t0) / T,
    e = (t - t0) (1 - tau)^3). ``done`` (1.0) once ``tau >= 1`` (the rest 0 then). A plain
    function: the compiled AUTO step runs it too."""
    tau = (t - t0) / T if T > 0.0 else 1.0
    if tau >= 1.0:
        return 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    u = 1.0 - tau
    w = tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau)
    w1 = 30.0 * tau * tau * (u * u) / T
    w2 = 60.0 * tau * u * (1.0 - 2.0 * tau) / (T * T)
    e = (t - t0) * (u * u * u)
    e1 = (u * u) * (1.0 - 4.0 * tau)
    e2 = u * (12.0 * tau - 6.0) / T
    return 0.0, w, w1, w2, e, e1, e2


#: the path rejoin's search (:func:`nearest_on_phase`): at most this far back and ahead of the
#: path parameter [s] of cycle time, and the weight of the velocity difference [s] (a point the
#: glider passes at its own velocity is nearer than one it crosses)
SEEK_BACK, SEEK_AHEAD, SEEK_TAU = 10.0, 20.0, 1.0


def nearest_on_phase(ts, table, T1: float, period: float, tc: float, px: float, py: float, pz: float,
                     vx: float, vy: float, vz: float) -> float:
    """The cycle time [s] of the reference's row nearest the glider (position ``p*`` [m], ground
    velocity ``v*`` [m/s], NED) in the phase of cycle time ``tc`` [s] (generation below ``T1``
    [s], recovery from it to ``period`` [s]), between :data:`SEEK_BACK` before and
    :data:`SEEK_AHEAD` after ``tc``: the smallest ``|p - p_ref| + SEEK_TAU |v - v_ref|``
    (``ts`` the rows' cycle times [s], ``table`` their linear columns, position then velocity
    first; :mod:`fdm_awe.trajectory.sampler`); ``tc`` itself if no row is in the window. Where
    the glider has lost its path it rejoins there (:func:`fdm_awe.autopilot.auto_step.auto_guide`)
    rather than at a point the path parameter froze or ran away with. A plain function: the
    compiled AUTO step runs it too."""
    lo, hi = (0.0, T1) if tc < T1 else (T1, period)
    a, b = max(lo, tc - SEEK_BACK), min(hi, tc + SEEK_AHEAD)
    best, best_t = math.inf, tc
    for j in range(len(ts)):
        tj = ts[j]
        if tj < a or tj > b or tj >= hi:
            continue
        dx, dy, dz = px - table[j, 0], py - table[j, 1], pz - table[j, 2]
        ux, uy, uz = vx - table[j, 3], vy - table[j, 4], vz - table[j, 5]
        d = math.sqrt(dx * dx + dy * dy + dz * dz) + SEEK_TAU * math.sqrt(ux * ux + uy * uy + uz * uz)
        if d < best:
            best, best_t = d, tj
    return best_t
