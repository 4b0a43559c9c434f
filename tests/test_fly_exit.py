"""The exit status of ``fdm-awe fly`` for every way a flight ends (docs/design.md section 1),
the step the attitude loops fly with and the steps a flight keeps in memory, both checked
before any work."""

from __future__ import annotations

import json
import re
import time
from pathlib import Path

import pytest

from fdm_awe.cli import main
from fdm_awe.groundstation.substeps import EVENTS as STATION_EVENTS
from fdm_awe.sim import budget
from fdm_awe.sim.events import EVENTS
from fdm_awe.sim.report import FLIGHT_STATUSES, flight_exit_code

ROOT = Path(__file__).resolve().parent.parent
REF = ROOT / "tests" / "data" / "ref_physical_nominal_8mps.json"
FAILSAFE = "failsafe: 51.0 m from the path for 5.0 s (FS_TRK_ERR 50 m)"


def _design_exit_table() -> dict[str, str]:
    """The ``fly`` section's table of statuses and exit codes in docs/design.md."""
    text = (ROOT / "docs" / "design.md").read_text()
    section = text[text.index("### `fdm-awe fly`"):text.index("### `fdm-awe compare`")]
    rows = re.findall(r"^\s*\| (.+?) \| (.+?) \|$", section, re.M)
    return {name: code for name, code in rows if name not in ("status", "---")}


def test_every_flight_status_has_its_exit_code_in_the_design():
    table = _design_exit_table()
    # every status a flight can end with: the flight's, the co-simulation's events', the ground station's
    statuses = set(FLIGHT_STATUSES) | {k.status for k in EVENTS if k.status}
    for status in statuses:
        assert f"`{status}`" in table, f"docs/design.md section 1 lists no exit code for {status}"
        code = table[f"`{status}`"]
        if status in ("landed", "parked"):
            assert code == "0 after a commanded RECOVER, 1 after a failsafe"
            assert flight_exit_code(status, "commanded") == 0
            assert flight_exit_code(status, FAILSAFE) == 1
            assert flight_exit_code(status, None) == 1
        else:
            assert flight_exit_code(status, None) == int(code) == flight_exit_code(status, "commanded")
    station = [k for k in table if "ground-station event" in k]
    assert len(station) == 1 and table[station[0]] == "1"
    for name in STATION_EVENTS[1:]:
        assert flight_exit_code(name, None) == 1


def _params(tmp_path: Path, **values: float) -> Path:
    p = tmp_path / "params.json"
    p.write_text(json.dumps({"format": "fdm-awe-params-1", "params": values}))
    return p


def test_a_flight_the_failsafe_lands_did_not_fly_its_cycle_exit_1(tmp_path, capsys):
    """The lost-path failsafe (FS_TRK_ERR 1 cm: at once) takes the glider out of its only cycle;
    it lands at the winch, safe, but the cycle asked for was not flown: exit 1 (0 before), the
    JSON says why it was in RECOVER."""
    out = tmp_path / "run.json"
    rc = main(["fly", "--reference", str(REF), "--cycles", "1", "--quiet", "--json", str(out),
               "--params", str(_params(tmp_path, FS_TRK_ERR=0.01, FS_TRK_TIME=0.1))])
    doc = json.loads(out.read_text())
    assert doc["status"] == "landed", doc["message"]
    assert doc["recover_cause"].startswith("failsafe: ") and "FS_TRK_ERR" in doc["recover_cause"]
    assert not any(c["complete"] for c in doc["cycles"])
    assert "0 of 1 cycles complete" in doc["message"]
    assert rc == 1


def test_the_start_mode_recover_is_commanded(tmp_path):
    """``--mode RECOVER`` asks for the recovery: its cause is "commanded" (a landing or a
    hold then exits 0); the autopilot keeps the failsafe's cause until another mode is set."""
    from fdm_awe.autopilot.vehicle_commands import VehicleCommands

    class _Ap:  # the autopilot's mode bookkeeping without a glider
        set_mode = VehicleCommands.set_mode
        _failsafe = VehicleCommands._failsafe

        def __init__(self):
            self.mode, self.reference, self.log = "AUTO", object(), []
            self.recover_cause = self._failsafe_note = None
            self.recovery = type("R", (), {"stage": None})()

        def _note(self, text):
            self.log.append(text)

    ap = _Ap()
    assert ap.set_mode("RECOVER") and ap.recover_cause == "commanded"
    assert ap.set_mode("AUTO") and ap.recover_cause is None
    ap._failsafe(FAILSAFE)
    assert ap.mode == "RECOVER" and ap.recover_cause == FAILSAFE and ap._failsafe_note is None
    assert ap.set_mode("RECOVER") and ap.recover_cause == FAILSAFE  # no change of mode: still the failsafe's
    assert ap.set_mode("FBWA") and ap.set_mode("RECOVER") and ap.recover_cause == "commanded"


# ------------------------------------------------------------------ the step and the memory, before any work
def _refused(argv: list[str], capsys) -> str:
    t0 = time.perf_counter()
    assert main(argv) == 2
    assert time.perf_counter() - t0 < 10.0  # refused before JSBSim, the optimiser or a flight
    err = capsys.readouterr().err.strip()
    assert "\n" not in err
    return err


def test_a_step_the_attitude_loops_cannot_fly_with_is_refused(tmp_path, capsys):
    """20 Hz (the issue's ``--dt 0.05``): W_PHI 20 rad/s x 0.05 s = 1, the path is lost; the
    allowed range follows the gains (0.25 / W)."""
    err = _refused(["fly", "--reference", str(REF), "--cycles", "1", "--dt", "0.05"], capsys)
    assert "--dt 0.05" in err and "W_PHI 20 rad/s" in err and "allowed 0.0001..0.0125 s" in err
    err = _refused(["fly", "--reference", str(REF), "--dt", "0.01",
                    "--params", str(_params(tmp_path, W_PHI=30.0))], capsys)
    assert "--dt 0.01" in err and "W_PHI 30 rad/s" in err and "allowed 0.0001..0.008333 s" in err
    assert budget.check_step(1.0 / 120.0, {"W_ALPHA": 15.0, "W_PHI": 20.0}) == pytest.approx(1.0 / 120.0)
    assert budget.check_step(0.0125, {"W_ALPHA": 15.0, "W_PHI": 20.0}) == 0.0125


@pytest.mark.parametrize("argv, allowed", [
    (["--reference", str(REF), "--cycles", "1000"], "allowed 1..51 cycles at this step"),
    (["--reference", str(REF), "--cycles", "200"], "allowed 1..51 cycles at this step"),
    (["--cycles", "200"], "allowed 1..52 cycles at this step"),  # before the optimisation: its longest cycle, 60 s
    (["--reference", str(REF), "--cycles", "1", "--dt", "0.0001"], "a step of at least 0.00017 s (--dt)"),
])
def test_a_flight_longer_than_the_memory_holds_is_refused(argv, allowed, capsys):
    """The issue's ``--cycles 1000`` (19 MB a cycle, 1.4 GB after 75): refused before the work,
    the limit named."""
    err = _refused(["fly", *argv, "--quiet"], capsys)
    assert err.startswith("fdm-awe fly: error: --cycles ") and "750000" in err and allowed in err
    assert str(budget.MAX_FLIGHT_STEPS) == "750000"

