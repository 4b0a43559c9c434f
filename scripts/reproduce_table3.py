#!/usr/bin/env python
"""The paper's Table 3: the `paper` scenario (its simplifications) at 3 m/s from the south,
nominal and foldable glider, printed next to the paper's numbers, plus the zero-wind check.

Writes into ``--out`` (default runs/table3): table3.md (Table-3 style, the paper's column
as printed: gains NEGATIVE there, positive in ours), table3.json, the two reference files,
compare_3d.png / compare_time.png, and per configuration a recording, plots and CSV.
``--fly`` also flies one cycle of each in 6-DOF and adds the flown energies.

Usage: python scripts/reproduce_table3.py [--out runs/table3] [--fly] [--no-zero-wind] [--quiet]
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import sys
from pathlib import Path

os.environ.setdefault("JSBSIM_DEBUG", "0")
os.environ.setdefault("MPLBACKEND", "Agg")

WIND = 3.0
SCENARIO = "paper"


def _sibling(name: str):
    spec = importlib.util.spec_from_file_location(name, Path(__file__).with_name(f"{name}.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="runs/table3")
    ap.add_argument("--fly", action="store_true", help="also fly one cycle of each in 6-DOF")
    ap.add_argument("--no-zero-wind", action="store_true", help="skip the zero-wind check")
    ap.add_argument("--quiet", action="store_true")
    args = ap.parse_args(argv)
    from fdm_awe.commands.compare import PAPER_TABLE3, markdown, zero_wind_verdict
    from fdm_awe.recording import cycle_outputs, plot_compare, table3_markdown

    pair = _sibling("compare_nominal_foldable")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    quiet = True if args.quiet else None
    results = pair.optimise_pair(SCENARIO, WIND, out, quiet)
    zero = None
    if not args.no_zero_wind:
        zdir = out / "zero_wind"
        zdir.mkdir(exist_ok=True)
        zero = {c: r.summary() for c, r in pair.optimise_pair(SCENARIO, 0.0, zdir, quiet).items()}
    summaries = {c: r.summary() for c, r in results.items()}
    text = markdown(SCENARIO, WIND, summaries, zero)
    ok = [c for c in pair.CONFIGS if results[c].ok]
    for c in ok:
        cycle_outputs(out / f"reference_{c}.json", out_dir=out / c)
    if ok:
        plot_compare([out / f"reference_{c}.json" for c in ok], ok, out)
    flights = pair.fly_pair(results, out, quiet) if args.fly else []
    if flights:
        flown = table3_markdown([], flights=flights).split("## Flown (6-DOF co-simulation)", 1)[1]
        text += "\n## Flown in 6-DOF (one cycle each)\n" + flown
    (out / "table3.md").write_text(text + "\n")
    doc = {"scenario": SCENARIO, "wind_mps": WIND, "paper_table3_as_printed": PAPER_TABLE3,
           "sign_note": "ours: gains > 0; paper Table 3: gains < 0", "results": summaries, "zero_wind": zero,
           "zero_wind_verdict": None if zero is None else {c: zero_wind_verdict(SCENARIO, z) for c, z in zero.items()},
           "flown": [f.as_json() for f in flights]}
    (out / "table3.json").write_text(json.dumps(doc, indent=2, default=lambda o: None) + "\n")
    print(text)
    print(f"wrote {out}/")
    return 0 if len(ok) == len(pair.CONFIGS) else 1


if __name__ == "__main__":
    sys.exit(main())
