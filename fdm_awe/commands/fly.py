"""``fdm-awe fly``: fly N pumping cycles of an optimised reference in 6-DOF co-simulation.

The reference comes from ``--reference FILE`` (written by ``fdm-awe optimize``) or is optimised
first from ``--scenario/--config/--wind``. Prints a per-cycle energy table, writes JSON per
docs/design.md section 1 (``--json``), a rerun recording (``--rrd``), and optionally speaks MAVLink
(``--mavlink URL``) paced at real time (``--realtime [FACTOR]``).

Without ``--reference`` the reference is optimised (default: physical scenario, nominal
glider, 8 m/s) and handed to the flight in memory; its file is written only with ``--out``
(``DIR/reference_<scenario>_<config>_<wind>.json``): the command writes nothing else. The
JSON's ``reference`` names the file flown or written, ``null`` for a reference flown from
memory.

The plant follows the scenario (``--scenario``; with ``--reference`` and no ``--scenario``, the
reference file's scenario): ``physical`` flies the JSBSim propeller and the ground station,
``paper`` the ideal thruster and kinematic winch of :mod:`fdm_awe.sim.paper_plant` (the paper
scenario's simplifications). The JSON says which plant flew (``plant``, ``plant_note``).

A reference fixes what it was optimised for: with ``--reference``, the options that only shape
an optimisation (``--wind``, ``--wind-from``, ``--gamma-max``, ``--line``, ``--propeller``,
``--line-weight``/``--no-line-weight``) are refused (the flight flies the line the reference names), and a ``--config``/``--scenario`` other than the reference's
is refused unless ``--allow-mismatch`` is given (then a warning is printed).

Checks before any work (one line, exit 2): every number in range, the turbulence form and
seed (1..2**31-1), the MAVLink URL (form, port, an IPv4 host; a listening address bound for a
moment; a ``tcp`` client's connection tried once, within 3 s, and kept for the flight), the
input files (``--reference``, ``--mavlink-key``: regular files; ``--params``: a regular file or
a new name in an existing folder), the reference file (field by field, its units, one periodic
and continuous cycle), ``--tether lumped:N`` only on the physical plant, every output path
(writable, a regular file or a new name, not an input such as ``--reference``,
``--mavlink-key`` or ``--params``); ``--out`` is locked for the run. Outputs are written
atomically; the JSON writes NaN as ``null`` (e.g. the tracking error of a cycle without
reference points) and records the turbulence (``null`` in calm air): its form and seed, the
JSBSim parameters, the target sigma and intensity at the hub height and the turbulence
measured at the glider (:mod:`fdm_awe.turbulence`); the step against the attitude loops and the
flight's steps against the memory it keeps (:mod:`fdm_awe.sim.budget`).

Exit codes (:func:`fdm_awe.sim.report.flight_exit_code`): 0 the flight flew every requested
cycle, or a commanded RECOVER (``--mode``, a MAVLink mode change or RTL) ended it landed or
parked; 1 it ended otherwise (an event, cycles left incomplete, or landed or parked after a
failsafe took it out of its cycles); 2 bad input; 130 Ctrl-C: the flight stops,
the steps flown so far are written to every requested output (status ``interrupted``).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path
from typing import Any, Callable

from .. import defaults as D
from ..errors import EXIT_INTERRUPTED, InputError
from ..fileio import write_json
from ._aircraft import add_aircraft_arg, aircraft_from_args
from ._station import add_station_arg, check_reference_definitions, station_from_args
from . import _checks as chk
from .optimize import (NOMINAL_DEFAULT_WHY, add_margin_args, add_plant_model_args, add_smoothness_args,
                       add_wind_profile_args, check_plant_args, margin_bounds, smoothness_bounds, wind_profile_from_args)

# The modules of the work (the optimiser, JSBSim, numba, the recordings, MAVLink) are imported in
# the functions that use them: the command line imports every command module at its start.

HELP = "fly the optimised pumping cycle in 6-DOF (JSBSim + ground station + autopilot)"

#: effective defaults of the options that shape the optimised reference (None on the command
#: line means "not given", so that ``--reference`` can refuse them)
DEFAULT_WIND_MPS = D.WIND_MPS
DEFAULT_WIND_FROM_DEG = D.WIND_FROM_DEG
DEFAULT_CONFIG = D.CONFIG
DEFAULT_SCENARIO = D.SCENARIO

#: the options a reference fixes (only used when optimising): attribute -> option
REFERENCE_FIXED = {"wind": "--wind", "wind_from": "--wind-from", "gamma_max": "--gamma-max",
                   "line": "--line", "line_model": "--line-model", "propeller": "--propeller", "line_weight": "--line-weight",
                   "generator": "--generator", "wind_profile": "--wind-profile",
                   "wind_ref_height": "--wind-ref-height", "v_min": "--v-min", "bank_rate_max": "--bank-rate-max",
                   "alpha_rate_max": "--alpha-rate-max", "catch_speed_max": "--catch-speed-max",
                   "tension_margin": "--tension-margin", "stall_margin": "--stall-margin",
                   "reel_in_margin": "--reel-in-margin"}


#: the margins of a reference that ``fly`` optimises (``--tension-margin``, ``--stall-margin``):
#: the stall margin keeps C_L at most 85 % of each wing's C_Lmax (the flyable margin the stored
#: references were made with). The tension margin keeps the cycle's tension at most the 50 N
#: rating / 1.25 = 40 N: the flown peaks of the stored sized-line cycles at 8-12 m/s, made with
#: the whole rating, came to 1.15-1.32 x the optimum's peak in calm air (the catch at the start
#: of generation) and up to 1.5 x in light turbulence (nominal 12 m/s: 74.7 N on a 50 N optimum),
#: so 40 N keeps the flown peak at about 1.2 x the rating (60 N) in calm and light air
FLY_TENSION_MARGIN = D.FLYABLE_TENSION_MARGIN
FLY_STALL_MARGIN = D.FLYABLE_STALL_MARGIN
#: the reel-in margin (``--reel-in-margin``): off by default. The flown winch still pays out
#: when the reference's recovery starts (it follows the glider, not the reference's instant
#: reversal); a reference that reels in at the drive's limit (5.36 m/s) leaves it no speed to
#: catch up: the nominal 12 m/s cycle's line ended each recovery 6, 10 and 15 m longer than
#: planned, and on the lumped line the drift cost 200-450 J of thrust a cycle, which a margin of
#: 0.1 (4.87 m/s) removes (docs/design.md section 10). But the foldable glider's folded recovery
#: needs the fast reel-in: at 8 m/s a margin of 0.1 costs it 1400 J a cycle (-4440 J against
#: -3090 J flown), so it is an option (scripts/line_calibration.py sets 0.1), not a default
FLY_REEL_IN_MARGIN = 0.0


def flyable_bounds(gamma_max: float | None = None, smoothness: dict[str, float] | None = None,
                   v_min: float | None = None, margins: dict[str, float] | None = None):
    """The bounds of a reference that ``fly`` optimises to fly it (below), as a
    :class:`~fdm_awe.ocp.problem.Bounds`."""
    from ..ocp.problem import Bounds

    # A reference to be flown keeps margins the optimiser's own optimum does not: C_L at most
    # 85 % of each wing's C_Lmax (``margins``: --stall-margin, default FLY_STALL_MARGIN), the
    # tension at most the rating / (1 + --tension-margin, default FLY_TENSION_MARGIN) and the bank
    # 0.2 rad inside the Table-3 limit, leaving the autopilot room to correct. ``gamma_max`` [rad]
    # (--gamma-max) bounds the flight-path angle below Table 3's 1 rad: the paper nominal cycle at
    # 3 m/s dives at -1 rad and climbs at +1 rad within its 9.8 s recovery, which the 6-DOF glider
    # does not follow (it stalls in the climb); with 0.7 rad it is flown within 2 m RMS.
    # ``smoothness``: the reference's rate and catch bounds given (--bank-rate-max,
    # --alpha-rate-max, --catch-speed-max; none by default); ``v_min`` [m/s] (--v-min): the
    # airspeed bound, Table 3's 5 m/s when None; ``margins``: Bounds fields ``tension_margin`` and
    # ``cl_margin`` (:func:`fdm_awe.commands.optimize.margin_bounds`; None: fly's defaults).
    if margins is None:
        margins = {"tension_margin": FLY_TENSION_MARGIN, "cl_margin": 1.0 - FLY_STALL_MARGIN}
        if FLY_REEL_IN_MARGIN > 0.0:
            from .optimize import drive_reel_in_speed

            margins["reel_in_speed_max"] = drive_reel_in_speed() / (1.0 + FLY_REEL_IN_MARGIN)
    m = dict(margins)
    return Bounds(phi_max=D.FLYABLE_PHI_MAX, **m, **({} if gamma_max is None else {"gamma_max": gamma_max}),
                  **({} if v_min is None else {"V_min": v_min}), **(smoothness or {}))


def add_arguments(p: argparse.ArgumentParser) -> None:
    from ..example_refs import EXAMPLES

    p.add_argument("--reference", metavar="FILE", help="reference trajectory from 'fdm-awe optimize', or example:NAME, a "
                                                       f"stored reference of the package ({', '.join(EXAMPLES)}) "
                                                       "(default: optimise one now and fly it from memory; its file is "
                                                       "written only into --out)")
    p.add_argument("--references", metavar="DIR",
                   help="a reference set: a folder of reference files, each optimised for one wind (its metadata's "
                        "wind_mps; e.g. scripts/reference_set.py); at every cycle boundary the autopilot flies the "
                        "next cycle on the reference nearest its onboard wind estimate. --wind, --wind-from, "
                        "--wind-profile, --wind-ref-height then give the wind the flight meets (default: the first "
                        "reference's own); not with --reference")
    p.add_argument("--start-wind", type=float, default=None, metavar="M/S",
                   help="with --references: the first cycle flies the set's reference nearest this wind, 0..25 "
                        "(default: nearest --wind, else the set's lowest wind)")
    p.add_argument("--scenario", choices=("physical", "paper"), default=None,
                   help="scenario of the reference to optimise and of the plant that flies it: physical (JSBSim propeller + "
                        f"ground station) or paper (ideal thruster + kinematic winch); default {D.SCENARIO}, or the "
                        "--reference file's")
    p.add_argument("--config", choices=("foldable", "nominal"), default=None,
                   help=f"foldable folds for recovery, nominal never folds; default the --reference file's, else {D.CONFIG} ("
                        + NOMINAL_DEFAULT_WHY + ")")
    add_aircraft_arg(p, "the glider flown (and optimised, when fly optimises the reference; a --reference optimised for another aircraft is flown with a warning)")
    add_station_arg(p, "the ground station flown (and optimised with; a --reference optimised with another is flown with a warning)")
    p.add_argument("--allow-mismatch", action="store_true",
                   help="fly a --reference with a --config/--scenario other than the one it was optimised for (a warning "
                        "is printed; without this option the mismatch is refused)")
    p.add_argument("--wind", type=float, default=None, metavar="M/S",
                   help=f"wind speed for the optimised reference, 0..25 (default {DEFAULT_WIND_MPS:g}; not with --reference)")
    p.add_argument("--wind-from", type=float, default=None, metavar="DEG",
                   help=f"wind direction, blowing from, -360..360 (default {DEFAULT_WIND_FROM_DEG:g} = south; "
                        "not with --reference)")
    p.add_argument("--tether-drag-scale", type=float, default=None, metavar="F",
                   help="factor on the line drag of the ground station (and of the optimiser when it optimises the "
                        f"reference), 0..10; default: the --reference file's tether_drag_scale, else "
                        f"{D.TETHER_DRAG_SCALE:g} = the defined line")
    from ..groundstation.linemodels import LINE_MODELS

    p.add_argument("--tether", default=D.TETHER, metavar="MODEL",
                   help=f"line model of the ground station (default {D.TETHER}): "
                        + "; ".join(f"{k.forms}: {k.doc}" for k in LINE_MODELS))
    from ..trajectory.schema import FLYABLE_GENERATORS

    add_plant_model_args(p, prefix="when it optimises the reference (not with --reference): ",
                         generators=FLYABLE_GENERATORS)
    add_wind_profile_args(p, prefix="when it optimises the reference (not with --reference; a reference flies its own "
                                    "profile, JSBSim's wind set every step from the glider's altitude): ")
    p.add_argument("--v-min", type=float, default=None, metavar="M_S",
                   help=f"minimum airspeed of the optimised reference, 1..20 m/s (default {D.V_MIN_MPS:g}, Table 3's; not with "
                        "--reference): a margin above the open wing's stall speed")
    add_smoothness_args(p, prefix="when it optimises the reference (not with --reference): ")
    add_margin_args(p, prefix="when it optimises the reference (not with --reference; a reference's own are shown): ",
                    tension_default=FLY_TENSION_MARGIN, stall_default=FLY_STALL_MARGIN,
                    reel_in_default=FLY_REEL_IN_MARGIN, why=", fly's flyable margins")
    p.add_argument("--gamma-max", type=float, default=None, metavar="RAD",
                   help="flight-path angle bound of the optimised reference, 0.1..1.5 (default 1 rad, Table 3's); 0.7 "
                        "makes the paper nominal 3 m/s cycle flyable (not with --reference)")
    p.add_argument("--cycles", type=int, default=D.CYCLES,
                   help=f"number of pumping cycles, 1..1000 (default {D.CYCLES}), and at most 750000 steps in the flight's time "
                        "cap (2 x cycles x period + 10 s) / --dt: a flight keeps every step in memory, about 2 kB each "
                        "(about 51 cycles of a 60 s cycle at the default step)")
    p.add_argument("--dt", type=float, default=D.DT_S,
                   help="co-simulation step, s (default 1/120), 0.0001..0.25 / max(W_ALPHA, W_PHI): the attitude loops "
                        "fly with one update a step; 0.0001..0.0125 with the defined gains (W_PHI 20 rad/s)")
    p.add_argument("--turbulence", metavar="FORM[:SEED]",
                   help="JSBSim turbulence, seeded (SEED 1..2147483647, default 1): light|moderate|severe (fixed "
                        "wind at 20 ft: 15|30|45 kt), milspec:light|moderate|severe (MIL-F-8785C with the flight's "
                        "own wind at 20 ft) or iec:A|B|C (IEC 61400-1 class at the cycle's mean height); "
                        "docs/wind.md")
    p.add_argument("--mode", choices=("AUTO", "RECOVER"), default="AUTO", help="autopilot mode at the start (RECOVER: brake the drum, reel in, circle down and land at the "
                        "winch, or park in a hold with REC_LAND 0)")
    p.add_argument("--json", metavar="FILE", help="write the numbers as JSON (NaN written as null)")
    p.add_argument("--rrd", metavar="FILE", help="write a rerun recording of the flight")
    p.add_argument("--out", metavar="DIR", help="write recording, plots, CSV, a markdown report (and an optimised "
                                                "reference's file) into DIR")
    p.add_argument("--mavlink", metavar="URL", nargs="?", const="udpout:127.0.0.1:14550",
                   help="speak MAVLink 2 to a ground station: udpout|udpin|udp|tcp|tcpin:HOST:PORT, an IPv4 host; a "
                        "listening address must be this machine's, a tcp ground station must accept the connection "
                        "before the work (one attempt, 3 s) (default URL udpout:127.0.0.1:14550)")
    p.add_argument("--mavlink-key", metavar="FILE",
                   help="MAVLink 2 signing key: a 32-byte key file, or a one-line passphrase (hashed with SHA-256 like "
                        "MAVProxy's 'signing setup'); only signed commands are obeyed (needs --mavlink)")
    p.add_argument("--exit-after-cycles", action="store_true",
                   help="with --mavlink: end the program when the flight ends (default: once a ground station was "
                        "heard, the vehicle stays on the link, answering, until a ground station shuts it down "
                        "(MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN 2) or Ctrl-C, as SITL does)")
    p.add_argument("--realtime", metavar="FACTOR", type=float, nargs="?", const=1.0,
                   help="pace against the wall clock, > 0 and <= 1000 (default 1x)")
    p.add_argument("--params", metavar="FILE", help="autopilot parameter file (PARAM_SET changes are saved there)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    from ..recording.stream import add_live_arguments

    add_live_arguments(p)  # --spawn / --connect [ADDR]: a live view in rerun


def _check(args: argparse.Namespace) -> None:
    """Every option on its own (ranges, forms) and the options a reference fixes."""
    from ..groundstation.tether import TETHER_DRAG_SCALE_MAX

    aircraft_from_args(args), station_from_args(args)  # their files checked first (errors name --aircraft, --ground-station)
    chk.integer(args.cycles, "--cycles", 1, 1000, what="pumping cycles")
    chk.number(args.dt, "--dt", 1e-4, 0.05, unit="s", what="co-simulation step")
    chk.number(args.wind, "--wind", 0.0, 25.0, unit="m/s", what="wind speed")
    chk.number(args.wind_from, "--wind-from", -360.0, 360.0, unit="deg", what="wind direction")
    chk.number(args.realtime, "--realtime", 0.0, 1000.0, lo_open=True, what="pacing factor")
    chk.number(args.tether_drag_scale, "--tether-drag-scale", 0.0, TETHER_DRAG_SCALE_MAX, what="line drag factor")
    chk.number(args.gamma_max, "--gamma-max", 0.1, 1.5, unit="rad", what="flight-path angle bound")
    chk.number(args.v_min, "--v-min", 1.0, 20.0, unit="m/s", what="minimum airspeed of the reference")
    chk.number(args.start_wind, "--start-wind", 0.0, 25.0, unit="m/s", what="wind of the first reference")
    smoothness_bounds(args)
    margin_bounds(args)
    args.turbulence = chk.turbulence(args.turbulence)
    from ..groundstation.linemodels import parse_tether

    args.tether = parse_tether(args.tether)  # parsed once: the flight and its ground station take the model
    chk.mavlink_url(args.mavlink)
    from ..recording.stream import check_live_args

    check_live_args(args)
    from ..example_refs import resolve

    args.reference = resolve(args.reference, "--reference")  # example:NAME -> the stored file
    chk.input_file(args.reference, "--reference")  # a regular file: a FIFO or a device would block or never end
    if args.mavlink_key is not None:
        if not args.mavlink:
            raise InputError("--mavlink-key: only with --mavlink (there is no link to sign)")
        from ..mavlink.signing import load_key

        args.signing_key = load_key(args.mavlink_key)  # checked before any work (one line)
    # read now and written back on every PARAM_SET: a regular file or a new name in a writable folder
    chk.io_file(args.params, "--params", inputs=[args.reference, args.mavlink_key])
    chk.input_dir(args.references, "--references")
    if args.references is not None and args.reference is not None:
        raise InputError("--references: not with --reference (the set's references are the flight's; drop one)")
    if args.start_wind is not None and args.references is None:
        raise InputError("--start-wind: only with --references (it chooses the set's first reference)")
    if args.reference is not None or args.references is not None:
        flight_wind = FLIGHT_WIND if args.references is not None else ()
        given = [("--no-line-weight" if attr == "line_weight" and getattr(args, attr) is False else opt)
                 for attr, opt in REFERENCE_FIXED.items() if getattr(args, attr, None) is not None
                 and attr not in flight_wind]
        if given:
            what = (f"the reference {args.reference}" if args.reference is not None
                    else f"the references {args.references}")
            raise InputError(f"{', '.join(given)}: {what} fix{'es' if args.reference is not None else ''} "
                             f"{'this' if len(given) == 1 else 'these'} (only used when fly optimises a reference; drop "
                             f"{'it' if len(given) == 1 else 'them'} or drop "
                             f"{'--reference' if args.reference is not None else '--references'})")
        if args.references is not None:
            wind_profile_from_args(args, args.scenario or DEFAULT_SCENARIO)
    elif args.allow_mismatch:
        raise InputError("--allow-mismatch: only with --reference or --references (nothing to mismatch when fly "
                         "optimises the reference)")
    else:
        check_plant_args(args, args.scenario or DEFAULT_SCENARIO)
        wind_profile_from_args(args, args.scenario or DEFAULT_SCENARIO)


#: the options that give the flight's wind with ``--references`` (attributes)
FLIGHT_WIND = ("wind", "wind_from", "wind_profile", "wind_ref_height")


def check_reference_options(args: argparse.Namespace, meta: dict, ref_path: str) -> None:
    """An explicit ``--config``/``--scenario`` must be the reference's (``meta``), unless
    ``--allow-mismatch``: then a warning line each on stderr."""
    for attr, option, what in (("config", "--config", "configuration"), ("scenario", "--scenario", "scenario")):
        want, have = getattr(args, attr), meta.get(attr)
        if want is None or want == have:
            continue
        if not args.allow_mismatch:
            raise InputError(f"{option} {want}: {ref_path} was optimised for the {what} {have!r}; fly it with its own "
                             f"{what}, or add --allow-mismatch to fly it anyway")
        print(f"warning: {ref_path} was optimised for the {what} {have!r}; flying it with {option} {want} "
              f"(--allow-mismatch)", file=sys.stderr)


def reference_problem(args: argparse.Namespace):
    """The validated :class:`~fdm_awe.ocp.problem.CycleProblem` of the reference to optimise
    (flyable bounds; the effective defaults for options not given)."""
    from ..ocp.problem import CycleProblem

    return CycleProblem(scenario=args.scenario, config=args.config,
                        wind_speed=DEFAULT_WIND_MPS if args.wind is None else args.wind,
                        wind_from_deg=DEFAULT_WIND_FROM_DEG if args.wind_from is None else args.wind_from,
                        bounds=flyable_bounds(args.gamma_max, smoothness_bounds(args), args.v_min,
                                              margin_bounds(args, FLY_TENSION_MARGIN, FLY_STALL_MARGIN,
                                                            FLY_REEL_IN_MARGIN)),
                        tether_drag_scale=1.0 if args.tether_drag_scale is None else args.tether_drag_scale,
                        propeller=args.propeller, line_weight=args.line_weight, line=args.line,
                        generator=args.generator, line_model=args.line_model or "straight",
                        wind_profile=wind_profile_from_args(args, args.scenario or DEFAULT_SCENARIO),
                        aircraft=aircraft_from_args(args), ground_station=station_from_args(args)).validate()


def optimise_reference(problem):
    """Optimise the reference of the run; returns the ok CycleResult (InputError if none)."""
    from ..ocp.solve import solve_cycle

    b = problem.bounds
    print(f"optimising a {problem.scenario} {problem.config} cycle at {problem.wind_speed:g} m/s (flyable bounds: "
          f"C_L <= {b.cl_margin:g} C_Lmax, tension <= {b.G_cycle_max:.3g} N (rating {b.G_max:g} N / "
          f"{1 + b.tension_margin:g}), "
          f"{'' if b.reel_in_speed_max is None else f'reel-in <= {b.reel_in_speed_max:.3g} m/s, '}|bank| <= {b.phi_max} rad, |gamma| <= {b.gamma_max:g} rad, "
          f"V >= {b.V_min:g} m/s; "
          f"line drag x {problem.tether_drag_scale:g}{_smoothness_text(b)}) ...", file=sys.stderr)
    res = solve_cycle(problem)
    if not res.ok:
        raise InputError(f"the optimiser found no {problem.scenario} {problem.config} cycle at {problem.wind_speed:g} m/s: "
                         f"{res.status} ({getattr(res, 'reason', '')})")
    return res


def _smoothness_text(b) -> str:
    """The smoothness bounds of ``b`` that are set, for the progress line ('' when none)."""
    parts = [f"{name} {v:g} {unit}" for name, v, unit in (("bank rate <=", b.bank_rate_max, "rad/s"),
                                                         ("alpha rate <=", b.alpha_rate_max, "rad/s"),
                                                         ("catch <=", b.catch_speed_max, "m/s")) if v is not None]
    return "".join(f"; {p}" for p in parts)


def reference_file_name(args: argparse.Namespace) -> str:
    """File name of an optimised reference written into ``--out``."""
    wind = DEFAULT_WIND_MPS if args.wind is None else args.wind
    return f"reference_{args.scenario}_{args.config}_{wind:g}.json"


def flight_drag_scale(meta: dict, requested: float | None, ref_path: object) -> float:
    """The line-drag factor of the flight: the reference's ``tether_drag_scale`` (metadata; 1
    for files written before it existed) unless ``requested`` overrides it. Prints an info line
    with the scale, and a warning when an override makes the flight's line differ from the one
    the reference was optimised with."""
    ref_scale = float(meta.get("tether_drag_scale", 1.0))
    scale = ref_scale if requested is None else float(requested)
    if scale != ref_scale:
        print(f"warning: {ref_path} was optimised with tether_drag_scale {ref_scale:g}; the flight uses "
              f"{scale:g} (--tether-drag-scale), so its line drag differs from the reference's", file=sys.stderr)
    else:
        print(f"line {meta.get('line', 'paper')}, line drag x {scale:g} ({'the defined line' if scale == 1.0 else 'scaled line'}), "
              f"as {ref_path} was optimised with", file=sys.stderr)
    return scale


def run(args: argparse.Namespace, given: Any = None, result: dict[str, Any] | None = None) -> int:
    """``fdm-awe fly``: returns the exit code. ``given``: a reference in memory (a
    :class:`~fdm_awe.autopilot.tracking.TrackingReference`, the Python API's) flown as a
    ``--reference`` file would be, with the same checks; ``result``: filled with the flight's
    ``report`` and the ``reference`` flown (the Python API's results)."""
    _check(args)
    ref = problem = refs = flight_wind = None
    if args.references:
        refs, ref, flight_wind, args.reference_flown = _read_references(args)
    elif given is not None:
        ref = _given_reference(args, given)
    elif args.reference:
        ref = _read_reference(args)
    else:
        args.scenario = args.scenario or DEFAULT_SCENARIO
        args.config = args.config or DEFAULT_CONFIG
        problem = reference_problem(args)
    plant = flight_plant(args, ref)
    args.tether.check_plant(plant == "paper", _plant_why(args, plant))
    params = _autopilot_params(args.params, aircraft=aircraft_from_args(args))  # checked before any work
    _check_budget(args, params, ref, problem)
    out_dir = Path(args.out) if args.out else None
    with _check_outputs(args, out_dir, optimising=ref is None):  # --out locked until the last file is written
        return _run_checked(args, ref, problem, params, plant, out_dir, refs, flight_wind,
                            given_label="the reference given" if given is not None else None, result=result)


def _run_checked(args: argparse.Namespace, ref: Any, problem: Any, params: Any, plant: str, out_dir: Path | None,
                 refs: Any = None, flight_wind: dict[str, Any] | None = None, given_label: str | None = None,
                 result: dict[str, Any] | None = None) -> int:
    """The work of :func:`run` once every input and output is checked: open the MAVLink link,
    optimise the reference (without ``--reference`` or ``--references``; ``refs`` the set, ``flight_wind`` the wind it meets), fly, print, write the outputs; returns the
    exit code."""
    link = _open_link(args)  # the MAVLink transport: a ground station that is not there is said now
    beacon = _boot_beacon(args, link)  # a heartbeat each second until the flight's endpoint takes the link
    stay: list[Any] = []  # the endpoint kept on the link after the flight (--mavlink without --exit-after-cycles)
    try:
        if ref is None:
            ref, ref_path, ref_label = _optimised_reference(args, problem, out_dir)
        elif given_label is not None:  # a reference in memory: no file
            ref_path, ref_label = None, given_label
        else:
            ref_path = Path(args.reference or args.reference_flown)
            ref_label = str(ref_path)
        scale = flight_drag_scale(ref.meta, args.tether_drag_scale, ref_label)
        if refs is not None:  # what each reference was optimised with (after the checks: bad input stays one line)
            for e in refs.entries:
                print_reference_margins(e.reference.meta, e.source)
        elif args.reference or given_label is not None:
            print_reference_margins(ref.meta, ref_label)
        from ..recording.stream import open_live

        live = open_live(args, ref)  # --spawn / --connect: the viewer the flight streams to (None without)
        report = _fly(args, ref, params, plant, scale, live, link, refs, flight_wind, beacon, stay)
        link = None  # the flight's MAVLink endpoint took it and closed it (or keeps it: ``stay``)
    finally:
        if beacon is not None:
            beacon.stop()
        if link is not None:
            from ..mavlink.transport import close_link

            close_link(link)
    optimised = optimised_energies(ref, refs)
    if result is not None:
        result.update(report=report, reference=ref)
    try:
        _print_summary(report, ref_label, optimised)
        code = _finish(args, report, ref, ref_path, out_dir, optimised)
        if stay:
            _stay_on_link(*stay)
    finally:
        if stay:
            stay[0].close()
    return code


def _boot_beacon(args: argparse.Namespace, link: Any) -> Any:
    """The heartbeat sent while the rest loads (:class:`~fdm_awe.mavlink.boot.BootBeacon`) on the
    opened ``--mavlink`` link, None without one."""
    if link is None:
        return None
    from ..mavlink.boot import BootBeacon

    return BootBeacon(link, args.mode, signing_key=getattr(args, "signing_key", None))


def _stay_on_link(endpoint: Any, tel: Any, t_end: float) -> None:
    """After the flight and its outputs: keep the vehicle on the MAVLink link, answering
    (heartbeats and the streams of the last simulated state, parameters, the mission; the
    commands that would fly refused with their reason), until a ground station shuts it down
    (MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN 2) or Ctrl-C; the endpoint's clock runs on from the
    flight's end time ``t_end`` [s] at wall-clock rate."""
    print("flight over: the vehicle stays on the MAVLink link (the last simulated state) until a ground station "
          "shuts it down (MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN 2) or Ctrl-C (--exit-after-cycles: end at once)",
          file=sys.stderr, flush=True)
    w0 = time.monotonic()
    try:
        while not endpoint.shutdown_requested:
            endpoint.update(t_end + (time.monotonic() - w0), tel)
            time.sleep(0.01)
    except KeyboardInterrupt:
        print("\nCtrl-C: the vehicle leaves the link", file=sys.stderr)
        return
    endpoint.update(t_end + (time.monotonic() - w0), tel)  # the COMMAND_ACK of the shutdown goes out
    print("shut down by the ground station", file=sys.stderr)


def flight_plant(args: argparse.Namespace, ref: Any) -> str:
    """The plant that flies: ``--scenario``, else the reference's scenario (physical when it
    names none)."""
    if args.scenario:
        return args.scenario
    scenario = ref.meta.get("scenario") if ref is not None else None
    return scenario if scenario in ("physical", "paper") else "physical"


def _plant_why(args: argparse.Namespace, plant: str) -> str:
    """What chose the plant ``plant``, for messages."""
    if args.reference and args.scenario is None:
        return f"the {plant} scenario of {args.reference}"
    return f"--scenario {plant}"


def _open_link(args: argparse.Namespace) -> Any:
    """The ``--mavlink`` transport opened (a tcp client connected once, bounded in time), or
    None without ``--mavlink``; one-line error naming the option when it cannot be opened."""
    if not args.mavlink:
        return None
    from ..mavlink.transport import open_link

    return open_link(args.mavlink)


def _autopilot_params(path: str | None, option: str = "--params", aircraft: Any = None) -> Any:
    """The autopilot's parameters of ``aircraft``'s autopilot definition (None: the package's
    glider), from the file ``path`` (``--params``) when given: a JSON parameter file, or a path
    where none exists yet (created at the first change). A folder, a device, a FIFO or a
    malformed file is refused in one line naming ``option``."""
    from ..autopilot.config import autopilot_params
    from ..autopilot.params import ParamStore
    from ..errors import DefinitionError
    from ..fileio import check_input_file

    definition = None if aircraft is None else aircraft.autopilot_file
    if path is None:
        return autopilot_params(definition)
    p = Path(path)
    if p.exists():
        check_input_file(p, option)  # a regular file (none yet: created at the first change)
    try:
        return autopilot_params(definition, store=ParamStore(p))
    except DefinitionError as exc:
        raise InputError(f"{option} {exc.path}: {exc.element}: {exc.problem}") from None


def _check_budget(args: argparse.Namespace, params: Any, ref: Any, problem: Any) -> None:
    """Before any work (:mod:`fdm_awe.sim.budget`): ``--dt`` is a step the attitude loops fly
    with under ``params``, and ``--cycles`` of the reference's period (of the longest cycle the
    optimiser may return, ``problem``'s bound, when it optimises one) at ``--dt`` fit in the
    steps a flight keeps in memory."""
    from ..sim.budget import check_length, check_step

    check_step(args.dt, params)
    if ref is not None:
        check_length(args.cycles, ref.period, args.dt, what=f"{args.reference or args.references}")
    else:
        check_length(args.cycles, problem.bounds.t_max, args.dt,
                     what="the longest cycle the optimiser may return (T1 + T2 <= t_max)")


def _given_reference(args: argparse.Namespace, ref: Any) -> Any:
    """A reference in memory (``ref``), checked as :func:`_read_reference` checks a file: the
    options it fixes refused, its configuration and scenario against the options, the
    turbulence form against its wind; ``args.config`` defaults to the reference's."""
    given = [opt for attr, opt in REFERENCE_FIXED.items() if getattr(args, attr, None) is not None]
    if given:
        raise InputError(f"{', '.join(given)}: the reference given fixes {'this' if len(given) == 1 else 'these'}"
                         " (only used when fly optimises a reference)")
    return _checked_reference(args, ref, "the reference given")


def _checked_reference(args: argparse.Namespace, ref: Any, source: object) -> Any:
    """``ref`` (from ``source``) checked against the options: its configuration and scenario,
    the turbulence form against its wind; ``args.config`` defaults to the reference's."""
    check_reference_options(args, ref.meta, source)
    check_reference_definitions(ref.meta, args, source)
    if args.turbulence is not None:  # a form the reference's wind cannot realise: refused before the flight
        from ..sim.flight_rig import turbulence_setting

        turbulence_setting(ref, args.turbulence)
    args.config = args.config or (ref.meta.get("config") if ref.meta.get("config") in ("foldable", "nominal")
                                  else DEFAULT_CONFIG)
    return ref


def _read_reference(args: argparse.Namespace) -> Any:
    """The ``--reference`` file as a :class:`~fdm_awe.autopilot.tracking.TrackingReference` (checked field by
    field, one-line errors), its configuration and scenario against the options; ``args.config`` defaults to its."""
    from ..autopilot.tracking import TrackingReference

    return _checked_reference(args, TrackingReference.from_ocp_file(args.reference), args.reference)


def print_reference_margins(meta: dict, source: object) -> None:
    """One line on stderr: the margins the reference ``source`` (metadata ``meta``) was optimised
    with and its line model (:func:`fdm_awe.trajectory.files.margins_text`)."""
    from ..trajectory.files import margins_text

    print(f"{source}: {margins_text(meta)}; line model {meta.get('line_model', 'straight')}", file=sys.stderr)


def _read_references(args: argparse.Namespace) -> tuple[Any, Any, dict[str, Any], str]:
    """The ``--references`` set (:class:`~fdm_awe.autopilot.schedule.ReferenceSet`, checked file by
    file and as a set; its configuration and scenario against the options), the reference it
    starts on (``--start-wind``) and the wind the flight meets (``--wind`` ... or the start
    reference's own) as reference metadata gives a wind, and the start reference's file."""
    from ..autopilot.schedule import ReferenceSet
    from ..pointmass.model import wind_vector

    refs = ReferenceSet.from_folder(args.references)
    first = refs.entries[0]
    check_reference_options(args, first.reference.meta, first.source)
    for e in refs.entries:
        check_reference_definitions(e.reference.meta, args, e.source)
    args.config = args.config or (first.reference.meta.get("config") if first.reference.meta.get("config") in
                                  ("foldable", "nominal") else DEFAULT_CONFIG)
    start_w = args.start_wind if args.start_wind is not None else args.wind
    entry = refs.entries[0 if start_w is None else refs.nearest(start_w)]
    ref = entry.reference
    if args.wind is None and args.wind_profile is None and args.wind_from is None:
        meta = ref.meta
        wind = {"wind_ned_mps": list(meta.get("wind_ned_mps", (0.0, 0.0, 0.0))),
                "wind_profile": meta.get("wind_profile")}
    else:
        prof = wind_profile_from_args(args, args.scenario or DEFAULT_SCENARIO)
        speed = entry.wind_mps if args.wind is None else args.wind
        from_deg = refs.wind_from_deg if args.wind_from is None else args.wind_from
        wind = {"wind_ned_mps": list(wind_vector(speed, from_deg)),
                "wind_profile": prof.as_dict(), "wind_mps": speed}
    print(f"reference set {args.references}: {len(refs.entries)} references at "
          f"{', '.join(f'{w:g}' for w in refs.winds)} m/s ({refs.profile.describe()}); the first cycle flies "
          f"{entry.source}", file=sys.stderr)
    return refs, ref, wind, entry.source


def _check_outputs(args: argparse.Namespace, out_dir: Path | None, optimising: bool) -> Any:
    """Every output path checked before any work: ``--json``, ``--rrd``, ``--out`` and the files
    it will hold (with an optimised reference's file when ``optimising``), none an input; the
    names ``--out`` gives its files (``flight.rrd`` too) are its own, even when ``--rrd`` takes
    the recording elsewhere. Returns the lock of ``--out`` (:func:`_checks.outputs`)."""
    from ..recording.outputs import output_files

    in_dir = [("--out", p) for p in output_files(out_dir, "flight").values()] if out_dir else []
    if out_dir and optimising:
        in_dir.append(("--out", out_dir / reference_file_name(args)))
    return chk.outputs(files=[("--json", args.json), ("--rrd", args.rrd)], dirs=[("--out", args.out)],
                       inputs=[args.reference, args.params, args.mavlink_key], dir_files=in_dir)


def _optimised_reference(args: argparse.Namespace, problem: Any, out_dir: Path | None) -> tuple[Any, Path | None, str]:
    """Optimise the reference of ``problem`` and hand it over in memory (the content of the file
    written with ``--out``, no file otherwise); returns (reference, its file or None, label)."""
    from ..autopilot.tracking import TrackingReference
    from ..trajectory import reference_from_result, write_reference

    res = optimise_reference(problem)
    ref_label = f"the optimised {args.scenario} {args.config} reference"
    ref = TrackingReference.from_ocp(reference_from_result(res, ref_label))
    ref_path: Path | None = None
    if out_dir is not None:
        ref_path = write_reference(res, out_dir / reference_file_name(args))
        ref_label = str(ref_path)
        print(f"reference trajectory: {ref_path}", file=sys.stderr)
    return ref, ref_path, ref_label


class _FlightHooks:
    """What the command attaches to a flight: the progress bar (unless ``--quiet`` or not a
    terminal; ``n_total`` steps), and at the flight's set-up the start mode (``--mode``), the
    MAVLink endpoint with its telemetry and link-loss failsafe (``--mavlink``) and the pacing
    against the wall clock (``--realtime``) and the live viewer (``--spawn`` / ``--connect``,
    ``live``); all called after every step (:meth:`on_step`)."""

    def __init__(self, args: argparse.Namespace, n_total: int, live: Any = None, link: Any = None,
                 beacon: Any = None) -> None:
        self.args = args
        self.live = live
        self.link = link  #: the --mavlink transport, opened before the work (None: opened at set-up)
        self.beacon = beacon  #: the boot heartbeat on ``link``, stopped before the endpoint's first update
        self.endpoint: Any = None
        self.telemetry: Any = None  #: the last step's telemetry, built when read (``--mavlink``)
        self.bar: Any = None
        self._hooks: list[Callable[[int, Any, Any], None]] = []
        if not args.quiet and sys.stderr.isatty():
            from tqdm import tqdm

            bar = self.bar = tqdm(total=n_total, unit="step", desc="flying", file=sys.stderr, mininterval=0.5)
            self._hooks.append(lambda k, s, o: bar.update(600) if k % 600 == 0 else None)

    def setup(self, ap: Any, sim: Any) -> None:
        """The flight's ``setup(autopilot, cosim)``."""
        args = self.args
        if args.mode != "AUTO":
            ap.set_mode(args.mode)
        if args.mavlink:
            from ..mavlink.bridge import telemetry_builder
            from ..mavlink.endpoint import MavlinkEndpoint

            endpoint = self.endpoint = MavlinkEndpoint(args.mavlink, vehicle=ap,
                                                       signing_key=getattr(args, "signing_key", None),
                                                       signing_key_file=args.mavlink_key, connection=self.link)
            self.link = None  # the endpoint owns it now
            build = telemetry_builder(ap, sim)

            def link(k: int, s: Any, o: Any) -> None:
                if self.beacon is not None:  # the first step: the endpoint sends from now on
                    self.beacon.stop()
                    self.beacon = None
                build.integrate(s)
                self.telemetry = lambda: build(s, o)
                endpoint.update(s.t, self.telemetry)
                ap.gcs_link(endpoint.link_up, s.t)  # the link-loss failsafe (FS_GCS_ENABL)

            self._hooks.append(link)
        if args.realtime:
            from ..sim.pacing import RealtimePacer

            pacer = RealtimePacer(args.realtime)
            self._hooks.append(lambda k, s, o: pacer.wait(s.t))
        if self.live is not None:
            self.live.setup(ap, sim)
            self._hooks.append(self.live)
        print(f"flying: {args.cycles} cycle(s), mode {ap.mode}", file=sys.stderr, flush=True)  # set up, the loop starts

    @property
    def per_step(self) -> bool:
        """Whether the flight has work for every step (progress bar, MAVLink, pacing, live
        viewer); without, it passes no ``on_step`` and the autopilot may fly compiled blocks."""
        a = self.args
        return bool(self._hooks) or bool(a.mavlink) or bool(a.realtime) or self.live is not None

    def on_step(self, k: int, s: Any, o: Any) -> None:
        """The flight's ``on_step``: every hook in turn."""
        for h in self._hooks:
            h(k, s, o)

    def close(self, keep_endpoint: bool = False) -> None:
        """Close the progress bar, the MAVLink endpoint unless ``keep_endpoint`` (or the link no
        endpoint took) and the live viewer's stream."""
        if self.bar is not None:
            self.bar.close()
        if self.beacon is not None:
            self.beacon.stop()
        if self.endpoint is not None:
            if not keep_endpoint:
                self.endpoint.close()
        elif self.link is not None:
            from ..mavlink.transport import close_link

            close_link(self.link)
            self.link = None
        if self.live is not None:
            self.live.close()


def _fly(args: argparse.Namespace, ref: Any, params: Any, plant: str, scale: float, live: Any = None,
         link: Any = None, refs: Any = None, flight_wind: dict[str, Any] | None = None, beacon: Any = None,
         stay: list[Any] | None = None) -> Any:
    """Fly ``ref`` as the options say (:func:`fdm_awe.sim.flight.fly` with the command's hooks);
    the report's wall time is the whole flight's, hooks included. The ground station on the
    MAVLink link (``link``, opened before the work, its boot heartbeat ``beacon``) is told how the
    flight ended; the link is closed here, or, without ``--exit-after-cycles``, when the flight
    ended by itself and a ground station was heard on the link during it, its endpoint, the last
    telemetry and the end time go into ``stay`` (:func:`_stay_on_link`)."""
    from ..sim import flight

    hooks = _FlightHooks(args, int(round(args.cycles * ref.period / args.dt)), live, link, beacon)
    t0 = time.perf_counter()
    keep = False
    try:
        report = flight.fly(ref, config=args.config, cycles=args.cycles, dt=args.dt, turbulence=args.turbulence,
                            on_step=hooks.on_step if hooks.per_step else None, params=params, setup=hooks.setup,
                            plant=plant, tether_drag_scale=scale, tether=args.tether, references=refs,
                            flight_wind=flight_wind, aircraft=aircraft_from_args(args), ground_station=station_from_args(args))
        if hooks.endpoint is not None:
            hooks.endpoint.flight_ended(report.status, report.message)  # the crash or landing, told to the ground station
            if (stay is not None and not getattr(args, "exit_after_cycles", False) and report.status != "interrupted"
                    and hooks.telemetry is not None and hooks.endpoint.ever_linked):
                tel = hooks.telemetry()
                stay[:] = [hooks.endpoint, tel, float(tel.t)]
                keep = True
        if live is not None:
            live.finish(report)  # the last rows, the flown path, the events and the report
    finally:
        hooks.close(keep_endpoint=keep)
    report.wall_s = time.perf_counter() - t0
    return report


def _finish(args: argparse.Namespace, report, ref, ref_path: Path | None, out_dir: Path | None,
            optimised: dict[str, float] | None = None) -> int:
    """Write every requested output (also after Ctrl-C) and return the exit code.

    A flight interrupted by Ctrl-C (status ``interrupted``) keeps the steps flown so far: they
    are written like a finished flight's and the exit code is 130. A Ctrl-C while the outputs
    are written stops the files not yet begun (those written stay, none is truncated); the JSON
    then lists the files written (``outputs_cut_short`` true) and the exit code is 130.
    """

    doc = report.as_json()
    doc["reference"] = None if ref_path is None else str(ref_path)
    doc["reference_margins"] = ref.meta.get("margins")  # as the reference recorded them (None: not recorded)
    doc["reference_line_model"] = ref.meta.get("line_model", "straight")
    doc["references"] = getattr(args, "references", None)
    doc["optimised"] = optimised  # the reference's own cycle (J, W, s); null for a reference set
    rrd = args.rrd or (str(out_dir / "flight.rrd") if out_dir else None)
    written: dict[str, object] = {}
    cut = False
    if rrd or out_dir:
        from ..recording import flight_outputs

        try:
            flight_outputs(report, ref, rrd=rrd, out_dir=out_dir, written=written)
        except KeyboardInterrupt:
            cut = True
            print("fdm-awe fly: interrupted while writing the outputs; the files listed in the JSON are complete",
                  file=sys.stderr)
    doc.update(written)
    optimised_ref = ref_path if ref_path is not None and not (args.reference or args.references) else None
    if cut:
        doc["outputs_cut_short"] = True
    if args.json:
        write_json(args.json, doc)
    listed = _written_files(written, optimised_ref, args.json)
    if listed:
        print("wrote: " + ", ".join(listed))
    if cut:
        return EXIT_INTERRUPTED
    return report.exit_code


def _fmt(v: float, spec: str) -> str:
    """``v`` formatted with ``spec``, or ``-`` right-aligned when it is not a finite number."""
    if v is None or not math.isfinite(v):
        width = "".join(ch for ch in spec.split(".")[0] if ch.isdigit())
        return "-".rjust(int(width or 1))
    return format(v, spec)


def _turbulence_line(t: dict) -> str:
    """One line on the flight's turbulence: the form, the target at the hub height and what the
    glider met (``FlightReport.turbulence``)."""
    tg, m = t["target"], t["measured"]

    def f(v: Any, spec: str) -> str:
        return "-" if v is None or not math.isfinite(v) else format(v, spec)

    hub = f"{f(tg['sigma_u_mps'], '.2f')} m/s at {f(t['hub_height_m'], '.0f')} m"
    return (f"turbulence {t['text']}: target sigma_u {hub}, intensity {f(tg['intensity'], '.3f')}; met over "
            f"{f(m['duration_s'], '.0f')} s: sigma_u/v/w {f(m['sigma_u_mps'], '.2f')}/{f(m['sigma_v_mps'], '.2f')}/"
            f"{f(m['sigma_w_mps'], '.2f')} m/s, intensity {f(m['intensity'], '.3f')}")


def realtime_text(rtf: float) -> str:
    """The measured real-time factor (simulated / wall seconds) as printed: two significant
    digits below 10 (``0.58x``), whole numbers above (``12x``)."""
    if not math.isfinite(rtf):
        return "-"
    return f"{rtf:.2g}x" if rtf < 10 else f"{rtf:.0f}x"


def optimised_energies(ref: Any, refs: Any = None) -> dict[str, float] | None:
    """The optimised cycle's energies [J] and average power [W] of the reference flown
    (``metadata.energies`` of the reference file, with ``T1_s``/``T2_s`` [s]); None for a reference
    set (each cycle may fly another reference) or a reference that names none."""
    if refs is not None or ref is None:
        return None
    e = ref.meta.get("energies")
    if not isinstance(e, dict) or "E_net_J" not in e:
        return None
    out = {k: float(e[k]) for k in ("E_generated_J", "E_thrust_J", "E_reel_in_J", "E_net_J", "P_avg_W") if k in e}
    for k in ("T1_s", "T2_s"):
        if k in ref.meta:
            out[k] = float(ref.meta[k])
    return out


def _print_summary(report, ref_label: str, optimised: dict[str, float] | None = None) -> None:
    """The flight in a few lines: the run, the status with the measured real-time factor, and
    one row per cycle (numbered from 0, as the JSON's ``index`` and ``flight.md``) with the
    optimised reference's net energy beside the flown one."""
    print(f"{report.scenario} / {report.config} / wind {report.wind_mps:g} m/s  reference {ref_label}  plant {report.plant}"
          f"  line drag x {report.tether_drag_scale:g}  tether {report.tether}")
    print(f"status {report.status}: {report.message}; {report.sim_time_s:.1f} s simulated in {report.wall_s:.1f} s "
          f"({realtime_text(report.realtime_factor)} real time, measured); energy ledger residual "
          f"{report.ledger_residual_rel:.2e}")
    if report.turbulence is not None:
        print(_turbulence_line(report.turbulence))
    opt = math.nan if optimised is None else optimised["E_net_J"]
    print(f"{'cycle':>5} {'T1 s':>6} {'T2 s':>6} {'gen J':>8} {'thrust J':>9} {'reel-in J':>9} {'net J':>8} "
          f"{'opt net J':>9} {'rms m':>7} {'max m':>7}")
    for c in report.cycles:
        flag = "" if c.complete else "  (incomplete)"
        print(f"{c.index:>5} {_fmt(c.T1_s, '6.2f')} {_fmt(c.T2_s, '6.2f')} {_fmt(c.E_generated_J, '8.1f')} "
              f"{_fmt(c.E_thrust_J, '9.1f')} {_fmt(c.E_reel_in_J, '9.1f')} {_fmt(c.E_net_J, '8.1f')} "
              f"{_fmt(opt, '9.1f')} {_fmt(c.track_rms_m, '7.2f')} {_fmt(c.track_max_m, '7.2f')}{flag}")
    if optimised is not None:
        print(f"optimised: net {optimised['E_net_J']:.1f} J per cycle ({optimised.get('P_avg_W', math.nan):.2f} W), "
              f"the reference's own (cycles are numbered from 0)")
    if report.wind_estimates:
        print("wind at the glider per cycle, estimated (true) m/s: " + ", ".join(
            f"{w['cycle']}: {w['estimated_at_glider']['speed_mps']:.2f} ({w['true_at_glider']['speed_mps']:.2f})"
            + (f" on the {w['reference_wind_mps']:g} m/s reference" if "reference_wind_mps" in w else "")
            for w in report.wind_estimates))


def _written_files(written: dict[str, object], ref_written: Path | None, json_path: str | None) -> list[str]:
    """Every file the run wrote, in order: the optimised reference (``ref_written``, into
    ``--out``), the outputs of :func:`fdm_awe.recording.flight_outputs` and ``--json``."""
    files: list[str] = [] if ref_written is None else [str(ref_written)]
    for v in written.values():
        if isinstance(v, str):
            files.append(v)
        elif isinstance(v, (list, tuple)):
            files.extend(str(x) for x in v)
    if json_path:
        files.append(str(json_path))
    return files
