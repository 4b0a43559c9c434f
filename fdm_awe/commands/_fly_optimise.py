"""The reference ``fdm-awe fly`` optimises when it is given none: the effective defaults of the
options that shape it, the flyable bounds (margins below the line's rating, the stall and the
bank limit that leave the autopilot room to correct), the problem, the optimisation with its
progress line, and the reference handed to the flight in memory (its file written only into
``--out``)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from .. import defaults as D
from ..errors import InputError
from ._aircraft import aircraft_from_args
from ._bound_options import margin_bounds, smoothness_bounds
from ._model_options import wind_profile_from_args
from ._station import station_from_args

#: effective defaults of the options that shape the optimised reference (None on the command
#: line means "not given", so that ``--reference`` can refuse them)
DEFAULT_WIND_MPS = D.WIND_MPS
DEFAULT_WIND_FROM_DEG = D.WIND_FROM_DEG
DEFAULT_CONFIG = D.CONFIG
DEFAULT_SCENARIO = D.SCENARIO


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
    # ``cl_margin`` (:func:`fdm_awe.commands._bound_options.margin_bounds`; None: fly's defaults).
    if margins is None:
        margins = {"tension_margin": FLY_TENSION_MARGIN, "cl_margin": 1.0 - FLY_STALL_MARGIN}
        if FLY_REEL_IN_MARGIN > 0.0:
            from ._bound_options import drive_reel_in_speed

            margins["reel_in_speed_max"] = drive_reel_in_speed() / (1.0 + FLY_REEL_IN_MARGIN)
    m = dict(margins)
    return Bounds(phi_max=D.FLYABLE_PHI_MAX, **m, **({} if gamma_max is None else {"gamma_max": gamma_max}),
                  **({} if v_min is None else {"V_min": v_min}), **(smoothness or {}))


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


def optimised_reference(args: argparse.Namespace, problem: Any, out_dir: Path | None) -> tuple[Any, Path | None, str]:
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
