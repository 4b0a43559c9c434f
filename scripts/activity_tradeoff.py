"""What a smoother reference costs: control activity and tracking against power.

For each configuration the physical cycle at 8 m/s (the demo's) is optimised with the flyable
margins of ``fdm-awe fly`` (C_L <= 0.85 C_Lmax, |bank| <= 0.8 rad) and, variant by variant,
further bounds on the reference (:class:`fdm_awe.ocp.problem.Bounds`): a higher minimum
airspeed, the bank's and the angle of attack's rate around the whole cycle, the line's catch
speed at the end of recovery. Each reference is flown for ``--cycles`` cycles by the autopilot
in the 6-DOF co-simulation (the default plant, calm air). Reported per run:

- the optimiser's average power ``P_opt`` [W] and the flown net energy per cycle [J] (the
  mean of the cycles after the first, which starts from the reference's initial state);
- the control activity (RMS of each surface command above 0.5 Hz, full deflections,
  :mod:`fdm_awe.sim.activity`) and the tracking RMS [m];
- where the activity sits: the share of the surfaces' high-pass energy (4th-order Butterworth
  at 0.5 Hz, zero phase) within 1.5 s before to 3 s after a phase switch, and that window's
  share of the flight time.

Usage::

    python scripts/activity_tradeoff.py --config nominal,foldable --json runs/tradeoff.json \
        --report runs/tradeoff.md

Prints a table; writes the JSON and the markdown atomically. Exit 0 when every optimisation and
flight ended ok, 1 otherwise, 2 on bad input.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from fdm_awe.errors import InputError

WIND_MPS = 8.0
#: the variants: name -> extra Bounds fields over the flyable margins
VARIANTS: dict[str, dict[str, float]] = {
    "optimum": {},
    "vmin10": {"V_min": 10.0},
    "rates": {"bank_rate_max": 0.3, "alpha_rate_max": 0.1},
    "catch": {"catch_speed_max": 1.0},
    "all": {"V_min": 10.0, "bank_rate_max": 0.3, "alpha_rate_max": 0.1, "catch_speed_max": 1.0},
}
#: s, the window around a phase switch: before, after
SWITCH_WINDOW = (1.5, 3.0)


def switch_share(controls: np.ndarray, phases: list[str], dt: float) -> tuple[float, float]:
    """Share of the surfaces' high-pass energy within :data:`SWITCH_WINDOW` of a phase switch,
    and the windows' share of the flight time; ``controls`` (steps x 3) the surface commands."""
    from scipy.signal import butter, sosfiltfilt

    from fdm_awe.sim.activity import F_CUT_HZ

    n = min(len(controls), len(phases))
    u = np.nan_to_num(np.asarray(controls[:n], float))
    hp = sosfiltfilt(butter(4, F_CUT_HZ, "hp", fs=1.0 / dt, output="sos"), u, axis=0)
    e = np.sum(hp * hp, axis=1)
    t = np.arange(n) * dt
    mask = np.zeros(n, bool)
    for k in range(1, n):
        if phases[k] != phases[k - 1]:
            mask |= (t > t[k] - SWITCH_WINDOW[0]) & (t < t[k] + SWITCH_WINDOW[1])
    total = float(e.sum())
    return (float(e[mask].sum()) / total if total > 0 else 0.0), float(mask.mean())


def run(config: str, variant: str, cycles: int) -> dict:
    """Optimise and fly one variant; the row of the table."""
    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.commands._fly_optimise import flyable_bounds
    from fdm_awe.ocp.problem import CycleProblem
    from fdm_awe.ocp.solve import solve_cycle
    from fdm_awe.sim.flight import fly
    from fdm_awe.trajectory import reference_from_result

    extra = dict(VARIANTS[variant])
    v_min = extra.pop("V_min", None)
    bounds = flyable_bounds(None, extra, v_min)
    pr = CycleProblem(scenario="physical", config=config, wind_speed=WIND_MPS, bounds=bounds).validate()
    row: dict = {"config": config, "variant": variant, "bounds": VARIANTS[variant]}
    t0 = time.perf_counter()
    res = solve_cycle(pr)
    row["optimise_s"] = round(time.perf_counter() - t0, 1)
    row["optimiser"] = res.status
    if not res.ok:
        return row
    row["P_opt_W"] = res.P_avg_W
    ref = TrackingReference.from_ocp(reference_from_result(res, f"{config} {variant}"))
    rep = fly(ref, config=config, cycles=cycles)
    row["flight"] = rep.status
    e = [c.E_net_J for c in rep.cycles]
    row["E_net_J_cycles"] = [round(x, 1) for x in e]
    row["E_net_J"] = float(np.mean(e[1:])) if len(e) > 1 else (e[0] if e else None)
    row["E_opt_J"] = res.P_avg_W * (res.T1_s + res.T2_s)
    a = rep.control_activity
    row["activity"] = {k: round(v, 4) for k, v in a.as_dict().items()}
    err = np.asarray(rep.track_error, float)
    row["track_rms_m"] = float(np.sqrt(np.nanmean(err * err)))
    res6 = rep.result
    share, time_share = switch_share(res6.controls[: res6.steps, :3], list(res6.phase[: res6.steps]), res6.dt)
    row["switch_energy_share"], row["switch_time_share"] = round(share, 3), round(time_share, 3)
    return row


def markdown(rows: list[dict]) -> str:
    def f(v, fmt="{:.3f}"):
        return "-" if v is None else fmt.format(v)

    out = ["| config | variant | P_opt W | flown J/cycle | activity (ail/elev/rud) | tracking RMS m | "
           "activity at the switches (time) |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        a = r.get("activity")
        act = "-" if a is None else (f"{a['total_rms']:.3f} ({a['aileron_rms']:.3f}/{a['elevator_rms']:.3f}/"
                                     f"{a['rudder_rms']:.3f})")
        out.append(f"| {r['config']} | {r['variant']} | {f(r.get('P_opt_W'), '{:+.2f}')} | "
                   f"{f(r.get('E_net_J'), '{:+.0f}')} | {act} | {f(r.get('track_rms_m'), '{:.2f}')} | "
                   f"{f(r.get('switch_energy_share'), '{:.0%}')} ({f(r.get('switch_time_share'), '{:.0%}')}) |")
    return "\n".join(out) + "\n"


def main(argv: list[str] | None = None) -> int:
    from fdm_awe.fileio import atomic_write_text, write_json
    from study_args import add_configs, add_outputs, check_outputs, choice_list, configs

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_configs(ap)
    ap.add_argument("--variant", default=",".join(VARIANTS),
                    help=f"variants, comma list of {', '.join(VARIANTS)} (default all of them)")
    ap.add_argument("--cycles", type=int, default=3, help="cycles flown per run, 2..20 (default 3)")
    add_outputs(ap)
    args = ap.parse_args(argv)
    try:
        cfgs = configs(args)
        variants = choice_list(args.variant, "--variant", list(VARIANTS))
        if not 2 <= args.cycles <= 20:
            raise InputError(f"--cycles {args.cycles}: out of range (allowed 2..20)")
        check_outputs(args)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    rows = []
    for cfg in cfgs:
        for v in variants:
            r = run(cfg, v, args.cycles)
            rows.append(r)
            print(markdown([r]).splitlines()[-1], flush=True)
            if args.json:  # after every run: a long study keeps what it has
                write_json(Path(args.json), {"wind_mps": WIND_MPS, "cycles": args.cycles, "rows": rows})
    text = markdown(rows)
    print(text)
    if args.report:
        atomic_write_text(Path(args.report), text)
    failed = [(r["config"], r["variant"]) for r in rows if r.get("optimiser") != "ok" or r.get("flight") != "ok"]
    for c, v in failed:
        print(f"failed: {c} {v}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
