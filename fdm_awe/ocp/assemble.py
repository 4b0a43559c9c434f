"""A solution of the cycle NLP made a result: the acceptance check, the :class:`CycleResult`
with its energies and reference-trajectory columns, and the result of a failed solve.

A result's ``status`` is ``"ok"`` only when IPOPT reports success AND the scaled constraints
hold within :data:`VIOLATION_TOL` (:func:`accept`); otherwise ``"failed"`` with the reason
(never a result presented as valid).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .active import active_bounds
from .build import structure_key
from .collocation import CycleNLP, RawSolution
from .problem import CycleProblem
from .result import CycleResult

#: largest scaled constraint violation accepted as a solution
VIOLATION_TOL = 1e-6


def accept(nlp: CycleNLP, r: RawSolution | None) -> bool:
    """IPOPT success, finite objective and scaled constraints within :data:`VIOLATION_TOL`
    (otherwise ``r`` is marked failed, with the violated constraint as its reason)."""
    if r is None or r.status != "ok":
        return False
    viol, where = nlp.constraint_violation(r.w, r.params)
    if not (viol <= VIOLATION_TOL) or not math.isfinite(r.objective):
        r.status, r.reason = "failed", f"constraint {where} violated by {viol:.2e} after '{r.reason}'"
        return False
    return True


def ok_result(problem: CycleProblem, nlp: CycleNLP, k: int, label: str, r: RawSolution, build_s: float,
              total_s: float, total_it: int) -> CycleResult:
    """The result of the accepted solution ``r`` (heading wrap ``k``, start ``label``), with the
    build time ``build_s`` [s], solve time ``total_s`` [s] and iterations ``total_it`` of the
    solves that led to it."""
    en = nlp.energies(r.w, r.params)
    viol, _ = nlp.constraint_violation(r.w, r.params)
    phases = nlp.unpack(r.w)
    res = CycleResult(problem.scenario, problem.config, problem.wind_speed, problem.wind_from_deg, "ok", r.reason,
                      total_s, build_s, total_it, en["T1_s"], en["T2_s"], en["E_generated_J"], en["E_thrust_J"],
                      en["E_reel_in_J"], k, label, viol, trajectory_columns(nlp, phases, r.params), r.w, r.lam_x,
                      r.lam_g, structure_key(problem), phases, problem=problem,
                      fold_time_s=nlp.model.fold_time, motor_off=nlp.model.motor_off)
    res.active_bounds = active_bounds(nlp, r.w, r.lam_x, r.lam_g, r.params)
    return res


def failed_result(problem: CycleProblem, reason: str, solve_s: float, build_s: float, iterations: int) -> CycleResult:
    """The result of a solve that found no cycle: ``reason``, solve and build times [s], iterations."""
    return CycleResult(problem.scenario, problem.config, problem.wind_speed, problem.wind_from_deg, "failed", reason,
                       solve_s, build_s, iterations, problem=problem, key=structure_key(problem))


def trajectory_columns(nlp: CycleNLP, phases: list[dict[str, Any]], params: np.ndarray) -> dict[str, np.ndarray]:
    """Reference-trajectory columns (see :mod:`fdm_awe.ocp.result`) from the unpacked phases."""
    m = nlp.model
    d = nlp.d
    wind = (float(params[0]), float(params[1]))
    rows: dict[str, list[float]] = {k: [] for k in ("t", "phase", "x", "y", "z", "V", "gamma", "psi", "alpha", "phi", "T",
                                                    "tension", "tether_length", "reel_speed", "fold", "p_generated_W",
                                                    "p_thrust_W", "p_reel_in_W", "motor_on", "boost_duty")}
    t_off = 0.0
    for ip, ph in enumerate(phases):
        X, U, t = ph["X"], ph["U"], ph["t"]
        block = m.phase(ip)
        for q in range(len(t)):
            kint = min(q // d, len(U) - 1)
            u = U[kint]
            out = block(list(X[q]), list(u), wind, 1.0)
            rows["t"].append(t_off + t[q])
            rows["phase"].append(ip)
            for i, s in enumerate(("x", "y", "z", "V", "gamma", "psi")):
                rows[s].append(X[q, i])
            rows["alpha"].append(u[0])
            rows["phi"].append(u[1])
            rows["T"].append(float(m.mean_thrust(ip, u)))  # s T_on in the motor-off mode
            rows["tension"].append(float(out["G"]))
            rows["tether_length"].append(float(out["l"]))
            rows["reel_speed"].append(float(out["v_reel"]))
            rows["fold"].append(float(ph["fold"][q]))
            rows["p_generated_W"].append(float(out["P_gen"]))
            rows["p_thrust_W"].append(float(out["P_thr"]))
            rows["p_reel_in_W"].append(float(out["P_rw"]))
            on = m.on_fraction(ip, u)  # None: no motor-off mode, the motor runs throughout
            rows["motor_on"].append(1.0 if on is None else float(on))
            duty = m.boost_duty(u) if ip == 0 else None  # None: the passive rectifier (recovery: motor mode)
            rows["boost_duty"].append(0.0 if duty is None else float(duty))
        t_off += ph["T"]
    return {k: np.asarray(v, float) for k, v in rows.items()}
