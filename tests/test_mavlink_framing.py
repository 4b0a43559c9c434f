"""MAVLink framing: every UDP datagram is parsed on its own, so garbage in one datagram cannot
swallow the valid messages of the next (real UDP sockets on 127.0.0.1, bounded waits); a TCP
stream keeps stream semantics (a message split over several reads is still assembled)."""

from __future__ import annotations

import random
import socket
import time

import pytest

from mavlink_helpers import GCS_COMPID, GCS_SYSID, Link, StandInVehicle, free_udp_port, telemetry_at
from pymavlink import mavutil
from pymavlink.dialects.v20 import common as mav

from fdm_awe.mavlink.endpoint import MavlinkEndpoint
from fdm_awe.mavlink.framing import parse_datagram


def _encoder(sysid: int = 250) -> mav.MAVLink:
    return mav.MAVLink(None, srcSystem=sysid, srcComponent=1)


def _garbage_kinds() -> list[bytes]:
    """Datagrams that are not (only) valid MAVLink: each one alone must not disturb the next."""
    enc = _encoder()
    valid = enc.command_long_encode(1, 1, mav.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0).pack(enc)
    bad_crc = bytearray(valid)
    bad_crc[-1] ^= 0xFF
    rng = random.Random(7)
    return [
        b"\xfd\xff",                                # the reported case: a v2 header announcing 255 bytes
        b"\xfd",                                    # a lone start byte
        b"\xfd\x21\x00\x00",                        # truncated v2 header
        b"\xfe\xff\x00",                            # truncated v1 header announcing 255 bytes
        valid[:-3],                                 # a valid frame cut short
        bytes(bad_crc),                             # a complete frame with a bad CRC
        bytes([0xFD, 0xF0]) + bytes(rng.getrandbits(8) for _ in range(40)),
        bytes(rng.getrandbits(8) for _ in range(300)),
    ]


def test_each_datagram_is_parsed_on_its_own_and_valid_frames_are_recovered():
    """The parsing function itself: a truncated frame ends with its datagram; a valid frame
    after garbage in the same datagram is still found (resynchronised on the next start byte)."""
    enc = _encoder()
    parser = _encoder(1)
    parser.robust_parsing = True
    a = enc.param_set_encode(1, 1, b"AP_ROLL_KP", 1.5, 9).pack(enc)
    b = enc.command_long_encode(1, 1, 400, 0, 1, 0, 0, 0, 0, 0, 0).pack(enc)
    msgs, bad = parse_datagram(parser, b"\xfd\xff")
    assert msgs == [] and bad >= 1
    msgs, bad = parse_datagram(parser, a)               # the previous datagram left nothing behind
    assert [m.get_type() for m in msgs] == ["PARAM_SET"] and bad == 0
    msgs, bad = parse_datagram(parser, a + b)           # two frames in one datagram
    assert [m.get_type() for m in msgs] == ["PARAM_SET", "COMMAND_LONG"] and bad == 0
    msgs, bad = parse_datagram(parser, b"\x00\x01" + a[:7] + b)  # junk, a cut frame, then a valid one
    assert [m.get_type() for m in msgs] == ["COMMAND_LONG"] and bad >= 1
    corrupt = bytearray(a)
    corrupt[-2] ^= 0x55
    msgs, bad = parse_datagram(parser, bytes(corrupt) + b)  # a bad CRC does not take the next frame along
    assert [m.get_type() for m in msgs] == ["COMMAND_LONG"] and bad >= 1
    assert parser.buf_len() == 0


@pytest.mark.parametrize("vehicle_listens", [True, False], ids=["udpin", "udpout"])
def test_garbage_datagrams_never_swallow_the_next_valid_command(vehicle_listens):
    """Every kind of garbage datagram, each followed by a valid COMMAND_LONG and a valid PARAM_SET
    from a pymavlink ground station: every valid message is answered."""
    lk = Link(StandInVehicle(), gcs_udpin=not vehicle_listens)
    try:
        lk.tx.heartbeat_send(mav.MAV_TYPE_GCS, mav.MAV_AUTOPILOT_INVALID, 0, 0, 0)
        lk.step(3)
        if vehicle_listens:
            dest = ("127.0.0.1", lk.port)
        else:  # the vehicle sends from an ephemeral port, where the ground station answers
            dest = ("127.0.0.1", lk.ep._conn.port.getsockname()[1])
        raw = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        ts, tc = lk.target()
        kinds = _garbage_kinds()
        answered_cmd = answered_param = 0
        n = 0
        t_end = time.monotonic() + 60.0
        for rep in range(2):
            for i, junk in enumerate(kinds):
                assert time.monotonic() < t_end
                value = round(0.1 + 0.1 * n, 3)
                n += 1
                raw.sendto(junk, dest)
                lk.tx.command_long_send(ts, tc, mav.MAV_CMD_REQUEST_MESSAGE, 0,
                                        mav.MAVLINK_MSG_ID_HOME_POSITION, 0, 0, 0, 0, 0, 0)
                raw.sendto(junk, dest)
                lk.gcs.mav.param_set_send(ts, tc, b"AP_ROLL_KP", value, mav.MAV_PARAM_TYPE_REAL32)
                ack = lk.wait_for("COMMAND_ACK", lambda m: m.command == mav.MAV_CMD_REQUEST_MESSAGE, timeout=2.0)
                pv = lk.wait_for("PARAM_VALUE", lambda m, v=value: m.param_id == "AP_ROLL_KP"
                                 and abs(m.param_value - v) < 1e-6, timeout=2.0)
                answered_cmd += ack is not None and ack.result == mav.MAV_RESULT_ACCEPTED
                answered_param += pv is not None
                assert ack is not None and pv is not None, (rep, i, junk[:8])
        raw.close()
        assert answered_cmd == answered_param == n == 2 * len(kinds)
        assert lk.vehicle.params["AP_ROLL_KP"] == pytest.approx(round(0.1 + 0.1 * (n - 1), 3))
        assert lk.ep.stats["bad_packets"] >= 2 * n  # every garbage datagram counted, none acted on
        assert lk.ep.stats["handler_errors"] == 0
    finally:
        lk.close()


def test_a_burst_of_short_garbage_then_commands_loses_none():
    """The reported failure: ``\\xfd\\xff`` then eight valid commands, all in the socket before the
    vehicle polls; every command is acknowledged."""
    lk = Link(StandInVehicle(), gcs_udpin=False)
    try:
        lk.tx.heartbeat_send(mav.MAV_TYPE_GCS, mav.MAV_AUTOPILOT_INVALID, 0, 0, 0)
        lk.step(3)
        raw = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        ts, tc = lk.target()
        raw.sendto(b"\xfd\xff", ("127.0.0.1", lk.port))
        tx = lk.tx
        for k in range(8):  # distinct unsupported command numbers: one ACK each, told apart
            tx.command_long_send(ts, tc, 31000 + k, 0, 0, 0, 0, 0, 0, 0, 0)
        raw.close()
        got: set[int] = set()
        t_end = time.monotonic() + 5.0
        while len(got) < 8 and time.monotonic() < t_end:
            lk.step()
            got |= {m.command for m in lk.received if m.get_type() == "COMMAND_ACK" and 31000 <= m.command < 31008}
            time.sleep(0.0005)
        assert got == set(range(31000, 31008))
    finally:
        lk.close()


def test_tcp_keeps_stream_semantics():
    """Over TCP a message split across writes is assembled: the parser keeps its state there."""
    port = free_udp_port()
    v = StandInVehicle()
    ep = MavlinkEndpoint(f"tcpin:127.0.0.1:{port}", v)
    t = 0.0
    ep.update(t, telemetry_at(t))
    sock = socket.create_connection(("127.0.0.1", port), timeout=2.0)
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    try:
        enc = mav.MAVLink(None, srcSystem=GCS_SYSID, srcComponent=GCS_COMPID)
        frame = enc.command_long_encode(1, 1, mav.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0).pack(enc)
        t_end = time.monotonic() + 5.0
        for part in (frame[:5], frame[5:17], frame[17:]):
            sock.sendall(part)
            for _ in range(30):  # let the endpoint read each piece on its own
                t += 1 / 120
                ep.update(t, lambda: telemetry_at(t, v))
                time.sleep(0.001)
        while not v.armed and time.monotonic() < t_end:
            t += 1 / 120
            ep.update(t, lambda: telemetry_at(t, v))
            time.sleep(0.001)
        assert v.armed
    finally:
        sock.close()
        ep.close()
