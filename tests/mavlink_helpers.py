"""Shared pieces of the MAVLink tests: a stand-in vehicle and a pymavlink ground station."""

from __future__ import annotations

import math
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

os.environ.setdefault("MAVLINK20", "1")

import numpy as np  # noqa: E402
from pymavlink import mavutil  # noqa: E402

from fdm_awe.mavlink.endpoint import MavlinkEndpoint  # noqa: E402
from fdm_awe.autopilot.params import ParamStore  # noqa: E402
from fdm_awe.mavlink.vehicle import NavTarget, Telemetry  # noqa: E402
from fdm_awe.autopilot.vehicle import Waypoint  # noqa: E402

GCS_SYSID = 255
GCS_COMPID = 190


def free_udp_port() -> int:
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def reference_path(n: int = 24) -> list[Waypoint]:
    """A lying figure-eight at 100-200 m from the winch, 30 deg elevation (test data)."""
    out = []
    for k in range(n):
        s = 2 * math.pi * k / n
        az = 0.35 * math.sin(s)
        el = math.radians(30) + 0.12 * math.sin(2 * s)
        r = 150.0 + 40.0 * math.cos(s)
        out.append(Waypoint(r * math.cos(el) * math.cos(az), r * math.cos(el) * math.sin(az),
                            -r * math.sin(el), time_s=0.5 * k,
                            phase="generation" if k < n - 6 else "recovery"))
    return out


class StandInVehicle:
    """Implements VehicleInterface with plain bookkeeping (what an autopilot would do)."""

    modes = ["MANUAL", "FBWA", "AUTO", "RECOVER"]

    def __init__(self, params_path=None, tether_max_m: float = 300.0) -> None:
        self.mode = "MANUAL"
        self.armed = False
        self.cycling = False
        self._mission = reference_path()
        self.tether_max_m = tether_max_m
        self.changes: list[tuple[str, float]] = []
        self.received_missions: list[list[Waypoint]] = []
        self.params = ParamStore(params_path)
        cb = lambda name, value: self.changes.append((name, value))  # noqa: E731
        self.params.add("AP_ROLL_KP", 0.8, 0.0, 5.0, doc="bank -> aileron, 1/rad", on_change=cb)
        self.params.add("AP_PITCH_KP", 1.2, 0.0, 5.0, doc="alpha -> elevator, 1/rad", on_change=cb)
        self.params.add("WINCH_PI_KP", 0.004, 0.0, 0.1, doc="duty per rad/s", on_change=cb)
        self.params.add("WINCH_PI_KI", 0.10, 0.0, 10.0, doc="duty per rad", on_change=cb)
        self.params.add("FOLD_TIME_S", 0.6, 0.05, 5.0, doc="fold actuator time, s", on_change=cb)
        self.params.add("CYCLE_COUNT", 3, 0, 1000, kind="int", on_change=cb)
        self.params.add("FOLD_ENABLE", 1, 0, 1, kind="bool", on_change=cb)

    def set_mode(self, name: str) -> bool:
        if name not in self.modes:
            return False
        self.mode = name
        return True

    def arm(self, on: bool) -> bool:
        if not on and self.cycling:
            return False   # refuse to disarm while the cycle runs
        self.armed = bool(on)
        return True

    def start_cycling(self) -> bool:
        if not self.armed or not self._mission:
            return False
        self.cycling = True
        self.mode = "AUTO"
        return True

    def stop_cycling(self) -> bool:
        self.cycling = False
        return True

    def mission(self) -> list[Waypoint]:
        return list(self._mission)

    def set_mission(self, wps: list[Waypoint]) -> tuple[bool, str]:
        if len(wps) < 2:
            return False, "need at least 2 waypoints"
        for i, w in enumerate(wps):
            if w.down >= 0:
                return False, f"waypoint {i} not above the winch"
            if math.sqrt(w.north**2 + w.east**2 + w.down**2) > self.tether_max_m:
                return False, f"waypoint {i} beyond the tether length"
        self._mission = list(wps)
        self.received_missions.append(list(wps))
        return True, "ok"

    def clear_mission(self) -> None:
        self._mission = []


def telemetry_at(t: float, v: StandInVehicle | None = None) -> Telemetry:
    """Telemetry of a glider on a circle at 150 m (stand-in flight state)."""
    w = 0.3
    r = 150.0
    pos = np.array([r * 0.8, r * 0.5 * math.sin(w * t), -r * 0.5])
    vel = np.array([0.0, r * 0.5 * w * math.cos(w * t), 0.0])
    return Telemetry(t=t, pos_ned=pos, vel_ned=vel, euler=np.array([0.2, 0.05, 1.5]),
                     omega_body=np.array([0.01, 0.02, 0.03]), airspeed=18.0, throttle=0.3,
                     tension_N=30.0, reel_speed_mps=3.5, winch_power_W=56.7, net_energy_J=120.0,
                     phase="generation", fold=0.0, battery_voltage_V=11.8, battery_current_A=2.5,
                     battery_remaining=0.8, mode=v.mode if v else "AUTO",
                     armed=v.armed if v else True, cycling=v.cycling if v else True,
                     line_length_m=160.0, winch_voltage_V=48.5, winch_current_A=1.25,
                     winch_mode="generator", surfaces=(0.1, -0.2, 0.05, 0.0), mission_seq=3,
                     nav=NavTarget(roll=0.3, pitch=0.1, heading=1.4, target_bearing=1.6,
                                   distance_m=7.5, alt_error_m=-1.5, airspeed_error_mps=0.5,
                                   xtrack_m=2.0))


class Link:
    """An endpoint (vehicle side) and a pymavlink ground station on 127.0.0.1, one thread.

    Simulation time advances by ``dt`` per step; ``pump`` steps the endpoint and
    collects what the ground station receives.
    """

    def __init__(self, vehicle=None, dt: float = 1 / 120, gcs_udpin: bool = True, **kw) -> None:
        port = free_udp_port()
        self.vehicle = vehicle if vehicle is not None else StandInVehicle()
        if gcs_udpin:   # vehicle sends to the ground station's port (the usual set-up)
            self.gcs = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}",
                                                  source_system=GCS_SYSID,
                                                  source_component=GCS_COMPID)
            self.ep = MavlinkEndpoint(f"udpout:127.0.0.1:{port}", self.vehicle, **kw)
        else:           # vehicle listens; ground station sends first
            self.ep = MavlinkEndpoint(f"udpin:127.0.0.1:{port}", self.vehicle, **kw)
            self.gcs = mavutil.mavlink_connection(f"udpout:127.0.0.1:{port}",
                                                  source_system=GCS_SYSID,
                                                  source_component=GCS_COMPID)
        self.port = port
        self.dt = dt
        self.t = 0.0
        self.received: list = []
        self._mark = 0

    @property
    def tx(self):
        """The ground station's encoder; marks where replies to what is sent now begin."""
        self._mark = len(self.received)
        return self.gcs.mav

    def step(self, n: int = 1) -> None:
        for _ in range(n):
            self.ep.update(self.t, lambda: telemetry_at(self.t, self.vehicle))
            self.t += self.dt
            self.drain()

    def drain(self) -> list:
        got = []
        while True:
            m = self.gcs.recv_match(blocking=False)
            if m is None:
                break
            if m.get_type() != "BAD_DATA":
                got.append(m)
        self.received.extend(got)
        return got

    def wait_for(self, mtype: str | tuple[str, ...], cond=None, timeout: float = 3.0,
                 sleep: float = 0.0005):
        """First matching message received since the last ``tx`` use, stepping until it
        arrives; None after ``timeout`` wall seconds."""
        types = (mtype,) if isinstance(mtype, str) else mtype
        t_end = time.monotonic() + timeout
        start = self._mark
        while True:
            for m in self.received[start:]:
                if m.get_type() in types and (cond is None or cond(m)):
                    return m
            start = len(self.received)
            if time.monotonic() >= t_end:
                return None
            self.step()
            time.sleep(sleep)

    def target(self):
        return self.ep.sysid, self.ep.compid

    def close(self) -> None:
        self.ep.close()
        self.gcs.close()


def stop_process(proc: "subprocess.Popen", sig: int = signal.SIGTERM, wait: float = 20.0) -> None:
    """Send ``sig`` to ``proc`` if it still runs and wait up to ``wait`` s for it to end; kill
    it after that (a ground-station test's flight or MAVProxy, whatever state the test left)."""
    if proc.poll() is None:
        proc.send_signal(sig)
        try:
            proc.wait(timeout=wait)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=10)


#: the stored reference the ground-station tests fly
FLY_REFERENCE = Path(__file__).parent / "data" / "ref_physical_nominal_8mps.json"


def launch_fly(port: int, *options: str, env: dict[str, str] | None = None) -> "subprocess.Popen":
    """``fdm-awe fly`` of :data:`FLY_REFERENCE` speaking MAVLink to a ground station on UDP
    ``port`` of 127.0.0.1, with ``options`` (``--cycles``, ``--realtime``, ...); its output
    merged on a pipe."""
    return subprocess.Popen(
        [sys.executable, "-m", "fdm_awe", "fly", "--reference", str(FLY_REFERENCE), "--quiet",
         "--mavlink", f"udpout:127.0.0.1:{port}", *options],
        stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        env=env if env is not None else dict(os.environ, JSBSIM_DEBUG="0"))
