#!/usr/bin/env python
"""Benchmark: a whole autopilot flight, compiled, against the same flight with the autopilot run
by Python, measured in one run, and the plain-Python run's bits.

Each flight is ``fdm_awe.sim.flight.fly`` of a stored physical reference of the tests (8 m/s,
the sized line; nominal and foldable), ``--cycles`` pumping cycles at 120 Hz, no recording:

- ``compiled``: no per-step hook, so the autopilot's AUTO steps run compiled inside the
  co-simulation kernel in blocks (:mod:`fdm_awe.sim.autopilot_kernel`);
- ``python_autopilot``: the same flight with a per-step hook that does nothing: the compiled
  co-simulation step with the autopilot called from Python every step (as with MAVLink);
- ``plain_python``: ``FDM_AWE_JIT=0`` in a child process (Python loop, Python ground station,
  Python autopilot), once: the reference every compiled run must equal bit for bit.

The real-time factor is simulated time over the wall time of the flight loop (``FlightReport.
realtime_factor``), the best of ``--flights`` flights (the machine is shared); the whole ``fly``
call (JSBSim's load, the plant's set-up, the report) is given too. The compiled flights are
compared with the Python-autopilot flight and with the plain-Python one: every logged column,
the tracking error, the reference points, the ledgers, the cycles' energies and the autopilot's
log must be identical. Target (docs/design.md section 9): >= 500x real time, bit-identical.

With ``--tether`` (e.g. ``lumped-implicit:30``) the flights fly that line (a lumped line's
shape sampled at 10 Hz is compared too) and the straight line's compiled flights are flown
alongside for the ratio.

Usage: python scripts/bench_autopilot.py [--json bench_autopilot.json] [--cycles 3] [--flights 3] [--tether straight]
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("JSBSIM_DEBUG", "0")

ROOT = Path(__file__).resolve().parent.parent
REFERENCES = {"nominal": "tests/data/ref_physical_nominal_8mps_sized.json",
              "foldable": "tests/data/ref_physical_foldable_8mps_sized.json"}
TARGET = 500.0


def flight(config: str, cycles: int, per_step: bool, tether: str = "straight") -> tuple[dict, float, float]:
    """One flight on the line ``tether``: (its comparable outputs, real-time factor of the loop,
    wall time of ``fly`` [s])."""
    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.flight import fly

    ref = TrackingReference.from_ocp_file(ROOT / REFERENCES[config])
    t0 = time.perf_counter()
    rep = fly(ref, config=config, cycles=cycles, on_step=(lambda k, s, o: None) if per_step else None, tether=tether)
    wall = time.perf_counter() - t0
    out = {"data": rep.result.data, "track_error": rep.track_error, "reference_pos": rep.reference_pos,
           "ledger": rep.ledger, "cycles": [c.E_net_J for c in rep.cycles], "log": rep.autopilot_log,
           "status": rep.status, "steps": rep.result.steps, "sim_time_s": rep.sim_time_s,
           "line_shape": None if rep.line_shape is None else {k: v.tolist() for k, v in rep.line_shape.items()}}
    return out, rep.realtime_factor, wall


def same(a: dict, b: dict) -> list[str]:
    """The outputs in which two flights differ (empty: bit-identical)."""
    import numpy as np

    diff = []
    for k in ("data", "track_error", "reference_pos"):
        x, y = a[k], b[k]
        if x.shape != y.shape or not np.array_equal(x, y, equal_nan=True):
            diff.append(k)
    for k in ("ledger", "cycles", "log", "status", "steps", "line_shape"):
        if a[k] != b[k]:
            diff.append(k)
    return diff


def plain_python(config: str, cycles: int, tether: str = "straight") -> tuple[dict, float]:
    """The flight in a child process with ``FDM_AWE_JIT=0``: (its outputs, its real-time factor)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "flight.pkl"
        env = dict(os.environ, FDM_AWE_JIT="0")
        code = ("import pickle, sys; sys.path.insert(0, %r); import bench_autopilot as b; "
                "r = b.flight(%r, %d, False, %r); pickle.dump((r[0], r[1]), open(%r, 'wb'))"
                % (str(Path(__file__).parent), config, cycles, tether, str(out)))
        subprocess.run([sys.executable, "-c", code], check=True, env=env, cwd=ROOT)
        with open(out, "rb") as fh:
            return pickle.load(fh)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", default="bench_autopilot.json", help="output JSON file")
    ap.add_argument("--cycles", type=int, default=3, help="pumping cycles per flight")
    ap.add_argument("--flights", type=int, default=3, help="flights of each kind (the best counts)")
    ap.add_argument("--tether", default="straight",
                    help="the line flown (a --tether form, default straight); another than straight also flies "
                         "the straight line's compiled flights for the ratio")
    a = ap.parse_args(argv)
    from fdm_awe.errors import InputError
    from fdm_awe.groundstation.linemodels import parse_tether

    try:
        parse_tether(a.tether)
    except InputError as exc:
        print(f"bench_autopilot: {exc}", file=sys.stderr)
        return 2
    if not (1 <= a.cycles <= 20 and 1 <= a.flights <= 20):
        print("bench_autopilot: --cycles and --flights: allowed 1 .. 20", file=sys.stderr)
        return 2
    if not Path(a.json).resolve().parent.is_dir():
        print(f"bench_autopilot: --json {a.json}: its directory does not exist", file=sys.stderr)
        return 2
    result: dict = {"cycles": a.cycles, "flights": a.flights, "rate_hz": 120, "target_realtime_factor": TARGET,
                    "tether": a.tether}
    flight("nominal", 1, False, a.tether)  # compile (or load) the kernels once, outside the timings
    for config in REFERENCES:
        kinds = ["compiled", "python_autopilot"] + (["straight"] if a.tether != "straight" else [])
        rt: dict = {k: [] for k in kinds}
        wall: dict = {k: [] for k in kinds}
        runs: dict = {}
        for _ in range(a.flights):  # interleaved: both kinds see the same machine load
            for kind in rt:
                out, r, w = flight(config, a.cycles, kind == "python_autopilot",
                                   "straight" if kind == "straight" else a.tether)
                rt[kind].append(r)
                wall[kind].append(w)
                runs[kind] = out
        ref_out, rt_plain = plain_python(config, a.cycles, a.tether)
        d_py = same(runs["compiled"], runs["python_autopilot"])
        d_plain = same(runs["compiled"], ref_out)
        best = {k: max(v) for k, v in rt.items()}
        res = {
            "reference": REFERENCES[config], "status": runs["compiled"]["status"], "steps": runs["compiled"]["steps"],
            "sim_time_s": runs["compiled"]["sim_time_s"],
            "realtime_factor": best["compiled"], "realtime_factor_python_autopilot": best["python_autopilot"],
            "realtime_factor_plain_python": rt_plain, "speedup_over_python_autopilot":
                best["compiled"] / best["python_autopilot"],
            "fly_call_s": min(wall["compiled"]), "fly_call_python_autopilot_s": min(wall["python_autopilot"]),
            "fly_call_realtime_factor": runs["compiled"]["sim_time_s"] / min(wall["compiled"]),
            "identical_to_python_autopilot": not d_py, "identical_to_plain_python": not d_plain,
            "differences": {"python_autopilot": d_py, "plain_python": d_plain},
            "all_realtime_factors": rt, "target_met": best["compiled"] >= TARGET and not d_py and not d_plain,
        }
        if "straight" in best:
            res["realtime_factor_straight"] = best["straight"]
            res["ratio_to_straight"] = best["compiled"] / best["straight"]
        result[config] = res
        print(f"{config:8s} {a.cycles} cycles, {res['sim_time_s']:.1f} s, {res['steps']} steps, {res['status']}: "
              f"compiled {best['compiled']:6.0f} x, Python autopilot {best['python_autopilot']:5.0f} x "
              f"(ratio {res['speedup_over_python_autopilot']:.1f}), plain Python {rt_plain:4.0f} x; "
              f"whole fly() {res['fly_call_realtime_factor']:.0f} x; bit-identical to the Python autopilot "
              f"{'yes' if not d_py else 'NO ' + str(d_py)}, to plain Python {'yes' if not d_plain else 'NO ' + str(d_plain)}"
              + (f"; the straight line {best['straight']:.0f} x (ratio {res['ratio_to_straight']:.2f})"
                 if "straight" in best else ""))
    result["target_met"] = all(result[c]["target_met"] for c in REFERENCES)
    result["loadavg_1min"] = os.getloadavg()[0]
    result["python"] = sys.version.split()[0]
    result["machine"] = platform.machine()
    print(f"target >= {TARGET:g}x real time, bit-identical: {'met' if result['target_met'] else 'NOT met'} "
          f"(load average {result['loadavg_1min']:.2f})")
    tmp = Path(a.json).with_suffix(".json.tmp")
    tmp.write_text(json.dumps(result, indent=2))
    os.replace(tmp, a.json)
    print(f"wrote {a.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
