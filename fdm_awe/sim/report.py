"""The report of a flight (:func:`fdm_awe.sim.flight.fly`): its status, per-cycle numbers, energy
ledger and logs, and its JSON (docs/design.md section 1). Statuses, energy terms and the
ledger are described in :mod:`fdm_awe.sim.flight`."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import EXIT_INTERRUPTED

#: what each plant is (written into the flight's JSON)
PLANT_NOTES = {
    "physical": "JSBSim 9x5 propeller and motor; ground station with DC machine, converter and PI speed loop",
    "paper": "paper scenario's simplifications: ideal thruster (body-x force, power by the P(T) fit), "
             "kinematic winch on an elastic line (generation booked as tension x reel speed, reel-in at constant power)",
}

#: statuses of a flight (:mod:`fdm_awe.sim.flight`); other ground-station events appear by name
FLIGHT_STATUSES = ("ok", "incomplete", "interrupted", "landed", "parked", "ground_contact", "tether_break",
                   "nonfinite", "airspeed_limit", "load_limit")

#: the statuses that end a flight as RECOVER meant it to (:func:`flight_exit_code`)
RECOVERED = ("landed", "parked")


def flight_exit_code(status: str, recover_cause: str | None) -> int:
    """The exit code of ``fdm-awe fly`` for a flight that ended with ``status`` (docs/design.md
    section 1): 0 when it did what it was asked, 1 when not, 130 after Ctrl-C.

    ``ok`` (every requested cycle flown to its end, or the requested length) is 0. ``landed``
    and ``parked`` are 0 only when RECOVER was asked for (``recover_cause`` "commanded": the
    start mode, the ground station's mode change or RTL, its clearing of the mission); after a
    failsafe took the glider out of its cycles (the lost path, the lost link) the glider is
    safe but the requested cycles were not flown: 1. ``interrupted`` is 130; ``incomplete``,
    the co-simulation's events and the ground station's are 1."""
    if status == "interrupted":
        return EXIT_INTERRUPTED
    if status == "ok":
        return 0
    if status in RECOVERED and recover_cause == "commanded":
        return 0
    return 1


@dataclass
class CycleMetrics:
    """One cycle of a flight: ``index`` (0-based), times flown in generation ``T1_s`` and in
    recovery ``T2_s`` (s, >= 0), energies (J; :mod:`fdm_awe.sim.flight`; all >= 0 except ``E_net_J``),
    position tracking error RMS and maximum (m; NaN when no step of the cycle had a reference
    point), and whether the cycle was flown to its end (``complete``)."""

    index: int
    T1_s: float
    T2_s: float
    E_generated_J: float
    E_thrust_J: float
    E_reel_in_J: float
    E_net_J: float
    track_rms_m: float
    track_max_m: float
    complete: bool

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: floats rounded to 6 decimals, NaN as None."""
        return {k: (_json_float(v) if isinstance(v, float) else v) for k, v in self.__dict__.items()}


def _json_float(v: float, digits: int = 6) -> float | None:
    """``v`` rounded for JSON, None when not finite (JSON never carries NaN)."""
    v = float(v)
    return round(v, digits) if math.isfinite(v) else None


@dataclass
class FlightReport:
    """What :func:`fdm_awe.sim.flight.fly` returns: the run's facts (wind m/s, simulated and wall
    time s), its status and message, per-cycle numbers, the energy ledger (J) with its largest
    relative residual, and the logs (the co-simulation's result, tracking error m, reference
    position m NED, the autopilot's notes with the flight's logged events, the lumped line's
    shape) and the armature current against the machine's ratings (physical plant)."""

    scenario: str
    config: str
    wind_mps: float
    status: str
    message: str
    sim_time_s: float
    wall_s: float
    cycles: list[CycleMetrics]
    ledger: dict[str, Any]
    ledger_residual_rel: float
    result: Any = field(repr=False, default=None)  #: fdm_awe.sim.result.FlightResult
    track_error: np.ndarray | None = field(repr=False, default=None)
    reference_pos: np.ndarray | None = field(repr=False, default=None)
    #: (time s, note): the autopilot's notes and the flight's logged events (``machine_current``)
    autopilot_log: list[tuple[float, str]] = field(default_factory=list)
    plant: str = "physical"  #: "physical" or "paper" (see PLANT_NOTES)
    tether_drag_scale: float = 1.0  #: factor on the line drag the ground station applied (1 = the defined line)
    line: str | None = None  #: the tether line flown (:data:`fdm_awe.groundstation.line.LINES`)
    #: the generator load the winch flew in generation (reference metadata ``generator``;
    #: None on the paper plant, whose kinematic winch has none)
    generator: str | None = None
    tether: str = "straight"  #: the line model: "straight" or "lumped:N"
    #: the lumped line's shape sampled at :data:`fdm_awe.sim.flight_log.LINE_SHAPE_HZ`: ``t`` (m,) s,
    #: ``nodes`` (m, N+1, 3) m NED winch first, ``tension`` (m, N) N per segment; None for the straight line
    line_shape: dict[str, np.ndarray] | None = field(repr=False, default=None)
    peak_current_A: float | None = None  #: largest armature current, A (None on the paper plant)
    #: time the armature current spent above the machine's rated current, s (None on the paper plant)
    time_above_rated_current_s: float | None = None
    #: surface motion above 0.5 Hz (:class:`fdm_awe.sim.activity.ControlActivity`), None before a run
    control_activity: Any = None
    #: how the steps ran: ``loop`` "compiled" or "python" (and why not compiled), the steps the
    #: autopilot flew compiled in blocks (:mod:`fdm_awe.sim.autopilot_kernel`), the rest with the
    #: autopilot in Python
    loop: dict[str, Any] = field(default_factory=dict)
    #: the turbulence flown (:func:`fdm_awe.sim.flight.fly`): the form, its JSBSim parameters,
    #: targets and the measured turbulence at the glider; None in calm air
    turbulence: dict[str, Any] | None = None
    #: the onboard wind estimate per cycle against the true mean wind at the glider, and the
    #: reference flown with a reference set (:meth:`fdm_awe.sim.onboard_wind.CycleWind.close`)
    wind_estimates: list[dict[str, Any]] = field(default_factory=list)
    #: why the flight ended in RECOVER (:attr:`fdm_awe.autopilot.autopilot.Autopilot.recover_cause`):
    #: None (not in RECOVER), "commanded", or the failsafe's note
    recover_cause: str | None = None
    #: per row of ``result``: the cycle index of the reference point flown (0-based; -1 outside
    #: AUTO cycling), what :func:`fdm_awe.sim.cycles.segment_cycles` cuts the cycles by
    cycle_index: np.ndarray | None = field(repr=False, default=None)
    #: the aircraft flown (:meth:`fdm_awe.definitions.catalog.Aircraft.record`: table name or
    #: folder, content hash) with its mass ``mass_kg`` [kg]; None before a run
    aircraft: dict[str, Any] | None = None
    #: the ground station flown (:meth:`fdm_awe.groundstation.source.StationFile.record`: ``file``
    #: "default" or the path of a user's definition, and ``sha256``); None before a run
    ground_station: dict[str, str] | None = None

    @property
    def exit_code(self) -> int:
        """The exit code of ``fdm-awe fly`` for this flight (:func:`flight_exit_code`)."""
        return flight_exit_code(self.status, self.recover_cause)

    @property
    def realtime_factor(self) -> float:
        return self.sim_time_s / self.wall_s if self.wall_s > 0 else float("inf")

    def as_json(self) -> dict[str, Any]:
        """docs/design.md section 1 output contract of ``fdm-awe fly``.

        ``status``: one of :data:`FLIGHT_STATUSES` or a ground-station event name (:mod:`fdm_awe.sim.flight`:
        ``ok`` only when every requested cycle was completed; ``incomplete`` when the time cap
        ended the flight first; ``interrupted`` after Ctrl-C; ``landed``; event names). Each
        cycle carries ``complete``. Numbers that cannot be computed (e.g. the tracking error
        of a cycle without a reference point) are ``null``: the JSON never carries NaN."""
        return {
            "scenario": self.scenario, "plant": self.plant, "plant_note": PLANT_NOTES.get(self.plant, ""),
            "config": self.config, "aircraft": _json_tree(self.aircraft),
            "ground_station": _json_tree(self.ground_station), "wind_mps": _json_float(self.wind_mps), "tether_drag_scale": self.tether_drag_scale,
            "line": self.line, "generator": self.generator, "tether": self.tether,
            "status": self.status, "recover_cause": self.recover_cause,
            "message": self.message, "sim_time_s": _json_float(self.sim_time_s), "wall_s": _json_float(self.wall_s, 3),
            "realtime_factor": _json_float(self.realtime_factor, 1),
            "ledger_residual_rel": _json_float(float(f"{self.ledger_residual_rel:.3e}"), 12),
            "peak_current_A": None if self.peak_current_A is None else _json_float(self.peak_current_A),
            "time_above_rated_current_s": (None if self.time_above_rated_current_s is None
                                           else _json_float(self.time_above_rated_current_s)),
            "ledger": {k: (_json_float(v) if isinstance(v, float) else v) for k, v in self.ledger.items()},
            "cycles": [c.as_dict() for c in self.cycles],
            "control_activity": None if self.control_activity is None else
            {k: _json_float(v) for k, v in self.control_activity.as_dict().items()},
            "loop": dict(self.loop),
            "turbulence": _json_tree(self.turbulence),
            "wind_estimates": [_json_tree(r) for r in self.wind_estimates],
        }


def _json_tree(v: Any) -> Any:
    """``v`` (nested dicts, lists, numbers) JSON-ready: floats as :func:`_json_float`."""
    if isinstance(v, dict):
        return {k: _json_tree(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_json_tree(x) for x in v]
    if isinstance(v, float):
        return _json_float(v)
    return v
