#!/usr/bin/env python
"""Safe aborts: RECOVER triggered at evenly spaced times of one pumping cycle.

For each reference (the physical nominal 8 m/s cycle on the physical plant, the paper foldable
3 m/s cycle on the paper plant), each trigger time k P / n (k = 0 .. n-1, P the period) and each
air condition (calm: the reference's steady wind; moderate turbulence, seeds 1 and 2) the flight
switches AUTO -> RECOVER at the trigger and runs until it lands or ``--after`` seconds later.
A run passes when it ends ``landed`` (or ``parked``) without an event. Prints a table (end
status, touchdown sink, largest load factor and peak armature current after the trigger) and
writes every run as JSON.

Usage: python scripts/abort_grid.py [--n 12] [--after 220] [--workers 2] [--out abort_grid.json]
                                    [--cases nominal,foldable] [--air calm,moderate1,moderate2]
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

os.environ.setdefault("JSBSIM_DEBUG", "0")
os.environ.setdefault("MPLBACKEND", "Agg")

ROOT = Path(__file__).resolve().parent.parent
CASES = {
    "nominal": ("tests/data/ref_physical_nominal_8mps_sized.json", "physical"),
    "foldable": ("tests/data/ref_paper_foldable_3mps.json", "paper"),
}
AIR = {"calm": None, "moderate1": ("moderate", 1), "moderate2": ("moderate", 2)}


def abort_run(case: str, trigger_s: float, air: str, after_s: float, dt: float = 1.0 / 120.0) -> dict[str, Any]:
    """Fly ``case``'s reference in AUTO, switch to RECOVER at ``trigger_s`` [s] (0: from the
    start) and fly until the run ends or ``after_s`` [s] after the trigger. Returns the run's
    numbers: status, message, touchdown sink/ground speed/distance, largest |load factor|,
    peak armature current [A] and largest tension [N] after the trigger, time to the end."""
    import numpy as np

    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.result import COLUMNS
    from fdm_awe.sim.flight import fly

    path, plant = CASES[case]
    ref = TrackingReference.from_ocp_file(ROOT / path)
    k_tr = int(round(trigger_s / dt))
    holder: dict[str, Any] = {}

    def setup(ap: Any, sim: Any) -> None:
        holder["ap"] = ap
        if k_tr == 0:
            ap.set_mode("RECOVER")

    def on_step(k: int, s: Any, o: Any) -> None:
        if k == k_tr and k_tr > 0:
            holder["ap"].set_mode("RECOVER")

    wall = time.perf_counter()
    rep = fly(ref, config=str(ref.meta.get("config", "nominal")), cycles=1, dt=dt, turbulence=AIR[air],
              setup=setup, on_step=on_step, t_end=trigger_s + after_s, plant=plant)
    d = rep.result.data
    C = {c: i for i, c in enumerate(COLUMNS)}
    after = d[max(k_tr, 1):]
    end = d[-1]
    landed = rep.status == "landed"
    return {
        "case": case, "plant": plant, "air": air, "trigger_s": round(trigger_s, 3), "status": rep.status,
        "message": rep.message, "end_t_s": round(float(end[0]), 2), "stage": holder["ap"].rec_stage,
        "touchdown_sink_mps": round(float(end[C["vd"]]), 3) if rep.status in ("landed", "ground_contact") else None,
        "touchdown_speed_mps": round(math.hypot(end[C["vn"]], end[C["ve"]]), 2) if landed else None,
        "touchdown_dist_m": round(math.hypot(end[C["x"]], end[C["y"]]), 1) if landed else None,
        "max_load_g": round(float(np.nanmax(np.abs(after[:, C["load_factor"]]))), 2),
        "peak_current_A": round(float(np.nanmax(np.abs(after[:, C["current"]]))), 2) if plant == "physical" else None,
        "max_tension_N": round(float(np.nanmax(after[:, C["tension"]])), 1),
        "min_airspeed_mps": round(float(np.nanmin(after[:, C["airspeed"]])), 2),
        "max_airspeed_mps": round(float(np.nanmax(after[:, C["airspeed"]])), 2),
        "wall_s": round(time.perf_counter() - wall, 1),
    }


def passed(run: dict[str, Any]) -> bool:
    """Landed or parked: no crash, no load or airspeed limit, no tether event."""
    return run["status"] in ("landed", "parked")


def _fmt(v: Any, spec: str) -> str:
    return "-" if v is None else format(v, spec)


def main(argv: list[str] | None = None) -> int:
    sys.path.insert(0, str(ROOT))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=12, help="trigger times per cycle (evenly spaced from 0)")
    ap.add_argument("--after", type=float, default=220.0, help="flight time after the trigger, s")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--cases", default="nominal,foldable")
    ap.add_argument("--air", default="calm,moderate1,moderate2")
    ap.add_argument("--out", default="abort_grid.json")
    a = ap.parse_args(argv)
    if not (1 <= a.n <= 100):
        ap.error(f"--n: {a.n} out of range (allowed 1 .. 100)")
    if not (10.0 <= a.after <= 1000.0):
        ap.error(f"--after: {a.after:g} s out of range (allowed 10 .. 1000 s)")
    cases = a.cases.split(",")
    airs = a.air.split(",")
    for c in cases:
        if c not in CASES:
            ap.error(f"--cases: {c!r} unknown (allowed: {', '.join(CASES)})")
    for c in airs:
        if c not in AIR:
            ap.error(f"--air: {c!r} unknown (allowed: {', '.join(AIR)})")
    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.fileio import check_output_file, write_json

    out = check_output_file(a.out, "--out")
    jobs = []
    for c in cases:
        P = TrackingReference.from_ocp_file(ROOT / CASES[c][0]).period
        for k in range(a.n):
            for air in airs:
                jobs.append((c, k * P / a.n, air, a.after))
    t0 = time.perf_counter()
    print(f"{'case':9s} {'air':10s} {'trigger':>7s} {'status':15s} {'end t':>6s} {'sink':>5s} {'gs':>5s} "
          f"{'dist':>5s} {'load':>5s} {'I_pk':>5s} {'T_max':>6s}", flush=True)
    runs = []
    with ProcessPoolExecutor(max_workers=max(1, a.workers)) as pool:
        for r in pool.map(abort_run, *zip(*jobs)):  # in order, each row as soon as it is flown
            runs.append(r)
            print(f"{r['case']:9s} {r['air']:10s} {r['trigger_s']:7.1f} {r['status']:15s} {r['end_t_s']:6.1f} "
                  f"{_fmt(r['touchdown_sink_mps'], '5.2f')} {_fmt(r['touchdown_speed_mps'], '5.1f')} "
                  f"{_fmt(r['touchdown_dist_m'], '5.0f')} {r['max_load_g']:5.2f} "
                  f"{_fmt(r['peak_current_A'], '5.1f')} {r['max_tension_N']:6.1f}", flush=True)
    n_ok = sum(passed(r) for r in runs)
    print(f"{n_ok} of {len(runs)} runs landed or parked; wall {time.perf_counter() - t0:.0f} s")
    write_json(out, {"n": a.n, "after_s": a.after, "runs": runs, "passed": n_ok, "total": len(runs)})
    return 0 if n_ok == len(runs) else 1


if __name__ == "__main__":
    sys.exit(main())
