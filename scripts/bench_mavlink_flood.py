#!/usr/bin/env python3
"""Commands answered while another peer misbehaves: a flood, an idle TCP client, a stray byte.

A MavlinkEndpoint (no vehicle: every command is answered, MAV_RESULT_FAILED) is stepped at
120 Hz, paced at real time. A pymavlink ground station sends --commands distinct commands
one at a time and counts those whose COMMAND_ACK arrives within --timeout s. Meanwhile, by
--case:

- ``udp-flood``: a separate process sends HEARTBEATs from one UDP socket to the vehicle
  (``udpin:``) at --rate datagrams/s (0: as fast as it can);
- ``tcp-idle``: a client connects to the vehicle (``tcpin:``) first and sends nothing; the
  ground station connects second;
- ``tcp-flood``: the same, the first client sending HEARTBEATs at --rate frames/s;
- ``tcp-stray``: the ground station alone sends one 0xFD byte before its commands.

Prints one line per case (answered / sent, what the vehicle read and dropped) and writes
them to --json.

    python scripts/bench_mavlink_flood.py
    python scripts/bench_mavlink_flood.py --case udp-flood --rate 0 --json flood.json
"""

from __future__ import annotations

import argparse
import json
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

os.environ.setdefault("MAVLINK20", "1")

from pymavlink import mavutil  # noqa: E402
from pymavlink.dialects.v20 import common as mav  # noqa: E402

from fdm_awe.fileio import atomic_write_text  # noqa: E402
from fdm_awe.mavlink.endpoint import MavlinkEndpoint  # noqa: E402
from fdm_awe.mavlink.vehicle import Telemetry  # noqa: E402
from fdm_awe.sim.pacing import RealtimePacer  # noqa: E402

CASES = ("udp-flood", "tcp-idle", "tcp-flood", "tcp-stray")

_FLOODER = r"""
import socket, sys, time
from pymavlink.dialects.v20 import common as mav
kind, port, rate = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
enc = mav.MAVLink(None, srcSystem=77, srcComponent=1)
hb = enc.heartbeat_encode(mav.MAV_TYPE_GCS, mav.MAV_AUTOPILOT_INVALID, 0, 0, 0).pack(enc)
if kind == "udp":
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    send = lambda: s.sendto(hb, ("127.0.0.1", port))
else:
    s = socket.create_connection(("127.0.0.1", port))
    send = lambda: s.sendall(hb)
    if rate < 0:                      # idle: connected, silent
        sys.stdout.write("ready\n"); sys.stdout.flush()
        time.sleep(1e6)
sys.stdout.write("ready\n"); sys.stdout.flush()
t0 = time.monotonic(); n = 0
while True:
    try:
        send()
    except OSError:
        pass
    n += 1
    if rate > 0:
        lag = t0 + n / rate - time.monotonic()
        if lag > 0:
            time.sleep(lag)
"""


def _free_port() -> int:
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def run_case(case: str, rate: float, commands: int, timeout: float) -> dict:
    """Run one case; its counts."""
    port = _free_port()
    tcp = case.startswith("tcp")
    ep = MavlinkEndpoint(f"tcpin:127.0.0.1:{port}" if tcp else f"udpin:127.0.0.1:{port}", None,
                         log=lambda s: None)
    pacer = RealtimePacer(1.0)
    t = 0.0

    def step() -> None:
        nonlocal t
        ep.update(t, Telemetry(t=t))
        pacer.wait(t)
        t += 1 / 120

    flooder = None
    if case in ("udp-flood", "tcp-idle", "tcp-flood"):
        r = -1.0 if case == "tcp-idle" else rate
        flooder = subprocess.Popen([sys.executable, "-c", _FLOODER, "tcp" if tcp else "udp", str(port), str(r)],
                                   stdout=subprocess.PIPE, text=True)
        if tcp:
            while flooder.stdout.readline().strip() != "ready":   # connected before the ground station
                pass
        for _ in range(24):
            step()
    gcs = mavutil.mavlink_connection(f"tcp:127.0.0.1:{port}" if tcp else f"udpout:127.0.0.1:{port}",
                                     source_system=255, source_component=190)
    answered = 0
    try:
        if case == "tcp-stray":
            gcs.port.sendall(b"\xfd")
        for k in range(commands):
            gcs.mav.command_long_send(1, 1, 31000 + k, 0, 0, 0, 0, 0, 0, 0, 0)
            t_end = time.monotonic() + timeout
            got = False
            while not got and time.monotonic() < t_end:
                step()
                while not got:
                    m = gcs.recv_match(blocking=False)
                    if m is None:
                        break
                    got = m.get_type() == "COMMAND_ACK" and m.command == 31000 + k
            answered += got
            while time.monotonic() < t_end:   # commands at a steady pace, answered or not
                step()
    finally:
        gcs.close()
        if flooder is not None:
            flooder.kill()
            flooder.wait()
        ep.close()
    st = ep.stats
    return {"case": case, "rate": rate, "answered": answered, "sent": commands,
            "reads": st["datagrams"], "dropped": st.get("rx_dropped", 0), "bad": st["bad_packets"]}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--case", choices=CASES, action="append", help="a case (repeatable; default all)")
    ap.add_argument("--rate", type=float, default=610.0, help="flood rate, messages/s (0: as fast as possible)")
    ap.add_argument("--commands", type=int, default=22, help="commands sent, one at a time")
    ap.add_argument("--timeout", type=float, default=1.0, help="wait for each ACK, s")
    ap.add_argument("--json", type=Path, help="write the results here")
    a = ap.parse_args()
    if a.rate < 0 or a.commands < 1 or a.timeout <= 0:
        print("bench_mavlink_flood: --rate >= 0, --commands >= 1, --timeout > 0", file=sys.stderr)
        return 2
    results = []
    for case in a.case or CASES:
        r = run_case(case, a.rate, a.commands, a.timeout)
        results.append(r)
        print(f"{case:10s} rate {a.rate:g}/s: {r['answered']}/{r['sent']} commands answered "
              f"({r['reads']} reads, {r['dropped']} dropped, {r['bad']} bad)")
    if a.json:
        atomic_write_text(a.json, json.dumps(results, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
