#!/usr/bin/env python
"""Golden outputs: record a fixed set of deterministic runs, or compare against a recording.

    python scripts/golden.py record DIR      # run the set into DIR
    python scripts/golden.py compare DIR     # run it again into a temporary folder and compare
    python scripts/golden.py compare DIR --only gs_python,gs_default   # a subset of the runs

The set (from the repository root, the package of this checkout):

- ``fly_nominal``    fly the physical nominal 8 m/s reference, 1 cycle (JSON + CSV of ``--out``)
- ``fly_turbulent``  the same with ``--turbulence moderate:7``
- ``fly_paper``      fly the paper foldable 3 m/s reference (paper plant), 1 cycle
- ``optimize``       ``optimize --scenario physical --config nominal --wind 8 --mesh 20,12,3``
- ``sweep``          ``sweep --wind 7,8 --config nominal --mesh 20,12,3 --workers 1 --no-cold-check``
- ``gs_python`` / ``gs_default``  the ground station alone (generation through the line,
  a switch to PI reel-in, a prescribed-tension stall and a boost stage), every state and
  ledger term of every step as CSV, with ``FDM_AWE_JIT=0`` and with the default (compiled)

The optimiser runs set ``FDM_AWE_NLP_CACHE=off``. Compare mode reads every JSON and CSV file of
each run, number by number (JSON: every numeric leaf except wall-clock keys; CSV: every cell;
NPZ: every element),
prints the largest absolute and relative difference per file, and exits 0 only when every
file is bit-identical (other files, e.g. plots, are listed as not compared).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

#: JSON keys of wall-clock / machine facts, never compared
TIMING_KEYS = {"wall_s", "solve_s", "build_s", "realtime_factor", "cpu_s", "worker", "t_wall", "wall",
               "elapsed_s", "time_s", "seconds", "timestamp", "created", "date", "host", "hostname", "pid",
               "t_solve", "t_build", "t_proc_total", "t_wall_total", "duration_s", "cpu_time", "wall_time"}


def _runs(out: Path) -> dict[str, list[str]]:
    """The command line of each run, writing into ``out/<name>``."""
    fly = ["fly", "--cycles", "1", "--quiet"]
    nominal = ["--reference", "tests/data/ref_physical_nominal_8mps.json"]
    return {
        "fly_nominal": fly + nominal + ["--out", str(out / "fly_nominal"),
                                        "--json", str(out / "fly_nominal" / "flight.json")],
        "fly_turbulent": fly + nominal + ["--turbulence", "moderate:7", "--out", str(out / "fly_turbulent"),
                                          "--json", str(out / "fly_turbulent" / "flight.json")],
        "fly_paper": fly + ["--reference", "tests/data/ref_paper_foldable_3mps.json",
                            "--out", str(out / "fly_paper"), "--json", str(out / "fly_paper" / "flight.json")],
        "optimize": ["optimize", "--scenario", "physical", "--config", "nominal", "--wind", "8",
                     "--mesh", "20,12,3", "--json", str(out / "optimize" / "result.json")],
        "sweep": ["sweep", "--wind", "7,8", "--config", "nominal", "--mesh", "20,12,3", "--workers", "1",
                  "--no-cold-check", "--out", str(out / "sweep"), "--json", str(out / "sweep" / "summary.json")],
        "gs_python": ["@gs", str(out / "gs_python" / "history.csv")],
        "gs_default": ["@gs", str(out / "gs_default" / "history.csv")],
    }


def gs_history(path: Path) -> None:
    """Step one ground station through a fixed scenario and write its history as CSV."""
    import numpy as np

    from fdm_awe.fileio import atomic_write_text
    from fdm_awe.groundstation import GroundStation, WinchCommand, load_ground_station

    el = math.radians(30.0)
    u = np.array([math.cos(el), 0.0, -math.sin(el)])
    e = np.array([0.0, 1.0, 0.0])
    gs = GroundStation(load_ground_station(), wind_ned=(3.0, 0.0, 0.0))
    gs.reset(200.0, 0.0, "generator")
    dt = 1 / 120
    rows = []
    states = ("length", "omega", "current", "u_link", "integ", "duty", "broken", "at_stop", "stretch")
    outs = ("tension", "length", "reel_speed", "omega", "current", "duty", "u_link", "p_electrical",
            "p_mechanical", "distance", "slack", "broken")
    header = None
    for k in range(int(round(10.0 / dt))):
        t = k * dt
        if t < 4.0:  # generation while the glider flies out and sideways
            pos = u * (200.0 + 3.0 * t) + e * 20.0 * math.sin(0.8 * t)
            vel = u * 3.0 + e * 16.0 * math.cos(0.8 * t)
            o = gs.step(dt, tuple(pos.tolist()), tuple(vel.tolist()), WinchCommand("generator"))
        elif t < 8.0:  # mode switch: PI reel-in while it returns
            pos = u * (212.0 - 2.5 * (t - 4.0)) + e * 20.0 * math.sin(0.8 * t)
            vel = u * -2.5 + e * 16.0 * math.cos(0.8 * t)
            o = gs.step(dt, pos, vel, WinchCommand("motor", reel_speed_ref=-3.0))
        elif t < 8.5:  # stall of the PI (saturation, anti-windup)
            o = gs.step_with_tension(dt, 150.0, WinchCommand("motor", reel_speed_ref=-3.0))
        elif t < 9.0:  # open-loop duty
            o = gs.step_with_tension(dt, 5.0, WinchCommand("motor", duty=0.7))
        else:  # boost stage, then stick-slip on a light load
            o = gs.step_with_tension(dt, 60.0 if t < 9.5 else 0.0,
                                     WinchCommand("generator", boost_duty=0.3, load_resistance=2.0))
        led = gs.ledger.as_dict()
        dtr = gs.drivetrain
        row = {"t": t}
        row.update({"out_" + n: float(getattr(o, n)) for n in outs})
        f = o.force_on_glider_ned
        row.update({"fx": float(f[0]), "fy": float(f[1]), "fz": float(f[2])})
        row["event"] = o.event or ""
        row["mode"] = o.mode
        row["machine_mode"] = o.machine_mode
        row.update({"state_" + n: float(getattr(dtr, n)) for n in states})
        row.update({"ledger_" + n: v for n, v in led.items()})
        if header is None:
            header = list(row)
        rows.append(row)
    lines = [",".join(header)]
    for row in rows:
        lines.append(",".join(repr(row[h]) if isinstance(row[h], float) else str(row[h]) for h in header))
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(path, "\n".join(lines) + "\n")


def run_set(out: Path, only: list[str] | None) -> dict[str, float]:
    """Run the set (or ``only`` those runs) into ``out``; returns the wall time of each, s."""
    out.mkdir(parents=True, exist_ok=True)
    times = {}
    for name, args in _runs(out).items():
        if only and name not in only:
            continue
        env = dict(os.environ, JSBSIM_DEBUG="0", MPLBACKEND="Agg", FDM_AWE_NLP_CACHE="off")
        env["PYTHONPATH"] = str(ROOT) + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
        if name == "gs_python":
            env["FDM_AWE_JIT"] = "0"
        elif name == "gs_default":
            env.pop("FDM_AWE_JIT", None)
        (out / name).mkdir(parents=True, exist_ok=True)
        if args[0] == "@gs":
            cmd = [sys.executable, str(Path(__file__).resolve()), "_gs", args[1]]
        else:
            cmd = [sys.executable, "-m", "fdm_awe"] + args
        t0 = time.perf_counter()
        res = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)
        times[name] = time.perf_counter() - t0
        (out / name / "_stdout.txt").write_text(res.stdout + "\n--- stderr\n" + res.stderr)
        print(f"{name:14s} exit {res.returncode}  {times[name]:7.1f} s", flush=True)
        if res.returncode != 0:
            print(res.stderr[-2000:], file=sys.stderr)
    return times


def _leaves(doc, path: str = ""):
    """Yield (path, value) of every leaf of a JSON document, skipping timing keys."""
    if isinstance(doc, dict):
        for k, v in doc.items():
            if k in TIMING_KEYS or k.endswith("_wall_s") or k.endswith("_seconds"):
                continue
            yield from _leaves(v, f"{path}/{k}")
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            yield from _leaves(v, f"{path}[{i}]")
    else:
        yield path, doc


def _diff(a, b) -> tuple[bool, float, float]:
    """(identical, abs diff, rel diff) of two leaves (numbers compared as floats, bit for bit)."""
    if isinstance(a, bool) or isinstance(b, bool) or not isinstance(a, (int, float)) or not isinstance(b, (int, float)):
        return a == b, (0.0 if a == b else math.inf), (0.0 if a == b else math.inf)
    fa, fb = float(a), float(b)
    if fa == fb or (math.isnan(fa) and math.isnan(fb)):
        return True, 0.0, 0.0
    d = abs(fa - fb)
    return False, d, d / max(abs(fa), abs(fb))


class _Tally:
    """Counts compared values and keeps the largest difference with its label."""

    def __init__(self) -> None:
        self.n = self.bad = 0
        self.mabs = self.mrel = 0.0
        self.worst = ""

    def add(self, u, v, label) -> None:
        """Compare ``u`` with ``v``; ``label()`` names the place when it is the worst so far."""
        self.n += 1
        same, da, dr = _diff(u, v)
        if not same:
            self.bad += 1
            if da >= self.mabs:
                self.worst = label()
            self.mabs, self.mrel = max(self.mabs, da), max(self.mrel, dr)

    def result(self) -> tuple[int, int, float, float, str]:
        return self.n, self.bad, self.mabs, self.mrel, self.worst


def _number(s: str):
    try:
        return float(s)
    except ValueError:
        return s


def _compare_json(a: Path, b: Path, roots: tuple[Path, Path]) -> tuple[int, int, float, float, str]:
    """Every leaf; strings compared with each run's own folder written as ``<DIR>``."""
    def load(p: Path, root: Path) -> dict:
        return {k: (v.replace(str(root), "<DIR>") if isinstance(v, str) else v)
                for k, v in _leaves(json.loads(p.read_text()))}

    la, lb = load(a, roots[0]), load(b, roots[1])
    t = _Tally()
    for k in sorted(set(la) | set(lb)):
        if k not in la or k not in lb:
            t.n += 1
            t.bad += 1
            t.worst = t.worst or f"{k} only in one file"
            t.mabs = t.mrel = math.inf
            continue
        t.add(la[k], lb[k], lambda k=k: f"{k}: {la[k]!r} vs {lb[k]!r}")
    return t.result()


def _compare_csv(a: Path, b: Path, roots: tuple[Path, Path]) -> tuple[int, int, float, float, str]:
    ra = list(csv.reader(a.open()))
    rb = list(csv.reader(b.open()))
    if len(ra) != len(rb):
        return 0, 1, math.inf, math.inf, f"rows {len(ra)} vs {len(rb)}"
    header = ra[0] if ra else []
    skip = {j for j, h in enumerate(header) if h in TIMING_KEYS}
    t = _Tally()
    for i, (x, y) in enumerate(zip(ra, rb)):
        if len(x) != len(y):
            return t.n, t.bad + 1, math.inf, math.inf, f"row {i}: {len(x)} vs {len(y)} cells"
        for j, (u, v) in enumerate(zip(x, y)):
            if j in skip and i > 0:
                continue
            t.add(_number(u), _number(v), lambda i=i, j=j, u=u, v=v: f"row {i} {header[j] if j < len(header) else j}: {u} vs {v}")
    return t.result()


def _compare_npz(a: Path, b: Path, roots: tuple[Path, Path]) -> tuple[int, int, float, float, str]:
    import numpy as np

    with np.load(a) as za, np.load(b) as zb:
        if sorted(za.files) != sorted(zb.files):
            return 0, 1, math.inf, math.inf, f"arrays {sorted(za.files)} vs {sorted(zb.files)}"
        t = _Tally()
        for k in za.files:
            x, y = np.ravel(za[k]), np.ravel(zb[k])
            if x.shape != y.shape:
                return t.n, t.bad + 1, math.inf, math.inf, f"{k}: shape {x.shape} vs {y.shape}"
            for j, (u, v) in enumerate(zip(x.tolist(), y.tolist())):
                t.add(u, v, lambda k=k, j=j, u=u, v=v: f"{k}[{j}]: {u!r} vs {v!r}")
    return t.result()


def compare(golden: Path, fresh: Path, only: list[str] | None) -> bool:
    ok = True
    for name in _runs(golden):
        if only and name not in only:
            continue
        ga, fr = golden / name, fresh / name
        files = sorted(p.relative_to(ga) for p in ga.rglob("*") if p.is_file() and p.name != "_stdout.txt")
        new = sorted(p.relative_to(fr) for p in fr.rglob("*") if p.is_file() and p.name != "_stdout.txt")
        for rel in sorted(set(new) - set(files)):
            print(f"  {name}/{rel}: only in the new run")
        if not files:
            print(f"  {name}: nothing recorded")
            ok = False
        for rel in files:
            a, b = ga / rel, fr / rel
            if rel.suffix not in (".json", ".csv", ".npz"):
                print(f"  {name}/{rel}: not compared ({rel.suffix or 'no suffix'})")
                continue
            if not b.exists():
                print(f"  {name}/{rel}: MISSING in the new run")
                ok = False
                continue
            how = {".json": _compare_json, ".csv": _compare_csv, ".npz": _compare_npz}[rel.suffix]
            n, bad, mabs, mrel, worst = how(a, b, (golden, fresh))
            flag = "identical" if bad == 0 else f"DIFFERS in {bad} of {n}"
            print(f"  {name}/{rel}: {n} numbers, {flag}; max abs {mabs:.3g}, max rel {mrel:.3g}"
                  + (f"; largest: {worst}" if bad else ""))
            ok = ok and bad == 0
    return ok


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    for name in ("record", "compare"):
        p = sub.add_parser(name)
        p.add_argument("dir", type=Path, help="folder of the golden set")
        p.add_argument("--only", default="", help="comma-separated run names (default all)")
    g = sub.add_parser("_gs")  # the ground-station run of the set (a child process)
    g.add_argument("csv", type=Path)
    args = ap.parse_args(argv)
    if args.cmd == "_gs":
        gs_history(args.csv)
        return 0
    only = [s for s in args.only.split(",") if s] or None
    if only:
        unknown = set(only) - set(_runs(args.dir))
        if unknown:
            ap.error(f"--only: unknown run(s) {', '.join(sorted(unknown))} (allowed {', '.join(_runs(args.dir))})")
    if args.cmd == "record":
        if args.dir.exists() and any(args.dir.iterdir()) and not only:
            ap.error(f"record: {args.dir} is not empty")
        run_set(args.dir.resolve(), only)
        return 0
    with tempfile.TemporaryDirectory(prefix="golden-") as tmp:
        run_set(Path(tmp), only)
        same = compare(args.dir.resolve(), Path(tmp), only)
    print("bit-identical" if same else "DIFFERENCES found")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
