"""Cycle result, its JSON summary (docs/design.md section 1) and the reference-trajectory file.

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
- ``p_generated_W, p_thrust_W, p_reel_in_W`` [W] the scenario's power terms.

:func:`read_reference` returns a :class:`ReferenceTrajectory` with NumPy columns and a
``sample(t)`` helper (cycle-periodic linear interpolation within each phase).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError

FORMAT = "fdm-awe-reference-trajectory"
VERSION = 1

COLUMN_UNITS = {
    "t": "s", "phase": "-", "x": "m", "y": "m", "z": "m", "V": "m/s", "gamma": "rad", "psi": "rad",
    "alpha": "rad", "phi": "rad", "T": "N", "tension": "N", "tether_length": "m", "reel_speed": "m/s",
    "fold": "-", "p_generated_W": "W", "p_thrust_W": "W", "p_reel_in_W": "W",
}


@dataclass
class CycleResult:
    """Outcome of one cycle optimisation. Energies [J] (all >= 0 except ``E_net_J``)."""

    scenario: str
    config: str
    wind_mps: float
    wind_from_deg: float
    status: str  #: "ok" or "failed"
    reason: str  #: solver return status or failure reason
    solve_s: float  #: wall time of the solves [s] (excluding the NLP build)
    build_s: float  #: wall time of building the NLP and the IPOPT instances this solve created [s] (0 when all reused)
    iterations: int  #: IPOPT iterations summed over homotopy steps/starts that led here
    T1_s: float = math.nan
    T2_s: float = math.nan
    E_generated_J: float = math.nan
    E_thrust_J: float = math.nan
    E_reel_in_J: float = math.nan
    k_wrap: int = 0
    start: str = ""
    max_violation: float = math.nan  #: largest scaled constraint/bound violation
    columns: dict[str, np.ndarray] = field(default_factory=dict)
    w: np.ndarray | None = None  #: scaled decision vector (warm start)
    lam_x: np.ndarray | None = None
    lam_g: np.ndarray | None = None
    key: tuple | None = None  #: NLP structure key (warm start only between equal keys)
    phases: list[dict[str, Any]] = field(default_factory=list)  #: raw per-phase collocation data
    trajectory_path: str | None = None
    problem: Any = None

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    @property
    def E_net_J(self) -> float:
        return self.E_generated_J - self.E_thrust_J - self.E_reel_in_J

    @property
    def P_avg_W(self) -> float:
        return self.E_net_J / (self.T1_s + self.T2_s)

    def summary(self) -> dict[str, Any]:
        """The ``--json`` contract of ``fdm-awe optimize`` (docs/design.md section 1)."""
        def num(v: float) -> float | None:
            return None if (v is None or not math.isfinite(v)) else float(v)

        ok = self.ok
        return {
            "scenario": self.scenario, "config": self.config, "wind_mps": self.wind_mps,
            "wind_from_deg": self.wind_from_deg, "status": self.status, "reason": self.reason,
            "solve_s": round(self.solve_s, 4), "build_s": round(self.build_s, 4), "iterations": self.iterations,
            "T1_s": num(self.T1_s) if ok else None, "T2_s": num(self.T2_s) if ok else None,
            "E_generated_J": num(self.E_generated_J) if ok else None, "E_thrust_J": num(self.E_thrust_J) if ok else None,
            "E_reel_in_J": num(self.E_reel_in_J) if ok else None, "E_net_J": num(self.E_net_J) if ok else None,
            "P_avg_W": num(self.P_avg_W) if ok else None, "k_wrap": self.k_wrap, "max_violation": num(self.max_violation),
            "trajectory": self.trajectory_path,
        }

    def metadata(self) -> dict[str, Any]:
        pr = self.problem
        from ..pointmass import wind_vector

        md: dict[str, Any] = {
            "scenario": self.scenario, "config": self.config, "wind_mps": self.wind_mps, "wind_from_deg": self.wind_from_deg,
            "wind_ned_mps": list(wind_vector(self.wind_mps, self.wind_from_deg)), "T1_s": self.T1_s, "T2_s": self.T2_s,
            "period_s": self.T1_s + self.T2_s, "k_wrap": self.k_wrap, "status": self.status,
            "phase_names": ["generation", "recovery"],
            "recovery_airframe": "folded" if self.config == "foldable" else "unfolded",
            "energies": {k: v for k, v in self.summary().items() if k.startswith(("E_", "P_"))},
        }
        if pr is not None:
            md.update({"d0_m": pr.d0, "d_tf_m": pr.d_tf, "elevation0_deg": pr.elevation0_deg, "azimuth0_deg": pr.azimuth0_deg,
                       "tether_drag_scale": pr.tether_drag_scale,
                       "propeller": {"physical": "momentum"}.get(pr.scenario_spec.propeller, pr.scenario_spec.propeller),
                       "line_weight": pr.line_weight,
                       "mesh": {"n_gen": pr.mesh.n_gen, "n_rec": pr.mesh.n_rec, "degree": pr.mesh.degree},
                       "bounds": {k: v for k, v in pr.bounds.__dict__.items()}})
        return md


def write_reference(result: CycleResult, path: str | Path) -> Path:
    """Write the reference-trajectory JSON file of an ``ok`` result; returns the path."""
    if not result.ok:
        raise InputError(f"no reference trajectory for a {result.status} result ({result.reason})")
    p = Path(path)
    doc = {
        "format": FORMAT, "version": VERSION, "metadata": result.metadata(),
        "units": {k: COLUMN_UNITS[k] for k in result.columns},
        "columns": {k: [float(v) for v in np.asarray(a, float)] for k, a in result.columns.items()},
    }
    p.write_text(json.dumps(doc, allow_nan=False))
    result.trajectory_path = str(p)
    return p


@dataclass
class ReferenceTrajectory:
    """A reference trajectory read back from its file."""

    metadata: dict[str, Any]
    columns: dict[str, np.ndarray]
    units: dict[str, str]

    @property
    def period(self) -> float:
        return float(self.metadata["period_s"])

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]

    def sample(self, t: float) -> dict[str, float]:
        """All columns at cycle time ``t`` [s] (taken modulo the period); linear in time
        within a phase, controls held piecewise constant as stored."""
        T = self.period
        tc = t % T if T > 0 else 0.0
        tt, ph = self.columns["t"], self.columns["phase"]
        phase = 0 if tc < float(self.metadata["T1_s"]) else 1
        sel = ph == phase
        ts = tt[sel]
        out: dict[str, float] = {"phase": float(phase), "t": tc}
        i = int(np.clip(np.searchsorted(ts, tc, side="right") - 1, 0, len(ts) - 1))
        for k, col in self.columns.items():
            if k in ("t", "phase"):
                continue
            c = col[sel]
            if k in ("alpha", "phi", "T", "fold"):
                out[k] = float(c[i])
            else:
                out[k] = float(np.interp(tc, ts, c))
        return out


def read_reference(path: str | Path) -> ReferenceTrajectory:
    """Read a reference-trajectory file (raises InputError naming the problem)."""
    p = Path(path)
    try:
        doc = json.loads(p.read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise InputError(f"{p}: cannot read reference trajectory ({exc})") from None
    if doc.get("format") != FORMAT:
        raise InputError(f"{p}: not an {FORMAT} file (format = {doc.get('format')!r})")
    if int(doc.get("version", -1)) != VERSION:
        raise InputError(f"{p}: version {doc.get('version')!r} not supported (allowed {VERSION})")
    cols = {k: np.asarray(v, float) for k, v in doc["columns"].items()}
    missing = [k for k in COLUMN_UNITS if k not in cols]
    if missing:
        raise InputError(f"{p}: columns missing: {', '.join(missing)}")
    n = {len(v) for v in cols.values()}
    if len(n) != 1:
        raise InputError(f"{p}: columns differ in length")
    return ReferenceTrajectory(doc["metadata"], cols, doc.get("units", {}))
