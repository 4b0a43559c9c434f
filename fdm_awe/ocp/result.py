"""Cycle result and its JSON summary (docs/design.md section 1).

The reference-trajectory file an ``ok`` result is written to (format, checks, reader and writer)
is :mod:`fdm_awe.trajectory`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..pointmass.model import wind_vector
from ..trajectory import PHASE_NAMES


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
    #: how the optimum was found (:mod:`fdm_awe.ocp.strategy`): every start's outcome, the
    #: winner, the polish and any cold check; JSON-ready, empty when no strategy ran
    strategy: dict[str, Any] = field(default_factory=dict)
    #: fold time the cycle was optimised with [s] (the model's resolved fold time; None: unknown)
    fold_time_s: float | None = None
    #: the optimiser could stop the motor (column ``motor_on``; None: unknown)
    motor_off: bool | None = None
    #: the bounds that bind at the optimum (:func:`fdm_awe.ocp.active.active_bounds`): which
    #: constraint, phase, where in the cycle, IPOPT's multiplier; strongest first
    active_bounds: list[dict[str, Any]] = field(default_factory=list)

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
            "strategy": self.strategy or None,
            "active_bounds": self.active_bounds if ok else [],
        }

    def metadata(self) -> dict[str, Any]:
        pr = self.problem
        md: dict[str, Any] = {
            "scenario": self.scenario, "config": self.config, "wind_mps": self.wind_mps, "wind_from_deg": self.wind_from_deg,
            "wind_ned_mps": list(wind_vector(self.wind_mps, self.wind_from_deg)), "T1_s": self.T1_s, "T2_s": self.T2_s,
            "period_s": self.T1_s + self.T2_s, "k_wrap": self.k_wrap, "status": self.status,
            "phase_names": list(PHASE_NAMES),
            "recovery_airframe": "folded" if self.config == "foldable" else "unfolded",
            "energies": {k: v for k, v in self.summary().items() if k.startswith(("E_", "P_"))},
        }
        if self.strategy:
            md["strategy"] = self.strategy
        if self.fold_time_s is not None:
            md["fold_time_s"] = float(self.fold_time_s)
        if self.motor_off is not None:
            md["motor_off"] = bool(self.motor_off)
        if pr is not None:
            md.update({"d0_m": pr.d0, "d_tf_m": pr.d_tf, "elevation0_deg": pr.elevation0_deg, "azimuth0_deg": pr.azimuth0_deg,
                       "tether_drag_scale": pr.tether_drag_scale,
                       "propeller": {"physical": "momentum"}.get(pr.scenario_spec.propeller, pr.scenario_spec.propeller),
                       "line_weight": pr.line_weight, "line": pr.line,
                       **({"generator": pr.generator} if pr.generator is not None else {}),
                       "wind_profile": pr.wind_profile.as_dict(),
                       "mesh": {"n_gen": pr.mesh.n_gen, "n_rec": pr.mesh.n_rec, "degree": pr.mesh.degree},
                       "bounds": {k: v for k, v in pr.bounds.__dict__.items()}})
            if pr.aircraft is not None:  # which aircraft (table name or folder, content hash)
                md["aircraft"] = pr.aircraft.record()
            if pr.ground_station is not None:  # which ground station ("default" or the file, content hash)
                md["ground_station"] = pr.ground_station.record()
        return md

