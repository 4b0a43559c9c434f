"""``fdm-awe optimize``: the optimal periodic pumping cycle (two-phase OCP, CasADi + IPOPT).

Every option is checked and every output path probed before the optimisation starts (bad
input: one line, exit 2). Outputs are written atomically; ``--json`` writes NaN as ``null``.
Exit codes: 0 a cycle was found, 1 the optimiser found none, 2 bad input, 130 Ctrl-C.
"""

from __future__ import annotations

import argparse
import math
import sys
from typing import Any

from .. import defaults as D
from ._aircraft import add_aircraft_arg, aircraft_from_args
from ._bound_options import add_margin_args, add_smoothness_args, margin_bounds, smoothness_bounds
from ._model_options import add_plant_model_args, add_wind_profile_args, check_plant_args, wind_profile_from_args
from ._station import add_station_arg, station_from_args

HELP = "optimise one periodic pumping cycle (generation + recovery) and write the reference trajectory"

#: Why the default configuration is ``nominal`` (help texts of ``optimize`` and ``fly``).
NOMINAL_DEFAULT_WHY = D.NOMINAL_WHY


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--scenario", choices=("physical", "paper"), default=D.SCENARIO,
                   help=f"model family (docs/design.md section 4; default {D.SCENARIO})")
    p.add_argument("--config", choices=("nominal", "foldable"), default=D.CONFIG,
                   help="nominal: unfolded throughout; foldable: folded for recovery; " + NOMINAL_DEFAULT_WHY)
    add_aircraft_arg(p, "the glider optimised (the reference records it)")
    add_station_arg(p, "the ground station optimised with (its drive and line; the reference records it)")
    p.add_argument("--wind", type=float, default=D.WIND_MPS, metavar="M_S",
                   help=f"wind speed magnitude [m/s], 0..25 (default {D.WIND_MPS:g})")
    p.add_argument("--wind-from", type=float, default=D.WIND_FROM_DEG, metavar="DEG",
                   help=f"direction the wind blows FROM [deg, compass], -360..360 (default {D.WIND_FROM_DEG:g} = from "
                        "the south)")
    p.add_argument("--d0", type=float, default=D.D0_M, metavar="M",
                   help=f"tether length at the cycle start [m], > 0 (default {D.D0_M:g})")
    p.add_argument("--d-tf", type=float, default=D.D_TF_M, metavar="M",
                   help=f"tether length at the end of generation [m], > d0 (default {D.D_TF_M:g})")
    p.add_argument("--v-min", type=float, default=D.V_MIN_MPS, metavar="M_S",
                   help=f"minimum airspeed [m/s], > 0 (default {D.V_MIN_MPS:g})")
    p.add_argument("--v-max", type=float, default=D.V_MAX_MPS, metavar="M_S",
                   help=f"maximum airspeed [m/s], > v-min (default {D.V_MAX_MPS:g})")
    p.add_argument("--h-min", type=float, default=D.H_MIN_M, metavar="M",
                   help=f"ground clearance [m], >= 0 (default {D.H_MIN_M:g})")
    p.add_argument("--t-max", type=float, default=D.T_MAX_S, metavar="S",
                   help=f"longest cycle T1 + T2 [s], > 0 (default {D.T_MAX_S:g})")
    p.add_argument("--flyable", action="store_true",
                   help=f"keep the flyable margins of a reference to be flown (C_L <= {D.FLYABLE_CL_MARGIN:g} C_Lmax, "
                        f"tension <= rating / {1 + D.FLYABLE_TENSION_MARGIN:g}, |bank| <= {D.FLYABLE_PHI_MAX:g} rad; "
                        "--stall-margin / --tension-margin replace the first two), the bounds with which 'fdm-awe fly' optimises its own "
                        "reference (default: Table 3's bounds, the optimiser's own optimum)")
    p.add_argument("--tether-drag-scale", type=float, default=D.TETHER_DRAG_SCALE, metavar="F",
                   help=f"factor on the line drag, physical scenario, 0..10 (sensitivity study; default "
                        f"{D.TETHER_DRAG_SCALE:g} = the defined line)")
    p.add_argument("--reel-in-speed-max", type=float, default=None, metavar="M_S",
                   help=f"fastest reel-in [m/s], 0..{REEL_IN_LIMIT:g} (default: what the winch's drive reaches at full "
                        "duty with a slack line, from the ground-station definition's supply voltage; 'fdm-awe info' "
                        "shows it)")
    p.add_argument("--supply-voltage", type=float, default=None, metavar="V",
                   help="physical scenario: the winch's supply voltage [V], 6..200 (default: the ground-station "
                        "definition's 48 V): a design variable of the drive, it sets the full-duty reel-in speed; "
                        "the optimiser's only (a flight flies the definition's drive)")
    p.add_argument("--fold-time", type=float, default=None, metavar="S",
                   help="foldable configuration: the wing's full fold (and unfold) travel at the start (end) of "
                        "recovery [s], 0 (an instantaneous switch) .. 60 (default: the aircraft definition's "
                        "fcs/wing-fold-time-s)")
    add_plant_model_args(p)
    p.add_argument("--recovery-tension", choices=("free", "slack"), default=None,
                   help="the line's tension in recovery (physical scenario): free, a control >= 0 the winch's motor "
                        "holds while it reels in (the drive's supply power and full-duty speed; the line taut "
                        "wherever it pulls), so the optimum chooses between a taut reel-in and a slack glide-back "
                        "(the default), or slack, fixed at zero (the earlier published numbers; always slack in "
                        "the paper scenario)")
    add_wind_profile_args(p)
    add_smoothness_args(p)
    add_margin_args(p)
    p.add_argument("--mesh", default=None, metavar="NG,NR,DEG",
                   help="collocation intervals in generation, recovery and the Radau degree (default 60,20,4)")
    p.add_argument("--starts", type=int, default=1, metavar="N", help=f"successful starts to compare, 1..{MAX_STARTS} (default 1), on meshes solved "
                        "without the global strategy (coarse --mesh); at the default mesh the global strategy "
                        "solves every start and keeps the best, and this option has no effect there")
    p.add_argument("--time-budget", type=float, default=180.0, metavar="S",
                   help=f"solver seconds before the optimisation is reported as failed, > 0 and <= {MAX_TIME_BUDGET_S:g} "
                        "(default 180)")
    p.add_argument("--verify", action="store_true", help="re-integrate the optimal controls and report the check")
    p.add_argument("--json", metavar="FILE", help="write the result summary as JSON (NaN written as null)")
    p.add_argument("--rrd", metavar="FILE", help="write a rerun recording of the optimised cycle")
    p.add_argument("--out", metavar="DIR", help="write recording, plots, CSV and a markdown report of the cycle into DIR")
    p.add_argument("--trajectory", metavar="FILE",
                   help="reference-trajectory file to write (default: next to --json as *.trajectory.json)")


#: ``--starts`` upper limit (the optimiser has a few distinct starts; more are never tried)
MAX_STARTS = 100
#: ``--time-budget`` upper limit [s] (one day)
MAX_TIME_BUDGET_S = 86400.0


def parse_mesh(text: str | None, option: str = "--mesh", two: bool = False):
    """The :class:`~fdm_awe.ocp.problem.Mesh` of ``NG,NR,DEG`` (or ``NG,NR`` when ``two``; None:
    the default mesh), validated; errors name ``option``."""
    from ..errors import InputError
    from ..ocp.problem import Mesh

    if text is None:
        return Mesh()
    form = "NGEN,NREC[,DEGREE] integers" if two else "NG,NR,DEG integers, e.g. 30,16,4"
    try:
        m = [int(v) for v in text.split(",")]
        if len(m) not in ((2, 3) if two else (3,)):
            raise ValueError
    except ValueError:
        raise InputError(f"{option} {text!r} invalid (allowed {form})") from None
    mesh = Mesh(n_gen=m[0], n_rec=m[1], **({"degree": m[2]} if len(m) == 3 else {}))
    try:
        mesh.validate()
    except InputError as exc:
        raise InputError(f"{option} {text!r}: {exc}") from None
    return mesh


def check_solver_args(args: argparse.Namespace) -> None:
    """``--starts``, ``--time-budget``, ``--wind``, ``--wind-from`` and ``--tether-drag-scale``
    of a command that optimises (optimize, compare)."""
    from ..groundstation.tether import TETHER_DRAG_SCALE_MAX
    from . import _checks as chk

    chk.integer(args.starts, "--starts", 1, MAX_STARTS, what="successful starts")
    chk.number(args.time_budget, "--time-budget", 0.0, MAX_TIME_BUDGET_S, lo_open=True, unit="s", what="solver time")
    chk.number(args.wind, "--wind", 0.0, 25.0, unit="m/s", what="wind speed")
    chk.number(args.wind_from, "--wind-from", -360.0, 360.0, unit="deg", what="wind direction")
    chk.number(args.tether_drag_scale, "--tether-drag-scale", 0.0, TETHER_DRAG_SCALE_MAX, what="line drag factor")


#: highest ``--v-max`` [m/s]: twice the paper's 25 m/s bound, past which the glider's polynomial
#: aerodynamics and the propeller's tables are not made for
V_MAX_LIMIT = 50.0
#: longest ``--t-max`` [s]: ten times the paper's 60 s cycle (the mesh's intervals stretch with it)
T_MAX_LIMIT = 600.0
#: fastest ``--reel-in-speed-max`` [m/s]
REEL_IN_LIMIT = 50.0


def problem_from_args(args: argparse.Namespace):
    """Build and validate the :class:`CycleProblem` from command-line arguments."""
    from ..ocp.problem import Bounds, CycleProblem
    from . import _checks as chk

    aircraft = aircraft_from_args(args)  # its files checked first (a missing file names --aircraft)
    station = station_from_args(args)  # so is the ground station's (a bad file names --ground-station)
    check_solver_args(args)
    check_plant_args(args)
    drum = station.load().tether.max_length  # the drum's capacity [m]
    chk.number(args.d0, "--d0", 0.0, drum, lo_open=True, hi_open=True, unit="m (below the drum's capacity)",
               what="tether length at the cycle start")
    chk.number(args.d_tf, "--d-tf", args.d0, drum, lo_open=True, unit="m (above --d0, up to the drum's capacity)",
               what="tether length at the end of generation")
    chk.number(args.v_min, "--v-min", 0.0, None, lo_open=True, unit="m/s", what="minimum airspeed")
    chk.number(args.v_max, "--v-max", args.v_min, V_MAX_LIMIT, lo_open=True, unit="m/s (above --v-min)",
               what="maximum airspeed")
    h0 = args.d0 * math.sin(math.radians(CycleProblem.elevation0_deg))
    chk.number(args.h_min, "--h-min", 0.0, h0, unit="m (below the start altitude --d0 x sin(elevation))",
               what="ground clearance")
    chk.number(args.t_max, "--t-max", 0.0, T_MAX_LIMIT, lo_open=True, unit="s", what="longest cycle")
    reel_in = getattr(args, "reel_in_speed_max", None)
    if reel_in is not None:
        chk.number(reel_in, "--reel-in-speed-max", 0.0, REEL_IN_LIMIT, lo_open=True, unit="m/s", what="fastest reel-in")
    fold_time = getattr(args, "fold_time", None)
    if fold_time is not None:
        from ..definitions.aircraft import FOLD_TIME_MAX_S

        chk.number(fold_time, "--fold-time", 0.0, FOLD_TIME_MAX_S, unit="s", what="fold travel")
    volts = getattr(args, "supply_voltage", None)
    if volts is not None:
        from ..errors import InputError
        from ..groundstation.variants import SUPPLY_VOLTAGE_RANGE

        chk.number(volts, "--supply-voltage", *SUPPLY_VOLTAGE_RANGE, unit="V", what="winch supply")
        if args.scenario != "physical":
            raise InputError("--supply-voltage: only the physical scenario has the winch's drive (the paper scenario's "
                             "reel-in power is a constant)")
    mesh = parse_mesh(args.mesh)
    flyable = getattr(args, "flyable", False)
    margins = margin_bounds(args, tension_default=D.FLYABLE_TENSION_MARGIN if flyable else 0.0,
                            stall_default=D.FLYABLE_STALL_MARGIN if flyable else 0.0)
    if flyable:
        margins["phi_max"] = D.FLYABLE_PHI_MAX
    if reel_in is not None:  # the explicit bound and the margin's: the tighter one
        margins["reel_in_speed_max"] = min(reel_in, margins.get("reel_in_speed_max", reel_in))
    bounds = Bounds(V_min=args.v_min, V_max=args.v_max, h_min=args.h_min, t_max=args.t_max, **smoothness_bounds(args),
                    **margins)
    return CycleProblem(scenario=args.scenario, config=args.config, wind_speed=args.wind, wind_from_deg=args.wind_from,
                        d0=args.d0, d_tf=args.d_tf, bounds=bounds, mesh=mesh,
                        tether_drag_scale=getattr(args, "tether_drag_scale", 1.0),
                        propeller=getattr(args, "propeller", None), line_weight=getattr(args, "line_weight", None),
                        line=getattr(args, "line", None), generator=getattr(args, "generator", None),
                        fold_time=fold_time, recovery_tension=getattr(args, "recovery_tension", None),
                        supply_voltage=volts,
                        wind_profile=wind_profile_from_args(args),
                        line_model=getattr(args, "line_model", None) or "straight", aircraft=aircraft,
                        ground_station=station).validate()


def print_summary(res, file=None) -> None:
    """The report of result ``res`` on ``file`` (None: the standard output at the call)."""
    file = file if file is not None else sys.stdout
    s = res.summary()
    head = f"{res.scenario} / {res.config} / wind {res.wind_mps:g} m/s from {res.wind_from_deg:g} deg"
    if res.problem is not None and not res.problem.wind_profile.uniform:
        head += f" at {res.problem.wind_profile.ref_height:g} m ({res.problem.wind_profile.label()})"
    if res.problem is not None:
        head += f" / {plant_text(res.problem)}"
        if res.problem.aircraft is not None and not res.problem.aircraft.builtin:
            head += f" / aircraft {res.problem.aircraft.label()}"
        if res.problem.ground_station is not None and not res.problem.ground_station.builtin:
            head += f" / ground station {res.problem.ground_station.label()}"
    if not res.ok:
        print(f"{head}: FAILED ({res.reason}) after {res.iterations} iterations, {res.solve_s:.2f} s", file=file)
        return
    print(f"{head}: ok in {res.solve_s:.2f} s ({res.iterations} IPOPT iterations, build {res.build_s:.2f} s)", file=file)
    print(f"  generation T1 = {s['T1_s']:.2f} s, recovery T2 = {s['T2_s']:.2f} s", file=file)
    print(f"  E_generated {s['E_generated_J']:9.1f} J   E_thrust {s['E_thrust_J']:9.1f} J   "
          f"E_reel_in {s['E_reel_in_J']:9.1f} J", file=file)
    print(f"  E_net       {s['E_net_J']:9.1f} J   P_avg {s['P_avg_W']:8.2f} W "
          f"({'net gain' if s['E_net_J'] > 0 else 'net loss'})", file=file)
    b = res.problem.bounds if res.problem is not None else None
    if b is not None and (b.tension_margin or b.cl_margin < 1.0 or b.reel_in_speed_max is not None):
        from ..trajectory.files import margins_record, margins_text

        print(f"  margins: {margins_text({'margins': margins_record(b)})}", file=file)
    from ..ocp.strategy import optima_lines

    for line in optima_lines(getattr(res, "strategy", None)):
        print(line, file=file)
    if res.active_bounds:
        from ..ocp.active import format_active
        print(f"  binding bounds ({len(res.active_bounds)}, strongest first):", file=file)
        for line in format_active(res.active_bounds):
            print(line, file=file)


def plant_text(problem) -> str:
    """The plant model of ``problem`` in a few words: line, propeller, line weight."""
    if problem.scenario != "physical":
        return f"line {problem.line}"
    return (f"line {problem.line}" + ("" if problem.line_model == "straight" else f" ({problem.line_model} model)")
            + f", propeller {problem.propeller}, "
            f"line weight {'on' if problem.line_weight else 'off'}, generator {problem.generator}")


def trajectory_path(args: argparse.Namespace) -> str | None:
    """``--trajectory``, else next to ``--json`` as ``*.trajectory.json``, else None."""
    if args.trajectory is not None or not args.json:
        return args.trajectory
    return args.json[:-5] + ".trajectory.json" if args.json.endswith(".json") else args.json + ".trajectory.json"


def run(args: argparse.Namespace) -> int:
    from . import _checks as chk

    problem = problem_from_args(args)
    traj = trajectory_path(args)
    from ..recording.outputs import output_files

    # the names --out gives its files (cycle.rrd too) are its own, even when --rrd takes the recording elsewhere
    locks = chk.outputs(files=[("--json", args.json), ("--trajectory", traj), ("--rrd", args.rrd)],
                        dirs=[("--out", args.out)],
                        dir_files=[("--out", p) for p in output_files(args.out, "cycle").values()] if args.out else [])
    with locks:  # --out locked until the last file is written
        return _run_checked(args, problem, traj)


def _run_checked(args: argparse.Namespace, problem: Any, traj: str | None) -> int:
    """The work of :func:`run` once every option and output is checked: optimise, print, write
    the outputs; returns the exit code."""
    from ..fileio import write_json
    from ..trajectory import write_reference
    from ..ocp import build, solve

    print(f"optimising {problem.scenario}/{problem.config} at {problem.wind_speed:g} m/s ...", file=sys.stderr, flush=True)
    res = solve.solve_cycle(problem, n_starts=args.starts, time_budget_s=args.time_budget)
    if res.ok and traj:
        write_reference(res, traj)  # atomic (temporary name, then renamed)
    print_summary(res)
    out = res.summary()
    if res.ok and args.verify:
        from ..ocp.verify import verify

        v = verify(res, build.get_nlp(problem)[0])
        print(f"  check: interval defects sum to {100 * v.position_error_rel:.3f} % of the {v.path_length_m:.0f} m path; "
              f"energies re-integrated: " + ", ".join(f"{k} {100 * e:.2f} %" for k, e in v.energy_error_rel.items())
              + f"; max scaled constraint violation {v.nlp_max_violation:.1e}")
        out["verification"] = v.as_dict()
    if res.ok and traj:
        print(f"  reference trajectory: {traj}")
    if res.ok and (args.rrd or args.out):
        from ..recording import cycle_outputs

        out.update(cycle_outputs(res, rrd=args.rrd, out_dir=args.out))
    if args.json:
        write_json(args.json, out)
    written = ([traj] if res.ok and traj else []) + [str(x) for k in ("rrd", "plots", "csv", "report") if k in out
                                                     for x in (out[k] if isinstance(out[k], list) else [out[k]])]
    written += [args.json] if args.json else []
    if written:
        print("wrote: " + ", ".join(written))
    return 0 if res.ok else 1
