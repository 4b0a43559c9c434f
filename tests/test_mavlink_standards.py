"""Ground-station standards: the winch component, STATUSTEXT, standard messages, parameters as
set and MAVLink 2 signing, against independent pymavlink ground stations on 127.0.0.1.

Every wait is bounded (a few wall seconds); the sockets are closed by each test.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from pathlib import Path

import numpy as np
import pytest

from mavlink_helpers import GCS_COMPID, GCS_SYSID, Link, StandInVehicle, telemetry_at
from pymavlink import mavutil
from pymavlink.dialects.v20 import common as mav

from fdm_awe.cli import main
from fdm_awe.errors import InputError
from fdm_awe.mavlink.params import from_wire, param_text
from fdm_awe.mavlink.signing import load_key, passphrase_key
from fdm_awe.mavlink.statustext import chunks
from fdm_awe.constants import G0

KEY = hashlib.sha256(b"tethered glider test key").digest()
REF = Path(__file__).parent / "data" / "ref_physical_nominal_8mps.json"


@pytest.fixture
def link(tmp_path):
    lk = Link(StandInVehicle(params_path=tmp_path / "params.json"))
    lk.step(2)
    yield lk
    lk.close()


def _cmd(lk, command, *params, comp=None):
    p = list(params) + [0.0] * (7 - len(params))
    lk.tx.command_long_send(lk.ep.sysid, lk.ep.compid if comp is None else comp, command, 0, *p)


def _from(comp):
    return lambda m: m.get_srcComponent() == comp


# ---------------------------------------------------------------- the winch component
def test_winch_is_component_169_with_heartbeat_and_winch_status(link):
    link.tx
    hb = link.wait_for("HEARTBEAT", _from(mav.MAV_COMP_ID_WINCH), timeout=4.0)
    assert hb is not None and hb.get_srcSystem() == 1
    assert hb.type == mav.MAV_TYPE_WINCH and hb.autopilot == mav.MAV_AUTOPILOT_INVALID
    ws = link.wait_for("WINCH_STATUS", timeout=4.0)
    assert ws is not None and ws.get_srcComponent() == mav.MAV_COMP_ID_WINCH == 169
    # the stand-in telemetry: 160 m out, paying out at 3.5 m/s under 30 N, 48.5 V, 1.25 A
    assert ws.line_length == pytest.approx(160.0) and ws.speed == pytest.approx(3.5)
    assert ws.tension == pytest.approx(30.0 / G0, rel=1e-6)          # MAVLink's unit is kg
    assert (ws.voltage, ws.current) == pytest.approx((48.5, 1.25))
    flags = ws.status
    assert flags & mav.MAV_WINCH_STATUS_HEALTHY and flags & mav.MAV_WINCH_STATUS_MOVING
    assert flags & mav.MAV_WINCH_STATUS_CLUTCH_ENGAGED
    assert not flags & mav.MAV_WINCH_STATUS_FULLY_RETRACTED and not flags & 256     # not retracting
    # commands addressed to the winch are answered by the winch
    _cmd(link, mav.MAV_CMD_REQUEST_MESSAGE, mav.MAVLINK_MSG_ID_WINCH_STATUS, comp=169)
    ack = link.wait_for("COMMAND_ACK", lambda m: m.command == mav.MAV_CMD_REQUEST_MESSAGE)
    assert ack.result == mav.MAV_RESULT_ACCEPTED and ack.get_srcComponent() == 169
    _cmd(link, mav.MAV_CMD_DO_WINCH, 1, 0, 5.0, comp=169)
    ack = link.wait_for("COMMAND_ACK", lambda m: m.command == mav.MAV_CMD_DO_WINCH)
    assert ack.result == mav.MAV_RESULT_UNSUPPORTED and ack.get_srcComponent() == 169
    assert link.vehicle.mode == "MANUAL"        # the autopilot did not take it


# ---------------------------------------------------------------- STATUSTEXT
def test_statustext_on_mode_arm_and_phase_changes(link):
    _cmd(link, mav.MAV_CMD_DO_SET_MODE, mav.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 10)   # AUTO
    st = link.wait_for("STATUSTEXT", lambda m: "mode" in m.text)
    assert st is not None and st.text == "mode MANUAL -> AUTO" and st.severity == mav.MAV_SEVERITY_NOTICE
    assert st.get_srcComponent() == 1
    _cmd(link, mav.MAV_CMD_COMPONENT_ARM_DISARM, 1)
    assert link.wait_for("STATUSTEXT", lambda m: m.text == "armed") is not None
    # a mode change made by the vehicle itself (not commanded) is reported too
    link.vehicle.mode = "RECOVER"
    link.tx
    assert link.wait_for("STATUSTEXT", lambda m: m.text == "mode AUTO -> RECOVER") is not None
    # phase changes come from the telemetry
    ep, t = link.ep, link.t
    link.tx
    for k in range(40):
        tel = telemetry_at(t + k / 120.0, link.vehicle)
        tel.phase = "generation" if k < 20 else "recovery"
        ep.update(t + k / 120.0, tel)
        time.sleep(0.001)
    link.t = t + 40 / 120.0
    st = link.wait_for("STATUSTEXT", lambda m: m.text.startswith("phase"))
    assert st is not None and st.text == "phase generation -> recovery"


def test_statustext_says_why_a_failsafe_changed_the_mode(link):
    """The vehicle's failsafe notes go out as WARNING before the mode change they cause; its
    other notes do not."""
    link.vehicle.log = [(0.5, "rejoin: on the path")]
    link.tx
    link.step(2)
    link.vehicle.log.append((1.0, "failsafe: 68.5 m from the path for 5.0 s (FS_TRK_ERR 50 m)"))
    link.vehicle.mode = "RECOVER"
    texts = []
    st = link.wait_for("STATUSTEXT", lambda m: texts.append((m.text, m.severity)) or m.text.startswith("mode"))
    assert st is not None
    # a text over 50 characters arrives in chunks (tested above), the mode change after it
    warned = "".join(t for t, sev in texts if sev == mav.MAV_SEVERITY_WARNING)
    assert warned == "failsafe: 68.5 m from the path for 5.0 s (FS_TRK_ERR 50 m)"
    assert texts[-1] == ("mode MANUAL -> RECOVER", mav.MAV_SEVERITY_NOTICE)
    assert not [t for t, _ in texts if t.startswith("rejoin")]


def test_flight_end_and_long_texts_go_out_in_chunks(link):
    msg = ("ground contact at x=12.3 m, y=-4.5 m, 14.2 m/s, sink 4.8 m/s (a crash, not a landing)")
    link.tx
    link.ep.flight_ended("ground_contact", msg)
    parts = []
    t_end = time.monotonic() + 3.0
    while time.monotonic() < t_end and (not parts or len(parts[-1].text) == 50):
        link.drain()
        parts = [m for m in link.received if m.get_type() == "STATUSTEXT" and m.id != 0]
        time.sleep(0.01)
    text = f"flight ground_contact: {msg}"
    n = len(text) // 50 + 1
    assert len(parts) == n == 3 and [m.chunk_seq for m in parts] == list(range(n))
    assert len({m.id for m in parts}) == 1 and len(parts[-1].text) < 50
    assert all(m.severity == mav.MAV_SEVERITY_CRITICAL for m in parts)
    assert "".join(m.text for m in parts) == text
    # a text of exactly 50 characters: one chunk; 100: two full ones and an empty end chunk
    assert [len(c[2]) for c in chunks("x" * 50)] == [50]
    assert [len(c[2]) for c in chunks("x" * 100)] == [50, 50, 0]


# ---------------------------------------------------------------- standard messages
def test_gps_mission_current_nav_controller_and_servo_outputs(link):
    got = {}
    link.tx
    for mtype in ("GPS_RAW_INT", "MISSION_CURRENT", "NAV_CONTROLLER_OUTPUT", "SERVO_OUTPUT_RAW",
                  "GLOBAL_POSITION_INT"):
        got[mtype] = link.wait_for(mtype, timeout=4.0)
        assert got[mtype] is not None, mtype
    gps, gp = got["GPS_RAW_INT"], got["GLOBAL_POSITION_INT"]
    assert gps.fix_type == mav.GPS_FIX_TYPE_3D_FIX and gps.satellites_visible >= 6
    # the same glider: within the distance flown between the two messages (< 2 m)
    assert abs(gps.lat - gp.lat) < 200 and abs(gps.lon - gp.lon) < 300 and abs(gps.alt - gp.alt) < 2000
    tel = telemetry_at(gps.time_usec * 1e-6)
    assert gps.vel == round(math.hypot(*tel.vel_ned[:2]) * 100)
    mc = got["MISSION_CURRENT"]
    assert (mc.seq, mc.total) == (3, 24)
    assert mc.mission_state == mav.MISSION_STATE_PAUSED          # stand-in: MANUAL, not cycling
    nav = got["NAV_CONTROLLER_OUTPUT"]
    assert (nav.nav_roll, nav.nav_pitch) == pytest.approx((math.degrees(0.3), math.degrees(0.1)), abs=1e-3)
    assert (nav.nav_bearing, nav.target_bearing, nav.wp_dist) == (80, 92, 8)
    assert (nav.alt_error, nav.aspd_error, nav.xtrack_error) == pytest.approx((-1.5, 0.5, 2.0))
    sv = got["SERVO_OUTPUT_RAW"]
    # ArduPlane order: aileron 0.1, elevator -0.2, throttle 0.3, rudder 0.05, fold 0
    assert (sv.servo1_raw, sv.servo2_raw, sv.servo3_raw, sv.servo4_raw, sv.servo5_raw) == (
        1550, 1400, 1300, 1525, 1000)


# ---------------------------------------------------------------- parameters as set
def test_param_set_is_stored_as_typed_not_as_float32(link, tmp_path):
    ts, tc = link.target()
    link.tx.param_set_send(ts, tc, b"AP_ROLL_KP", 1.1, mav.MAV_PARAM_TYPE_REAL32)
    pv = link.wait_for("PARAM_VALUE", lambda m: m.param_id == "AP_ROLL_KP")
    assert pv.param_value == float(np.float32(1.1))              # the wire carries float32
    assert link.vehicle.params["AP_ROLL_KP"] == 1.1              # the store keeps what was typed
    saved = json.loads((tmp_path / "params.json").read_text())["params"]
    assert saved["AP_ROLL_KP"] == 1.1 and "1.100000023841858" not in (tmp_path / "params.json").read_text()
    # the top of a range: float32(0.1) > 0.1 would be refused; as typed it is accepted
    link.tx.param_set_send(ts, tc, b"WINCH_PI_KP", 0.1, mav.MAV_PARAM_TYPE_REAL32)
    link.wait_for("PARAM_VALUE", lambda m: m.param_id == "WINCH_PI_KP")
    assert link.vehicle.params["WINCH_PI_KP"] == 0.1
    assert from_wire(float(np.float32(0.35))) == 0.35 and param_text(1.1) == "1.1" and param_text(3.0) == "3"


# ---------------------------------------------------------------- signing
def _gcs(port, key=None, sysid=GCS_SYSID):
    g = mavutil.mavlink_connection(f"udpout:127.0.0.1:{port}", source_system=sysid, source_component=GCS_COMPID)
    if key is not None:
        g.setup_signing(key, sign_outgoing=True)
    return g


def _signed(m) -> bool:
    """The frame carried a signature (whether or not the receiver could check it)."""
    return bool(m.get_header().incompat_flags & mav.MAVLINK_IFLAG_SIGNED)


def _pump(lk, gcs, cond, timeout=1.5):
    """Step the vehicle until ``cond(msg)`` holds for a message ``gcs`` received; None on timeout."""
    t_end = time.monotonic() + timeout
    while time.monotonic() < t_end:
        lk.ep.update(lk.t, lambda: telemetry_at(lk.t, lk.vehicle))   # not lk.step(): it drains lk.gcs
        lk.t += lk.dt
        while True:
            m = gcs.recv_match(blocking=False)
            if m is None:
                break
            if m.get_type() != "BAD_DATA" and cond(m):
                return m
        time.sleep(0.001)
    return None


def _try_commands(lk, gcs, value):
    """Arm, mode AUTO and a parameter set from ``gcs``; the acknowledgements it got."""
    ts, tc = lk.target()
    gcs.mav.command_long_send(ts, tc, mav.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0)
    arm = _pump(lk, gcs, lambda m: m.get_type() == "COMMAND_ACK" and m.command == mav.MAV_CMD_COMPONENT_ARM_DISARM)
    gcs.mav.command_long_send(ts, tc, mav.MAV_CMD_DO_SET_MODE, 0, mav.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 10,
                              0, 0, 0, 0, 0)
    mode = _pump(lk, gcs, lambda m: m.get_type() == "COMMAND_ACK" and m.command == mav.MAV_CMD_DO_SET_MODE)
    gcs.mav.param_set_send(ts, tc, b"AP_ROLL_KP", value, mav.MAV_PARAM_TYPE_REAL32)
    par = _pump(lk, gcs, lambda m: m.get_type() == "PARAM_VALUE" and m.param_id == "AP_ROLL_KP")
    return arm, mode, par


def test_with_a_key_only_a_ground_station_holding_it_commands(tmp_path):
    lk = Link(StandInVehicle(), gcs_udpin=False, signing_key=KEY)
    v = lk.vehicle
    try:
        # no key: sees the (signed) telemetry, but arm, mode and parameter changes are ignored
        lk.gcs.mav.heartbeat_send(mav.MAV_TYPE_GCS, mav.MAV_AUTOPILOT_INVALID, 0, 0, 0)
        hb = _pump(lk, lk.gcs, lambda m: m.get_type() == "HEARTBEAT" and m.get_srcComponent() == 1, timeout=3.0)
        assert hb is not None and _signed(hb)
        ws = _pump(lk, lk.gcs, lambda m: m.get_type() == "WINCH_STATUS", timeout=3.0)
        assert ws is not None and _signed(ws)
        assert _try_commands(lk, lk.gcs, 2.5) == (None, None, None)
        assert (v.armed, v.mode, v.params["AP_ROLL_KP"]) == (False, "MANUAL", 0.8)
        assert lk.ep.stats["signing"]["unsigned_rejected"] >= 4     # heartbeat + three commands

        # the wrong key: badly signed, ignored the same way
        wrong = _gcs(lk.port, hashlib.sha256(b"not the key").digest(), sysid=254)
        assert _try_commands(lk, wrong, 2.5) == (None, None, None)
        assert (v.armed, v.mode, v.params["AP_ROLL_KP"]) == (False, "MANUAL", 0.8)
        assert lk.ep.stats["signing"]["bad_signature_rejected"] >= 3
        wrong.close()

        # the key: obeyed
        good = _gcs(lk.port, KEY, sysid=253)
        arm, mode, par = _try_commands(lk, good, 2.5)
        assert arm.result == mav.MAV_RESULT_ACCEPTED and mode.result == mav.MAV_RESULT_ACCEPTED
        assert par.param_value == 2.5 and arm.get_signed()
        assert (v.armed, v.mode, v.params["AP_ROLL_KP"]) == (True, "AUTO", 2.5)
        ss = _pump(lk, good, lambda m: m.get_type() == "SYS_STATUS", timeout=3.0)
        assert ss.errors_count3 >= 7          # rejected messages are counted in SYS_STATUS too

        # a recorded signed command replayed: its timestamp is old on its stream, ignored
        ts, tc = lk.target()
        frame = good.mav.command_long_encode(ts, tc, mav.MAV_CMD_COMPONENT_ARM_DISARM, 0, 0, 0, 0, 0, 0, 0, 0)
        raw = frame.pack(good.mav)
        good.write(raw)
        assert _pump(lk, good, lambda m: m.get_type() == "COMMAND_ACK") is not None and not v.armed
        v.arm(True)
        before = lk.ep.stats["signing"]["bad_signature_rejected"]
        good.write(raw)
        assert _pump(lk, good, lambda m: m.get_type() == "COMMAND_ACK", timeout=1.0) is None and v.armed
        assert lk.ep.stats["signing"]["bad_signature_rejected"] == before + 1
        good.close()
    finally:
        lk.close()


def test_setup_signing_changes_the_key_and_saves_it(tmp_path):
    key_file = tmp_path / "vehicle.key"
    key_file.write_bytes(KEY)
    lk = Link(StandInVehicle(), gcs_udpin=False, signing_key=load_key(key_file), signing_key_file=key_file)
    try:
        old = _gcs(lk.port, KEY, sysid=253)
        new_key = hashlib.sha256(b"the new key").digest()
        ts, tc = lk.target()
        old.mav.setup_signing_send(ts, tc, list(new_key), 0)
        t_end = time.monotonic() + 2.0
        while lk.ep.signer.key != new_key and time.monotonic() < t_end:
            _pump(lk, old, lambda m: False, timeout=0.05)
        assert lk.ep.signer.key == new_key          # (its STATUSTEXT is signed with the new key)
        assert key_file.read_bytes() == new_key and load_key(key_file) == new_key
        assert _try_commands(lk, old, 2.0) == (None, None, None)      # the old key no longer works
        old.close()
        new = _gcs(lk.port, new_key, sysid=252)
        arm, _, _ = _try_commands(lk, new, 2.0)
        assert arm is not None and arm.result == mav.MAV_RESULT_ACCEPTED
        new.close()
    finally:
        lk.close()
    # without a key, SETUP_SIGNING cannot lock the operator out
    lk = Link(StandInVehicle(), gcs_udpin=False)
    try:
        lk.gcs.mav.setup_signing_send(*lk.target(), list(KEY), 0)
        st = _pump(lk, lk.gcs, lambda m: m.get_type() == "STATUSTEXT", timeout=2.0)
        assert st is not None and "refused" in st.text and not lk.ep.signer.on
    finally:
        lk.close()


def test_key_files_passphrases_and_their_errors(tmp_path):
    raw = tmp_path / "raw.key"
    raw.write_bytes(KEY)
    assert load_key(raw) == KEY
    phrase = tmp_path / "phrase.txt"
    phrase.write_text("correct horse battery staple\n")
    assert load_key(phrase) == passphrase_key("correct horse battery staple") == hashlib.sha256(
        b"correct horse battery staple").digest()
    cases = {"missing.key": None, "empty.key": b"", "two_lines.txt": b"a\nb\n", "zero.key": bytes(32),
             "binary.key": bytes(range(200, 240)), "big.txt": b"x" * 5000}
    for name, data in cases.items():
        p = tmp_path / name
        if data is not None:
            p.write_bytes(data)
        with pytest.raises(InputError, match="--mavlink-key") as e:
            load_key(p)
        assert "\n" not in str(e.value), name


def test_fly_checks_the_key_file_before_the_flight(tmp_path, capsys):
    for argv, words in (
            (["--mavlink", "udpout:127.0.0.1:14550", "--mavlink-key", str(tmp_path / "none.key")], ("no such file",)),
            (["--mavlink-key", str(REF)], ("only with --mavlink",)),
    ):
        t0 = time.monotonic()
        rc = main(["fly", "--reference", str(REF), "--quiet", *argv])
        err = capsys.readouterr().err.strip()
        assert rc == 2 and time.monotonic() - t0 < 10.0, err
        assert "\n" not in err and "--mavlink-key" in err and all(w in err for w in words), err
