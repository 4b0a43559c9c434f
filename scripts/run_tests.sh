#!/usr/bin/env bash
# Set up .venv if needed, then run the whole test suite: first the wheel check
# (scripts/check_wheel.py: sdist and wheel built from this checkout, the wheel installed with its
# dependencies into a fresh virtual environment in a temporary folder, then `fdm-awe info`, a short
# `optimize` and `fly --cycles 1` run from outside the checkout), then pytest, in parallel
# (pytest-xdist). Extra arguments go to pytest. The exit status is non-zero if either fails;
# pytest's closing line stays the last
# line of the test run (a failed wheel check adds one line after it).
# FDM_AWE_WHEEL_CHECK=0 skips the wheel check (e.g. for a quick targeted pytest run).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
export JSBSIM_DEBUG=0 MPLBACKEND=Agg
wheel=0
if [ "${FDM_AWE_WHEEL_CHECK:-1}" != "0" ]; then
    .venv/bin/python scripts/check_wheel.py || wheel=$?
fi
tests=0
# in parallel, by file: a module's tests run in one worker in their order (the documented
# command lines of tests/test_docs_commands.py read each other's outputs); one worker per core,
# at most 4
.venv/bin/python -m pytest -q -n auto --maxprocesses=4 --dist loadfile "$@" || tests=$?
if [ "$wheel" != "0" ]; then
    echo "run_tests: the wheel check failed (exit $wheel, see its output above the tests)"
    exit "$wheel"
fi
exit "$tests"
