"""What may keep the ground-station link up, and what a hostile or broken peer cannot do
(real UDP and TCP sockets on 127.0.0.1, bounded waits).

The link (``MavlinkEndpoint.link_up``, which drives the FS_GCS_ENABL failsafe) is kept up only
by a ground station: another system than the vehicle's, and with a key set, a message signed
with it.
"""

from __future__ import annotations

import hashlib
import json
import socket
import time

import pytest

from mavlink_helpers import GCS_COMPID, GCS_SYSID, Link, StandInVehicle, free_udp_port, telemetry_at
from pymavlink import mavutil
from pymavlink.dialects.v20 import common as mav

from fdm_awe.mavlink.endpoint import MavlinkEndpoint
from fdm_awe.mavlink.framing import StreamParser
from fdm_awe.mavlink.transport import MAX_TCP_CLIENTS, MAX_UDP_CLIENTS

KEY = hashlib.sha256(b"tethered glider test key").digest()
LINK_TIMEOUT_S = 0.8   # long beside a step's stalls on a loaded machine


def _peer(port: int, sysid: int, compid: int, key: bytes | None = None):
    """A pymavlink connection sending to the vehicle's port, signed when ``key`` is given."""
    g = mavutil.mavlink_connection(f"udpout:127.0.0.1:{port}", source_system=sysid, source_component=compid)
    if key is not None:
        g.setup_signing(key, sign_outgoing=True)
    return g


def _run(lk: Link, seconds: float, send, period: float = 0.1, until=None) -> None:
    """Step the vehicle for ``seconds`` of wall time (or until ``until()`` holds), calling
    ``send()`` every ``period`` s."""
    t_end = time.monotonic() + seconds
    t_next = 0.0
    while time.monotonic() < t_end and not (until is not None and until()):
        if send is not None and time.monotonic() >= t_next:
            send()
            t_next = time.monotonic() + period
        lk.step()
        time.sleep(0.001)


def _heartbeat(g) -> None:
    g.mav.heartbeat_send(mav.MAV_TYPE_GCS, mav.MAV_AUTOPILOT_INVALID, 0, 0, 0)


@pytest.mark.parametrize("kind", ["radio_status", "heartbeat"])
def test_with_a_key_unsigned_traffic_does_not_keep_the_link_up(kind):
    """The issue's case: a signed ground station links, then falls silent while an unsigned peer
    keeps sending (RADIO_STATUS, which signing lets through as ArduPilot does, or a HEARTBEAT,
    which it refuses): the link is lost all the same."""
    lk = Link(StandInVehicle(), gcs_udpin=False, signing_key=KEY, link_timeout_s=LINK_TIMEOUT_S)
    lk.gcs.setup_signing(KEY, sign_outgoing=True)
    intruder = _peer(lk.port, 254, 1)
    try:
        _run(lk, 1.0, lambda: _heartbeat(lk.gcs))     # the signed ground station keeps it up
        assert lk.ep.link_up and lk.ep.stats["link_losses"] == 0
        if kind == "radio_status":
            send = lambda: intruder.mav.radio_status_send(200, 180, 90, 20, 15, 0, 0)  # noqa: E731
        else:
            send = lambda: _heartbeat(intruder)  # noqa: E731
        _run(lk, 3 * LINK_TIMEOUT_S, send)
        assert not lk.ep.link_up and lk.ep.stats["link_losses"] == 1
        sg = lk.ep.stats["signing"]   # the intruder's messages did arrive
        assert (sg["unsigned_accepted"] if kind == "radio_status" else sg["unsigned_rejected"]) >= 5
        _run(lk, 2.0, lambda: _heartbeat(lk.gcs), until=lambda: lk.ep.link_up)  # the ground station back

        assert lk.ep.link_up
    finally:
        intruder.close()
        lk.close()


@pytest.mark.parametrize("key", [KEY, None], ids=["signed", "unsigned"])
def test_the_vehicles_own_components_are_no_ground_station(key):
    """The vehicle's own winch HEARTBEAT (system 1, component 169; signed with the vehicle's key
    when it has one) sent back to it, and any other component of system 1, never bring the link up
    nor keep it up; a ground station does."""
    lk = Link(StandInVehicle(), gcs_udpin=False, signing_key=key, link_timeout_s=LINK_TIMEOUT_S)
    if key is not None:
        lk.gcs.setup_signing(key, sign_outgoing=True)
    winch = _peer(lk.port, lk.ep.sysid, mav.MAV_COMP_ID_WINCH, key)
    other = _peer(lk.port, lk.ep.sysid, 42, key)

    def echo() -> None:
        winch.mav.heartbeat_send(mav.MAV_TYPE_WINCH, mav.MAV_AUTOPILOT_INVALID, 0, 0, mav.MAV_STATE_ACTIVE)
        _heartbeat(other)

    try:
        _run(lk, 3 * LINK_TIMEOUT_S, echo)            # never linked by the vehicle's own traffic
        assert lk.ep.stats["received"] >= 10
        assert not lk.ep.link_up and lk.ep.gcs is None
        _run(lk, 2.0, lambda: _heartbeat(lk.gcs), until=lambda: lk.ep.link_up)  # a ground station links
        assert lk.ep.link_up and lk.ep.gcs == (GCS_SYSID, GCS_COMPID)
        _run(lk, 3 * LINK_TIMEOUT_S, echo)            # and the echoes do not keep it up
        assert not lk.ep.link_up and lk.ep.stats["link_losses"] == 1
    finally:
        winch.close()
        other.close()
        lk.close()


# ---------------------------------------------------------------- parameters
def test_param_set_of_a_switch_takes_only_0_or_1(tmp_path):
    """PARAM_SET FS_GCS_ENABL 0.5 is refused as ArduPilot refuses a write: the PARAM_VALUE
    answer carries the old value, a STATUSTEXT says why, the file keeps the old value; 1 is
    taken. The autopilot definition's switches are all 0/1 only."""
    from fdm_awe.autopilot.config import autopilot_params
    from fdm_awe.autopilot.params import ParamStore

    path = tmp_path / "params.json"
    v = StandInVehicle()
    v.params = autopilot_params(store=ParamStore(path))
    switches = [n for n in v.params if v.params.info(n).kind == "bool"]
    assert {"FS_GCS_ENABL", "GUID_NEGLIFT", "GUID_REFPULL", "REC_LAND"} <= set(switches)
    lk = Link(v, gcs_udpin=False)
    try:
        ts, tc = lk.target()
        for name, value, kept in (("FS_GCS_ENABL", 0.5, 0.0), ("GUID_NEGLIFT", 0.25, 1.0), ("FS_GCS_ENABL", 1.0, 1.0)):
            lk.tx.param_set_send(ts, tc, name.encode(), value, mav.MAV_PARAM_TYPE_REAL32)
            pv = lk.wait_for("PARAM_VALUE", lambda m, n=name: m.param_id == n, timeout=2.0)
            assert pv is not None and pv.param_value == kept, (name, value, pv)
            assert v.params[name] == kept
            if value != kept:
                text = lk.wait_for("STATUSTEXT", lambda m, n=name: n in m.text, timeout=2.0)
                assert text is not None and "whole number" in text.text, text
        assert json.loads(path.read_text())["params"]["FS_GCS_ENABL"] == 1.0
    finally:
        lk.close()


@pytest.mark.parametrize("content, words", [
    ({"format": "fdm-awe-params-1", "params": {"FS_GCS_ENABLE": 1}}, ("parameter FS_GCS_ENABLE", "unknown id", "FS_GCS_ENABL?")),
    ({"format": "fdm-awe-params-2", "params": {"GUID_KP": 1.0}}, ("format", "fdm-awe-params-1")),
    ({"params": {"GUID_KP": 1.0}}, ("format", "fdm-awe-params-1")),
    ({"format": "fdm-awe-params-1", "params": {"FS_GCS_ENABL": 0.5}}, ("parameter FS_GCS_ENABL", "whole number")),
], ids=["unknown-id", "wrong-format", "no-format", "half-a-switch"])
def test_fly_refuses_a_bad_params_file_before_the_flight(tmp_path, capsys, content, words):
    """``fly --params FILE``: an unknown id, a wrong or missing format tag, a switch at 0.5: a
    one-line error naming the file and the field, exit 2, before any work."""
    from pathlib import Path

    from fdm_awe.cli import main

    ref = Path(__file__).parent / "data" / "ref_physical_nominal_8mps.json"
    path = tmp_path / "params.json"
    path.write_text(json.dumps(content))
    t0 = time.monotonic()
    rc = main(["fly", "--reference", str(ref), "--quiet", "--params", str(path)])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and time.monotonic() - t0 < 10.0, err
    assert "\n" not in err and "--params" in err and str(path) in err and all(w in err for w in words), err


# ---------------------------------------------------------------- floods, squatters, stray bytes
def _tcp_vehicle():
    port = free_udp_port()   # a free number; TCP and UDP port spaces are separate
    v = StandInVehicle()
    ep = MavlinkEndpoint(f"tcpin:127.0.0.1:{port}", v)
    return ep, v, port


def _acks(ep, v, gcs, n: int, timeout: float = 1.5, before_each=None) -> int:
    """Send ``n`` distinct (unsupported) commands one at a time, stepping the vehicle; how many
    got their COMMAND_ACK within ``timeout`` s each."""
    t = [ep.t_now]
    answered = 0
    for k in range(n):
        if before_each is not None:
            before_each()
        gcs.mav.command_long_send(1, 1, 31000 + k, 0, 0, 0, 0, 0, 0, 0, 0)
        t_end = time.monotonic() + timeout
        got = False
        while not got and time.monotonic() < t_end:
            t[0] += 1 / 120
            ep.update(t[0], lambda: telemetry_at(t[0], v))
            while not got:
                m = gcs.recv_match(blocking=False)
                if m is None:
                    break
                got = m.get_type() == "COMMAND_ACK" and m.command == 31000 + k
            time.sleep(0.0005)
        answered += got
    return answered


def _step(ep, v, seconds: float) -> None:
    t_end = time.monotonic() + seconds
    while time.monotonic() < t_end:
        t = ep.t_now + 1 / 120
        ep.update(t, lambda: telemetry_at(t, v))
        time.sleep(0.001)


@pytest.mark.parametrize("squatter", ["idle", "flooding"])
def test_tcp_serves_a_ground_station_that_connects_after_another_client(squatter):
    """The issue's case: a peer connects first and sends nothing (or floods HEARTBEATs); a
    ground station connecting after it gets every command answered."""
    ep, v, port = _tcp_vehicle()
    first = socket.create_connection(("127.0.0.1", port), timeout=2.0)
    _step(ep, v, 0.1)
    enc = mav.MAVLink(None, srcSystem=77, srcComponent=1)
    hb = enc.heartbeat_encode(mav.MAV_TYPE_GCS, mav.MAV_AUTOPILOT_INVALID, 0, 0, 0).pack(enc)
    flood = (lambda: first.sendall(hb * 20)) if squatter == "flooding" else None
    gcs = mavutil.mavlink_connection(f"tcp:127.0.0.1:{port}", source_system=GCS_SYSID,
                                     source_component=GCS_COMPID)
    try:
        assert _acks(ep, v, gcs, 10, before_each=flood) == 10
        assert ep.stats["handler_errors"] == 0
    finally:
        gcs.close()
        first.close()
        ep.close()


def test_a_full_tcp_server_drops_the_client_silent_longest():
    """MAX_TCP_CLIENTS idle connections: a ground station connecting next takes the place of
    the one that connected first (none ever sent a valid message), and is served."""
    ep, v, port = _tcp_vehicle()
    idle = [socket.create_connection(("127.0.0.1", port), timeout=2.0) for _ in range(MAX_TCP_CLIENTS)]
    _step(ep, v, 0.2)
    assert len(ep._conn.clients) == MAX_TCP_CLIENTS
    gcs = mavutil.mavlink_connection(f"tcp:127.0.0.1:{port}", source_system=GCS_SYSID,
                                     source_component=GCS_COMPID)
    try:
        assert _acks(ep, v, gcs, 3) == 3
        assert len(ep._conn.clients) == MAX_TCP_CLIENTS
        idle[0].settimeout(1.0)
        while idle[0].recv(4096):                # what it was sent, then the end: closed by the vehicle
            pass
    finally:
        gcs.close()
        for s in idle:
            s.close()
        ep.close()


def test_a_stray_byte_on_tcp_costs_no_command():
    """One 0xFD byte on the stream, then commands one at a time: every one is answered (the
    stray start byte's header would take the next frames' bytes as its own)."""
    ep, v, port = _tcp_vehicle()
    gcs = mavutil.mavlink_connection(f"tcp:127.0.0.1:{port}", source_system=GCS_SYSID,
                                     source_component=GCS_COMPID)
    try:
        assert _acks(ep, v, gcs, 1) == 1
        gcs.port.sendall(b"\xfd")
        assert _acks(ep, v, gcs, 8, timeout=1.0) == 8
        assert ep.stats["bad_packets"] >= 1
    finally:
        gcs.close()
        ep.close()


def test_stream_parser_resynchronises_on_the_next_frame():
    """The stream parser itself: a stray start byte before a whole frame gives the frame at once;
    a frame that arrives in pieces is waited for; a bad CRC costs only its own frame."""
    enc = mav.MAVLink(None, srcSystem=250, srcComponent=1)
    a = enc.command_long_encode(1, 1, 400, 0, 1, 0, 0, 0, 0, 0, 0).pack(enc)
    b = enc.param_set_encode(1, 1, b"AP_ROLL_KP", 1.5, 9).pack(enc)
    codec = mav.MAVLink(None, srcSystem=1, srcComponent=1)
    codec.robust_parsing = True
    sp = StreamParser(codec)
    msgs, bad = sp.feed(b"\xfd" + a)
    assert [m.get_type() for m in msgs] == ["COMMAND_LONG"] and bad == 1 and sp.pending == 0
    msgs, bad = sp.feed(b[:7])
    assert msgs == [] and bad == 0 and sp.pending == 7          # a frame in pieces: waited for
    msgs, bad = sp.feed(b[7:] + b"\xfe\x21")
    assert [m.get_type() for m in msgs] == ["PARAM_SET"] and sp.pending == 2
    corrupt = bytearray(a)
    corrupt[-1] ^= 0x55
    msgs, bad = sp.feed(bytes(corrupt) + b)   # (the two bytes held are junk, their frame bad)
    assert [m.get_type() for m in msgs] == ["PARAM_SET"] and bad >= 2 and sp.pending == 0


def test_a_udp_flood_does_not_starve_a_command():
    """A peer's datagrams beyond its share of a poll are dropped unparsed: a command behind 50 of
    them is answered in the first poll (with 8 parsed reads a poll, without the share it
    would wait 7 polls)."""
    lk = Link(StandInVehicle(), gcs_udpin=False, max_rx_per_poll=8)
    raw = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        lk.tx.heartbeat_send(mav.MAV_TYPE_GCS, mav.MAV_AUTOPILOT_INVALID, 0, 0, 0)
        lk.step(3)
        enc = mav.MAVLink(None, srcSystem=77, srcComponent=1)
        hb = enc.heartbeat_encode(mav.MAV_TYPE_GCS, mav.MAV_AUTOPILOT_INVALID, 0, 0, 0).pack(enc)
        for _ in range(50):
            raw.sendto(hb, ("127.0.0.1", lk.port))
        ts, tc = lk.target()
        lk.tx.command_long_send(ts, tc, 31000, 0, 0, 0, 0, 0, 0, 0, 0)
        time.sleep(0.2)                                   # all of it in the vehicle's socket
        polls = lk.ep.stats["polls"]
        lk.t += 1.0                                       # one poll
        lk.step()
        assert lk.ep.stats["polls"] == polls + 1
        t_end = time.monotonic() + 1.0
        while time.monotonic() < t_end and not any(m.get_type() == "COMMAND_ACK" for m in lk.received):
            lk.drain()
            time.sleep(0.01)
        assert any(m.get_type() == "COMMAND_ACK" and m.command == 31000 for m in lk.received)
        assert lk.ep.stats["rx_dropped"] >= 45
    finally:
        raw.close()
        lk.close()


def test_udp_destinations_are_peers_that_sent_mavlink_and_bounded():
    """``udpin:``: junk from ever new source ports adds no destination; valid messages from many
    ports add at most MAX_UDP_CLIENTS; the ground station that keeps talking stays one."""
    lk = Link(StandInVehicle(), gcs_udpin=False)
    try:
        lk.tx.heartbeat_send(mav.MAV_TYPE_GCS, mav.MAV_AUTOPILOT_INVALID, 0, 0, 0)
        lk.step(3)
        assert len(lk.ep._conn.clients) == 1
        enc = mav.MAVLink(None, srcSystem=77, srcComponent=1)
        hb = enc.heartbeat_encode(mav.MAV_TYPE_GCS, mav.MAV_AUTOPILOT_INVALID, 0, 0, 0).pack(enc)
        for data in (b"\xfd\xff junk", hb):
            for _ in range(40):
                s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
                s.sendto(data, ("127.0.0.1", lk.port))
                s.close()
            lk.tx.heartbeat_send(mav.MAV_TYPE_GCS, mav.MAV_AUTOPILOT_INVALID, 0, 0, 0)
            time.sleep(0.05)
            lk.step(30)
            if data != hb:
                assert len(lk.ep._conn.clients) == 1
        assert len(lk.ep._conn.clients) == MAX_UDP_CLIENTS
        gcs_port = lk.gcs.port.getsockname()[1]
        assert any(a[1] == gcs_port for a in lk.ep._conn.clients)
    finally:
        lk.close()


def test_fs_gcs_recovers_a_flight_whose_signed_ground_station_falls_silent():
    """The issue's flight: the real autopilot with FS_GCS_ENABL 1 and FS_LONG_TIMEOUT 1 s, paced
    at real time, signed link; the signed ground station talks for 1 s, then only an unsigned
    peer sends RADIO_STATUS every 0.3 s. The link is lost and the failsafe switches AUTO to
    RECOVER (before, the RADIO_STATUS kept the link up and the glider in AUTO)."""
    from flight_helpers import DATA

    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.mavlink.bridge import telemetry_builder
    from fdm_awe.sim.flight import fly
    from fdm_awe.sim.pacing import RealtimePacer

    ref = TrackingReference.from_ocp_file(DATA / "ref_physical_nominal_8mps_sized.json")
    port = free_udp_port()
    h: dict = {"next_send": 0.0}
    gcs = _peer(port, GCS_SYSID, GCS_COMPID, KEY)
    radio = _peer(port, 51, 68)       # a telemetry radio's ids, unsigned
    pacer = RealtimePacer(1.0)

    def setup(ap, sim):
        assert ap.params.try_set("FS_GCS_ENABL", 1)[0] and ap.params.try_set("FS_LONG_TIMEOUT", 1.0)[0]
        h["ap"] = ap
        h["ep"] = MavlinkEndpoint(f"udpin:127.0.0.1:{port}", ap, signing_key=KEY, link_timeout_s=0.5,
                                  log=lambda s: None)
        h["build"] = telemetry_builder(ap, sim)

    def on_step(k, s, o):
        ep, ap, build = h["ep"], h["ap"], h["build"]
        if s.t >= h["next_send"]:
            h["next_send"] = s.t + (0.2 if s.t < 1.0 else 0.3)
            if s.t < 1.0:
                _heartbeat(gcs)
            else:
                radio.mav.radio_status_send(200, 180, 90, 20, 15, 0, 0)
        build.integrate(s)
        ep.update(s.t, lambda: build(s, o))
        ap.gcs_link(ep.link_up, s.t)
        if ap.mode != h.get("mode"):
            h.setdefault("modes", []).append((s.t, ap.mode, ep.link_up))
            h["mode"] = ap.mode
        pacer.wait(s.t)

    try:
        fly(ref, config="nominal", cycles=1, t_end=3.5, setup=setup, on_step=on_step)
        ep = h["ep"]
        assert h["ap"].mode == "RECOVER", h.get("modes")
        assert ep._ever_linked and ep.stats["link_losses"] == 1
        assert ep.stats["signing"]["unsigned_accepted"] >= 5
        t_fs = [t for t, m in h["ap"].log if m.startswith("failsafe")]
        # the last signed heartbeat at 0.8 s, lost 0.5 s (wall) after it, failsafe FS_LONG_TIMEOUT later
        assert len(t_fs) == 1 and 2.3 - 0.05 <= t_fs[0] <= 3.5, t_fs
    finally:
        if "ep" in h:
            h["ep"].close()
        gcs.close()
        radio.close()
