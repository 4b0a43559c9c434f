"""``fdm-awe sweep``: power curves and design sweeps of the pumping cycle on Dask.

Each point is one periodic-cycle optimisation; points of a line (same design, varying wind)
are warm-started from their neighbour. Every finished point is written at once to
``OUT/points/<id>.json``: rerunning the same command computes only the missing points.

Outputs in ``OUT``: ``points.csv`` (every point, failed ones with their reason),
``power_curve.png``, ``folding_map.png``, ``summary.md``; ``--json FILE`` writes the numbers.

``--fly`` flies every optimised point in 6-DOF (:mod:`fdm_awe.sweep.flown`, one Dask task per
flight, stored in ``OUT/flights/`` and resumed like the points) and writes the power-curve
report (:mod:`fdm_awe.sweep.curve_report`: ``power_curve.csv``, ``power_curve_flown.png``,
``power_curve.md``); ``--yield`` adds the energy yield at a site (``yield.csv``,
:mod:`fdm_awe.sweep.energy_yield`), also from a finished folder with ``--report-only``. Exit 1
also when some flights have no result.

Warm-started points are also solved cold with the optimiser's global strategy and keep the
better solution (``--no-cold-check`` turns this off); the summary lists every point where the
two differ by more than 0.5 W.

Every option is checked before the cluster starts (numbers in range, list items not empty,
``--scheduler`` a ``[SCHEME://]HOST:PORT`` address whose host resolves, ``--out``/``--json``
writable); bad input is one line and exit 2. ``--out`` is locked while the sweep runs: a second
sweep into it is refused (exit 2). The outputs are written atomically; the JSON writes NaN as
``null``.

``--compare OTHER_DIR`` solves nothing: it compares the points of ``--out`` with those of
another sweep's folder (:mod:`fdm_awe.sweep.compare`; exit 0 when they agree within 0.5 W or
every difference is explained by the records, 1 otherwise).

Exit codes: 0 when every point of the sweep has a result (converged or failed: failed points
are counted, listed and do not change the exit code); 1 when some points have no result (a
worker died, ``--stop-after``); 2 on bad input; 130 on Ctrl-C: the cluster is shut down
quietly (no tracebacks) and the points finished so far are kept for a rerun.
"""

from __future__ import annotations

import argparse
import math
from typing import Any

from ._aircraft import add_aircraft_arg
from ._bound_options import add_margin_args, margin_bounds
from ._model_options import add_plant_model_args, add_wind_profile_args, check_plant_args, wind_profile_from_args
from ._station import add_station_arg, station_from_args

HELP = "power curves and design sweeps (wind x folded span x ...) of the pumping cycle on Dask"


def add_arguments(p: argparse.ArgumentParser) -> None:
    from .. import defaults as D

    p.add_argument("--wind", default=D.SWEEP_WINDS, metavar="SPEC",
                   help=f"wind speeds [m/s], each 0..25: START:STOP:STEP or a comma list (default {D.SWEEP_WINDS})")
    p.add_argument("--config", default=D.SWEEP_CONFIGS, help=f"configurations: nominal,foldable (default {D.SWEEP_CONFIGS})")
    add_aircraft_arg(p, "the glider of every point (its design axes vary it; a changed folder's points are new points)")
    add_station_arg(p, "the ground station of every point (a changed file's points are new points)")
    p.add_argument("--scenario", default=D.SCENARIO, choices=("physical", "paper"),
                   help=f"scenario family (default {D.SCENARIO})")
    p.add_argument("--folded-span", metavar="LIST", help="folded spans b_f [m] (default: the folded definition's)")
    p.add_argument("--folded-drag-area", metavar="LIST", help="folded drag areas C_Dmin S_f [m2] (default: the definition's)")
    p.add_argument("--wing-area", metavar="LIST", help="unfolded wing areas [m2] at the definition's aspect ratio (default: the definition's)")
    p.add_argument("--tether-range", default=f"{D.D0_M:g}:{D.D_TF_M:g}", metavar="D0:DTF,...",
                   help=f"reel-out ranges d0:d_tf [m] (default {D.D0_M:g}:{D.D_TF_M:g})")
    p.add_argument("--fold-time", default=None, metavar="LIST",
                   help="fold (and unfold) times of the foldable glider [s], each 0..60 (default: the aircraft "
                        "definition's, 2 s; 0 = the instantaneous switch of earlier sweeps)")
    p.add_argument("--mesh", default=None, metavar="NGEN,NREC[,DEG]", help="collocation mesh (default: the optimiser's)")
    p.add_argument("--max-iter", type=int, default=None, help="IPOPT iteration limit per solve, 10..100000 (default 1000)")
    p.add_argument("--max-iter-total", type=int, default=None,
                   help="IPOPT iterations over all solves of one point, 10..1000000 (default 3000)")
    p.add_argument("--warm-fallback", default="all", choices=("all", "one", "none"),
                   help="after a failed warm start: the whole cold strategy (all, default), one cold solve from the "
                        "first start (one), or fail at once (none); with one or none, a point after a failed neighbour that "
                        "passes on no warm start also gets a single cold solve")
    p.add_argument("--anchor-every", type=int, default=0, metavar="N",
                   help="a cold-started anchor every N winds of a line, 0..1000 (more, shorter warm-start chains; "
                        "default 0: one anchor per line, the wind nearest 8 m/s)")
    p.add_argument("--line-diameter", metavar="LIST",
                   help="diameters [m] of the sized line, each 1e-05..0.005 (e.g. 0.0003,0.00045,0.0006): the line is "
                        "sized again from its material, so mass per length, breaking load and EA scale with d^2 "
                        "(a diameter whose breaking load falls below the 50 N rated tension is refused; default: as "
                        "defined, 'fdm-awe info' shows it)")
    add_plant_model_args(p, line_axis=True, generators=())
    add_wind_profile_args(p, prefix="every point: ")
    add_margin_args(p, prefix="every point: ", reel_in=False)
    p.add_argument("--workers", type=int, default=None,
                   help=f"local Dask worker processes, 1..{MAX_WORKERS} (default: number of cores; not with --scheduler)")
    p.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                   help="use this Dask scheduler ([SCHEME://]HOST:PORT, scheme tcp, tls, ws, wss or ucx) instead of a "
                        "local cluster")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder (point files, table, plots, summary)")
    p.add_argument("--json", metavar="FILE",
                   help="also write the summary numbers and every point as JSON (NaN written as null)")
    p.add_argument("--cold", action="store_true", help="solve every point cold (no warm starts along the wind axis)")
    p.add_argument("--no-cold-check", action="store_true",
                   help="warm-started points are not also solved cold (faster; by default each is, with the "
                        "optimiser's global strategy, and keeps the better solution; the summary lists the points "
                        "where the two differ by more than 0.5 W)")
    p.add_argument("--retry-failed", action="store_true", help="recompute points recorded as failed")
    p.add_argument("--stop-after", type=int, default=None, metavar="N",
                   help="stop after N >= 1 newly finished points (as an interruption would; for testing resume)")
    p.add_argument("--report-only", action="store_true",
                   help="compute nothing: write the outputs from the points already finished in --out")
    p.add_argument("--compare", metavar="OTHER_DIR",
                   help="compute nothing: compare the points in --out with those in OTHER_DIR (another sweep's --out), "
                        "matched by their physical identity; prints both powers and the difference per point, flags "
                        "differences over 0.5 W with their explanation from the records; --json writes the comparison; "
                        "exit 0 when every point agrees or is explained, 1 otherwise")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    g = p.add_argument_group("flown power curve (--fly) and energy yield (--yield); see docs/sweep.md")
    g.add_argument("--fly", action="store_true",
                   help="fly every optimised point in 6-DOF with the autopilot (one Dask task per flight, stored in "
                        "OUT/flights/, resumed like the points); the points are then optimised with fly's flyable "
                        "bounds (--bounds flyable)")
    g.add_argument("--bounds", default=None, choices=("table3", "flyable"),
                   help="bounds of every optimisation: table3 (the optimiser's own) or flyable (fly's: |bank| <= 0.8 rad "
                        "and fly's margins, C_L <= 0.85 C_Lmax and tension <= rating / 1.25, where --stall-margin / "
                        "--tension-margin are not given); default flyable with --fly, table3 otherwise")
    g.add_argument("--fly-cycles", type=int, default=3, metavar="K", help="cycles per flight, 1..20 (default 3)")
    g.add_argument("--fly-seeds", type=int, default=5, metavar="S",
                   help="turbulence seeds 1..S per point, S 1..100 (default 5; calm air is flown once)")
    g.add_argument("--fly-air", default="light", metavar="AIR",
                   help="calm, or a turbulence form without seed: light, moderate, severe, milspec:SEVERITY, "
                        "iec:CLASS (default light)")
    g.add_argument("--fly-tether", default="straight", metavar="MODEL",
                   help="line model of the flights: a --tether form of fly (default straight)")
    g.add_argument("--fly-stop-after", type=int, default=None, metavar="N",
                   help="stop after N >= 1 newly flown flights (as an interruption would; for testing resume)")
    g.add_argument("--yield", dest="yield_", action="append", metavar="DIST",
                   help="energy yield of the curves at a site: rayleigh:MEAN[,MEAN...] (annual means, m/s) or "
                        "weibull:K:C (shape, scale m/s); may be repeated; works with --report-only on a finished sweep")
    g.add_argument("--yield-height", type=float, default=None, metavar="M",
                   help="height [m] of the site's wind distribution, 1..1000 (default: the sweep's reference height, "
                        "10 m)")
    g.add_argument("--yield-profile", default=None, metavar="KIND",
                   help="wind profile carrying the site's wind to the curve's height: log:Z0 or power:ALPHA "
                        "(default: the sweep's --wind-profile; uniform: no change with height)")
    g.add_argument("--yield-clip", default="positive", choices=("positive", "none"),
                   help="positive (default): not operated where the net power is <= 0 (it would buy energy to fly); "
                        "none: negative power counts as negative")
    g.add_argument("--rated-power", type=float, default=None, metavar="W",
                   help="rated power [W] for the capacity factor and the rated wind, > 0 and <= 100000 (default: the "
                        "curve's largest power)")


#: ``--rated-power`` upper limit [W] (a rated power far beyond any glider of this package)
RATED_POWER_MAX_W = 1e5

#: ``--workers`` upper limit (local worker processes)
MAX_WORKERS = 1024


def check_args(args: argparse.Namespace) -> None:
    """The integer options and ``--scheduler`` (one-line errors naming the option); the
    ``--aircraft`` folder's files first."""
    from ..errors import InputError
    from ..sweep.spec import ANCHOR_EVERY_RANGE, MAX_ITER_RANGE, MAX_ITER_TOTAL_RANGE
    from . import _checks as chk
    from ._aircraft import aircraft_from_args

    aircraft_from_args(args), station_from_args(args)  # their files checked first

    chk.integer(args.max_iter, "--max-iter", *MAX_ITER_RANGE, what="IPOPT iterations per solve")
    chk.integer(args.max_iter_total, "--max-iter-total", *MAX_ITER_TOTAL_RANGE, what="IPOPT iterations per point")
    chk.integer(args.anchor_every, "--anchor-every", *ANCHOR_EVERY_RANGE, what="winds between anchors")
    chk.integer(args.workers, "--workers", 1, MAX_WORKERS, what="local worker processes")
    chk.integer(args.stop_after, "--stop-after", 1, None, what="newly finished points")
    chk.integer(getattr(args, "fly_stop_after", None), "--fly-stop-after", 1, None, what="newly flown flights")
    chk.scheduler_address(args.scheduler)
    from ..sweep.energy_yield import HEIGHT_RANGE

    chk.number(getattr(args, "yield_height", None), "--yield-height", *HEIGHT_RANGE, unit="m", what="height")
    if getattr(args, "rated_power", None) is not None and not (math.isfinite(args.rated_power)
                                                                and 0 < args.rated_power <= RATED_POWER_MAX_W):
        raise InputError(f"--rated-power {args.rated_power:g}: out of range (allowed > 0 and <= {RATED_POWER_MAX_W:g} W)")
    if args.scheduler is not None and args.workers is not None:
        raise InputError("--workers: not with --scheduler (the external cluster has its own workers)")


def design_axes(args: argparse.Namespace) -> dict[str, tuple]:
    """The design axes of the command line, each value in its range with the option named in
    the error: ``--wing-area`` (:data:`~fdm_awe.sweep.design.WING_AREA_RANGE`),
    ``--folded-drag-area`` (above 0, below :data:`~fdm_awe.sweep.design.FOLDED_DRAG_AREA_MAX`),
    ``--fold-time`` (0 .. the aircraft's longest fold), ``--folded-span`` (above 0, at most the
    unfolded span at every wing area of the sweep); ``(None,)`` for an option not given."""
    from ..definitions.aircraft import FOLD_TIME_MAX_S
    from ..errors import InputError
    from ..sweep.design import FOLDED_DRAG_AREA_MAX, WING_AREA_RANGE, unfolded_span
    from ..sweep.spec import parse_floats

    def axis(text: str | None, option: str, unit: str, *rng, **ends) -> tuple:
        return (None,) if text is None else parse_floats(text, option, unit, *rng, **ends)

    out = {"wing_areas": axis(args.wing_area, "--wing-area", "m2", *WING_AREA_RANGE),
           "folded_drag_areas": axis(args.folded_drag_area, "--folded-drag-area", "m2", 0.0, FOLDED_DRAG_AREA_MAX,
                                     lo_open=True, hi_open=True),
           "fold_times": axis(args.fold_time, "--fold-time", "s", 0.0, FOLD_TIME_MAX_S),
           "folded_spans": axis(args.folded_span, "--folded-span", "m", 0.0, None, lo_open=True)}
    if args.folded_span is not None:  # a folded wing no longer than the unfolded one, at every wing area
        from ..sweep.runner import base_glider

        base = base_glider(_aircraft_fields(args)["aircraft"])
        for S in out["wing_areas"]:
            b_u = unfolded_span(base, S)
            for b in out["folded_spans"]:
                if b > b_u:
                    at = "the definition's wing area" if S is None else f"--wing-area {S:g} m2"
                    raise InputError(f"--folded-span {args.folded_span!r}: {b:g} m out of range (allowed > 0 and <= "
                                     f"the unfolded span {b_u:.4g} m at {at})")
    return out


def _aircraft_fields(args: argparse.Namespace) -> dict[str, str | None]:
    """The spec's ``aircraft`` and ``aircraft_sha256`` of ``--aircraft`` (both None for the
    package's glider: its points keep their ids)."""
    from ._aircraft import aircraft_from_args

    a = aircraft_from_args(args)
    if a.builtin and a.name == "glider":
        return {"aircraft": None, "aircraft_sha256": None}
    return {"aircraft": a.name if a.builtin else str(a.root), "aircraft_sha256": a.sha256}


def _station_fields(args: argparse.Namespace) -> dict[str, str | None]:
    """The spec's ``ground_station`` and ``ground_station_sha256`` of ``--ground-station`` (both
    None for the package's: its points keep their ids)."""
    st = station_from_args(args)
    if st.builtin:
        return {"ground_station": None, "ground_station_sha256": None}
    return {"ground_station": str(st.path), "ground_station_sha256": st.sha256}


def build_spec(args: argparse.Namespace):
    """The :class:`~fdm_awe.sweep.spec.SweepSpec` of the command line (canonical ids)."""
    from ..trajectory.schema import CONFIGS
    from ..sweep.runner import canonical_spec
    from ..errors import InputError
    from ..groundstation.line import LINES
    from ..sweep.runner import FLYABLE_STALL_MARGIN, FLYABLE_TENSION_MARGIN
    from ..sweep.spec import (DEFAULT_MAX_ITER, DEFAULT_MAX_ITER_TOTAL, LINE_DIAMETER_RANGE, WIND_RANGE, SweepSpec,
                              parse_floats, parse_names, parse_tether_ranges)
    from .optimize import parse_mesh

    mesh = parse_mesh(args.mesh, two=True)
    configs = parse_names(args.config, "--config", CONFIGS)
    designs = design_axes(args)

    check_plant_args(args)
    profile = wind_profile_from_args(args)
    margins = margin_bounds(args)
    # a flyable point takes fly's margins where --tension-margin / --stall-margin are not given
    bounds = args.bounds or ("flyable" if getattr(args, "fly", False) else "table3")
    diameters: tuple = (None,)
    if getattr(args, "line_diameter", None) is not None:
        from ..sweep.design import line_station

        diameters = parse_floats(args.line_diameter, "--line-diameter", "m", *LINE_DIAMETER_RANGE)
        for d in diameters:  # the sized line resized: its breaking load must reach the rated tension
            try:
                line_station("sized", d, station_from_args(args))
            except InputError as exc:
                raise InputError(f"--line-diameter {args.line_diameter!r}: {exc}") from None
    spec = SweepSpec(
        winds=parse_floats(args.wind, "--wind", "m/s", *WIND_RANGE), configs=configs,
        folded_spans=designs["folded_spans"], folded_drag_areas=designs["folded_drag_areas"],
        wing_areas=designs["wing_areas"], tether_ranges=parse_tether_ranges(args.tether_range),
        fold_times=designs["fold_times"],
        scenario=args.scenario, mesh=mesh, max_iter=args.max_iter if args.max_iter is not None else DEFAULT_MAX_ITER,
        max_iter_total=args.max_iter_total if args.max_iter_total is not None else DEFAULT_MAX_ITER_TOTAL,
        warm_fallback=args.warm_fallback, anchor_every=args.anchor_every,
        propeller=getattr(args, "propeller", None), line_weight=getattr(args, "line_weight", None),
        lines=(None,) if getattr(args, "line", None) is None else parse_names(args.line, "--line", LINES),
        line_diameters=diameters,
        # --cold has no warm starts to check: its points keep the ids of points without the check
        cold_check=not (getattr(args, "no_cold_check", False) or getattr(args, "cold", False)),
        wind_profile=profile.label(),
        tension_margin=margins["tension_margin"] if bounds == "table3" or args.tension_margin is not None
        else FLYABLE_TENSION_MARGIN,
        stall_margin=(float(args.stall_margin or 0.0) if bounds == "table3" or args.stall_margin is not None
                      else FLYABLE_STALL_MARGIN),  # checked above
        line_model=getattr(args, "line_model", None) or "straight",
        bounds=bounds, **_aircraft_fields(args), **_station_fields(args),
    ).validate()
    return canonical_spec(spec)


def run(args: argparse.Namespace) -> int:
    from . import _checks as chk

    check_args(args)
    if args.compare is not None:  # report-only: nothing is solved, the sweep options play no part
        from ..sweep.compare import run_compare

        chk.input_dir(args.out, "--out")  # both folders are inputs here
        chk.input_dir(args.compare, "--compare")
        chk.outputs(files=[("--json", args.json)])
        return run_compare(args.out, args.compare, args.json)
    spec = build_spec(args)
    extras = extra_settings(args, spec)
    check_not_in_points(args)
    locks = output_locks(args)
    with locks:  # --out locked until the last file is written: a second sweep into it is refused
        return run_checked(args, spec, extras)


def extra_settings(args: argparse.Namespace, spec) -> dict:
    """The ``--fly`` and ``--yield`` settings, checked (one-line errors naming the option)."""
    from ..sweep.energy_yield import parse_distributions
    from ..sweep.flown import FlySpec
    from ..wind import WindProfile

    # checked with or without --fly: a bad value is refused whether or not it is used
    fly = FlySpec(air=args.fly_air.strip().lower(), seeds=args.fly_seeds, cycles=args.fly_cycles,
                  tether=args.fly_tether.strip()).validate()
    if not args.fly:
        fly = None
    else:
        from ..groundstation.linemodels import parse_tether

        parse_tether(fly.tether, "--fly-tether").check_plant(spec.scenario == "paper", "--scenario paper",
                                                                   "--fly-tether")
    dists = parse_distributions(args.yield_) if args.yield_ else []
    sweep_prof = WindProfile.parse(spec.wind_profile, option="wind profile")
    prof = sweep_prof if args.yield_profile is None else WindProfile.parse(
        args.yield_profile, sweep_prof.ref_height if not sweep_prof.uniform else None, "--yield-profile")
    curve_h = float(sweep_prof.ref_height) if not sweep_prof.uniform else 10.0
    site_h = curve_h if args.yield_height is None else float(args.yield_height)
    ratio = 1.0 if prof.uniform else float(prof.factor(curve_h)) / float(prof.factor(site_h))
    return {"fly": fly, "dists": dists, "clip": args.yield_clip == "positive", "rated": args.rated_power,
            "site_height": site_h, "curve_height": curve_h, "ratio": ratio, "profile": prof}


def output_locks(args: argparse.Namespace, json_option: str = "--json", out_option: str = "--out") -> Any:
    """The sweep's outputs checked (``args.json``, the ``args.out`` folder and the files it will
    hold; errors name them ``json_option``/``out_option``): a context that keeps them locked."""
    from ..sweep.report import output_files
    from . import _checks as chk

    return chk.outputs(files=[(json_option, args.json)], dirs=[(out_option, args.out)],
                       dir_files=[(out_option, p) for p in output_files(args.out).values()])


def check_not_in_points(args: argparse.Namespace) -> None:
    """``--json`` may not go into ``OUT/points/``: the point files (any name there may be one a
    later sweep writes or reads as a point)."""
    import os
    from pathlib import Path

    from ..errors import InputError

    points = Path(os.path.realpath(args.out)) / "points"
    if args.json is not None and Path(os.path.realpath(args.json)).parent == points:
        raise InputError(f"--json {args.json}: inside the points/ folder of --out, which holds the sweep's point "
                         f"files; choose another path")


def run_checked(args: argparse.Namespace, spec, extras: dict | None = None) -> int:
    """The work of :func:`run` once every option and output is checked: solve the missing
    points (or none, ``--report-only``), write the outputs; returns the exit code."""
    from pathlib import Path

    from ..fileio import remove_stale_parts, write_json

    for sub in ("points", "flights"):  # point and flight files a killed sweep left half-written
        remove_stale_parts(Path(args.out) / sub)
    from ..sweep.execute import run_sweep
    from ..sweep.report import write_outputs

    n = len(spec.points())
    print(f"sweep: {n} points ({spec.scenario} scenario, configs {','.join(spec.configs)}, mesh "
          f"{spec.mesh.n_gen}/{spec.mesh.n_rec}/{spec.mesh.degree}) -> {args.out}", flush=True)
    if args.report_only:
        from ..sweep.execute import SweepRun
        from ..sweep.store import PointStore

        ids = [p.id for p in spec.points()]
        done = PointStore(args.out).records(ids)
        res = SweepRun(n_points=len(ids), n_cached=len(done), records=done)
    else:
        res = run_sweep(spec, args.out, workers=args.workers, scheduler=args.scheduler, retry_failed=args.retry_failed,
                        progress=not args.no_progress, stop_after=args.stop_after, warm_start=not args.cold)
    records = list(res.records.values())
    rep = write_outputs(spec, records, args.out)
    extras = extras or {"fly": None, "dists": []}
    fly_res, curve = None, None
    if extras["fly"] is not None or extras["dists"]:
        fly_res, curve = _fly_and_report(args, spec, res, records, extras, rep)
    where = f"{res.workers} worker(s) on {res.scheduler}" if res.workers else "nothing to compute"
    print(f"points: {res.n_points} total, {res.n_cached} already done, {res.n_computed} computed now "
          f"({res.n_failed_now} failed) in {res.wall_s:.1f} s with {where}")
    n_fail = res.n_failed
    if n_fail:
        print(f"failed points: {n_fail} of {len(records)} finished (reasons in points.csv and summary.md)")
    for label, reason in res.errors:
        print(f"not computed: {label}: {reason}")
    missing = res.n_points - len(records)
    if missing:
        print(f"INCOMPLETE: {missing} point(s) have no result; rerun the same command to compute them")
    print(rep.sentence)
    for k, v in rep.files.items():
        print(f"{k}: {v}")
    if args.json:
        doc = {"scenario": spec.scenario, "spec": spec.to_dict(), "n_points": res.n_points, "n_finished": len(records),
               "n_ok": len(records) - n_fail, "n_failed": n_fail, "n_cached": res.n_cached, "n_computed": res.n_computed,
               "complete": res.complete, "wall_s": res.wall_s, "workers": res.workers, "scheduler": res.scheduler,
               "answer": rep.answer, "answer_text": rep.sentence, "files": rep.files, "cold_check": rep.cold_check,
               "not_computed": [{"point": lbl, "reason": r} for lbl, r in res.errors],
               "failed": [{"id": r["id"], "config": r["config"], "wind_mps": r["wind_mps"], "b_f_m": r.get("b_f_m"),
                           "reason": r["reason"]} for r in records if r["status"] != "ok"],
               "points": records}
        if curve is not None:
            doc.update(curve)
        write_json(args.json, doc, indent=1)
    if fly_res is not None and not fly_res.complete:
        return 1
    return 0 if res.complete else 1


def _fly_and_report(args: argparse.Namespace, spec, res, records: list, extras: dict, rep):
    """Fly the missing flights (``--fly``, not with ``--report-only``), then write the
    power-curve report and the yield; returns the :class:`~fdm_awe.sweep.flown.FlyRun` (None
    without ``--fly``) and the numbers for the ``--json`` document."""
    from ..fileio import atomic_write_text
    from ..sweep.curve_report import (curve_files, curve_markdown, curve_plot, curve_rows, write_curve_csv,
                                      write_yield_csv, yields)
    from ..sweep.flown import FlyRun, run_flights

    fly = extras["fly"]
    points = spec.points()
    flights_by_point: dict = {}
    run = None
    if fly is not None:
        if args.report_only or not res.complete and args.stop_after is not None:
            from ..sweep.flown import FlightStore, flight_tasks

            tasks, skipped = flight_tasks(points, res.records, fly)
            st = FlightStore(args.out)
            done = {t.id: r for t in tasks if (r := st.load(t.id)) is not None}
            run = FlyRun(len(tasks), len(done), 0, [], done, skipped)
        else:
            run = run_flights(points, res.records, args.out, fly, workers=args.workers, scheduler=args.scheduler,
                              progress=not args.no_progress, stop_after=getattr(args, "fly_stop_after", None))
            print(f"flights: {run.n_flights} total, {run.n_cached} already done, {run.n_flown} flown now in "
                  f"{run.wall_s:.1f} s")
            for label, reason in run.errors or []:
                print(f"not flown: {label}: {reason}")
        for r in (run.records or {}).values():
            flights_by_point.setdefault(r["point_id"], []).append(r)
        if not run.complete:
            print(f"INCOMPLETE: {run.n_flights - len(run.records or {})} flight(s) have no result; rerun the same "
                  f"command to fly them")
    files = curve_files(args.out)
    rows = curve_rows(records, flights_by_point, fly, rep.refs)
    write_curve_csv(rows, files["curve_table"])
    title = f"{spec.scenario} scenario, bounds {spec.bounds}" + (
        "" if fly is None else f", flown {fly.cycles} cycles, {fly.air}" + ("" if fly.air == "calm" else f" x {fly.seeds} seeds")
        + ("" if fly.tether == "straight" else f", line {fly.tether}"))
    curve_plot(rows, files["curve_plot"], title, "wind speed [m/s]" if spec.wind_profile == "uniform"
               else f"wind speed at {extras['curve_height']:g} m [m/s]")
    ys = None
    note = ""
    if extras["dists"]:
        ys = yields(rows, extras["dists"], clip=extras["clip"], rated_power_W=extras["rated"], height_ratio=extras["ratio"])
        write_yield_csv(ys, extras["site_height"], files["yield_table"])
        prof = extras["profile"]
        note = (f"Site distributions at {extras['site_height']:g} m; the curve's winds hold at "
                f"{extras['curve_height']:g} m; wind profile {prof.describe() if not prof.uniform else 'uniform'} "
                f"(site speeds x {extras['ratio']:.4f} at the curve's height). Linear interpolation between curve "
                f"points; not operated (zero) outside the curve's wind range"
                + ("; not operated where the net power is <= 0 (--yield-clip positive, the default: a system that "
                   "loses energy at a wind speed is not run there)" if extras["clip"]
                   else "; negative net power counted as negative (--yield-clip none)")
                + f". AEP = mean power x 8766 h. Capacity factor against "
                + (f"the rated power {extras['rated']:g} W." if extras["rated"] else "each curve's largest power."))
    skipped = [] if run is None else [f"{p.label()}: {why}" for p, why in (run.skipped or [])]
    md = curve_markdown(rows, records, fly, ys, note, skipped, extras["rated"])
    atomic_write_text(files["curve_report"], md)
    for k in ("curve_table", "curve_plot", "curve_report") + (("yield_table",) if ys else ()):
        print(f"{k}: {files[k]}")
    if ys:
        for name, source, y in ys:
            print(f"yield {source} {name} {y.distribution}: {y.mean_power_W:.3f} W, {y.aep_kWh:.2f} kWh/yr"
                  + ("" if y.capacity_factor is None else f", CF {y.capacity_factor:.3f}")
                  + (" (curve outside the distribution's mass)" if y.outside_mass else ""))
    curve = {"power_curve": rows, "fly": None if fly is None else fly.as_dict(),
             "flights": None if run is None else {"n_flights": run.n_flights, "n_cached": run.n_cached,
                                                  "n_flown": run.n_flown, "complete": run.complete},
             "yield": None if not ys else [{"curve": n, "source": src, **y.as_dict()} for n, src, y in ys]}
    return run, curve
