"""Rerun recording of a flight (6-DOF co-simulation) and of an optimised cycle.

``record_flight(report, reference, path)`` writes the 3D scene and the time series of a
finished, failed or interrupted flight; it reads only the logged rows, so a run cut short by
an event (or Ctrl-C, which the co-simulation turns into the ``interrupted`` event) is recorded
up to its last step. ``record_cycle(reference, path)`` records an optimised cycle from a
reference-trajectory file (or trajectory / CycleResult) the same way.

A flight is recorded in three parts, which :class:`~fdm_awe.recording.stream.LiveFlight` also
uses to stream a flight to a viewer while it is flown: :func:`log_flight_start` (the static
scene: ground, winch, wind, reference path, airframe), :func:`log_flight_rows` (everything
over time: pose, wing, tether, forces, plots, the mode lane (numbers, lined up with the plots)
and the modes by name (state lanes and a log of the changes), phase, the path flown so far every
second; callable for consecutive slices of rows) and :func:`log_flight_end` (the whole flown
path, the event log and the report). Every temporal row carries its cycle on the ``cycle``
timeline (:class:`~fdm_awe.recording.rrd.CycleClock`, fed by :func:`log_flight_rows`).

Cost: the scalar series go out at full rate as columns; the 3D scene (pose, tether, force
arrows, reference marker) and the mode lane are decimated to ``scene_hz`` (30 Hz by default;
the viewer interpolates nothing, it shows the latest pose), the path so far to ``PATH_HZ``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..mode_table import MODE_NUMBERS
from ..sim.cycles import OTHER_PHASE, PHASE_CODES
from .blueprint import MODE_LANES, MODE_LOG, cycle_blueprint, flight_blueprint
from .forces import GliderForces, flight_forces
from .rrd import RecordingSink, RrdFile
from .scene import REFERENCE_COLOR, recorded_aircraft, scene_extent
from .series import Series, cycle_series, flight_series, load_reference, robust_range
from .world import (
    FORCE_SCALE, GLIDER_SCALE, log_airframe, log_error_line, log_forces, log_forces_description, log_glider, log_path,
    log_paths_so_far, log_phase, log_point, log_static_scene, log_tether, log_tether_nodes,
)

#: (entity, series name, display name) of a flight's plots
FLIGHT_PLOTS: tuple[tuple[str, str, str], ...] = (
    ("plots/airspeed", "airspeed", "airspeed"),
    ("plots/altitude", "altitude", "altitude"),
    ("plots/tension", "tension", "tension"),
    ("plots/reel_speed", "reel_speed", "reel speed"),
    ("plots/attitude/roll", "roll", "roll phi"),
    ("plots/attitude/pitch", "pitch", "pitch theta"),
    ("plots/attitude/yaw", "yaw", "yaw psi"),
    ("plots/flow/alpha", "alpha", "alpha"),
    ("plots/flow/beta", "beta", "beta"),
    ("plots/surfaces/aileron", "aileron", "aileron"),
    ("plots/surfaces/elevator", "elevator", "elevator"),
    ("plots/surfaces/rudder", "rudder", "rudder"),
    ("plots/surfaces/throttle", "throttle", "throttle"),
    ("plots/duty", "duty", "converter duty"),
    ("plots/fold", "fold", "fold state"),
    ("plots/power/winch_electrical", "p_electrical", "winch electrical (+ out)"),
    ("plots/power/propeller", "prop_power", "propeller electrical"),
    ("plots/energy/generated", "E_generated", "generated"),
    ("plots/energy/thrust", "E_thrust", "thrust"),
    ("plots/energy/reel_in", "E_reel_in", "reel-in"),
    ("plots/energy/net", "E_net", "net"),
    ("plots/tracking_error", "track_error", "tracking error"),
)

CYCLE_PLOTS: tuple[tuple[str, str, str], ...] = (
    ("plots/airspeed", "airspeed", "airspeed"),
    ("plots/altitude", "altitude", "altitude"),
    ("plots/tension", "tension", "tension"),
    ("plots/reel_speed", "reel_speed", "reel speed"),
    ("plots/alpha", "alpha", "alpha"),
    ("plots/bank", "bank", "bank"),
    ("plots/thrust", "thrust", "thrust"),
    ("plots/fold", "fold", "fold state"),
    ("plots/power/generated", "p_generated", "generated"),
    ("plots/power/thrust", "p_thrust", "thrust"),
    ("plots/power/reel_in", "p_reel_in", "reel-in"),
    ("plots/energy/generated", "E_generated", "generated"),
    ("plots/energy/thrust", "E_thrust", "thrust"),
    ("plots/energy/reel_in", "E_reel_in", "reel-in"),
    ("plots/energy/net", "E_net", "net"),
)

#: (entity, GliderForces scalar, display name) of the force plots: lift and drag signed in wind
#: axes (drag > 0 against the air velocity), the tether force's magnitude, the logged thrust
FORCE_PLOTS: tuple[tuple[str, str, str], ...] = (
    ("plots/forces/lift", "L", "lift"),
    ("plots/forces/drag", "D", "drag"),
    ("plots/forces/side", "C", "side force"),
    ("plots/forces/tether", "tether_N", "tether force"),
    ("plots/forces/thrust", "thrust_N", "thrust"),
)

#: the path flown so far (re-sent every PATH_EVERY_S of flight time, points at about PATH_HZ)
LIVE_PATH = "world/flown/live"
PATH_EVERY_S = 1.0
PATH_HZ = 5.0

#: the mode lane: key -> (entity, series name, colour); the autopilot's mode as its MAVLink
#: custom_mode number (fdm_awe.mode_table), the winch as 0 generator / 1 motor (the
#: electrical power's sign), the phase as its code (fdm_awe.sim.cycles.PHASE_CODES, -1 other)
MODE_PLOTS: dict[str, tuple[str, str, tuple[int, int, int]]] = {
    "autopilot": ("plots/mode/autopilot",
                  "autopilot mode (" + ", ".join(f"{v} {k}" for k, v in MODE_NUMBERS.items() if k != "GUIDED") + ")",
                  (31, 119, 180)),
    "winch": ("plots/mode/winch", "winch mode (0 generator, 1 motor)", (214, 39, 40)),
    "phase": ("plots/mode/phase", "phase (" + ", ".join(f"{v} {k}" for k, v in PHASE_CODES.items())
              + f", {OTHER_PHASE} other)", (44, 160, 44)),
}

#: the named mode lanes (state timelines under :data:`~.blueprint.MODE_LANES`): key -> (entity,
#: state name -> colour); the autopilot's modes (fdm_awe.mode_table) and the winch's two modes
MODE_STATES: dict[str, tuple[str, dict[str, tuple[int, int, int]]]] = {
    "autopilot": (f"{MODE_LANES}/autopilot", {"MANUAL": (127, 127, 127), "FBWA": (148, 103, 189), "AUTO": (31, 119, 180),
                                               "RECOVER": (214, 39, 40), "LOITER": (255, 127, 14),
                                               "GUIDED": (188, 189, 34)}),
    "winch": (f"{MODE_LANES}/winch", {"generator": (44, 160, 44), "motor": (214, 39, 40)}),
}
#: the level of a change into an autopilot mode in the log of mode changes (every other mode
#: and the winch's and the phase's changes: INFO): leaving the pumping cycle is a warning
MODE_LEVELS: dict[str, str] = {"MANUAL": "WARN", "FBWA": "WARN", "RECOVER": "WARN", "LOITER": "WARN", "GUIDED": "WARN"}

_COLORS = {"generated": (44, 160, 44), "thrust": (214, 39, 40), "reel_in": (255, 127, 14), "net": (31, 119, 180),
           "winch_electrical": (31, 119, 180), "propeller": (214, 39, 40), "lift": (31, 119, 180),
           "drag": (255, 127, 14), "tether": (148, 103, 189)}


def describe(meta: dict[str, Any], what: str) -> str:
    """One-line title: what, scenario, configuration, wind, status."""
    parts = [what]
    if meta.get("scenario"):
        parts.append(f"scenario {meta['scenario']}")
    if meta.get("config"):
        parts.append(f"config {meta['config']}")
    w = meta.get("wind_mps")
    if w is not None:
        parts.append(f"wind {float(w):g} m/s")
    if meta.get("status"):
        parts.append(f"status {meta['status']}")
    return ", ".join(parts)


def _decimate(t: np.ndarray, hz: float) -> np.ndarray:
    """Row indices at about ``hz`` (always the first and the last row)."""
    n = len(t)
    if n == 0:
        return np.zeros(0, int)
    dt = float(np.median(np.diff(t))) if n > 1 else 1.0
    every = max(1, int(round(1.0 / (hz * dt)))) if dt > 0 else 1
    idx = np.arange(0, n, every)
    if idx[-1] != n - 1:
        idx = np.r_[idx, n - 1]
    return idx


def _send_plots(rf: RecordingSink, s: Series, plots: tuple[tuple[str, str, str], ...]) -> None:
    for entity, key, label in plots:
        if key in s:
            color = _COLORS.get(entity.rsplit("/", 1)[-1])
            rf.scalars(entity, s.t, s[key], name=f"{label} [{s.unit(key)}]", color=color)


def _reference_points(reference: Any) -> tuple[np.ndarray, list[str], Any] | None:
    """(points, phase labels, wind) of one cycle of a TrackingReference or reference file."""
    if reference is None:
        return None
    if hasattr(reference, "pos") and hasattr(reference, "T1") and hasattr(reference, "sample"):
        from ..trajectory import PHASE_NAMES

        pts = np.asarray(reference.pos, float)
        labels = [PHASE_NAMES[int(p)] if 0 <= int(p) < len(PHASE_NAMES) else str(p) for p in reference.phase]
        pts = np.vstack([pts, pts[:1]])  # closed loop
        labels = labels + labels[-1:]
        return pts, labels, reference.meta.get("wind_ned_mps")
    s = cycle_series(reference)
    return s.pos, s.phase, load_reference(reference).metadata.get("wind_ned_mps")


def power_range(s: Series) -> tuple[float, float] | None:
    """Robust y-range [W] of a flight's power panel (:func:`~fdm_awe.recording.series.robust_range`)."""
    return robust_range(s.t, [s[key] for entity, key, _ in FLIGHT_PLOTS if entity.startswith("plots/power/")])


@dataclass
class RowsSent:
    """What :func:`log_flight_rows` sent up to now, for the next slice of the same flight."""

    fold: float | None = None  #: fold state of the last wing mesh sent
    phase: str | None = None  #: phase label of the last row sent
    phases: set[str] = field(default_factory=set)  #: every phase label sent
    #: the path so far (NED m): its finished runs of one phase (label, points (n, 3)) and the run
    #: being flown (label, points), which begins at the last point of the run before it
    path_runs: list[tuple[str, np.ndarray]] = field(default_factory=list)
    path_run: tuple[str, list[np.ndarray]] | None = None
    path_next: float = -np.inf  #: simulation time [s] from which the path so far is sent again
    #: the last named state sent per lane of the mode changes (``autopilot``, ``winch``, ``phase``)
    modes: dict[str, str] = field(default_factory=dict)
    path_last: float = -np.inf  #: simulation time [s] of the last point kept


def _send_modes(rf: RecordingSink, s: Series, rows: np.ndarray) -> None:
    """The mode lane of rows ``s`` (a slice of a flight): the autopilot's mode number, the
    winch's mode and the phase code at ``rows`` (indices into ``s``) and around each change,
    so the drawn lines step where the mode changed."""
    series: list[tuple[str, np.ndarray]] = []
    if s.mode is not None:
        series.append(("autopilot", np.array([MODE_NUMBERS.get(m, np.nan) for m in s.mode], float)))
    pe = s["p_electrical"]
    series.append(("winch", np.where(np.isfinite(pe), (pe < 0.0).astype(float), np.nan)))
    series.append(("phase", np.array([PHASE_CODES.get(p, OTHER_PHASE) for p in s.phase], float)))
    for key, values in series:
        v = np.nan_to_num(values, nan=-1e9)
        change = np.flatnonzero(v[1:] != v[:-1]) + 1
        keep = np.unique(np.r_[rows, change, change - 1].astype(int))
        entity, label, color = MODE_PLOTS[key]
        rf.scalars(entity, s.t[keep], values[keep], name=label, color=color)


def mode_labels(s: Series) -> dict[str, list[str | None]]:
    """The named modes of each row of ``s``: ``autopilot`` (its mode name, None where unknown;
    absent when the rows carry no mode), ``winch`` (``generator`` or ``motor`` by the sign of the
    electrical power, None before the station's first step) and ``phase`` (the phase label)."""
    out: dict[str, list[str | None]] = {}
    if s.mode is not None:
        out["autopilot"] = [m if m in MODE_NUMBERS else None for m in s.mode]
    pe = s["p_electrical"]
    out["winch"] = [None if not np.isfinite(p) else ("motor" if p < 0.0 else "generator") for p in pe.tolist()]
    out["phase"] = list(s.phase)
    return out


def _send_mode_names(rf: RecordingSink, s: Series, sent: RowsSent) -> None:
    """The modes of rows ``s`` (a slice of a flight) by name: a state change on the named lanes
    (:data:`MODE_STATES`; the phase has its own lane) and a line in the log of mode changes
    (:data:`~.blueprint.MODE_LOG`) at each row whose mode differs from the row before (``sent``
    holds the last one sent), at that row's time; the first known mode of a lane is logged too."""
    rr = rf.rr
    for key, labels in mode_labels(s).items():
        prev = sent.modes.get(key)
        idx, names = [], []
        for i, name in enumerate(labels):
            if name is not None and name != prev:
                idx.append(i)
                names.append(name)
                prev = name
        if not idx:
            continue
        times = np.asarray(s.t)[idx]
        if key in MODE_STATES:
            entity, colors = MODE_STATES[key]
            rf.static(entity, rr.StateConfiguration(values=list(colors), colors=list(colors.values())))
            rf.columns(entity, times, rr.StateChange.columns(state=names))
        before = sent.modes.get(key)
        for t, name in zip(times.tolist(), names):
            text = f"{key} {name}" if before is None else f"{key} {before} -> {name}"
            color = MODE_STATES[key][1].get(name) if key in MODE_STATES else None
            level = MODE_LEVELS.get(name, "INFO") if key == "autopilot" else "INFO"
            rf.at(MODE_LOG, t, rr.TextLog(text, level=level, color=color))
            before = name
        sent.modes[key] = names[-1]


def _send_path_so_far(rf: RecordingSink, s: Series, sent: RowsSent, *, every_s: float = PATH_EVERY_S,
                      hz: float = PATH_HZ) -> None:
    """The path flown so far, from the rows ``s`` (the next slice of a flight): points kept at
    about ``hz``, the whole path sent to :data:`LIVE_PATH` every ``every_s`` seconds of flight
    time (at the first kept point at or after each multiple; a slice's last row is kept when a
    multiple has passed, so the path reaches the glider however the flight is sliced)."""
    pos = s.pos
    eps = 1e-6  # [s] time stamps are multiples of the step, not of 1 / hz
    last = len(s.t) - 1
    times: list[float] = []
    paths: list[list[tuple[str, np.ndarray]]] = []
    for j, tj in enumerate(s.t.tolist()):
        if tj < sent.path_last + 1.0 / hz - eps and not (j == last and tj >= sent.path_next - eps):
            continue
        sent.path_last = tj
        if np.all(np.isfinite(pos[j])):
            run = sent.path_run
            if run is None or run[0] != s.phase[j]:
                if run is not None:
                    sent.path_runs.append((run[0], np.asarray(run[1])))
                run = sent.path_run = (s.phase[j], ([run[1][-1]] if run is not None else []))
            run[1].append(pos[j])
        if tj >= sent.path_next - eps:
            times.append(tj)
            run = sent.path_run
            paths.append(sent.path_runs + ([] if run is None else [(run[0], np.asarray(run[1]))]))
            sent.path_next = (np.floor(tj / every_s + eps) + 1.0) * every_s
    log_paths_so_far(rf, LIVE_PATH, np.asarray(times), paths)


def log_flight_start(rf: RecordingSink, reference: Any, pos: np.ndarray | None = None, *,
                     glider_scale: float = GLIDER_SCALE, force_scale: float = FORCE_SCALE, aircraft: Any = None) -> None:
    """Static scene of a flight: ground covering ``pos`` (n, 3) and the reference, winch, wind,
    the reference path, the body of ``aircraft`` (None: the package's glider) and the
    description of the force arrows."""
    ref = _reference_points(reference)
    log_static_scene(rf, scene_extent(pos, ref[0] if ref else None), ref[2] if ref is not None else None)
    if ref is not None:
        log_path(rf, "world/reference", ref[0], ref[1], radius=0.4, reference=True)
    log_airframe(rf, glider_scale, aircraft)
    log_forces_description(rf, force_scale)


def log_flight_rows(rf: RecordingSink, flight: Any, s: Series, forces: GliderForces, sent: RowsSent | None = None, *,
                    rows: slice = slice(None), scene_hz: float = 30.0, force_scale: float = FORCE_SCALE,
                    aircraft: Any = None) -> RowsSent:
    """Everything over time of the ``rows`` of a flight (or of a slice of one): pose and wing,
    tether, force arrows, reference marker and tracking error (3D scene at about ``scene_hz``),
    every plot at full rate, the mode lane, the modes by name (:func:`mode_labels`: state lanes and
    the log of changes, at the rows where they change), the phase lane and the path flown so far. ``s`` and
    ``forces`` are the flight's :func:`~fdm_awe.recording.series.flight_series` and
    :func:`~fdm_awe.recording.forces.flight_forces` on the recording's time axis; ``sent``
    carries the state between consecutive slices; the wing drawn is ``aircraft``'s (None: the
    one the flight records, else the package's glider). Returns it, updated."""
    sent = RowsSent() if sent is None else sent
    res = getattr(flight, "result", None) or flight
    idx = np.arange(len(s.t))[rows]
    t = s.t[idx]
    if s.cycle is not None:  # every row from here on carries its cycle
        rf.clock.extend(t, s.cycle[idx])
    i = idx[_decimate(t, scene_hz)]
    if len(i):
        pos = s.pos
        if aircraft is None:
            aircraft = recorded_aircraft(getattr(flight, "aircraft", None))
        sent.fold = log_glider(rf, s.t[i], pos[i], np.asarray(res.quat, float)[i], s["fold"][i], last_fold=sent.fold,
                               aircraft=aircraft)
        shape = getattr(flight, "line_shape", None)
        if shape is not None and len(shape["t"]):  # the lumped line: its nodes and tensions
            log_tether_nodes(rf, s.t[0] + shape["t"], shape["nodes"], shape["tension"])
        else:
            log_tether(rf, s.t[i], pos[i], s["tension"][i])
        log_forces(rf, s.t[i], pos[i], {name: forces[name][i] for name in ("lift", "drag", "tether", "thrust")},
                   force_scale)
        refp = np.c_[s["ref_x"], s["ref_y"], s["ref_z"]][i]
        log_point(rf, "world/reference_point", s.t[i], refp, REFERENCE_COLOR)
        log_error_line(rf, "world/tracking_error", s.t[i], pos[i], refp)
    part = s.rows(idx)
    _send_plots(rf, part, FLIGHT_PLOTS)
    _send_modes(rf, part, _decimate(t, scene_hz))
    _send_mode_names(rf, part, sent)
    _send_path_so_far(rf, part, sent)
    scalars = {"L": forces.L, "D": forces.D, "C": forces.C, "tether_N": forces.magnitude("tether"),
               "thrust_N": s["thrust"]}
    _send_plots(rf, Series(t=t, columns={k: ("N", v[idx]) for k, v in scalars.items()}, phase=part.phase), FORCE_PLOTS)
    sent.phases |= set(part.phase)
    log_phase(rf, t, part.phase, previous=sent.phase, states=sent.phases)
    if len(part.phase):
        sent.phase = part.phase[-1]
    return sent


def log_flight_end(rf: RecordingSink, flight: Any, s: Series) -> None:
    """The whole flown path (coloured by phase) at the flight's last time, replacing the path so
    far; the event log and, for a report, its markdown."""
    t_end = float(s.t[-1]) if len(s.t) else 0.0
    rf.at(LIVE_PATH, t_end, rf.rr.Clear(recursive=False))
    log_path(rf, "world/flown", s.pos, s.phase, radius=0.7, t=t_end)
    _log_events(rf, flight, s)
    if hasattr(flight, "cycles") and hasattr(flight, "ledger"):
        from .report import flight_markdown

        rf.static("report", rf.rr.TextDocument(flight_markdown(flight), media_type=rf.rr.MediaType.MARKDOWN))


def record_flight(flight: Any, reference: Any = None, path: str | Path = "flight.rrd", *, scene_hz: float = 30.0,
                  glider_scale: float = GLIDER_SCALE, name: str | None = None) -> Path:
    """Record a flight (FlightReport or FlightResult, complete or cut short) into ``path``.

    ``reference``: the flown :class:`~fdm_awe.autopilot.tracking.TrackingReference`, a
    reference-trajectory file or None. Returns the path of the finalised ``.rrd`` file. The
    file appears complete or not at all: an exception (Ctrl-C) while it is written leaves
    ``path`` as it was.
    """
    s = flight_series(flight)
    title = describe(s.meta, "flight")
    blueprint = flight_blueprint(title, power_range(s))
    aircraft = recorded_aircraft(getattr(flight, "aircraft", None))
    with RrdFile(path, name=name or title, blueprint=blueprint, keep_on_error=False) as rf:
        log_flight_start(rf, reference, s.pos, glider_scale=glider_scale, aircraft=aircraft)
        log_flight_rows(rf, flight, s, flight_forces(flight), scene_hz=scene_hz, aircraft=aircraft)
        log_flight_end(rf, flight, s)
    return Path(path)


def _log_events(rf: RecordingSink, flight: Any, s: Series) -> None:
    rr = rf.rr
    t0 = float(getattr(getattr(flight, "result", None) or flight, "t")[0]) if len(s.t) else 0.0
    for t, msg in getattr(flight, "autopilot_log", []) or []:
        rf.at("events", float(t) - t0, rr.TextLog(str(msg), level="INFO"))
    if len(s.t):
        status = s.meta.get("status", "unknown")
        msg = s.meta.get("message") or status
        rf.at("events", float(s.t[-1]), rr.TextLog(f"end: {status}: {msg}", level="INFO" if status == "ok" else "WARN"))


def record_cycle(reference: Any, path: str | Path = "cycle.rrd", *, glider_scale: float = GLIDER_SCALE,
                 name: str | None = None, samples_hz: float = 30.0) -> Path:
    """Record an optimised cycle (reference-trajectory file, trajectory or CycleResult).

    The collocation points are drawn as the path; the glider is posed along it at
    ``samples_hz``. The point-mass model has no body attitude of its own: the pose drawn is
    heading psi, pitch gamma + alpha, bank phi (ZYX Euler angles; exact for wings level,
    an illustration when banked).
    """
    s = cycle_series(reference)
    tr = load_reference(reference)
    title = describe(s.meta, "optimised cycle")
    wind = tr.metadata.get("wind_ned_mps")
    with RrdFile(path, name=name or title, blueprint=cycle_blueprint(title), keep_on_error=False) as rf:
        log_static_scene(rf, scene_extent(s.pos), wind)
        log_path(rf, "world/reference", s.pos, s.phase, radius=0.6)
        T = float(s.t[-1]) if len(s.t) else 0.0
        if T > 0:
            tt = np.arange(0.0, T, 1.0 / samples_hz)
            smp = [tr.sample(float(x)) for x in tt]
            pos = np.array([[d["x"], d["y"], d["z"]] for d in smp])
            quat = np.array([_air_path_quat(d["gamma"], d["psi"], d["phi"], d["alpha"]) for d in smp])
            fold = np.array([d.get("fold", 0.0) for d in smp])
            tens = np.array([d.get("tension", 0.0) for d in smp])
            aircraft = recorded_aircraft(tr.metadata.get("aircraft"))
            log_airframe(rf, glider_scale, aircraft)
            log_glider(rf, tt, pos, quat, fold, aircraft=aircraft)
            log_tether(rf, tt, pos, tens)
        _send_plots(rf, s, CYCLE_PLOTS)
        log_phase(rf, s.t, s.phase)
        from .report import cycle_markdown

        rf.static("report", rf.rr.TextDocument(cycle_markdown(reference), media_type=rf.rr.MediaType.MARKDOWN))
    return Path(path)


def _air_path_quat(gamma: float, psi: float, phi: float, alpha: float) -> tuple[float, float, float, float]:
    """(w, x, y, z) drawn attitude: heading psi, pitch gamma + alpha, bank phi (ZYX Euler angles)."""
    from ..sixdof.state import euler_to_quat

    return euler_to_quat(phi, gamma + alpha, psi)


__all__ = ["CYCLE_PLOTS", "FLIGHT_PLOTS", "FORCE_PLOTS", "LIVE_PATH", "MODE_PLOTS", "RowsSent", "describe",
           "log_flight_end", "log_flight_rows", "log_flight_start", "power_range", "record_cycle", "record_flight"]
