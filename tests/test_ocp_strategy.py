"""Global strategy of the cycle optimiser (fdm_awe/ocp/strategy.py, solve_cycle(strategy=...)).

The selection rule and the parallel merge are tested on constructed outcomes, so no test
depends on which local optimum IPOPT reaches; one real solve on a tiny mesh checks that the
record holds every start and that the winner is the best of them by the rule.
"""

from __future__ import annotations

import math
import random
import time

import pytest

from fdm_awe.ocp import solve
from fdm_awe.ocp.problem import CycleProblem, Mesh
from fdm_awe.ocp.result import CycleResult
from fdm_awe.ocp.strategy import TIE_W, Outcome, mirror_symmetric, run_tasks, select, strategy_starts

TINY = Mesh(6, 4, 3)


def test_select_best_power_ties_to_the_earlier_start():
    outs = [Outcome(0, "a", True, 10.00), Outcome(1, "b", False), Outcome(2, "c", True, 10.04),
            Outcome(3, "d", True, 12.0), Outcome(4, "e", True, 11.97)]
    ranked = select(outs)
    # 12.0 and 11.97 tie (within 0.05 W): the earlier start (3) wins; then 10.04 ~ 10.00 -> start 0
    assert [o.index for o in ranked] == [3, 4, 0, 2]
    assert select([Outcome(0, "a", True, 1.0), Outcome(1, "b", True, 1.0 + 2 * TIE_W)])[0].index == 1


def test_select_does_not_depend_on_arrival_order():
    rng = random.Random(1)
    outs = [Outcome(i, str(i), rng.random() > 0.2, rng.choice([5.0, 5.03, 5.2, 6.0, 6.04, math.nan])) for i in range(12)]
    want = [o.index for o in select(outs)]
    for _ in range(20):
        rng.shuffle(outs)
        assert [o.index for o in select(outs)] == want


def test_refine_candidates_band_and_minimum():
    from fdm_awe.ocp.strategy import REFINE, REFINE_BAND_W, refine_candidates

    far = [Outcome(0, "a", True, 10.0), Outcome(1, "b", True, 10.0 - 3 * REFINE_BAND_W),
           Outcome(2, "c", True, 10.0 - 4 * REFINE_BAND_W)]
    assert [o.index for o in refine_candidates(select(far))] == [0, 1][:max(REFINE, 1)]
    near = [Outcome(i, str(i), True, 10.0 - 0.4 * REFINE_BAND_W * i) for i in range(4)]
    assert [o.index for o in refine_candidates(select(near))] == [0, 1, 2]
    assert refine_candidates([]) == []


def _slow_identity(i: int, n: int) -> int:
    time.sleep(0.05 * (n - i))  # the first task finishes last
    return i


def test_parallel_results_come_back_in_task_order():
    n = 4
    assert run_tasks(_slow_identity, [(i, n) for i in range(n)], workers=2) == list(range(n))
    assert run_tasks(_slow_identity, [(i, n) for i in range(n)], workers=1) == list(range(n))


def test_starts_cover_both_families_and_turns():
    sym = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, mesh=TINY)
    assert mirror_symmetric(sym)
    st = strategy_starts(sym)
    assert [(s.shape, s.dir1, s.dir2) for s in st] == [("loop", 1, 1), ("loop", 1, -1), ("eight", 1, 1), ("eight", 1, -1)]
    skew = sym.with_wind(8.0, 150.0)
    assert not mirror_symmetric(skew)
    st = strategy_starts(skew)
    assert len(st) == 8 and {(s.shape, s.dir1, s.dir2) for s in st} == {
        (f, d1, d2) for f in ("loop", "eight") for d1 in (1, -1) for d2 in (1, -1)}


def _fake(problem: CycleProblem, P: float | None) -> CycleResult:
    """A result of average power ``P`` [W] (None: failed)."""
    if P is None:
        return CycleResult(problem.scenario, problem.config, problem.wind_speed, problem.wind_from_deg, "failed",
                           "no luck", 0.1, 0.0, 7, problem=problem)
    return CycleResult(problem.scenario, problem.config, problem.wind_speed, problem.wind_from_deg, "ok", "ok", 0.1,
                       0.0, 5, T1_s=10.0, T2_s=10.0, E_generated_J=20.0 * P + 30.0, E_thrust_J=10.0,
                       E_reel_in_J=20.0, problem=problem)


@pytest.mark.parametrize("powers, winner", [((3.0, 5.0, 4.0, None), 1), ((5.0, 5.04, None, 5.01), 0),
                                            ((None, None, 2.0, 2.0), 2)])
def test_global_picks_the_best_start_and_records_every_start(monkeypatch, powers, winner):
    """With the starts' local optima given, the strategy returns the winner of the rule and
    records the power of every start (failed ones with their reason)."""
    pr = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, mesh=TINY)
    starts = strategy_starts(pr)
    by_start = {st: P for st, P in zip(starts, powers)}
    monkeypatch.setattr(solve, "_explore_task", lambda problem, start, limits: _fake(problem, by_start[start]))
    res = solve.solve_cycle(pr, strategy="global", coarse=None, polish=False, workers=1)
    rec = res.strategy
    assert res.ok and res.P_avg_W == pytest.approx(powers[winner])
    assert rec["winner"]["index"] == winner and rec["winner"]["family"] in res.start
    assert [s["status"] for s in rec["starts"]] == ["failed" if P is None else "ok" for P in powers]
    for s, P in zip(rec["starts"], powers):
        assert (math.isnan(s["P_avg_W"]) and s["reason"] == "no luck") if P is None else s["P_avg_W"] == pytest.approx(P)
    assert res.iterations == sum(7 if P is None else 5 for P in powers)
    assert res.summary()["strategy"] is rec and res.metadata()["strategy"] is rec


def test_global_fails_with_every_start_named(monkeypatch):
    pr = CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, mesh=TINY)
    monkeypatch.setattr(solve, "_explore_task", lambda problem, start, limits: _fake(problem, None))
    res = solve.solve_cycle(pr, strategy="global", coarse=None, workers=1)
    assert not res.ok and res.reason.count("no luck") == len(strategy_starts(pr)) and "\n" not in res.reason
    assert res.summary()["P_avg_W"] is None


def test_global_solve_is_the_same_serial_and_parallel():
    """A real global solve (tiny mesh, paper scenario): the winner is the best start by the
    rule, the polish keeps its power, and two workers give the identical result."""
    pr = CycleProblem(scenario="paper", config="nominal", wind_speed=3.0, mesh=Mesh(10, 6, 3))
    a = solve.solve_cycle(pr, strategy="global", coarse=None, workers=1)
    assert a.ok, a.reason
    rec = a.strategy
    assert len(rec["starts"]) == len(strategy_starts(pr))
    ok = [s for s in rec["starts"] if s["status"] == "ok"]
    best = max(s["P_avg_W"] for s in ok)
    win = rec["starts"][rec["winner"]["index"]]
    assert win["P_avg_W"] >= best - TIE_W
    assert all(s["index"] >= win["index"] for s in ok if s["P_avg_W"] >= best - TIE_W)
    assert rec["polish"]["status"] == "ok" and abs(a.P_avg_W - win["P_avg_W"]) < 0.05 and "polished" in a.start
    b = solve.solve_cycle(pr, strategy="global", coarse=None, workers=2)
    assert b.strategy["winner"] == rec["winner"] and b.P_avg_W == a.P_avg_W and b.iterations == a.iterations


def test_cold_check_keeps_the_better_and_records_both():
    """A warm-started point checked against a cold solve: both powers recorded, the kept one is
    the better (a tie keeps the warm one), and a difference above 0.5 W is flagged."""
    from fdm_awe.ocp.strategy import COLD_CHECK_W

    pr = CycleProblem(scenario="paper", config="nominal", wind_speed=3.0, mesh=Mesh(10, 6, 3))
    first = solve.solve_cycle(pr, coarse=None)
    assert first.ok, first.reason
    res = solve.solve_cycle(pr.with_wind(3.5), warm=first, cold_check=True, workers=1)
    assert res.ok, res.reason
    chk = res.strategy["cold_check"]
    warm_P, cold_P = chk["warm_P_avg_W"], chk["cold_P_avg_W"]
    assert chk["warm_status"] == "ok" and chk["cold_status"] == "ok"
    assert res.P_avg_W == pytest.approx(max(warm_P, cold_P), abs=TIE_W + 1e-6)
    assert chk["kept"] == ("cold" if cold_P > warm_P + TIE_W else "warm")
    assert chk["disagree"] == (abs(warm_P - cold_P) > COLD_CHECK_W)
    assert chk["difference_W"] == pytest.approx(abs(warm_P - cold_P), abs=1e-5)


def test_the_report_names_the_local_optima_the_strategy_met():
    """``optima_lines``: the kept optimum, the others best first with ties (within TIE_W) of one
    already named left out, and the refined starts that failed; nothing when one start was refined."""
    from fdm_awe.ocp.strategy import optima_lines

    def rec(i, fam, p, status="ok"):
        return {"index": i, "start": f"{fam}: loops T1=18.8s", "status": status, "P_avg_W": p}

    record = {"winner": {"index": 0, "family": "loop +1/+1", "P_avg_W": 5.23},
              "refined": [rec(0, "loop +1/+1", 5.23), rec(1, "loop +1/-1", None, "failed"),
                          rec(3, "eight +1/-1", 3.04), rec(2, "eight +1/+1", 3.04 - 0.5 * TIE_W),
                          rec(4, "loop -1/+1", 5.23 - 0.5 * TIE_W)]}
    lines = optima_lines(record)
    assert lines[0].endswith("kept loop +1/+1 +5.23 W; others eight +1/-1 +3.04 W"), lines
    assert "(5 starts refined)" in lines[0]
    assert lines[1] == "  refined starts that did not converge: loop +1/-1"
    one = {"winner": record["winner"], "refined": record["refined"][:1]}
    assert optima_lines(one) == [] and optima_lines(None) == []
    same = {"winner": record["winner"], "refined": [rec(0, "loop +1/+1", 5.23), rec(4, "loop -1/+1", 5.2)]}
    assert optima_lines(same)[0].endswith("; every other start reached it")
