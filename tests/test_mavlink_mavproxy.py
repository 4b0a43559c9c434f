"""MAVProxy against the real vehicle: ``fdm-awe fly --mavlink`` flying a stored reference.

The flight (the autopilot of :mod:`fdm_awe.autopilot`, its parameters from
``aircraft/glider_foldable/autopilot.xml``, the reference path as its mission) runs as a
subprocess paced at real time; MAVProxy (a dev extra) connects headless with
``--non-interactive`` and runs its commands with its ``repeat`` module once the vehicle's first
heartbeat has arrived. Bounded: MAVProxy is stopped after a fixed wall time, the flight with
Ctrl-C (SIGINT) after that.
"""

from __future__ import annotations

import importlib.util
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from mavlink_helpers import free_udp_port, launch_fly, stop_process
from pymavlink import mavutil

from fdm_awe.autopilot.config import load_autopilot_definition
from fdm_awe.mavlink.geo import GeoFrame


# a path to upload, written in the QGC WPL 110 text format MAVProxy loads (index, current,
# frame 6 = GLOBAL_RELATIVE_ALT_INT, command 16 = NAV_WAYPOINT, p1-p4, lat, lon, alt, autocontinue)
UPLOAD_NED = [(110.0 + 12.0 * k, -20.0 + 8.0 * k, -55.0 - 4.0 * k) for k in range(6)]

pytestmark = pytest.mark.skipif(importlib.util.find_spec("MAVProxy") is None,
                                reason="MAVProxy not installed (pip install 'fdm-awe[dev]')")

RUN_S = 16.0        # MAVProxy's wall time once the vehicle is up
START_S = 60.0      # the flight's start (imports, JSBSim) at most


def _write_wpl(path: Path) -> None:
    geo = GeoFrame()
    lines = ["QGC WPL 110"]
    for i, (n, e, d) in enumerate(UPLOAD_NED):
        lat, lon, _ = geo.to_geodetic(n, e, d)
        lines.append(f"{i}\t0\t6\t16\t0\t0\t0\t0\t{lat:.8f}\t{lon:.8f}\t{-d:.3f}\t1")
    path.write_text("\n".join(lines) + "\n")



def test_mavproxy_reads_the_real_vehicles_parameters_and_mission(tmp_path):
    port = free_udp_port()
    params = tmp_path / "params.json"
    env = dict(os.environ, MAVLINK20="1")
    fly = launch_fly(port, "--cycles", "1", "--realtime", "1", "--params", str(params),
                     "--json", str(tmp_path / "flight.json"), env=env)
    mavproxy = None
    log = tmp_path / "mavproxy.txt"
    try:
        # wait for the vehicle's first heartbeat, then hand the port to MAVProxy
        # (not one sent while the flight loads: MAV_STATE_BOOT, before the vehicle answers)
        probe = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}")
        t_end = time.monotonic() + START_S
        hb = None
        while time.monotonic() < t_end and (hb is None or hb.system_status == mavutil.mavlink.MAV_STATE_BOOT):
            hb = probe.recv_match(type="HEARTBEAT", blocking=True, timeout=max(t_end - time.monotonic(), 0.1))
        probe.close()
        assert hb is not None, "the flight sent no heartbeat"
        wpl = tmp_path / "upload.txt"
        _write_wpl(wpl)
        cmds = "; ".join([
            # periods chosen so that a download (wp list) never overlaps an upload (wp load)
            "repeat add 4 param show GUID_*",
            "repeat add 5 param set GUID_KP 1.1",
            "repeat add 7 wp load " + str(wpl),
            "repeat add 10 wp list",
            "repeat add 12 mode RTL",
        ])
        with open(log, "w") as out:
            mavproxy = subprocess.Popen(
                [sys.executable, "-m", "MAVProxy.mavproxy", f"--master=udpin:127.0.0.1:{port}",
                 "--non-interactive", "--no-state", f"--cmd={cmds}"],
                stdin=subprocess.DEVNULL, stdout=out, stderr=subprocess.STDOUT, text=True, cwd=tmp_path, env=env)
            time.sleep(RUN_S)
            stop_process(fly, signal.SIGINT)              # Ctrl-C: the flight ends, its outputs are written
            time.sleep(1.0)                        # the flight's last STATUSTEXT reaches MAVProxy
            stop_process(mavproxy)
    finally:
        for p in (fly, mavproxy):
            if p is not None:
                stop_process(p, signal.SIGKILL, 5.0)
    out = log.read_text()
    flown = fly.stdout.read()
    print(out)
    print(flown)
    assert fly.returncode == 130, flown                        # interrupted by the Ctrl-C above
    assert "Detected vehicle 1:1" in out and "Detected vehicle 1:169" in out    # autopilot and winch
    # the real vehicle's parameters: those of the autopilot definition, none of a stand-in's
    defined = [d.id for d in load_autopilot_definition()]
    assert f"Received {len(defined)} parameters" in out
    assert re.search(r"^GUID_KD\s+2\.0\b", out, re.M) and "AP_ROLL_KP" not in out
    # its mission: the reference path, 60 waypoints (NAV_WAYPOINT, GLOBAL_RELATIVE_ALT_INT)
    listed = re.findall(r"Requesting (\d+) waypoints", out)
    assert listed and listed[0] == "60" and set(listed) <= {"60"}
    assert out.count("16 6 ") >= 60
    # a path uploaded from MAVProxy's file is accepted by the autopilot
    assert "Sent all 6 waypoints" in out and "MISSION_ACK: TYPE_MISSION: ACCEPTED" in out
    # the mode change, its STATUSTEXT, and the flight's end
    assert "DO_SET_MODE: ACCEPTED" in out or "Mode RTL" in out
    assert "mode AUTO -> RECOVER" in out
    assert "flight interrupted" in out
    # the parameter as typed: 1.1 in the vehicle's parameter file, not float32's 1.100000023841858
    saved = json.loads(params.read_text())["params"]
    assert saved["GUID_KP"] == 1.1 and "1.1000000" not in params.read_text()
    doc = json.loads((tmp_path / "flight.json").read_text())
    assert doc["status"] == "interrupted"
