#!/usr/bin/env python
"""Benchmark and reference numbers of the ground station.

Prints the cost of one ``GroundStation.step`` (microseconds, at several flight steps, in
generator and PI-motor mode) next to one bare JSBSim step of the glider measured in the same
run, plus the closed-form checks (docs/design.md section 6 generator point, motor at full duty), the
PI reel-in step response (overshoot, 2 % settling time) and the energy-ledger residuals.
Writes everything to a JSON file.

    python scripts/bench_groundstation.py [--json groundstation_bench.json] [--calls 3000]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

os.environ.setdefault("JSBSIM_DEBUG", "0")

import numpy as np  # noqa: E402

from fdm_awe import ROOT  # noqa: E402
from fdm_awe.groundstation import (  # noqa: E402
    GroundStation, WinchCommand, generator_steady, load_ground_station, motor_steady)

EL = math.radians(30.0)
U = np.array([math.cos(EL), 0.0, -math.sin(EL)])
E = np.array([0.0, 1.0, 0.0])


def _best_us(fn, calls: int, repeats: int = 7) -> float:
    """Fastest over ``repeats`` of the mean cost of one call, microseconds (the minimum is the
    least disturbed by other processes on a shared machine)."""
    out = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn(calls)
        out.append((time.perf_counter() - t0) / calls * 1e6)
    return min(out)


def bench_ground_station(calls: int) -> dict:
    params = load_ground_station()
    res = {}
    for label, dt in (("1/1000", 1 / 1000), ("1/120", 1 / 120), ("1/60", 1 / 60)):
        for mode in ("generator", "motor"):
            gs = GroundStation(params, wind_ned=(3.0, 0.0, 0.0))
            gs.reset(200.0, 3.0 if mode == "generator" else -3.0, mode)
            cmd = WinchCommand(mode, reel_speed_ref=-3.0)
            v = 3.0 if mode == "generator" else -2.5
            pos, vel = 200.0 * U + 5.0 * E, v * U + 12.0 * E

            def run(n, gs=gs, cmd=cmd, dt=dt, pos=pos, vel=vel):
                step = gs.step
                for _ in range(n):
                    step(dt, pos, vel, cmd)

            run(200)
            n_sub = gs._substeps(dt)
            res[f"{mode}@{label}"] = {"us_per_step": _best_us(run, calls), "substeps": n_sub}
    return res


def bench_jsbsim(calls: int, dt: float = 1 / 120) -> dict:
    import jsbsim

    name, root = "glider_unfolded", ROOT
    note = None
    if not (ROOT / "aircraft" / name / f"{name}.xml").is_file():
        name, root = "c172x", jsbsim.get_default_root_dir()
        note = "glider_unfolded.xml not found: timed JSBSim's bundled c172x instead"
        print("note:", note)
    fdm = jsbsim.FGFDMExec(str(root))
    fdm.set_debug_level(0)
    if not fdm.load_model(name):
        raise SystemExit(f"JSBSim could not load {name}")
    fdm.set_dt(dt)
    fdm["ic/h-sl-ft"] = 300.0
    fdm["ic/vc-kts"] = 25.0
    fdm["ic/gamma-deg"] = 0.0
    fdm.run_ic()

    def run(n, fdm=fdm):
        r = fdm.run
        for _ in range(n):
            r()

    run(200)
    return {"aircraft": name, "dt": dt, "us_per_step": _best_us(run, calls), "note": note}


def reference_checks() -> dict:
    params = load_ground_station()
    g = generator_steady(30.0, params, 1.5)
    gs = GroundStation(params)
    gs.reset(200.0, 0.0, "generator")
    for _ in range(360):
        out = gs.step_with_tension(1 / 120, 30.0, WinchCommand("generator"))
    dyn = dict(omega=out.omega, reel_speed=out.reel_speed, current=out.current, p_load=out.p_electrical,
               p_mech=out.p_mechanical, efficiency=out.p_electrical / out.p_mechanical)
    # motor at full duty, slack line: closed form of the armature equation
    K, R = params.machine.k, params.machine.resistance
    Va, Ud = params.converter.supply_voltage, params.converter.device_drop
    Mc, B = params.winch.coulomb_friction, params.winch.viscous_friction
    w_cf = (Va - 2 * Ud - R * Mc / K) / (K + R * B / K)
    gs.reset(200.0, 0.0, "motor")
    for _ in range(120):
        m = gs.step(1 / 120, (1.0, 0.0, -1.0), (0.0, 0.0, 0.0), WinchCommand("motor", duty=1.0))
    return {
        "generator_G30_RL1.5": {"steady_py": g._asdict(), "dynamic": dyn,
                                "design_md_6": dict(omega=117.010, reel_speed=3.5103, current=6.148,
                                                    p_load=56.70, p_mech=105.31, efficiency=0.538)},
        "motor_full_duty_no_tension": {"omega_closed_form": -w_cf, "omega_dynamic": m.omega,
                                       "current_closed_form": (Mc + B * w_cf) / K, "current_dynamic": m.current},
        "motor_steady_3mps_5N": motor_steady(3.0, 5.0, params)._asdict(),
    }


def pi_response(dt: float = 1 / 120, load: float = 5.0, v_ref: float = -3.0) -> dict:
    gs = GroundStation(load_ground_station())
    gs.reset(200.0, 0.0, "motor")
    cmd = WinchCommand("motor", reel_speed_ref=v_ref)
    t, v, imax = [], [], 0.0
    for k in range(int(2.0 / dt)):
        o = gs.step_with_tension(dt, load, cmd)
        t.append((k + 1) * dt)
        v.append(o.reel_speed)
        imax = max(imax, o.current)
    t, v = np.array(t), np.array(v)
    outside = np.nonzero(np.abs(v - v_ref) > 0.02 * abs(v_ref))[0]
    return {"v_ref_mps": v_ref, "load_N": load, "dt": dt,
            "overshoot_pct": float(max(0.0, (np.max(-v) + v_ref) / -v_ref * 100.0)),
            "settling_time_2pct_s": float(t[outside[-1]]) if len(outside) else 0.0,
            "final_mps": float(v[-1]), "peak_current_A": imax}


def ledger_cases() -> dict:
    params = load_ground_station()
    dt = 1 / 120
    out = {}
    gs = GroundStation(params)
    gs.reset(200.0, 0.0, "generator")
    for k in range(int(6 / dt)):
        t = k * dt
        gs.step(dt, U * (200 + 3.3 * t) + E * 15 * math.sin(t), U * 3.3 + E * 15 * math.cos(t),
                WinchCommand("generator"))
    out["generation"] = gs.ledger.as_dict()
    gs.reset(150.0, 0.0, "motor")
    for k in range(int(6 / dt)):
        t = k * dt
        gs.step(dt, U * (150 - 2.8 * t), U * -2.8, WinchCommand("motor", reel_speed_ref=-3.0))
    out["reel_in"] = gs.ledger.as_dict()
    gs.reset(200.0, 0.0, "generator")
    for k in range(360):
        gs.step_with_tension(dt, 30.0, WinchCommand("generator"))
    for k in range(360):
        gs.step_with_tension(dt, 5.0, WinchCommand("motor", reel_speed_ref=-3.0))
    for k in range(120):
        gs.step_with_tension(dt, 25.0, WinchCommand("generator"))
    out["mode_switch"] = gs.ledger.as_dict()
    for v in out.values():
        big = max(abs(x) for k, x in v.items() if k not in ("residual", "relative_residual"))
        v["numerical_rel"] = v["numerical"] / big
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", default="groundstation_bench.json", help="output JSON file")
    ap.add_argument("--calls", type=int, default=3000, help="calls per timing repeat")
    a = ap.parse_args(argv)

    jsb = bench_jsbsim(a.calls)
    gsb = bench_ground_station(a.calls)
    jsb2 = bench_jsbsim(a.calls)  # before and after: keep the faster (less disturbed) timing
    if jsb2["us_per_step"] < jsb["us_per_step"]:
        jsb = jsb2
    print(f"bare JSBSim step ({jsb['aircraft']}, dt 1/120 s): {jsb['us_per_step']:.1f} us")
    for k, v in gsb.items():
        print(f"ground-station step {k:<17s} ({v['substeps']:2d} sub-steps): {v['us_per_step']:6.1f} us"
              f"  = {v['us_per_step'] / jsb['us_per_step']:.2f} x JSBSim")
    ref = reference_checks()
    g = ref["generator_G30_RL1.5"]
    print("generator G=30 N, R_L=1.5 ohm (steady.py | dynamic | docs/design.md 6):")
    for k in g["design_md_6"]:
        print(f"  {k:<11s} {g['steady_py'][k]:10.5f} | {g['dynamic'][k]:10.5f} | {g['design_md_6'][k]}")
    m = ref["motor_full_duty_no_tension"]
    print(f"motor full duty, no tension: omega {m['omega_dynamic']:.4f} rad/s (closed form {m['omega_closed_form']:.4f}),"
          f" i {m['current_dynamic']:.5f} A (closed form {m['current_closed_form']:.5f})")
    pi = pi_response()
    print(f"PI reel-in {pi['v_ref_mps']} m/s under {pi['load_N']} N: overshoot {pi['overshoot_pct']:.2f} %, "
          f"2 % settling {pi['settling_time_2pct_s']:.3f} s, final {pi['final_mps']:.6f} m/s")
    led = ledger_cases()
    for k, v in led.items():
        print(f"ledger {k:<12s}: relative residual {v['relative_residual']:.2e}, "
              f"integrator dissipation {v['numerical']:.4f} J ({v['numerical_rel']:.2e} of the largest term)")
    result = {"jsbsim": jsb, "ground_station": gsb,
              "ratio_gs_over_jsbsim_at_1_120": {k: v["us_per_step"] / jsb["us_per_step"]
                                                for k, v in gsb.items() if k.endswith("1/120")},
              "reference": ref, "pi_step": pi, "ledger": led,
              "python": sys.version.split()[0]}
    with open(a.json, "w") as f:
        json.dump(result, f, indent=2)
    print("wrote", a.json)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
