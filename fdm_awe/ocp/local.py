"""The local strategy of the cycle optimiser: one NLP solved from its starts within one budget.

For each start solve the NLP; if it fails, the continuations (:meth:`LocalSolve.attempt`): for
the foldable glider first an elastic solve (fictitious accelerations in the recovery dynamics,
exact L1 penalty) whose result starts the strict problem only if every slack vanished (a
feasibility aid, never a relaxation: a result always satisfies the strict problem), then a
path through the nominal recovery (aerodynamics morphed 0 -> 1); where the scenario has tether
drag, a homotopy in the tether drag factor (0 -> 0.5 -> 1), each step started from the previous
solution. Starts are tried until ``n_starts`` succeeded; the best average power among them is
kept. Warm: start from a previous result of the same NLP structure (e.g. the neighbouring wind
speed of a sweep) with its multipliers, or from another structure's result interpolated as the
initial guess; on failure the cold strategy follows (or less, ``warm_fallback``).

Limits are iteration counts (per attempt and over all attempts of one solve, deterministic);
wall time is only a safety net.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..pointmass.model import wind_vector
from .assemble import accept, failed_result, ok_result
from .build import structure_key
from .collocation import DEFAULT_MAX_CPU_S, DEFAULT_MAX_ITER, CycleNLP, RawSolution
from .guess import LoopStart, default_starts, guess_from_result, loop_guess
from .problem import CycleProblem
from .result import CycleResult
from .transfer import same_but_recovery_tension, transfer_result

#: IPOPT iterations per attempt (one NLP solve) and over all attempts of one ``solve_cycle``
MAX_ITER = DEFAULT_MAX_ITER
MAX_ITER_TOTAL = 3000
#: wall-clock safety net [s] of one ``solve_cycle`` (the iteration budget is the primary limit)
SAFETY_WALL_S = DEFAULT_MAX_CPU_S
#: weight of the exact L1 penalty on the elastic slacks (per recovery interval, relative to the
#: scaled objective) and the largest scaled slack counted as zero
ELASTIC_PENALTY = 1000.0
ELASTIC_SLACK_TOL = 1e-6

#: warm start: primal-dual restart with a small monotone barrier (measured at the default mesh,
#: physical nominal 8 -> 8.25 / 8.5 m/s: 188 / 199 iterations where the adaptive barrier from
#: mu 1e-4 took 211 and at +0.5 m/s lost the warm start; with the 1e-6 tolerances 198 / 196,
#: because the neighbouring wind's optimum is another local optimum: -11.8 -> -5.9 W; paper
#: foldable 3 -> 3.25 m/s: 20 iterations)
WARM_OPTIONS = {"ipopt.warm_start_init_point": "yes", "ipopt.warm_start_bound_push": 1e-6,
                "ipopt.warm_start_mult_bound_push": 1e-6, "ipopt.mu_init": 1e-5, "ipopt.mu_strategy": "monotone"}

#: the morph of the recovery's aerodynamics from the nominal wing to the folded one (foldable
#: glider) and the tether-drag factors of the drag homotopy, each step from the previous solution
MORPH_STEPS = (0.0, 0.25, 0.5, 0.75, 1.0)
DRAG_STEPS = (0.0, 0.5, 1.0)


def attempt_options(max_iter: int, time_budget_s: float, ipopt_options: dict | None) -> dict[str, Any]:
    """IPOPT options of every attempt of a call that differ from the NLP's defaults (each
    distinct option set builds its own solver)."""
    opts: dict[str, Any] = {}
    if int(max_iter) != MAX_ITER:
        opts["ipopt.max_iter"] = int(max_iter)
    if float(time_budget_s) != SAFETY_WALL_S:
        opts["ipopt.max_cpu_time"] = float(max(time_budget_s, 1.0))
    opts.update(ipopt_options or {})
    return opts


class LocalSolve:
    """The attempts of one local solve of ``nlp`` (built in ``nlp_build_s`` [s] by this call):
    they share the iteration budget ``max_iter_total`` and the wall-time safety net
    ``time_budget_s`` [s]; each failed one leaves its reason."""

    def __init__(self, problem: CycleProblem, nlp: CycleNLP, nlp_build_s: float, *, ipopt_options: dict | None,
                 time_budget_s: float, max_iter: int, max_iter_total: int) -> None:
        self.problem, self.nlp = problem, nlp
        self.nlp_build_s = nlp_build_s
        self.solvers_s0 = nlp.solvers_build_s
        self.wind = wind_vector(problem.wind_speed, problem.wind_from_deg)[:2]
        self.time_budget_s, self.max_iter_total = time_budget_s, max_iter_total
        self.base_opts = attempt_options(max_iter, time_budget_s, ipopt_options)
        self.total_s = 0.0  #: solver time so far [s]
        self.total_it = 0  #: IPOPT iterations so far
        self.reasons: list[str] = []  #: why the failed attempts failed
        self.elastic_slack: list[float] = []  #: largest slack of each converged elastic solve (scaled)

    def built(self) -> float:
        """Build time of this call [s]: the NLP (if not cached) and the IPOPT instances created."""
        return self.nlp_build_s + self.nlp.solvers_build_s - self.solvers_s0

    def run(self, w0: np.ndarray, k: int, drag: float, morph: float = 1.0, lam_x: np.ndarray | None = None,
            lam_g: np.ndarray | None = None, opts: dict | None = None, elastic: bool = False) -> RawSolution:
        """One IPOPT solve from ``w0`` (heading wrap ``k``, tether-drag factor ``drag``, morph
        ``morph``, multipliers ``lam_*``, extra options ``opts``, the ``elastic`` mode), or a
        failed solution naming the budget when it is spent."""
        nlp = self.nlp
        params = nlp.params(self.wind, drag, k, morph, ELASTIC_PENALTY if elastic else 0.0)
        if self.total_it >= self.max_iter_total or self.total_s > self.time_budget_s:
            why = (f"iteration budget of {self.max_iter_total} used up" if self.total_it >= self.max_iter_total
                   else f"wall-time safety net of {self.time_budget_s:g} s reached")
            return RawSolution("failed", why, 0, 0.0, w0, np.zeros_like(w0), np.zeros(len(nlp.lbg)), math.nan, params)
        o = dict(self.base_opts)
        if opts:
            o.update(opts)
        r = nlp.solve(w0, params, lam_x, lam_g, o or None, elastic=elastic)
        self.total_s += r.solve_s
        self.total_it += r.iterations
        return r

    def finish(self, k: int, label: str, r: RawSolution) -> CycleResult:
        """The result of the accepted solution ``r`` with this call's times and iterations."""
        return ok_result(self.problem, self.nlp, k, label, r, self.built(), self.total_s, self.total_it)

    def failed(self, reason: str) -> CycleResult:
        """The failed result of this call."""
        return failed_result(self.problem, reason, self.total_s, self.built(), self.total_it)

    def from_warm(self, warm: CycleResult) -> CycleResult | None:
        """A solve started from the successful result ``warm``: with its multipliers when it has
        this NLP's structure, else from its trajectory as the initial guess; None when it fails
        (its reason noted)."""
        nlp = self.nlp
        if warm.key == structure_key(self.problem) and warm.w is not None:
            label, k = "warm start", warm.k_wrap
            r = self.run(warm.w, k, 1.0, 1.0, warm.lam_x, warm.lam_g, WARM_OPTIONS)
        elif warm.w is not None and warm.problem is not None and same_but_recovery_tension(warm.problem, self.problem):
            # the same mesh with the recovery's tension fixed or free: primal-dual, by name
            from .build import get_nlp

            label, k = "warm start", warm.k_wrap
            w0, lx, lg = transfer_result(warm, nlp, get_nlp(warm.problem)[0])
            r = self.run(w0, k, 1.0, 1.0, lx, lg, WARM_OPTIONS)
        else:
            label = "from a previous solution"
            phases, k = guess_from_result(warm, nlp.model)
            r = self.run(nlp.pack(phases), k, 1.0, 1.0)
        if accept(nlp, r):
            return self.finish(k, label, r)
        self.reasons.append(f"{label}: {r.reason}")
        return None

    def single(self, start: LoopStart) -> CycleResult | None:
        """One IPOPT solve from ``start``, no continuation; None when it fails (its reason noted)."""
        phases, k = loop_guess(self.problem, self.nlp.model, start, self.wind)
        r = self.run(self.nlp.pack(phases), k, 1.0, 1.0)
        if accept(self.nlp, r):
            return self.finish(k, start.label(), r)
        self.reasons.append(f"{start.label()} (one cold solve): {r.reason}")
        return None

    def continuation(self, w0: np.ndarray, k: int, steps: list[tuple[float, float]]) -> RawSolution:
        """Solves along ``steps`` of (tether-drag factor, morph), each started from the previous
        solution; the last solve's solution (the first failed one stops the path)."""
        w = w0
        for drag, morph in steps:
            r = self.run(w, k, drag, morph)
            if not accept(self.nlp, r):
                break
            w = r.w
        return r

    def attempt(self, w0: np.ndarray, k: int) -> RawSolution:
        """Direct solve; on failure, for the foldable glider an elastic solve (the recovery's
        dynamics slacks open, exact L1 penalty) and the strict problem from it if its slacks
        vanished, then a continuation from the nominal recovery (:data:`MORPH_STEPS`); then
        (tether drag) a homotopy in the tether drag (:data:`DRAG_STEPS`)."""
        nlp = self.nlp
        r = self.run(w0, k, 1.0, 1.0)
        if accept(nlp, r):
            return r
        if self.problem.config == "foldable":
            re = self.run(w0, k, 1.0, 1.0, elastic=True)
            if re.status == "ok":
                self.elastic_slack.append(nlp.max_slack(re.w))
                if self.elastic_slack[-1] <= ELASTIC_SLACK_TOL:
                    r = self.run(re.w, k, 1.0, 1.0)
                    if accept(nlp, r):
                        return r
            r = self.continuation(w0, k, [(1.0, morph) for morph in MORPH_STEPS])
            if accept(nlp, r):
                return r
        if nlp.model.scenario.tether_drag:
            r = self.continuation(w0, k, [(drag, 1.0) for drag in DRAG_STEPS])
        return r

    def best_of(self, starts: list[LoopStart], n_starts: int) -> CycleResult:
        """The starts in order (each by :meth:`attempt`) until ``n_starts`` succeeded; the best
        average power among them, or the failed result naming every start's reason."""
        best: tuple[float, RawSolution, int, str] | None = None
        n_ok = 0
        for st in starts:
            phases, k = loop_guess(self.problem, self.nlp.model, st, self.wind)
            r = self.attempt(self.nlp.pack(phases), k)
            if accept(self.nlp, r):
                n_ok += 1
                if best is None or r.objective < best[0]:
                    best = (r.objective, r, k, st.label())
                if n_ok >= n_starts:
                    break
            else:
                self.reasons.append(f"{st.label()}: {r.reason}")
        if best is None:
            reason = "; ".join(self.reasons) or "no start converged"
            if self.elastic_slack and min(self.elastic_slack) > ELASTIC_SLACK_TOL:
                reason = (f"no feasible cycle found: the elastic feasibility solves end with a fictitious acceleration "
                          f"of {min(self.elastic_slack):.3g} (scaled) left in the folded recovery (locally infeasible; "
                          f"README: folding, line drag and T <= T_avail(V)); {reason}")
            return self.failed(reason)
        _, r, k, label = best
        return self.finish(k, label, r)


def solve_local(problem: CycleProblem, nlp: CycleNLP, nlp_build_s: float, *, warm: CycleResult | None,
                starts: list[LoopStart] | None, n_starts: int, warm_fallback: str, cold: str,
                ipopt_options: dict | None, time_budget_s: float, max_iter: int, max_iter_total: int) -> CycleResult:
    """The local strategy on ``nlp`` (module docstring; the arguments as
    :func:`fdm_awe.ocp.solve.solve_cycle`'s): the warm start, then what ``warm_fallback`` or
    ``cold`` allow: nothing, one solve from the first start, or every start with its
    continuations."""
    ls = LocalSolve(problem, nlp, nlp_build_s, ipopt_options=ipopt_options, time_budget_s=time_budget_s,
                    max_iter=max_iter, max_iter_total=max_iter_total)
    if warm is not None and warm.key == structure_key(problem) and warm.w is not None and len(warm.w) != nlp.nw:
        warm = None  # a vector of another NLP layout (e.g. stored by an older version): start cold
    if warm is not None and warm.ok:
        res = ls.from_warm(warm)
        if res is not None:
            return res
    one_cold = warm is None and cold == "one"
    if (ls.reasons and warm_fallback != "all") or one_cold:
        if warm_fallback == "one" or one_cold:
            res = ls.single((starts or default_starts(problem))[0])
            if res is not None:
                return res
        return ls.failed("; ".join(ls.reasons))
    return ls.best_of(starts or default_starts(problem), n_starts)
