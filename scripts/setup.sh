#!/usr/bin/env bash
# Create (or update) the project's virtual environment in .venv and install fdm-awe with its
# test extras. Safe to run again: it reinstalls only when pyproject.toml or setup.py changed.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
    echo "setup: creating .venv with $($PY --version)"
    "$PY" -m venv .venv
fi
stamp=.venv/.fdm-awe-installed
want=$(cat pyproject.toml setup.py | sha256sum | cut -d' ' -f1)
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
    echo "setup: installing fdm-awe and its dependencies into .venv (first run takes a few minutes)"
    .venv/bin/python -m pip install -q --upgrade pip
    .venv/bin/python -m pip install -q -e ".[dev]"
    # compile the ground station's numba kernels into their disk cache now (~8 s once), so the
    # first flight starts within about a second
    .venv/bin/python -c "from fdm_awe.groundstation.substeps import compiled_station; compiled_station()"
    echo "$want" > "$stamp"
fi
