"""Solve the cycle OCP robustly: a global multi-start strategy, homotopy, warm starts, NLP caches.

``solve_cycle(problem)`` returns a :class:`CycleResult` whose ``status`` is ``"ok"`` only when
IPOPT reports success AND the scaled constraints hold within
:data:`fdm_awe.ocp.assemble.VIOLATION_TOL`; otherwise ``"failed"`` with the reason (never a
result presented as valid; :mod:`fdm_awe.ocp.assemble`).

Global strategy (a cold solve through the coarse mesh, the default of ``fdm-awe optimize``;
:mod:`fdm_awe.ocp.strategy`, docs/design.md section 5): every start of
:func:`fdm_awe.ocp.strategy.strategy_starts` (loops and figures of eight, both turn
directions) is solved to a local optimum on :data:`COARSE_MESH` by the local strategy below,
in parallel processes; those within :data:`fdm_awe.ocp.strategy.REFINE_BAND_W` of the best
average power (at least :data:`fdm_awe.ocp.strategy.REFINE`; ties within
:data:`fdm_awe.ocp.strategy.TIE_W` to the earlier start) are refined to the target mesh;
the winner by the same rule is polished (:data:`POLISH_OPTIONS`). ``result.strategy`` records
every start's outcome. ``cold_check=True`` compares a warm-started solution with a cold solve
of the same point and keeps the better.

Local strategy (one start, or ``strategy="first"``; :mod:`fdm_awe.ocp.local`): each start
solved directly, then by its continuations (elastic solve, morph of the folded recovery,
tether-drag homotopy) until ``n_starts`` succeeded, the best kept; a warm start from a
previous result first, with a cold fallback.

Limits are iteration counts (per attempt and in total, deterministic; in the global strategy
per start and per refinement); wall time is only a safety net. Built NLPs are cached per
structure (scenario, configuration, geometry, bounds, mesh) in the process, so sweeps and
repeated solves pay the build once, and on disk (:mod:`fdm_awe.ocp.nlpcache`), so a new
process loads them instead of building them (:mod:`fdm_awe.ocp.build`).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

from ..definitions.aircraft import Glider
from ..pointmass.model import wind_vector
from .assemble import accept, failed_result, ok_result
from .collocation import RawSolution
from .transfer import transfer_result
from .build import get_nlp, structure_key
from .energy import WinchElectrics
from .guess import LoopStart
from .local import MAX_ITER, MAX_ITER_TOTAL, SAFETY_WALL_S, WARM_OPTIONS, attempt_options, solve_local
from .problem import CycleProblem, Mesh
from .result import CycleResult
from .strategy import (COLD_CHECK_W, REFINE, TIE_W, Outcome, auto_workers, family, outcome_record, refine_candidates,
                       run_tasks, select, strategy_starts)

#: the entry points of the optimiser (the NLP caches' are :mod:`fdm_awe.ocp.build`'s)
__all__ = ["COARSE_MESH", "POLISH_OPTIONS", "STRATEGIES", "WARM_FALLBACKS", "solve_cycle"]

#: mesh of the first, cheap solve of a cold start; the target mesh is then solved from its
#: interpolated solution (mesh continuation)
COARSE_MESH = Mesh(20, 10, 3)

#: what ``solve_cycle`` tries after a failed warm start (see its ``warm_fallback``)
WARM_FALLBACKS = ("all", "one", "none")

#: the final polish of the global strategy: a primal-dual warm start from the winner, as
#: :data:`fdm_awe.ocp.local.WARM_OPTIONS`, with a 100x tighter optimality and a 100x tighter
#: constraint tolerance
POLISH_OPTIONS = {**WARM_OPTIONS, "ipopt.tol": 1e-8, "ipopt.constr_viol_tol": 1e-9}

#: cold strategies of ``solve_cycle`` (see its ``strategy``)
STRATEGIES = ("auto", "global", "first")


def solve_cycle(problem: CycleProblem, *, warm: CycleResult | None = None, starts: list[LoopStart] | None = None,
                n_starts: int = 1, glider: Glider | None = None, winch: WinchElectrics | None = None,
                ipopt_options: dict | None = None, cache: bool = True, coarse: Mesh | None | bool = True,
                time_budget_s: float = SAFETY_WALL_S, max_iter: int = MAX_ITER, max_iter_total: int = MAX_ITER_TOTAL,
                warm_fallback: str = "all", cold: str = "all", strategy: str = "auto", workers: int | None = None,
                polish: bool = True, cold_check: bool = False) -> CycleResult:
    """Optimise one pumping cycle (see the module docstring).

    ``strategy``: ``"global"`` (every start of :func:`fdm_awe.ocp.strategy.strategy_starts`, or
    of ``starts``, solved to a local optimum on the coarse mesh, the best refined to the target
    mesh and polished, :mod:`fdm_awe.ocp.strategy`), ``"first"`` (the starts in order until
    ``n_starts`` succeeded, the best of those), or ``"auto"`` (the default: ``"global"`` for a
    cold solve that goes through a coarse mesh, ``"first"`` otherwise, e.g. a direct solve of a
    coarse mesh or the fallback after a failed warm start). ``workers``: processes for the
    independent starts of the global strategy (None: :func:`fdm_awe.ocp.strategy.auto_workers`);
    the result does not depend on it. ``polish``: the global strategy's final tighter re-solve.

    ``cold_check`` (with ``warm``): also solve the point cold (the global strategy) and keep the
    better of the two; ``result.strategy["cold_check"]`` records both powers and whether they
    differ by more than :data:`fdm_awe.ocp.strategy.COLD_CHECK_W` (a sweep's warm chain and a
    cold solve then never disagree silently).

    ``warm``: a previous result; the same NLP structure restarts with its multipliers, any
    other (different mesh or scenario) is interpolated as the initial guess. ``coarse``: mesh
    of a first cheap solve of each cold start (``True``: :data:`COARSE_MESH` when the target mesh
    is finer; ``None``/``False``: solve the target mesh directly).

    Limits (deterministic first): ``max_iter`` IPOPT iterations per attempt (an
    ``ipopt.max_iter`` in ``ipopt_options`` takes precedence), ``max_iter_total`` over all
    attempts of this call (checked before each attempt, so the last one may overrun it by at most
    one attempt). ``time_budget_s`` is only a wall-clock safety net (no new attempt after this
    much solver time; also IPOPT's CPU-time limit per attempt): with the defaults the iteration
    budget decides, so a busy machine does not change a result.

    ``warm_fallback``: what follows a failed warm start: ``"all"`` the whole cold strategy
    (every start with its continuations), ``"one"`` a single IPOPT solve from the first start,
    ``"none"`` nothing (the result is ``failed`` at once). The cheaper settings bound the cost of
    a point that cannot converge (a sweep's failure), at the risk of missing a cycle that only
    a later start or a continuation finds.

    ``cold``: the strategy without a warm start: ``"all"`` (every start with its continuations)
    or ``"one"`` (a single IPOPT solve from the first start, the same as ``warm_fallback="one"``
    after a failed warm start; a sweep uses it after a failed neighbour).
    """
    if warm_fallback not in WARM_FALLBACKS:
        raise ValueError(f"warm_fallback {warm_fallback!r} unknown (allowed: {', '.join(WARM_FALLBACKS)})")
    if cold not in ("all", "one"):
        raise ValueError(f"cold {cold!r} unknown (allowed: all, one)")
    if strategy not in STRATEGIES:
        raise ValueError(f"strategy {strategy!r} unknown (allowed: {', '.join(STRATEGIES)})")
    problem = problem.validate()
    if coarse is True:
        coarse = COARSE_MESH if problem.mesh.n_gen > COARSE_MESH.n_gen else None
    limits = dict(glider=glider, winch=winch, ipopt_options=ipopt_options, cache=cache, time_budget_s=time_budget_s,
                  max_iter=max_iter, max_iter_total=max_iter_total)
    if warm is not None and cold_check:
        return _with_cold_check(problem, warm, starts, coarse, limits, warm_fallback, strategy, workers, polish)
    if warm is None and problem.recovery_tension == "free":
        return _free_from_slack(problem, dict(starts=starts, n_starts=n_starts, coarse=coarse or None, cold=cold,
                                              strategy=strategy, workers=workers, polish=polish), limits)
    if strategy == "auto":
        strategy = "global" if (coarse and warm is None and cold == "all") else "first"
    if strategy == "global" and warm is None and cold == "all":
        return _solve_global(problem, starts, coarse or None, limits, workers, polish)
    if coarse and warm is None:
        return _solve_through_coarse(problem, coarse, starts, n_starts, cold, limits)
    nlp, nlp_build_s = get_nlp(problem, glider, winch, cache)
    return solve_local(problem, nlp, nlp_build_s, warm=warm, starts=starts, n_starts=n_starts,
                       warm_fallback=warm_fallback, cold=cold, ipopt_options=ipopt_options,
                       time_budget_s=time_budget_s, max_iter=max_iter, max_iter_total=max_iter_total)


def _free_from_slack(problem: CycleProblem, how: dict[str, Any], limits: dict[str, Any]) -> CycleResult:
    """A cold solve of the free recovery tension: the slack line's problem solved cold (``how``:
    the strategy's arguments), then the free problem warm from its optimum, primal-dual
    (:mod:`fdm_awe.ocp.transfer`; the slack recovery is one admissible recovery of the free
    problem, so the answer is at least the slack line's: where the warm solve fails or ends
    worse, the slack optimum itself is the answer). Where the global strategy ran, the warm solve
    has the polish's tolerances (:data:`POLISH_OPTIONS`) and replaces its polish. A cold solve of
    the free problem from the
    loop starts takes far more iterations (2249 against 66 + 22 at 8 m/s, foldable, mesh 20/10/3)
    and ends in no better optimum."""
    # the global strategy's polish is the free solve's (one tight solve instead of two)
    slack = solve_cycle(replace(problem, recovery_tension="slack"), **{**how, "polish": False}, **limits)
    if not slack.ok or slack.w is None:  # no cycle, or none to start from (nothing to carry over)
        slack.problem, slack.key = problem, structure_key(problem)
        return slack
    nlp, b = get_nlp(problem, limits["glider"], limits["winch"], limits["cache"])
    budget = max(limits["max_iter_total"] - slack.iterations, 1)
    tight = {**(limits["ipopt_options"] or {}), **POLISH_OPTIONS} if how["polish"] and slack.strategy else \
        limits["ipopt_options"]
    free = solve_cycle(problem, warm=slack, coarse=None, strategy="first", warm_fallback="none",
                       **{**limits, "max_iter_total": budget, "ipopt_options": tight})
    record = {"slack_P_avg_W": round(slack.P_avg_W, 6), "status": free.status, "iterations": int(free.iterations),
              "solve_s": round(free.solve_s, 4)}
    if free.ok and free.P_avg_W >= slack.P_avg_W:
        res = free
        record["P_avg_W"] = round(free.P_avg_W, 6)
    else:  # the slack optimum, as a point of the free problem (its tension zero)
        if free.ok:
            record["P_avg_W"] = round(free.P_avg_W, 6)
        elif free.reason:
            record["reason"] = str(free.reason)
        w, lx, lg = transfer_result(slack, nlp, get_nlp(slack.problem, limits["glider"], limits["winch"],
                                                        limits["cache"])[0])
        params = nlp.params(wind_vector(problem.wind_speed, problem.wind_from_deg)[:2], 1.0, slack.k_wrap, 1.0)
        r = RawSolution("ok", "the slack line's optimum", 0, 0.0, w, lx, lg, -slack.P_avg_W, params)
        if not accept(nlp, r):
            slack.problem, slack.key, slack.status, slack.reason = problem, structure_key(problem), "failed", r.reason
            return slack
        res = ok_result(problem, nlp, slack.k_wrap, slack.start + " (slack line)", r, 0.0, 0.0, 0)
    record["kept"] = "free" if res is free else "slack"
    res.strategy = {**(slack.strategy or {}), "recovery_tension": record}
    res.build_s = slack.build_s + free.build_s + (b if res is not free else 0.0)
    res.solve_s = slack.solve_s + free.solve_s
    res.iterations = slack.iterations + free.iterations
    if res is free:
        res.start = f"{slack.start}, then the free recovery tension"
    return res


def _solve_through_coarse(problem: CycleProblem, coarse: Mesh, starts: list[LoopStart] | None, n_starts: int,
                          cold: str, limits: dict[str, Any]) -> CycleResult:
    """Mesh continuation of the local strategy: its solve on the ``coarse`` mesh, then the target
    mesh started from that solution (interpolated) with what is left of the iteration budget."""
    first = solve_cycle(replace(problem, mesh=coarse), starts=starts, n_starts=n_starts, coarse=None, cold=cold,
                        **limits)
    if first.ok:
        res = solve_cycle(problem, warm=first, coarse=None,
                          **{**limits, "max_iter_total": max(limits["max_iter_total"] - first.iterations, 1)})
        res.build_s += first.build_s
        res.solve_s += first.solve_s
        res.iterations += first.iterations
        if res.ok:
            res.start = f"{first.start}, refined from mesh {coarse.n_gen}/{coarse.n_rec}/{coarse.degree}"
        return res
    # the coarse mesh found no cycle: the target mesh is not tried cold (same starts, same
    # strategy, many more variables); the reason names the coarse mesh
    first.reason = f"mesh {coarse.n_gen}/{coarse.n_rec}/{coarse.degree}: {first.reason}"
    first.problem, first.key = problem, structure_key(problem)
    return first


def _mesh_name(mesh: Mesh) -> str:
    return f"{mesh.n_gen}/{mesh.n_rec}/{mesh.degree}"


def _prebuild(problem: CycleProblem, limits: dict[str, Any], options: dict | None = None) -> float:
    """Build (or fetch) the NLP of ``problem`` and its IPOPT instance for the attempts' options
    in this process, so that forked workers inherit them; returns the build time spent [s]."""
    if not limits["cache"]:
        return 0.0
    nlp, b = get_nlp(problem, limits["glider"], limits["winch"])
    s0 = nlp.solvers_build_s
    opts = options if options is not None else attempt_options(limits["max_iter"], limits["time_budget_s"],
                                                               limits["ipopt_options"])
    nlp.solver_for(opts or None)
    return b + nlp.solvers_build_s - s0


def _explore_task(problem: CycleProblem, start: LoopStart, limits: dict[str, Any]) -> CycleResult:
    """One start of the global strategy solved to a local optimum on ``problem``'s mesh (the
    direct solve, then the local aids), with its own iteration budget."""
    return solve_cycle(problem, starts=[start], coarse=None, strategy="first", **limits)


def _refine_task(problem: CycleProblem, source: CycleResult, limits: dict[str, Any]) -> CycleResult:
    """A candidate of the exploration refined to ``problem``'s mesh (interpolated start; no
    fallback: another candidate takes its place if it fails)."""
    return solve_cycle(problem, warm=source, coarse=None, strategy="first", warm_fallback="none", **limits)


def _outcome(index: int, label: str, r: CycleResult) -> Outcome:
    return Outcome(index, label, r.ok, r.P_avg_W if r.ok else math.nan, int(r.iterations), float(r.solve_s),
                   "" if r.ok else str(r.reason), r)


def _solve_global(problem: CycleProblem, starts: list[LoopStart] | None, coarse: Mesh | None,
                  limits: dict[str, Any], workers: int | None, polish: bool) -> CycleResult:
    """The global strategy (:mod:`fdm_awe.ocp.strategy`): explore every start on the coarse mesh
    (or on the target mesh when ``coarse`` is None), refine the candidates of
    :func:`fdm_awe.ocp.strategy.refine_candidates`, pick by :func:`fdm_awe.ocp.strategy.select`,
    polish. Each start and each refinement has its
    own iteration budget (``max_iter_total``), so no outcome depends on another's."""
    starts = list(starts) if starts else strategy_starts(problem)
    labels = [f"{family(st)}: {st.label()}" for st in starts]
    explore = replace(problem, mesh=coarse) if coarse else problem
    n_workers = auto_workers(len(starts)) if workers is None else max(1, int(workers))
    build_s = _prebuild(explore, limits) if n_workers > 1 else 0.0
    explored = run_tasks(_explore_task, [(explore, st, limits) for st in starts], n_workers)
    outcomes = [_outcome(i, labels[i], r) for i, r in enumerate(explored)]
    build_s += sum(r.build_s for r in explored)
    solve_s = sum(r.solve_s for r in explored)
    iterations = sum(r.iterations for r in explored)
    record: dict[str, Any] = {"name": "global", "tie_W": TIE_W, "workers": n_workers,
                              "explore_mesh": _mesh_name(explore.mesh), "starts": [outcome_record(o) for o in outcomes]}
    ranked = select(outcomes)

    def failed(reason: str) -> CycleResult:
        res = failed_result(problem, reason, solve_s, build_s, iterations)
        res.strategy = record
        return res

    if not ranked:
        where = f"mesh {_mesh_name(explore.mesh)}: " if coarse else ""
        return failed(where + "; ".join(f"{o.label.split(':')[0]}: {o.reason}" for o in outcomes))
    if coarse:
        refined: list[Outcome] = []
        first = refine_candidates(ranked)
        todo = list(ranked)
        while todo and not any(o.ok for o in refined):
            size = len(first) if not refined else REFINE  # then the next ones, until one refines
            batch, todo = todo[:size], todo[size:]
            n = min(n_workers, len(batch))
            if n > 1:
                build_s += _prebuild(problem, limits)
            res = run_tasks(_refine_task, [(problem, o.payload, limits) for o in batch], n)
            refined += [_outcome(o.index, o.label, r) for o, r in zip(batch, res)]
            build_s += sum(r.build_s for r in res)
            solve_s += sum(r.solve_s for r in res)
            iterations += sum(r.iterations for r in res)
        record["refined"] = [outcome_record(o) for o in refined]
        ranked = select(refined)
        if not ranked:
            return failed("; ".join(f"{o.label.split(':')[0]} refined to mesh {_mesh_name(problem.mesh)}: {o.reason}"
                                    for o in refined))
    win = ranked[0]
    best: CycleResult = win.payload
    best.start = labels[win.index] + (f", refined from mesh {_mesh_name(coarse)}" if coarse else "")
    record["winner"] = {"index": win.index, "start": labels[win.index], "family": family(starts[win.index]),
                        "P_avg_W": round(win.P_avg_W, 6)}
    if polish:
        best, record["polish"], polish_build_s = _polish(problem, best, limits)
        build_s += polish_build_s
        solve_s += record["polish"]["solve_s"]
        iterations += record["polish"]["iterations"]
    best.build_s, best.solve_s, best.iterations = build_s, solve_s, iterations
    best.strategy = record
    return best


def _polish(problem: CycleProblem, best: CycleResult, limits: dict[str, Any]) -> tuple[CycleResult, dict[str, Any], float]:
    """The winner re-solved on its own mesh with :data:`POLISH_OPTIONS` (primal-dual warm
    start, tighter tolerances): the polished result if it is accepted, else ``best``; a record
    of the polish; the build time it spent [s]."""
    nlp, b = get_nlp(problem, limits["glider"], limits["winch"], limits["cache"])
    s0 = nlp.solvers_build_s
    wind = wind_vector(problem.wind_speed, problem.wind_from_deg)[:2]
    params = nlp.params(wind, 1.0, best.k_wrap, 1.0)
    opts = {**attempt_options(limits["max_iter"], limits["time_budget_s"], limits["ipopt_options"]), **POLISH_OPTIONS}
    r = nlp.solve(best.w, params, best.lam_x, best.lam_g, opts)
    built = b + nlp.solvers_build_s - s0
    info: dict[str, Any] = {"status": "ok" if accept(nlp, r) else "failed", "iterations": int(r.iterations),
                            "solve_s": round(r.solve_s, 4), "P_before_W": round(best.P_avg_W, 6)}
    if info["status"] != "ok":
        info["reason"] = r.reason
        return best, info, built
    res = ok_result(problem, nlp, best.k_wrap, best.start + ", polished", r, 0.0, 0.0, 0)
    info["P_after_W"] = round(res.P_avg_W, 6)
    return res, info, built


def _with_cold_check(problem: CycleProblem, warm: CycleResult, starts: list[LoopStart] | None, coarse: Mesh | None,
                     limits: dict[str, Any], warm_fallback: str, strategy: str, workers: int | None,
                     polish: bool) -> CycleResult:
    """The warm-started solution and a cold solve of the same point; the better is kept (a tie
    within :data:`TIE_W` keeps the warm one, the chain's continuation) and both are recorded."""
    rw = solve_cycle(problem, warm=warm, starts=starts, coarse=coarse, warm_fallback=warm_fallback, strategy=strategy,
                     workers=workers, polish=polish, **limits)
    rc = solve_cycle(problem, starts=starts, coarse=coarse if coarse else None,
                     strategy="global" if strategy == "auto" else strategy, workers=workers, polish=polish, **limits)
    ranked = select([_outcome(0, "warm", rw), _outcome(1, "cold", rc)])
    keep = ranked[0].payload if ranked else rw
    other = rc if keep is rw else rw
    diff = abs(rw.P_avg_W - rc.P_avg_W) if (rw.ok and rc.ok) else math.nan
    check = {"warm_status": rw.status, "cold_status": rc.status,
             "warm_P_avg_W": round(rw.P_avg_W, 6) if rw.ok else math.nan,
             "cold_P_avg_W": round(rc.P_avg_W, 6) if rc.ok else math.nan,
             "difference_W": round(diff, 6) if math.isfinite(diff) else math.nan,
             "disagree": bool(rw.ok != rc.ok or (math.isfinite(diff) and diff > COLD_CHECK_W)),
             "kept": "warm" if keep is rw else "cold", "tolerance_W": COLD_CHECK_W}
    keep.strategy = {**(keep.strategy or {}), "cold_check": check}
    if keep is rc and rw.strategy:
        keep.strategy["warm"] = rw.strategy
    if keep.ok and check["disagree"]:
        keep.start = f"{keep.start} (cold check: kept the {check['kept']} solution, {check['difference_W']:.2f} W apart)"
    keep.iterations += other.iterations
    keep.solve_s += other.solve_s
    keep.build_s += other.build_s
    return keep
