#!/usr/bin/env python
"""Nominal vs foldable glider: optimise both cycles in the same wind, optionally fly one cycle
of each in 6-DOF, and write a side-by-side report with plots into a folder:

    reference_nominal.json, reference_foldable.json    optimised references
    compare_3d.png, compare_time.png                   both cycles overlaid
    nominal/, foldable/                                recordings, plots, CSV, report of each
    compare.md, compare.json                           Table-3 style comparison (+ flown cycles)

Usage: python scripts/compare_nominal_foldable.py [--scenario physical] [--wind 6] [--fly]
                                                  [--out runs/compare] [--quiet]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path
from typing import Any

os.environ.setdefault("JSBSIM_DEBUG", "0")
os.environ.setdefault("MPLBACKEND", "Agg")

CONFIGS = ("nominal", "foldable")


def optimise_pair(scenario: str, wind: float, out: Path, quiet: bool | None) -> dict[str, Any]:
    """config -> CycleResult; writes reference_<config>.json for each ``ok`` result."""
    from fdm_awe.ocp.problem import CycleProblem
    from fdm_awe.trajectory import write_reference
    from fdm_awe.ocp.solve import solve_cycle
    from fdm_awe.progress import activity

    results = {}
    for cfg in CONFIGS:
        with activity(f"optimising {scenario}/{cfg} at {wind:g} m/s", quiet=quiet):
            res = solve_cycle(CycleProblem(scenario=scenario, config=cfg, wind_speed=wind))
        print(f"{cfg}: {res.status} ({res.reason}) in {res.solve_s:.1f} s, E_net {res.E_net_J:.1f} J", file=sys.stderr)
        if res.ok:
            write_reference(res, out / f"reference_{cfg}.json")
        results[cfg] = res
    return results


def fly_pair(results: dict[str, Any], out: Path, quiet: bool | None) -> list[Any]:
    """One cycle of each ``ok`` reference; recordings, plots, CSV, report in out/<config>/."""
    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.flight import fly
    from fdm_awe.progress import FlightProgress
    from fdm_awe.recording import flight_outputs

    flights = []
    for cfg, res in results.items():
        if not res.ok:
            continue
        ref = TrackingReference.from_ocp_file(str(out / f"reference_{cfg}.json"))
        with FlightProgress(ref.period, 1.0 / 120.0, desc=f"flying {cfg}", quiet=quiet) as bar:
            rep = fly(ref, config=cfg, cycles=1, on_step=bar)
        print(f"{cfg} flight: {rep.status} ({rep.message})", file=sys.stderr)
        flight_outputs(rep, ref, out_dir=out / cfg)
        flights.append(rep)
    return flights


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenario", choices=("physical", "paper"), default="physical")
    ap.add_argument("--wind", type=float, default=6.0, help="wind speed from the south, m/s (default 6)")
    ap.add_argument("--fly", action="store_true", help="also fly one cycle of each in 6-DOF")
    ap.add_argument("--out", default="runs/compare")
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args(argv)
    from fdm_awe.recording import cycle_outputs, plot_compare, table3_markdown

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    quiet = True if args.quiet else None
    results = optimise_pair(args.scenario, args.wind, out, quiet)
    ok = [c for c in CONFIGS if results[c].ok]
    for c in ok:
        cycle_outputs(out / f"reference_{c}.json", out_dir=out / c)
    if ok:
        plot_compare([out / f"reference_{c}.json" for c in ok], ok, out)
    flights = fly_pair(results, out, quiet) if args.fly else []
    text = table3_markdown([results[c] for c in CONFIGS],
                           title=f"Nominal vs foldable: scenario {args.scenario}, wind {args.wind:g} m/s",
                           flights=flights)
    (out / "compare.md").write_text(text + "\n")
    doc = {"optimised": {c: results[c].summary() for c in CONFIGS}, "flown": [f.as_json() for f in flights]}
    (out / "compare.json").write_text(json.dumps(doc, indent=2, default=lambda o: None) + "\n")
    print(text)
    print(f"wrote {out}/")
    return 0 if len(ok) == len(CONFIGS) else 1


if __name__ == "__main__":
    sys.exit(main())
