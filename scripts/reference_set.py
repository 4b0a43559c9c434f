"""A reference set for ``fdm-awe fly --references DIR``: one flyable cycle per wind.

Each point is the cycle ``fdm-awe fly`` would optimise for itself (flyable bounds: C_L at most
0.85 C_Lmax, |bank| <= 0.8 rad; one cold solve, global strategy, default mesh), written as
``DIR/reference_<scenario>_<config>_<wind>.json``; every file records the wind it was optimised
for in its metadata (``wind_mps``, ``wind_from_deg``, ``wind_profile``), which is what the
flight's scheduler reads. Usage::

    python scripts/reference_set.py --wind 8,10,12 --config nominal --out runs/refs_nominal
    python scripts/reference_set.py --wind 6,8 --config nominal --wind-profile log:0.1 --out runs/refs_log

``--files A.json,B.json`` gathers references optimised before (``fdm-awe optimize --trajectory``)
into the set instead, checked as a set first (one cycle family, one reference per wind)::

    python scripts/reference_set.py --files tests/data/ref_physical_nominal_8mps_sized.json,tests/data/ref_physical_nominal_12mps_sized.json --out runs/refs_8_12

Prints one line per point; exit 0 when every point was optimised, 1 when one failed (the
others are written), 2 on bad input (before any work).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from fdm_awe.errors import EXIT_INPUT, InputError
from fdm_awe.fileio import atomic_write_bytes


def _winds(text: str) -> list[float]:
    """``--wind``: a comma list of speeds [m/s], each 0..25."""
    try:
        winds = [float(w) for w in text.split(",") if w.strip()]
    except ValueError:
        raise InputError(f"--wind {text}: not a comma list of numbers (e.g. 8,10,12)") from None
    if not winds or any(not 0.0 <= w <= 25.0 for w in winds):
        raise InputError(f"--wind {text}: each speed 0..25 m/s, at least one")
    return winds


def _gather(files: list[str], out: Path) -> int:
    """Copy the reference ``files`` into the set's folder ``out``, checked as a set first."""
    from fdm_awe.autopilot.schedule import ReferenceSet, scheduled
    from fdm_awe.autopilot.tracking import TrackingReference

    paths = [Path(f) for f in files if f.strip()]
    for f in paths:
        if not f.is_file():
            raise InputError(f"--files {f}: no such file")
    refs = ReferenceSet([scheduled(TrackingReference.from_ocp_file(f), str(f)) for f in paths])
    if out.exists() and not out.is_dir():
        raise InputError(f"--out {out}: not a folder")
    out.mkdir(parents=True, exist_ok=True)
    for e in refs.entries:
        atomic_write_bytes(out / Path(e.source).name, Path(e.source).read_bytes())
        print(f"{e.wind_mps:g} m/s: {e.source} -> {out / Path(e.source).name}")
    return 0


def main(argv: list[str] | None = None) -> int:
    from fdm_awe.commands._fly_optimise import flyable_bounds
    from fdm_awe.commands._model_options import add_wind_profile_args, wind_profile_from_args

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--wind", metavar="LIST", help="wind speeds [m/s] to optimise, comma list, each 0..25")
    src.add_argument("--files", metavar="LIST", help="reference files to gather into the set, comma list")
    p.add_argument("--wind-from", type=float, default=180.0, metavar="DEG", help="wind direction, from (default 180)")
    p.add_argument("--config", choices=("nominal", "foldable"), default="nominal")
    p.add_argument("--scenario", choices=("physical", "paper"), default="physical")
    p.add_argument("--out", required=True, metavar="DIR", help="folder of the reference files (created)")
    add_wind_profile_args(p)
    args = p.parse_args(argv)
    try:
        if args.files is not None:
            return _gather(args.files.split(","), Path(args.out))
        winds = _winds(args.wind)
        if not -360.0 <= args.wind_from <= 360.0:
            raise InputError(f"--wind-from {args.wind_from:g}: out of range (allowed -360..360 deg)")
        profile = wind_profile_from_args(args, args.scenario)
        out = Path(args.out)
        if out.exists() and not out.is_dir():
            raise InputError(f"--out {out}: not a folder")
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    from fdm_awe.ocp.problem import CycleProblem
    from fdm_awe.ocp.solve import solve_cycle
    from fdm_awe.trajectory import write_reference

    out.mkdir(parents=True, exist_ok=True)
    failed = []
    for w in winds:
        problem = CycleProblem(scenario=args.scenario, config=args.config, wind_speed=w, wind_from_deg=args.wind_from,
                               bounds=flyable_bounds(), wind_profile=profile).validate()
        t0 = time.perf_counter()
        res = solve_cycle(problem)
        if not res.ok:
            failed.append(w)
            print(f"{w:g} m/s: no cycle ({res.status})", file=sys.stderr)
            continue
        path = write_reference(res, out / f"reference_{args.scenario}_{args.config}_{w:g}.json")
        print(f"{w:g} m/s: {res.P_avg_W:+.1f} W, period {res.T1_s + res.T2_s:.1f} s, "
              f"{time.perf_counter() - t0:.0f} s -> {path}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
