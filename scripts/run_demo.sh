#!/usr/bin/env bash
# Set up .venv if needed, then run the main job: optimise the pumping cycle of the nominal and
# the foldable glider side by side in the paper's setting (Table 3: paper scenario, 3 m/s,
# with the zero-wind check), then optimise the nominal glider's cycle in the physical scenario
# at 8 m/s and fly three cycles of it in 6-DOF co-simulation with recording, plots and report.
# Everything lands in runs/demo/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export JSBSIM_DEBUG=0 MPLBACKEND=Agg
out=runs/demo
mkdir -p "$out"
.venv/bin/fdm-awe compare --scenario paper --wind 3 --report "$out/table3.md" --json "$out/table3.json"
.venv/bin/fdm-awe fly --scenario physical --config nominal --wind 8 --cycles 3 --out "$out" --json "$out/fly.json"
echo "outputs in $out/ (open the recording with: .venv/bin/rerun $out/flight.rrd)"
