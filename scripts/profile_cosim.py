#!/usr/bin/env python
"""Where a co-simulation step goes: the split of one step of the benchmark flight (the kite on
50 m of line in 14 m/s wind of ``bench_cosim.py``), measured piece by piece in one run, for the
Python loop (``CoSim(compiled=False)``, the reference of the compiled loop; ``bench_cosim.py``
times both).

Pieces (microseconds per step, best of ``--repeat`` rounds, each over the same 30 s flight):

- ``jsbsim_run``: ``fdm.run()`` alone, the tether force of the flight replayed;
- ``force_set``: writing the tether force (three property sets);
- ``property_reads``: the per-step property reads (bound property-node getters);
- ``hook_and_state``: hook kinematics from the raw values (SI/NED conversion) and the lazy
  state object;
- ``ground_station``: ``GroundStation.step`` on the flight's hook positions and velocities
  (tether, drum, DC machine, converter, PI, ledger; ``ground_station_python`` the same with the
  Python step, the reference of the compiled one);
- ``controller``: the stabilising controller's ``update`` on the flight's states;
- ``loop``: the rest of ``CoSim.run`` (recording, event checks, bookkeeping), i.e. the
  co-simulation step with a replayed ground station minus the pieces above.

Usage: python scripts/profile_cosim.py [--repeat 5] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("JSBSIM_DEBUG", "0")
sys.path.insert(0, str(Path(__file__).resolve().parent))

import bench_cosim as bc  # noqa: E402
from fdm_awe.sim.loop import CoSim, Limits  # noqa: E402
from fdm_awe.groundstation import GroundStation, WinchCommand, load_ground_station  # noqa: E402
from fdm_awe.sixdof import Stabilizer  # noqa: E402

DT = 1.0 / 120.0


def _station() -> tuple[GroundStation, WinchCommand]:
    gs = GroundStation(load_ground_station(), wind_ned=(bc.WIND, 0.0, 0.0))
    gs.reset(tether_length=bc.LINE, reel_speed=0.0, mode="motor")
    return gs, WinchCommand(mode="motor", reel_speed_ref=0.0)


def record(seconds: float) -> dict:
    """One flight with fixed commands; the ground-station inputs and outputs of every step."""
    g = bc.make_glider()
    gs, hold = _station()
    calls, outs, states = [], [], []
    step = gs.step

    def rec(dt, hp, hv, cmd):
        o = step(dt, hp, hv, cmd)
        calls.append((hp, hv))
        outs.append(o)
        return o

    gs.step = rec  # type: ignore[method-assign]
    CoSim(g, gs, bc.FixedCommands(g.controls, hold), limits=Limits(max_tension=200.0),
          compiled=False).run(seconds, on_step=lambda k, s, o: states.append(s) and False)
    return {"calls": calls, "outs": outs, "states": states, "hold": hold}


class _Replay:
    def __init__(self, outs):
        self.outs, self.i = outs, 0

    def step(self, dt, hp, hv, cmd):
        o = self.outs[self.i]
        self.i += 1
        return o


def split(rec: dict) -> dict[str, float]:
    """One round of every piece, us per step."""
    pc = time.perf_counter
    outs, calls, n = rec["outs"], rec["calls"], len(rec["outs"])
    forces = [tuple(o.force_on_glider_ned.tolist()) for o in outs]
    res: dict[str, float] = {}
    g = bc.make_glider()
    fdm = g.fdm
    t = pc()
    for _ in range(n):
        fdm.run()
    res["bare_jsbsim_run"] = (pc() - t) / n
    g = bc.make_glider()
    fdm, setf, gets = g.fdm, g._set_force, g._get
    tr = tf = trd = 0.0
    for f in forces:
        t0 = pc()
        setf(f[0], f[1], f[2])
        t1 = pc()
        fdm.run()
        t2 = pc()
        [get() for get in gets]
        t3 = pc()
        tf += t1 - t0
        tr += t2 - t1
        trd += t3 - t2
    ov = _timer_overhead()
    res["jsbsim_run"] = tr / n - ov
    res["force_set"] = tf / n - ov
    res["property_reads"] = trd / n - ov
    t = pc()
    for _ in range(n):
        g._read()
        g._state = None
        g.state()
    res["hook_and_state"] = (pc() - t) / n - res["property_reads"]
    for key, jit in (("ground_station", True), ("ground_station_python", False)):
        gs, hold = _station()
        if not jit:
            gs.drivetrain._kernel = None
        st = gs.step
        t = pc()
        for hp, hv in calls:
            st(DT, hp, hv, hold)
        res[key] = (pc() - t) / n
    g = bc.make_glider()
    ctrl = Stabilizer(g, alpha_cmd=bc.ALPHA, psi_cmd=math.pi, winch=rec["hold"])
    t = pc()
    for k, s in enumerate(rec["states"]):
        ctrl.update(s.t, s, outs[k])
    res["controller"] = (pc() - t) / len(rec["states"])
    g = bc.make_glider()
    r = CoSim(g, _Replay(outs), bc.FixedCommands(g.controls, rec["hold"]), limits=Limits(max_tension=200.0),
              compiled=False).run(n * DT)
    res["cosim_replayed_ground_station"] = r.wall_s / r.steps
    res["loop"] = res["cosim_replayed_ground_station"] - (res["jsbsim_run"] + res["force_set"]
                                                          + res["property_reads"] + res["hook_and_state"])
    g = bc.make_glider()
    gs, hold = _station()
    r = CoSim(g, gs, bc.FixedCommands(g.controls, hold), limits=Limits(max_tension=200.0), compiled=False).run(n * DT)
    res["cosim_step"] = r.wall_s / r.steps
    return res


def _timer_overhead() -> float:
    pc = time.perf_counter
    t = pc()
    for _ in range(10000):
        pc()
    return (pc() - t) / 10000


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--seconds", type=float, default=30.0)
    ap.add_argument("--json", default=None, help="write the split as JSON")
    a = ap.parse_args(argv)
    rec = record(a.seconds)
    rounds = [split(rec) for _ in range(max(1, a.repeat))]
    best = {k: min(r[k] for r in rounds) * 1e6 for k in rounds[0]}
    order = ("jsbsim_run", "force_set", "property_reads", "hook_and_state", "ground_station", "loop")
    total = sum(best[k] for k in order)
    print(f"split of one co-simulation step (fixed commands), us, best of {a.repeat}; "
          f"load average {os.getloadavg()[0]:.2f}")
    for k in order:
        print(f"  {k:24s} {best[k]:7.2f}   {100 * best[k] / total:5.1f} %")
    print(f"  {'sum':24s} {total:7.2f}   (measured co-simulation step {best['cosim_step']:.2f})")
    print(f"  bare fdm.run()           {best['bare_jsbsim_run']:7.2f}")
    print(f"  in the loop: ground station {best['cosim_step'] - best['cosim_replayed_ground_station']:7.2f}, "
          f"everything but fdm.run() {best['cosim_step'] - best['jsbsim_run']:7.2f} "
          f"(pieces alternating with JSBSim cost more than alone: caches)")
    print(f"  ground station, Python step          {best['ground_station_python']:7.2f}")
    print(f"  stabilising controller update        {best['controller']:7.2f}")
    if a.json:
        Path(a.json).write_text(json.dumps({"us_per_step": best, "repeat": a.repeat,
                                            "loadavg": os.getloadavg()[0]}, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
