"""``fdm-awe fly``: fly N pumping cycles of an optimised reference in 6-DOF co-simulation.

The reference comes from ``--reference FILE`` (written by ``fdm-awe optimize``) or is optimised
first from ``--scenario/--config/--wind``. Prints a per-cycle energy table, writes JSON per
docs/design.md section 1 (``--json``), a rerun recording (``--rrd``), and optionally speaks MAVLink
(``--mavlink URL``) paced at real time (``--realtime [FACTOR]``).
Exit code 0 when the flight completed without an event (or landed in RECOVER mode).

The plant follows the scenario (``--scenario``; with ``--reference`` and no ``--scenario``, the
reference file's scenario): ``physical`` flies the JSBSim propeller and the ground station,
``paper`` the ideal thruster and kinematic winch of :mod:`fdm_awe.paper_plant` (the paper
scenario's simplifications). The JSON says which plant flew (``plant``, ``plant_note``).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

from .optimize import add_plant_model_args

HELP = "fly the optimised pumping cycle in 6-DOF (JSBSim + ground station + autopilot)"


def _flyable_bounds(gamma_max: float | None = None):
    from ..ocp.problem import Bounds

    # A reference to be flown keeps margins the optimiser's own optimum does not: C_L at most
    # 85 % of each wing's C_Lmax and the bank 0.2 rad inside the Table-3 limit, leaving the
    # autopilot room to correct. ``gamma_max`` [rad] (--gamma-max) bounds the flight-path angle
    # below Table 3's 1 rad: the paper nominal cycle at 3 m/s dives at -1 rad and climbs at +1 rad
    # within its 9.8 s recovery, which the 6-DOF glider does not follow (it stalls in the
    # climb); with 0.7 rad it is flown within 2 m RMS.
    return Bounds(cl_margin=0.85, phi_max=0.8, **({} if gamma_max is None else {"gamma_max": gamma_max}))


def _turbulence(text: str) -> tuple[str, int]:
    level, _, seed = text.partition(":")
    if level not in ("light", "moderate", "severe"):
        raise argparse.ArgumentTypeError(f"--turbulence level {level!r} unknown (allowed light, moderate, severe)")
    try:
        return level, int(seed or "1")
    except ValueError:
        raise argparse.ArgumentTypeError(f"--turbulence seed {seed!r} is not an integer") from None


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--reference", metavar="FILE", help="reference trajectory from 'fdm-awe optimize' (default: optimise one now)")
    p.add_argument("--scenario", choices=("physical", "paper"), default=None,
                   help="scenario of the reference to optimise and of the plant that flies it: physical (JSBSim propeller + "
                        "ground station) or paper (ideal thruster + kinematic winch); default physical, or the --reference file's")
    p.add_argument("--config", choices=("foldable", "nominal"), default=None,
                   help="foldable folds for recovery, nominal never folds; default foldable, or the --reference file's")
    p.add_argument("--wind", type=float, default=8.0, metavar="M/S", help="wind speed for the optimised reference (default 8)")
    p.add_argument("--wind-from", type=float, default=180.0, metavar="DEG", help="wind direction, blowing from (default 180 = south)")
    p.add_argument("--tether-drag-scale", type=float, default=None, metavar="F",
                   help="factor on the line drag of the ground station (and of the optimiser when it optimises the "
                        "reference); default: the --reference file's tether_drag_scale, else 1 = the defined line")
    add_plant_model_args(p, prefix="when it optimises the reference: ")
    p.add_argument("--gamma-max", type=float, default=None, metavar="RAD",
                   help="flight-path angle bound of the optimised reference (default 1 rad, Table 3's); 0.7 makes "
                        "the paper nominal 3 m/s cycle flyable")
    p.add_argument("--cycles", type=int, default=3, help="number of pumping cycles (default 3)")
    p.add_argument("--dt", type=float, default=1.0 / 120.0, help="co-simulation step, s (default 1/120)")
    p.add_argument("--turbulence", type=_turbulence, metavar="LEVEL[:SEED]", help="JSBSim turbulence: light|moderate|severe, seeded")
    p.add_argument("--mode", choices=("AUTO", "RECOVER"), default="AUTO", help="autopilot mode at the start (RECOVER: reel in and land)")
    p.add_argument("--json", metavar="FILE", help="write the numbers as JSON")
    p.add_argument("--rrd", metavar="FILE", help="write a rerun recording of the flight")
    p.add_argument("--out", metavar="DIR", help="write recording, plots, CSV and a markdown report into DIR")
    p.add_argument("--mavlink", metavar="URL", nargs="?", const="udpout:127.0.0.1:14550",
                   help="speak MAVLink 2 to a ground station (default URL udpout:127.0.0.1:14550)")
    p.add_argument("--realtime", metavar="FACTOR", type=float, nargs="?", const=1.0, help="pace against the wall clock (default 1x)")
    p.add_argument("--params", metavar="FILE", help="autopilot parameter file (PARAM_SET changes are saved there)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def _check(args: argparse.Namespace) -> None:
    from ..errors import InputError

    if not (1 <= args.cycles <= 1000):
        raise InputError(f"--cycles {args.cycles} out of range (allowed 1..1000)")
    if not (1e-4 <= args.dt <= 0.05) or not math.isfinite(args.dt):
        raise InputError(f"--dt {args.dt} out of range (allowed 0.0001..0.05 s)")
    if not (0.0 <= args.wind <= 25.0):
        raise InputError(f"--wind {args.wind} out of range (allowed 0..25 m/s)")
    if args.realtime is not None and not (0.0 < args.realtime <= 1000.0):
        raise InputError(f"--realtime {args.realtime} out of range (allowed > 0 and <= 1000)")
    s = getattr(args, "tether_drag_scale", None)
    if s is not None and not (math.isfinite(s) and 0.0 <= s <= 10.0):
        raise InputError(f"--tether-drag-scale {s} out of range (allowed 0..10)")
    gm = getattr(args, "gamma_max", None)
    if gm is not None and not (math.isfinite(gm) and 0.1 <= gm <= 1.5):
        raise InputError(f"--gamma-max {gm} out of range (allowed 0.1..1.5 rad)")


def load_or_optimise_reference(args: argparse.Namespace, out_dir: Path | None):
    """The tracking reference of the run and the reference file it came from."""
    from ..autopilot.tracking import TrackingReference
    from ..errors import InputError

    if args.reference:
        ref = TrackingReference.from_ocp_file(args.reference)
        if args.config is None:
            args.config = ref.meta.get("config") if ref.meta.get("config") in ("foldable", "nominal") else "foldable"
        return ref, Path(args.reference)
    args.scenario = args.scenario or "physical"
    args.config = args.config or "foldable"
    from ..ocp.problem import CycleProblem
    from ..ocp.result import write_reference
    from ..ocp.solve import solve_cycle

    b = _flyable_bounds(getattr(args, "gamma_max", None))
    scale = 1.0 if getattr(args, "tether_drag_scale", None) is None else args.tether_drag_scale
    print(f"optimising a {args.scenario} {args.config} cycle at {args.wind:g} m/s (flyable bounds: "
          f"C_L <= {b.cl_margin:g} C_Lmax, |bank| <= {b.phi_max} rad, |gamma| <= {b.gamma_max:g} rad; "
          f"line drag x {scale:g}) ...", file=sys.stderr)
    res = solve_cycle(CycleProblem(scenario=args.scenario, config=args.config, wind_speed=args.wind,
                                   wind_from_deg=args.wind_from, bounds=b, tether_drag_scale=scale,
                                   propeller=getattr(args, "propeller", None) if args.scenario == "physical" else None,
                                   line_weight=bool(getattr(args, "line_weight", False)) and args.scenario == "physical"))
    if not res.ok:
        raise InputError(f"the optimiser found no cycle: {res.status} ({getattr(res, 'reason', '')})")
    path = (out_dir or Path(".")) / f"reference_{args.scenario}_{args.config}_{args.wind:g}.json"
    write_reference(res, path)
    return TrackingReference.from_ocp_file(str(path)), path


def flight_drag_scale(meta: dict, requested: float | None, ref_path: Path) -> float:
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
        print(f"line drag x {scale:g} ({'the defined line' if scale == 1.0 else 'scaled line'}), "
              f"as {ref_path} was optimised with", file=sys.stderr)
    return scale


def run(args: argparse.Namespace) -> int:
    _check(args)
    out_dir = Path(args.out) if args.out else None
    if out_dir:
        out_dir.mkdir(parents=True, exist_ok=True)
    ref, ref_path = load_or_optimise_reference(args, out_dir)
    plant = args.scenario or (ref.meta.get("scenario") if ref.meta.get("scenario") in ("physical", "paper") else "physical")
    scale = flight_drag_scale(ref.meta, getattr(args, "tether_drag_scale", None), ref_path)
    from ..autopilot.config import autopilot_params
    from ..flight import fly
    from ..mavlink.params import ParamStore

    params = autopilot_params(store=ParamStore(args.params) if args.params else None)
    endpoint = pacer = None
    hooks = []
    holder: dict = {}

    def setup(ap, sim) -> None:
        nonlocal endpoint, pacer
        holder["ap"] = ap
        if args.mode != "AUTO":
            ap.set_mode(args.mode)
        if args.mavlink:
            from ..mavlink.endpoint import MavlinkEndpoint
            from ..mavlink.bridge import telemetry_builder

            endpoint = MavlinkEndpoint(args.mavlink, vehicle=ap)
            build = telemetry_builder(ap, sim)
            def link(k, s, o) -> None:
                build.integrate(s)
                endpoint.update(s.t, lambda: build(s, o))

            hooks.append(link)
        if args.realtime:
            from ..pacing import RealtimePacer

            pacer = RealtimePacer(args.realtime)
            hooks.append(lambda k, s, o: pacer.wait(s.t))

    n_total = int(round(args.cycles * ref.period / args.dt))
    bar = None
    if not args.quiet and sys.stderr.isatty():
        from tqdm import tqdm

        bar = tqdm(total=n_total, unit="step", desc="flying", file=sys.stderr, mininterval=0.5)
        hooks.append(lambda k, s, o: bar.update(600) if k % 600 == 0 else None)

    def on_step(k, s, o) -> None:
        for h in hooks:
            h(k, s, o)

    t0 = time.perf_counter()
    report = fly(ref, config=args.config, cycles=args.cycles, dt=args.dt, turbulence=args.turbulence,
                 on_step=on_step, params=params, setup=setup, plant=plant, tether_drag_scale=scale)
    if bar is not None:
        bar.close()
    if endpoint is not None:
        endpoint.close()
    report.wall_s = time.perf_counter() - t0
    _print_summary(report, ref_path)
    doc = report.as_json()
    doc["reference"] = str(ref_path)
    outputs = _write_outputs(args, report, ref, out_dir)
    doc.update(outputs)
    if args.json:
        Path(args.json).write_text(json.dumps(doc, indent=2, allow_nan=False, default=_nan_to_none) + "\n")
    ok = report.status == "ok" or (args.mode == "RECOVER" and report.status == "landed")
    return 0 if ok else 1


def _nan_to_none(o):  # pragma: no cover - json default hook
    return None


def _write_outputs(args, report, ref, out_dir: Path | None) -> dict:
    """Recording, plots, CSV and markdown where asked for (and where the modules exist)."""
    written: dict[str, str] = {}
    rrd = args.rrd or (str(out_dir / "flight.rrd") if out_dir else None)
    try:
        from ..recording import flight_outputs
    except ImportError:
        if rrd:
            print("fly: recording module not available; no .rrd written", file=sys.stderr)
        return written

    written.update(flight_outputs(report, ref, rrd=rrd, out_dir=out_dir))
    return written


def _print_summary(report, ref_path: Path) -> None:
    print(f"{report.scenario} / {report.config} / wind {report.wind_mps:g} m/s  reference {ref_path}  plant {report.plant}"
          f"  line drag x {report.tether_drag_scale:g}")
    print(f"status {report.status}: {report.message}; {report.sim_time_s:.1f} s simulated in {report.wall_s:.1f} s "
          f"({report.realtime_factor:.0f}x real time); energy ledger residual {report.ledger_residual_rel:.2e}")
    print(f"{'cycle':>5} {'T1 s':>6} {'T2 s':>6} {'gen J':>8} {'thrust J':>9} {'reel-in J':>9} {'net J':>8} {'rms m':>7} {'max m':>7}")
    for c in report.cycles:
        flag = "" if c.complete else "  (incomplete)"
        print(f"{c.index + 1:>5} {c.T1_s:6.2f} {c.T2_s:6.2f} {c.E_generated_J:8.1f} {c.E_thrust_J:9.1f} {c.E_reel_in_J:9.1f} "
              f"{c.E_net_J:8.1f} {c.track_rms_m:7.2f} {c.track_max_m:7.2f}{flag}")
