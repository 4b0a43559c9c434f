"""The result of a co-simulation run (:class:`fdm_awe.sim.loop.CoSim`): its statuses, the event
that ended it, the logged columns (:data:`COLUMNS`, SI units, angles rad) and
:class:`FlightResult`, which names them."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

STATUSES = ("ok", "ground_contact", "tether_break", "nonfinite", "airspeed_limit", "load_limit", "interrupted")


@dataclass(frozen=True)
class Event:
    """What ended a run: ``kind`` (one of the statuses), time s, one-line message."""

    kind: str
    t: float
    message: str


# Logged columns, in order (SI units; angles rad).
COLUMNS: tuple[str, ...] = (
    "t", "x", "y", "z", "vn", "ve", "vd", "qw", "qx", "qy", "qz", "phi", "theta", "psi", "p", "q", "r",
    "airspeed", "alpha", "beta", "fold", "thrust", "p_prop", "load_factor",
    "tension", "length", "reel_speed", "omega", "current", "duty", "p_elec",
    "fx", "fy", "fz", "aileron", "elevator", "rudder", "throttle", "fold_cmd", "phase",
    "wind_n", "wind_e", "wind_d",
)
_C = {name: i for i, name in enumerate(COLUMNS)}
#: column ranges of the vector-valued names: (first, end)
_SPANS = {"pos": (_C["x"], _C["z"] + 1), "vel": (_C["vn"], _C["vd"] + 1), "quat": (_C["qw"], _C["qz"] + 1),
          "euler": (_C["phi"], _C["psi"] + 1), "omega_body": (_C["p"], _C["r"] + 1),
          "tether_force": (_C["fx"], _C["fz"] + 1), "controls": (_C["aileron"], _C["fold_cmd"] + 1),
          "wind": (_C["wind_n"], _C["wind_d"] + 1)}
#: the ground station's logged columns (tension .. fz)
_GS_SPAN = (_C["tension"], _C["fz"] + 1)
#: logged columns (or ranges, see _SPANS) from the glider's converted rows: (column, JSBSimGlider.convert_raw key)
_FROM_STATE = (("t", "t"), ("pos", "pos_ned"), ("vel", "vel_ned"), ("quat", "quat"), ("euler", "euler"),
               ("omega_body", "omega_body"), ("airspeed", "airspeed"), ("alpha", "alpha"), ("beta", "beta"),
               ("fold", "fold"), ("thrust", "thrust_N"), ("p_prop", "prop_power_W"), ("load_factor", "load_factor"),
               ("wind", "wind_ned"))
#: the ground station's logged columns, in the order of its per-step record
STATION_COLUMNS = COLUMNS[_GS_SPAN[0]:_GS_SPAN[1]]


@dataclass
class FlightResult:
    """A co-simulation run: ``status`` (see :data:`STATUSES`), the ending ``event`` (None when
    the run reached ``t_end``), and the logged time series (one row per step plus the initial
    row; SI units). Named arrays: ``t``, ``pos`` (n,3), ``vel`` (n,3), ``quat`` (n,4),
    ``euler`` (n,3), ``omega_body`` (n,3), ``airspeed``, ``alpha``, ``beta``, ``fold``,
    ``thrust``, ``p_prop``, ``load_factor``, ``tension``, ``length``, ``reel_speed``,
    ``omega`` (drum), ``current``, ``duty``, ``p_elec``, ``tether_force`` (n,3), ``controls``
    (n,5: aileron, elevator, rudder, throttle, fold_cmd), ``phase`` (labels per row), ``wind``
    (n,3: the total wind at the glider's CG, steady and turbulence, NED).
    Ground-station columns of the initial row are NaN (no step yet)."""

    status: str
    event: Event | None
    data: np.ndarray
    phase_labels: list[str]
    dt: float
    wall_s: float
    steps: int

    def __getattr__(self, name: str) -> np.ndarray:
        """A logged column (:data:`COLUMNS`) or a vector's columns (``pos``, ``vel``, ``quat``,
        ``euler``, ``omega_body``, ``tether_force``, ``controls``, ``wind``) as a view of ``data``."""
        if "data" in self.__dict__:
            if name in _C:
                return self.__dict__["data"][:, _C[name]]
            if name in _SPANS:
                a, b = _SPANS[name]
                return self.__dict__["data"][:, a:b]
        raise AttributeError(name)

    @property
    def phase(self) -> list[str]:
        codes = self.data[:, _C["phase"]]
        return [self.phase_labels[int(c)] if c == c else "" for c in codes]

    @property
    def sim_time_s(self) -> float:
        t = _C["t"]
        return float(self.data[-1, t] - self.data[0, t]) if len(self.data) else 0.0

    @property
    def realtime_factor(self) -> float:
        return self.sim_time_s / self.wall_s if self.wall_s > 0 else float("inf")

    def truncate(self, steps: int) -> None:
        """Keep the first ``steps`` steps (rows ``0 .. steps``), e.g. the steps a caller booked
        whole before an interruption."""
        steps = max(0, min(int(steps), self.steps))
        self.data = self.data[: steps + 1]
        self.steps = steps
        if self.event is not None and self.event.kind == "interrupted" and len(self.data):
            self.event = Event("interrupted", float(self.data[-1, _C["t"]]), self.event.message)


def log_table(convert_raw: Callable[[np.ndarray], dict[str, np.ndarray]], raws: np.ndarray, gsrec: np.ndarray,
              ctl: list, phases: list | None) -> np.ndarray:
    """The logged columns (:data:`COLUMNS`) of a run's rows: the glider's raw JSBSim rows ``raws``
    converted to SI by ``convert_raw`` (:meth:`JSBSimGlider.convert_raw`), the ground station's
    records ``gsrec`` (:data:`STATION_COLUMNS`), the commands ``ctl`` (:class:`Surfaces`, or the
    five values as a list) and the phase
    codes ``phases`` (None: no phase; a negative code: NaN)."""
    n = len(raws)
    data = np.full((n, len(COLUMNS)), np.nan)
    if n == 0:
        return data
    si = convert_raw(raws)
    for name, key in _FROM_STATE:
        if name in _SPANS:
            i, j = _SPANS[name]
            data[:, i:j] = si[key]
        else:
            data[:, _C[name]] = si[key]
    i, j = _GS_SPAN
    data[:, i:j] = gsrec
    i, j = _SPANS["controls"]
    # a row's commands: a Surfaces, or the five values as a list (the rows of a compiled block)
    data[:, i:j] = np.array([c if type(c) is list else (c.aileron, c.elevator, c.rudder, c.throttle, c.fold_cmd)
                             for c in ctl])
    if phases is not None:
        ph = np.array(phases[:n], dtype=float)
        ph[ph < 0] = np.nan
        data[: len(ph), _C["phase"]] = ph
    return data


__all__ = ["COLUMNS", "STATION_COLUMNS", "STATUSES", "Event", "FlightResult", "log_table"]
