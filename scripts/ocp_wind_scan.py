#!/usr/bin/env python3
"""Optimal pumping cycle over wind speed for the nominal and the foldable glider.

For each configuration and wind speed: cold solves from the crosswind-loop starts (``--starts``
successful ones compared), then one sweep upwards and one downwards warm-started from the
neighbouring wind's solution; the best average power found is kept. Writes a JSON file and a
markdown table (energies in J, gains positive).

    .venv/bin/python scripts/ocp_wind_scan.py --scenario physical --winds 3:12:1 --out ocp_scan
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def parse_winds(text: str) -> list[float]:
    if ":" in text:
        a, b, s = (float(v) for v in text.split(":"))
        n = int(round((b - a) / s)) + 1
        return [round(a + i * s, 6) for i in range(n)]
    return [float(v) for v in text.split(",")]


def main() -> int:
    from fdm_awe.ocp.problem import CycleProblem, Mesh
    from fdm_awe.ocp.solve import solve_cycle

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="physical", choices=("physical", "paper"))
    ap.add_argument("--configs", default="nominal,foldable")
    ap.add_argument("--winds", default="3:12:1")
    ap.add_argument("--mesh", default=None, help="NG,NR,DEG (default: the OCP default mesh)")
    ap.add_argument("--starts", type=int, default=2, help="successful cold starts compared per point")
    ap.add_argument("--out", default="ocp_wind_scan", help="output stem (.json and .md are added)")
    ap.add_argument("--cold-at", default=None, help="winds with cold solves (default: all); the others rely on the warm sweeps")
    ap.add_argument("--max-iter-total", type=int, default=None,
                    help="IPOPT iterations per solve_cycle call (default: the optimiser's budget); the limit that decides failures")
    ap.add_argument("--time-budget", type=float, default=None, help="wall-clock safety net per solve_cycle call [s]")
    args = ap.parse_args()
    mesh = Mesh(*(int(v) for v in args.mesh.split(","))) if args.mesh else Mesh()
    limits = {k: v for k, v in (("max_iter_total", args.max_iter_total), ("time_budget_s", args.time_budget)) if v is not None}
    winds = parse_winds(args.winds)
    table: dict[str, dict[float, dict]] = {}
    t_all = time.perf_counter()
    for cfg in args.configs.split(","):
        best: dict[float, object] = {}
        tried: dict[float, list[str]] = {w: [] for w in winds + ([] if args.cold_at is None else parse_winds(args.cold_at))}

        def keep(w: float, r, how: str) -> None:
            tried[w].append(f"{how}: {r.status} {r.P_avg_W:.2f} W" if r.ok else f"{how}: {r.status} ({r.reason[:240]})")
            if r.ok and (w not in best or r.P_avg_W > best[w].P_avg_W):
                best[w] = r

        cold_at = winds if args.cold_at is None else parse_winds(args.cold_at)
        for w in cold_at:
            pr = CycleProblem(scenario=args.scenario, config=cfg, wind_speed=w, mesh=mesh)
            keep(w, solve_cycle(pr, n_starts=args.starts, **limits), "cold")
            print(f"{cfg} {w:5.1f} m/s cold: {tried[w][-1]}", flush=True)
        for order in (winds, winds[::-1]):
            prev = None
            for w in order:
                if prev is not None and prev in best:
                    pr = CycleProblem(scenario=args.scenario, config=cfg, wind_speed=w, mesh=mesh)
                    keep(w, solve_cycle(pr, warm=best[prev], **limits), f"warm from {prev:g}")
                    print(f"{cfg} {w:5.1f} m/s {tried[w][-1]}", flush=True)
                prev = w
        table[cfg] = {}
        for w in winds:
            r = best.get(w)
            row = r.summary() if r is not None else {"status": "failed", "wind_mps": w}
            row["attempts"] = tried[w]
            table[cfg][w] = row
    wall = time.perf_counter() - t_all
    out = Path(args.out)
    doc = {"scenario": args.scenario, "load_avg_end": os.getloadavg(), "mesh": {"n_gen": mesh.n_gen, "n_rec": mesh.n_rec, "degree": mesh.degree},
           "winds_mps": winds, "wall_s": wall, "results": {c: {str(w): v for w, v in t.items()} for c, t in table.items()}}
    out.with_suffix(".json").write_text(json.dumps(doc, indent=2, default=float))
    cfgs = list(table)
    lines = [f"# Optimal cycle vs wind: `{args.scenario}` scenario (mesh {mesh.n_gen}/{mesh.n_rec}/deg {mesh.degree})", "",
             "Gains positive. P_avg = E_net / (T1 + T2).", "",
             "| wind [m/s] | " + " | ".join(f"{c} P_avg [W] | {c} E_net [J] | {c} T1/T2 [s]" for c in cfgs) + " | better |",
             "|---:|" + "---:|---:|---:|" * len(cfgs) + "---|"]
    reasons: dict[str, list[str]] = {}
    for w in winds:
        cells = []
        vals = {}
        for c in cfgs:
            r = table[c][w]
            if r.get("status") == "ok":
                vals[c] = r["P_avg_W"]
                cells += [f"{r['P_avg_W']:.2f}", f"{r['E_net_J']:.0f}", f"{r['T1_s']:.1f}/{r['T2_s']:.1f}"]
            else:
                cells += ["failed", "—", "—"]
                reasons.setdefault(c, []).append(f"{w:g} m/s: {r.get('attempts', ['?'])[0][:240]}")
        better = max(vals, key=vals.get) if len(vals) == len(cfgs) else "—"
        lines.append(f"| {w:g} | " + " | ".join(cells) + f" | {better} |")
    for c, rs in reasons.items():
        lines += ["", f"{c} failures (first attempt's reason):", *[f"- {t}" for t in rs]]
    lines += ["", f"Wall time {wall:.0f} s, load average at the end {os.getloadavg()[0]:.1f}."]
    out.with_suffix(".md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0 if all(r.get("status") == "ok" for t in table.values() for r in t.values()) else 1


if __name__ == "__main__":
    sys.exit(main())
