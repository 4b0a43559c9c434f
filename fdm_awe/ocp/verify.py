"""Independent check of an optimal cycle: re-integrate the optimal controls, re-count energies.

The collocated solution is trusted only as far as an adaptive Runge-Kutta integration
(:func:`scipy.integrate.solve_ivp`, DOP853, tight tolerances) of the same model with the same
piecewise-constant controls reproduces it:

- states: every mesh interval is re-integrated from its collocated start node with its optimal
  control; the end of each interval is compared with the next collocated node. The sum of these
  position defects bounds the distance between the collocated path and a path stitched from
  exact ODE solutions; it is reported relative to the path length. (One open-loop run through
  the whole cycle is NOT a meaningful test: the tethered point mass has unstable modes with
  time constants of a fraction of a second, so any error grows e-fold many times over a phase;
  ``open_loop_drift`` reports it on request, for information.)
- energies: ``E_generated``, ``E_thrust``, ``E_reel_in`` are integrated as extra ODE states by the
  same adaptive integrator (a quadrature independent of the Radau weights of the optimiser);
- the same model functions as the optimiser's: the motor's on-fraction is one of the controls,
  and a folding wing's recovery intervals (their bounds from the solution, ``t_nodes``) are
  integrated with the fold state of :meth:`fdm_awe.ocp.model.CycleModel.fold_fraction` at each
  instant, the law the collocation evaluates at its points;
- constraints: the NLP's scaled constraints and bounds at the solution (needs the NLP), and the
  path constraints sampled densely along the re-integration (reported in SI units).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp

from ..definitions.aircraft import load_glider
from ..pointmass.model import wind_vector
from .energy import problem_winch
from .model import CycleModel
from .result import CycleResult

#: integrator tolerances (relative, absolute in SI units)
RTOL, ATOL = 1e-10, 1e-9

#: Acceptance of a cycle on the mesh it was solved on: the interval position defects sum to at
#: most this share of the path, and each re-integrated energy agrees within ``ENERGY_TOL_REL``.
#: The default mesh (:class:`fdm_awe.ocp.problem.Mesh`) is chosen to meet them with a wide
#: margin in the physical scenario (defects ~0.01-0.07 %, energies ~0.03-0.3 %). Coarse meshes
#: do not resolve the generator's stiff radial mode (time constant ~0.1 s against intervals of
#: ~2.5 s at 20 generation intervals): an optimum there can use the gap between the collocation
#: points (the reel-out speed dips below zero between them), so its defects reach several
#: percent and its generated energy is off by up to ~15 %. Such a solution converges but is not
#: accepted as accurate.
POSITION_TOL_REL = 0.005
ENERGY_TOL_REL = 0.01


@dataclass
class Verification:
    """What the re-integration found. Errors are absolute [SI] unless named ``_rel``."""

    path_length_m: float
    max_position_error_m: float  #: largest end-of-interval position defect [m]
    position_error_rel: float  #: sum of all interval position defects / path length
    max_state_error: dict[str, float]
    energies: dict[str, float]  #: re-integrated energies [J]
    energy_error_rel: dict[str, float]  #: |collocated - re-integrated| / max(|re-integrated|, 1 J)
    nlp_max_violation: float = math.nan  #: scaled, at the collocation points
    nlp_violation_where: str = ""
    dense_violation: dict[str, float] = field(default_factory=dict)  #: SI, sampled along the re-integration
    open_loop_drift_m: float = math.nan  #: largest node distance of one open-loop run through the cycle (information)

    def as_dict(self) -> dict[str, Any]:
        return {k: v for k, v in self.__dict__.items()}

    def accurate(self) -> bool:
        """The re-integration reproduces the cycle within :data:`POSITION_TOL_REL` (path) and
        :data:`ENERGY_TOL_REL` (each energy)."""
        return (self.position_error_rel <= POSITION_TOL_REL
                and all(e <= ENERGY_TOL_REL for e in self.energy_error_rel.values()))


def _phase_rhs(model: CycleModel, ip: int, u: np.ndarray, wind: tuple[float, float], fold=None):
    """Right-hand side (states, then the three power integrals and the ground-track length) of
    phase ``ip`` with controls ``u``; ``fold(t)`` the fold state at local time ``t`` (None: the
    phase's own wing)."""
    block = model.phase(ip)

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        n = 6 if ip == 0 else 7
        s = y[:n]
        out = block(list(s), list(u), wind) if fold is None else block(list(s), list(u), wind, 1.0, 1.0, fold(t))
        V, gam, psi = s[3], s[4], s[5]
        w = model.wind_at(wind, s[2])  # the wind at the glider's height (the reference height's for a uniform wind)
        gs = math.sqrt((V * math.cos(gam) * math.cos(psi) + w[0]) ** 2 + (V * math.cos(gam) * math.sin(psi) + w[1]) ** 2
                       + (V * math.sin(gam)) ** 2)
        return np.r_[np.asarray(out["f"], float), float(out["P_gen"]), float(out["P_thr"]), float(out["P_rw"]), gs]

    return rhs


def verify(result: CycleResult, nlp: Any = None, model: CycleModel | None = None, dense_per_interval: int = 8,
           open_loop_drift: bool = False) -> Verification:
    """Re-integrate ``result`` (an ``ok`` :class:`CycleResult`) and compare (module docstring)."""
    if not result.ok:
        raise ValueError(f"cannot verify a {result.status} result")
    pr = result.problem
    if model is None:
        model = nlp.model if nlp is not None else CycleModel.build(pr, load_glider(pr.aircraft), problem_winch(pr))
    wind = wind_vector(result.wind_mps, result.wind_from_deg)[:2]
    d = pr.mesh.degree
    names = ("x", "y", "z", "V", "gamma", "psi", "l")
    max_err = {n: 0.0 for n in names}
    pos_defects: list[float] = []
    E = np.zeros(3)
    path = 0.0
    dense_rows: list[tuple[int, np.ndarray, np.ndarray]] = []
    open_loop = 0.0
    for ip, ph in enumerate(result.phases):
        X, U, T, n = ph["X"], ph["U"], ph["T"], len(ph["U"])
        folding = ip == 1 and model.folds
        nodes = np.asarray(ph["t_nodes"], float) if folding else None
        nx = X.shape[1]
        y_ol = np.r_[X[0], 0.0, 0.0, 0.0, 0.0] if ip == 0 else np.r_[y_ol[:6], X[0, 6], y_ol[6:10]]
        for k in range(n):
            if folding:
                t0, h = nodes[k], nodes[k + 1] - nodes[k]
                rhs = _phase_rhs(model, ip, U[k], wind, lambda t, t0=t0: model.fold_fraction(t0 + t, T))
            else:
                h = T / n
                rhs = _phase_rhs(model, ip, U[k], wind)
            y0 = np.r_[X[k * d], 0.0, 0.0, 0.0, 0.0]
            sol = solve_ivp(rhs, (0.0, h), y0, method="DOP853", rtol=RTOL, atol=ATOL, dense_output=True)
            if not sol.success:
                raise RuntimeError(f"re-integration failed in phase {ip}, interval {k}: {sol.message}")
            for tq in np.linspace(0.0, h, dense_per_interval, endpoint=False):
                dense_rows.append((ip, sol.sol(tq)[:nx], U[k]))
            y = sol.y[:, -1]
            ref = X[(k + 1) * d]
            err = np.abs(y[:nx] - ref)
            pos_defects.append(float(np.linalg.norm(y[:3] - ref[:3])))
            for i in range(nx):
                max_err[names[i]] = max(max_err[names[i]], float(err[i]))
            E += y[nx:nx + 3]
            path += float(y[nx + 3])
            if open_loop_drift and math.isfinite(open_loop):
                ol = solve_ivp(rhs, (0.0, h), y_ol, method="DOP853", rtol=RTOL, atol=ATOL)
                y_ol = ol.y[:, -1] if ol.success else np.full_like(y_ol, np.nan)
                open_loop = max(open_loop, float(np.linalg.norm(y_ol[:3] - ref[:3])))
    colloc = {"E_generated_J": result.E_generated_J, "E_thrust_J": result.E_thrust_J, "E_reel_in_J": result.E_reel_in_J}
    re = {"E_generated_J": float(E[0]), "E_thrust_J": float(E[1]), "E_reel_in_J": float(E[2])}
    re["E_net_J"] = re["E_generated_J"] - re["E_thrust_J"] - re["E_reel_in_J"]
    rel = {k: abs(colloc[k] - re[k]) / max(abs(re[k]), 1.0) for k in colloc}
    stitched = float(np.sum(pos_defects))
    v = Verification(path, max(pos_defects), stitched / path, max_err, re, rel,
                     open_loop_drift_m=open_loop if open_loop_drift else math.nan)
    if nlp is not None:
        v.nlp_max_violation, v.nlp_violation_where = nlp.constraint_violation(result.w, nlp.params(wind, 1.0, result.k_wrap, 1.0))
    v.dense_violation = _dense_check(model, pr, dense_rows, wind)
    return v


def _dense_check(model: CycleModel, pr: Any, rows: list, wind: tuple[float, float]) -> dict[str, float]:
    """Largest violation [SI] of each path constraint sampled along the re-integration."""
    b = pr.bounds
    viol = {"V": 0.0, "h_min": 0.0, "ddot": 0.0, "tension": 0.0, "slack": 0.0}
    for ip, s, u in rows:
        out = model.phase(ip)(list(s), list(u), wind)
        viol["V"] = max(viol["V"], b.V_min - s[3], s[3] - b.V_max)
        viol["h_min"] = max(viol["h_min"], b.h_min + s[2])
        if ip == 0:
            viol["ddot"] = max(viol["ddot"], -float(out["v_reel"]))
            viol["tension"] = max(viol["tension"], float(out["G"]) - b.G_cycle_max, b.G_min - float(out["G"]))
        else:
            viol["slack"] = max(viol["slack"], float(out["d"] - out["l"]))
    return {k: max(v, 0.0) for k, v in viol.items()}
