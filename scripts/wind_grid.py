#!/usr/bin/env python
"""Flights in real wind: stored references x air x turbulence seeds, on Dask.

Each reference (default: the stored sized-line physical cycles of both gliders at 8, 10 and
12 m/s, optimised with fly's flyable bounds) is flown by the autopilot for ``--cycles`` cycles in each air condition (``calm``, or a
``fly --turbulence`` form without its seed: ``light``, ``moderate``, ``iec:A`` ...) with seeds
``1..--seeds``, each flight one Dask task (processes). Per flight: status, complete cycles,
mean net energy per complete cycle [J], mean tracking RMS [m], peak line tension [N] and peak
armature current [A]; per reference and air: flights that completed every cycle, parked ones,
the largest tension and current against the ratings (50 N, 1.2 x 50 N in calm and light air;
24.2 A peak). Prints the markdown table and writes the rows as JSON (atomically). ``--set``
flies every flight with autopilot parameters changed from their definition
(``aircraft/glider_foldable/autopilot.xml``), each checked against it before any flight.

Usage: python scripts/wind_grid.py [--refs FILE,FILE] [--air calm,light,moderate] [--seeds 3]
                                   [--cycles 3] [--workers 2] [--tether straight|lumped:N|rigid]
                                   [--set NAME=VALUE,...] [--json FILE] [--report FILE]
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from pathlib import Path
from typing import Any

os.environ.setdefault("JSBSIM_DEBUG", "0")
os.environ.setdefault("MPLBACKEND", "Agg")

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))

from study_args import add_outputs, check_outputs  # noqa: E402

REFS = tuple(f"tests/data/ref_physical_{config}_{wind}mps_sized.json" for config in ("nominal", "foldable")
             for wind in (8, 10, 12))


def flight(ref_path: str, air: str, seed: int, cycles: int, tether: str = "straight",
           params: dict[str, float] | None = None) -> dict[str, Any]:
    """One flight of the reference ``ref_path`` in ``air`` (``calm`` or a turbulence form) with
    turbulence seed ``seed``, ``cycles`` cycles, on the line model ``tether`` (``--tether``), the
    autopilot's ``params`` changed (``--set``); its row."""
    import numpy as np

    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.flight import fly

    from fdm_awe.turbulence import Turbulence

    ref = TrackingReference.from_ocp_file(ref_path)
    turb = None if air == "calm" else Turbulence.parse(f"{air}:{seed}")

    def setup(autopilot: Any, sim: Any) -> None:
        for name, value in (params or {}).items():
            ok, why = autopilot.params.try_set(name, value)
            if not ok:
                raise ValueError(f"--set {name}={value:g}: {why}")

    rep = fly(ref, config=ref.meta.get("config", "nominal"), cycles=cycles, turbulence=turb, tether=tether,
              setup=setup)
    done = [c for c in rep.cycles if c.complete]
    tension = rep.result.tension
    return {"reference": Path(ref_path).name, "air": air, "seed": seed if air != "calm" else None,
            "status": rep.status, "cycles_complete": len(done), "cycles": cycles,
            "E_net_J": float(np.mean([c.E_net_J for c in done])) if done else math.nan,
            "track_rms_m": float(np.mean([c.track_rms_m for c in done])) if done else math.nan,
            "peak_tension_N": float(np.nanmax(tension)) if len(tension) else math.nan,
            "peak_current_A": float(rep.peak_current_A), "message": rep.message}


def table(rows: list[dict[str, Any]]) -> str:
    """The markdown summary of ``rows``: one line per reference and air."""
    lines = ["| reference | air | flights complete | parked | other | net J/cycle (mean of complete) | "
             "tracking RMS m | peak tension N | peak current A |", "|---|---|---|---|---|---|---|---|---|"]
    keys: list[tuple[str, str]] = []
    for r in rows:
        if (r["reference"], r["air"]) not in keys:
            keys.append((r["reference"], r["air"]))
    for ref, air in keys:
        g = [r for r in rows if r["reference"] == ref and r["air"] == air]
        ok = [r for r in g if r["cycles_complete"] == r["cycles"]]
        parked = sum(r["status"] == "parked" for r in g)
        nets = [r["E_net_J"] for r in g if not math.isnan(r["E_net_J"])]
        rms = [r["track_rms_m"] for r in g if not math.isnan(r["track_rms_m"])]
        lines.append(f"| {ref} | {air} | {len(ok)} of {len(g)} | {parked} | {len(g) - len(ok) - parked} | "
                     f"{(sum(nets) / len(nets)) if nets else math.nan:.0f} | "
                     f"{(sum(rms) / len(rms)) if rms else math.nan:.1f} | "
                     f"{max(r['peak_tension_N'] for r in g):.1f} | {max(r['peak_current_A'] for r in g):.1f} |")
    return "\n".join(lines)


def parse_settings(text: str) -> dict[str, float]:
    """``--set NAME=VALUE,...`` as a dict, each checked against the autopilot's definition (a
    one-line InputError naming ``--set``, the parameter and its allowed range)."""
    from fdm_awe.autopilot.config import autopilot_params
    from fdm_awe.errors import InputError

    out: dict[str, float] = {}
    if not text.strip():
        return out
    store = autopilot_params()
    for item in text.split(","):
        name, sep, value = item.strip().partition("=")
        try:
            v = float(value)
        except ValueError:
            v = math.nan
        if not sep or not math.isfinite(v):
            raise InputError(f"--set {item.strip()!r}: expected NAME=VALUE with a finite number")
        ok, why = store.try_set(name.strip(), v)
        if not ok:
            raise InputError(f"--set {item.strip()}: {why} (aircraft/glider_foldable/autopilot.xml)")
        out[name.strip()] = v
    return out


def main(argv: list[str] | None = None) -> int:
    from fdm_awe.errors import InputError

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--refs", default=",".join(REFS), help="reference files (comma list)")
    ap.add_argument("--air", default="calm,light,moderate", help="calm and turbulence forms without seed (comma list)")
    ap.add_argument("--seeds", type=int, default=3, help="turbulence seeds 1..N per form, 1..100 (default 3)")
    ap.add_argument("--cycles", type=int, default=3, help="cycles per flight, 1..10 (default 3)")
    ap.add_argument("--workers", type=int, default=2, help="Dask worker processes, 1..64 (default 2)")
    ap.add_argument("--tether", default="straight", help="line model as fly's --tether (default straight; e.g. lumped:30)")
    ap.add_argument("--set", default="", metavar="NAME=VALUE,...",
                    help="autopilot parameters changed for every flight (comma list; default none)")
    add_outputs(ap)
    args = ap.parse_args(argv)
    try:
        from fdm_awe.turbulence import Turbulence

        refs = [str((Path.cwd() / p).resolve()) if not Path(p).is_absolute() else p for p in args.refs.split(",")]
        for p in refs:
            if not Path(p).is_file():
                raise InputError(f"--refs {p}: no such reference file")
        air = [a.strip() for a in args.air.split(",")]
        for a in air:
            if a != "calm":
                Turbulence.parse(f"{a}:1", "--air")
        for opt, v, hi in (("--seeds", args.seeds, 100), ("--cycles", args.cycles, 10), ("--workers", args.workers, 64)):
            if not 1 <= v <= hi:
                raise InputError(f"{opt} {v}: out of range (allowed 1..{hi})")
        from fdm_awe.groundstation.linemodels import parse_tether

        parse_tether(args.tether)
        params = parse_settings(args.set)
        check_outputs(args)
    except InputError as e:
        print(f"wind_grid: error: {e}", file=sys.stderr)
        return 2
    import dask
    from dask import delayed

    tasks = [delayed(flight)(r, a, s, args.cycles, args.tether, params) for r in refs for a in air
             for s in ([1] if a == "calm" else range(1, args.seeds + 1))]
    rows = list(dask.compute(*tasks, scheduler="processes" if args.workers > 1 else "sync",
                             num_workers=args.workers))
    text = table(rows)
    print(text)
    from fdm_awe.fileio import atomic_write_text, write_json

    if args.json:
        write_json(args.json, {"cycles": args.cycles, "seeds": args.seeds, "tether": args.tether, "params": params,
                               "rows": rows})
    if args.report:
        atomic_write_text(args.report, text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
