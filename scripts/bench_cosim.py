#!/usr/bin/env python
"""Benchmark: bare JSBSim step of the glider vs one co-simulation step, measured in one run.

- bare: ``fdm.run()`` of the same aircraft (glider_foldable) in the same flight condition;
- co-simulation: JSBSim + tether hook + ground station (tether, winch, DC machine, converter,
  PI; fdm_awe.groundstation) through ``CoSim.run``, once with fixed commands and once with the
  simple stabilising controller;
- real-time factor of a 30 s flight at 120 Hz (a kite hovering on 50 m of line in 14 m/s wind,
  winch held by the PI speed loop at zero reel speed).

Step timings are the best of ``--repeat`` interleaved short rounds, the real-time factors the best
of ``--flights`` whole flights (the machine is shared; the 1-minute load average is printed and
stored). The ground station runs its step as one compiled call when
numba is installed (``FDM_AWE_JIT=0``: the Python step, its reference); both are timed alone. Targets
(design notes, section 9): ratio <= 3, real-time factor >= 500.

Usage: python scripts/bench_cosim.py [--json bench_cosim.json] [--repeat 20] [--round-seconds 2.5] [--seconds 30] [--flights 3]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time

os.environ.setdefault("JSBSIM_DEBUG", "0")

from fdm_awe.cosim import CoSim, Limits  # noqa: E402
from fdm_awe.groundstation import GroundStation, WinchCommand, load_ground_station  # noqa: E402
from fdm_awe.groundstation.substeps import compiled_station  # noqa: E402
from fdm_awe.sixdof import JSBSimGlider, Stabilizer  # noqa: E402

WIND = 14.0  # m/s from the south
LINE = 50.0  # m
ELEVATION = math.radians(80.0)
ALPHA = 0.10436  # rad, best glide ratio of the unfolded glider


def make_glider() -> JSBSimGlider:
    g = JSBSimGlider("glider_foldable", dt=1.0 / 120.0, wind_ned=(WIND, 0.0, 0.0))
    g.reset((LINE * math.cos(ELEVATION), 0.0, -LINE * math.sin(ELEVATION)), WIND, gamma=0.0, psi=math.pi, alpha=ALPHA)
    return g


def bench_bare(seconds: float) -> float:
    """Seconds per bare ``fdm.run()`` (tether force held constant, controls fixed)."""
    g = make_glider()
    fdm = g.fdm
    n = int(round(seconds * 120))
    t = time.perf_counter()
    for _ in range(n):
        fdm.run()
    return (time.perf_counter() - t) / n


def bench_ground_station(seconds: float, compiled: bool = True) -> float:
    """Seconds per ``GroundStation.step`` alone, glider hook fixed at the start position
    (``compiled`` False: the Python step, the reference of the compiled one)."""
    g = make_glider()
    gs = GroundStation(load_ground_station(), wind_ned=(WIND, 0.0, 0.0))
    gs.reset(tether_length=LINE, reel_speed=0.0, mode="motor")
    if not compiled:
        gs.drivetrain._kernel = None
    hold = WinchCommand(mode="motor", reel_speed_ref=0.0)
    hp, hv = g.hook_kinematics()
    n = int(round(seconds * 120))
    t = time.perf_counter()
    for _ in range(n):
        gs.step(1.0 / 120.0, hp, hv, hold)
    return (time.perf_counter() - t) / n


class FixedCommands:
    """Controller with constant commands (isolates JSBSim + tether + ground station)."""

    def __init__(self, surfaces, winch):
        self.out = (surfaces, winch)

    def update(self, t, state, gs_output):
        return self.out


def bench_cosim(seconds: float, controller: str = "stabilizer") -> tuple[float, float, str]:
    """Seconds per co-simulation step, real-time factor, and the run's status."""
    g = make_glider()
    gs = GroundStation(load_ground_station(), wind_ned=(WIND, 0.0, 0.0))
    gs.reset(tether_length=LINE, reel_speed=0.0, mode="motor")
    hold = WinchCommand(mode="motor", reel_speed_ref=0.0)
    if controller == "stabilizer":
        ctrl = Stabilizer(g, alpha_cmd=ALPHA, psi_cmd=math.pi, winch=hold)
    else:
        ctrl = FixedCommands(g.controls, hold)
    sim = CoSim(g, gs, ctrl, limits=Limits(max_tension=200.0))
    res = sim.run(seconds)
    return res.wall_s / max(res.steps, 1), res.realtime_factor, res.status


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", default="bench_cosim.json", help="output JSON file")
    ap.add_argument("--repeat", type=int, default=20, help="interleaved rounds of the step timings")
    ap.add_argument("--round-seconds", type=float, default=2.5,
                    help="simulated seconds per round of the step timings (short rounds: on a shared "
                         "machine the best of many short rounds is the least disturbed)")
    ap.add_argument("--seconds", type=float, default=30.0, help="flight of the real-time factor, s")
    ap.add_argument("--flights", type=int, default=3, help="flights of the real-time factor (best counts)")
    a = ap.parse_args(argv)
    bare, co, rtf, co0, rtf0, gst, gsp, status = [], [], [], [], [], [], [], "ok"
    jit = compiled_station() is not None
    rs = a.round_seconds
    for k in range(max(1, a.repeat)):
        bare.append(bench_bare(rs))
        gst.append(bench_ground_station(rs))
        if k < 3:
            gsp.append(bench_ground_station(rs, compiled=False))
        co0.append(bench_cosim(rs, "fixed")[0])
        co.append(bench_cosim(rs)[0])
    for _ in range(max(1, a.flights)):
        rtf0.append(bench_cosim(a.seconds, "fixed")[1])
        _, r, status = bench_cosim(a.seconds)
        rtf.append(r)
    b, c, c0 = min(bare), min(co), min(co0)
    out = {
        "aircraft": "glider_foldable",
        "rate_hz": 120,
        "flight_s": a.seconds,
        "bare_step_us": b * 1e6,
        "cosim_step_us": c * 1e6,
        "ratio": c / b,
        "realtime_factor": max(rtf),
        "ground_station_step_us": min(gst) * 1e6,
        "ground_station_compiled": jit,
        "ground_station_step_python_us": min(gsp) * 1e6,
        "cosim_fixed_commands_step_us": c0 * 1e6,
        "ratio_fixed_commands": c0 / b,
        "realtime_factor_fixed_commands": max(rtf0),
        "flight_status": status,
        "targets": {"ratio_max": 3.0, "realtime_factor_min": 500.0},
        "ratio_ok": c / b <= 3.0,
        "realtime_ok": max(rtf) >= 500.0,
        "repeat": a.repeat,
        "round_s": rs,
        "flights": a.flights,
        "loadavg_1min": os.getloadavg()[0],
        "python": sys.version.split()[0],
        "machine": platform.machine(),
        "all_bare_us": [x * 1e6 for x in bare],
        "all_cosim_us": [x * 1e6 for x in co],
        "all_cosim_fixed_commands_us": [x * 1e6 for x in co0],
    }
    print(f"bare JSBSim step      {out['bare_step_us']:8.2f} us")
    print(f"ground station step   {out['ground_station_step_us']:8.2f} us  (alone; "
          f"{'one compiled call' if jit else 'in Python'}; Python step {out['ground_station_step_python_us']:.2f} us)")
    print(f"co-simulation step    {out['cosim_fixed_commands_step_us']:8.2f} us  (JSBSim + tether + ground station, fixed commands)"
          f"  ratio {out['ratio_fixed_commands']:.2f}")
    print(f"co-simulation step    {out['cosim_step_us']:8.2f} us  (JSBSim + tether + ground station + stabilising controller)")
    print(f"ratio                 {out['ratio']:8.2f}     (target <= 3)")
    print(f"real-time factor      {out['realtime_factor']:8.0f} x   ({a.seconds:g} s flight at 120 Hz, target >= 500; status {status})")
    print(f"  with fixed commands {out['realtime_factor_fixed_commands']:8.0f} x")
    with open(a.json, "w") as fh:
        json.dump(out, fh, indent=2)
    print(f"load average (1 min)  {out['loadavg_1min']:8.2f}")
    print(f"wrote {a.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
