#!/usr/bin/env bash
# Set up .venv if needed, then run the main job:
# 1. optimise the pumping cycle of the nominal and the foldable glider side by side in the
#    paper's setting (Table 3: paper scenario, 3 m/s, with the zero-wind check);
# 2. optimise the foldable glider's cycle in the physical scenario (the default plant: the line
#    sized for its load, the glider's own motor and propeller with a motor-off mode, the line's
#    weight, a 2 s fold) at 8 m/s and fly three cycles of it in 6-DOF co-simulation, with
#    recording, plots and report;
# 3. the same for the nominal glider, which never folds, for comparison.
# Everything lands in runs/demo/ (foldable/ and nominal/ hold each flight's outputs).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export JSBSIM_DEBUG=0 MPLBACKEND=Agg
out=runs/demo
mkdir -p "$out"
.venv/bin/fdm-awe compare --scenario paper --wind 3 --report "$out/table3.md" --json "$out/table3.json"
for cfg in foldable nominal; do
    .venv/bin/fdm-awe fly --scenario physical --config "$cfg" --wind 8 --cycles 3 --out "$out/$cfg" --json "$out/$cfg/fly.json"
done
echo "outputs in $out/ (open a recording with: .venv/bin/rerun $out/foldable/flight.rrd)"
