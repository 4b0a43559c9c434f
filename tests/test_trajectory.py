"""The trajectory module's one sampler and the in-memory reference.

The sampler's rules (fdm_awe/trajectory.py): LINEAR is linear in time across the segment
(exact at the rows, between its neighbours inside), HELD is the value of the optimiser's
interval (the row opening the segment, the closing row's across a phase switch). The file's
rules hold the controls; the autopilot's feed-forward is linear. A reference built in memory
from a cycle result is what the file written from it reads back as.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fdm_awe.autopilot.tracking import TRACKING_RULES, TrackingReference
from fdm_awe.ocp.result import CycleResult
from fdm_awe.trajectory import (COLUMN_UNITS, GENERATION, HELD, LINEAR, RECOVERY, REFERENCE_RULES, CycleSampler,
                                read_reference, reference_from_result, write_reference)

DATA = Path(__file__).parent / "data"
STORED = sorted(DATA.glob("ref_*.json"))


@pytest.mark.parametrize("path", STORED, ids=lambda p: p.stem)
def test_file_rules_at_and_between_the_rows(path: Path) -> None:
    ref = read_reference(path)
    c = ref.columns
    t, ph = c["t"], c["phase"]
    T1 = ref.metadata["T1_s"]
    names = [k for k in c if k not in ("t", "phase")]
    for i in range(len(t) - 1):
        if t[i + 1] == t[i]:  # the switch row of generation: a sample at T1 is recovery's
            continue
        s = ref.sample(float(t[i]))
        assert s["phase"] == (GENERATION if t[i] < T1 else RECOVERY)
        for k in names:
            assert s[k] == c[k][i], (k, i)  # both rules give the row itself
        m = ref.sample(float(0.5 * (t[i] + t[i + 1])))
        for k in names:
            if REFERENCE_RULES.get(k, LINEAR) == HELD:
                assert m[k] == c[k][i], (k, i)  # the interval's value, as stored
            else:
                lo, hi = sorted((c[k][i], c[k][i + 1]))
                assert lo - 1e-9 * (1 + abs(lo)) <= m[k] <= hi + 1e-9 * (1 + abs(hi)), (k, i)
    # within a phase: just after the switch every column is the recovery's first row
    j = int(np.flatnonzero(ph == 1.0)[0])
    s = ref.sample(float(t[j]))
    assert all(s[k] == c[k][j] for k in names)


@pytest.mark.parametrize("path", STORED, ids=lambda p: p.stem)
def test_tracking_rules_feed_forward_linear_motor_and_duty_held(path: Path) -> None:
    tr = TrackingReference.from_ocp_file(path)
    assert {TRACKING_RULES[k] for k in ("pos", "vel", "acc", "airspeed", "alpha", "phi", "thrust")} == {LINEAR}
    assert TRACKING_RULES["motor_on"] == TRACKING_RULES["boost_duty"] == HELD
    k1 = int(np.flatnonzero(tr.phase == 1)[0])  # first recovery row after the switch (stored once)
    t0, t1 = tr.t[k1 - 1], tr.t[k1]
    assert t0 == pytest.approx(tr.T1) and tr.phase[k1 - 1] == 0
    p = tr.sample(float(0.5 * (t0 + t1)))
    assert p.phase == RECOVERY
    lo, hi = sorted((tr.alpha[k1 - 1], tr.alpha[k1]))
    assert lo - 1e-12 <= p.alpha <= hi + 1e-12  # linear from the generation's last row
    assert p.motor_on == tr.motor_on[k1] and p.boost_duty == tr.boost_duty[k1]  # the recovery's interval
    later = tr.sample(float(0.5 * (t0 + t1)) + 3 * tr.period)
    assert later.cycle == 3 and later.t_cycle == pytest.approx(p.t_cycle, abs=1e-9)


def test_sampler_refuses_what_it_cannot_sample() -> None:
    t, ph = [0.0, 1.0, 1.0, 2.0], [0, 0, 1, 1]
    s = CycleSampler(t, ph, {"x": [0.0, 1.0, 5.0, 6.0], "u": [1.0, 1.0, 2.0, 2.0]}, {"x": LINEAR, "u": HELD}, 1.0, 2.0)
    a = s.sample(1.0)
    assert (a.phase, a["x"], a["u"]) == (RECOVERY, 5.0, 2.0)  # the later of a repeated time opens the segment
    assert s.sample(0.5)["x"] == 0.5 and s.sample(0.5)["u"] == 1.0
    with pytest.raises(ValueError, match="increasing"):
        CycleSampler([0.0, 1.0, 1.0], [0, 0, 0], {}, {}, 1.0, 2.0)  # a repeated time inside a phase
    with pytest.raises(ValueError, match="rule"):
        CycleSampler(t, ph, {"x": [0.0] * 4}, {"x": "cubic"}, 1.0, 2.0)
    with pytest.raises(ValueError, match="shape"):
        CycleSampler(t, ph, {"u": np.zeros((4, 2))}, {"u": HELD}, 1.0, 2.0)


def test_reference_in_memory_is_the_file_written_from_it(tmp_path: Path) -> None:
    src = read_reference(STORED[0])
    md = src.metadata
    res = CycleResult(md["scenario"], md["config"], md["wind_mps"], md["wind_from_deg"], "ok", "Solve_Succeeded",
                      0.0, 0.0, 0, T1_s=md["T1_s"], T2_s=md["T2_s"], k_wrap=md["k_wrap"],
                      E_generated_J=1.0, E_thrust_J=2.0,
                      E_reel_in_J=0.5, columns={k: src[k].copy() for k in COLUMN_UNITS})
    mem = reference_from_result(res)
    disk = read_reference(write_reference(res, tmp_path / "ref.json"))
    assert mem.metadata == disk.metadata and mem.units == disk.units
    assert list(mem.columns) == list(disk.columns)
    for k in mem.columns:
        assert mem[k].tobytes() == disk[k].tobytes(), k
    a, b = TrackingReference.from_ocp(mem), TrackingReference.from_ocp(disk)
    for x in np.linspace(0.0, 2 * a.period, 97):
        pa, pb = a.sample(float(x)), b.sample(float(x))
        assert pa.pos.tobytes() == pb.pos.tobytes() and pa.alpha == pb.alpha and pa.motor_on == pb.motor_on
