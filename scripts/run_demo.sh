#!/usr/bin/env bash
# Set up .venv if needed, then run the main job: optimise the pumping cycle of the nominal and
# the foldable glider side by side (physical scenario, 8 m/s), then fly three cycles of the
# nominal glider's optimised cycle in 6-DOF co-simulation with recording, plots and report.
# Everything lands in runs/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export JSBSIM_DEBUG=0 MPLBACKEND=Agg
out=runs/demo
mkdir -p "$out"
.venv/bin/fdm-awe compare --scenario physical --wind 8 --report "$out/compare.md" --json "$out/compare.json" || true
.venv/bin/fdm-awe fly --scenario physical --config nominal --wind 8 --cycles 3 --out "$out" --json "$out/fly.json"
echo "outputs in $out/ (open the recording with: .venv/bin/rerun $out/flight.rrd)"
