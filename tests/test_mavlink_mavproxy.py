"""MAVProxy connects headless to the endpoint and shows vehicle, parameters and mission.

MAVProxy (a dev extra) runs as a subprocess with ``--non-interactive``; its commands are
scheduled with its ``repeat`` module so they run after the vehicle is detected. The
endpoint runs in a thread with simulation time following wall time. Bounded: MAVProxy
is stopped after a fixed wall time.
"""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys
import threading
import time

import pytest

from mavlink_helpers import StandInVehicle, free_udp_port, telemetry_at

from fdm_awe.mavlink.endpoint import MavlinkEndpoint
from fdm_awe.mavlink.geo import GeoFrame

# a path to upload, written here in the QGC WPL 110 text format MAVProxy loads
# (index, current, frame 6 = GLOBAL_RELATIVE_ALT_INT, command 16 = NAV_WAYPOINT, p1-p4,
# lat, lon, alt, autocontinue)
UPLOAD_NED = [(110.0 + 12.0 * k, -20.0 + 8.0 * k, -55.0 - 4.0 * k) for k in range(6)]


def _write_wpl(path):
    geo = GeoFrame()
    lines = ["QGC WPL 110"]
    for i, (n, e, d) in enumerate(UPLOAD_NED):
        lat, lon, _ = geo.to_geodetic(n, e, d)
        lines.append(f"{i}\t0\t6\t16\t0\t0\t0\t0\t{lat:.8f}\t{lon:.8f}\t{-d:.3f}\t1")
    path.write_text("\n".join(lines) + "\n")

pytestmark = pytest.mark.skipif(importlib.util.find_spec("MAVProxy") is None,
                                reason="MAVProxy not installed (pip install 'fdm-awe[dev]')")

RUN_S = 12.0


def test_mavproxy_shows_vehicle_parameters_and_mission(tmp_path):
    port = free_udp_port()
    v = StandInVehicle(params_path=tmp_path / "params.json")
    ep = MavlinkEndpoint(f"udpout:127.0.0.1:{port}", v)
    stop = threading.Event()

    def loop():
        t0 = time.monotonic()
        while not stop.is_set():
            t = time.monotonic() - t0
            ep.update(t, lambda: telemetry_at(t, v))
            time.sleep(0.002)

    th = threading.Thread(target=loop, daemon=True)
    th.start()
    wpl = tmp_path / "upload.txt"
    _write_wpl(wpl)
    cmds = "; ".join([
        "repeat add 4 wp list",
        f"repeat add 7 wp load {wpl}",
        "repeat add 5 long MISSION_START",
        "repeat add 5 param show AP_*",
        "repeat add 3 mode AUTO",
        "repeat add 3 arm throttle",
        "repeat add 4 param set WINCH_PI_KP 0.006",
    ])
    mavproxy = [sys.executable, "-m", "MAVProxy.mavproxy"]
    proc = subprocess.Popen(
        mavproxy + [f"--master=udpin:127.0.0.1:{port}", "--non-interactive", "--no-state",
                    f"--cmd={cmds}"],
        stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        cwd=tmp_path, env=dict(os.environ, MAVLINK20="1"))
    try:
        out, _ = proc.communicate(timeout=RUN_S)
    except subprocess.TimeoutExpired:
        proc.terminate()
        try:
            out, _ = proc.communicate(timeout=5)
        except subprocess.TimeoutExpired:
            proc.kill()
            out, _ = proc.communicate()
    finally:
        stop.set()
        th.join(timeout=2)
        ep.close()
    print(out)
    assert "Detected vehicle 1:1" in out
    assert "Mode MANUAL" in out or "Mode AUTO" in out          # heartbeat decoded with its mode
    assert "Received 7 parameters" in out                      # MAVFTP refused, PARAM_* used
    # the mission download: 24 waypoints before the upload below, 6 after it
    listed = re.findall(r"Requesting (\d+) waypoints", out)
    assert listed and set(listed) <= {"24", "6"}
    assert out.count("16 6 ") >= int(listed[0])                # NAV_WAYPOINT, GLOBAL_RELATIVE_ALT_INT
    assert "AP_ROLL_KP" in out
    assert "fence breach" not in out
    # commands from MAVProxy reached the vehicle
    assert "DO_SET_MODE: ACCEPTED" in out and v.mode == "AUTO"
    assert "COMPONENT_ARM_DISARM: ACCEPTED" in out and v.armed
    assert v.params["WINCH_PI_KP"] == pytest.approx(0.006)
    assert "MISSION_START: ACCEPTED" in out and v.cycling
    # upload from MAVProxy's file reached the vehicle (8 decimals in the file ~ 1 mm)
    assert "Sent all 6 waypoints" in out and "MISSION_ACK: TYPE_MISSION: ACCEPTED" in out
    got = v.received_missions[-1]
    assert len(got) == 6
    for w, (n, e, d) in zip(got, UPLOAD_NED):
        assert (w.north, w.east, w.down) == pytest.approx((n, e, d), abs=0.02)
