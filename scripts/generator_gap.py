"""How much of the free-tension gap the generator's T2 duty closes.

For each configuration and wind the physical cycle is optimised three times on the default mesh:

- ``passive``: the passive rectifier (tension tied to the reel speed), cold, global strategy;
- ``boost``: the T2 duty as a control, warm-started from the passive optimum (a feasible point
  with the same power) and checked against a cold solve (the better is kept);
- ``ideal``: a loss-free converter holding any tension (the physical counterpart of the
  paper's free tension), warm-started from the boost optimum, with the same cold check.

Each problem contains the one before, so passive <= boost <= ideal up to the solver's local
optima. The closed share is ``(P_boost - P_passive) / (P_ideal - P_passive)``.

Usage::

    python scripts/generator_gap.py --wind 6,8,10,12 --config nominal,foldable \
        --json runs/generator_gap.json --report runs/generator_gap.md

Prints a table; writes the JSON and the markdown atomically. Exit 0 when every solve converged,
1 otherwise (the failed ones are listed), 2 on bad input.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

from fdm_awe.errors import InputError

GENERATORS = ("passive", "boost", "ideal")


def _duty_stats(res) -> dict[str, float | None]:
    """Mean T2 duty over generation (time-weighted by rows) and the share of rows at its bound."""
    if not res.ok or "boost_duty" not in res.columns:
        return {"duty_mean": None, "duty_at_max_share": None}
    from fdm_awe.ocp.energy import WinchElectrics

    d = np.asarray(res.columns["boost_duty"])[np.asarray(res.columns["phase"]) == 0]
    dmax = WinchElectrics.from_ground_station(line=res.problem.line).boost_duty_max
    return {"duty_mean": float(d.mean()), "duty_at_max_share": float(np.mean(d > dmax - 1e-3))}


def solve_point(config: str, wind: float) -> dict:
    from fdm_awe.ocp.problem import CycleProblem
    from fdm_awe.ocp.solve import solve_cycle

    base = CycleProblem(scenario="physical", config=config, wind_speed=wind).validate()
    row: dict = {"config": config, "wind_mps": wind}
    prev = None
    for gen in GENERATORS:
        t0 = time.perf_counter()
        pr = dataclasses.replace(base, generator=gen).validate()
        res = solve_cycle(pr) if prev is None else solve_cycle(pr, warm=prev, cold_check=True)
        row[gen] = {"status": res.status, "P_avg_W": res.P_avg_W if res.ok else None,
                    "T1_s": res.T1_s if res.ok else None, "T2_s": res.T2_s if res.ok else None,
                    "wall_s": round(time.perf_counter() - t0, 2), "start": res.start or None,
                    **(_duty_stats(res) if gen == "boost" else {})}
        if res.ok:
            prev = res
    P = {g: row[g]["P_avg_W"] for g in GENERATORS}
    gap = None if P["ideal"] is None or P["passive"] is None else P["ideal"] - P["passive"]
    row["gap_W"] = gap
    row["closed_share"] = (None if gap is None or P["boost"] is None or gap <= 0.05
                           else (P["boost"] - P["passive"]) / gap)
    return row


def markdown(rows: list[dict]) -> str:
    def f(v, fmt="{:+.1f}"):
        return "failed" if v is None else fmt.format(v)

    out = ["| config | wind m/s | passive W | boost W | ideal W | gap closed by the duty | mean duty | share at max duty |",
           "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        out.append(f"| {r['config']} | {r['wind_mps']:g} | {f(r['passive']['P_avg_W'])} | {f(r['boost']['P_avg_W'])} | "
                   f"{f(r['ideal']['P_avg_W'])} | {f(r['closed_share'], '{:.0%}')} | "
                   f"{f(r['boost'].get('duty_mean'), '{:.2f}')} | {f(r['boost'].get('duty_at_max_share'), '{:.0%}')} |")
    return "\n".join(out) + "\n"


def main(argv: list[str] | None = None) -> int:
    from fdm_awe.sweep.spec import parse_floats
    from fdm_awe.fileio import atomic_write_text, write_json
    from study_args import add_configs, add_outputs, check_outputs, configs

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--wind", default="6,8,10,12", help="winds [m/s], comma list, each 0..25 (default 6,8,10,12)")
    add_configs(ap)
    add_outputs(ap)
    args = ap.parse_args(argv)
    try:
        winds = parse_floats(args.wind, "--wind", "m/s", 0.0, 25.0)
        cfgs = configs(args)
        check_outputs(args)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    rows = []
    for cfg in cfgs:
        for w in winds:
            r = solve_point(cfg, w)
            rows.append(r)
            print(f"{cfg:8s} {w:5.1f} m/s  passive {r['passive']['P_avg_W']}  boost {r['boost']['P_avg_W']}  "
                  f"ideal {r['ideal']['P_avg_W']}  closed {r['closed_share']}", flush=True)
    text = markdown(rows)
    print(text)
    if args.json:
        write_json(Path(args.json), {"rows": rows})
    if args.report:
        atomic_write_text(Path(args.report), text)
    failed = [(r["config"], r["wind_mps"], g) for r in rows for g in GENERATORS if r[g]["status"] != "ok"]
    for f in failed:
        print(f"failed: {f[0]} {f[1]:g} m/s {f[2]}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
