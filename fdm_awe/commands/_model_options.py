"""The options of the model an optimised cycle is solved on that the commands which optimise
share (optimize, fly, compare, sweep): the plant (``--generator``, ``--line``, ``--line-model``,
``--propeller``, ``--line-weight``), checked against the scenario, and the wind over height
(``--wind-profile``, ``--wind-ref-height``)."""

from __future__ import annotations

import argparse


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
