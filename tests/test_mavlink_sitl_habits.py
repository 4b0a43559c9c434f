"""SITL habits on the real vehicle, with a pymavlink ground station on UDP 127.0.0.1.

``fdm-awe fly --mavlink`` flies the stored reference as a subprocess at 10x real time; the ground
station asks for stream rates with REQUEST_DATA_STREAM (as MAVProxy and QGroundControl do for an
ArduPilot vehicle), flies 10 s (simulated) of MANUAL through RC_CHANNELS_OVERRIDE, reads the reason
of a refused disarm, and after the flight's end finds the vehicle still answering (heartbeats,
parameters, the mission; a mode change refused with its reason) for 10 s, until it shuts it down
with MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN. Bounded: every wait has a deadline, the flight is killed
at the end if it still runs.
"""

from __future__ import annotations

import signal
import time

from mavlink_helpers import GCS_COMPID, GCS_SYSID, free_udp_port, launch_fly
from pymavlink import mavutil

START_S = 60.0  # the flight's start (imports, JSBSim, the kernels' compilation) at most
MAV = mavutil.mavlink

MANUAL_S = 10.0  # simulated seconds flown in MANUAL
PITCH_REF = 0.05  # the pilot's pitch attitude, rad


def _pilot(att) -> tuple[int, int, int, int]:
    """The sticks a pilot gives in MANUAL from what the ground station shows (ATTITUDE): wings
    level and a gentle nose-up attitude, throttle closed, yaw centred; ArduPlane's channels 1 roll
    (high = right), 2 pitch (high = pulled, nose up), 3 throttle, 4 yaw, in us."""
    roll = max(-1.0, min(1.0, -1.2 * att.roll - 0.25 * att.rollspeed))
    pitch = max(-1.0, min(1.0, 2.0 * (PITCH_REF - att.pitch) - 0.3 * att.pitchspeed))
    return int(1500 + 500 * roll), int(1500 + 500 * pitch), 1000, 1500


class _Gcs:
    """A pymavlink ground station that sends its heartbeat each wall second while it reads."""

    def __init__(self, port: int) -> None:
        self.c = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}", source_system=GCS_SYSID,
                                            source_component=GCS_COMPID)
        self._hb = 0.0
        self.texts: list[str] = []
        self.states: list[int] = []  #: system_status of the autopilot's heartbeats, in order

    def recv(self, timeout: float = 0.2):
        now = time.monotonic()
        if now - self._hb >= 1.0 and self.c.target_system:
            self.c.mav.heartbeat_send(MAV.MAV_TYPE_GCS, MAV.MAV_AUTOPILOT_INVALID, 0, 0, 0)
            self._hb = now
        m = self.c.recv_match(blocking=True, timeout=timeout)
        if m is not None and m.get_type() == "STATUSTEXT":
            self.texts.append(m.text)
        if m is not None and m.get_type() == "HEARTBEAT" and m.get_srcComponent() == 1:
            self.states.append(m.system_status)
        return m

    def wait(self, pred, timeout: float):
        """The first message for which ``pred`` holds within ``timeout`` wall seconds, or None."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            m = self.recv()
            if m is not None and m.get_srcComponent() == 1 and pred(m):
                return m
        return None

    def command(self, cmd: int, *params: float):
        self.c.mav.command_long_send(1, 1, cmd, 0, *(list(params) + [0.0] * (7 - len(params))))
        return self.wait(lambda m: m.get_type() == "COMMAND_ACK" and m.command == cmd, 5.0)


def test_sitl_habits_manual_rc_override_stream_rates_refusal_reasons_and_staying_alive(tmp_path):
    port = free_udp_port()
    fly = launch_fly(port, "--cycles", "1", "--realtime", "10", "--json", str(tmp_path / "flight.json"))
    gcs = _Gcs(port)
    try:
        t_launch = time.monotonic()
        first = gcs.wait(lambda m: m.get_type() == "HEARTBEAT", START_S)
        # the heartbeat while the flight loads (before: the first came with the flight's first step)
        assert first is not None and first.system_status == MAV.MAV_STATE_BOOT
        assert time.monotonic() - t_launch < 5.0
        up = gcs.wait(lambda m: m.get_type() == "HEARTBEAT" and m.system_status != MAV.MAV_STATE_BOOT, START_S)
        assert up is not None and up.autopilot == MAV.MAV_AUTOPILOT_ARDUPILOTMEGA and up.custom_mode == 10

        # REQUEST_DATA_STREAM: ATTITUDE (EXTRA1) at 2 Hz instead of 10, GLOBAL_POSITION_INT (POSITION) at 20
        gcs.c.mav.request_data_stream_send(1, 1, MAV.MAV_DATA_STREAM_EXTRA1, 2, 1)
        gcs.c.mav.request_data_stream_send(1, 1, MAV.MAV_DATA_STREAM_POSITION, 20, 1)
        gcs.wait(lambda m: False, 0.5)
        att: list[int] = []
        pos: list[int] = []
        end = time.monotonic() + 2.0   # 20 simulated seconds at 10x
        while time.monotonic() < end:
            m = gcs.recv()
            if m is not None and m.get_type() == "ATTITUDE":
                att.append(m.time_boot_ms)
            elif m is not None and m.get_type() == "GLOBAL_POSITION_INT":
                pos.append(m.time_boot_ms)
        att_hz = 1000.0 * (len(att) - 1) / (att[-1] - att[0])
        pos_hz = 1000.0 * (len(pos) - 1) / (pos[-1] - pos[0])
        assert 1.5 < att_hz < 2.5 and 16.0 < pos_hz < 24.0, (att_hz, pos_hz)

        # MANUAL through RC_CHANNELS_OVERRIDE, a pilot's sticks on each ATTITUDE (20 Hz): the
        # sticks reach the surfaces, no ground contact
        gcs.c.mav.request_data_stream_send(1, 1, MAV.MAV_DATA_STREAM_EXTRA1, 20, 1)
        ack = gcs.command(MAV.MAV_CMD_DO_SET_MODE, MAV.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 0)
        assert ack is not None and ack.result == MAV.MAV_RESULT_ACCEPTED
        t_manual = None
        servo, alts, landed, sticks = [], [], [], []
        while True:
            m = gcs.recv(0.02)
            if m is None or m.get_srcComponent() != 1:
                continue
            kind = m.get_type()
            if kind == "ATTITUDE":
                sticks.append(_pilot(m))
                gcs.c.mav.rc_channels_override_send(1, 1, *sticks[-1], *([0] * 4))
            elif kind == "GLOBAL_POSITION_INT":
                if t_manual is None:  # the MANUAL stretch is timed by the telemetry's clock
                    t_manual = m.time_boot_ms
                alts.append(m.relative_alt / 1000.0)
                if m.time_boot_ms - t_manual >= 1000.0 * MANUAL_S:
                    break
            elif kind == "SERVO_OUTPUT_RAW" and t_manual is not None:
                servo.append((m.servo1_raw, m.servo2_raw, m.servo3_raw))
            elif kind == "EXTENDED_SYS_STATE" and t_manual is not None:
                landed.append(m.landed_state)
            assert fly.poll() is None, fly.stdout.read()
        print(f"MANUAL: altitude {min(alts):.1f} .. {max(alts):.1f} m, servos {servo[-1] if servo else None}")
        assert min(alts) > 2.0 and landed and set(landed) == {MAV.MAV_LANDED_STATE_IN_AIR}
        # the surfaces follow the sticks: aileron as the roll stick, elevator against the pitch
        # stick (pulled = trailing edge up), the throttle closed
        assert len(servo) >= 10 and all(s[2] == 1000 for s in servo), servo
        assert any(s[0] != 1500 for s in servo) and any(s[1] != 1500 for s in servo)

        # a refused disarm says why
        ack = gcs.command(MAV.MAV_CMD_COMPONENT_ARM_DISARM, 0)
        assert ack is not None and ack.result == MAV.MAV_RESULT_FAILED
        why = gcs.wait(lambda m: m.get_type() == "STATUSTEXT" and "disarm" in m.text, 3.0)
        assert why is not None and "in flight" in why.text and "21196" in why.text

        # the rest of the flight in RECOVER; its end, then the vehicle still answers for 10 s
        ack = gcs.command(MAV.MAV_CMD_NAV_RETURN_TO_LAUNCH)
        assert ack is not None and ack.result == MAV.MAV_RESULT_ACCEPTED
        end = gcs.wait(lambda m: m.get_type() == "STATUSTEXT" and m.text.startswith("flight "), 30.0)
        assert end is not None, gcs.texts
        t_end = time.monotonic()
        beats = 0
        while time.monotonic() - t_end < 10.0:
            m = gcs.recv()
            beats += m is not None and m.get_type() == "HEARTBEAT" and m.get_srcComponent() == 1
        assert beats >= 8 and fly.poll() is None
        gcs.c.mav.param_request_read_send(1, 1, b"REC_LAND", -1)
        pv = gcs.wait(lambda m: m.get_type() == "PARAM_VALUE" and m.param_id == "REC_LAND", 3.0)
        assert pv is not None and pv.param_type == MAV.MAV_PARAM_TYPE_INT32
        gcs.c.mav.mission_request_list_send(1, 1)
        mc = gcs.wait(lambda m: m.get_type() == "MISSION_COUNT", 3.0)
        assert mc is not None and mc.count == 60
        gcs.c.mav.mission_ack_send(1, 1, MAV.MAV_MISSION_ACCEPTED)
        ack = gcs.command(MAV.MAV_CMD_DO_SET_MODE, MAV.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 10)
        assert ack is not None and ack.result == MAV.MAV_RESULT_FAILED
        why = gcs.wait(lambda m: m.get_type() == "STATUSTEXT" and "flight over" in m.text, 3.0)
        assert why is not None
        # the ground station ends it
        ack = gcs.command(MAV.MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN, 2)
        assert ack is not None and ack.result == MAV.MAV_RESULT_ACCEPTED
        fly.wait(timeout=10.0)
        assert fly.returncode in (0, 1)
        # the boot heartbeat stopped when the flight's began: none after the first of the flight's
        first_up = next(i for i, st in enumerate(gcs.states) if st != MAV.MAV_STATE_BOOT)
        assert MAV.MAV_STATE_BOOT not in gcs.states[first_up:] and len(gcs.states) - first_up > 20
        assert (tmp_path / "flight.json").exists()   # the outputs were written before the vehicle stayed
    finally:
        if fly.poll() is None:
            fly.send_signal(signal.SIGKILL)
            fly.wait(timeout=10)
        gcs.c.close()
        print(fly.stdout.read())
