"""The wing's fold over a recovery: the fold fraction the rate-limited actuator reaches (one law
for the optimiser's model, :mod:`fdm_awe.ocp.model`, and the autopilot's fold command,
:mod:`fdm_awe.autopilot.fold`).

A pure function of floats (no NumPy, no CasADi), so numba compiles it into the autopilot's
compiled step with the same bits as the Python call.
"""

from __future__ import annotations


def fold_fraction(t: float, T2: float, fold_time: float) -> float:
    """Fold state (0 unfolded .. 1 folded) at time ``t`` [s] into a recovery of ``T2`` [s]: the
    rate-limited actuator (full travel in ``fold_time`` [s]) commanded folded at ``t = 0`` and
    open at ``t = T2 - fold_time``; ``T2 >= 2 fold_time`` (the optimiser's bound), so it is
    ``min(1, t / fold_time, (T2 - t) / fold_time)``. ``fold_time`` 0: folded throughout."""
    if fold_time <= 0.0:
        return 1.0
    return min(1.0, max(0.0, min(t, T2 - t) / fold_time))
