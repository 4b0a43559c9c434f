"""The autopilot's AUTO steps compiled in blocks (:mod:`fdm_awe.sim.autopilot_kernel`) fly the
Python autopilot's flight bit for bit: every logged column, the tracking error, the reference
points, both ledgers, the cycles' energies and the autopilot's log; and the plain-Python run
(``FDM_AWE_JIT=0``: Python loop, ground station and autopilot) gives the same bits."""

from __future__ import annotations

import os
import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.sim.flight import fly

DATA = Path(__file__).parent / "data"
REFS = {"nominal": "ref_physical_nominal_8mps_sized.json", "foldable": "ref_physical_foldable_8mps_sized.json"}


def _flight(config: str, per_step: bool, t_end: float | None = None, setup=None) -> tuple[dict, object]:
    """A flight of one cycle (or ``t_end`` s); its comparable outputs and its co-simulation."""
    ref = TrackingReference.from_ocp_file(DATA / REFS[config])
    held = {}

    def keep(ap, sim):
        held["sim"] = sim
        if setup is not None:
            setup(ap, sim)

    rep = fly(ref, config=config, cycles=1, t_end=t_end, setup=keep,
              on_step=(lambda k, s, o: None) if per_step else None)
    out = {"data": rep.result.data, "track_error": rep.track_error, "reference_pos": rep.reference_pos,
           "ledger": rep.ledger, "cycles": [c.E_net_J for c in rep.cycles], "log": rep.autopilot_log,
           "status": rep.status, "steps": rep.result.steps, "loop": rep.as_json()["loop"]}
    return out, held["sim"]


def _assert_same(a: dict, b: dict) -> None:
    for k in ("data", "track_error", "reference_pos"):
        assert a[k].shape == b[k].shape and np.array_equal(a[k], b[k], equal_nan=True), k
    for k in ("ledger", "cycles", "log", "status", "steps"):
        assert a[k] == b[k], k


def _compiled_blocks(sim) -> int:
    """Steps the co-simulation flew in compiled blocks (skips the test where none can run)."""
    runner = sim.block_runner
    if runner is None:
        pytest.skip(f"compiled blocks not available here ({sim.loop}: {sim.loop_reason or 'no native JSBSim calls'})")
    return runner.steps


@pytest.mark.parametrize("config", ["nominal", "foldable"])
def test_compiled_blocks_fly_the_python_autopilots_bits(config):
    """One whole cycle (phase switches, the fold and the motor's stops on the foldable glider):
    nearly every step compiled, the Python steps only where the autopilot notes something."""
    blocks, sim = _flight(config, per_step=False)
    n = _compiled_blocks(sim)
    per_step, _ = _flight(config, per_step=True)
    assert blocks["status"] == "ok" and n >= blocks["steps"] - 10
    # the flight's JSON says how its steps ran
    assert blocks["loop"]["autopilot_compiled_steps"] == n
    assert blocks["loop"]["autopilot_python_steps"] == blocks["steps"] - n
    assert per_step["loop"]["autopilot_compiled_steps"] == 0
    _assert_same(blocks, per_step)


def test_a_rejoin_in_blocks_ends_in_python_with_its_note():
    """Cycling restarted at the start: the rejoin segment is flown compiled, its end (a note)
    by the Python autopilot; the same bits as the Python autopilot's flight."""

    def restart(ap, sim):
        ap.stop_cycling()
        ap.start_cycling()

    blocks, sim = _flight("nominal", per_step=False, t_end=15.0, setup=restart)
    _compiled_blocks(sim)
    per_step, _ = _flight("nominal", per_step=True, t_end=15.0, setup=restart)
    notes = [text for _, text in blocks["log"]]
    assert any(text.startswith("rejoin: ") and "from the path" in text for text in notes)
    assert "rejoin: on the path" in notes
    _assert_same(blocks, per_step)


def test_the_plain_python_flight_has_the_same_bits(tmp_path):
    """``FDM_AWE_JIT=0`` in a child process: the Python loop, ground station and autopilot."""
    blocks, sim = _flight("foldable", per_step=False, t_end=60.0)
    _compiled_blocks(sim)
    out = tmp_path / "plain.pkl"
    code = ("import pickle, sys; sys.path.insert(0, %r); import test_sim_autopilot_kernel as t; "
            "pickle.dump(t._flight('foldable', False, 60.0)[0], open(%r, 'wb'))" % (str(Path(__file__).parent), str(out)))
    subprocess.run([sys.executable, "-c", code], check=True, env=dict(os.environ, FDM_AWE_JIT="0"), timeout=300)
    with open(out, "rb") as fh:
        plain = pickle.load(fh)
    _assert_same(blocks, plain)
