"""The events that end a co-simulation run: one table of codes, statuses and messages, and the
per-step check written once.

:data:`EVENTS` lists every event with its code (the index), its name, the run status it gives
and its one-line message (a ``str.format`` template; :func:`event_message` fills it).
:func:`step_event` checks a step just run, in this order: a non-finite glider state, a
ground-station event, ground contact after the glider was airborne, the airspeed limits (after
the grace time), the line tension, the load factor. It is a plain function: the compiled
co-simulation step (:mod:`fdm_awe.sim.kernel`) compiles it with numba and the Python loop
(:meth:`fdm_awe.sim.loop.CoSim.run`) runs the same source, so both end a run on the same step with
the same code. Its thresholds come in a vector (layout :data:`LIM`) built by
:func:`limit_vector`, a float64 array in the compiled step and a list in Python.

One event of the table is logged and does not end the run (its status ``ok``):
``machine_current``, the armature current above the machine's peak rating. The converter
holds the motor mode's current at its limit, below that rating; the generator's passive
rectifier does not limit, and a current above the peak for a few steps heats the machine, it
does not stop the flight (:func:`machine_current` reads it from a flight's log).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import slots
from ..constants import G0
from ..sixdof.row import FINITE_END, FINITE_FIRST, ROW


@dataclass(frozen=True)
class EventKind:
    """One event: ``code`` (its index in :data:`EVENTS`), ``name``, the run ``status`` it gives
    ("" : the ground station's event name) and its ``message`` template (fields: ``error``,
    ``force`` (N), ``gs_event``, ``x``, ``y`` (m), ``airspeed`` (m/s), ``tension`` (N),
    ``load_factor`` (g), ``current`` (A) and the limits ``airspeed_max``, ``airspeed_min``,
    ``max_tension``, ``max_load_factor``, ``peak_current`` (A))."""

    code: int
    name: str
    status: str
    message: str


#: every event, indexed by its code; the compiled step returns codes 0 .. 9, the Python loop
#: also ``jsbsim_failed`` and ``interrupted``; a flight logs ``machine_current`` (the run goes on)
EVENTS: tuple[EventKind, ...] = (
    EventKind(0, "none", "ok", ""),
    EventKind(1, "hook_rejected", "nonfinite", "ground station rejected the glider state: {error}"),
    EventKind(2, "nonfinite_force", "nonfinite", "non-finite tether force {force!r}"),
    EventKind(3, "nonfinite_state", "nonfinite", "non-finite glider state"),
    EventKind(4, "ground_station", "", "ground station event: {gs_event}"),
    EventKind(5, "ground_contact", "ground_contact", "ground contact at x={x:.1f} m, y={y:.1f} m, {airspeed:.1f} m/s"),
    EventKind(6, "airspeed_high", "airspeed_limit", "airspeed {airspeed:.2f} m/s above {airspeed_max:g} m/s"),
    EventKind(7, "airspeed_low", "airspeed_limit", "airspeed {airspeed:.2f} m/s below {airspeed_min:g} m/s"),
    EventKind(8, "tension", "load_limit", "tether tension {tension:.1f} N above {max_tension:g} N"),
    EventKind(9, "load_factor", "load_limit", "load factor {load_factor:.2f} g beyond {max_load_factor:g} g"),
    EventKind(10, "jsbsim_failed", "nonfinite", "JSBSim failed: {error}"),
    EventKind(11, "interrupted", "interrupted", "interrupted by the user"),
    EventKind(12, "machine_current", "ok", "armature current {current:.1f} A above the machine's peak rating "
                                           "{peak_current:g} A"),
)
#: each event's code by its name (``CODE.tension``), its index in :data:`EVENTS`
CODE = slots.declare("EventCodes", tuple(e.name for e in EVENTS))
if any(e.code != i for i, e in enumerate(EVENTS)):  # pragma: no cover - a definition error in this module
    raise RuntimeError("fdm_awe.sim.events: EVENTS must list each event at the index of its code")

#: the vector of :func:`step_event`'s thresholds and state (see :func:`limit_vector`)
LIM = slots.declare("EventLimits", ("vhi", "vlo", "thi", "nmax", "grace", "t0", "checkv", "ground", "airborne", "kv",
                                    "kfz", "km"))


def limit_vector(limits: Any, t0: float, airborne: bool, k_v: float, k_fz: float, k_m: float) -> list[float]:
    """:func:`step_event`'s vector from ``limits`` (:class:`fdm_awe.sim.loop.Limits`): airspeeds
    m/s (disabled: -inf/inf), tension N (inf), load factor g (NaN), grace time s, start time
    ``t0`` s, the airspeed-check and ground-contact flags, the ``airborne`` flag (updated by the
    check) and the row's SI factors of airspeed (``k_v``), body z force (``k_fz``) and mass
    (``k_m``)."""
    inf = math.inf
    v = [0.0] * slots.size(LIM)
    v[LIM.vhi] = inf if limits.airspeed_max is None else limits.airspeed_max
    v[LIM.vlo] = -inf if limits.airspeed_min is None else limits.airspeed_min
    v[LIM.thi] = inf if limits.max_tension is None else limits.max_tension
    v[LIM.nmax] = math.nan if limits.max_load_factor is None else limits.max_load_factor
    v[LIM.grace], v[LIM.t0] = limits.grace_s, t0
    v[LIM.checkv] = 1.0 if (limits.airspeed_max is not None or limits.airspeed_min is not None) else 0.0
    v[LIM.ground] = 1.0 if limits.ground_contact else 0.0
    v[LIM.airborne] = 1.0 if airborne else 0.0
    v[LIM.kv], v[LIM.kfz], v[LIM.km] = k_v, k_fz, k_m
    return v


def step_event(r, tension, gs_event, lim):
    """Event code (:data:`EVENTS`) of a step just run, ``CODE.none`` when the run goes on:
    ``r`` the step's raw row (:mod:`fdm_awe.sixdof.row`), ``tension`` the line tension N,
    ``gs_event`` true when the ground station reported an event, ``lim`` the vector of
    :func:`limit_vector` (its airborne flag set once the glider is off the ground)."""
    if not math.isfinite(sum(r[FINITE_FIRST:FINITE_END])):
        return CODE.nonfinite_state
    if gs_event:
        return CODE.ground_station
    if r[ROW.wow] > 0.5:  # weight on wheels: a contact touches the ground
        if lim[LIM.airborne] != 0.0 and lim[LIM.ground] != 0.0:
            return CODE.ground_contact
    else:
        lim[LIM.airborne] = 1.0
    if lim[LIM.checkv] != 0.0 and r[ROW.t] - lim[LIM.t0] >= lim[LIM.grace]:
        v = r[ROW.vt] * lim[LIM.kv]  # SixDofState.airspeed
        if v > lim[LIM.vhi]:
            return CODE.airspeed_high
        if v < lim[LIM.vlo]:
            return CODE.airspeed_low
    if tension > lim[LIM.thi]:
        return CODE.tension
    nmax = lim[LIM.nmax]
    if nmax == nmax:  # NaN: no load-factor limit
        nz = -r[ROW.fbz] * lim[LIM.kfz] / (r[ROW.mass] * lim[LIM.km]) / G0  # SixDofState.load_factor
        if nz > nmax or nz < -nmax:
            return CODE.load_factor
    return CODE.none


def event_message(code: int, limits: Any, state: Any = None, gs_out: Any = None,
                  force: tuple[float, float, float] | None = None, error: str = "") -> tuple[str, str]:
    """(status, message) of event ``code`` from the table: ``limits`` the run's
    :class:`fdm_awe.sim.loop.Limits`, ``state`` the glider state (:class:`SixDofState`) at the
    event, ``gs_out`` the ground station's last output, ``force`` the line force N, ``error``
    the text of a rejected step."""
    kind = EVENTS[code]
    gev = getattr(gs_out, "event", None)
    status = kind.status or str(gev)
    msg = kind.message
    if "{" not in msg:
        return status, msg
    values: dict[str, Any] = {"error": error, "force": force, "gs_event": gev,
                              "airspeed_max": limits.airspeed_max, "airspeed_min": limits.airspeed_min,
                              "max_tension": limits.max_tension, "max_load_factor": limits.max_load_factor}
    if code == CODE.ground_contact:
        values.update(x=state.x, y=state.y, airspeed=state.airspeed)
    elif code in (CODE.airspeed_high, CODE.airspeed_low):
        values["airspeed"] = state.airspeed
    elif code == CODE.load_factor:
        values["load_factor"] = state.load_factor
    elif code == CODE.tension:
        values["tension"] = gs_out.tension
    return status, msg.format(**values)


def machine_current(t: np.ndarray, current: np.ndarray, rated: float,
                    peak: float) -> tuple[float, float, list[tuple[float, str]]]:
    """The armature current of a flight's log against the machine's ratings: ``t`` the rows'
    times s, ``current`` their armature currents A (the value at the end of each step; NaN
    where none), ``rated`` the rated continuous current A, ``peak`` the peak current A. Returns
    the largest current A (NaN without one), the time above the rated current s (the steps
    whose current ends above it) and the logged events: for each excursion above the peak, its
    first row's time s and the ``machine_current`` message with the excursion's largest
    current."""
    i = np.nan_to_num(np.asarray(current, dtype=float), nan=0.0)
    t = np.asarray(t, dtype=float)
    i_max = float(np.nanmax(current)) if np.any(np.isfinite(current)) else math.nan
    above = float(np.sum(np.diff(t)[i[1:] > rated])) if len(t) > 1 else 0.0
    over = np.flatnonzero(i > peak)
    events: list[tuple[float, str]] = []
    for run in np.split(over, np.flatnonzero(np.diff(over) > 1) + 1) if len(over) else []:
        msg = EVENTS[CODE.machine_current].message.format(current=float(i[run].max()), peak_current=peak)
        events.append((float(t[run[0]]), msg))
    return i_max, above, events


__all__ = ["CODE", "EVENTS", "EventKind", "LIM", "event_message", "limit_vector", "machine_current",
           "step_event"]
