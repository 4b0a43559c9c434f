"""What each streamed message says: one sender per stream, and AUTOPILOT_VERSION.

Each sender takes ``(endpoint, telemetry, t)`` and is scheduled as a stream by
:class:`fdm_awe.mavlink.streams.StreamSchedule` (default rates in :data:`RATES`, Hz of
simulation time; a ground station may also ask for any of them once, MAV_CMD_REQUEST_MESSAGE).
Telemetry fields that are missing or not finite go out as the message's "unknown" value or 0.

``HEARTBEAT``
    MAV_TYPE_FIXED_WING, MAV_AUTOPILOT_ARDUPILOTMEGA (the custom modes are ArduPlane's numbers,
    :data:`fdm_awe.mode_table.MODE_NUMBERS`, so MAVProxy, MAVSDK and QGroundControl name and
    command them), armed flag; MAV_STATE_CRITICAL when the simulation's health is lost. The winch's HEARTBEAT (:mod:`fdm_awe.mavlink.winch`) goes with it.
``ATTITUDE``, ``GLOBAL_POSITION_INT``, ``VFR_HUD``
    Euler angles and body rates; position about home (altitude AMSL and above home) and NED
    velocity; airspeed, ground speed, heading, throttle, altitude and climb rate.
``SYS_STATUS``
    All simulated sensors/controllers are present, enabled and healthy, including the
    pre-arm check (the vehicle is always armable) and the geofence bit (the tether is the fence; without the health bit MAVProxy announces a fence
    breach). ``drop_rate_comm`` is 10000 (100 %) while the ground-station link is lost,
    ``errors_comm`` counts undecodable packets, ``errors_count1`` link losses,
    ``errors_count2`` messages whose handling failed and ``errors_count3`` messages refused
    by signing.
``BATTERY_STATUS``, ``HOME_POSITION``
    The glider's battery: the motor's supply voltage (its engine file), the current the motor
    draws from it (electrical input / voltage), the charge and energy drawn since the start;
    remaining -1 (unknown: no capacity is modelled). The winch's position (the NED origin).
``EXTENDED_SYS_STATE``
    Fixed-wing, landed state IN_AIR or ON_GROUND (the glider's ground contact at the last step).
``ATTITUDE_QUATERNION``, ``SYSTEM_TIME``
    The attitude as a quaternion (body to NED) and the body rates; the wall clock (Unix time)
    and the simulation time.
``NAMED_VALUE_FLOAT``
    The values of :data:`NAMED_VALUES`.

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
``WIND``
    ArduPilot's message (id 168, ardupilotmega dialect; MAVProxy shows it): the onboard wind
    estimate at the glider (:mod:`fdm_awe.autopilot.wind_estimate`, the last cycle's), the
    direction it blows from (deg, 0..360), its horizontal speed and its vertical speed (m/s, 0:
    the estimate has no vertical wind, as EKF3's). Not sent before the first estimate.

``AUTOPILOT_VERSION`` (on request only): the package version and the protocol capabilities
(mission and parameter protocols in float and int form, COMMAND_INT, MAVLink 2).
"""

from __future__ import annotations

import math
import time
from typing import Any, Callable

from pymavlink.dialects.v20 import ardupilotmega as apm
from pymavlink.dialects.v20 import common as mav

from .link import Link
from ..mode_table import MODE_NUMBERS
from .vehicle import PHASE_CODES, Telemetry


#: default rates of the streams, Hz of simulation time (also the order they go out in)
RATES: dict[str, float] = {
    "HEARTBEAT": 1.0,
    "ATTITUDE": 10.0,
    "ATTITUDE_QUATERNION": 10.0,
    "GLOBAL_POSITION_INT": 10.0,
    "VFR_HUD": 4.0,
    "SYS_STATUS": 1.0,
    "BATTERY_STATUS": 1.0,
    "HOME_POSITION": 0.2,
    "NAMED_VALUE_FLOAT": 2.0,
    "GPS_RAW_INT": 5.0,
    "MISSION_CURRENT": 1.0,
    "NAV_CONTROLLER_OUTPUT": 4.0,
    "SERVO_OUTPUT_RAW": 4.0,
    "WINCH_STATUS": 2.0,
    "WIND": 1.0,
    "EXTENDED_SYS_STATE": 1.0,
    "SYSTEM_TIME": 1.0,
}

#: Names and units of the NAMED_VALUE_FLOAT values (names <= 10 characters).
NAMED_VALUES: dict[str, str] = {
    "tension": "tether tension at the winch, N",
    "reel_spd": "reel speed, m/s (+ = reel-out)",
    "winch_pwr": "winch electrical power, W (+ = generated)",
    "net_energy": "net electrical energy, J (+ = gain)",
    "phase": "cycle phase code (0 ground, 1 generation, 2 transition, 3 recovery)",
    "fold": "wing fold state, 0 unfolded .. 1 folded",
}

_HDOP_X100 = 80
_SATELLITES = 12

_SENSORS = (mav.MAV_SYS_STATUS_SENSOR_3D_GYRO | mav.MAV_SYS_STATUS_SENSOR_3D_ACCEL
            | mav.MAV_SYS_STATUS_SENSOR_3D_MAG | mav.MAV_SYS_STATUS_SENSOR_ABSOLUTE_PRESSURE
            | mav.MAV_SYS_STATUS_SENSOR_DIFFERENTIAL_PRESSURE | mav.MAV_SYS_STATUS_SENSOR_GPS
            | mav.MAV_SYS_STATUS_SENSOR_ANGULAR_RATE_CONTROL
            | mav.MAV_SYS_STATUS_SENSOR_ATTITUDE_STABILIZATION
            | mav.MAV_SYS_STATUS_SENSOR_YAW_POSITION | mav.MAV_SYS_STATUS_SENSOR_Z_ALTITUDE_CONTROL
            | mav.MAV_SYS_STATUS_SENSOR_XY_POSITION_CONTROL
            | mav.MAV_SYS_STATUS_SENSOR_MOTOR_OUTPUTS | mav.MAV_SYS_STATUS_AHRS
            | mav.MAV_SYS_STATUS_GEOFENCE | mav.MAV_SYS_STATUS_SENSOR_BATTERY
            | mav.MAV_SYS_STATUS_PREARM_CHECK)

_CAPABILITIES = (mav.MAV_PROTOCOL_CAPABILITY_MISSION_FLOAT | mav.MAV_PROTOCOL_CAPABILITY_PARAM_FLOAT
                 | mav.MAV_PROTOCOL_CAPABILITY_MISSION_INT | mav.MAV_PROTOCOL_CAPABILITY_COMMAND_INT
                 | mav.MAV_PROTOCOL_CAPABILITY_MAVLINK2)

_I32 = (-2**31, 2**31 - 1)


def as_finite(x: Any, default: float = 0.0) -> float:
    """``x`` as a finite float, else ``default`` (telemetry fields may be missing or NaN)."""
    try:
        v = float(x)
    except (TypeError, ValueError):
        return default
    return v if math.isfinite(v) else default


def _i(x: float, lo: int, hi: int, default: int = 0) -> int:
    """``x`` rounded to an int inside [lo, hi]; non-finite or non-numeric -> ``default``."""
    v = as_finite(x, math.nan)
    if math.isnan(v):
        return default
    return int(min(hi, max(lo, round(v))))


def _us(t: float) -> int:
    """Simulation time ``t`` (s) as uint64 microseconds."""
    return _i(t * 1e6, 0, 2**63 - 1)


def _ms(t: float) -> int:
    """Simulation time ``t`` (s) as uint32 milliseconds (time_boot_ms)."""
    return _i(t * 1000.0, 0, 0xFFFFFFFF, 0)


def _vec3(v: Any) -> tuple[float, float, float]:
    """The first three components of ``v`` as finite floats (zeros if it has fewer)."""
    try:
        return as_finite(v[0]), as_finite(v[1]), as_finite(v[2])
    except (TypeError, IndexError, KeyError):
        return 0.0, 0.0, 0.0


def pwm_surface(u: float) -> int:
    """PWM microseconds of a surface command -1..1 (1000..2000, 1500 neutral)."""
    return _i(1500.0 + 500.0 * min(max(as_finite(u), -1.0), 1.0), 1000, 2000, 1500)


def pwm_unit(u: float) -> int:
    """PWM microseconds of a command 0..1 (throttle, fold): 1000..2000."""
    return _i(1000.0 + 1000.0 * min(max(as_finite(u), 0.0), 1.0), 1000, 2000, 1000)


def _vehicle_state(ep: Link, tel: Telemetry) -> tuple[str, bool]:
    """Mode and armed flag: the vehicle's own, else (no vehicle, or it fails) the telemetry's."""
    v = ep.vehicle
    if v is not None:
        try:
            return str(v.mode), bool(v.armed)
        except Exception:  # noqa: BLE001
            pass
    return str(tel.mode), bool(tel.armed)


def send_heartbeat(ep: Link, tel: Telemetry, t: float) -> None:
    mode, armed = _vehicle_state(ep, tel)
    custom = MODE_NUMBERS.get(mode, 0)
    base = mav.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
    if armed:
        base |= mav.MAV_MODE_FLAG_SAFETY_ARMED
    if mode == "MANUAL":
        base |= mav.MAV_MODE_FLAG_MANUAL_INPUT_ENABLED
    else:
        base |= mav.MAV_MODE_FLAG_STABILIZE_ENABLED
        if mode in ("AUTO", "RECOVER", "GUIDED", "LOITER"):
            base |= mav.MAV_MODE_FLAG_GUIDED_ENABLED | mav.MAV_MODE_FLAG_AUTO_ENABLED
    if not tel.health_ok:
        status = mav.MAV_STATE_CRITICAL
    else:
        status = mav.MAV_STATE_ACTIVE if armed else mav.MAV_STATE_STANDBY
    ep.send("HEARTBEAT", ep.mav.heartbeat_send, mav.MAV_TYPE_FIXED_WING,
             mav.MAV_AUTOPILOT_ARDUPILOTMEGA, base, custom, status)
    ep.winch.send_heartbeat(ep, tel)


def send_attitude(ep: Link, tel: Telemetry, t: float) -> None:
    phi, theta, psi = _vec3(tel.euler)
    p, q, r = _vec3(tel.omega_body)
    ep.send("ATTITUDE", ep.mav.attitude_send, _ms(t), phi, theta, psi, p, q, r)


def euler_quaternion(phi: float, theta: float, psi: float) -> tuple[float, float, float, float]:
    """The quaternion (w, x, y, z) of the body-to-NED rotation of Euler angles roll ``phi``,
    pitch ``theta``, yaw ``psi`` (rad, 3-2-1 order), as MAVLink's ATTITUDE_QUATERNION carries it."""
    cr, sr = math.cos(0.5 * phi), math.sin(0.5 * phi)
    cp, sp = math.cos(0.5 * theta), math.sin(0.5 * theta)
    cy, sy = math.cos(0.5 * psi), math.sin(0.5 * psi)
    return (cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy)


def send_attitude_quaternion(ep: Link, tel: Telemetry, t: float) -> None:
    w, x, y, z = euler_quaternion(*_vec3(tel.euler))
    p, q, r = _vec3(tel.omega_body)
    ep.send("ATTITUDE_QUATERNION", ep.mav.attitude_quaternion_send, _ms(t), w, x, y, z, p, q, r,
             [0.0, 0.0, 0.0, 0.0])


def send_extended_sys_state(ep: Link, tel: Telemetry, t: float) -> None:
    if tel.in_air is None:
        landed = mav.MAV_LANDED_STATE_UNDEFINED
    else:
        landed = mav.MAV_LANDED_STATE_IN_AIR if tel.in_air else mav.MAV_LANDED_STATE_ON_GROUND
    ep.send("EXTENDED_SYS_STATE", ep.mav.extended_sys_state_send, mav.MAV_VTOL_STATE_FW, landed)


def send_system_time(ep: Link, tel: Telemetry, t: float) -> None:
    ep.send("SYSTEM_TIME", ep.mav.system_time_send, _i(time.time() * 1e6, 0, 2**63 - 1), _ms(t))


def send_global_position(ep: Link, tel: Telemetry, t: float) -> None:
    n, e, d = _vec3(tel.pos_ned)
    vn, ve, vd = _vec3(tel.vel_ned)
    lat, lon, alt = ep.geo.to_geodetic(n, e, d)
    hdg = math.degrees(as_finite(_vec3(tel.euler)[2])) % 360.0
    ep.send("GLOBAL_POSITION_INT", ep.mav.global_position_int_send, _ms(t),
             _i(lat * 1e7, -900000000, 900000000, 0), _i(lon * 1e7, -1800000000, 1800000000, 0),
             _i(alt * 1000.0, *_I32, 0), _i(-d * 1000.0, *_I32, 0),
             _i(vn * 100.0, -32768, 32767, 0), _i(ve * 100.0, -32768, 32767, 0),
             _i(vd * 100.0, -32768, 32767, 0), _i(hdg * 100.0, 0, 35999, 65535))


def send_vfr_hud(ep: Link, tel: Telemetry, t: float) -> None:
    n, e, d = _vec3(tel.pos_ned)
    vn, ve, vd = _vec3(tel.vel_ned)
    hdg = _i(math.degrees(_vec3(tel.euler)[2]) % 360.0, 0, 359, 0)
    ep.send("VFR_HUD", ep.mav.vfr_hud_send, as_finite(tel.airspeed), math.hypot(vn, ve), hdg,
             _i(as_finite(tel.throttle) * 100.0, 0, 100, 0), ep.geo.home.alt_m - d, -vd)


def _millivolts(tel: Telemetry) -> int:
    """Battery voltage in mV (65535 = unknown)."""
    return _i(as_finite(tel.battery_voltage_V, -1) * 1000.0, 0, 65534, 65535)


def _centiamps(tel: Telemetry) -> int:
    """Battery current in cA (-1 = unknown)."""
    return _i(as_finite(tel.battery_current_A, -0.01) * 100.0, -1, 32767, -1)


def _remaining_pct(tel: Telemetry) -> int:
    """Battery remaining in % (-1 = unknown)."""
    r = as_finite(tel.battery_remaining, -1.0)
    return -1 if r < 0 else _i(r * 100.0, 0, 100, -1)


def send_sys_status(ep: Link, tel: Telemetry, t: float) -> None:
    health = _SENSORS if tel.health_ok else _SENSORS & ~mav.MAV_SYS_STATUS_AHRS
    st = ep.stats
    sg = st["signing"]
    refused = sg["unsigned_rejected"] + sg["bad_signature_rejected"]
    ep.send("SYS_STATUS", ep.mav.sys_status_send, _SENSORS, _SENSORS, health, 0,
             _millivolts(tel), _centiamps(tel), _remaining_pct(tel), 10000 if ep.link_lost else 0,
             min(st["bad_packets"], 65535), min(st["link_losses"], 65535),
             min(st["handler_errors"], 65535), min(refused, 65535), 0)


def send_battery(ep: Link, tel: Telemetry, t: float) -> None:
    volts = [65535] * 10
    volts[0] = _millivolts(tel)
    ep.send("BATTERY_STATUS", ep.mav.battery_status_send, 0, mav.MAV_BATTERY_FUNCTION_ALL,
             mav.MAV_BATTERY_TYPE_LIPO, 32767, volts, _centiamps(tel),
             _i(as_finite(tel.battery_consumed_mAh, -1.0), -1, 2**31 - 1, -1),
             _i(as_finite(tel.battery_energy_J, -100.0) / 100.0, -1, 2**31 - 1, -1), _remaining_pct(tel))


def send_home(ep: Link, tel: Telemetry, t: float) -> None:
    h = ep.geo.home
    ep.send("HOME_POSITION", ep.mav.home_position_send, int(round(h.lat_deg * 1e7)),
             int(round(h.lon_deg * 1e7)), int(round(h.alt_m * 1000.0)), 0.0, 0.0, 0.0,
             [1.0, 0.0, 0.0, 0.0], 0.0, 0.0, 0.0, _us(t))


def send_named_values(ep: Link, tel: Telemetry, t: float) -> None:
    ms = _ms(t)
    for name, value in ((b"tension", tel.tension_N), (b"reel_spd", tel.reel_speed_mps),
                        (b"winch_pwr", tel.winch_power_W), (b"net_energy", tel.net_energy_J),
                        (b"phase", PHASE_CODES.get(tel.phase, -1.0)), (b"fold", tel.fold)):
        ep.send("NAMED_VALUE_FLOAT", ep.mav.named_value_float_send, ms, name, as_finite(value, math.nan))


def send_autopilot_version(ep: Link) -> None:
    """AUTOPILOT_VERSION: the package version (major.minor.patch, official) and capabilities."""
    from fdm_awe import __version__
    parts = [int(x) if x.isdigit() else 0 for x in __version__.split(".")[:3]] + [0, 0, 0]
    sw = (parts[0] << 24) | (parts[1] << 16) | (parts[2] << 8) | 255   # 255 = FIRMWARE_VERSION_TYPE_OFFICIAL
    ep.send("AUTOPILOT_VERSION", ep.mav.autopilot_version_send, _CAPABILITIES, sw, 0, 0, 0,
             [0] * 8, [0] * 8, [0] * 8, 0, 0, 0)


def send_gps_raw(ep: Link, tel: Telemetry, t: float) -> None:
    n, e, d = (as_finite(v) for v in tel.pos_ned[:3])
    vn, ve = as_finite(tel.vel_ned[0]), as_finite(tel.vel_ned[1])
    lat, lon, alt = ep.geo.to_geodetic(n, e, d)
    gs = math.hypot(vn, ve)
    cog = math.degrees(math.atan2(ve, vn)) % 360.0 if gs > 0.1 else 0.0
    ep.send("GPS_RAW_INT", ep.mav.gps_raw_int_send, _us(t), mav.GPS_FIX_TYPE_3D_FIX,
             _i(lat * 1e7, -900000000, 900000000), _i(lon * 1e7, -1800000000, 1800000000),
             _i(alt * 1000.0, *_I32), _HDOP_X100, _HDOP_X100, _i(gs * 100.0, 0, 65534),
             _i(cog * 100.0, 0, 35999), _SATELLITES)


def mission_size(ep: Link) -> int:
    """Number of items of the vehicle's mission (0 without a vehicle or when it fails)."""
    v = ep.vehicle
    if v is None:
        return 0
    try:
        return len(v.mission())
    except Exception:  # noqa: BLE001 - a failing vehicle call reads as no mission
        return 0


def current_item(tel: Telemetry, total: int) -> int:
    """The mission item flown to (MISSION_CURRENT's ``seq``, the downloaded item marked
    ``current``): the telemetry's, else 0 (the first)."""
    return tel.mission_seq if 0 <= tel.mission_seq < total else 0


def send_mission_current(ep: Link, tel: Telemetry, t: float) -> None:
    total = mission_size(ep)
    if total == 0:
        state = mav.MISSION_STATE_NO_MISSION
    elif tel.cycling and tel.mode == "AUTO":
        state = mav.MISSION_STATE_ACTIVE
    else:
        state = mav.MISSION_STATE_PAUSED
    seq = current_item(tel, total)
    ep.send("MISSION_CURRENT", ep.mav.mission_current_send, seq, total, state,
             1 if tel.mode == "AUTO" else 0)


def send_nav_controller(ep: Link, tel: Telemetry, t: float) -> None:
    nav = tel.nav
    if nav is None:
        return
    ep.send("NAV_CONTROLLER_OUTPUT", ep.mav.nav_controller_output_send,
             math.degrees(as_finite(nav.roll)), math.degrees(as_finite(nav.pitch)),
             _i(math.degrees(as_finite(nav.heading)) % 360.0, -32768, 32767),
             _i(math.degrees(as_finite(nav.target_bearing)) % 360.0, -32768, 32767),
             _i(nav.distance_m, 0, 65535), as_finite(nav.alt_error_m), as_finite(nav.airspeed_error_mps), as_finite(nav.xtrack_m))


def send_servo_output(ep: Link, tel: Telemetry, t: float) -> None:
    try:
        ail, ele, rud, fold = (float(v) for v in tel.surfaces[:4])
    except (TypeError, ValueError):
        ail = ele = rud = fold = 0.0
    ep.send("SERVO_OUTPUT_RAW", ep.mav.servo_output_raw_send, _i(t * 1e6, 0, 2**32 - 1), 0,
             pwm_surface(ail), pwm_surface(ele), pwm_unit(tel.throttle), pwm_surface(rud), pwm_unit(fold),
             0, 0, 0)


def send_winch_status(ep: Link, tel: Telemetry, t: float) -> None:
    ep.winch.send_status(ep, tel, t)


def send_wind(ep: Link, tel: Telemetry, t: float) -> None:
    w = tel.wind_ned
    if w is None:
        return
    n, e, d = _vec3(w)
    ep.send("WIND", ep.mav.send, apm.MAVLink_wind_message(math.degrees(math.atan2(-e, -n)) % 360.0,
                                                           math.hypot(n, e), d))


#: stream name -> sender (the streams of :data:`RATES`)
SENDERS: dict[str, Callable[[Link, Telemetry, float], None]] = {
    "HEARTBEAT": send_heartbeat,
    "ATTITUDE": send_attitude,
    "ATTITUDE_QUATERNION": send_attitude_quaternion,
    "GLOBAL_POSITION_INT": send_global_position,
    "VFR_HUD": send_vfr_hud,
    "SYS_STATUS": send_sys_status,
    "BATTERY_STATUS": send_battery,
    "HOME_POSITION": send_home,
    "NAMED_VALUE_FLOAT": send_named_values,
    "GPS_RAW_INT": send_gps_raw,
    "MISSION_CURRENT": send_mission_current,
    "NAV_CONTROLLER_OUTPUT": send_nav_controller,
    "SERVO_OUTPUT_RAW": send_servo_output,
    "WINCH_STATUS": send_winch_status,
    "WIND": send_wind,
    "EXTENDED_SYS_STATE": send_extended_sys_state,
    "SYSTEM_TIME": send_system_time,
}
