"""The whole system flying: autopilot + 6-DOF JSBSim + ground station, on an optimised cycle."""

import json
from pathlib import Path

import numpy as np
import pytest

from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.sim.flight import fly
from fdm_awe.sim.flight_outcome import LAND_SINK_MAX


@pytest.fixture(scope="module")
def reference():
    """A physical-scenario cycle at 8 m/s for the nominal glider, written by the optimiser
    (physical scenario, nominal, 8 m/s, with the flyable bounds of ``fdm-awe fly``:
    C_L <= 0.85 C_Lmax, |bank| <= 0.8 rad) and kept as test data, so these flight tests do not
    depend on the optimiser's run time."""
    return TrackingReference.from_ocp_file(str(Path(__file__).parent / "data" / "ref_physical_nominal_8mps.json"))


def test_one_cycle_flies_without_event_and_ledger_closes(reference):
    rep = fly(reference, config="nominal", cycles=1)
    assert rep.status == "ok", rep.message
    assert len(rep.cycles) == 1 and rep.cycles[0].complete
    c = rep.cycles[0]
    # the generator delivered energy and the recovery drew from the supply
    assert c.E_generated_J > 0 and c.E_reel_in_J > 0 and c.E_thrust_J > 0
    assert c.E_net_J == pytest.approx(c.E_generated_J - c.E_thrust_J - c.E_reel_in_J)
    # both ledgers close within 1 % of their largest term
    assert rep.ledger_residual_rel < 0.01
    t = rep.ledger
    assert abs(t["glider_residual_J"]) < 0.01 * max(abs(t["glider_aero_work_J"]), abs(t["glider_tether_work_J"]))
    # issue acceptance: position tracking RMS <= 5 m and max <= 15 m per cycle
    assert c.track_rms_m <= 5.0 and c.track_max_m <= 15.0, (c.track_rms_m, c.track_max_m)


def test_same_inputs_give_identical_json(reference):
    """Deterministic: the same flight twice gives the same JSON except the wall-clock timing."""
    a = fly(reference, config="nominal", cycles=1, t_end=6.0).as_json()
    b = fly(reference, config="nominal", cycles=1, t_end=6.0).as_json()
    for d in (a, b):
        d.pop("wall_s")
        d.pop("realtime_factor")
    assert json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)


def test_losing_the_reference_recovers_and_lands_near_the_winch(reference):
    """Mission cleared 10 s into the flight: RECOVER reels in, circles down and lands."""
    holder = {}

    def setup(ap, sim):
        holder["ap"] = ap

    def on_step(k, s, o):
        if k == 1200:
            holder["ap"].clear_mission()

    rep = fly(reference, config="nominal", cycles=1, t_end=300.0, setup=setup, on_step=on_step)
    assert holder["ap"].mode == "RECOVER"
    assert rep.status == "landed", rep.message
    r = rep.result
    assert rep.sim_time_s < 300.0
    horizontal = float(np.hypot(r.pos[-1][0], r.pos[-1][1]))
    assert horizontal < 100.0  # on the 60 m recovery circle, give or take the wind drift
    assert float(r.vel[-1][2]) < LAND_SINK_MAX
    from fdm_awe.groundstation import load_ground_station

    assert np.nanmax(r.tension) < 0.5 * load_ground_station().tether.breaking_load  # line intact, with margin


def test_ground_station_over_mavlink_commands_the_real_autopilot(reference, tmp_path):
    """A pymavlink ground station on 127.0.0.1 (own thread) talks to the flying autopilot:
    mission download equals the reference, PARAM_SET takes effect and persists, an uploaded
    path is flown, and DO_SET_MODE RECOVER switches the autopilot."""
    import threading
    import time

    from pymavlink import mavutil
    from pymavlink.dialects.v20 import common as mav

    from fdm_awe.autopilot.config import autopilot_params
    from fdm_awe.mavlink.bridge import telemetry_builder
    from fdm_awe.mavlink.endpoint import MavlinkEndpoint
    from fdm_awe.autopilot.params import ParamStore
    from fdm_awe.mode_table import MODE_NUMBERS
    from fdm_awe.sim.pacing import RealtimePacer

    import socket

    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    port = sock.getsockname()[1]
    sock.close()
    gcs = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}", source_system=255, source_component=190)
    gcs.port.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)  # room for seconds of telemetry
    out: dict = {}
    holder: dict = {}

    def wait(mtype, cond=None, timeout=8.0):
        t_end = time.monotonic() + timeout
        while time.monotonic() < t_end:
            m = gcs.recv_match(type=mtype, blocking=True, timeout=0.2)
            if m is not None and (cond is None or cond(m)):
                return m
        return None

    def ground_station():
        hb = wait("HEARTBEAT")
        out["mode_at_start"] = hb.custom_mode if hb else None
        gcs.mav.mission_request_list_send(1, 1)
        cnt = wait("MISSION_COUNT")
        items = []
        for seq in range(cnt.count if cnt else 0):
            gcs.mav.mission_request_int_send(1, 1, seq)
            items.append(wait("MISSION_ITEM_INT", lambda m, s=seq: m.seq == s))
        gcs.mav.mission_ack_send(1, 1, mav.MAV_MISSION_ACCEPTED)
        out["items"] = items
        gcs.mav.param_set_send(1, 1, b"GUID_KP", 0.7, mav.MAV_PARAM_TYPE_REAL32)
        out["param"] = wait("PARAM_VALUE", lambda m: m.param_id == "GUID_KP")
        # upload the path moved 3 m north (another path: MAVLink carries no timing, the
        # autopilot times it itself; the vehicle's own path back keeps its cycle, see
        # tests/test_mavlink_mission_roundtrip.py)
        gcs.mav.mission_count_send(1, 1, len(items))
        while True:
            m = wait(["MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_ACK"])
            if m is None or m.get_type() == "MISSION_ACK":
                out["upload_ack"] = m
                break
            it = items[m.seq]
            gcs.mav.mission_item_int_send(1, 1, m.seq, it.frame, it.command, 0, 1, 0, 0, 0, 0, it.x + 270, it.y, it.z)
        # the uploaded path is flown a while: the ground station keeps the link up and keeps
        # reading (a reader that pauses lets the socket's buffer fill with telemetry, and the
        # kernel then drops the next datagram, which may be the COMMAND_ACK awaited below)
        t_hold = time.monotonic() + 3.0
        while time.monotonic() < t_hold:
            gcs.mav.heartbeat_send(mav.MAV_TYPE_GCS, mav.MAV_AUTOPILOT_INVALID, 0, 0, 0)
            wait("NO_SUCH_MESSAGE", timeout=0.5)
        gcs.mav.command_long_send(1, 1, mav.MAV_CMD_DO_SET_MODE, 0, mav.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED,
                                  MODE_NUMBERS["RECOVER"], 0, 0, 0, 0, 0)
        out["mode_ack"] = wait("COMMAND_ACK", lambda m: m.command == mav.MAV_CMD_DO_SET_MODE)
        out["t_done"] = holder["t"]
        out["done"] = True

    params = autopilot_params(store=ParamStore(tmp_path / "params.json"))

    def setup(ap, sim):
        holder["ap"] = ap
        holder["ep"] = MavlinkEndpoint(f"udpout:127.0.0.1:{port}", vehicle=ap)
        holder["build"] = telemetry_builder(ap, sim)
        holder["pacer"] = RealtimePacer(2.0)

    def on_step(k, s, o):
        holder["t"] = s.t
        holder["build"].integrate(s)
        holder["ep"].update(s.t, lambda: holder["build"](s, o))
        holder["pacer"].wait(s.t)
        if k == 1:
            holder["thread"] = threading.Thread(target=ground_station, daemon=True)
            holder["thread"].start()
        if out.get("upload_ack") is not None and "mission_at_upload" not in holder:
            holder["mission_at_upload"] = holder["ap"].reference.meta.get("source")
            holder["k_upload"] = k
        # the flight ends 2 s (simulated) after the ground station's last command, however slow
        # the machine; t_end only bounds a ground station that never finishes
        return out.get("done") and s.t >= out["t_done"] + 2.0

    try:
        rep = fly(reference, config="nominal", cycles=1, t_end=150.0, params=params, setup=setup, on_step=on_step)
    finally:
        holder["thread"].join(timeout=10.0)
        holder["ep"].close()
        gcs.close()
    ap = holder["ap"]
    assert out.get("done"), out
    assert out["mode_at_start"] == MODE_NUMBERS["AUTO"]
    wps = reference.waypoints()
    assert len(out["items"]) == len(wps)
    assert out["param"] is not None and out["param"].param_value == pytest.approx(0.7)
    assert ap.guidance.k.kp == pytest.approx(0.7)
    # the change persisted: a new store on the same file starts from it
    assert autopilot_params(store=ParamStore(tmp_path / "params.json"))["GUID_KP"] == pytest.approx(0.7)
    assert out["upload_ack"] is not None
    assert out["upload_ack"].type == mav.MAV_MISSION_ACCEPTED
    assert holder["mission_at_upload"] == "uploaded mission"
    assert out["mode_ack"].result == mav.MAV_RESULT_ACCEPTED and ap.mode == "RECOVER"
    # the uploaded path was flown without an event until the mode change
    assert rep.status in ("ok", "landed"), rep.message
    e = rep.track_error[holder["k_upload"]:]
    assert np.nanmax(e) < 60.0


def test_fly_validates_the_line_drag_scale(reference):
    from fdm_awe.errors import InputError

    for bad in (-0.5, 10.5, float("nan")):
        with pytest.raises(InputError, match=r"tether_drag_scale .* out of range \(allowed 0 \.\. 10\)"):
            fly(reference, config="nominal", tether_drag_scale=bad)


def test_physical_foldable_cycle_with_half_the_line_drag():
    """The physical plant flies a folding cycle: JSBSim propeller (T <= T_avail(V)), passive
    rectifier and PI reel-in, wing folded for the recovery. With the defined line no physical
    foldable cycle exists (README: line-drag sensitivity); with half the line drag in both the
    optimiser and the ground station one does (stored reference: physical, foldable, 8 m/s,
    flyable bounds, ``tether_drag_scale`` 0.5). One cycle meets the autopilot's acceptance:
    no event, tracking RMS <= 5 m and max <= 15 m, net energy within 15 % of the optimiser's,
    both ledgers closed within 1 %, and the wing actually folds and opens again."""
    from flight_helpers import DATA, assert_cycle_accepted

    ref = TrackingReference.from_ocp_file(str(DATA / "ref_physical_foldable_8mps_halfline.json"))
    scale = ref.meta["tether_drag_scale"]
    assert scale == 0.5 and ref.meta["scenario"] == "physical" and ref.meta["recovery_airframe"] == "folded"
    rep = fly(ref, config="foldable", cycles=1, tether_drag_scale=scale)
    c = assert_cycle_accepted(rep, ref)
    t, fold = rep.result.data[:, 0], rep.result.data[:, 20]  # fold state: 0 open, 1 folded
    folded = t[fold > 0.5]
    assert fold[0] == 0.0 and np.nanmax(fold) == pytest.approx(1.0)
    # folded in the recovery (after generation, for most of it), open again at the cycle's end
    assert folded[0] >= c.T1_s and folded[-1] - folded[0] >= 0.5 * c.T2_s
    assert fold[-1] < 0.1
    assert rep.as_json()["tether_drag_scale"] == 0.5
