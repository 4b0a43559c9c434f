"""The flyable reference: the optimiser's cycle with its held controls' steps smoothed out.

The optimiser holds its controls (bank, angle of attack, thrust, tension) constant over each
mesh interval of length ``h`` (0.5 .. 0.85 s on the stored cycles) and lets them jump at the
interval boundaries, up to a bank reversal of 1.2 rad at a phase switch. The path's
acceleration and the tension, which the guidance feeds forward, are then staircases that step
every ``h`` (1.2 .. 2 Hz). A glider cannot jump its bank: the attitude loops chase each step,
and with the airframe's strong adverse yaw (a full aileron yaws it nearly as hard as a full
rudder: ``Cn_da`` 0.014 against ``Cn_dr`` 0.016 per full deflection) every step rings through
aileron, rudder and sideslip at the interval rate -- the ~1.1 Hz oscillation seen through
turns and dives.

:func:`flyable_reference` smooths the reference the autopilot flies with a centred running
mean of width ``h`` taken twice over the cycle (periodic, across the phase switches): a
triangular window ``2 h`` wide. One mean has its transfer function zero at ``1/h, 2/h, ...``,
so the staircase's harmonics vanish and its steps become ramps between the intervals' middles;
the second makes those ramps' corners round, so a bank change takes about ``2 h`` (~1.6 s at
``h`` = 0.8 s) and the roll rate no longer steps. Position, velocity, acceleration and tension
go through the same linear filter, so they stay consistent (the filter commutes with the time
derivative); on the stored cycles the smoothed path lies 0.25 .. 0.5 m RMS (0.9 .. 2.3 m at the
sharpest corners) from the optimiser's, and the lateral acceleration's content above 0.5 Hz
drops 1.6 .. 4.6 times. Being centred, the filter adds no lag: the path is known ahead.
A wider window is not better: centred, it brings part of a pull-up's acceleration forward to
where the glider is still slow and asks there for lift beyond its CLmax (with ``h`` then
``2 h`` the half-line foldable cycle fell 17 m behind its path in a dive; with ``h`` then
``1.5 h`` the paper cycle in moderate turbulence, seed 1, touched the 40 m/s airspeed limit).
The tether length and reel speed (the winch's targets) and the feed-forward controls are left
as they are.

A reference without held controls (e.g. one built from waypoints) is returned unchanged.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from .tracking import TrackingReference

#: the columns smoothed (see the module doc)
SMOOTHED = ("pos", "vel", "acc", "tension")
#: widths of the running means, in hold intervals (see the module doc)
WINDOWS = (1.0, 1.0)
#: the held controls whose steps mark the optimiser's interval boundaries
_HELD = ("alpha", "phi", "thrust")


def hold_interval(ref: TrackingReference) -> float:
    """The optimiser's hold interval [s]: the longest of the phases' intervals, from the
    metadata's ``mesh`` (``n_gen``, ``n_rec`` intervals over ``T1`` and ``T2``) when given, else
    the median time between steps of the held controls in each phase; 0 when the reference
    has no held controls."""
    mesh = ref.meta.get("mesh")
    if isinstance(mesh, dict) and mesh.get("n_gen") and mesh.get("n_rec"):
        return max(ref.T1 / float(mesh["n_gen"]), ref.T2 / float(mesh["n_rec"]))
    widths = []
    for p in np.unique(ref.phase):
        sel = np.flatnonzero(ref.phase == p)
        steps = np.zeros(len(sel) - 1, bool)
        for name in _HELD:
            steps |= np.diff(np.asarray(getattr(ref, name), float)[sel]) != 0.0
        times = ref.t[sel][1:][steps]
        if len(times) >= 3:
            widths.append(float(np.median(np.diff(times))))
    return max(widths) if widths else 0.0


def periodic_mean(t: np.ndarray, y: np.ndarray, width: float, period: float) -> np.ndarray:
    """Centred running mean over ``width`` [s] of the periodic (``period`` [s]), piecewise-
    linear signal with samples ``y`` (``(n,)`` or ``(n, k)``) at increasing times ``t`` in
    ``[0, period)``, at the sample times: the exact integral of the linear interpolant over
    the window, divided by its width."""
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    if not (0.0 < width < period):
        raise ValueError(f"periodic_mean: width {width!r} s out of range (allowed 0 .. the period {period!r} s)")
    # three cycles of the samples in [0, period) (a last sample at the period is the first
    # one again), so every window lies inside
    base = t < t[0] + period - 1e-9
    tb, yb = t[base], y[base]
    tt = np.concatenate([tb - period, tb, tb + period])
    yy = np.concatenate([yb, yb, yb])
    shape = (-1,) + (1,) * (y.ndim - 1)
    F = np.concatenate([np.zeros((1,) + y.shape[1:]),
                        np.cumsum(0.5 * (yy[1:] + yy[:-1]) * np.diff(tt).reshape(shape), axis=0)])

    def integral(x: np.ndarray) -> np.ndarray:
        i = np.clip(np.searchsorted(tt, x, side="right") - 1, 0, len(tt) - 2)
        s = (x - tt[i]).reshape(shape)
        slope = (yy[i + 1] - yy[i]) / (tt[i + 1] - tt[i]).reshape(shape)
        return F[i] + yy[i] * s + 0.5 * slope * s * s

    return (integral(t + 0.5 * width) - integral(t - 0.5 * width)) / width


def flyable_reference(ref: TrackingReference, windows: tuple[float, ...] = WINDOWS) -> TrackingReference:
    """``ref`` with :data:`SMOOTHED` passed through centred running means of ``windows`` hold
    intervals each (:func:`hold_interval`; see the module doc). Its metadata gains
    ``shaping_windows_s``, the widths used [s]."""
    h = hold_interval(ref)
    widths = [w * h for w in windows]
    if h <= 0.0 or not all(0.0 < w < ref.period for w in widths) or not math.isfinite(h):
        return ref
    new = {}
    for name in SMOOTHED:
        y = np.asarray(getattr(ref, name), float)
        for w in widths:
            y = periodic_mean(ref.t, y, w, ref.period)
        new[name] = y
    return replace(ref, **new, meta={**ref.meta, "shaping_windows_s": [round(w, 6) for w in widths]})
