"""Standard telemetry messages ground stations expect beyond the basic set.

Each sender takes ``(endpoint, telemetry, t)`` and is scheduled as a stream by
:class:`fdm_awe.mavlink.endpoint.MavlinkEndpoint` (rates in :data:`RATES`, Hz of simulation time):

``GPS_RAW_INT``
    A simulated perfect receiver: 3D fix, the glider's position (lat/lon about home, altitude
    AMSL), ground speed and course over ground, HDOP/VDOP 0.8, 12 satellites. Positions are the
    simulation's own (no GPS noise is modelled).
``MISSION_CURRENT``
    ``seq``: the mission item being flown to (the next waypoint of the reference path after the
    reference point), ``total``: the mission's size, ``mission_state``: ACTIVE while the cycles
    run, PAUSED when stopped, NO_MISSION without a path; ``mission_mode`` 1 in AUTO.
``NAV_CONTROLLER_OUTPUT``
    What the path follower aims at (:class:`fdm_awe.mavlink.vehicle.NavTarget`): commanded roll
    and pitch (deg), commanded heading and the bearing to the reference point (deg, 0..359),
    the distance to it (m), altitude error (m, + = too low), airspeed error (m/s, + = too slow)
    and cross-track error (m, + = right of the track). Not sent outside path following.
``SERVO_OUTPUT_RAW``
    The commands as PWM microseconds in ArduPlane's channel order: 1 aileron, 2 elevator,
    3 throttle, 4 rudder (surfaces 1500 +- 500 us for -1..1, throttle 1000..2000 us for 0..1),
    5 fold actuator (1000 us unfolded .. 2000 us folded). Sign conventions are those of
    :class:`fdm_awe.sixdof.state.Surfaces`.
``WINCH_STATUS``
    Sent by the winch component (:mod:`fdm_awe.mavlink.winch`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Callable

from pymavlink.dialects.v20 import common as mav

from .vehicle import Telemetry

if TYPE_CHECKING:  # pragma: no cover
    from .endpoint import MavlinkEndpoint

#: default rates of these streams, Hz of simulation time
RATES: dict[str, float] = {
    "GPS_RAW_INT": 5.0,
    "MISSION_CURRENT": 1.0,
    "NAV_CONTROLLER_OUTPUT": 4.0,
    "SERVO_OUTPUT_RAW": 4.0,
    "WINCH_STATUS": 2.0,
}

_HDOP_X100 = 80
_SATELLITES = 12


def _f(x: Any, default: float = 0.0) -> float:
    """``x`` as a finite float, else ``default`` (telemetry fields may be missing or NaN)."""
    try:
        v = float(x)
    except (TypeError, ValueError):
        return default
    return v if math.isfinite(v) else default


def _i(x: float, lo: int, hi: int, default: int = 0) -> int:
    v = _f(x, math.nan)
    if math.isnan(v):
        return default
    return int(min(hi, max(lo, round(v))))


def _us(t: float) -> int:
    return _i(t * 1e6, 0, 2**63 - 1)


def pwm_surface(u: float) -> int:
    """PWM microseconds of a surface command -1..1 (1000..2000, 1500 neutral)."""
    return _i(1500.0 + 500.0 * min(max(_f(u), -1.0), 1.0), 1000, 2000, 1500)


def pwm_unit(u: float) -> int:
    """PWM microseconds of a command 0..1 (throttle, fold): 1000..2000."""
    return _i(1000.0 + 1000.0 * min(max(_f(u), 0.0), 1.0), 1000, 2000, 1000)


def send_gps_raw(ep: "MavlinkEndpoint", tel: Telemetry, t: float) -> None:
    n, e, d = (_f(v) for v in tel.pos_ned[:3])
    vn, ve = _f(tel.vel_ned[0]), _f(tel.vel_ned[1])
    lat, lon, alt = ep.geo.to_geodetic(n, e, d)
    gs = math.hypot(vn, ve)
    cog = math.degrees(math.atan2(ve, vn)) % 360.0 if gs > 0.1 else 0.0
    i32 = (-2**31, 2**31 - 1)
    ep._send("GPS_RAW_INT", ep._mav.gps_raw_int_send, _us(t), mav.GPS_FIX_TYPE_3D_FIX,
             _i(lat * 1e7, -900000000, 900000000), _i(lon * 1e7, -1800000000, 1800000000),
             _i(alt * 1000.0, *i32), _HDOP_X100, _HDOP_X100, _i(gs * 100.0, 0, 65534),
             _i(cog * 100.0, 0, 35999), _SATELLITES)


def mission_size(ep: "MavlinkEndpoint") -> int:
    """Number of items of the vehicle's mission (0 without a vehicle or when it fails)."""
    v = ep.vehicle
    if v is None:
        return 0
    try:
        return len(v.mission())
    except Exception:  # noqa: BLE001 - a failing vehicle call reads as no mission
        return 0


def send_mission_current(ep: "MavlinkEndpoint", tel: Telemetry, t: float) -> None:
    total = mission_size(ep)
    if total == 0:
        state = mav.MISSION_STATE_NO_MISSION
    elif tel.cycling and tel.mode == "AUTO":
        state = mav.MISSION_STATE_ACTIVE
    else:
        state = mav.MISSION_STATE_PAUSED
    seq = tel.mission_seq if 0 <= tel.mission_seq < total else 0
    ep._send("MISSION_CURRENT", ep._mav.mission_current_send, seq, total, state,
             1 if tel.mode == "AUTO" else 0)


def send_nav_controller(ep: "MavlinkEndpoint", tel: Telemetry, t: float) -> None:
    nav = tel.nav
    if nav is None:
        return
    ep._send("NAV_CONTROLLER_OUTPUT", ep._mav.nav_controller_output_send,
             math.degrees(_f(nav.roll)), math.degrees(_f(nav.pitch)),
             _i(math.degrees(_f(nav.heading)) % 360.0, -32768, 32767),
             _i(math.degrees(_f(nav.target_bearing)) % 360.0, -32768, 32767),
             _i(nav.distance_m, 0, 65535), _f(nav.alt_error_m), _f(nav.airspeed_error_mps), _f(nav.xtrack_m))


def send_servo_output(ep: "MavlinkEndpoint", tel: Telemetry, t: float) -> None:
    try:
        ail, ele, rud, fold = (float(v) for v in tel.surfaces[:4])
    except (TypeError, ValueError):
        ail = ele = rud = fold = 0.0
    ep._send("SERVO_OUTPUT_RAW", ep._mav.servo_output_raw_send, _i(t * 1e6, 0, 2**32 - 1), 0,
             pwm_surface(ail), pwm_surface(ele), pwm_unit(tel.throttle), pwm_surface(rud), pwm_unit(fold),
             0, 0, 0)


def send_winch_status(ep: "MavlinkEndpoint", tel: Telemetry, t: float) -> None:
    ep.winch.send_status(ep, tel, t)


#: stream name -> sender
SENDERS: dict[str, Callable[["MavlinkEndpoint", Telemetry, float], None]] = {
    "GPS_RAW_INT": send_gps_raw,
    "MISSION_CURRENT": send_mission_current,
    "NAV_CONTROLLER_OUTPUT": send_nav_controller,
    "SERVO_OUTPUT_RAW": send_servo_output,
    "WINCH_STATUS": send_winch_status,
}
