"""The references ``fdm-awe fly`` reads: a ``--reference`` file, a reference given in memory (the
Python API's) or a ``--references`` set, each checked against the options (the options a
reference fixes refused, its configuration and scenario, its aircraft and ground station, the
turbulence form against its wind); the line-drag factor the flight takes from it, the margins it
was optimised with (printed) and its own optimised energies."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from ..errors import InputError
from ._fly_optimise import DEFAULT_CONFIG, DEFAULT_SCENARIO
from ._model_options import wind_profile_from_args
from ._station import check_reference_definitions

#: the options a reference fixes (only used when optimising): attribute -> option
REFERENCE_FIXED = {"wind": "--wind", "wind_from": "--wind-from", "gamma_max": "--gamma-max",
                   "line": "--line", "line_model": "--line-model", "propeller": "--propeller", "line_weight": "--line-weight",
                   "generator": "--generator", "wind_profile": "--wind-profile",
                   "wind_ref_height": "--wind-ref-height", "v_min": "--v-min", "bank_rate_max": "--bank-rate-max",
                   "alpha_rate_max": "--alpha-rate-max", "catch_speed_max": "--catch-speed-max",
                   "tension_margin": "--tension-margin", "stall_margin": "--stall-margin",
                   "reel_in_margin": "--reel-in-margin"}


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


def given_reference(args: argparse.Namespace, ref: Any) -> Any:
    """A reference in memory (``ref``), checked as :func:`read_reference` checks a file: the
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


def read_reference(args: argparse.Namespace) -> Any:
    """The ``--reference`` file as a :class:`~fdm_awe.autopilot.tracking.TrackingReference` (checked field by
    field, one-line errors), its configuration and scenario against the options; ``args.config`` defaults to its."""
    from ..autopilot.tracking import TrackingReference

    return _checked_reference(args, TrackingReference.from_ocp_file(args.reference), args.reference)


def print_reference_margins(meta: dict, source: object) -> None:
    """One line on stderr: the margins the reference ``source`` (metadata ``meta``) was optimised
    with and its line model (:func:`fdm_awe.trajectory.files.margins_text`)."""
    from ..trajectory.files import margins_text

    print(f"{source}: {margins_text(meta)}; line model {meta.get('line_model', 'straight')}", file=sys.stderr)


def read_references(args: argparse.Namespace) -> tuple[Any, Any, dict[str, Any], str]:
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
