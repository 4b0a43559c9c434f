"""The wing's fold in AUTO: the fold time a reference is flown with (:func:`reference_fold_time`)
and the fold command over a pumping cycle (:func:`fold_command`, a pure function of floats that
numba compiles with the same bits as the Python call)."""

from __future__ import annotations

import math

from ..errors import InputError
from ..pointmass.fold import fold_fraction

#: slack on the fold-time comparison [s] (the reference's and the aircraft's are one number)
FOLD_TIME_TOL_S = 1e-6


def reference_fold_time(meta: dict, aircraft_fold_time_s: float) -> float:
    """Fold time [s] a reference (metadata ``meta``) is flown with on an aircraft whose fold
    actuator takes ``aircraft_fold_time_s`` for its full travel: the reference's
    ``fold_time_s`` (absent = 0: optimised with an instantaneous fold, flown with the
    FOLD_LEAD/UNFOLD_LEAD parameters). A fold time the aircraft can fly (0, or at least its
    actuator's) is returned; a faster one raises a one-line :class:`InputError`."""
    ft = meta.get("fold_time_s")
    ft = 0.0 if ft is None else float(ft)
    if not math.isfinite(ft) or ft < 0.0:
        raise InputError(f"reference metadata.fold_time_s: {ft:g} s out of range (allowed 0 or >= {aircraft_fold_time_s:g} s)")
    if 0.0 < ft < aircraft_fold_time_s - FOLD_TIME_TOL_S:
        raise InputError(f"reference metadata.fold_time_s: {ft:g} s, faster than the aircraft's fold actuator "
                         f"(fcs/wing-fold-time-s {aircraft_fold_time_s:g} s); allowed 0 (an instantaneous fold) or "
                         f">= {aircraft_fold_time_s:g} s: optimise the reference with the aircraft's fold time")
    return ft


def fold_command(t_cycle: float, T1: float, period: float, fold_time_s: float, fold_lead_s: float,
                 unfold_lead_s: float) -> float:
    """Fold command (0 open .. 1 folded) at cycle time ``t_cycle`` [s] of a cycle of ``period``
    [s] whose recovery starts at ``T1`` [s].

    With the reference's fold time ``fold_time_s`` > 0 the command is the optimiser's fold law
    (:func:`fdm_awe.pointmass.fold.fold_fraction`: folding from the start of recovery, unfolding
    over its last ``fold_time_s``), a ramp the rate-limited actuator follows (at its own full rate
    when it is the aircraft's fold time). A reference optimised with an instantaneous fold
    (``fold_time_s`` 0) is flown as such references always were: folded from ``fold_lead_s``
    (FOLD_LEAD) before the recovery to ``unfold_lead_s`` (UNFOLD_LEAD) before its end."""
    if fold_time_s > 0.0:
        if t_cycle < T1:
            return 0.0
        return fold_fraction(t_cycle - T1, period - T1, fold_time_s)
    return 1.0 if (T1 - fold_lead_s) <= t_cycle < (period - unfold_lead_s) else 0.0
