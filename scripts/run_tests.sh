#!/usr/bin/env bash
# Set up .venv if needed, then run the whole test suite. Extra arguments go to pytest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export JSBSIM_DEBUG=0 MPLBACKEND=Agg
exec .venv/bin/python -m pytest -q "$@"
