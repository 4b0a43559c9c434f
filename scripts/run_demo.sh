#!/usr/bin/env bash
# Set up .venv if needed, then run the main job.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export JSBSIM_DEBUG=0 MPLBACKEND=Agg
.venv/bin/fdm-awe info
