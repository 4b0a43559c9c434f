"""A standard vehicle for every ground-station library, message by message, against a pymavlink
ground station on 127.0.0.1 (the endpoint with a stand-in vehicle), and the autopilot's side of
it (LOITER, the pilot's sticks in FBWA) in short real flights.

Every wait is bounded (a few wall seconds); the sockets are closed by each test.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from flight_helpers import DATA
from mavlink_helpers import Link, StandInVehicle, free_udp_port
from pymavlink import mavutil
from pymavlink.dialects.v20 import common as mav

from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.mavlink.boot import BootBeacon
from fdm_awe.mavlink.transport import close_link, open_link
from fdm_awe.mavlink import pilot as pilot_mod
from fdm_awe.mavlink.messages import euler_quaternion
from fdm_awe.sim.flight import fly

NOMINAL = DATA / "ref_physical_nominal_8mps_sized.json"


class _Piloted(StandInVehicle):
    """The stand-in vehicle with LOITER and the pilot's sticks recorded."""

    modes = ["MANUAL", "FBWA", "AUTO", "RECOVER", "LOITER"]

    def __init__(self, *a, **kw) -> None:
        super().__init__(*a, **kw)
        self.sticks: list[tuple[float, float, float, float]] = []

    def set_pilot(self, aileron, elevator, rudder, throttle) -> None:
        self.sticks.append((aileron, elevator, rudder, throttle))


@pytest.fixture
def link(tmp_path):
    lk = Link(_Piloted(params_path=tmp_path / "params.json"))
    lk.step(2)
    yield lk
    lk.close()


def _cmd(lk, command, *params):
    p = list(params) + [0.0] * (7 - len(params))
    lk.tx.command_long_send(lk.ep.sysid, lk.ep.compid, command, 0, *p)
    return lk.wait_for("COMMAND_ACK", lambda m: m.command == command)


def _text(lk, word):
    return lk.wait_for("STATUSTEXT", lambda m: word in m.text, timeout=2.0)


def test_heartbeat_is_ardupilots_with_arduplane_modes_and_loiter_is_offered(link):
    link.tx
    hb = link.wait_for("HEARTBEAT", lambda m: m.get_srcComponent() == 1)
    assert hb.autopilot == mav.MAV_AUTOPILOT_ARDUPILOTMEGA and hb.type == mav.MAV_TYPE_FIXED_WING
    assert hb.custom_mode == 0                                   # the stand-in starts in MANUAL
    ack = _cmd(link, mav.MAV_CMD_DO_SET_MODE, mav.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 12)
    assert ack.result == mav.MAV_RESULT_ACCEPTED and link.vehicle.mode == "LOITER"
    link.tx
    hb = link.wait_for("HEARTBEAT", lambda m: m.get_srcComponent() == 1 and m.custom_mode == 12, timeout=3.0)
    assert hb is not None


def test_extended_state_quaternion_system_time_prearm_bit_and_battery(link):
    link.tx
    got = {t: link.wait_for(t, timeout=3.0) for t in ("EXTENDED_SYS_STATE", "ATTITUDE_QUATERNION",
                                                       "SYSTEM_TIME", "SYS_STATUS", "BATTERY_STATUS")}
    assert all(v is not None for v in got.values()), got
    # the stand-in telemetry says nothing of ground contact: UNDEFINED, never a guess
    assert got["EXTENDED_SYS_STATE"].landed_state == mav.MAV_LANDED_STATE_UNDEFINED
    q = got["ATTITUDE_QUATERNION"]
    w, x, y, z = euler_quaternion(0.2, 0.05, 1.5)                # the stand-in's attitude
    assert (q.q1, q.q2, q.q3, q.q4) == pytest.approx((w, x, y, z), abs=1e-6)
    assert math.isclose(q.q1**2 + q.q2**2 + q.q3**2 + q.q4**2, 1.0, rel_tol=1e-6)
    # roll back from the quaternion: 0.2 rad
    assert math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y)) == pytest.approx(0.2, abs=1e-9)
    assert got["SYSTEM_TIME"].time_unix_usec > 1.6e15          # the wall clock, after 2020
    ss = got["SYS_STATUS"]
    bit = mav.MAV_SYS_STATUS_PREARM_CHECK
    assert ss.onboard_control_sensors_present & bit and ss.onboard_control_sensors_enabled & bit
    assert ss.onboard_control_sensors_health & bit
    bs = got["BATTERY_STATUS"]
    assert bs.voltages[0] == 11800 and bs.current_battery == 250 and bs.battery_remaining == 80
    # charge and energy drawn are not in the stand-in telemetry: unknown (-1), not invented
    assert bs.current_consumed == -1 and bs.energy_consumed == -1


def test_whole_number_and_switch_parameters_are_int32(link):
    link.tx.param_request_list_send(1, 1)
    types = {}
    for _ in range(200):
        link.step()
        for m in link.received:
            if m.get_type() == "PARAM_VALUE":
                types[m.param_id] = m.param_type
        if len(types) == len(link.vehicle.params):
            break
    assert types["CYCLE_COUNT"] == types["FOLD_ENABLE"] == mav.MAV_PARAM_TYPE_INT32
    assert types["AP_ROLL_KP"] == mav.MAV_PARAM_TYPE_REAL32


def test_a_repeated_refused_param_set_gets_its_reason_once(link):
    for _ in range(5):   # MAVSDK's retries
        link.tx.param_set_send(1, 1, b"CYCLE_COUNT", 2.5, mav.MAV_PARAM_TYPE_INT32)
        pv = link.wait_for("PARAM_VALUE", lambda m: m.param_id == "CYCLE_COUNT")
        assert pv.param_value == 3.0                  # the old value, as ArduPilot answers a denied write
    link.step(20)
    texts = [m.text for m in link.received if m.get_type() == "STATUSTEXT" and "CYCLE_COUNT" in m.text]
    assert len(texts) == 1 and "whole number" in texts[0]


def test_downloaded_items_mark_the_current_one(link):
    link.tx.mission_request_list_send(1, 1)
    count = link.wait_for("MISSION_COUNT").count
    current = []
    for seq in range(count):
        link.tx.mission_request_int_send(1, 1, seq)
        it = link.wait_for("MISSION_ITEM_INT", lambda m, s=seq: m.seq == s)
        current.append(it.current)
    link.tx.mission_ack_send(1, 1, mav.MAV_MISSION_ACCEPTED)
    link.tx
    mc = link.wait_for("MISSION_CURRENT")
    assert current.count(1) == 1 and current.index(1) == mc.seq == 3    # the stand-in flies to item 3


def test_every_refusal_says_why(link):
    cases = [
        ((mav.MAV_CMD_DO_SET_MODE, mav.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 15), mav.MAV_RESULT_DENIED,
         "GUIDED) not offered"),
        ((mav.MAV_CMD_DO_SET_MODE, mav.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 99), mav.MAV_RESULT_DENIED, "unknown"),
        ((mav.MAV_CMD_DO_CHANGE_SPEED, 0, 15.0), mav.MAV_RESULT_DENIED, "speed change refused"),
        ((mav.MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN, 2), mav.MAV_RESULT_DENIED, "shutdown refused: in flight"),
        ((mav.MAV_CMD_DO_FOLLOW,), mav.MAV_RESULT_UNSUPPORTED, "DO_FOLLOW: unsupported"),
    ]
    for (cmd, *p), result, why in cases:
        ack = _cmd(link, cmd, *p)
        assert ack.result == result, cmd
        assert _text(link, why) is not None, why


def test_nav_land_is_recover_and_after_the_flight_flying_commands_are_refused(link):
    ack = _cmd(link, mav.MAV_CMD_NAV_LAND)
    assert ack.result == mav.MAV_RESULT_ACCEPTED and link.vehicle.mode == "RECOVER"
    link.ep.flight_ended("ok", "1 of 1 cycles")
    ack = _cmd(link, mav.MAV_CMD_DO_SET_MODE, mav.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 10)
    assert ack.result == mav.MAV_RESULT_FAILED and _text(link, "flight over") is not None
    assert link.vehicle.mode == "RECOVER"
    ack = _cmd(link, mav.MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN, 2)
    assert ack.result == mav.MAV_RESULT_ACCEPTED and link.ep.shutdown_requested


def test_request_data_stream_sets_the_groups_rates(link):
    link.tx.request_data_stream_send(1, 1, mav.MAV_DATA_STREAM_EXTRA1, 25, 1)
    link.tx.request_data_stream_send(1, 1, mav.MAV_DATA_STREAM_EXTENDED_STATUS, 0, 0)
    link.step(5)
    r = link.ep.rates()
    assert r["ATTITUDE"] == r["ATTITUDE_QUATERNION"] == 25.0
    assert r["SYS_STATUS"] == r["GPS_RAW_INT"] == r["MISSION_CURRENT"] == 0.0
    assert r["HEARTBEAT"] == 1.0 and r["VFR_HUD"] == 4.0                    # other groups untouched
    link.tx.request_data_stream_send(1, 1, mav.MAV_DATA_STREAM_ALL, 3, 1)
    link.step(5)
    r = link.ep.rates()
    assert r["VFR_HUD"] == r["SYS_STATUS"] == r["ATTITUDE"] == 3.0 and r["HEARTBEAT"] == 1.0


def test_rc_override_and_manual_control_are_the_pilots_sticks(link, monkeypatch):
    v = link.vehicle
    # roll right, pitch pulled (nose up), throttle 30 %, yaw right: ArduPlane's channels
    link.tx.rc_channels_override_send(1, 1, 1750, 1600, 1300, 1600, 0, 0, 0, 0)
    link.step(5)
    a, e, r, thr = v.sticks[-1]
    assert a == pytest.approx(0.5) and e == pytest.approx(-0.2) and r == pytest.approx(-0.2)
    assert thr == pytest.approx(0.3)
    # a joystick: x forward (nose down), y left, z 60 % throttle
    link.tx.manual_control_send(1, 500, -1000, 600, 0, 0)
    link.step(5)
    a, e, r, thr = v.sticks[-1]
    assert (a, e, r) == pytest.approx((-1.0, 0.5, 0.0)) and thr == pytest.approx(0.6)
    # released after the override times out (wall clock)
    now = link.ep.clock()
    monkeypatch.setattr(link.ep, "clock", lambda: now + pilot_mod.OVERRIDE_TIMEOUT_S + 1.0)
    link.step(3)
    assert v.sticks[-1] == (0.0, 0.0, 0.0, 0.0)


def test_boot_heartbeat_each_second_until_stopped():
    port = free_udp_port()
    gcs = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}")
    conn = open_link(f"udpout:127.0.0.1:{port}")
    beacon = BootBeacon(conn, "RECOVER")
    try:
        t0 = time.monotonic()
        beats = []
        while time.monotonic() - t0 < 2.5:
            m = gcs.recv_match(type="HEARTBEAT", blocking=True, timeout=0.5)
            if m is not None:
                beats.append(m)
        assert 2 <= len(beats) <= 4                                       # one a second
        assert all(b.system_status == mav.MAV_STATE_BOOT and b.autopilot == mav.MAV_AUTOPILOT_ARDUPILOTMEGA
                   and b.type == mav.MAV_TYPE_FIXED_WING and b.custom_mode == 11 for b in beats)
        t1 = time.monotonic()
        beacon.stop()
        assert time.monotonic() - t1 < 1.0
        while gcs.recv_match(blocking=False) is not None:
            pass                                                         # what was sent before the stop
        assert gcs.recv_match(type="HEARTBEAT", blocking=True, timeout=1.5) is None
    finally:
        beacon.stop()
        close_link(conn)
        gcs.close()


# ------------------------------------------------------------------ the autopilot's side
def _flight(mode: str, pilot: tuple[float, float, float, float] | None, t_switch: float, t_end: float):
    ref = TrackingReference.from_ocp_file(NOMINAL)
    h: dict = {}

    def setup(ap, sim):
        h["ap"] = ap

    def on_step(k, s, o):
        if k == int(t_switch * 120):
            assert h["ap"].set_mode(mode)
            if pilot is not None:
                h["ap"].set_pilot(*pilot)

    rep = fly(ref, config="nominal", cycles=1, t_end=t_end, setup=setup, on_step=on_step)
    return rep, h["ap"]


@pytest.mark.parametrize("stick", [0.5, -0.5])
def test_fbwa_banks_the_way_the_roll_stick_says(stick):
    """FBWA with the roll stick at +-0.5: the glider banks to that side (the bank target is
    0.5 LIM_BANK, 0.55 rad); 3 s after the switch its roll has the stick's sign."""
    rep, ap = _flight("FBWA", (stick, 0.0, 0.0, 0.0), 10.0, 16.0)
    assert ap.mode == "FBWA"
    t, phi = rep.result.t, rep.result.euler[:, 0]
    m = (t >= 13.0) & (t <= 16.0)
    assert m.sum() > 300 and float(np.mean(np.sign(stick) * phi[m])) > 0.2


def test_loiter_holds_on_the_circle_and_never_lands():
    """LOITER from the cycle: RECOVER's path to the hold circle (the park), never the final or the
    flare, whatever REC_LAND says; the glider stays in the air."""
    rep, ap = _flight("LOITER", None, 10.0, 70.0)
    assert ap.mode == "LOITER" and ap.recovery.park
    assert ap.recovery.stage in ("return", "hold")
    assert ap.params["REC_LAND"] > 0.5                       # the default lands, LOITER does not
    h = -rep.result.pos[:, 2]
    t = rep.result.t
    assert float(h[t > 10.0].min()) > 5.0
