#!/usr/bin/env python3
"""Benchmark of the cycle OCP at the default mesh: cold solve and warm re-solve.

Cold: a fresh process-level cache, so each run builds the NLP (reported separately) and solves
from the crosswind-loop start. Warm: re-solve after a wind change of +0.25 / +0.5 m/s from the
cold solution (primal and multipliers), as a sweep does. Continuation: a chain of ``--steps``
warm re-solves ``--step`` m/s apart from the cold solution, each from the previous one (how a
fine parameter sweep or a receding-horizon re-solve uses warm starts); a step where the
followed local optimum ends shows up as one long re-solve. Medians of ``--repeat`` runs;
targets (docs/design.md section 9): cold <= 3 s, warm <= 0.5 s on 2 cores. Prints ratios to the
targets and writes JSON.

    .venv/bin/python scripts/bench_ocp.py --out bench_ocp.json
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

COLD_TARGET_S, WARM_TARGET_S = 3.0, 0.5


def main() -> int:
    from fdm_awe.ocp.problem import CycleProblem, Mesh
    from fdm_awe.ocp.solve import clear_cache, solve_cycle

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--cases", default="paper:foldable:3,physical:nominal:8")
    ap.add_argument("--mesh", default=None)
    ap.add_argument("--step", type=float, default=0.05, help="wind step of the continuation chain [m/s]")
    ap.add_argument("--steps", type=int, default=10, help="re-solves in the continuation chain")
    ap.add_argument("--out", default="bench_ocp.json")
    args = ap.parse_args()
    mesh = Mesh(*(int(v) for v in args.mesh.split(","))) if args.mesh else Mesh()
    out = {"mesh": {"n_gen": mesh.n_gen, "n_rec": mesh.n_rec, "degree": mesh.degree}, "cpu_count": os.cpu_count(),
           "load_avg_start": os.getloadavg(), "cases": []}
    for case in args.cases.split(","):
        scn, cfg, w = case.split(":")
        pr = CycleProblem(scenario=scn, config=cfg, wind_speed=float(w), mesh=mesh)
        cold_solve, cold_build, cold_it, warm, warm_it = [], [], [], [], []
        status = []
        for _ in range(args.repeat):
            clear_cache()
            t0 = time.perf_counter()
            r = solve_cycle(pr)
            total = time.perf_counter() - t0
            cold_solve.append(r.solve_s)
            cold_build.append(r.build_s)
            cold_it.append(r.iterations)
            status.append(r.status)
            if r.ok:
                prev = r
                solve_cycle(pr.with_wind(float(w) + 0.25), warm=prev)  # builds the warm-start solver once
                for k in range(args.repeat):
                    rw = solve_cycle(pr.with_wind(float(w) + 0.25 * (1 + (k % 2))), warm=prev)
                    if rw.start == "warm start":
                        warm.append(rw.solve_s)
                        warm_it.append(rw.iterations)
            del total
        cont_s, cont_it, cont_P = [], [], []
        if status and status[-1] == "ok":
            cur, wc = prev, float(w)
            for _ in range(args.steps):
                wc = round(wc + args.step, 6)
                rc = solve_cycle(pr.with_wind(wc), warm=cur)
                cont_s.append(rc.solve_s)
                cont_it.append(rc.iterations)
                cont_P.append(rc.P_avg_W if rc.ok else None)
                if rc.ok:
                    cur = rc
        row = {"case": case, "status": status, "continuation_step_mps": args.step,
               "continuation_solve_s": cont_s, "continuation_iterations": cont_it, "continuation_P_avg_W": cont_P,
               "continuation_median_s": statistics.median(cont_s) if cont_s else None, "cold_solve_s": cold_solve, "cold_build_s": cold_build,
               "cold_iterations": cold_it, "warm_solve_s": warm, "warm_iterations": warm_it,
               "cold_solve_median_s": statistics.median(cold_solve),
               "cold_total_median_s": statistics.median([a + b for a, b in zip(cold_solve, cold_build)]),
               "warm_median_s": statistics.median(warm) if warm else None}
        row["cold_ratio_to_target"] = row["cold_solve_median_s"] / COLD_TARGET_S
        row["cold_total_ratio_to_target"] = row["cold_total_median_s"] / COLD_TARGET_S
        row["warm_ratio_to_target"] = None if not warm else row["warm_median_s"] / WARM_TARGET_S
        out["cases"].append(row)
        print(f"{case}: cold solve median {row['cold_solve_median_s']:.2f} s (x{row['cold_ratio_to_target']:.2f} of the "
              f"{COLD_TARGET_S:g} s target; with build {row['cold_total_median_s']:.2f} s), warm re-solve median "
              + (f"{row['warm_median_s']:.3f} s (x{row['warm_ratio_to_target']:.2f} of {WARM_TARGET_S:g} s)" if warm else "n/a")
              + f", iterations cold {cold_it} warm {warm_it}", flush=True)
        if cont_s:
            print(f"  continuation +{args.step:g} m/s x {len(cont_s)}: median {row['continuation_median_s']:.3f} s "
                  f"(x{row['continuation_median_s'] / WARM_TARGET_S:.2f} of {WARM_TARGET_S:g} s), max {max(cont_s):.2f} s, "
                  f"iterations {cont_it}", flush=True)
    out["load_avg_end"] = os.getloadavg()
    Path(args.out).write_text(json.dumps(out, indent=2))
    print(f"load average (1, 5, 15 min) at start {out['load_avg_start']}, end {out['load_avg_end']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
