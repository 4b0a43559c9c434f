"""The reference trajectory: one periodic pumping cycle of the optimiser, its file, its phases
and how it is sampled at any time.

Every user of an optimised cycle goes through this module: the optimiser writes the file
(:func:`write_reference`), ``fdm-awe fly`` hands the cycle it optimised to the flight in memory
(:func:`reference_from_result`, the content of the file it would write), the autopilot's
:class:`~fdm_awe.autopilot.tracking.TrackingReference` and the recordings sample it with
:class:`CycleSampler`.

Phases (:data:`PHASE_NAMES`, codes :data:`GENERATION` = 0 and :data:`RECOVERY` = 1): a cycle is
one generation phase from ``t = 0`` to ``T1``, then one recovery phase to ``T1 + T2``.

Reference-trajectory file format (``fdm-awe-reference-trajectory``, version 1), JSON::

    {
      "format": "fdm-awe-reference-trajectory", "version": 1,
      "metadata": {"scenario", "config", "wind_mps", "wind_from_deg", "wind_ned_mps" [3],
                   "d0_m", "d_tf_m", "elevation0_deg", "azimuth0_deg", "T1_s", "T2_s",
                   "period_s", "k_wrap", "mesh": {...}, "energies": {...}, "status",
                   "phase_names": ["generation", "recovery"], "recovery_airframe"},
      "units": {column: unit},
      "columns": {column: [values...]}
    }

Columns (one row per collocation point, rows in time order; the phase switch at ``t = T1``
appears twice, once per phase):

- ``t`` [s] cycle time, 0 .. T1 + T2; ``phase`` 0 = generation, 1 = recovery;
- ``x, y, z`` [m] NED glider position (winch at the origin); ``V`` [m/s] airspeed;
  ``gamma, psi`` [rad] air-path angles (``psi`` continuous, not wrapped);
- ``alpha, phi`` [rad], ``T`` [N] controls (piecewise constant per mesh interval: each row
  carries the value of the interval that starts at or contains it);
- ``tension`` [N] tether tension (0 in recovery), ``tether_length`` [m], ``reel_speed`` [m/s]
  (> 0 paid out), ``fold`` (0 unfolded, 1 folded);
- ``p_generated_W, p_thrust_W, p_reel_in_W`` [W] the scenario's power terms;
- optional ``motor_on`` (0 .. 1): the motor's on-fraction of the interval (motor-off mode;
  ``T`` is then the mean thrust); absent = 1, the motor runs throughout;
- optional ``boost_duty`` (0 .. 1): the generator's T2 duty of the interval (generator
  ``boost``; 0 in recovery); absent = 0, the passive rectifier.

Metadata: ``scenario`` (physical | paper) and ``config`` (foldable | nominal) are required;
``T1_s``, ``T2_s`` [s] > 0 (at most 3600 each) are required; the wind is given as ``wind_mps``
(0..25 m/s) with ``wind_from_deg``, or as the horizontal vector ``wind_ned_mps``, or both
(then they must agree); ``tether_drag_scale`` (0..10, default 1), ``period_s`` (= T1 + T2),
``status`` (ok), ``recovery_airframe`` (folded for foldable, unfolded for nominal),
``propeller``, ``line_weight``, ``d0_m`` < ``d_tf_m`` are checked when present; ``line`` (the
tether line the cycle was optimised with, :data:`fdm_awe.groundstation.line.LINES`) is checked
when present; absent means ``paper`` (Table 1's line): every file written before lines were
named was optimised with it, and a flight flies it. ``fold_time_s`` [s] (0 .. 60; 0 for the
nominal config) is the fold (and unfold) time the cycle was optimised with; absent means 0, the
instantaneous fold every file written before fold transitions was optimised with.
``motor_off`` (boolean) says whether the optimiser could stop the motor (column ``motor_on``);
absent means false, and then ``motor_on`` (if present) must be 1 throughout. ``generator``
(physical scenario: :data:`fdm_awe.ocp.problem.GENERATORS`) is the generator load of the
generation phase; absent means ``passive``, and then ``boost_duty`` (if present) must be 0
throughout. ``wind_profile`` (:meth:`fdm_awe.wind.WindProfile.as_dict`: ``kind`` uniform | log |
power, with ``ref_height_m`` and ``z0_m`` or ``exponent``) says how the wind varies with height;
``wind_mps`` / ``wind_ned_mps`` are then the wind at ``ref_height_m``; absent means uniform, the
wind of every file written before profiles existed.

:func:`read_reference` checks a file field by field (:func:`check_reference_document`, then
:func:`check_reference`: every column a list of finite numbers within :data:`COLUMN_RANGES`,
all of one length, at least 2 rows; ``t`` from 0 strictly increasing to T1 + T2 except one
repeated time at the phase switch; ``phase`` 0 then 1 with the switch at T1; ``fold`` 0 for
the nominal config). A malformed file raises :class:`~fdm_awe.errors.InputError` with one line
naming the file, the field and the allowed range or form. It returns a
:class:`ReferenceTrajectory` with NumPy columns, the completed metadata (both wind forms,
``period_s``, ``tether_drag_scale``) and a ``sample(t)`` helper (:data:`REFERENCE_RULES`).
:func:`write_reference` runs the same checks before it writes, atomically.

Sampling (:class:`CycleSampler`, one implementation for every user): the cycle repeats with the
period ``T1 + T2`` (cycle ``k = floor(t / period)``, cycle time ``t - k * period``; generation
while the cycle time is below ``T1``). A cycle time falls into the segment between the last row
at or before it and the next row (before the first row: the first segment; at or after the last
row: the last one); at a time stored twice (the phase switch) the later row, the new phase,
opens the segment. Each column has a named rule:

- :data:`LINEAR`: linear in time across the segment, ``a_i (1 - w) + a_(i+1) w`` with
  ``w = (t - t_i) / (t_(i+1) - t_i)`` clipped to 0 .. 1. With the switch row stored once per
  phase (the file) this is linear within a phase; the autopilot's
  :class:`~fdm_awe.autopilot.tracking.TrackingReference` stores it once, so its first recovery
  segment runs from the generation's last row;
- :data:`HELD`: held per optimiser interval: the value of the row opening the segment (each row
  carries the value of its interval), the closing row's when the segment crosses a phase switch
  (a segment belongs to the phase of the row closing it).

The file's own meaning is :data:`REFERENCE_RULES` (states and derived quantities linear, the
optimiser's controls ``alpha, phi, T``, ``fold``, ``motor_on``, ``boost_duty`` held); the
autopilot's is :data:`fdm_awe.autopilot.tracking.TRACKING_RULES`.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from .errors import InputError

#: Phase names of a cycle, indexed by phase code (metadata ``phase_names``)
PHASE_NAMES = ("generation", "recovery")
#: Phase codes (column ``phase``)
GENERATION, RECOVERY = 0, 1

FORMAT = "fdm-awe-reference-trajectory"
VERSION = 1

COLUMN_UNITS = {
    "t": "s", "phase": "-", "x": "m", "y": "m", "z": "m", "V": "m/s", "gamma": "rad", "psi": "rad",
    "alpha": "rad", "phi": "rad", "T": "N", "tension": "N", "tether_length": "m", "reel_speed": "m/s",
    "fold": "-", "p_generated_W": "W", "p_thrust_W": "W", "p_reel_in_W": "W",
}
#: Columns a reference may carry beyond the required :data:`COLUMN_UNITS` (absent: the default)
OPTIONAL_COLUMN_UNITS = {"motor_on": "-", "boost_duty": "-"}

# ------------------------------------------------------------------------------------ sampling

#: Sampling rule: linear in time across the segment (see the module docstring)
LINEAR = "linear"
#: Sampling rule: held per optimiser interval (see the module docstring)
HELD = "held"
RULES = (LINEAR, HELD)

#: How a reference file's columns are sampled (:meth:`ReferenceTrajectory.sample`): the states and
#: what follows from them linear in time within a phase, the optimiser's controls held per interval
#: as stored; a column not named here is linear.
REFERENCE_RULES: dict[str, str] = {
    "x": LINEAR, "y": LINEAR, "z": LINEAR, "V": LINEAR, "gamma": LINEAR, "psi": LINEAR,
    "alpha": HELD, "phi": HELD, "T": HELD, "tension": LINEAR, "tether_length": LINEAR, "reel_speed": LINEAR,
    "fold": HELD, "p_generated_W": LINEAR, "p_thrust_W": LINEAR, "p_reel_in_W": LINEAR,
    "motor_on": HELD, "boost_duty": HELD,
}


class CycleSample:
    """One sample of a :class:`CycleSampler`: ``cycle`` (0-based), ``t_cycle`` [s], ``phase``
    (:data:`GENERATION` or :data:`RECOVERY`), ``segment`` (index of the row opening it) and
    ``weight`` (0 .. 1 across it); ``sample[name]`` is a column's value (a float, or a NumPy
    array for a column with several components, e.g. a position)."""

    __slots__ = ("cycle", "t_cycle", "phase", "segment", "weight", "_row", "_sampler")

    def __init__(self, sampler: "CycleSampler", cycle: int, t_cycle: float, phase: int, segment: int,
                 weight: float, row: np.ndarray) -> None:
        self._sampler = sampler
        self.cycle, self.t_cycle, self.phase, self.segment, self.weight = cycle, t_cycle, phase, segment, weight
        self._row = row

    def __getitem__(self, name: str) -> Any:
        j = self._sampler._where.get(name)
        if j is not None:
            return self._row[j]
        return float(self._sampler._held[name][self.segment])


class CycleSampler:
    """One periodic cycle of rows, evaluated at any time with a named rule per column.

    Args:
        t: row times [s], non-decreasing from the cycle start; a time may repeat only where the
            phase changes (the switch row stored once per phase).
        phase: phase code of each row.
        columns: name -> values per row (``(n,)``, or ``(n, k)`` for a vector such as a position).
        rules: name -> :data:`LINEAR` or :data:`HELD` for every name of ``columns`` (held columns
            one value per row).
        T1: cycle time of the phase switch [s]; the phase of a sample is generation below it.
        period: cycle period [s] (> 0).

    The rules are those of the module docstring; :meth:`sample` returns a :class:`CycleSample`.
    """

    def __init__(self, t: Any, phase: Any, columns: Mapping[str, Any], rules: Mapping[str, str], T1: float,
                 period: float) -> None:
        t = np.asarray(t, float)
        phase = np.asarray(phase)
        n = len(t)
        if n < 2 or t.shape != (n,) or phase.shape != (n,):
            raise ValueError("a cycle sampler needs at least 2 rows of times and phases")
        dt = np.diff(t)
        if not np.all(np.isfinite(t)) or np.any(dt < 0.0) or np.any((dt == 0.0) & (phase[:-1] == phase[1:])):
            raise ValueError("sampler times must be finite and increasing (a time repeated only at a phase switch)")
        if not (math.isfinite(period) and period > 0.0):
            raise ValueError(f"sampler period {period!r}: allowed > 0 s")
        self.t, self.phase, self.T1, self.period = t, phase, float(T1), period
        lin: list[np.ndarray] = []
        self._where: dict[str, int | slice] = {}
        self._held: dict[str, np.ndarray] = {}
        self.rules = dict(rules)
        col = 0
        for name, values in columns.items():
            rule = rules.get(name)
            a = np.asarray(values, float)
            if rule not in RULES:
                raise ValueError(f"sampler column {name}: rule {rule!r}, allowed {', '.join(RULES)}")
            if a.shape[:1] != (n,) or a.ndim > 2 or (rule == HELD and a.ndim != 1):
                raise ValueError(f"sampler column {name}: shape {a.shape}, expected ({n},)"
                                 + ("" if rule == HELD else f" or ({n}, k)"))
            if rule == HELD:
                # a segment belongs to the phase of the row closing it
                self._held[name] = np.where(phase[:-1] == phase[1:], a[:-1], a[1:])
            elif a.ndim == 1:
                self._where[name] = col
                lin.append(a[:, None])
                col += 1
            else:
                self._where[name] = slice(col, col + a.shape[1])
                lin.append(a)
                col += a.shape[1]
        self._table = np.column_stack(lin) if lin else np.zeros((n, 0))

    def cycle_time(self, t: float) -> tuple[int, float]:
        """(cycle index, cycle time [s]) of time ``t`` [s]: ``k = floor(t / period)``, ``t - k period``."""
        k = int(t // self.period)
        return k, t - k * self.period

    def segment_index(self, t_cycle: float) -> int:
        """Index of the segment ``[t_i, t_i+1)`` holding cycle time ``t_cycle`` [s] (the first one
        before the first row, the last one at or beyond the last row)."""
        i = int(np.searchsorted(self.t, t_cycle, side="right")) - 1
        return min(max(i, 0), len(self.t) - 2)

    def segments(self, name: str) -> np.ndarray:
        """The value of held column ``name`` on each of the ``n - 1`` segments."""
        return self._held[name]

    def where(self, name: str) -> int | slice:
        """Position of linear column ``name`` in the row :meth:`evaluate` returns."""
        return self._where[name]

    def evaluate(self, t: float) -> tuple[int, float, int, int, float, np.ndarray]:
        """``(cycle, t_cycle, phase, segment, weight, row)`` at time ``t`` [s]: ``row`` holds every
        linear column (at :meth:`where`), ``segments(name)[segment]`` a held one. The fast form of
        :meth:`sample`, for a caller sampling every step."""
        k, tc = self.cycle_time(t)
        ts = self.t
        i = int(np.searchsorted(ts, tc, side="right")) - 1
        i = min(max(i, 0), len(ts) - 2)
        w = min(max((tc - ts[i]) / (ts[i + 1] - ts[i]), 0.0), 1.0)
        tab = self._table
        return k, tc, GENERATION if tc < self.T1 else RECOVERY, i, w, tab[i] * (1.0 - w) + tab[i + 1] * w

    def sample(self, t: float) -> CycleSample:
        """Every column at time ``t`` [s] (the cycle repeated periodically)."""
        k, tc, phase, i, w, row = self.evaluate(t)
        return CycleSample(self, k, tc, phase, i, w, row)


# ------------------------------------------------------------------------------ the trajectory

@dataclass
class ReferenceTrajectory:
    """A reference trajectory read back from its file (``source``: the file, for messages)."""

    metadata: dict[str, Any]
    columns: dict[str, np.ndarray]
    units: dict[str, str]
    source: str = "reference trajectory"

    @property
    def period(self) -> float:
        return float(self.metadata["period_s"])

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]

    def sampler(self) -> CycleSampler:
        """The :class:`CycleSampler` of every column but ``t`` and ``phase``, by :data:`REFERENCE_RULES`."""
        c = self.columns
        key = (tuple((k, id(a)) for k, a in c.items()), self.metadata.get("T1_s"), self.metadata.get("period_s"))
        cached = self.__dict__.get("_sampler")
        if cached is None or cached[0] != key:
            cols = {k: a for k, a in c.items() if k not in ("t", "phase")}
            s = CycleSampler(c["t"], c["phase"], cols, {k: REFERENCE_RULES.get(k, LINEAR) for k in cols},
                             float(self.metadata["T1_s"]), self.period)
            cached = self.__dict__["_sampler"] = (key, s)
        return cached[1]

    def sample(self, t: float) -> dict[str, float]:
        """All columns at time ``t`` [s] (the cycle repeated), by :data:`REFERENCE_RULES`:
        ``{"phase", "t" (the cycle time), column: value, ...}``."""
        s = self.sampler().sample(t)
        out: dict[str, float] = {"phase": float(s.phase), "t": s.t_cycle}
        for k in self.columns:
            if k not in ("t", "phase"):
                out[k] = float(s[k])
        return out


# --------------------------------------------------------------------- from the optimiser's result

def reference_document(result: Any) -> dict[str, Any]:
    """The JSON document of the reference file of an ``ok`` cycle result
    (:class:`~fdm_awe.ocp.result.CycleResult`): what :func:`write_reference` writes."""
    if not result.ok:
        raise InputError(f"no reference trajectory for a {result.status} result ({result.reason})")
    return {
        "format": FORMAT, "version": VERSION, "metadata": result.metadata(),
        "units": {k: COLUMN_UNITS.get(k, OPTIONAL_COLUMN_UNITS.get(k, "")) for k in result.columns},
        "columns": {k: [float(v) for v in np.asarray(a, float)] for k, a in result.columns.items()},
    }


def reference_from_result(result: Any, source: str = "the optimised reference") -> ReferenceTrajectory:
    """The reference of an ``ok`` cycle result in memory: exactly what :func:`read_reference`
    returns for the file :func:`write_reference` writes (the same document, through the same
    JSON text and the same checks), without a file. ``source`` names it in messages."""
    from .fileio import json_text

    return check_reference_document(json.loads(json_text(reference_document(result), indent=None)), source)


def write_reference(result: Any, path: str | Path) -> Path:
    """Write the reference-trajectory JSON file of an ``ok`` result atomically; returns the path.

    The document is checked as :func:`read_reference` checks it before anything is written, so a
    file this function writes always reads back; the file appears complete or not at all
    (temporary name + rename, :func:`fdm_awe.fileio.write_json`).
    """
    from .fileio import write_json

    doc = reference_document(result)
    p = Path(path)
    check_reference(ReferenceTrajectory(doc["metadata"], {k: np.asarray(v, float) for k, v in doc["columns"].items()},
                                        doc["units"], source=f"{p} (to be written)"))
    write_json(p, doc, indent=None)
    result.trajectory_path = str(p)
    return p


def as_reference(ref: Any) -> ReferenceTrajectory:
    """A :class:`ReferenceTrajectory` from a trajectory (as it is), a file path (read and checked)
    or a cycle result (its columns and metadata as they are, unchecked)."""
    if isinstance(ref, ReferenceTrajectory):
        return ref
    if isinstance(ref, (str, Path)):
        return read_reference(ref)
    if hasattr(ref, "columns") and hasattr(ref, "metadata") and callable(getattr(ref, "metadata")):
        cols = {k: np.asarray(v, float) for k, v in ref.columns.items()}
        return ReferenceTrajectory(ref.metadata(), cols, {k: COLUMN_UNITS.get(k, "") for k in cols})
    raise TypeError(f"not a reference trajectory, file or cycle result: {type(ref).__name__}")


# ------------------------------------------------------------------------------- reading and checks

#: Largest reference file read [bytes] (a 60 s cycle on the default mesh is about 100 kB).
MAX_FILE_BYTES = 64 * 2**20
#: Allowed values of the columns: ``(lo, hi, lo_open)`` SI, or ``None`` for any finite number.
#: Bounds that the optimiser meets only up to its constraint tolerance get a relative slack of
#: :data:`SLACK` (of the column's largest magnitude); open lower bounds (airspeed, line length)
#: get none.
COLUMN_RANGES: dict[str, tuple[float, float, bool] | None] = {
    "t": None, "phase": (0.0, 1.0, False), "x": (-1e4, 1e4, False), "y": (-1e4, 1e4, False), "z": (-1e4, 0.0, False),
    "V": (0.0, 100.0, True), "gamma": (-math.pi / 2, math.pi / 2, False), "psi": None,
    "alpha": (-math.pi / 2, math.pi / 2, False), "phi": (-math.pi / 2, math.pi / 2, False), "T": (0.0, 1e3, False),
    "tension": (0.0, 1e4, False), "tether_length": (0.0, 1e4, True), "reel_speed": (-100.0, 100.0, False),
    "fold": (0.0, 1.0, False), "p_generated_W": None, "p_thrust_W": None, "p_reel_in_W": None,
    "motor_on": (0.0, 1.0, False), "boost_duty": (0.0, 1.0, False),
}
SLACK = 1e-6
#: Relative tolerance of the time relations (t ends at T1 + T2, the phase switch at T1, period_s).
TIME_RTOL = 1e-6
#: Wind speed range of a reference [m/s] (the optimiser's, :class:`fdm_awe.ocp.problem.CycleProblem`).
WIND_MAX = 25.0
#: Longest phase of a reference [s].
PHASE_MAX_S = 3600.0
#: Configuration -> airframe of its recovery phase (metadata ``recovery_airframe``).
RECOVERY_AIRFRAME = {"foldable": "folded", "nominal": "unfolded"}


def _kind(v: Any) -> str:
    """JSON type name of a parsed value (for messages)."""
    if v is None:
        return "null"
    if isinstance(v, bool):
        return "a boolean"
    if isinstance(v, (int, float)):
        return "a number"
    if isinstance(v, str):
        return "a string"
    if isinstance(v, list):
        return "a list"
    if isinstance(v, dict):
        return "an object"
    return type(v).__name__


def _show(v: Any) -> str:
    """A short one-line rendering of a metadata value."""
    text = repr(v) if isinstance(v, str) else (json.dumps(v) if isinstance(v, (bool, type(None))) else str(v))
    text = text.replace("\n", " ")
    return text if len(text) <= 40 else text[:37] + "..."


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, (bool, np.bool_))


def _load_json(p: Path) -> Any:
    """The parsed JSON of reference file ``p`` (InputError: file and problem, one line)."""
    try:
        if not p.exists():
            raise InputError(f"{p}: reference trajectory file not found")
        if p.is_dir():
            raise InputError(f"{p}: is a folder, not a reference trajectory file")
        if not p.is_file():
            raise InputError(f"{p}: not a regular file (a reference trajectory is a JSON file)")
        size = p.stat().st_size
        if size > MAX_FILE_BYTES:
            raise InputError(f"{p}: {size} bytes, too large for a reference trajectory (allowed <= {MAX_FILE_BYTES} bytes)")
        data = p.read_bytes()
    except OSError as exc:
        raise InputError(f"{p}: cannot read the reference trajectory ({exc.strerror or exc})") from None
    if not data.strip():
        raise InputError(f"{p}: empty file, expected the JSON written by 'fdm-awe optimize'")
    nul = data.find(b"\x00")
    if nul >= 0:
        raise InputError(f"{p}: binary content (NUL byte at offset {nul}), expected the JSON text written by 'fdm-awe optimize'")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"{p}: not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start}), "
                         f"expected the JSON text written by 'fdm-awe optimize'") from None
    try:
        return json.loads(text.lstrip("\ufeff"))
    except json.JSONDecodeError as exc:
        raise InputError(f"{p}: invalid JSON at line {exc.lineno} column {exc.colno} ({exc.msg})") from None
    except RecursionError:
        raise InputError(f"{p}: invalid reference trajectory: JSON nested too deeply") from None
    except ValueError as exc:  # e.g. an integer literal beyond Python's digit limit
        raise InputError(f"{p}: invalid JSON ({str(exc).splitlines()[0] if str(exc) else type(exc).__name__})") from None


def _column_from_json(src: str, name: str, v: Any) -> np.ndarray:
    """Column ``name`` of the file as a float array: a list of finite numbers."""
    if not isinstance(v, list):
        raise InputError(f"{src}: columns.{name}: {_kind(v)}, expected a list of numbers")
    for i, x in enumerate(v):
        if not _is_number(x):
            shown = "" if x is None else f" {_show(x)}"
            raise InputError(f"{src}: columns.{name}[{i}]: {_kind(x)}{shown}, expected a finite number")
    try:
        a = np.array(v, dtype=float)
    except OverflowError:
        i = next(i for i, x in enumerate(v) if isinstance(x, int) and abs(x) > 1e308)
        raise InputError(f"{src}: columns.{name}[{i}]: number too large, expected a finite number") from None
    return a


def _check_column(src: str, name: str, a: np.ndarray) -> np.ndarray:
    """``a`` as a 1-D float array of finite numbers within :data:`COLUMN_RANGES`."""
    try:
        a = np.asarray(a, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{src}: columns.{name}: not a list of numbers") from None
    if a.ndim != 1:
        raise InputError(f"{src}: columns.{name}: {a.ndim}-dimensional, expected a list of numbers")
    bad = np.flatnonzero(~np.isfinite(a))
    if len(bad):
        i = int(bad[0])
        raise InputError(f"{src}: columns.{name}[{i}]: {a[i]} is not a finite number ({len(bad)} such value(s))")
    rng = COLUMN_RANGES.get(name)
    if rng is not None and len(a):
        lo, hi, lo_open = rng
        slack = SLACK * max(1.0, float(np.max(np.abs(a))))
        below = (a <= lo) if lo_open else (a < lo - slack)
        out = np.flatnonzero(below | (a > hi + slack))
        if len(out):
            i = int(out[0])
            unit = COLUMN_UNITS.get(name, "-")
            unit = "" if unit == "-" else f" {unit}"
            allowed = f"> {lo:.6g} and <= {hi:.6g}{unit}" if lo_open else f"{lo:.6g} .. {hi:.6g}{unit}"
            raise InputError(f"{src}: columns.{name}[{i}]: {a[i]:.6g}{unit} out of range (allowed {allowed})")
    return a


def _meta_number(src: str, md: dict[str, Any], key: str, lo: float | None = None, hi: float | None = None,
                 lo_open: bool = False, unit: str = "") -> float | None:
    """Metadata number ``key`` (None when absent), finite and within ``lo .. hi``."""
    if key not in md or md[key] is None:
        return None
    v = md[key]
    u = f" {unit}" if unit else ""
    if lo is None and hi is None:
        allowed = "a finite number"
    elif hi is None:
        allowed = f"{'>' if lo_open else '>='} {lo:g}{u}"
    elif lo is None:
        allowed = f"<= {hi:g}{u}"
    elif lo_open:
        allowed = f"> {lo:g} and <= {hi:g}{u}"
    else:
        allowed = f"{lo:g} .. {hi:g}{u}"
    if not _is_number(v) or not math.isfinite(float(v)):
        raise InputError(f"{src}: metadata.{key}: {_show(v)} is not a finite number (allowed {allowed})")
    x = float(v)
    if (lo is not None and (x <= lo if lo_open else x < lo)) or (hi is not None and x > hi):
        raise InputError(f"{src}: metadata.{key}: {x:g}{u} out of range (allowed {allowed})")
    return x


def _meta_choice(src: str, md: dict[str, Any], key: str, allowed: tuple[str, ...], required: bool = True) -> str | None:
    v = md.get(key)
    if v is None and not required:
        return None
    if v is None:
        raise InputError(f"{src}: metadata.{key}: missing (allowed {', '.join(allowed)})")
    if v not in allowed or not isinstance(v, str):
        raise InputError(f"{src}: metadata.{key}: {_show(v)} not allowed (allowed {', '.join(allowed)})")
    return v


def _check_wind(src: str, md: dict[str, Any]) -> None:
    """Wind speed, direction and NED vector: in range and consistent; the missing ones filled in."""
    from .pointmass.model import wind_vector

    speed = _meta_number(src, md, "wind_mps", 0.0, WIND_MAX, unit="m/s")
    from_deg = _meta_number(src, md, "wind_from_deg", -360.0, 360.0, unit="deg")
    ned = md.get("wind_ned_mps")
    if ned is not None:
        if not (isinstance(ned, (list, tuple)) and len(ned) == 3 and all(_is_number(v) and math.isfinite(float(v)) for v in ned)):
            raise InputError(f"{src}: metadata.wind_ned_mps: {_show(ned)}, expected 3 finite numbers [north, east, down] m/s")
        ned = [float(v) for v in ned]
        horiz = math.hypot(ned[0], ned[1])
        tol = SLACK * max(1.0, horiz)
        if abs(ned[2]) > tol:
            raise InputError(f"{src}: metadata.wind_ned_mps: down component {ned[2]:g} m/s, allowed 0 (a horizontal wind)")
        if horiz > WIND_MAX + tol:
            raise InputError(f"{src}: metadata.wind_ned_mps: horizontal speed {horiz:g} m/s out of range (allowed 0 .. {WIND_MAX:g} m/s)")
        if speed is not None and abs(horiz - speed) > tol:
            raise InputError(f"{src}: metadata.wind_mps: {speed:g} m/s disagrees with metadata.wind_ned_mps "
                             f"(horizontal speed {horiz:g} m/s; allowed difference {tol:.2g} m/s)")
        if speed is None:
            speed = horiz
        if from_deg is not None and speed > tol:
            expected = wind_vector(speed, from_deg)
            if math.hypot(expected[0] - ned[0], expected[1] - ned[1]) > tol:
                blows = math.degrees(math.atan2(-ned[1], -ned[0])) % 360.0
                raise InputError(f"{src}: metadata.wind_from_deg: {from_deg:g} deg disagrees with metadata.wind_ned_mps "
                                 f"(a wind from {blows:g} deg)")
        if from_deg is None:
            from_deg = math.degrees(math.atan2(-ned[1], -ned[0])) % 360.0 if speed > tol else 180.0
    else:
        if speed is None:
            raise InputError(f"{src}: metadata.wind_mps: missing, and no metadata.wind_ned_mps (allowed 0 .. {WIND_MAX:g} m/s)")
        if from_deg is None and speed > 0.0:
            raise InputError(f"{src}: metadata.wind_from_deg: missing, and no metadata.wind_ned_mps to give the wind's direction")
        from_deg = 180.0 if from_deg is None else from_deg
        ned = list(wind_vector(speed, from_deg))
    md["wind_mps"], md["wind_from_deg"], md["wind_ned_mps"] = float(speed), float(from_deg), ned


def _check_metadata(src: str, md: dict[str, Any]) -> dict[str, Any]:
    """The metadata, checked field by field; returns a copy with the derived fields filled in
    (``wind_*``, ``period_s``, ``tether_drag_scale``)."""
    from .groundstation.line import LINES
    from .groundstation.tether import TETHER_DRAG_SCALE_MAX
    from .ocp.problem import CONFIGS, GENERATORS, PROPELLERS, SCENARIOS

    md = dict(md)
    scenario = _meta_choice(src, md, "scenario", SCENARIOS)
    config = _meta_choice(src, md, "config", CONFIGS)
    status = md.get("status")
    if status is not None and status != "ok":
        raise InputError(f"{src}: metadata.status: {_show(status)}, a reference must be an 'ok' cycle (allowed ok)")
    ra = md.get("recovery_airframe")
    if ra is not None and ra != RECOVERY_AIRFRAME[config]:  # type: ignore[index]
        raise InputError(f"{src}: metadata.recovery_airframe: {_show(ra)} does not fit config {config!r} "
                         f"(allowed {RECOVERY_AIRFRAME[config]!r})")  # type: ignore[index]
    names = md.get("phase_names")
    if names is not None and names != list(PHASE_NAMES):
        raise InputError(f"{src}: metadata.phase_names: {_show(names)} not allowed (allowed {json.dumps(list(PHASE_NAMES))})")
    T1 = _meta_number(src, md, "T1_s", 0.0, PHASE_MAX_S, lo_open=True, unit="s")
    T2 = _meta_number(src, md, "T2_s", 0.0, PHASE_MAX_S, lo_open=True, unit="s")
    for key, v in (("T1_s", T1), ("T2_s", T2)):
        if v is None:
            raise InputError(f"{src}: metadata.{key}: missing (allowed > 0 and <= {PHASE_MAX_S:g} s)")
    period = T1 + T2  # type: ignore[operator]
    tol = TIME_RTOL * max(1.0, period)
    P = _meta_number(src, md, "period_s", 0.0, 2 * PHASE_MAX_S, lo_open=True, unit="s")
    if P is not None and abs(P - period) > tol:
        raise InputError(f"{src}: metadata.period_s: {P:.9g} s, but T1_s + T2_s = {period:.9g} s (allowed difference {tol:.2g} s)")
    md["T1_s"], md["T2_s"], md["period_s"] = T1, T2, period
    _check_wind(src, md)
    scale = _meta_number(src, md, "tether_drag_scale", 0.0, TETHER_DRAG_SCALE_MAX)
    md["tether_drag_scale"] = 1.0 if scale is None else scale  # files written before it existed: the defined line
    prop = md.get("propeller")
    if prop is not None:
        allowed = PROPELLERS if scenario == "physical" else ("paper",)
        if prop not in allowed or not isinstance(prop, str):
            raise InputError(f"{src}: metadata.propeller: {_show(prop)} not allowed for the {scenario} scenario "
                             f"(allowed {', '.join(allowed)})")
    line = md.get("line")  # absent: a file written before lines were named, flown on Table 1's line
    if line is not None and (not isinstance(line, str) or line not in LINES):
        raise InputError(f"{src}: metadata.line: {_show(line)} not allowed (allowed {', '.join(LINES)}; "
                         f"absent = paper, Table 1's line)")
    from .definitions.aircraft import FOLD_TIME_MAX_S

    fold_time = _meta_number(src, md, "fold_time_s", 0.0, FOLD_TIME_MAX_S, unit="s")
    if fold_time is not None and fold_time > 0.0 and config == "nominal":
        raise InputError(f"{src}: metadata.fold_time_s: {fold_time:g} s, but metadata.config is 'nominal' (never folds; allowed 0)")
    md["fold_time_s"] = 0.0 if fold_time is None else fold_time  # older files: optimised with an instantaneous fold
    mo = md.get("motor_off")
    if mo is not None and not isinstance(mo, bool):
        raise InputError(f"{src}: metadata.motor_off: {_show(mo)} not allowed (allowed true or false; absent = false)")
    md["motor_off"] = bool(mo)
    from .wind import WindProfile

    prof = WindProfile.from_dict(md.get("wind_profile"), f"{src}: metadata.wind_profile")  # absent: uniform
    if scenario == "paper" and not prof.uniform:
        raise InputError(f"{src}: metadata.wind_profile: {prof.label()!r}, but the paper scenario's wind is uniform (allowed uniform)")
    md["wind_profile"] = prof.as_dict()
    gen = md.get("generator")
    if gen is not None and (not isinstance(gen, str) or gen not in GENERATORS or scenario != "physical"):
        raise InputError(f"{src}: metadata.generator: {_show(gen)} not allowed (allowed {', '.join(GENERATORS)}, "
                         f"physical scenario only; absent = passive)")
    if scenario == "physical":
        md["generator"] = "passive" if gen is None else gen
    lw = md.get("line_weight")
    if lw is not None and (not isinstance(lw, bool) or (lw and scenario != "physical")):
        raise InputError(f"{src}: metadata.line_weight: {_show(lw)} not allowed (allowed true or false; true only in the physical scenario)")
    d0 = _meta_number(src, md, "d0_m", 0.0, 1e4, lo_open=True, unit="m")
    dtf = _meta_number(src, md, "d_tf_m", 0.0, 1e4, lo_open=True, unit="m")
    if d0 is not None and dtf is not None and dtf <= d0:
        raise InputError(f"{src}: metadata.d_tf_m: {dtf:g} m, allowed > d0_m = {d0:g} m (the line is reeled out in generation)")
    _meta_number(src, md, "elevation0_deg", -90.0, 90.0, unit="deg")
    _meta_number(src, md, "azimuth0_deg", -360.0, 360.0, unit="deg")
    kw = md.get("k_wrap")
    if kw is not None and not (isinstance(kw, int) and not isinstance(kw, bool)):
        raise InputError(f"{src}: metadata.k_wrap: {_show(kw)}, expected an integer")
    for key in ("mesh", "bounds", "energies"):
        if md.get(key) is not None and not isinstance(md[key], dict):
            raise InputError(f"{src}: metadata.{key}: {_kind(md[key])}, expected an object")
    for k, v in (md.get("energies") or {}).items():  # shown in reports beside the other summary numbers
        if not (isinstance(k, str) and k.startswith(("E_", "P_"))) or not (v is None or (_is_number(v) and math.isfinite(v))):
            raise InputError(f"{src}: metadata.energies.{k}: {_show(v)} not allowed (allowed: E_*_J / P_*_W names "
                             f"with finite numbers or null)")
    return md


def check_reference(ref: ReferenceTrajectory) -> ReferenceTrajectory:
    """``ref`` checked field by field: the metadata (:func:`_check_metadata`), every column finite
    and within :data:`COLUMN_RANGES`, equal lengths, at least 2 rows, ``t`` from 0 strictly
    increasing (one repeated time at the phase switch) to ``T1_s + T2_s``, ``phase`` 0 then 1
    with the switch at ``T1_s``, ``fold`` 0 throughout for the nominal config.

    Returns a new :class:`ReferenceTrajectory` with float columns and the completed metadata;
    raises :class:`~fdm_awe.errors.InputError` (one line: source, field, allowed range/form).
    """
    src = ref.source
    if not isinstance(ref.metadata, dict):
        raise InputError(f"{src}: metadata: {_kind(ref.metadata)}, expected an object")
    if not isinstance(ref.columns, dict):
        raise InputError(f"{src}: columns: {_kind(ref.columns)}, expected an object of named lists")
    md = _check_metadata(src, ref.metadata)
    missing = [k for k in COLUMN_UNITS if k not in ref.columns]
    if missing:
        raise InputError(f"{src}: columns missing: {', '.join(missing)} (required: {', '.join(COLUMN_UNITS)})")
    cols = {k: _check_column(src, k, v) for k, v in ref.columns.items()}
    t, ph = cols["t"], cols["phase"]
    n = len(t)
    for k, a in cols.items():
        if len(a) != n:
            raise InputError(f"{src}: columns.{k}: {len(a)} values, expected {n} (the length of columns.t)")
    if n < 2:
        raise InputError(f"{src}: columns.t: {n} row(s), at least 2 needed (a cycle from t = 0 to T1 + T2)")
    if not np.all((ph == 0.0) | (ph == 1.0)):
        i = int(np.flatnonzero((ph != 0.0) & (ph != 1.0))[0])
        raise InputError(f"{src}: columns.phase[{i}]: {ph[i]:g} not allowed (allowed 0 = generation, 1 = recovery)")
    back = np.flatnonzero(np.diff(ph) < 0)
    if len(back):
        i = int(back[0]) + 1
        raise InputError(f"{src}: columns.phase[{i}]: generation (0) after recovery (1); allowed: the generation rows, then the recovery rows")
    dt = np.diff(t)
    switch = (ph[:-1] == 0.0) & (ph[1:] == 1.0)
    bad = np.flatnonzero((dt < 0.0) | ((dt == 0.0) & ~switch))
    if len(bad):
        i = int(bad[0]) + 1
        raise InputError(f"{src}: columns.t[{i}]: {t[i]:.9g} s after {t[i - 1]:.9g} s; allowed: strictly increasing "
                         f"times (one repeated time at the generation/recovery switch)")
    T1, T2, period = md["T1_s"], md["T2_s"], md["period_s"]
    tol = TIME_RTOL * max(1.0, period)
    if abs(t[0]) > tol:
        raise InputError(f"{src}: columns.t[0]: {t[0]:.9g} s, allowed 0 (the cycle starts at t = 0)")
    if abs(t[-1] - period) > tol:
        raise InputError(f"{src}: columns.t: ends at {t[-1]:.9g} s, but metadata T1_s + T2_s = {period:.9g} s "
                         f"(allowed difference {tol:.2g} s)")
    if not (np.any(ph == 0.0) and np.any(ph == 1.0)):
        which = "generation (0)" if not np.any(ph == 0.0) else "recovery (1)"
        raise InputError(f"{src}: columns.phase: no {which} rows; allowed: both phases, generation first")
    t_gen_end, t_rec_start = float(t[ph == 0.0][-1]), float(t[ph == 1.0][0])
    if abs(t_gen_end - T1) > tol or abs(t_rec_start - T1) > tol:
        raise InputError(f"{src}: columns.phase: switches from generation (last at t = {t_gen_end:.9g} s) to recovery "
                         f"(first at {t_rec_start:.9g} s), but metadata.T1_s = {T1:.9g} s (allowed difference {tol:.2g} s)")
    if md["config"] == "nominal" and np.any(cols["fold"] != 0.0):
        i = int(np.flatnonzero(cols["fold"] != 0.0)[0])
        raise InputError(f"{src}: columns.fold[{i}]: {cols['fold'][i]:g}, but metadata.config is 'nominal' (never folds; allowed 0)")
    if "motor_on" in cols and not md["motor_off"] and np.any(cols["motor_on"] != 1.0):
        i = int(np.flatnonzero(cols["motor_on"] != 1.0)[0])
        raise InputError(f"{src}: columns.motor_on[{i}]: {cols['motor_on'][i]:g}, but metadata.motor_off is not true "
                         f"(the motor runs throughout; allowed 1)")
    if "boost_duty" in cols and md.get("generator") != "boost" and np.any(cols["boost_duty"] != 0.0):
        i = int(np.flatnonzero(cols["boost_duty"] != 0.0)[0])
        raise InputError(f"{src}: columns.boost_duty[{i}]: {cols['boost_duty'][i]:g}, but metadata.generator is "
                         f"{md.get('generator', 'passive')!r} (no T2 duty; allowed 0)")
    units = ref.units if isinstance(ref.units, dict) else {}
    return ReferenceTrajectory(md, cols, dict(units), source=src)


def check_reference_document(doc: Any, source: str) -> ReferenceTrajectory:
    """The parsed JSON ``doc`` of a reference file (named ``source``) checked as a document
    (object, ``format``, ``version``, ``metadata``/``columns`` objects, columns lists of finite
    numbers) and then by :func:`check_reference`."""
    src = source
    if not isinstance(doc, dict):
        raise InputError(f"{src}: top level is {_kind(doc)}, expected a JSON object with format, version, metadata and columns")
    fmt = doc.get("format")
    if fmt != FORMAT:
        raise InputError(f"{src}: format: {_show(fmt)}, expected {FORMAT!r} (a file written by 'fdm-awe optimize')")
    ver = doc.get("version")
    if not (isinstance(ver, int) and not isinstance(ver, bool) and ver == VERSION):
        raise InputError(f"{src}: version: {_show(ver)} not supported (allowed {VERSION})")
    for key, what in (("metadata", "an object with scenario, config, wind_mps, T1_s, T2_s, ..."),
                      ("columns", "an object of named lists of numbers")):
        if key not in doc:
            raise InputError(f"{src}: {key}: missing (expected {what})")
        if not isinstance(doc[key], dict):
            raise InputError(f"{src}: {key}: {_kind(doc[key])}, expected {what}")
    units = doc.get("units", {})
    if not (isinstance(units, dict) and all(isinstance(v, str) for v in units.values())):
        raise InputError(f"{src}: units: {_kind(units)}, expected an object of unit names")
    raw = doc["columns"]
    missing = [k for k in COLUMN_UNITS if k not in raw]
    if missing:
        raise InputError(f"{src}: columns missing: {', '.join(missing)} (required: {', '.join(COLUMN_UNITS)})")
    order = list(COLUMN_UNITS) + [k for k in raw if k not in COLUMN_UNITS]  # t first: its problems are named as t's
    cols = {k: _column_from_json(src, k, raw[k]) for k in order}
    for k, a in cols.items():
        _check_column(src, k, a)  # finite values named by column before any relation between columns
    return check_reference(ReferenceTrajectory(doc["metadata"], cols, units, source=src))


def read_reference(path: str | Path) -> ReferenceTrajectory:
    """Read and check a reference-trajectory file (see the module docstring).

    Every malformed file raises :class:`~fdm_awe.errors.InputError` with one line naming the
    file, the field and the allowed range or form; the returned metadata carries checked
    ``scenario``, ``config``, ``T1_s``, ``T2_s``, ``period_s``, ``wind_mps``, ``wind_from_deg``,
    ``wind_ned_mps`` and ``tether_drag_scale`` (1 when the file predates it); ``line`` is checked
    when present (absent: Table 1's ``paper`` line, as :func:`fdm_awe.sim.flight.fly` reads it).
    """
    p = Path(path)
    return check_reference_document(_load_json(p), str(p))
