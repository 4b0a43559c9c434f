"""The recovery's numbers are autopilot parameters (``autopilot.xml``, MAVLink visible): each is
declared with its unit, range and description, read and set through the parameter store, and
flown: RECOVER's reel-in follows REC_SLK_KL (Python autopilot), and the cycle's recovery phase
reads REC_LEN_KL, REC_TENS_KT and REC_PAY_MAX from the compiled AUTO step's parameter block as
the Python step reads them from the store (the same bits)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from fdm_awe.autopilot.config import autopilot_params, load_autopilot_definition
from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.autopilot.winch import LIMIT_PARAMS
from fdm_awe.sim.flight import fly
from fdm_awe.sim.result import COLUMNS

DATA = Path(__file__).parent / "data"
DOCS = Path(__file__).resolve().parents[1] / "docs" / "mavlink.md"
NOMINAL = DATA / "ref_physical_nominal_8mps_sized.json"
C = {c: i for i, c in enumerate(COLUMNS)}

#: the recovery's numbers that were literals in the code -> their value there (the default)
RECOVERY_PARAMS = {
    "REC_LEN_KL": 0.5, "REC_TENS_KT": 0.2, "REC_PAY_MAX": 0.5, "REC_GUST_TAU": 10.0, "REC_GUST_BAND": 10.0,
    "REC_SLK_KL": 0.5, "REC_SPOOL_RL": 1.0e4, "REC_SPOOL_SLK": 2.0, "REC_CAPT_W": 0.5, "REC_TURN_RMAX": 0.45,
    "REC_CIRC_BAND": 0.25, "REC_HOLD_TOL": 5.0, "REC_FLR_SINK": 1.0, "REC_FLR_SINK_TD": 0.3, "REC_FLR_KA": 0.05,
    "REC_FLR_AMARG": 0.9, "REC_FLR_KT": 4.0, "REC_FLR_VMIN": 0.8, "REC_FLR_TMAX": 8.0,
}


def test_each_recovery_number_is_a_parameter_with_unit_range_and_description():
    defs = {d.id: d for d in load_autopilot_definition()}
    store = autopilot_params()
    listed = DOCS.read_text()
    for name, was in RECOVERY_PARAMS.items():
        d = defs[name]
        assert re.fullmatch(r"[A-Z0-9_]{1,16}", name), name  # a MAVLink param_id
        assert d.value == was and d.lo <= was <= d.hi and d.lo < d.hi, name
        assert d.unit and len(d.doc) > 20, name
        assert f"`{name}`" in listed, f"{name} missing from docs/mavlink.md's table"
        # read and set through the store, its range enforced
        assert store[name] == was
        inside = d.lo + 0.25 * (d.hi - d.lo)
        assert store.try_set(name, inside)[0] and store[name] == inside
        assert not store.try_set(name, d.hi + 1.0)[0] and store[name] == inside
        assert not store.try_set(name, d.lo - 1.0)[0] and store[name] == inside
    # the cycle's recovery gains ride in the compiled step's parameter block (the winch's lim vector)
    assert {"REC_LEN_KL", "REC_TENS_KT", "REC_PAY_MAX"} <= set(LIMIT_PARAMS)
    # the table's count is the definition's
    assert f"There are {len(defs)} of them" in listed


def _recover(k_slack: float) -> np.ndarray:
    """30 s of RECOVER from the start of the physical nominal cycle with REC_SLK_KL ``k_slack``:
    the line length [m] of every step."""
    ref = TrackingReference.from_ocp_file(NOMINAL)

    def setup(ap, sim):
        assert ap.params.try_set("REC_SLK_KL", k_slack)[0]
        ap.set_mode("RECOVER")

    rep = fly(ref, config="nominal", cycles=1, t_end=30.0, setup=setup)
    assert rep.status == "ok", rep.message
    return rep.result.data[1:, C["length"]]


def test_recover_reels_in_by_rec_slk_kl():
    """REC_SLK_KL 0: RECOVER takes up no slack (the line stays paid out); the default 0.5 1/s
    reels in the slack beyond REC_SLACK (over 30 m in 30 s, measured 48 m); 2 1/s no less."""
    off, default, fast = (_recover(k) for k in (0.0, 0.5, 2.0))
    assert np.min(off) > off[0] - 1.0 and off[-1] > 190.0
    assert default[-1] < off[-1] - 30.0
    assert fast[-1] <= default[-1] + 0.5


def _cycle(params: dict[str, float], per_step: bool) -> tuple[np.ndarray, object]:
    """One cycle of the physical nominal reference with ``params`` set: the log and the runner."""
    ref = TrackingReference.from_ocp_file(NOMINAL)
    held = {}

    def setup(ap, sim):
        held["sim"] = sim
        for k, v in params.items():
            assert ap.params.try_set(k, v)[0]

    rep = fly(ref, config="nominal", cycles=1, setup=setup, on_step=(lambda k, s, o: None) if per_step else None)
    return rep.result.data, held["sim"]


def test_the_compiled_step_reads_the_recovery_gains_from_its_parameter_block():
    """The cycle's recovery with other REC_LEN_KL, REC_TENS_KT and REC_PAY_MAX: the flight
    changes in its recovery phase, and the compiled blocks fly the Python autopilot's bits."""
    changed = {"REC_LEN_KL": 2.0, "REC_TENS_KT": 0.05, "REC_PAY_MAX": 0.1}
    blocks, sim = _cycle(changed, per_step=False)
    if sim.block_runner is None:
        pytest.skip(f"compiled blocks not available here ({sim.loop}: {sim.loop_reason})")
    assert sim.block_runner.steps > 0.9 * len(blocks)
    python, _ = _cycle(changed, per_step=True)
    assert blocks.shape == python.shape and np.array_equal(blocks, python, equal_nan=True)
    default, _ = _cycle({}, per_step=False)
    n = min(len(default), len(blocks))
    t1 = TrackingReference.from_ocp_file(NOMINAL).meta["T1_s"]
    gen = blocks[:n, C["t"]] < t1 - 5.0
    assert np.array_equal(default[:n][gen], blocks[:n][gen], equal_nan=True)  # generation: not touched
    assert not np.array_equal(default[:n, C["reel_speed"]], blocks[:n, C["reel_speed"]])
