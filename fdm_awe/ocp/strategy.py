"""The global strategy of the cycle optimiser: which starts, how the winner is chosen, in parallel.

IPOPT finds a local optimum, and which one depends on the start and, over a few hundred
iterations, on the last bits of the machine's rounding. A single start therefore gives an
answer that can differ between two machines by several watts. The strategy (used by
:func:`fdm_awe.ocp.solve.solve_cycle` for a cold solve, docs/design.md section 5):

1. **Starts** (:func:`strategy_starts`): the two families of crosswind paths, loops and
   figures of eight, each with the recovery turning the same way as the generation or the
   other way; the generation's own turn direction both ways unless the problem is mirror
   symmetric (wind along the start's meridian, the default case), where a mirrored start is a
   mirror image of the same local optima and adds nothing. Sizes follow the wind (the
   guesses size the loops so that the generation's reel-out fits, :mod:`fdm_awe.ocp.guess`).
2. **Exploration**: every start is solved to a local optimum on the coarse mesh, each with the
   local aids (line-drag homotopy, morphing of the folded recovery, elastic solve) where the
   direct solve fails. Independent starts run in a process pool (:func:`run_tasks`).
3. **Selection** (:func:`select`): the best objective wins; objectives within
   :data:`TIE_W` of the best count as equal and the earliest start among them wins, so two
   machines whose rounding lands on the same optima choose the same start whatever order
   the workers finish in. The candidates within :data:`REFINE_BAND_W` of the best (at least
   :data:`REFINE`) are refined to the target mesh and the same rule picks among them.
4. **Polish**: a re-solve of the winner on the same mesh with tighter tolerances, started
   from its primal and dual solution; kept only if it converges.

Every start's outcome is recorded in ``CycleResult.strategy`` (:func:`outcome_record`).
"""

from __future__ import annotations

import math
import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, replace
from typing import Any, Callable, Sequence

from .guess import LoopStart, default_starts
from .problem import CycleProblem

#: objectives (as average power [W]) closer than this to the best count as a tie; the
#: earliest start among them wins
TIE_W = 0.05
#: candidates of the exploration refined to the target mesh: every start whose coarse-mesh power
#: is within REFINE_BAND_W [W] of the best, and at least the best REFINE (ties by start order).
#: The coarse mesh does not resolve the generator's stiff radial mode, so its powers are off by
#: watts and rank close optima by chance (measured at 8 m/s: coarse optima 2.0..2.3 W refine to
#: -13.2..-9.3 W, in another order); only clearly worse starts are left out
REFINE = 2
REFINE_BAND_W = 1.0
#: a warm-started solution and a cold solve of the same point that differ by more than this
#: [W] are reported (``solve_cycle(..., cold_check=True)`` keeps the better)
COLD_CHECK_W = 0.5
#: environment variable: worker processes of the start pool (``1`` serial; unset: automatic)
WORKERS_ENV = "FDM_AWE_OPT_WORKERS"
#: largest automatic number of worker processes
MAX_AUTO_WORKERS = 2


def mirror_symmetric(problem: CycleProblem, tol_deg: float = 1e-9) -> bool:
    """True when the problem is symmetric under the mirror through the start's meridian
    plane: the wind blows along that plane (from the side opposite the start or from the
    start's side), or there is no wind. A start and its mirror image then lead to mirrored
    local optima of equal objective."""
    if problem.wind_speed == 0.0:
        return True
    rel = (problem.wind_from_deg - problem.azimuth0_deg) % 180.0
    return min(rel, 180.0 - rel) <= tol_deg


def strategy_starts(problem: CycleProblem) -> list[LoopStart]:
    """The starts of the global strategy, in their tie-breaking order (see the module
    docstring): loops, then figures of eight; per family the recovery turning with the
    generation, then against it; the generation turning left (+1), then right (-1) unless the
    problem is mirror symmetric."""
    base = default_starts(problem)
    loop = next(s for s in base if s.shape == "loop")
    eight = next(s for s in base if s.shape == "eight")
    dirs1 = (1,) if mirror_symmetric(problem) else (1, -1)
    out = []
    for fam in (loop, eight):
        for d1 in dirs1:
            for rel in (1, -1):
                out.append(replace(fam, dir1=d1, dir2=d1 * rel))
    return out


def family(start: LoopStart) -> str:
    """Short name of a start's family and turn directions, e.g. ``loop +1/-1``."""
    return f"{start.shape} {start.dir1:+d}/{start.dir2:+d}"


@dataclass
class Outcome:
    """One start (or candidate) solved to a local optimum: ``index`` is its place in the start
    order (the tie-breaker); ``P_avg_W`` the cycle's average net power [W], the objective the
    NLP maximises (up to its small control-smoothing term; NaN when the start failed)."""

    index: int
    label: str
    ok: bool
    P_avg_W: float = math.nan
    iterations: int = 0
    solve_s: float = 0.0
    reason: str = ""
    payload: Any = None  #: the solver's result (not recorded)


def select(outcomes: Sequence[Outcome], tie_W: float = TIE_W) -> list[Outcome]:
    """The successful outcomes best first: by average power, where powers within ``tie_W`` [W]
    of the best count as equal and the earlier start wins; then the rest in the same way.

    Depends only on the outcomes' values and start indices, never on the order in which they
    arrive (a process pool's completion order)."""
    rest = sorted((o for o in outcomes if o.ok and math.isfinite(o.P_avg_W)), key=lambda o: o.index)
    ranked: list[Outcome] = []
    while rest:
        best = max(o.P_avg_W for o in rest)
        pick = min((o for o in rest if o.P_avg_W >= best - tie_W), key=lambda o: o.index)
        ranked.append(pick)
        rest.remove(pick)
    return ranked


def refine_candidates(ranked: Sequence[Outcome]) -> list[Outcome]:
    """The first candidates of ``ranked`` (:func:`select`'s order) to refine: those within
    :data:`REFINE_BAND_W` of the best power, at least :data:`REFINE`."""
    if not ranked:
        return []
    best = ranked[0].P_avg_W
    n = sum(1 for o in ranked if o.P_avg_W >= best - REFINE_BAND_W)
    return list(ranked[:max(n, REFINE)])


def outcome_record(o: Outcome) -> dict[str, Any]:
    """JSON-ready record of one outcome (NaN left for the JSON writer to turn into null)."""
    return {"index": o.index, "start": o.label, "status": "ok" if o.ok else "failed",
            "P_avg_W": round(o.P_avg_W, 6) if math.isfinite(o.P_avg_W) else math.nan,
            "iterations": o.iterations, "solve_s": round(o.solve_s, 4),
            **({} if o.ok else {"reason": o.reason})}


def optima_lines(record: dict[str, Any] | None, tie_W: float = TIE_W) -> list[str]:
    """Lines of the report saying which local optima the strategy met on the target mesh (the
    ``refined`` outcomes of a ``CycleResult.strategy`` record): the one kept, the others best
    first (powers within ``tie_W`` [W] of one already listed are the same optimum), the starts
    that failed there. Empty where nothing was refined or only one start was."""
    refined = (record or {}).get("refined") or []
    if len(refined) < 2:
        return []
    winner = (record or {}).get("winner") or {}
    ok = sorted((r for r in refined if r.get("status") == "ok" and isinstance(r.get("P_avg_W"), (int, float))
                 and math.isfinite(r["P_avg_W"])), key=lambda r: (-r["P_avg_W"], r.get("index", 0)))
    seen: list[float] = []
    others = []
    for r in ok:
        if r.get("index") == winner.get("index") or any(abs(r["P_avg_W"] - p) <= tie_W for p in seen):
            seen.append(r["P_avg_W"])
            continue
        seen.append(r["P_avg_W"])
        others.append(f"{family_of_label(r.get('start', ''))} {r['P_avg_W']:+.2f} W")
    failed = [family_of_label(r.get("start", "")) for r in refined if r.get("status") != "ok"]
    kept = f"{winner.get('family') or family_of_label(winner.get('start', ''))} {winner.get('P_avg_W', math.nan):+.2f} W"
    lines = [f"  local optima of the global strategy on the target mesh ({len(refined)} starts refined): kept {kept}"
             + (f"; others {', '.join(others)}" if others else "; every other start reached it")]
    if failed:
        lines.append(f"  refined starts that did not converge: {', '.join(failed)}")
    return lines


def family_of_label(label: str) -> str:
    """The start's family and turn directions from an outcome's label (``"loop +1/-1: ..."``)."""
    return label.split(":", 1)[0].strip()


def auto_workers(n_tasks: int) -> int:
    """Worker processes for ``n_tasks`` independent solves: :data:`WORKERS_ENV` when set, else
    ``min(MAX_AUTO_WORKERS, usable cores, n_tasks)``; 1 inside a daemonic process (a pool's
    worker, which may not start processes of its own)."""
    env = os.environ.get(WORKERS_ENV)
    if env:
        try:
            n = int(env)
        except ValueError:
            n = 1
        return max(1, min(n, n_tasks))
    if multiprocessing.current_process().daemon:
        return 1
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cores = os.cpu_count() or 1
    return max(1, min(MAX_AUTO_WORKERS, cores, n_tasks))


def run_tasks(fn: Callable[..., Any], tasks: Sequence[tuple], workers: int | None = None) -> list[Any]:
    """``[fn(*t) for t in tasks]``, in parallel in forked worker processes when ``workers`` > 1
    (None: :func:`auto_workers`). The results come back in task order whatever order the
    workers finish in. Forking lets the workers use the NLPs and IPOPT instances the parent
    has already built (its in-process cache), so nothing is built twice; where ``fork`` is not
    available the tasks run serially."""
    n = auto_workers(len(tasks)) if workers is None else max(1, min(int(workers), len(tasks)))
    if n <= 1 or "fork" not in multiprocessing.get_all_start_methods():
        return [fn(*t) for t in tasks]
    with ProcessPoolExecutor(max_workers=n, mp_context=multiprocessing.get_context("fork")) as pool:
        futures = [pool.submit(fn, *t) for t in tasks]
        return [f.result() for f in futures]
