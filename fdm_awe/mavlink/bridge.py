"""From the co-simulation's state to the MAVLink endpoint's :class:`Telemetry`."""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from .vehicle import NavTarget, Telemetry

#: line length below which the line counts as fully reeled in, m
FULLY_IN_M = 0.5


def nav_target(autopilot: Any, s: Any) -> NavTarget | None:
    """What the autopilot's path follower aims at (None outside AUTO/RECOVER/LOITER path following)."""
    r, cmd = getattr(autopilot, "ref_point", None), getattr(autopilot, "last_guidance", None)
    if r is None or cmd is None or autopilot.mode not in ("AUTO", "RECOVER", "LOITER"):
        return None
    p = np.asarray(s.pos_ned, float)
    d = np.asarray(r.pos, float) - p
    bearing = math.atan2(d[1], d[0])
    v = np.asarray(r.vel, float)
    vh = math.hypot(v[0], v[1])
    # + = right of the track: the glider's offset e = -d from the reference point on the
    # track's right-hand unit vector (-v_e, v_n) / |v_h|
    xtrack = ((-d[0]) * (-v[1]) + (-d[1]) * v[0]) / vh if vh > 0.1 else 0.0
    return NavTarget(roll=float(cmd.roll), pitch=float(cmd.pitch), heading=float(cmd.yaw),
                     target_bearing=bearing, distance_m=float(np.linalg.norm(d)),
                     alt_error_m=float(-d[2]), airspeed_error_mps=float(r.airspeed - s.airspeed),
                     xtrack_m=float(xtrack))


def telemetry_builder(autopilot: Any, sim: Any) -> Callable[[Any, Any], Telemetry]:
    """A function ``(glider_state, gs_output) -> Telemetry`` for ``MavlinkEndpoint.update``.

    Net energy = ground-station load energy - supply energy - glider motor energy (J); the
    motor energy is integrated here from the glider's electrical power, step by step. The
    battery is the motor's supply: its voltage (the motor's voltage at full throttle, the
    engine file's), the current the motor's electrical input draws from it, and the charge
    and energy drawn, integrated step by step.
    The mission item flown to (``mission_seq``) is the first of the autopilot's mission
    waypoints (times within the cycle) after the reference point.
    """
    ledger = sim.gs.ledger
    dt = sim.dt
    acc = {"thrust": 0.0, "t": None, "charge": 0.0}
    volts = float(getattr(getattr(sim, "glider", None), "motor_volts", math.nan))
    mission: dict[str, Any] = {"ref": None, "times": None, "period": 0.0}

    def mission_seq() -> int:
        ref, r = autopilot.reference, getattr(autopilot, "ref_point", None)
        if ref is None or r is None or autopilot.mode != "AUTO" or not autopilot.cycling:
            return -1
        if mission["ref"] is not ref:
            mission.update(ref=ref, times=np.array([w.time_s for w in autopilot.mission()], float),
                           period=float(ref.period))
        times = mission["times"]
        if times is None or len(times) == 0 or not np.all(np.isfinite(times)):
            return -1
        return int(np.searchsorted(times, r.t_cycle, side="right")) % len(times)

    def wind_ned() -> np.ndarray | None:
        est = getattr(autopilot, "wind_estimate", None)
        return None if est is None else np.asarray(est.at_glider_ned(), float)

    def build(s: Any, o: Any) -> Telemetry:
        c = autopilot.glider.controls
        length = math.nan if o is None else float(o.length)
        return Telemetry(
            t=s.t, pos_ned=s.pos_ned, vel_ned=s.vel_ned, euler=s.euler, omega_body=s.omega_body,
            airspeed=s.airspeed, throttle=c.throttle,
            tension_N=0.0 if o is None else o.tension, reel_speed_mps=0.0 if o is None else o.reel_speed,
            winch_power_W=0.0 if o is None else o.p_electrical,
            net_energy_J=ledger.load - ledger.supply - acc["thrust"],
            phase=autopilot.phase if autopilot.phase in ("ground", "generation", "transition", "recovery") else "transition",
            fold=s.fold, battery_voltage_V=volts, battery_current_A=battery_current(s),
            battery_consumed_mAh=acc["charge"] / 3.6, battery_energy_J=acc["thrust"],
            in_air=not bool(s.on_ground), mode=autopilot.mode, armed=autopilot.armed,
            cycling=autopilot.cycling, health_ok=s.is_finite(),
            line_length_m=length,
            winch_voltage_V=math.nan if o is None else float(getattr(o, "u_link", math.nan)),
            winch_current_A=math.nan if o is None else float(o.current),
            winch_mode="" if o is None else str(getattr(o, "machine_mode", "")),
            winch_ok=True if o is None else not bool(getattr(o, "broken", False)),
            line_fully_in=(o is not None and (o.event == "tether_fully_reeled_in" or length <= FULLY_IN_M)),
            surfaces=(c.aileron, c.elevator, c.rudder, c.fold_cmd),
            mission_seq=mission_seq(), nav=nav_target(autopilot, s), wind_ned=wind_ned(),
        )

    def battery_current(s: Any) -> float:
        """The battery's current, A: the motor's electrical input over the supply voltage."""
        return max(float(s.prop_power_W), 0.0) / volts if volts > 0.0 else math.nan

    def integrate(s: Any) -> None:
        acc["thrust"] += max(s.prop_power_W, 0.0) * dt
        i = battery_current(s)
        if i == i:
            acc["charge"] += i * dt

    build.integrate = integrate  # type: ignore[attr-defined]
    return build
