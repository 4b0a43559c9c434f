#!/usr/bin/env python
"""Benchmark: bare JSBSim step of the glider vs one co-simulation step, measured in one run.

- bare: ``fdm.run()`` of the same aircraft (glider_foldable) in the same flight condition;
- co-simulation: JSBSim + tether hook + ground station (tether, winch, DC machine, converter,
  PI; fdm_awe.groundstation) through ``CoSim.run``: with fixed commands (the compiled loop runs
  in blocks), with fixed commands from a controller called every step (the per-step cost of a
  Python controller's slot, without its own work), and with the simple stabilising controller;
  the last two also with the Python loop (``CoSim(compiled=False)``), its reference;
- real-time factor of a 30 s flight at 120 Hz (a kite hovering on 50 m of line in 14 m/s wind,
  winch held by the PI speed loop at zero reel speed);
- for scale, one pumping cycle flown by the autopilot (``fdm_awe.sim.flight.fly`` on the stored
  physical nominal 8 m/s reference of the tests, no recording): compiled (the AUTO steps in the
  kernel, in blocks) and with the Python loop (the autopilot in Python every step);
  ``scripts/bench_autopilot.py`` is the benchmark of the autopilot flight.

Step timings are the best of ``--repeat`` interleaved short rounds, the real-time factors the best
of ``--flights`` whole flights (the machine is shared; the 1-minute load average is printed and
stored). The ground station runs its step as one compiled call when
numba is installed (``FDM_AWE_JIT=0``: the Python step, its reference); both are timed alone. Targets
(docs/design.md section 9): ratio <= 3, real-time factor >= 500.

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

from fdm_awe.sim.loop import CoSim, Limits  # noqa: E402
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

    constant_commands = True  # CoSim may run the compiled loop in blocks

    def __init__(self, surfaces, winch):
        self.out = (surfaces, winch)

    def update(self, t, state, gs_output):
        return self.out


class FixedEveryStep(FixedCommands):
    """The same commands, but the loop calls the controller every step."""

    constant_commands = False


def bench_cosim(seconds: float, controller: str = "stabilizer", compiled: bool | None = None) -> tuple[float, float, str, str]:
    """Seconds per co-simulation step, real-time factor, and the run's status. ``controller``:
    "stabilizer", "fixed" or "fixed-every-step"; ``compiled`` False: the Python loop."""
    g = make_glider()
    gs = GroundStation(load_ground_station(), wind_ned=(WIND, 0.0, 0.0))
    gs.reset(tether_length=LINE, reel_speed=0.0, mode="motor")
    hold = WinchCommand(mode="motor", reel_speed_ref=0.0)
    if controller == "stabilizer":
        ctrl = Stabilizer(g, alpha_cmd=ALPHA, psi_cmd=math.pi, winch=hold)
    elif controller == "fixed":
        ctrl = FixedCommands(g.controls, hold)
    else:
        ctrl = FixedEveryStep(g.controls, hold)
    sim = CoSim(g, gs, ctrl, limits=Limits(max_tension=200.0), compiled=compiled)
    res = sim.run(seconds)
    return res.wall_s / max(res.steps, 1), res.realtime_factor, res.status, sim.loop


REFERENCE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "data", "ref_physical_nominal_8mps.json")


def bench_autopilot_cycle(compiled: bool | None = None) -> tuple[float, float, int, str]:
    """One pumping cycle of the stored reference flown by the autopilot: wall s per step,
    real-time factor, steps and status (``compiled`` False: the Python loop)."""
    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.flight import fly

    ref = TrackingReference.from_ocp_file(REFERENCE)

    def setup(autopilot, sim):
        sim.compiled = compiled

    rep = fly(ref, config="nominal", cycles=1, setup=setup)
    n = max(rep.result.steps, 1)
    return rep.wall_s / n, rep.realtime_factor, rep.result.steps, rep.status


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
    kinds = (("fixed", None), ("fixed-every-step", None), ("stabilizer", None), ("fixed-every-step", False),
             ("stabilizer", False))
    steps: dict[tuple, list[float]] = {k: [] for k in kinds}
    rtfs: dict[tuple, list[float]] = {k: [] for k in kinds}
    bare, gst, gsp, status, loop_name = [], [], [], "ok", ""
    jit = compiled_station() is not None
    rs = a.round_seconds
    for k in range(max(1, a.repeat)):
        bare.append(bench_bare(rs))
        gst.append(bench_ground_station(rs))
        if k < 3:
            gsp.append(bench_ground_station(rs, compiled=False))
        for kind in kinds:
            steps[kind].append(bench_cosim(rs, *kind)[0])
    for _ in range(max(1, a.flights)):
        for kind in kinds:
            _, r, st, loop = bench_cosim(a.seconds, *kind)
            rtfs[kind].append(r)
            if kind == ("stabilizer", None):
                status = st
            if kind == ("fixed", None):
                loop_name = loop
    ap = {c: [bench_autopilot_cycle(c) for _ in range(max(1, min(a.flights, 2)))] for c in (None, False)}
    ap_us = {c: min(x[0] for x in v) * 1e6 for c, v in ap.items()}
    ap_rt = {c: max(x[1] for x in v) for c, v in ap.items()}
    b = min(bare)
    us = {k: min(v) * 1e6 for k, v in steps.items()}
    rt = {k: max(v) for k, v in rtfs.items()}
    name = {("fixed", None): "fixed_commands", ("fixed-every-step", None): "controller_every_step",
            ("stabilizer", None): "stabilizer", ("fixed-every-step", False): "python_loop_controller_every_step",
            ("stabilizer", False): "python_loop_stabilizer"}
    out = {
        "aircraft": "glider_foldable",
        "rate_hz": 120,
        "flight_s": a.seconds,
        "loop": loop_name,
        "bare_step_us": b * 1e6,
        "ground_station_step_us": min(gst) * 1e6,
        "ground_station_compiled": jit,
        "ground_station_step_python_us": min(gsp) * 1e6,
        # the co-simulation (JSBSim + tether + ground station): fixed commands
        "cosim_step_us": us[("fixed", None)],
        "ratio": us[("fixed", None)] / (b * 1e6),
        "realtime_factor": rt[("fixed", None)],
        "flight_status": status,
        "targets": {"ratio_max": 3.0, "realtime_factor_min": 500.0},
        "ratio_ok": us[("fixed", None)] / (b * 1e6) <= 3.0,
        "realtime_ok": rt[("fixed", None)] >= 500.0,
        "step_us": {name[k]: v for k, v in us.items()},
        "ratio_to_bare": {name[k]: v / (b * 1e6) for k, v in us.items()},
        "realtime_factors": {name[k]: v for k, v in rt.items()},
        "repeat": a.repeat,
        "round_s": rs,
        "flights": a.flights,
        "loadavg_1min": os.getloadavg()[0],
        "python": sys.version.split()[0],
        "machine": platform.machine(),
        "autopilot_cycle": {"reference": "tests/data/ref_physical_nominal_8mps.json", "steps": ap[None][0][2],
                            "status": ap[None][0][3], "step_us": ap_us[None], "realtime_factor": ap_rt[None],
                            "python_loop_step_us": ap_us[False], "python_loop_realtime_factor": ap_rt[False],
                            "ratio_to_bare": ap_us[None] / (b * 1e6)},
        "all_bare_us": [x * 1e6 for x in bare],
        "all_step_us": {name[k]: [x * 1e6 for x in v] for k, v in steps.items()},
    }
    print(f"bare JSBSim step      {out['bare_step_us']:8.2f} us")
    print(f"ground station step   {out['ground_station_step_us']:8.2f} us  (alone; "
          f"{'one compiled call' if jit else 'in Python'}; Python step {out['ground_station_step_python_us']:.2f} us)")
    label = {("fixed", None): "fixed commands", ("fixed-every-step", None): "controller called every step",
             ("stabilizer", None): "stabilising controller", ("fixed-every-step", False): "Python loop, controller every step",
             ("stabilizer", False): "Python loop, stabilising controller"}
    print(f"co-simulation (JSBSim + tether + ground station; {loop_name} loop), per step, ratio to bare, "
          f"real-time factor of a {a.seconds:g} s flight at 120 Hz:")
    for kind in kinds:
        print(f"  {label[kind]:36s} {us[kind]:7.2f} us  ratio {us[kind] / (b * 1e6):5.2f}  {rt[kind]:6.0f} x")
    print(f"  {'autopilot, one pumping cycle':36s} {ap_us[None]:7.2f} us  ratio {ap_us[None] / (b * 1e6):5.2f}  "
          f"{ap_rt[None]:6.0f} x   ({ap[None][0][2]} steps, status {ap[None][0][3]}; "
          f"Python loop {ap_us[False]:.2f} us, {ap_rt[False]:.0f} x)")
    print(f"targets (co-simulation, fixed commands): ratio <= 3 {'met' if out['ratio_ok'] else 'NOT met'}, "
          f"real-time factor >= 500 {'met' if out['realtime_ok'] else 'NOT met'}; stabilised flight status {status}")
    with open(a.json, "w") as fh:
        json.dump(out, fh, indent=2)
    print(f"load average (1 min)  {out['loadavg_1min']:8.2f}")
    print(f"wrote {a.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
