"""Named time series of a flight and of an optimised cycle, each with its unit.

One place derives what recordings, plots and CSV files show, so the three agree. Inputs are
duck-typed so a partial run works too:

- a flight: :class:`fdm_awe.sim.report.FlightReport` (``.result`` a
  :class:`fdm_awe.sim.result.FlightResult`, plus ``track_error`` / ``reference_pos``) or a bare
  ``FlightResult``; any number of rows >= 1, NaN where a value does not exist yet (the
  ground-station columns of the initial row);
- an optimised cycle: a :class:`fdm_awe.trajectory.ReferenceTrajectory`, a
  :class:`fdm_awe.ocp.result.CycleResult` or the path of a reference-trajectory file.

Cumulative energies (J, all >= 0 except net) follow the project's electrical accounting
(``fdm_awe.sim.flight``): generated = energy into the load resistor, reel-in = energy drawn from
the supply, thrust = electrical energy of the glider's motor, net = generated - thrust - reel-in.
Per step the ground station reports ``p_elec = load - supply`` (mean over the step); the
machine is either a generator (supply 0) or a motor (load 0) within one step, so the positive
and negative parts of ``p_elec`` integrate to the load and supply energies exactly.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..trajectory import PHASE_NAMES


@dataclass
class Series:
    """Time series sharing one time axis ``t`` [s]: ``columns[name] = (unit, values)``.

    Names carry no unit; :meth:`csv_header` appends it (``tension`` + ``N`` -> ``tension_N``).
    ``phase`` holds one label per row; ``meta`` describes the run (scenario, config, wind...).
    A flight's series may also hold per row the cycle index of the reference point flown
    (``cycle``, -1 outside AUTO cycling) and the autopilot's mode (``mode``, e.g. ``AUTO``);
    None when the run does not tell.
    """

    t: np.ndarray
    columns: dict[str, tuple[str, np.ndarray]]
    phase: list[str]
    meta: dict[str, Any] = field(default_factory=dict)
    cycle: np.ndarray | None = None
    mode: list[str] | None = None

    def rows(self, idx: np.ndarray) -> "Series":
        """The rows ``idx`` (indices into ``t``) as a series of their own."""
        return Series(t=self.t[idx], columns={k: (u, v[idx]) for k, (u, v) in self.columns.items()},
                      phase=[self.phase[j] for j in idx], meta=self.meta,
                      cycle=None if self.cycle is None else self.cycle[idx],
                      mode=None if self.mode is None else [self.mode[j] for j in idx])

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name][1]

    def unit(self, name: str) -> str:
        return self.columns[name][0]

    def __contains__(self, name: str) -> bool:
        return name in self.columns

    def __len__(self) -> int:
        return len(self.t)

    @property
    def pos(self) -> np.ndarray:
        """(n, 3) NED position [m]."""
        return np.c_[self["x"], self["y"], self["z"]]

    def phase_segments(self) -> list[tuple[str, int, int]]:
        """Runs of equal phase as (label, first row, last row inclusive)."""
        out: list[tuple[str, int, int]] = []
        start = 0
        for i in range(1, len(self.phase) + 1):
            if i == len(self.phase) or self.phase[i] != self.phase[start]:
                out.append((self.phase[start], start, i - 1))
                start = i
        return out


def _unit_suffix(unit: str) -> str:
    """Unit text fit for a column name: ``m/s`` -> ``mps``, ``rad/s`` -> ``radps``, ``-`` -> ``1``."""
    return {"-": "1", "m/s": "mps", "rad/s": "radps", "m/s^2": "mps2", "deg": "deg"}.get(unit, unit.replace("/", "p"))


def csv_name(name: str, unit: str) -> str:
    """Column name with its unit: ``csv_name("tension", "N") == "tension_N"``."""
    return f"{name}_{_unit_suffix(unit)}"


def _cumtrapz(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    p = np.nan_to_num(np.asarray(p, float))
    if len(p) < 2:
        return np.zeros(len(p))
    return np.r_[0.0, np.cumsum(0.5 * (p[1:] + p[:-1]) * np.diff(t))]


def _cumrect(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Cumulative sum of step means: row k holds the mean over the step ending at row k."""
    p = np.nan_to_num(np.asarray(p, float))
    if len(p) < 2:
        return np.zeros(len(p))
    return np.r_[0.0, np.cumsum(p[1:] * np.diff(t))]


def flight_series(flight: Any) -> Series:
    """All recorded quantities of a flight (FlightReport or FlightResult), SI units."""
    res = getattr(flight, "result", None) or flight
    t = np.asarray(res.t, float)
    n = len(t)
    t = t - t[0] if n else t
    pos = np.asarray(res.pos, float)
    eul = np.asarray(res.euler, float)
    om = np.asarray(res.omega_body, float)
    ctl = np.asarray(res.controls, float)
    vel = np.asarray(res.vel, float)
    c: dict[str, tuple[str, np.ndarray]] = {
        "x": ("m", pos[:, 0]), "y": ("m", pos[:, 1]), "z": ("m", pos[:, 2]),
        "altitude": ("m", -pos[:, 2]), "distance": ("m", np.linalg.norm(pos, axis=1)),
        "vn": ("m/s", vel[:, 0]), "ve": ("m/s", vel[:, 1]), "vd": ("m/s", vel[:, 2]),
        "ground_speed": ("m/s", np.linalg.norm(vel, axis=1)),
        "roll": ("rad", eul[:, 0]), "pitch": ("rad", eul[:, 1]), "yaw": ("rad", eul[:, 2]),
        "p": ("rad/s", om[:, 0]), "q": ("rad/s", om[:, 1]), "r": ("rad/s", om[:, 2]),
        "airspeed": ("m/s", np.asarray(res.airspeed, float)), "alpha": ("rad", np.asarray(res.alpha, float)),
        "beta": ("rad", np.asarray(res.beta, float)), "fold": ("-", np.asarray(res.fold, float)),
        "thrust": ("N", np.asarray(res.thrust, float)), "prop_power": ("W", np.asarray(res.p_prop, float)),
        "load_factor": ("g", np.asarray(res.load_factor, float)),
        "tension": ("N", np.asarray(res.tension, float)), "tether_length": ("m", np.asarray(res.length, float)),
        "reel_speed": ("m/s", np.asarray(res.reel_speed, float)), "drum_speed": ("rad/s", np.asarray(res.omega, float)),
        "current": ("A", np.asarray(res.current, float)), "duty": ("-", np.asarray(res.duty, float)),
        "p_electrical": ("W", np.asarray(res.p_elec, float)),
        "aileron": ("-", ctl[:, 0]), "elevator": ("-", ctl[:, 1]), "rudder": ("-", ctl[:, 2]),
        "throttle": ("-", ctl[:, 3]), "fold_cmd": ("-", ctl[:, 4]),
    }
    pe = np.nan_to_num(c["p_electrical"][1])
    e_gen = _cumrect(np.maximum(pe, 0.0), t)
    e_rw = _cumrect(np.maximum(-pe, 0.0), t)
    e_thr = _cumtrapz(c["prop_power"][1], t)
    c["E_generated"] = ("J", e_gen)
    c["E_thrust"] = ("J", e_thr)
    c["E_reel_in"] = ("J", e_rw)
    c["E_net"] = ("J", e_gen - e_thr - e_rw)
    err = getattr(flight, "track_error", None)
    refp = getattr(flight, "reference_pos", None)
    c["track_error"] = ("m", _fit(err, n))
    rp = _fit(refp, n, 3)
    c["ref_x"], c["ref_y"], c["ref_z"] = ("m", rp[:, 0]), ("m", rp[:, 1]), ("m", rp[:, 2])
    labels = list(res.phase) if n else []
    labels = [p or "none" for p in labels]
    meta = {k: getattr(flight, k) for k in ("scenario", "config", "wind_mps", "status", "message") if hasattr(flight, k)}
    meta.setdefault("status", getattr(res, "status", "unknown"))
    if getattr(res, "event", None) is not None:
        meta.setdefault("message", res.event.message)
    cyc = getattr(flight, "cycle_index", None)
    cyc = getattr(res, "cycle_index", None) if cyc is None else cyc
    cycle = None if cyc is None else np.r_[np.asarray(cyc, float)[:n], np.full(max(0, n - len(cyc)), -1.0)]
    mode = getattr(res, "modes", None)
    if mode is None:
        mode = flight_modes(getattr(flight, "autopilot_log", None), np.asarray(res.t, float)) if n else None
    return Series(t=t, columns=c, phase=labels, meta=meta, cycle=cycle, mode=None if mode is None else list(mode)[:n])


#: the autopilot's note of a mode change (:meth:`fdm_awe.autopilot.vehicle_commands.VehicleCommands.set_mode`)
_MODE_NOTE = re.compile(r"^mode (\w+) -> (\w+)$")


def flight_modes(notes: Any, t: np.ndarray, start: str = "AUTO") -> list[str] | None:
    """The autopilot's mode at each time of ``t`` [s, the flight's own clock] from its notes
    (``(time s, text)``; a change is noted ``mode A -> B`` and holds from its time on): before
    the first change the mode it left, ``start`` when none was noted (a flight of a reference
    begins in AUTO). None without notes (a bare co-simulation result)."""
    if notes is None:
        return None
    changes = [(float(tn), m.group(1), m.group(2)) for tn, text in notes if (m := _MODE_NOTE.match(str(text)))]
    changes.sort(key=lambda c: c[0])
    first = changes[0][1] if changes else start
    names = [first] + [c[2] for c in changes]
    i = np.searchsorted(np.array([c[0] for c in changes], float), np.asarray(t, float), side="right")
    return [names[k] for k in i]


def _fit(a: Any, n: int, width: int | None = None) -> np.ndarray:
    """``a`` cut or NaN-padded to ``n`` rows (None -> all NaN)."""
    shape = (n,) if width is None else (n, width)
    out = np.full(shape, np.nan)
    if a is not None:
        a = np.asarray(a, float)
        m = min(n, len(a))
        out[:m] = a[:m]
    return out


def load_reference(ref: Any) -> Any:
    """A :class:`~fdm_awe.trajectory.ReferenceTrajectory` from a trajectory, a file path or a
    :class:`~fdm_awe.ocp.result.CycleResult` (:func:`fdm_awe.trajectory.as_reference`)."""
    from ..trajectory import as_reference

    return as_reference(ref)


def cycle_series(ref: Any) -> Series:
    """The optimised cycle (trajectory, file or CycleResult) as :class:`Series` over cycle time."""
    tr = load_reference(ref)
    cols = tr.columns
    md = tr.metadata
    names = list(md.get("phase_names", PHASE_NAMES))
    t = np.asarray(cols["t"], float)
    phase = [names[int(p)] if 0 <= int(p) < len(names) else str(int(p)) for p in cols["phase"]]
    units = {"x": "m", "y": "m", "z": "m", "V": "m/s", "gamma": "rad", "psi": "rad", "alpha": "rad", "phi": "rad",
             "T": "N", "tension": "N", "tether_length": "m", "reel_speed": "m/s", "fold": "-",
             "p_generated_W": "W", "p_thrust_W": "W", "p_reel_in_W": "W"}
    rename = {"V": "airspeed", "phi": "bank", "T": "thrust", "p_generated_W": "p_generated",
              "p_thrust_W": "p_thrust", "p_reel_in_W": "p_reel_in"}
    c: dict[str, tuple[str, np.ndarray]] = {}
    for k, u in units.items():
        if k in cols:
            c[rename.get(k, k)] = (u, np.asarray(cols[k], float))
    c["altitude"] = ("m", -c["z"][1])
    c["distance"] = ("m", np.sqrt(c["x"][1] ** 2 + c["y"][1] ** 2 + c["z"][1] ** 2))
    if "p_generated" in c:
        eg = _cumtrapz_phase(c["p_generated"][1], t)
        et = _cumtrapz_phase(c["p_thrust"][1], t)
        er = _cumtrapz_phase(c["p_reel_in"][1], t)
        c["E_generated"], c["E_thrust"], c["E_reel_in"] = ("J", eg), ("J", et), ("J", er)
        c["E_net"] = ("J", eg - et - er)
    meta = {k: md.get(k) for k in ("scenario", "config", "wind_mps", "status", "T1_s", "T2_s", "energies")}
    return Series(t=t, columns=c, phase=phase, meta=meta)


#: start-up transient [s] a robust plot range leaves out (the motor spinning up from rest, the
#: line taking the reference tension)
STARTUP_S = 1.0
#: percentile [%] a robust plot range cuts at each end
ROBUST_Q = 0.1


def robust_note() -> str:
    """How :func:`robust_range` (defaults) picks a range, for a panel title."""
    return f"y: {ROBUST_Q:g}-{100.0 - ROBUST_Q:g} % of the samples after the first {STARTUP_S:g} s"


def robust_range(t: np.ndarray, values: list[np.ndarray], *, skip_s: float = STARTUP_S, q: float = ROBUST_Q,
                 pad: float = 0.05) -> tuple[float, float] | None:
    """A y-range for ``values`` (arrays over ``t`` [s]) that a short spike does not stretch: the
    ``q`` and ``100 - q`` percentiles of the finite samples after the first ``skip_s`` seconds
    (all samples when fewer than 10 remain), widened by ``pad`` of the span on both sides. None
    when there is no finite sample."""
    t = np.asarray(t, float)
    late = t >= (t[0] + skip_s if len(t) else 0.0)
    picked = [np.asarray(v, float)[late] for v in values]
    vals = np.concatenate(picked) if picked else np.zeros(0)
    vals = vals[np.isfinite(vals)]
    if len(vals) < 10:
        vals = np.concatenate([np.asarray(v, float) for v in values]) if values else np.zeros(0)
        vals = vals[np.isfinite(vals)]
    if not len(vals):
        return None
    lo, hi = (float(x) for x in np.percentile(vals, [q, 100.0 - q]))
    span = hi - lo if hi > lo else max(abs(hi), 1.0)
    return lo - pad * span, hi + pad * span


def _cumtrapz_phase(p: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Cumulative trapezoid that adds nothing across a repeated time (the phase switch row)."""
    p = np.nan_to_num(np.asarray(p, float))
    dt = np.diff(t)
    inc = 0.5 * (p[1:] + p[:-1]) * dt
    inc[dt <= 1e-12] = 0.0
    return np.r_[0.0, np.cumsum(inc)]


__all__ = ["ROBUST_Q", "STARTUP_S", "Series", "csv_name", "cycle_series", "flight_modes", "flight_series",
           "load_reference", "robust_note", "robust_range"]
