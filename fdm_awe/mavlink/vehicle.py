"""What the MAVLink endpoint needs from the vehicle: telemetry in, commands out.

The endpoint (:mod:`fdm_awe.mavlink.endpoint`) speaks MAVLink; the autopilot speaks
physics. They meet here, in three small pieces:

``Telemetry``
    One snapshot of the simulated system, in SI units, ground frame NED with its
    origin at the winch. The flight loop builds it (or a callable that builds it
    lazily) and passes it to ``MavlinkEndpoint.update(t, telemetry)`` every step.

``Waypoint``
    One point of the reference path: ``north, east, down`` in metres relative to the
    winch, optionally the reference time within the cycle ``time_s`` and the cycle
    ``phase``. On the wire a waypoint is a ``MISSION_ITEM_INT`` (``MAV_CMD_NAV_WAYPOINT``,
    ``MAV_FRAME_GLOBAL_RELATIVE_ALT_INT``); ``time_s`` and ``phase`` have no place in a
    MAVLink mission item, so a path uploaded from a ground station arrives with
    ``time_s = phase = None`` and the autopilot decides how to time it (or rejects it
    through ``set_mission``).

``VehicleInterface``
    The protocol the autopilot implements so a ground station can command it::

        modes: list[str]                 # names from MODE_NUMBERS, incl. MANUAL, AUTO, RECOVER
        mode: str                        # current mode name
        set_mode(name) -> bool           # False = refused (stays in the old mode)
        armed: bool
        arm(on: bool, force=False) -> bool  # False = refused (a disarm in flight unless forced)
        cycling: bool                    # pumping cycles running
        start_cycling() -> bool
        stop_cycling() -> bool
        mission() -> list[Waypoint]      # the loaded reference path
        set_mission(wps) -> (ok, reason) # validate + load; reason says why not
        clear_mission() -> None
        params: ParamStore               # gains etc.; PARAM_SET calls their callbacks

    Every method is called from inside ``MavlinkEndpoint.update`` (the simulation
    thread), so no locking is needed; a method that raises is answered to the ground
    station as a failure and logged, it never stops the simulation.

Mode numbers (``custom_mode`` in HEARTBEAT, ``DO_SET_MODE`` and ``SET_MODE``) come from the
single table :data:`MODE_NUMBERS`. Where the meaning matches, the number is ArduPlane's,
because MAVProxy and other ArduPilot-aware tools name a fixed-wing vehicle's
``custom_mode`` with ArduPlane's table: MANUAL shows as ``MANUAL``, AUTO as ``AUTO`` and
RECOVER (the safe abort: brake the drum, reel in the slack, circle down and land at the winch or
park in a hold) as ``RTL``; MAVLink RTL (MAV_CMD_NAV_RETURN_TO_LAUNCH) switches to it
(:data:`RTL_MODE`). A disarm in flight is refused unless forced (:data:`ARM_DISARM_FORCE`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np

from fdm_awe.errors import InputError
from fdm_awe.mavlink.params import ParamStore

#: Mode name -> MAVLink ``custom_mode`` number (ArduPlane numbering where meanings match).
MODE_NUMBERS: dict[str, int] = {
    "MANUAL": 0,     # surfaces/throttle straight from the pilot (or held neutral)
    "FBWA": 5,       # stabilised attitude, no path following
    "AUTO": 10,      # fly the mission (reference path) and run the pumping cycle
    "RECOVER": 11,   # safe abort: reel in, circle down, land or park (shown as RTL)
    "LOITER": 12,    # circle on the tether at constant length
    "GUIDED": 15,    # hold the current point of the path
}

#: MAV_CMD_COMPONENT_ARM_DISARM param2 that forces an arm or disarm (ArduPilot's magic
#: number): without it a disarm in flight is refused.
ARM_DISARM_FORCE = 21196

#: MAVLink RTL (MAV_CMD_NAV_RETURN_TO_LAUNCH, MAVProxy ``rtl``) maps to this mode.
RTL_MODE = "RECOVER"

#: ``custom_mode`` number -> mode name.
MODE_NAMES: dict[int, str] = {v: k for k, v in MODE_NUMBERS.items()}

#: Cycle phase name -> number sent as NAMED_VALUE_FLOAT ``phase``.
PHASE_CODES: dict[str, float] = {
    "ground": 0.0,
    "generation": 1.0,
    "transition": 2.0,
    "recovery": 3.0,
}

PHASES = tuple(PHASE_CODES)


def mode_number(name: str) -> int:
    """``custom_mode`` number of a mode name; InputError for a name not in MODE_NUMBERS."""
    try:
        return MODE_NUMBERS[name]
    except KeyError:
        raise InputError(
            f"mode {name!r}: unknown; allowed: {', '.join(MODE_NUMBERS)}") from None


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
        battery_voltage_V, battery_current_A: onboard battery, V and A (+ = discharge).
        battery_remaining: state of charge 0..1, or -1 when unknown.
        mode: autopilot mode name (a key of MODE_NUMBERS).
        armed: motor armed.
        cycling: pumping cycles running.
        health_ok: False when the simulation reports a fault (clears the AHRS health bit).
        line_length_m: unstretched line paid out at the winch, m (NaN = unknown).
        winch_voltage_V: winch DC-link voltage, V (NaN = unknown).
        winch_current_A: winch machine (armature) current, A (NaN = unknown).
        winch_mode: what the winch machine does: "generator", "motor", "idle" or "" (unknown).
        winch_ok: False when the winch is out of order (line broken).
        line_fully_in: the line is reeled in completely.
        surfaces: aileron, elevator, rudder (-1..1) and fold command (0..1) as commanded.
        mission_seq: index of the mission item being flown to, -1 when no mission is flown.
        nav: what the path follower aims at (:class:`NavTarget`), None outside path following.
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
    battery_voltage_V: float = 12.6
    battery_current_A: float = 0.0
    battery_remaining: float = -1.0
    mode: str = "MANUAL"
    armed: bool = False
    cycling: bool = False
    health_ok: bool = True
    line_length_m: float = math.nan
    winch_voltage_V: float = math.nan
    winch_current_A: float = math.nan
    winch_mode: str = ""
    winch_ok: bool = True
    line_fully_in: bool = False
    surfaces: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    mission_seq: int = -1
    nav: "NavTarget | None" = None


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


@dataclass(frozen=True)
class Waypoint:
    """A point of the reference path, m relative to the winch (NED).

    ``time_s`` is the reference time within the cycle (s) and ``phase`` the cycle phase
    (one of PHASES); both are optional and are not carried by MAVLink missions.
    """

    north: float
    east: float
    down: float
    time_s: float | None = None
    phase: str | None = None

    def __post_init__(self) -> None:
        for name in ("north", "east", "down"):
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or not math.isfinite(v):
                raise InputError(f"waypoint {name}: {v!r} is not a finite number (m)")
        if self.time_s is not None and not math.isfinite(self.time_s):
            raise InputError(f"waypoint time_s: {self.time_s!r} is not finite (s)")
        if self.phase is not None and self.phase not in PHASE_CODES:
            raise InputError(
                f"waypoint phase: {self.phase!r}; allowed: {', '.join(PHASES)}")


@runtime_checkable
class VehicleInterface(Protocol):
    """What a ground station may command; implemented by the autopilot (see module doc)."""

    @property
    def modes(self) -> list[str]: ...

    @property
    def mode(self) -> str: ...

    def set_mode(self, name: str) -> bool: ...

    @property
    def armed(self) -> bool: ...

    def arm(self, on: bool, force: bool = False) -> bool: ...

    @property
    def cycling(self) -> bool: ...

    def start_cycling(self) -> bool: ...

    def stop_cycling(self) -> bool: ...

    def mission(self) -> list[Waypoint]: ...

    def set_mission(self, waypoints: list[Waypoint]) -> tuple[bool, str]: ...

    def clear_mission(self) -> None: ...

    @property
    def params(self) -> ParamStore: ...
