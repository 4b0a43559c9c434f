#!/usr/bin/env python3
"""Real-time pacing with a MAVLink endpoint streaming: step jitter and endpoint overhead.

Runs a stand-in simulation step (busy work of --work-us per step, standing in for the
JSBSim + tether + winch + autopilot step) at --rate Hz, paced at --factor x real time for
--seconds, with a MavlinkEndpoint streaming its default telemetry to a local UDP listener
(a separate process that reads and counts the datagrams). Prints and writes to JSON:

- step jitter (wake-up lateness against the absolute deadline): mean, p99, max in ms,
  against the 5 ms target;
- the cost of ``endpoint.update`` per step when nothing is due (the cost a flight pays
  for having a link), against an empty Python call, and its mean over the run;
- how many datagrams the listener received.

    python scripts/bench_mavlink_pacing.py                 # 60 s at 1x
    python scripts/bench_mavlink_pacing.py --seconds 10 --json bench.json
"""

from __future__ import annotations

import argparse
import json
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from fdm_awe.mavlink.endpoint import MavlinkEndpoint
from fdm_awe.mavlink.vehicle import Telemetry
from fdm_awe.sim.pacing import RealtimePacer


_LISTENER = r"""
import socket, sys
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.bind(("127.0.0.1", 0))
s.settimeout(1.0)
print(s.getsockname()[1], flush=True)
n = 0
while True:
    try:
        s.recv(65536)
    except socket.timeout:
        if n:
            break
        continue
    n += 1
print(n, flush=True)
"""


class _Listener:
    """A stand-in ground station in its own process: counts datagrams on a local UDP port
    and exits one second after the last one."""

    def __init__(self) -> None:
        self.proc = subprocess.Popen([sys.executable, "-c", _LISTENER], stdout=subprocess.PIPE,
                                     text=True)
        self.port = int(self.proc.stdout.readline())
        self.count = 0

    def finish(self) -> None:
        try:
            out, _ = self.proc.communicate(timeout=10)
            self.count = int(out.strip() or 0)
        except (subprocess.TimeoutExpired, ValueError):
            self.proc.kill()
            self.proc.communicate()


def _busy(us: float) -> None:
    end = time.perf_counter() + us * 1e-6
    while time.perf_counter() < end:
        pass


def idle_update_cost_ns(n: int = 200_000) -> tuple[float, float]:
    """(ns per endpoint.update when nothing is due, ns per empty Python call)."""
    ep = MavlinkEndpoint("udpout:127.0.0.1:9", None)
    tel = Telemetry()
    ep.update(0.0, tel)                      # sends the first of every stream
    # every stream has now its next deadline >= 0.1 s (rates <= 10 Hz) and input polls
    # every 0.01 s: stay below 0.01 s so nothing becomes due
    ts = np.linspace(1e-6, 0.009, n).tolist()
    upd = ep.update
    t0 = time.perf_counter()
    for t in ts:
        upd(t, tel)
    c_upd = (time.perf_counter() - t0) / n * 1e9

    def empty(t, x):
        return None

    t0 = time.perf_counter()
    for t in ts:
        empty(t, tel)
    c_empty = (time.perf_counter() - t0) / n * 1e9
    ep.close()
    return c_upd, c_empty


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=60.0, help="simulated seconds (default 60)")
    ap.add_argument("--rate", type=float, default=120.0, help="simulation steps per second")
    ap.add_argument("--factor", type=float, default=1.0, help="real-time factor (default 1)")
    ap.add_argument("--work-us", type=float, default=300.0, help="stand-in step work, us")
    ap.add_argument("--json", type=Path, default=Path("bench_mavlink_pacing.json"))
    a = ap.parse_args(argv)

    idle_ns, empty_ns = idle_update_cost_ns()

    lis = _Listener()
    ep = MavlinkEndpoint(f"udpout:127.0.0.1:{lis.port}", None)
    pacer = RealtimePacer(a.factor)
    dt = 1.0 / a.rate
    n = int(round(a.seconds * a.rate))
    pos = np.array([150.0, 0.0, -75.0])
    tel = Telemetry(pos_ned=pos, airspeed=18.0, phase="generation", mode="AUTO", armed=True)
    upd_cost = 0.0
    t_wall0 = time.monotonic()
    for k in range(n + 1):
        t = k * dt
        _busy(a.work_us)                     # the simulation step
        tel.t = t
        pos[1] = 40.0 * np.sin(0.3 * t)
        c0 = time.perf_counter()
        ep.update(t, tel)
        upd_cost += time.perf_counter() - c0
        pacer.wait(t)
    wall = time.monotonic() - t_wall0
    ep.close()
    lis.finish()
    st = pacer.stats()
    sent = sum(ep.stats["sent"].values())
    res = {
        "benchmark": "mavlink_pacing",
        "python": platform.python_version(),
        "sim_seconds": a.seconds, "step_hz": a.rate, "factor": a.factor, "work_us": a.work_us,
        "wall_seconds": wall, "achieved_factor": st.achieved_factor,
        "jitter_mean_ms": st.mean_ms, "jitter_p99_ms": st.p99_ms, "jitter_max_ms": st.max_ms,
        "late_steps_over_5ms": st.late_steps, "steps": st.steps, "resyncs": st.resyncs,
        "target_ms": 5.0, "meets_target": st.max_ms < 5.0,
        "update_idle_ns": idle_ns, "empty_call_ns": empty_ns,
        "update_idle_over_empty_call": idle_ns / empty_ns,
        "update_mean_us_per_step": upd_cost / (n + 1) * 1e6,
        "messages_sent": sent, "datagrams_received": lis.count,
    }
    print(f"{a.seconds:g} s at {a.factor:g}x, {a.rate:g} Hz steps, {a.work_us:g} us work/step, "
          f"endpoint streaming to 127.0.0.1:{lis.port}")
    print(f"  step jitter: mean {st.mean_ms:.3f} ms  p99 {st.p99_ms:.3f} ms  max {st.max_ms:.3f} ms"
          f"  (target < 5 ms: {'met' if st.max_ms < 5.0 else 'NOT met'}; "
          f"{st.late_steps} of {st.steps} steps later than 5 ms; {st.resyncs} resyncs)")
    print(f"  achieved factor {st.achieved_factor:.5f} over {wall:.2f} s wall")
    print(f"  endpoint.update when nothing is due: {idle_ns:.0f} ns/step "
          f"(empty Python call {empty_ns:.0f} ns; ratio {idle_ns / empty_ns:.2f})")
    print(f"  endpoint.update mean over the run: {res['update_mean_us_per_step']:.2f} us/step; "
          f"{sent} messages sent, {lis.count} datagrams received")
    a.json.write_text(json.dumps(res, indent=1) + "\n")
    print(f"  wrote {a.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
