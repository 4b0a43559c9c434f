#!/usr/bin/env python3
"""Benchmark of ``fdm-awe sweep`` on Dask: 2 workers vs 1 worker, warm-started lines vs cold points.

Three runs of the same sweep (>= 16 points) into fresh folders, measured in one go:

1. warm-started chains on 1 local worker;
2. warm-started chains on 2 local workers;
3. every point cold (independent tasks) on 2 local workers.

Wall times exclude the cluster start-up (reported separately); they include the workers'
imports and NLP builds. Prints the ratios (goals: 2-worker speed-up >= 1.7; warm vs cold
reported) and the summed per-point solve times, and writes everything to a JSON file.
The numbers depend on how busy the machine is: the load average before and after is recorded.

Chain layout and failure budget are the sweep's own options (``--anchor-every``,
``--warm-fallback``, ``--max-iter-total``). ``--reference OLD.json`` compares the statuses and
average powers with an earlier run of this benchmark (e.g. with the default layout): points
whose status changed or whose power moved by more than 1e-6 W are listed.

Usage: scripts/bench_sweep.py [--mesh 10,8] [--wind 5:12:1] [--anchor-every 2] [--warm-fallback one]
       [--reference old.json] [--json bench_sweep.json]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time

from fdm_awe.ocp.problem import Mesh
from fdm_awe.sweep.execute import run_sweep
from fdm_awe.sweep.spec import DEFAULT_MAX_ITER_TOTAL, SweepSpec, chains, parse_floats, parse_tether_ranges

#: largest change of an ok point's average power [W] still counted as the same result
SAME_P_TOL_W = 1e-6


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", default="10,8", help="NGEN,NREC (default 10,8)")
    ap.add_argument("--wind", default="5:12:1", help="wind speeds [m/s] (default 5:12:1)")
    ap.add_argument("--tether-range", default="200:250,200:300", help="reel-out ranges (default 200:250,200:300)")
    ap.add_argument("--anchor-every", type=int, default=0, help="a cold anchor every N winds of a line (default 0: one per line)")
    ap.add_argument("--warm-fallback", default="all", choices=("all", "one", "none"), help="after a failed warm start (default all)")
    ap.add_argument("--max-iter-total", type=int, default=DEFAULT_MAX_ITER_TOTAL, help="IPOPT iterations per point (default 3000)")
    ap.add_argument("--reference", default=None, help="earlier benchmark JSON whose statuses and powers are compared")
    ap.add_argument("--json", default="bench_sweep.json", help="output JSON file")
    args = ap.parse_args()
    ng, nr = (int(v) for v in args.mesh.split(","))
    spec = SweepSpec(winds=parse_floats(args.wind, "--wind", "m/s"), configs=("nominal",),
                     tether_ranges=parse_tether_ranges(args.tether_range), mesh=Mesh(n_gen=ng, n_rec=nr),
                     anchor_every=args.anchor_every, warm_fallback=args.warm_fallback,
                     max_iter_total=args.max_iter_total).validate()
    n_points = len(spec.points())
    if n_points < 16:
        print(f"warning: only {n_points} points (the benchmark asks for >= 16)", file=sys.stderr)
    load_before = os.getloadavg()
    runs = {}
    with tempfile.TemporaryDirectory(prefix="bench_sweep_") as tmp:
        for name, workers, warm in (("warm_1w", 1, True), ("warm_2w", 2, True), ("cold_2w", 2, False)):
            load_run = os.getloadavg()[0]
            t0 = time.perf_counter()
            r = run_sweep(spec, os.path.join(tmp, name), workers=workers, warm_start=warm, progress=False)
            recs = list(r.records.values())
            if name == "warm_1w":
                point_s = {pid: x["wall_s"] or 0.0 for pid, x in r.records.items()}
            runs[name] = {"workers": workers, "warm_start": warm, "wall_s": r.wall_s, "startup_s": r.startup_s,
                          "total_s": time.perf_counter() - t0, "n_ok": sum(x["status"] == "ok" for x in recs),
                          "n_failed": sum(x["status"] != "ok" for x in recs), "n_not_run": len(r.errors),
                          "sum_point_wall_s": sum(x["wall_s"] or 0.0 for x in recs),
                          "sum_point_cpu_s": sum(x.get("cpu_s") or 0.0 for x in recs),
                          "points_per_worker": sorted(sum(1 for x in recs if x.get("worker") == w)
                                                      for w in {x.get("worker") for x in recs}),
                          "busy_s_per_worker": sorted(round(sum(x["wall_s"] or 0.0 for x in recs if x.get("worker") == w), 1)
                                                      for w in {x.get("worker") for x in recs}),
                          "sum_iterations": sum(x["iterations"] or 0 for x in recs),
                          "P_avg_W": {f"{x['d0_m']:g}-{x['d_tf_m']:g}@{x['wind_mps']:g}": x["P_avg_W"] for x in recs},
                          "loadavg_1min_before": load_run, "loadavg_1min_after": os.getloadavg()[0],
                          "points": [{k: x.get(k) for k in ("id", "d_tf_m", "wind_mps", "status", "P_avg_W", "iterations",
                                                            "wall_s", "worker", "warm_from", "start")} for x in recs]}
            # share of its cores the sweep actually got: CPU seconds / (workers x wall seconds)
            runs[name]["cpu_share"] = runs[name]["sum_point_cpu_s"] / (workers * r.wall_s) if r.wall_s > 0 else None
            print(f"{name}: {n_points} points, {workers} worker(s), warm={warm}: {r.wall_s:.1f} s "
                  f"(+{r.startup_s:.1f} s start-up), {runs[name]['n_ok']} ok, {runs[name]['n_failed']} failed, "
                  f"sum of point times {runs[name]['sum_point_wall_s']:.1f} s (CPU {runs[name]['sum_point_cpu_s']:.1f} s, "
                  f"{100 * (runs[name]['cpu_share'] or 0):.0f} % of {workers} core(s)), {runs[name]['sum_iterations']} iterations, "
                  f"points per worker {runs[name]['points_per_worker']} (busy {runs[name]['busy_s_per_worker']} s), load {load_run:.2f} -> {os.getloadavg()[0]:.2f}",
                  flush=True)
    load_after = os.getloadavg()
    speedup_workers = runs["warm_1w"]["wall_s"] / runs["warm_2w"]["wall_s"]
    speedup_warm = runs["cold_2w"]["wall_s"] / runs["warm_2w"]["wall_s"]
    speedup_warm_cpu = runs["cold_2w"]["sum_point_wall_s"] / runs["warm_2w"]["sum_point_wall_s"]
    same = runs["warm_1w"]["P_avg_W"] == runs["warm_2w"]["P_avg_W"]
    doc = {"n_points": n_points, "mesh": [ng, nr], "winds": list(spec.winds), "tether_ranges": spec.tether_ranges,
           "anchor_every": spec.anchor_every, "warm_fallback": spec.warm_fallback, "max_iter_total": spec.max_iter_total,
           "cpu_count": os.cpu_count(), "loadavg_before": load_before, "loadavg_after": load_after, "runs": runs,
           "speedup_2w_vs_1w": speedup_workers, "goal_2w_vs_1w": 1.7, "speedup_warm_vs_cold_wall": speedup_warm,
           "speedup_warm_vs_cold_point_time": speedup_warm_cpu, "results_identical_1w_2w": same}
    crit = _critical_path(chains(spec.points(), spec.anchor_every), point_s)
    doc["critical_path_s"] = crit
    doc["bound_2w_s"] = max(crit, runs["warm_1w"]["sum_point_wall_s"] / 2)
    print(f"longest warm-start dependency path (1-worker point times): {crit:.1f} s of {runs['warm_1w']['sum_point_wall_s']:.1f} s; "
          f"best possible 2-worker speed-up {runs['warm_1w']['sum_point_wall_s'] / doc['bound_2w_s']:.2f}x")
    print(f"2 workers vs 1: {speedup_workers:.2f}x (goal >= 1.7)")
    print(f"warm-started lines vs cold points (2 workers): {speedup_warm:.2f}x wall, {speedup_warm_cpu:.2f}x summed point time")
    print(f"results identical with 1 and 2 workers: {same}")
    cpu_speedup = runs["warm_1w"]["sum_point_cpu_s"] / max(runs["warm_2w"]["sum_point_cpu_s"], 1e-9)
    doc["cpu_s_ratio_1w_vs_2w"] = cpu_speedup
    print(f"CPU seconds of the work, 1 worker / 2 workers: {cpu_speedup:.2f} (1.0 = same work; a 2-worker wall speed-up "
          f"below 2 with this near 1 means the cores were not free)")
    if args.reference:
        doc["changed_vs_reference"] = {}
        with open(args.reference) as fh:
            ref = json.load(fh)
        for name in ("warm_1w", "cold_2w"):
            changed = _changed(ref["runs"][name]["P_avg_W"], runs[name]["P_avg_W"])
            doc["changed_vs_reference"][name] = changed
            print(f"{name} vs {args.reference}: {len(changed)} of {n_points} points changed status or power"
                  + "".join(f"\n  {k}: {a} -> {b}" for k, (a, b) in changed.items()))
    print(f"load average before {load_before[0]:.2f}, after {load_after[0]:.2f} on {os.cpu_count()} cores")
    with open(args.json, "w") as fh:
        json.dump(doc, fh, indent=1)
    print(f"wrote {args.json}")
    return 0


def _critical_path(chain_list: list, point_s: dict) -> float:
    """Longest path [s] through the warm-start dependencies (a chain's points in order, a chain
    after the first point of the chain it is seeded by), with the given point times."""
    end: dict[str, float] = {}
    for ch in chain_list:  # a chain comes after the chain that seeds it
        t = 0.0 if ch.after is None else end[chain_list[ch.after].points[0].id]
        for p in ch.points:
            t += point_s.get(p.id, 0.0)
            end[p.id] = t
    return max(end.values(), default=0.0)


def _changed(ref: dict, new: dict) -> dict:
    """Points whose status (None = failed) or average power [W] differ (beyond :data:`SAME_P_TOL_W`)."""
    out = {}
    for k in sorted(set(ref) | set(new)):
        a, b = ref.get(k), new.get(k)
        if (a is None) != (b is None) or (a is not None and abs(a - b) > SAME_P_TOL_W):
            out[k] = (a, b)
    return out


if __name__ == "__main__":
    sys.exit(main())
