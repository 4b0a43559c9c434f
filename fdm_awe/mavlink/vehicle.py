"""What the MAVLink endpoint needs from the vehicle: telemetry in, commands out.

The endpoint (:mod:`fdm_awe.mavlink.endpoint`) speaks MAVLink; the autopilot speaks
physics. The autopilot defines what it offers (:mod:`fdm_awe.autopilot.vehicle`: ``Waypoint``,
``VehicleInterface`` and the vehicle ``PHASES``; :mod:`fdm_awe.autopilot.modes`: the mode table
:data:`~fdm_awe.mode_table.MODE_NUMBERS`; :mod:`fdm_awe.autopilot.params`: ``ParamStore``); the link's
modules import them from there, and this module adds the link's side:

``Telemetry``
    One snapshot of the simulated system, in SI units, ground frame NED with its
    origin at the winch. The flight loop builds it (or a callable that builds it
    lazily) and passes it to ``MavlinkEndpoint.update(t, telemetry)`` every step.

``Waypoint`` on the wire
    A ``MISSION_ITEM_INT`` (``MAV_CMD_NAV_WAYPOINT``, ``MAV_FRAME_GLOBAL_RELATIVE_ALT_INT``);
    ``time_s`` and ``phase`` have no place in a MAVLink mission item, so a path uploaded from a
    ground station arrives with ``time_s = phase = None``.

``VehicleInterface`` over the link
    Every method is called from inside ``MavlinkEndpoint.update`` (the simulation thread), so
    no locking is needed; a method that raises is answered to the ground station as a failure
    and logged, it never stops the simulation. ``PARAM_SET`` changes ``params`` (their
    callbacks run).

Mode numbers (``custom_mode`` in HEARTBEAT, ``DO_SET_MODE`` and ``SET_MODE``) come from the
autopilot's single table :data:`~fdm_awe.mode_table.MODE_NUMBERS` (ArduPlane's numbers where the meaning matches:
RECOVER shows as ``RTL``); MAVLink RTL (MAV_CMD_NAV_RETURN_TO_LAUNCH) switches to RECOVER
(:data:`RTL_MODE`). A disarm in flight is refused unless forced (:data:`ARM_DISARM_FORCE`).
The vehicle phase goes out as a number (:data:`PHASE_CODES`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from fdm_awe.autopilot.vehicle import PHASES

__all__ = ["ARM_DISARM_FORCE", "PHASE_CODES", "RTL_MODE", "NavTarget", "Telemetry"]

#: MAV_CMD_COMPONENT_ARM_DISARM param2 that forces an arm or disarm (ArduPilot's magic
#: number): without it a disarm in flight is refused.
ARM_DISARM_FORCE = 21196

#: MAVLink RTL (MAV_CMD_NAV_RETURN_TO_LAUNCH, MAVProxy ``rtl``) maps to this mode.
RTL_MODE = "RECOVER"

#: Vehicle phase name (:data:`fdm_awe.autopilot.vehicle.PHASES`) -> number sent as NAMED_VALUE_FLOAT ``phase``.
PHASE_CODES: dict[str, float] = {
    "ground": 0.0,
    "generation": 1.0,
    "transition": 2.0,
    "recovery": 3.0,
}
assert tuple(PHASE_CODES) == PHASES, "a wire code for every vehicle phase, in order"


@dataclass
class Telemetry:
    """One telemetry snapshot (SI units, NED with the origin at the winch).

    Attributes:
        t: simulation time, s.
        pos_ned: glider position, m (3,).
        vel_ned: ground velocity, m/s (3,).
        euler: roll phi, pitch theta, yaw psi, rad (3,).
        omega_body: body rates p, q, r, rad/s (3,).
        airspeed: true airspeed, m/s.
        throttle: throttle command, 0..1.
        tension_N: tether tension at the winch, N (>= 0).
        reel_speed_mps: reel speed, m/s (+ = paid out).
        winch_power_W: winch electrical power, W (+ = generated, delivered to the load).
        net_energy_J: net electrical energy since the start, J (+ = net gain).
        phase: cycle phase, one of PHASES.
        fold: wing fold state, 0 = unfolded .. 1 = folded.
        battery_voltage_V, battery_current_A: onboard battery, V and A (+ = discharge); NaN = unknown.
        battery_consumed_mAh, battery_energy_J: charge (mAh) and energy (J) drawn since the start,
            NaN = unknown.
        battery_remaining: state of charge 0..1, or -1 when unknown (no capacity modelled).
        mode: autopilot mode name (a key of MODE_NUMBERS).
        armed: motor armed.
        cycling: pumping cycles running.
        health_ok: False when the simulation reports a fault (clears the AHRS health bit).
        in_air: the glider touched no ground at the last step (None: unknown).
        line_length_m: unstretched line paid out at the winch, m (NaN = unknown).
        winch_voltage_V: winch DC-link voltage, V (NaN = unknown).
        winch_current_A: winch machine (armature) current, A (NaN = unknown).
        winch_mode: what the winch machine does: "generator", "motor", "idle" or "" (unknown).
        winch_ok: False when the winch is out of order (line broken).
        line_fully_in: the line is reeled in completely.
        surfaces: aileron, elevator, rudder (-1..1) and fold command (0..1) as commanded.
        mission_seq: index of the mission item being flown to, -1 when no mission is flown.
        nav: what the path follower aims at (:class:`NavTarget`), None outside path following.
        wind_ned: the autopilot's onboard wind estimate at the glider, m/s NED (the air's
            velocity; :mod:`fdm_awe.autopilot.wind_estimate`), None before its first estimate.
    """

    t: float = 0.0
    pos_ned: np.ndarray = field(default_factory=lambda: np.zeros(3))
    vel_ned: np.ndarray = field(default_factory=lambda: np.zeros(3))
    euler: np.ndarray = field(default_factory=lambda: np.zeros(3))
    omega_body: np.ndarray = field(default_factory=lambda: np.zeros(3))
    airspeed: float = 0.0
    throttle: float = 0.0
    tension_N: float = 0.0
    reel_speed_mps: float = 0.0
    winch_power_W: float = 0.0
    net_energy_J: float = 0.0
    phase: str = "ground"
    fold: float = 0.0
    battery_voltage_V: float = math.nan
    battery_current_A: float = math.nan
    battery_consumed_mAh: float = math.nan
    battery_energy_J: float = math.nan
    battery_remaining: float = -1.0
    mode: str = "MANUAL"
    armed: bool = False
    cycling: bool = False
    health_ok: bool = True
    in_air: bool | None = None
    line_length_m: float = math.nan
    winch_voltage_V: float = math.nan
    winch_current_A: float = math.nan
    winch_mode: str = ""
    winch_ok: bool = True
    line_fully_in: bool = False
    surfaces: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    mission_seq: int = -1
    nav: "NavTarget | None" = None
    wind_ned: np.ndarray | None = None


@dataclass(frozen=True)
class NavTarget:
    """What the path follower aims at (NAV_CONTROLLER_OUTPUT), SI units, angles in rad.

    Attributes:
        roll, pitch: commanded body roll and pitch, rad.
        heading: commanded body heading, rad.
        target_bearing: bearing from the glider to the reference point, rad (0 = north).
        distance_m: distance to the reference point, m.
        alt_error_m: reference altitude minus glider altitude, m (+ = glider too low).
        airspeed_error_mps: reference airspeed minus airspeed, m/s (+ = too slow).
        xtrack_m: horizontal offset across the reference track, m (+ = right of it).
    """

    roll: float
    pitch: float
    heading: float
    target_bearing: float
    distance_m: float
    alt_error_m: float
    airspeed_error_mps: float
    xtrack_m: float
