#!/usr/bin/env python
"""Benchmark: a turbulent flight on a lumped line (uniform wind), the autopilot compiled in
blocks (the blocks hand the line the gust the glider meets after every step) against the same
flight with the autopilot run by Python every step (a per-step hook that does nothing).

The flight is ``fdm_awe.sim.flight.fly`` of the stored 8 m/s nominal reference of the tests
(the sized line), ``--cycles`` pumping cycles at 120 Hz in ``--turbulence`` (named level and
seed). The real-time factor is simulated time over the wall time of the flight loop, the best
of ``--flights`` flights; both flights must be identical (logged columns, line shape, cycles'
energies, ledger).

Usage: python scripts/bench_line_gust.py [--tether lumped-implicit:30] [--cycles 3] [--turbulence light:3] [--flights 2]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.sim.flight import fly

REF = Path(__file__).resolve().parent.parent / "tests" / "data" / "ref_physical_nominal_8mps_sized.json"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tether", default="lumped-implicit:30")
    ap.add_argument("--cycles", type=int, default=3)
    ap.add_argument("--turbulence", default="light:3", help="LEVEL:SEED")
    ap.add_argument("--flights", type=int, default=2)
    a = ap.parse_args()
    level, seed = a.turbulence.split(":")
    ref = TrackingReference.from_ocp_file(REF)
    kw = dict(config="nominal", cycles=a.cycles, tether=a.tether, turbulence=(level, int(seed)))
    best: dict[str, float] = {}
    reps = {}
    for _ in range(a.flights):
        for name, on_step in (("compiled", None), ("python_autopilot", lambda k, s, o: None)):
            rep = fly(ref, on_step=on_step, **kw)
            reps[name] = rep
            best[name] = max(best.get(name, 0.0), rep.realtime_factor)
    b, c = reps["compiled"], reps["python_autopilot"]
    same = (np.array_equal(b.result.data, c.result.data, equal_nan=True)
            and all(np.array_equal(b.line_shape[k], c.line_shape[k], equal_nan=True) for k in ("t", "nodes", "tension"))
            and [m.E_net_J for m in b.cycles] == [m.E_net_J for m in c.cycles])
    print(f"{a.tether}, {a.cycles} cycles, turbulence {a.turbulence}, {b.result.steps} steps "
          f"({b.loop['autopilot_compiled_steps']} compiled), status {b.status}")
    for name, x in best.items():
        print(f"  {name:18s} {x:7.1f}x real time (best of {a.flights})")
    print(f"  ratio {best['compiled'] / best['python_autopilot']:.1f}, identical: {same}")


if __name__ == "__main__":
    main()
