"""``fdm-awe optimize``: the optimal periodic pumping cycle (two-phase OCP, CasADi + IPOPT)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
import sys

HELP = "optimise one periodic pumping cycle (generation + recovery) and write the reference trajectory"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--scenario", choices=("physical", "paper"), default="physical",
                   help="model family (docs/design.md section 4; default: physical)")
    p.add_argument("--config", choices=("nominal", "foldable"), default="foldable",
                   help="nominal: unfolded throughout; foldable: folded for recovery (default)")
    p.add_argument("--wind", type=float, default=6.0, metavar="M_S", help="wind speed magnitude [m/s] (default 6)")
    p.add_argument("--wind-from", type=float, default=180.0, metavar="DEG",
                   help="direction the wind blows FROM [deg, compass] (default 180 = from the south)")
    p.add_argument("--d0", type=float, default=200.0, metavar="M", help="tether length at the cycle start [m]")
    p.add_argument("--d-tf", type=float, default=250.0, metavar="M", help="tether length at the end of generation [m]")
    p.add_argument("--v-min", type=float, default=5.0, metavar="M_S", help="minimum airspeed [m/s]")
    p.add_argument("--v-max", type=float, default=25.0, metavar="M_S", help="maximum airspeed [m/s]")
    p.add_argument("--h-min", type=float, default=10.0, metavar="M", help="ground clearance [m]")
    p.add_argument("--t-max", type=float, default=60.0, metavar="S", help="longest cycle T1 + T2 [s]")
    p.add_argument("--tether-drag-scale", type=float, default=1.0, metavar="F",
                   help="factor on the line drag, physical scenario (sensitivity study; default 1 = the defined line)")
    add_plant_model_args(p)
    p.add_argument("--mesh", default=None, metavar="NG,NR,DEG",
                   help="collocation intervals in generation, recovery and the Radau degree (default 60,20,4)")
    p.add_argument("--starts", type=int, default=1, metavar="N", help="successful starts to compare (default 1)")
    p.add_argument("--time-budget", type=float, default=180.0, metavar="S",
                   help="solver seconds before the optimisation is reported as failed (default 180)")
    p.add_argument("--verify", action="store_true", help="re-integrate the optimal controls and report the check")
    p.add_argument("--json", metavar="FILE", help="write the result summary as JSON")
    p.add_argument("--rrd", metavar="FILE", help="write a rerun recording of the optimised cycle")
    p.add_argument("--out", metavar="DIR", help="write recording, plots, CSV and a markdown report of the cycle into DIR")
    p.add_argument("--trajectory", metavar="FILE",
                   help="reference-trajectory file to write (default: next to --json as *.trajectory.json)")


def add_plant_model_args(p: argparse.ArgumentParser, prefix: str = "") -> None:
    """``--propeller`` and ``--line-weight``: how closely the optimiser models the 6-DOF plant
    (physical scenario; ``prefix`` opens the help texts, e.g. when the command optimises)."""
    from ..ocp.problem import PROPELLERS  # plain dataclasses: no CasADi import

    p.add_argument("--propeller", choices=PROPELLERS, default=None,
                   help=prefix + "propeller model of the physical scenario: momentum theory + efficiencies (default) "
                        "or engine, the 6-DOF glider's own motor and 9x5 propeller (what a flight draws)")
    p.add_argument("--line-weight", action="store_true",
                   help=prefix + "physical scenario: the glider carries its share of the line's weight, as the "
                        "6-DOF plant's ground station applies it")


def problem_from_args(args: argparse.Namespace):
    """Build and validate the :class:`CycleProblem` from command-line arguments."""
    from ..errors import InputError
    from ..ocp.problem import Bounds, CycleProblem, Mesh

    mesh = Mesh()
    if args.mesh:
        try:
            ng, nr, deg = (int(v) for v in args.mesh.split(","))
        except ValueError:
            raise InputError(f"--mesh {args.mesh!r} invalid (expected NG,NR,DEG, e.g. 30,16,4)") from None
        mesh = Mesh(ng, nr, deg)
    bounds = Bounds(V_min=args.v_min, V_max=args.v_max, h_min=args.h_min, t_max=args.t_max)
    return CycleProblem(scenario=args.scenario, config=args.config, wind_speed=args.wind, wind_from_deg=args.wind_from,
                        d0=args.d0, d_tf=args.d_tf, bounds=bounds, mesh=mesh,
                        tether_drag_scale=getattr(args, "tether_drag_scale", 1.0),
                        propeller=getattr(args, "propeller", None),
                        line_weight=bool(getattr(args, "line_weight", False))).validate()


def print_summary(res, file=sys.stdout) -> None:
    s = res.summary()
    head = f"{res.scenario} / {res.config} / wind {res.wind_mps:g} m/s from {res.wind_from_deg:g} deg"
    if not res.ok:
        print(f"{head}: FAILED ({res.reason}) after {res.iterations} iterations, {res.solve_s:.2f} s", file=file)
        return
    print(f"{head}: ok in {res.solve_s:.2f} s ({res.iterations} IPOPT iterations, build {res.build_s:.2f} s)", file=file)
    print(f"  generation T1 = {s['T1_s']:.2f} s, recovery T2 = {s['T2_s']:.2f} s", file=file)
    print(f"  E_generated {s['E_generated_J']:9.1f} J   E_thrust {s['E_thrust_J']:9.1f} J   "
          f"E_reel_in {s['E_reel_in_J']:9.1f} J", file=file)
    print(f"  E_net       {s['E_net_J']:9.1f} J   P_avg {s['P_avg_W']:8.2f} W "
          f"({'net gain' if s['E_net_J'] > 0 else 'net loss'})", file=file)


def run(args: argparse.Namespace) -> int:
    problem = problem_from_args(args)
    from ..ocp.result import write_reference
    from ..ocp.solve import get_nlp, solve_cycle

    print(f"optimising {problem.scenario}/{problem.config} at {problem.wind_speed:g} m/s ...", file=sys.stderr, flush=True)
    res = solve_cycle(problem, n_starts=max(1, args.starts), time_budget_s=args.time_budget)
    for f in (args.json, args.trajectory, args.rrd):
        if f:
            Path(f).parent.mkdir(parents=True, exist_ok=True)
    traj = args.trajectory
    if traj is None and args.json:
        traj = args.json[:-5] + ".trajectory.json" if args.json.endswith(".json") else args.json + ".trajectory.json"
    if res.ok and traj:
        write_reference(res, traj)
    print_summary(res)
    out = res.summary()
    if res.ok and args.verify:
        from ..ocp.verify import verify

        v = verify(res, get_nlp(problem)[0])
        print(f"  check: interval defects sum to {100 * v.position_error_rel:.3f} % of the {v.path_length_m:.0f} m path; "
              f"energies re-integrated: " + ", ".join(f"{k} {100 * e:.2f} %" for k, e in v.energy_error_rel.items())
              + f"; max scaled constraint violation {v.nlp_max_violation:.1e}")
        out["verification"] = {k: (float(x) if not isinstance(x, (dict, str)) else x) for k, x in v.as_dict().items()}
    if res.ok and traj:
        print(f"  reference trajectory: {traj}")
    if res.ok and (args.rrd or args.out):
        from ..recording import cycle_outputs

        out.update(cycle_outputs(res, rrd=args.rrd, out_dir=args.out))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh, indent=2, default=float)
    return 0 if res.ok else 1
