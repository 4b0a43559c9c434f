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
import sys
from pathlib import Path
from typing import Any

from .. import defaults as D
from ..errors import EXIT_INTERRUPTED, InputError
from ..fileio import write_json
from ._aircraft import add_aircraft_arg, aircraft_from_args
from ._station import add_station_arg, station_from_args
from . import _checks as chk
from ._bound_options import add_margin_args, add_smoothness_args, margin_bounds, smoothness_bounds
from ._fly_hooks import boot_beacon, fly_with_hooks, open_mavlink, stay_on_link
from ._fly_optimise import (DEFAULT_CONFIG, DEFAULT_SCENARIO, DEFAULT_WIND_FROM_DEG, DEFAULT_WIND_MPS,
                            FLY_REEL_IN_MARGIN, FLY_STALL_MARGIN, FLY_TENSION_MARGIN, optimised_reference,
                            reference_file_name, reference_problem)
from ._fly_reference import (FLIGHT_WIND, REFERENCE_FIXED, flight_drag_scale, given_reference, optimised_energies,
                             print_reference_margins, read_reference, read_references)
from ._fly_summary import print_summary, written_files
from ._model_options import add_plant_model_args, add_wind_profile_args, check_plant_args, wind_profile_from_args
from .optimize import NOMINAL_DEFAULT_WHY

# The modules of the work (the optimiser, JSBSim, numba, the recordings, MAVLink) are imported in
# the functions that use them: the command line imports every command module at its start.

HELP = "fly the optimised pumping cycle in 6-DOF (JSBSim + ground station + autopilot)"


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
    _add_run_arguments(p)


def _add_run_arguments(p: argparse.ArgumentParser) -> None:
    """How the flight runs: progress, the compiled loop, a live view."""
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--compiled", choices=("auto", "yes", "no"), default="auto",
                   help="the flight's loop: numba's compiled kernels (yes: compiled now when not cached, about 35 s "
                        "once), the same functions as Python (no), or auto: compiled when cached, or when compiling "
                        "pays for a long flight, else Python, said on the standard error (default auto)")
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


def run(args: argparse.Namespace, given: Any = None, result: dict[str, Any] | None = None) -> int:
    """``fdm-awe fly``: returns the exit code. ``given``: a reference in memory (a
    :class:`~fdm_awe.autopilot.tracking.TrackingReference`, the Python API's) flown as a
    ``--reference`` file would be, with the same checks; ``result``: filled with the flight's
    ``report`` and the ``reference`` flown (the Python API's results)."""
    _check(args)
    ref = problem = refs = flight_wind = None
    if args.references:
        refs, ref, flight_wind, args.reference_flown = read_references(args)
    elif given is not None:
        ref = given_reference(args, given)
    elif args.reference:
        ref = read_reference(args)
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
    link = open_mavlink(args)  # the MAVLink transport: a ground station that is not there is said now
    beacon = boot_beacon(args, link)  # a heartbeat each second until the flight's endpoint takes the link
    stay: list[Any] = []  # the endpoint kept on the link after the flight (--mavlink without --exit-after-cycles)
    try:
        if ref is None:
            ref, ref_path, ref_label = optimised_reference(args, problem, out_dir)
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
        from ..sim.first_use import choose, flight_loop

        loop = choose(getattr(args, "compiled", "auto"), args.tether, args.cycles * ref.period)
        with flight_loop(loop):
            report = fly_with_hooks(args, ref, params, plant, scale, live, link, refs, flight_wind, beacon, stay)
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
        print_summary(report, ref_label, optimised)
        code = _finish(args, report, ref, ref_path, out_dir, optimised)
        if stay:
            stay_on_link(*stay)
    finally:
        if stay:
            stay[0].close()
    return code


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
    listed = written_files(written, optimised_ref, args.json)
    if listed:
        print("wrote: " + ", ".join(listed))
    if cut:
        return EXIT_INTERRUPTED
    return report.exit_code
