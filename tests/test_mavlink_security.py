"""What may keep the ground-station link up, and what a hostile or broken peer cannot do
(real UDP and TCP sockets on 127.0.0.1, bounded waits).

The link (``MavlinkEndpoint.link_up``, which drives the FS_GCS_ENABL failsafe) is kept up only
by a ground station: another system than the vehicle's, and with a key set, a message signed
with it.
"""

from __future__ import annotations

import hashlib
import time

import pytest

from mavlink_helpers import GCS_COMPID, GCS_SYSID, Link, StandInVehicle, telemetry_at
from pymavlink import mavutil
from pymavlink.dialects.v20 import common as mav

KEY = hashlib.sha256(b"tethered glider test key").digest()
LINK_TIMEOUT_S = 0.4


def _peer(port: int, sysid: int, compid: int, key: bytes | None = None):
    """A pymavlink connection sending to the vehicle's port, signed when ``key`` is given."""
    g = mavutil.mavlink_connection(f"udpout:127.0.0.1:{port}", source_system=sysid, source_component=compid)
    if key is not None:
        g.setup_signing(key, sign_outgoing=True)
    return g


def _run(lk: Link, seconds: float, send, period: float = 0.1) -> None:
    """Step the vehicle for ``seconds`` of wall time, calling ``send()`` every ``period`` s."""
    t_end = time.monotonic() + seconds
    t_next = 0.0
    while time.monotonic() < t_end:
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
        _run(lk, 0.3, lambda: _heartbeat(lk.gcs))     # the ground station back: the link is back
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
        _run(lk, 0.5, lambda: _heartbeat(lk.gcs))     # a ground station links
        assert lk.ep.link_up and lk.ep.gcs == (GCS_SYSID, GCS_COMPID)
        _run(lk, 3 * LINK_TIMEOUT_S, echo)            # and the echoes do not keep it up
        assert not lk.ep.link_up and lk.ep.stats["link_losses"] == 1
    finally:
        winch.close()
        other.close()
        lk.close()
