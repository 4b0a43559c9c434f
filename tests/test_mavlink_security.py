"""What may keep the ground-station link up, and what a hostile or broken peer cannot do
(real UDP and TCP sockets on 127.0.0.1, bounded waits).

The link (``MavlinkEndpoint.link_up``, which drives the FS_GCS_ENABL failsafe) is kept up only
by a ground station: another system than the vehicle's, and with a key set, a message signed
with it.
"""

from __future__ import annotations

import hashlib
import json
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


# ---------------------------------------------------------------- parameters
def test_param_set_of_a_switch_takes_only_0_or_1(tmp_path):
    """PARAM_SET FS_GCS_ENABL 0.5 is refused as ArduPilot refuses a write: the PARAM_VALUE
    answer carries the old value, a STATUSTEXT says why, the file keeps the old value; 1 is
    taken. The autopilot definition's switches are all 0/1 only."""
    from fdm_awe.autopilot.config import autopilot_params
    from fdm_awe.mavlink.params import ParamStore

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
    ({"format": "fdm-awe-params-1", "params": {"FS_GCS_ENABLE": 1}}, ("<parameter FS_GCS_ENABLE>", "unknown id")),
    ({"format": "fdm-awe-params-2", "params": {"GUID_KP": 1.0}}, ("<format>", "fdm-awe-params-1")),
    ({"params": {"GUID_KP": 1.0}}, ("<format>", "fdm-awe-params-1")),
    ({"format": "fdm-awe-params-1", "params": {"FS_GCS_ENABL": 0.5}}, ("<parameter FS_GCS_ENABL>", "whole number")),
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
    assert "\n" not in err and str(path) in err and all(w in err for w in words), err
