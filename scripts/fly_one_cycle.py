#!/usr/bin/env python
"""Optimise a pumping cycle, fly one cycle of it in 6-DOF, and write everything a person needs
to look at the run into one folder:

    reference.json          the optimised reference trajectory (optimiser's file format)
    cycle.rrd, cycle_*.png, cycle.csv, cycle.md      the optimised cycle
    flight.rrd, flight_*.png, flight.csv, flight.md  the flown cycle (also when it ended early)
    flight.json             the numbers of the flight (``fdm-awe fly --json`` contract)

Open a recording with ``rerun OUT/flight.rrd``.

Usage: python scripts/fly_one_cycle.py [--scenario physical] [--config foldable] [--wind 6]
                                       [--out runs/one_cycle] [--reference FILE] [--figure PNG] [--quiet]
Exit code 0 when the flight completed without an event.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

os.environ.setdefault("JSBSIM_DEBUG", "0")
os.environ.setdefault("MPLBACKEND", "Agg")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenario", choices=("physical", "paper"), default="physical")
    ap.add_argument("--config", choices=("foldable", "nominal"), default="foldable")
    ap.add_argument("--wind", type=float, default=6.0, help="wind speed from the south, m/s (default 6)")
    ap.add_argument("--out", default="runs/one_cycle", help="output folder (default runs/one_cycle)")
    ap.add_argument("--reference", help="fly this reference-trajectory file instead of optimising one")
    ap.add_argument("--figure", metavar="PNG", help="also write a one-picture summary of the flight (e.g. docs/cycle.png)")
    ap.add_argument("--quiet", action="store_true", help="no progress bars")
    args = ap.parse_args(argv)

    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.flight import fly
    from fdm_awe.progress import FlightProgress, activity
    from fdm_awe.recording import cycle_outputs, flight_outputs

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    quiet = True if args.quiet else None
    if args.reference:
        ref_file = Path(args.reference)
    else:
        from fdm_awe.ocp.problem import CycleProblem
        from fdm_awe.trajectory import write_reference
        from fdm_awe.ocp.solve import solve_cycle

        problem = CycleProblem(scenario=args.scenario, config=args.config, wind_speed=args.wind)
        with activity(f"optimising {args.scenario}/{args.config} at {args.wind:g} m/s", quiet=quiet):
            res = solve_cycle(problem)
        print(f"optimised: {res.status} ({res.reason}), {res.solve_s:.1f} s, T1 {res.T1_s:.2f} s, T2 {res.T2_s:.2f} s, "
              f"E_net {res.E_net_J:.1f} J, P_avg {res.P_avg_W:.2f} W")
        if not res.ok:
            print("no cycle to fly", file=sys.stderr)
            return 1
        ref_file = write_reference(res, out / "reference.json")
    written = {"reference": str(ref_file), "cycle": cycle_outputs(ref_file, out_dir=out)}

    ref = TrackingReference.from_ocp_file(str(ref_file))
    dt = 1.0 / 120.0
    with FlightProgress(ref.period, dt, desc="flying one cycle", quiet=quiet) as bar:
        # the plant follows the scenario (the reference file's, when one is given)
        plant = ref.meta.get("scenario") if args.reference and ref.meta.get("scenario") in ("physical", "paper") else args.scenario
        report = fly(ref, config=args.config, cycles=1, dt=dt, on_step=bar, plant=plant)
    print(f"flown: {report.status} ({report.message}), {report.sim_time_s:.1f} s simulated in {report.wall_s:.1f} s")
    written["flight"] = flight_outputs(report, ref, out_dir=out)
    if args.figure:
        from fdm_awe.recording import plot_summary

        written["figure"] = str(plot_summary(report, ref, args.figure))
    doc = report.as_json()
    doc["outputs"] = written
    (out / "flight.json").write_text(json.dumps(doc, indent=2, default=lambda o: None) + "\n")
    print((out / "flight.md").read_text().split("## Energy ledger")[0])
    print(f"wrote {out}/: reference.json, cycle.rrd, flight.rrd, PNGs, CSVs, markdown; view with: rerun {out / 'flight.rrd'}")
    return 0 if report.status == "ok" else 1


if __name__ == "__main__":
    sys.exit(main())
