"""The vehicle's own mission downloaded and uploaded back over real MAVLink on 127.0.0.1
(MAVProxy's ``wp list``, ``wp save``, ``wp load``): the flown cycle keeps its recovery phase.

Before, the upload replaced the reference by a path rebuilt from the items' positions (a
mission item carries no phase, timing, tension or reel speed): the recovery was gone (0 s,
no reel-in energy) and the status stayed ``ok``."""

from __future__ import annotations

import socket
import threading
import time
from pathlib import Path

import pytest
from pymavlink import mavutil
from pymavlink.dialects.v20 import common as mav

from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.autopilot.vehicle import Waypoint
from fdm_awe.mavlink.bridge import telemetry_builder
from fdm_awe.mavlink.endpoint import MavlinkEndpoint
from fdm_awe.sim.flight import fly
from fdm_awe.sim.pacing import RealtimePacer

REF = Path(__file__).parent / "data" / "ref_physical_nominal_8mps.json"


def _free_port() -> int:
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    port = sock.getsockname()[1]
    sock.close()
    return port


def test_the_vehicles_own_mission_uploaded_back_keeps_the_cycle():
    ref = TrackingReference.from_ocp_file(str(REF))
    port = _free_port()
    gcs = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}", source_system=255, source_component=190)
    gcs.port.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
    out: dict = {"texts": []}
    holder: dict = {}

    def wait(mtype, cond=None, timeout=8.0):
        """The next message of ``mtype`` (a name or a list) meeting ``cond``; STATUSTEXTs on the
        way are kept in ``out["texts"]``."""
        types = [mtype] if isinstance(mtype, str) else list(mtype)
        t_end = time.monotonic() + timeout
        while time.monotonic() < t_end:
            m = gcs.recv_match(type=types + ["STATUSTEXT"], blocking=True, timeout=0.2)
            if m is None:
                continue
            if m.get_type() == "STATUSTEXT":
                out["texts"].append(m.text)
            elif cond is None or cond(m):
                return m
        return None

    def ground_station():
        wait("HEARTBEAT")
        gcs.mav.mission_request_list_send(1, 1)
        cnt = wait("MISSION_COUNT")
        items = []
        for seq in range(cnt.count if cnt else 0):
            gcs.mav.mission_request_int_send(1, 1, seq)
            items.append(wait("MISSION_ITEM_INT", lambda m, s=seq: m.seq == s))
        gcs.mav.mission_ack_send(1, 1, mav.MAV_MISSION_ACCEPTED)
        out["items"] = items
        # the same items back, as MAVProxy's `wp load` of a `wp save` file sends them
        gcs.mav.mission_count_send(1, 1, len(items))
        while True:
            m = wait(["MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_ACK"])
            if m is None or m.get_type() == "MISSION_ACK":
                out["upload_ack"] = m
                break
            it = items[m.seq]
            gcs.mav.mission_item_int_send(1, 1, m.seq, it.frame, it.command, it.current, it.autocontinue,
                                          it.param1, it.param2, it.param3, it.param4, it.x, it.y, it.z)
        wait("NO_SUCH_MESSAGE", timeout=1.0)  # the STATUSTEXT that follows the ACK
        out["done"] = True

    def setup(ap, sim):
        holder["ap"] = ap
        holder["ep"] = MavlinkEndpoint(f"udpout:127.0.0.1:{port}", vehicle=ap)
        holder["build"] = telemetry_builder(ap, sim)
        holder["pacer"] = RealtimePacer(4.0)

    def on_step(k, s, o):
        holder["build"].integrate(s)
        holder["ep"].update(s.t, lambda: holder["build"](s, o))
        if k == 1:
            holder["thread"] = threading.Thread(target=ground_station, daemon=True)
            holder["thread"].start()
        if not out.get("done"):
            holder["pacer"].wait(s.t)  # paced until the round trip is done (bounded: 30 s of the cycle)
        elif "t_upload" not in holder:
            holder["t_upload"] = s.t

    try:
        rep = fly(ref, config="nominal", cycles=1, params=None, setup=setup, on_step=on_step)
    finally:
        if "thread" in holder:
            holder["thread"].join(timeout=10.0)
        if "ep" in holder:
            holder["ep"].close()
        gcs.close()
    ap = holder["ap"]
    assert out.get("done") and len(out["items"]) == 60
    assert out["upload_ack"] is not None and out["upload_ack"].type == mav.MAV_MISSION_ACCEPTED
    assert holder["t_upload"] < 0.5 * ref.T1  # the round trip ended in generation, before the recovery
    assert any("own path" in t for t in out["texts"]), out["texts"]
    assert ap.reference.meta.get("source") != "uploaded mission"
    # the flown cycle keeps its recovery phase and its reel-in
    assert rep.status == "ok", rep.message
    c = rep.cycles[0]
    assert c.complete
    assert c.T2_s == pytest.approx(ref.T2, rel=0.1) and c.T1_s == pytest.approx(ref.T1, rel=0.1)
    assert c.E_reel_in_J > 100.0
    assert c.track_rms_m < 5.0 and c.track_max_m < 15.0


def test_a_path_near_but_not_on_the_own_path_replaces_the_reference():
    """Within 1 m of each of the reference's points it is its own path (a mission item's
    resolution); 3 m off, another path."""
    from fdm_awe.autopilot.vehicle_commands import OWN_PATH_TOL_M, VehicleCommands

    ref = TrackingReference.from_ocp_file(str(REF))
    own = [Waypoint(n, e, d) for n, e, d, _, _ in ref.waypoints()]

    class _Ap:  # the autopilot's path comparison without a glider
        own_path = VehicleCommands.own_path
        mission = VehicleCommands.mission

        def __init__(self):
            self.reference = ref

    ap = _Ap()
    assert ap.own_path(own)
    near = [Waypoint(w.north + 0.6 * OWN_PATH_TOL_M, w.east, w.down) for w in own]
    assert ap.own_path(near)
    off = [Waypoint(w.north + 3.0, w.east, w.down) for w in own]
    assert not ap.own_path(off)
    assert not ap.own_path(own[:-1])
    assert not ap.own_path(own[::-1])
