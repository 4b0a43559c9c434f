"""The bounds options of an optimised cycle that the commands which optimise share (optimize, fly,
sweep): the reference's smoothness (``--bank-rate-max``, ``--alpha-rate-max``,
``--catch-speed-max``) and its margins below the line's rating, the stall and the drive's fastest
reel-in (``--tension-margin``, ``--stall-margin``, ``--reel-in-margin``), as
:class:`~fdm_awe.ocp.problem.Bounds` fields."""

from __future__ import annotations

import argparse
from typing import Any

from ._station import station_from_args


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
