#!/usr/bin/env python
"""The drive as design data: supply voltage x folded span x wind, and the co-design of the
winch's supply voltage at one wind.

Usage: python scripts/drive_map.py [--supply-voltage 24,36,48] [--folded-span 0.22,0.44,0.66]
       [--wind 8,10,12] [--codesign-wind 10] [--out runs/drive] [--workers 1]

For each supply voltage a ground-station variant of the package's definition (or of
``--ground-station FILE``) is written to ``OUT/stations/ground_station_<V>V.xml``
(:mod:`fdm_awe.groundstation.variants`: the supply, and the speed controller's gains scaled for
it; what the drive allows follows from the file through the ground station's own relations),
and ``fdm-awe sweep --ground-station`` that file solves the grid (the nominal glider and the
foldable one at each folded span, each wind) into ``OUT/<V>V/``. A rerun reuses every finished
point (same files, same point ids).

``--codesign-wind W`` adds the co-design of the supply voltage at wind ``W`` for the foldable
glider at ``--codesign-span`` (default: the folded definition's span):
:func:`fdm_awe.sweep.codesign.supply_search`, the grid's voltages, then bisection of the edge of
the power's plateau. Each voltage is a one-point sweep into ``OUT/codesign/<V>V/`` (a cold
solve: the optimiser's global strategy), and at a grid voltage the better of it and the grid's
point (warm-started along the wind) counts, as the sweep's cold check keeps the better of two. Its module docstring says why a search over solves and what it
guarantees.

Outputs in ``OUT``: ``drive_map.md`` (the power table with ``dP`` against the nominal glider on
the same drive, the drive's gain per m/s of reel-in where it binds, the co-design) and
``drive_map.json`` (the same numbers, the command line, the stations' files and hashes). Bad
input: one line naming the option and its allowed range, exit 2, before any solve.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from pathlib import Path
from typing import Any

os.environ.setdefault("JSBSIM_DEBUG", "0")
os.environ.setdefault("MPLBACKEND", "Agg")

from fdm_awe.errors import InputError  # noqa: E402
from fdm_awe.fileio import atomic_write_text, check_output_dir, write_json  # noqa: E402
from fdm_awe.groundstation.variants import SUPPLY_VOLTAGE_RANGE, variant_name, write_supply_variant  # noqa: E402
from fdm_awe.sweep.codesign import PLATEAU_TOL_W, STEPS, STEPS_RANGE, supply_search  # noqa: E402
from fdm_awe.sweep.spec import parse_floats  # noqa: E402

#: the reel-in bound counts as binding where the optimum would gain at least this per m/s [W s/m]
DRIVE_BINDS_W_PER_MPS = 0.05
#: fields of a point carried into the JSON
FIELDS = ("config", "wind_mps", "b_f_m", "status", "P_avg_W", "T1_s", "T2_s", "E_reel_in_J", "drive_gain_W_per_mps",
          "binding", "supply_voltage_V", "id")


def _sweep(station: Path, out: Path, args: argparse.Namespace, *, wind: str, config: str, spans: str | None) -> int:
    """``fdm-awe sweep`` with the ground station ``station`` into ``out`` (in this process)."""
    from fdm_awe.cli import main

    argv = ["sweep", "--ground-station", str(station), "--wind", wind, "--config", config,
            "--workers", str(args.workers), "--no-progress", "--out", str(out), "--json", str(out / "sweep.json")]
    argv += ["--folded-span", spans] if spans else []
    argv += ["--mesh", args.mesh] if args.mesh else []
    argv += ["--no-cold-check"] if args.no_cold_check else []
    print("fdm-awe " + " ".join(argv), flush=True)
    return main(argv)


def _records(folder: Path) -> list[dict[str, Any]]:
    """The point records of the last sweep into ``folder`` (its ``--json`` file: the points of
    that command line only, not those of another mesh or grid kept in the same folder)."""
    f = folder / "sweep.json"
    return json.loads(f.read_text(encoding="utf-8")).get("points", []) if f.is_file() else []


def _same(a: float | None, b: float | None) -> bool:
    return a is not None and b is not None and abs(a - b) <= 1e-9 * max(1.0, abs(b))


def _find(recs: list[dict[str, Any]], config: str, wind: float, b_f: float | None) -> dict[str, Any] | None:
    for r in recs:
        if r.get("config") == config and _same(r.get("wind_mps"), wind) and (config == "nominal" or _same(r.get("b_f_m"), b_f)):
            return r
    return None


def _reel_in_max(station: Any) -> float:
    """The drive's fastest reel-in on a slack line [m/s] (the ground station's relation)."""
    from fdm_awe.groundstation.steady import motor_max_reel_in_speed

    return float(motor_max_reel_in_speed(0.0, station.load()))


def _pw(r: dict[str, Any] | None) -> str:
    return "" if r is None else ("fail" if r.get("status") != "ok" or r.get("P_avg_W") is None else f"{r['P_avg_W']:+.1f}")


def _binds(r: dict[str, Any] | None) -> bool:
    return bool(r and r.get("status") == "ok" and (r.get("drive_gain_W_per_mps") or 0.0) >= DRIVE_BINDS_W_PER_MPS)


def grid_table(volts: tuple, spans: tuple, winds: tuple, grid: dict[float, list], reel: dict[float, float]) -> list[str]:
    """The power table: one row per drive and glider, one column per wind."""
    out = ["| supply [V] | reel-in max [m/s] | glider | " + " | ".join(f"{w:g} m/s" for w in winds) + " |",
           "|---|---|---|" + "---|" * len(winds)]
    for v in volts:
        for b in (None, *spans):
            cells = []
            for w in winds:
                r = _find(grid[v], "nominal" if b is None else "foldable", w, b)
                n = _find(grid[v], "nominal", w, None)
                c = _pw(r)
                if b is not None and r is not None and n is not None and r.get("P_avg_W") is not None \
                        and n.get("P_avg_W") is not None and r.get("status") == n.get("status") == "ok":
                    c += f" ({r['P_avg_W'] - n['P_avg_W']:+.1f})"
                cells.append(c + (" ^" if _binds(r) else ""))
            glider = "nominal" if b is None else f"foldable b_f {b:g} m"
            out.append(f"| {v:g} | {reel[v]:.2f} | {glider} | " + " | ".join(cells) + " |")
    return out


def gain_table(volts: tuple, spans: tuple, winds: tuple, grid: dict[float, list]) -> list[str]:
    """The drive's gain [W per m/s of reel-in] at each point (0: the drive does not bind)."""
    out = ["| supply [V] | glider | " + " | ".join(f"{w:g} m/s" for w in winds) + " |", "|---|---|" + "---|" * len(winds)]
    for v in volts:
        for b in (None, *spans):
            cells = []
            for w in winds:
                r = _find(grid[v], "nominal" if b is None else "foldable", w, b)
                g = None if r is None or r.get("status") != "ok" else r.get("drive_gain_W_per_mps")
                cells.append("" if g is None else f"{g:.2f}")
            out.append(f"| {v:g} | {'nominal' if b is None else f'foldable b_f {b:g} m'} | " + " | ".join(cells) + " |")
    return out


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    lo, hi = SUPPLY_VOLTAGE_RANGE
    ap.add_argument("--supply-voltage", default="24,36,48", metavar="LIST",
                    help=f"the winch's supply voltages [V], each {lo:g}..{hi:g} (default 24,36,48)")
    ap.add_argument("--folded-span", default="0.22,0.44,0.66", metavar="LIST", help="folded spans b_f [m] (default 0.22,0.44,0.66)")
    ap.add_argument("--wind", default="8,10,12", metavar="LIST", help="wind speeds [m/s], each 0..25 (default 8,10,12)")
    ap.add_argument("--ground-station", default=None, metavar="FILE", help="the definition the variants derive from (default: the package's)")
    ap.add_argument("--codesign-wind", type=float, default=None, metavar="M_S", help="co-design the supply voltage at this wind [m/s], 0..25")
    ap.add_argument("--codesign-span", type=float, default=None, metavar="M", help="the co-design's folded span [m] (default: the definition's)")
    ap.add_argument("--codesign-steps", type=int, default=STEPS, metavar="N",
                    help=f"bisection steps after the grid, {STEPS_RANGE[0]}..{STEPS_RANGE[1]} (default {STEPS})")
    ap.add_argument("--mesh", default=None, metavar="NGEN,NREC[,DEG]", help="collocation mesh (default: the optimiser's)")
    ap.add_argument("--no-cold-check", action="store_true", help="warm-started points are not also solved cold")
    ap.add_argument("--workers", type=int, default=1, help="local Dask worker processes per sweep, 1..16 (default 1)")
    ap.add_argument("--out", default="runs/drive", help="output folder (default runs/drive)")
    return ap.parse_args(argv)


def _in_range(value: float | int | None, option: str, lo: float, hi: float | None, what: str, unit: str = "",
              integer: bool = False) -> None:
    """One-line :class:`InputError` naming ``option`` where ``value`` (None passes) is outside ``lo..hi``."""
    if value is None:
        return
    ok = (isinstance(value, int) or not integer) and math.isfinite(value) and value >= lo and (hi is None or value <= hi)
    if not ok:
        allowed = f"{'integer ' if integer else ''}{lo:g}..{'' if hi is None else f'{hi:g}'}{f' {unit}' if unit else ''}"
        raise InputError(f"{option} {value!r} ({what}) out of range (allowed {allowed})")


def check(args: argparse.Namespace) -> tuple[tuple, tuple, tuple]:
    """The lists and numbers of the command line (one-line errors naming the option)."""
    volts = tuple(sorted(set(parse_floats(args.supply_voltage, "--supply-voltage", "V", *SUPPLY_VOLTAGE_RANGE))))
    spans = tuple(sorted(set(parse_floats(args.folded_span, "--folded-span", "m", 0.0, None, lo_open=True))))
    winds = tuple(sorted(set(parse_floats(args.wind, "--wind", "m/s", 0.0, 25.0))))
    _in_range(args.codesign_wind, "--codesign-wind", 0.0, 25.0, "wind speed", "m/s")
    if args.codesign_span is not None and not args.codesign_span > 0.0:
        raise InputError(f"--codesign-span {args.codesign_span!r} (folded span) out of range (allowed > 0 m)")
    _in_range(args.codesign_steps, "--codesign-steps", STEPS_RANGE[0], STEPS_RANGE[1], "bisection steps", integer=True)
    _in_range(args.workers, "--workers", 1, 16, "worker processes", integer=True)
    if args.codesign_wind is not None and len(volts) < 2:
        raise InputError(f"--supply-voltage {args.supply_voltage}: the co-design needs at least two voltages (its range)")
    check_output_dir(args.out, "--out")
    return volts, spans, winds


def run(args: argparse.Namespace) -> dict[str, Any]:
    """The grid, the co-design where asked, the outputs; returns the JSON document."""
    volts, spans, winds = check(args)
    out = Path(args.out)
    stations = {v: write_supply_variant(v, out / "stations" / variant_name(v), args.ground_station) for v in volts}
    reel = {v: _reel_in_max(stations[v]) for v in volts}
    text = ",".join(f"{w:g}" for w in winds)
    for v in volts:
        code = _sweep(stations[v].path, out / f"{v:g}V", args, wind=text, config="nominal,foldable",
                      spans=",".join(f"{b:g}" for b in spans))
        if code not in (0, 1):
            raise RuntimeError(f"the sweep at {v:g} V exited {code}")
    grid = {v: _records(out / f"{v:g}V") for v in volts}
    doc: dict[str, Any] = {"command": " ".join(sys.argv), "supply_voltages_V": list(volts), "folded_spans_m": list(spans),
                           "winds_mps": list(winds), "reel_in_max_mps": {f"{v:g}": reel[v] for v in volts},
                           "stations": {f"{v:g}": stations[v].record() for v in volts},
                           "points": {f"{v:g}": [{k: r.get(k) for k in FIELDS} for r in grid[v]] for v in volts}}
    if args.codesign_wind is not None:
        doc["codesign"] = codesign(args, volts, grid, out)
    write_outputs(doc, volts, spans, winds, grid, reel, out)
    return doc


def codesign(args: argparse.Namespace, volts: tuple, grid: dict[float, list], out: Path) -> dict[str, Any]:
    """The co-design of the supply voltage at ``--codesign-wind`` (module docstring)."""
    from fdm_awe.sweep.runner import base_glider

    w = float(args.codesign_wind)
    b = args.codesign_span if args.codesign_span is not None else float(base_glider(None).folded.aero.b)
    solved: dict[float, dict[str, Any]] = {}

    def evaluate(v: float) -> float | None:
        """The better of the grid's point (warm-started along the wind) and a cold solve."""
        st = write_supply_variant(v, out / "stations" / variant_name(v), args.ground_station)
        folder = out / "codesign" / f"{v:g}V"
        _sweep(st.path, folder, args, wind=f"{w:g}", config="foldable", spans=f"{b:g}")
        found = [r for r in (_find(grid.get(v, []), "foldable", w, b), _find(_records(folder), "foldable", w, b))
                 if r is not None and r.get("status") == "ok" and r.get("P_avg_W") is not None]
        if not found:
            return None
        r = max(found, key=lambda r: r["P_avg_W"])
        solved[v] = {k: r.get(k) for k in FIELDS}
        return float(r["P_avg_W"])

    res = supply_search(evaluate, volts, min(volts), max(volts), steps=args.codesign_steps)
    res.update({"wind_mps": w, "b_f_m": b, "points": {f"{v:g}": solved[v] for v in sorted(solved)}})
    return res


def codesign_lines(cd: dict[str, Any]) -> list[str]:
    lines = [f"Co-design of the supply voltage at {cd['wind_mps']:g} m/s, foldable b_f {cd['b_f_m']:g} m "
             f"({cd['method']}, plateau within {cd['tol_W']:g} W of the best):", "",
             "| supply [V] | grid | P [W] | drive's gain [W per m/s] | T1 + T2 [s] |", "|---|---|---|---|---|"]
    for e in sorted(cd["evaluations"], key=lambda e: e["V"]):
        p = cd["points"].get(f"{e['V']:g}", {})
        g = p.get("drive_gain_W_per_mps")
        t = "" if p.get("T1_s") is None else f"{p['T1_s']:.1f} + {p['T2_s']:.1f}"
        pw = "fail" if e["P_W"] is None else f"{e['P_W']:+.1f}"
        lines.append(f"| {e['V']:g} | {'yes' if e['grid'] else 'no'} | {pw} | {'' if g is None else f'{g:.2f}'} | {t} |")
    if cd["best"] is not None:
        lines += ["", f"Best power {cd['best']['P_W']:+.1f} W (at {cd['best']['V']:g} V); the smallest supply on the plateau "
                      f"{cd['needed']['V']:g} V ({cd['needed']['P_W']:+.1f} W); the plateau's edge lies in "
                      f"{cd['lo_V']:g}..{cd['hi_V']:g} V."]
    return lines


def write_outputs(doc: dict[str, Any], volts: tuple, spans: tuple, winds: tuple, grid: dict[float, list],
                  reel: dict[float, float], out: Path) -> None:
    md = ["# The drive as design data: supply voltage x folded span x wind", "",
          "Cycle-average net power [W]; in brackets `dP = P_foldable - P_nominal` on the same drive; `^`: the drive's "
          f"reel-in bound binds (the optimum gains at least {DRIVE_BINDS_W_PER_MPS:g} W per m/s of faster reel-in).", "",
          *grid_table(volts, spans, winds, grid, reel), "",
          "The drive's gain: the power [W] the optimum would gain per m/s of faster reel-in (0: the drive does not bind).", "",
          *gain_table(volts, spans, winds, grid)]
    if "codesign" in doc:
        md += ["", *codesign_lines(doc["codesign"])]
    md += ["", "Stations:", ""] + [f"- {v:g} V: `{Path(doc['stations'][f'{v:g}']['file']).name}` "
                                   f"sha256 {doc['stations'][f'{v:g}']['sha256'][:12]}" for v in volts]
    atomic_write_text(out / "drive_map.md", "\n".join(md) + "\n")
    write_json(out / "drive_map.json", doc, indent=1)


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    try:
        doc = run(args)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    out = Path(args.out)
    print(f"drive map: {len(doc['supply_voltages_V'])} supplies -> {out / 'drive_map.md'}, {out / 'drive_map.json'}")
    cd = doc.get("codesign")
    if cd and cd["best"] is not None:
        print(f"co-design at {cd['wind_mps']:g} m/s: best {cd['best']['P_W']:+.1f} W at {cd['best']['V']:g} V; "
              f"smallest supply on the plateau {cd['needed']['V']:g} V ({cd['needed']['P_W']:+.1f} W)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
