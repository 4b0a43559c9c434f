"""A recording that survives whatever ends the flight.

The co-simulation turns Ctrl-C and flight events into a normal result, which
:func:`~fdm_awe.recording.flight.record_flight` records. An exception raised inside the loop
(a controller bug, a failed assertion) propagates instead and takes the result with it.
:class:`FlightRecording` keeps a light copy of every step (about 20 floats, read through the
step callback) so that the recording is written from the steps flown in every case::

    with FlightRecording("run.rrd", reference) as rec:
        report = fly(reference, ..., on_step=rec, setup=rec.setup)
        rec.finish(report)          # full recording from the report
    # on an exception: the steps flown so far are recorded (status "aborted"), then it re-raises

Cost: one tuple per step (a few microseconds against a step of several hundred). The
propulsion columns are booked as :func:`fdm_awe.sim.flight.fly` books them in its report: the
paper plant's ideal thruster (its thrust and P(T) power), else the propeller's thrust and its
motor's electrical input plus the constant draw P0.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from ..sim.cycles import NO_CYCLE, step_reference
from ..sim.propulsion import logged_propulsion

STEP_FIELDS = ("t", "x", "y", "z", "phi", "theta", "psi", "airspeed", "alpha", "beta", "fold", "thrust", "p_prop",
           "load_factor", "tension", "length", "reel_speed", "omega", "current", "duty", "p_elec")


class StepBuffer:
    """Step callback ``(k, state, gs_output)`` plus ``setup(autopilot, cosim)`` hook that keeps
    a light copy of every step (:attr:`rows`; per row the phase label in :attr:`phases`, the
    autopilot's mode in :attr:`modes` and the cycle index of the reference point flown in
    :attr:`cycles`, -1 outside AUTO cycling)."""

    #: the buffered values of a row, in order (names of :data:`fdm_awe.sim.result.COLUMNS`)
    fields: tuple[str, ...] = STEP_FIELDS

    def __init__(self, *, chain: Any = None) -> None:
        self.chain = chain  #: another on_step callback to call after this one
        self.rows: list[tuple] = []
        self.phases: list[str] = []
        self.modes: list[str] = []
        self.cycles: list[int] = []
        self._ap: Any = None
        self._thruster: Any = None
        self._p0 = 0.0

    def setup(self, autopilot: Any, cosim: Any = None) -> None:
        """Keep the autopilot (for its phase and the propulsion booking) and the initial state
        (the first row, as the co-simulation logs it: no ground-station values yet)."""
        self._ap = autopilot
        self._thruster = getattr(autopilot, "thruster", None)
        airframes = getattr(autopilot, "airframes", None)
        self._p0 = float(airframes.unfolded.propulsion.P0) if airframes is not None else 0.0
        glider = getattr(cosim, "glider", None)
        if glider is not None and not self.rows:
            self.rows.append(self._row(glider.state(), None))
            self.phases.append(getattr(autopilot, "phase", "") or "")
            self._labels(autopilot)

    def _labels(self, ap: Any) -> None:
        """The mode and the cycle label of the step just flown (as the flight's log labels it)."""
        self.modes.append(str(getattr(ap, "mode", "")) if ap is not None else "")
        rp = step_reference(ap) if ap is not None and hasattr(ap, "ref_point") else None
        self.cycles.append(NO_CYCLE if rp is None else int(rp.cycle))

    def _row(self, s: Any, o: Any) -> tuple:
        """The values of :attr:`fields` after a step (``o`` the ground station's output, None
        before the first step)."""
        thrust, p_prop = logged_propulsion(s.thrust_N, s.prop_power_W, self._p0, self._thruster)
        gs = (math.nan,) * 7 if o is None else (o.tension, o.length, o.reel_speed, o.omega, o.current, o.duty,
                                                o.p_electrical)
        return (s.t, s.x, s.y, s.z, s.phi, s.theta, s.psi, s.airspeed, s.alpha, s.beta, s.fold, thrust, p_prop,
                s.load_factor) + gs

    def __call__(self, k: int, s: Any, o: Any) -> None:
        self.rows.append(self._row(s, o))
        ap = self._ap
        self.phases.append(getattr(ap, "phase", "") if ap is not None else "")
        self._labels(ap)
        if self.chain is not None:
            self.chain(k, s, o)

    def partial_result(self, status: str = "aborted", message: str = "", rows: slice = slice(None)) -> Any:
        """The buffered steps (``rows`` of them) as a :class:`~fdm_awe.sim.result.FlightResult`;
        what :attr:`fields` lacks is NaN (controls), the ground velocity, when not buffered, by
        differences of the positions. The result also carries the rows' ``modes`` and
        ``cycle_index`` (read by :func:`~fdm_awe.recording.series.flight_series`)."""
        from ..sim.result import COLUMNS, Event, FlightResult

        buffered, phases = self.rows[rows], self.phases[rows]
        n = len(buffered)
        data = np.full((n, len(COLUMNS)), np.nan)
        labels: list[str] = []
        if n:
            a = np.asarray(buffered, dtype=float)
            col = {name: i for i, name in enumerate(COLUMNS)}
            f = {name: a[:, i] for i, name in enumerate(self.fields)}
            for name, values in f.items():
                data[:, col[name]] = values
            data[:, col["qw"]:col["qz"] + 1] = _euler_to_quat(f["phi"], f["theta"], f["psi"])
            if n > 1 and "vn" not in f:  # ground velocity by differences (the callback does not copy it)
                v = np.gradient(a[:, 1:4], a[:, 0], axis=0)
                data[:, col["vn"]:col["vd"] + 1] = v
            labels = sorted(set(phases))
            codes = {p: i for i, p in enumerate(labels)}
            data[:, col["phase"]] = [codes[p] for p in phases]
        t_end = float(data[-1, 0]) if n else 0.0
        dt = float(np.median(np.diff(data[:, 0]))) if n > 1 else math.nan
        res = FlightResult(status=status, event=Event(status, t_end, message or status), data=data,
                           phase_labels=labels, dt=dt, wall_s=0.0, steps=max(n - 1, 0))
        if len(self.modes) == len(self.rows):  # the autopilot was known from the first row
            res.modes = self.modes[rows]
            res.cycle_index = np.asarray(self.cycles[rows], dtype=float)
        return res


class FlightRecording(StepBuffer):
    """A :class:`StepBuffer` (the ``setup`` hook only to read the autopilot's phase label and
    propulsion each step) that writes ``path`` on :meth:`finish` or, failing that, from the
    buffered steps when the ``with`` block ends."""

    def __init__(self, path: str | Path, reference: Any = None, *, chain: Any = None) -> None:
        super().__init__(chain=chain)
        self.path = Path(path)
        self.reference = reference
        self.finished: Path | None = None

    def finish(self, report: Any = None) -> Path:
        """Write the recording: from ``report`` (FlightReport/FlightResult) when given, else
        from the buffered steps."""
        from .flight import record_flight

        flight = report if report is not None else self.partial_result()
        self.finished = record_flight(flight, self.reference, self.path)
        return self.finished

    def __enter__(self) -> "FlightRecording":
        return self

    def __exit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
        if self.finished is None:
            from .flight import record_flight

            status = "aborted" if exc_type is not None else "unfinished"
            msg = f"{exc_type.__name__}: {exc}" if exc_type is not None else "flight not finished"
            self.finished = record_flight(self.partial_result(status, msg), self.reference, self.path)


def _euler_to_quat(phi: np.ndarray, theta: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """(n, 4) quaternions (w, x, y, z) of ZYX Euler angles (same convention as the JSBSim adapter)."""
    cr, sr = np.cos(0.5 * phi), np.sin(0.5 * phi)
    cp, sp = np.cos(0.5 * theta), np.sin(0.5 * theta)
    cy, sy = np.cos(0.5 * psi), np.sin(0.5 * psi)
    return np.stack((cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
                     cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy), axis=1)


__all__ = ["FlightRecording", "StepBuffer"]
