"""Solve the cycle OCP robustly: a global multi-start strategy, homotopy, warm starts, NLP caches.

``solve_cycle(problem)`` returns a :class:`CycleResult` whose ``status`` is ``"ok"`` only when
IPOPT reports success AND the scaled constraints hold within :data:`VIOLATION_TOL`; otherwise
``"failed"`` with the reason (never a result presented as valid).

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

Local strategy (one start, or ``strategy="first"``): for each start solve the NLP; if
it fails and the scenario has tether drag, retry by homotopy (tether drag factor 0 -> 0.5 -> 1,
each step started from the previous solution); for the foldable glider, finally through the
nominal recovery (aerodynamics morphed 0 -> 1); the foldable glider first tries an elastic solve
(fictitious accelerations in the recovery dynamics, exact L1 penalty) whose result starts the
strict problem only if every slack vanished (a feasibility aid, never a relaxation: a result
always satisfies the strict problem). Starts are tried until ``n_starts`` succeeded;
the best average power among them is kept. Warm: start from a previous result of the same NLP
structure (e.g. the neighbouring wind speed of a sweep) with its multipliers; on failure fall
back to the cold strategy.

Limits are iteration counts (per attempt and in total, deterministic; in the global strategy
per start and per refinement); wall time is only a safety net. Built NLPs are cached per
structure (scenario, configuration, geometry, bounds, mesh) in the process, so sweeps and
repeated solves pay the build once, and on disk (:mod:`fdm_awe.ocp.nlpcache`), so a new
process loads them instead of building them.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from typing import Any

import numpy as np

from ..definitions.aircraft import Glider, load_glider
from ..pointmass.model import wind_vector
from .collocation import DEFAULT_MAX_CPU_S, DEFAULT_MAX_ITER, CycleNLP, RawSolution
from .energy import WinchElectrics
from .guess import LoopStart, default_starts, guess_from_result, loop_guess
from . import nlpcache
from .model import CycleModel
from .problem import CycleProblem, Mesh
from .result import CycleResult
from .strategy import (COLD_CHECK_W, REFINE, TIE_W, Outcome, auto_workers, family, outcome_record, refine_candidates,
                       run_tasks, select, strategy_starts)

#: largest scaled constraint violation accepted as a solution
VIOLATION_TOL = 1e-6

#: IPOPT iterations per attempt (one NLP solve) and over all attempts of one ``solve_cycle``
MAX_ITER = DEFAULT_MAX_ITER
MAX_ITER_TOTAL = 3000
#: wall-clock safety net [s] of one ``solve_cycle`` (the iteration budget is the primary limit)
SAFETY_WALL_S = DEFAULT_MAX_CPU_S
#: weight of the exact L1 penalty on the elastic slacks (per recovery interval, relative to the
#: scaled objective) and the largest scaled slack counted as zero
ELASTIC_PENALTY = 1000.0
ELASTIC_SLACK_TOL = 1e-6

#: mesh of the first, cheap solve of a cold start; the target mesh is then solved from its
#: interpolated solution (mesh continuation)
COARSE_MESH = Mesh(20, 10, 3)

#: what ``solve_cycle`` tries after a failed warm start (see its ``warm_fallback``)
WARM_FALLBACKS = ("all", "one", "none")

_CACHE: "OrderedDict[tuple, CycleNLP]" = OrderedDict()

#: built NLPs kept per process (least recently used dropped first); a sweep over design
#: variants walks each variant's wind chain, so a few entries give every chain one build
CACHE_SIZE = 8

#: warm start: primal-dual restart with a small monotone barrier (measured at the default mesh,
#: physical nominal 8 -> 8.25 / 8.5 m/s: 188 / 199 iterations where the adaptive barrier from
#: mu 1e-4 took 211 and at +0.5 m/s lost the warm start; with the 1e-6 tolerances 198 / 196,
#: because the neighbouring wind's optimum is another local optimum: -11.8 -> -5.9 W; paper
#: foldable 3 -> 3.25 m/s: 20 iterations)
WARM_OPTIONS = {"ipopt.warm_start_init_point": "yes", "ipopt.warm_start_bound_push": 1e-6,
                "ipopt.warm_start_mult_bound_push": 1e-6, "ipopt.mu_init": 1e-5, "ipopt.mu_strategy": "monotone"}


#: the final polish of the global strategy: a primal-dual warm start from the winner, as
#: :data:`WARM_OPTIONS`, with a 100x tighter optimality and a 100x tighter constraint tolerance
POLISH_OPTIONS = {**WARM_OPTIONS, "ipopt.tol": 1e-8, "ipopt.constr_viol_tol": 1e-9}

#: cold strategies of ``solve_cycle`` (see its ``strategy``)
STRATEGIES = ("auto", "global", "first")


def _attempt_options(max_iter: int, time_budget_s: float, ipopt_options: dict | None) -> dict[str, Any]:
    """IPOPT options of every attempt of a call that differ from the NLP's defaults (each
    distinct option set builds its own solver)."""
    opts: dict[str, Any] = {}
    if int(max_iter) != MAX_ITER:
        opts["ipopt.max_iter"] = int(max_iter)
    if float(time_budget_s) != SAFETY_WALL_S:
        opts["ipopt.max_cpu_time"] = float(max(time_budget_s, 1.0))
    opts.update(ipopt_options or {})
    return opts


def structure_key(problem: CycleProblem) -> tuple:
    """Everything that shapes the NLP except the wind (a parameter)."""
    return (problem.scenario, problem.config, problem.d0, problem.d_tf, problem.elevation0_deg, problem.azimuth0_deg,
            problem.bounds, problem.mesh, problem.tether_drag_scale, problem.propeller,
            problem.line_weight, problem.line, problem.fold_time, problem.generator, problem.wind_profile)


def get_nlp(problem: CycleProblem, glider: Glider | None = None, winch: WinchElectrics | None = None,
            cache: bool = True, disk_cache: bool | None = None) -> tuple[CycleNLP, float]:
    """The NLP for ``problem`` (built or from the caches) and the build time [s] spent now.

    ``disk_cache`` (default: the same as ``cache``): look the NLP up in the on-disk cache of
    :mod:`fdm_awe.ocp.nlpcache` before building it, and store a newly built one there.

    The cache key is the problem's structure plus the glider and winch values (both frozen
    dataclasses compared by value), so a custom glider variant is built once per process and
    reused for every wind speed of its sweep chain.
    """
    if disk_cache is None:
        disk_cache = cache
    key = (structure_key(problem), glider, winch)
    if cache and key in _CACHE:
        _CACHE.move_to_end(key)
        return _CACHE[key], 0.0
    model = CycleModel.build(problem, glider or load_glider(), winch or WinchElectrics.from_ground_station(line=problem.line))
    nlp = nlpcache.load(problem, model) if disk_cache else None
    if nlp is None:
        nlp = CycleNLP(problem, model)
        if disk_cache:
            s0 = nlp.solvers_build_s
            nlpcache.save(nlp, background=True)  # generates the derivative functions (the first IPOPT instance)
            nlp.build_s += nlp.solvers_build_s - s0  # counted once, as the build of this NLP
            nlp.solvers_build_s = s0
    if cache:
        _CACHE[key] = nlp
        while len(_CACHE) > CACHE_SIZE:
            _CACHE.popitem(last=False)
    return nlp, nlp.build_s


def clear_cache() -> None:
    _CACHE.clear()


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
    if strategy == "auto":
        strategy = "global" if (coarse and warm is None and cold == "all") else "first"
    if strategy == "global" and warm is None and cold == "all":
        return _solve_global(problem, starts, coarse or None, limits, workers, polish)
    if coarse and warm is None:
        from dataclasses import replace as _replace

        first = solve_cycle(_replace(problem, mesh=coarse), starts=starts, n_starts=n_starts, glider=glider,
                            winch=winch, ipopt_options=ipopt_options, cache=cache, coarse=None,
                            time_budget_s=time_budget_s, max_iter=max_iter, max_iter_total=max_iter_total,
                            cold=cold)
        if first.ok:
            res = solve_cycle(problem, warm=first, glider=glider, winch=winch, ipopt_options=ipopt_options,
                              cache=cache, coarse=None,
                              time_budget_s=time_budget_s, max_iter=max_iter,
                              max_iter_total=max(max_iter_total - first.iterations, 1))
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
    nlp, nlp_build_s = get_nlp(problem, glider, winch, cache)
    solvers_s0 = nlp.solvers_build_s

    def built() -> float:
        """Build time of this call [s]: the NLP (if not cached) and the IPOPT instances created."""
        return nlp_build_s + nlp.solvers_build_s - solvers_s0

    wind = wind_vector(problem.wind_speed, problem.wind_from_deg)[:2]
    total_s = 0.0
    total_it = 0
    reasons: list[str] = []
    base_opts = _attempt_options(max_iter, time_budget_s, ipopt_options)

    def run(w0: np.ndarray, k: int, drag: float, morph: float = 1.0, lam_x=None, lam_g=None, opts=None,
            elastic: bool = False) -> RawSolution:
        nonlocal total_s, total_it
        params = nlp.params(wind, drag, k, morph, ELASTIC_PENALTY if elastic else 0.0)
        if total_it >= max_iter_total or total_s > time_budget_s:
            why = (f"iteration budget of {max_iter_total} used up" if total_it >= max_iter_total
                   else f"wall-time safety net of {time_budget_s:g} s reached")
            return RawSolution("failed", why, 0, 0.0, w0, np.zeros_like(w0), np.zeros(len(nlp.lbg)), math.nan, params)
        o = dict(base_opts)
        if opts:
            o.update(opts)
        r = nlp.solve(w0, params, lam_x, lam_g, o or None, elastic=elastic)
        total_s += r.solve_s
        total_it += r.iterations
        return r

    if warm is not None and warm.key == structure_key(problem) and warm.w is not None and len(warm.w) != nlp.nw:
        warm = None  # a vector of another NLP layout (e.g. stored by an older version): start cold
    if warm is not None and warm.ok and warm.key == structure_key(problem) and warm.w is not None:
        r = run(warm.w, warm.k_wrap, 1.0, 1.0, warm.lam_x, warm.lam_g, WARM_OPTIONS)
        if _accept(nlp, r):
            return _finish(problem, nlp, warm.k_wrap, "warm start", r, built(), total_s, total_it)
        reasons.append(f"warm start: {r.reason}")
    elif warm is not None and warm.ok:
        phases, k = guess_from_result(warm, nlp.model)
        r = run(nlp.pack(phases), k, 1.0, 1.0)
        if _accept(nlp, r):
            return _finish(problem, nlp, k, "from a previous solution", r, built(), total_s, total_it)
        reasons.append(f"from a previous solution: {r.reason}")
    one_cold = warm is None and cold == "one"
    if (reasons and warm_fallback != "all") or one_cold:
        if warm_fallback == "one" or one_cold:
            st = (starts or default_starts(problem))[0]
            phases, k = loop_guess(problem, nlp.model, st, wind)
            r = run(nlp.pack(phases), k, 1.0, 1.0)
            if _accept(nlp, r):
                return _finish(problem, nlp, k, st.label(), r, built(), total_s, total_it)
            reasons.append(f"{st.label()} (one cold solve): {r.reason}")
        return CycleResult(problem.scenario, problem.config, problem.wind_speed, problem.wind_from_deg, "failed",
                           "; ".join(reasons), total_s, built(), total_it, problem=problem, key=structure_key(problem))

    foldable = problem.config == "foldable"
    drag_homotopy = nlp.model.scenario.tether_drag

    elastic_slack: list[float] = []

    def attempt(w0: np.ndarray, k: int) -> RawSolution:
        """Direct solve; on failure, for the foldable glider an elastic solve (the recovery's
        dynamics slacks open, exact L1 penalty) and the strict problem from it if its slacks
        vanished, then a continuation from the nominal recovery (aerodynamics morphed 0 -> 1 in
        quarters); then (tether drag) a homotopy in the tether drag (0 -> 0.5 -> 1)."""
        r = run(w0, k, 1.0, 1.0)
        if _accept(nlp, r):
            return r
        if foldable:
            re = run(w0, k, 1.0, 1.0, elastic=True)
            if re.status == "ok":
                elastic_slack.append(nlp.max_slack(re.w))
                if elastic_slack[-1] <= ELASTIC_SLACK_TOL:
                    r = run(re.w, k, 1.0, 1.0)
                    if _accept(nlp, r):
                        return r
            w = w0
            for morph in (0.0, 0.25, 0.5, 0.75, 1.0):
                r = run(w, k, 1.0, morph)
                if not _accept(nlp, r):
                    break
                w = r.w
            if _accept(nlp, r):
                return r
        if drag_homotopy:
            w = w0
            for drag in (0.0, 0.5, 1.0):
                r = run(w, k, drag, 1.0)
                if not _accept(nlp, r):
                    break
                w = r.w
        return r

    best: tuple[float, RawSolution, int, str] | None = None
    n_ok = 0
    for st in starts or default_starts(problem):
        phases, k = loop_guess(problem, nlp.model, st, wind)
        r = attempt(nlp.pack(phases), k)
        if _accept(nlp, r):
            n_ok += 1
            if best is None or r.objective < best[0]:
                best = (r.objective, r, k, st.label())
            if n_ok >= n_starts:
                break
        else:
            reasons.append(f"{st.label()}: {r.reason}")
    if best is None:
        reason = "; ".join(reasons) or "no start converged"
        if elastic_slack and min(elastic_slack) > ELASTIC_SLACK_TOL:
            reason = (f"no feasible cycle found: the elastic feasibility solves end with a fictitious acceleration "
                      f"of {min(elastic_slack):.3g} (scaled) left in the folded recovery (locally infeasible; README: "
                      f"folding, line drag and T <= T_avail(V)); {reason}")
        return CycleResult(problem.scenario, problem.config, problem.wind_speed, problem.wind_from_deg, "failed",
                           reason, total_s, built(), total_it, problem=problem, key=structure_key(problem))
    _, r, k, label = best
    return _finish(problem, nlp, k, label, r, built(), total_s, total_it)


def _mesh_name(mesh: Mesh) -> str:
    return f"{mesh.n_gen}/{mesh.n_rec}/{mesh.degree}"


def _prebuild(problem: CycleProblem, limits: dict[str, Any], options: dict | None = None) -> float:
    """Build (or fetch) the NLP of ``problem`` and its IPOPT instance for the attempts' options
    in this process, so that forked workers inherit them; returns the build time spent [s]."""
    if not limits["cache"]:
        return 0.0
    nlp, b = get_nlp(problem, limits["glider"], limits["winch"])
    s0 = nlp.solvers_build_s
    opts = options if options is not None else _attempt_options(limits["max_iter"], limits["time_budget_s"],
                                                               limits["ipopt_options"])
    nlp._solver(opts or None)
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
    from dataclasses import replace as _replace

    starts = list(starts) if starts else strategy_starts(problem)
    labels = [f"{family(st)}: {st.label()}" for st in starts]
    explore = _replace(problem, mesh=coarse) if coarse else problem
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
        res = CycleResult(problem.scenario, problem.config, problem.wind_speed, problem.wind_from_deg, "failed", reason,
                          solve_s, build_s, iterations, problem=problem, key=structure_key(problem))
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
    opts = {**_attempt_options(limits["max_iter"], limits["time_budget_s"], limits["ipopt_options"]), **POLISH_OPTIONS}
    r = nlp.solve(best.w, params, best.lam_x, best.lam_g, opts)
    built = b + nlp.solvers_build_s - s0
    info: dict[str, Any] = {"status": "ok" if _accept(nlp, r) else "failed", "iterations": int(r.iterations),
                            "solve_s": round(r.solve_s, 4), "P_before_W": round(best.P_avg_W, 6)}
    if info["status"] != "ok":
        info["reason"] = r.reason
        return best, info, built
    res = _finish(problem, nlp, best.k_wrap, best.start + ", polished", r, 0.0, 0.0, 0)
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


def _accept(nlp: CycleNLP, r: RawSolution | None) -> bool:
    """IPOPT success, finite objective and scaled constraints within :data:`VIOLATION_TOL`."""
    if r is None or r.status != "ok":
        return False
    viol, where = nlp.constraint_violation(r.w, r.params)
    if not (viol <= VIOLATION_TOL) or not math.isfinite(r.objective):
        r.status, r.reason = "failed", f"constraint {where} violated by {viol:.2e} after '{r.reason}'"
        return False
    return True


def _finish(problem: CycleProblem, nlp: CycleNLP, k: int, label: str, r: RawSolution, build_s: float,
            total_s: float, total_it: int) -> CycleResult:
    en = nlp.energies(r.w, r.params)
    viol, _ = nlp.constraint_violation(r.w, r.params)
    phases = nlp.unpack(r.w)
    res = CycleResult(problem.scenario, problem.config, problem.wind_speed, problem.wind_from_deg, "ok", r.reason,
                      total_s, build_s, total_it, en["T1_s"], en["T2_s"], en["E_generated_J"], en["E_thrust_J"],
                      en["E_reel_in_J"], k, label, viol, trajectory_columns(nlp, phases, r.params), r.w, r.lam_x,
                      r.lam_g, structure_key(problem), phases, problem=problem,
                      fold_time_s=nlp.model.fold_time, motor_off=nlp.model.motor_off)
    return res


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
