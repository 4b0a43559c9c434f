"""The rejoin segment of AUTO: after FBWA, a restart of the cycling or a new mission, the glider
returns to its path over RJ_TIME along a reference that starts at its own position and velocity
(:func:`rejoin_weights`, run in the AUTO step :func:`fdm_awe.autopilot.auto_step.auto_guide`)."""

from __future__ import annotations


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
