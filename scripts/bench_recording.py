#!/usr/bin/env python
"""Benchmark: cost of the rerun recording relative to the flight it records, in one run.

The same flight (6-DOF co-simulation + ground station + autopilot, default 60 s of a 100 m
circle, or one cycle of ``--reference FILE``) is flown without and with recording; "with"
is the flight plus ``record_flight`` writing the finalised ``.rrd`` (scene + all time series).
A third variant flies with the step-buffering ``FlightRecording`` callback and finishes it.
Rounds are interleaved and the best of ``--repeat`` is kept for each (the machine is shared).
Target (docs/design.md section 9): recording adds <= 10 % to the flight's wall time.

Usage: python scripts/bench_recording.py [--seconds 60] [--repeat 3] [--reference FILE]
                                         [--json bench_recording.json]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("JSBSIM_DEBUG", "0")

import numpy as np  # noqa: E402


def circle_reference():
    from fdm_awe.autopilot.tracking import TrackingReference

    th = np.linspace(0.0, 2.0 * np.pi, 60, endpoint=False)
    pts = np.c_[150.0 + 50.0 * np.cos(th), 50.0 * np.sin(th), np.full_like(th, -100.0)]
    return TrackingReference.from_waypoints(pts, None, None, speed=14.0)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=60.0, help="simulated seconds per flight (default 60)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--reference", help="reference-trajectory file (default: a circle at 100 m)")
    ap.add_argument("--json", default="bench_recording.json")
    args = ap.parse_args(argv)

    import rerun  # noqa: F401  (import cost is paid once per process, not per flight)

    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.flight import fly
    from fdm_awe.recording import record_flight

    ref = TrackingReference.from_ocp_file(args.reference) if args.reference else circle_reference()
    T = ref.period if args.reference else args.seconds
    tmp = Path(tempfile.mkdtemp(prefix="bench_recording_"))
    from fdm_awe.recording import FlightRecording

    plain, with_rec, rec_only, live, sizes, statuses = [], [], [], [], [], []
    fly(ref, cycles=1, t_end=min(T, 2.0))  # warm-up (JSBSim load, imports)
    for i in range(args.repeat):
        t0 = time.perf_counter()
        r1 = fly(ref, cycles=1, t_end=T)
        plain.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        r2 = fly(ref, cycles=1, t_end=T)
        t1 = time.perf_counter()
        path = record_flight(r2, ref, tmp / f"run{i}.rrd")
        t2 = time.perf_counter()
        with_rec.append(t2 - t0)
        rec_only.append(t2 - t1)
        sizes.append(path.stat().st_size)
        # step-buffering recorder (survives exceptions in the loop): flight + buffer + finish
        t0 = time.perf_counter()
        with FlightRecording(tmp / f"live{i}.rrd", ref) as rec:
            r3 = fly(ref, cycles=1, t_end=T, on_step=rec, setup=rec.setup)
            rec.finish(r3)
        live.append(time.perf_counter() - t0)
        statuses.append((r1.status, r2.status, r3.status))
    best_plain, best_rec, best_only, best_live = min(plain), min(with_rec), min(rec_only), min(live)
    overhead = best_only / best_plain
    rows = len(r2.result.t)
    doc = {
        "benchmark": "recording overhead", "reference": args.reference or "circle r=50 m at 100 m, 14 m/s",
        "sim_seconds": float(r2.sim_time_s), "rows": rows, "repeat": args.repeat,
        "flight_wall_s": best_plain, "flight_plus_recording_wall_s": best_rec, "recording_wall_s": best_only,
        "ratio_with_over_without": best_rec / best_plain, "recording_over_flight": overhead,
        "flight_with_step_buffer_and_recording_wall_s": best_live, "ratio_step_buffer_over_without": best_live / best_plain,
        "target_recording_over_flight_max": 0.10, "pass": overhead <= 0.10,
        "rrd_bytes": int(np.median(sizes)), "statuses": statuses,
        "all_flight_wall_s": plain, "all_with_recording_wall_s": with_rec, "all_recording_wall_s": rec_only,
        "python": platform.python_version(), "machine": platform.machine(),
    }
    print(f"flight {r2.sim_time_s:.1f} s simulated ({rows} rows): {best_plain:.3f} s wall without recording, "
          f"{best_rec:.3f} s with; recording alone {best_only:.3f} s = {100 * overhead:.1f} % of the flight "
          f"(target <= 10 %); ratio with/without {best_rec / best_plain:.3f}; with the step-buffering "
          f"FlightRecording {best_live / best_plain:.3f}; .rrd {doc['rrd_bytes'] / 1e6:.1f} MB")
    Path(args.json).write_text(json.dumps(doc, indent=2) + "\n")
    print(f"wrote {args.json}")
    return 0 if doc["pass"] else 1


if __name__ == "__main__":
    sys.exit(main())
