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


def add_plant_model_args(p: argparse.ArgumentParser, prefix: str = "", line_axis: bool = False,
                         generators: tuple[str, ...] | None = None) -> None:
    """``--line``, ``--propeller`` and ``--line-weight``/``--no-line-weight``: the plant the
    optimiser models (``prefix`` opens the help texts, e.g. when the command optimises).

    Every option defaults to None (not given): the scenario's default
    (:data:`fdm_awe.ocp.problem.PLANT_DEFAULTS`; physical: the sized line, the glider's own
    drive, the line's weight), so that a command can tell an explicit option from its default.
    ``line_axis``: ``--line`` takes a comma list of line names (a sweep axis). ``generators``:
    the ``--generator`` choices (None: every generator of
    :data:`fdm_awe.trajectory.schema.GENERATORS`; empty: no such option, the sweep's case)."""
    from ..groundstation.line import LINE_MODELS, LINES  # plain module: no CasADi import
    from ..trajectory.schema import GENERATORS, PROPELLERS

    gens = GENERATORS if generators is None else generators
    if gens:
        p.add_argument("--generator", choices=gens, default=None,
                       help=prefix + "generator load in generation (physical scenario): passive, the passive rectifier "
                                     "(the default; the tension follows the reel speed, about 8 N per m/s), or boost, "
                                     "the converter's T2 duty as a control of the optimiser (0 .. the definition's "
                                     "boost_duty_max), flown by the ground station"
                                     + (", or ideal, a loss-free converter that holds any tension: an upper bound "
                                        "that no flight can realise" if "ideal" in gens else ""))

    if line_axis:
        p.add_argument("--line", default=None, metavar="LIST",
                       help=prefix + f"tether lines of the ground-station definition, comma list of {', '.join(LINES)} "
                                     "(default: the scenario's, sized in physical, paper = Table 1's line in paper)")
    else:
        p.add_argument("--line", choices=LINES, default=None,
                       help=prefix + "tether line of the ground-station definition: sized (sized for the 50 N rated "
                                     "tension x 4.5, 'fdm-awe info' shows it) or paper (Table 1's 0.72 mm line); "
                                     "default sized in the physical scenario, paper in the paper scenario")
    p.add_argument("--line-model", choices=LINE_MODELS, default=None,
                   help=prefix + "the line force on the glider in the physical scenario: straight (the default: the "
                                 "glider carries 1/4 of the drag of the line moving like it and 1/2 of its weight, as "
                                 "the ground station's straight line) or calibrated (the shares fitted to flights on "
                                 "the lumped line, with the drag of the still line in the wind: a reference to be "
                                 "flown on --tether lumped:N; tether/ground_station.xml holds the shares)")
    p.add_argument("--propeller", choices=PROPELLERS, default=None,
                   help=prefix + "propeller model of the physical scenario: engine, the 6-DOF glider's own motor and 9x5 "
                                 "propeller (what a flight draws; the default), or momentum, momentum theory + "
                                 "efficiencies (the model of the earlier published numbers)")
    p.add_argument("--line-weight", action=argparse.BooleanOptionalAction, default=None,
                   help=prefix + "physical scenario: the glider carries its share of the line's weight, as the 6-DOF "
                                 "plant's ground station applies it (default on in the physical scenario; "
                                 "--no-line-weight: a massless line, as the earlier published numbers)")


#: the reference-smoothness options: Bounds field -> (option, lower, upper, unit, what)
SMOOTHNESS_OPTIONS = {
    "bank_rate_max": ("--bank-rate-max", 0.01, 10.0, "rad/s", "the reference's bank rate bound"),
    "alpha_rate_max": ("--alpha-rate-max", 0.01, 10.0, "rad/s", "the reference's angle-of-attack rate bound"),
    "catch_speed_max": ("--catch-speed-max", 0.0, 30.0, "m/s", "the line's closing speed bound at the catch"),
}


def add_smoothness_args(p: argparse.ArgumentParser, prefix: str = "") -> None:
    """``--bank-rate-max``, ``--alpha-rate-max``, ``--catch-speed-max``: the reference's
    smoothness bounds (:class:`fdm_awe.ocp.problem.Bounds`), each None (off) unless given;
    ``prefix`` opens the help texts."""
    o = SMOOTHNESS_OPTIONS
    p.add_argument("--bank-rate-max", type=float, default=None, metavar="RAD_S",
                   help=prefix + "bound the bank's change between neighbouring control intervals, across the phase "
                                 f"switches too, to this rate, {_range(o['bank_rate_max'])} (default: unbounded). "
                                 "Smoother to fly, at a cost in power")
    p.add_argument("--alpha-rate-max", type=float, default=None, metavar="RAD_S",
                   help=prefix + f"the same for the angle of attack, {_range(o['alpha_rate_max'])} (default: unbounded)")
    p.add_argument("--catch-speed-max", type=float, default=None, metavar="M_S",
                   help=prefix + "bound the speed at which the slack line goes taut at the end of recovery (the "
                                 f"glider's distance rate minus the reel speed), {_range(o['catch_speed_max'])} "
                                 "(default: any)")


#: the margin options: Bounds field -> (option, lower, upper, what); the upper limits are the
#: problem's (:data:`fdm_awe.ocp.problem.TENSION_MARGIN_MAX`, :data:`~fdm_awe.ocp.problem.STALL_MARGIN_MAX`)
MARGIN_OPTIONS = {"tension_margin": "--tension-margin", "stall_margin": "--stall-margin"}


def add_margin_args(p: argparse.ArgumentParser, prefix: str = "", tension_default: float = 0.0,
                    stall_default: float = 0.0, why: str = "", reel_in: bool = True, reel_in_default: float = 0.0) -> None:
    """``--tension-margin`` and ``--stall-margin``: the margins the optimised cycle keeps below
    the line's rating and below the stall (:class:`fdm_awe.ocp.problem.Bounds`: ``tension_margin``
    and ``cl_margin = 1 - stall margin``), each None (the command's default) unless given;
    ``prefix`` opens the help texts, ``why`` ends the defaults' text; ``reel_in``: also
    ``--reel-in-margin`` (:data:`REEL_IN_MARGIN_MAX`; ``Bounds.reel_in_speed_max`` = the drive's
    fastest reel-in / (1 + M))."""
    from ..ocp.problem import STALL_MARGIN_MAX, TENSION_MARGIN_MAX

    p.add_argument("--tension-margin", type=float, default=None, metavar="M",
                   help=prefix + "the cycle's line tension stays at most the 50 N rating / (1 + M), "
                                 f"0..{TENSION_MARGIN_MAX:g} (default {tension_default:g}{why}): room for the catch "
                                 "of the line and for gusts, which the flown cycle adds to the optimum's tension")
    p.add_argument("--stall-margin", type=float, default=None, metavar="M",
                   help=prefix + f"C_L stays at most (1 - M) x each wing's C_Lmax, 0..{STALL_MARGIN_MAX:g} "
                                 f"(default {stall_default:g}{why})")
    if reel_in:
        p.add_argument("--reel-in-margin", type=float, default=None, metavar="M",
                       help=prefix + "the cycle reels in at most the drive's fastest reel-in (slack line, full duty: "
                                     f"'fdm-awe info') / (1 + M), 0..{REEL_IN_MARGIN_MAX:g} (default "
                                     f"{reel_in_default:g}{why}): room for the flown winch to catch up after the "
                                     "phase switch")


def margin_bounds(args: argparse.Namespace, tension_default: float = 0.0, stall_default: float = 0.0,
                  reel_in_default: float = 0.0) -> dict[str, float]:
    """The margins of ``--tension-margin`` / ``--stall-margin`` / ``--reel-in-margin`` (checked;
    the defaults where not given) as :class:`~fdm_awe.ocp.problem.Bounds` fields
    ``tension_margin``, ``cl_margin`` and, for a reel-in margin above 0, ``reel_in_speed_max``."""
    from ..ocp.problem import STALL_MARGIN_MAX, TENSION_MARGIN_MAX
    from . import _checks as chk

    tm = chk.number(getattr(args, "tension_margin", None), "--tension-margin", 0.0, TENSION_MARGIN_MAX,
                    what="tension margin below the rating")
    sm = chk.number(getattr(args, "stall_margin", None), "--stall-margin", 0.0, STALL_MARGIN_MAX,
                    what="stall margin (share of C_Lmax kept unused)")
    out = {"tension_margin": tension_default if tm is None else tm,
           "cl_margin": 1.0 - (stall_default if sm is None else sm)}
    rm = chk.number(getattr(args, "reel_in_margin", None), "--reel-in-margin", 0.0, REEL_IN_MARGIN_MAX,
                    what="reel-in speed margin below the drive's fastest")
    rm = reel_in_default if rm is None else rm
    if rm > 0.0:  # below the fastest reel-in of the drive the cycle is optimised for (--supply-voltage)
        out["reel_in_speed_max"] = drive_reel_in_speed(getattr(args, "supply_voltage", None), station_from_args(args)) / (1.0 + rm)
    return out


#: largest ``--reel-in-margin``: the cycle may reel in at half the drive's fastest
REEL_IN_MARGIN_MAX = 1.0


def drive_reel_in_speed(supply_voltage: float | None = None, station: Any = None) -> float:
    """The drive's fastest reel-in [m/s]: a slack line at full duty from the supply of the
    ground-station definition ``station`` (None: the package's), or from ``supply_voltage`` [V]
    where given (``--supply-voltage``) (:func:`fdm_awe.groundstation.steady.motor_max_reel_in_speed`;
    what the optimiser's reel-in bound is without a margin)."""
    from dataclasses import replace

    from ..groundstation.source import station_params
    from ..groundstation.steady import motor_max_reel_in_speed

    gs = station_params(station)
    if supply_voltage is not None:
        gs = replace(gs, converter=replace(gs.converter, supply_voltage=float(supply_voltage)))
    return float(motor_max_reel_in_speed(0.0, gs))


def _range(spec: tuple) -> str:
    """``lo..hi unit`` of a :data:`SMOOTHNESS_OPTIONS` entry."""
    return f"{spec[1]:g}..{spec[2]:g} {spec[3]}"


def smoothness_bounds(args: argparse.Namespace) -> dict[str, float]:
    """The smoothness bounds given on the command line (checked), as ``Bounds`` fields."""
    from . import _checks as chk

    out = {}
    for attr, (opt, lo, hi, unit, what) in SMOOTHNESS_OPTIONS.items():
        v = chk.number(getattr(args, attr, None), opt, lo, hi, unit=unit, what=what)
        if v is not None:
            out[attr] = v
    return out


def add_wind_profile_args(p: argparse.ArgumentParser, prefix: str = "") -> None:
    """``--wind-profile`` and ``--wind-ref-height``: how the wind varies with height
    (:mod:`fdm_awe.wind`); ``prefix`` opens the help texts."""
    p.add_argument("--wind-profile", default=None, metavar="KIND",
                   help=prefix + "wind speed over height: uniform (the default, the paper's: the same speed at every "
                                 "height), log:Z0 (logarithmic, roughness length Z0 in m, 0.00001..2, e.g. log:0.1 "
                                 "open country) or power:ALPHA (power law, exponent 0..1, e.g. power:0.143); --wind "
                                 "is then the speed at --wind-ref-height")
    p.add_argument("--wind-ref-height", type=float, default=None, metavar="M",
                   help=prefix + "height [m] at which --wind holds for a log or power profile, 1..1000 (default 10, "
                                 "the meteorological standard height of anemometers and wind statistics)")


def wind_profile_from_args(args: argparse.Namespace, scenario: str | None = None):
    """The :class:`~fdm_awe.wind.WindProfile` of ``--wind-profile`` / ``--wind-ref-height``
    (uniform when neither is given); one-line errors naming the option."""
    from ..errors import InputError
    from ..wind import REF_HEIGHT_RANGE_M, WindProfile
    from . import _checks as chk

    text = getattr(args, "wind_profile", None)
    h = getattr(args, "wind_ref_height", None)
    chk.number(h, "--wind-ref-height", *REF_HEIGHT_RANGE_M, unit="m", what="reference height")
    prof = WindProfile.parse("uniform" if text is None else text, h)
    if prof.uniform and h is not None:
        raise InputError(f"--wind-ref-height {h:g}: only with a log or power --wind-profile (a uniform wind has the "
                         f"same speed at every height)")
    scn = scenario or getattr(args, "scenario", None)
    if scn == "paper" and not prof.uniform:
        raise InputError(f"--wind-profile {text}: the paper scenario's wind is uniform (allowed uniform; shear is a "
                         f"physical-scenario option)")
    return prof


def check_plant_args(args: argparse.Namespace, scenario: str | None = None) -> None:
    """``--propeller`` and ``--line-weight`` only where the scenario (``scenario``, else
    ``args.scenario``) has the choice: one-line errors naming the option."""
    from ..errors import InputError

    scn = scenario or getattr(args, "scenario", None)
    if scn == "physical":
        return
    if getattr(args, "recovery_tension", None) == "free":
        raise InputError(f"--recovery-tension free: only the physical scenario has the winch's motor relations (the "
                         f"{scn} scenario's reel-in power is a constant; allowed: slack)")
    prop = getattr(args, "propeller", None)
    if prop is not None:
        raise InputError(f"--propeller {prop}: only the physical scenario has a propeller choice (the {scn} scenario "
                         f"uses the paper's eq. 39 fit)")
    if getattr(args, "line_weight", None):
        raise InputError(f"--line-weight: only the physical scenario has a line model (the {scn} scenario's line is "
                         f"massless)")
    lm = getattr(args, "line_model", None)
    if lm not in (None, "straight"):
        raise InputError(f"--line-model {lm}: only the physical scenario has a line model (the {scn} scenario's line "
                         f"has no drag; allowed straight)")
    gen = getattr(args, "generator", None)
    if gen is not None:
        raise InputError(f"--generator {gen}: only the physical scenario has a generator model (the {scn} scenario's "
                         f"tension is a free control)")


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
        from ..ocp.problem import SUPPLY_VOLTAGE_RANGE

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
