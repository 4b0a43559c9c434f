"""The co-design of the winch's drive: the supply voltage as a design variable of the cycle.

Why a search over solves and not a variable of the optimal control problem: in the cycle's
energy model the supply voltage ``V_a`` only bounds the drive (the motor's armature voltage at
full duty, :func:`fdm_awe.groundstation.steady.motor_max_reel_in_speed`); the power the motor
draws, ``v_arm i`` (:func:`~fdm_awe.groundstation.steady.motor_steady`), does not depend on it,
and the model holds no cost of a higher voltage. The best cycle's power ``P(V_a)`` is therefore
non-decreasing in ``V_a`` and flat from the voltage at which the drive stops binding: an OCP
variable ``V_a`` would sit anywhere on that plateau (its multiplier zero there), which answers
nothing. The design question is the smallest voltage that reaches the plateau, the drive the
cycle needs. :func:`supply_search` answers it with a bounded scalar search over solves:

1. the cycle is solved at every grid voltage (a sweep's voltages, inside ``lo..hi``);
2. the plateau is where the power is within ``tol_W`` of the best power found;
3. bisection between the highest grid voltage below the plateau and the lowest on it, ``steps``
   times (each step one more solve; the midpoint to 0.01 V).

Guarantees: ``best`` is the largest power of every solve, so it is never below the grid's best
(the grid's voltages are among the solves); ``needed`` is the smallest voltage solved whose
power is within ``tol_W`` of ``best``, inside ``lo..hi``; the bracket that holds the plateau's
edge is ``(lo_V, hi_V)``, of width ``(grid step) / 2**steps``. Local optima: each solve is a
local optimum (the sweep's cold check keeps the better of two); a solve that falls short moves
the edge up, never the best power down.
"""

from __future__ import annotations

import math
from typing import Any, Callable, Sequence

from ..errors import InputError

#: the power margin [W] of the plateau (the sweep's cold-check tolerance: differences below it are noise)
PLATEAU_TOL_W = 0.5
#: bisection steps after the grid (each one solve)
STEPS = 4
#: allowed bisection steps
STEPS_RANGE = (0, 20)


def supply_search(evaluate: Callable[[float], "float | None"], grid: Sequence[float], lo: float, hi: float, *,
                  tol_W: float = PLATEAU_TOL_W, steps: int = STEPS) -> dict[str, Any]:
    """The co-design of the supply voltage (module docstring). ``evaluate(V)`` solves the cycle
    with the supply ``V`` [V] and returns its cycle-average net power [W] (None: no converged
    cycle); ``grid`` the voltages solved first (those outside ``lo..hi`` are left out; ``lo``
    and ``hi`` are always solved). Returns ``evaluations`` (``V``, ``P_W``, ``grid``, in the order
    solved), ``best`` and ``needed`` (``V``, ``P_W``), the bracket ``lo_V``/``hi_V`` of the
    plateau's edge, ``tol_W``, ``steps`` and ``method``."""
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise InputError(f"co-design range {lo:g}..{hi:g} V: expected lo < hi")
    if not (STEPS_RANGE[0] <= int(steps) <= STEPS_RANGE[1]):
        raise InputError(f"co-design steps {steps!r} out of range (allowed integer {STEPS_RANGE[0]}..{STEPS_RANGE[1]})")
    if not (math.isfinite(tol_W) and 0.0 <= tol_W <= 100.0):
        raise InputError(f"co-design tolerance {tol_W!r} out of range (allowed 0..100 W)")
    done: dict[float, float | None] = {}
    order: list[dict[str, Any]] = []

    def solve(v: float, on_grid: bool) -> float | None:
        v = float(v)
        if v not in done:
            done[v] = evaluate(v)
            order.append({"V": v, "P_W": done[v], "grid": on_grid})
        return done[v]

    for v in sorted({float(x) for x in grid if lo <= x <= hi} | {float(lo), float(hi)}):
        solve(v, True)

    def ok() -> list[tuple[float, float]]:
        return sorted((v, p) for v, p in done.items() if p is not None)

    def edge() -> tuple[float | None, float | None, float]:
        """(highest voltage below the plateau under the lowest on it, lowest on it, the best power)."""
        pts = ok()
        best = max(p for _, p in pts)
        on = min(v for v, p in pts if p >= best - tol_W)
        below = [v for v in done if v < on]
        return (max(below) if below else None), on, best

    if not ok():
        return {"evaluations": order, "best": None, "needed": None, "lo_V": float(lo), "hi_V": float(hi),
                "tol_W": tol_W, "steps": int(steps), "method": "grid, then bisection of the plateau's edge"}
    for _ in range(int(steps)):
        below, on, _best = edge()
        if below is None:  # the whole range is on the plateau: the lowest voltage already needs no more
            break
        solve(round(0.5 * (below + on), 2), False)  # to 0.01 V: a variant file's name
    below, on, best = edge()
    v_best = min(v for v, p in ok() if p == best)
    return {"evaluations": order, "best": {"V": v_best, "P_W": best}, "needed": {"V": on, "P_W": done[on]},
            "lo_V": below if below is not None else float(lo), "hi_V": on, "tol_W": tol_W, "steps": int(steps),
            "method": "grid, then bisection of the plateau's edge"}
