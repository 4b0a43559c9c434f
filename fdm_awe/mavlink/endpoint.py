"""MAVLink 2 vehicle endpoint driven from the simulation loop.

``MavlinkEndpoint(url, vehicle)`` opens any pymavlink connection URL (default
``udpout:127.0.0.1:14550``, where MAVProxy and QGroundControl listen) and is driven by
one call per simulation step::

    ep = MavlinkEndpoint("udpout:127.0.0.1:14550", vehicle=autopilot, home=Home(...))
    for each step:
        ...
        ep.update(t, telemetry)      # Telemetry, or a zero-argument callable returning one
    ep.close()

``update`` never blocks and never raises. Streams are scheduled by SIMULATION time (run
with the real-time pacer, :class:`fdm_awe.sim.pacing.RealtimePacer`, for a person watching;
without it the streams come out as fast as the simulation runs). When nothing is due,
``update`` costs one or two float comparisons; a callable ``telemetry`` is only called
when a message needs it. Incoming messages are drained at ``rx_rate_hz`` (simulation
time), at most ``max_rx_per_poll`` datagrams per poll; link and mission-transfer
timeouts use the wall clock, because ground stations run on it.

Framing: on UDP every datagram is parsed on its own (:func:`parse_datagram`): the parser
starts empty for each one, so a cut frame or junk in one datagram cannot swallow the messages
of the next. On byte streams (TCP, serial) the parser keeps its state across reads, as a
message may arrive in pieces.

Streams (rates in Hz, configurable with ``rates=`` or SET_MESSAGE_INTERVAL; 0 = off):
HEARTBEAT (MAV_TYPE_FIXED_WING, MAV_AUTOPILOT_GENERIC, custom mode from
:data:`fdm_awe.mavlink.vehicle.MODE_NUMBERS`, armed flag), ATTITUDE, GLOBAL_POSITION_INT,
VFR_HUD, SYS_STATUS, BATTERY_STATUS, HOME_POSITION and NAMED_VALUE_FLOAT with
``tension`` (N), ``reel_spd`` (m/s, + = reel-out), ``winch_pwr`` (W electrical,
+ = generated), ``net_energy`` (J), ``phase`` (code from
:data:`~fdm_awe.mavlink.vehicle.PHASE_CODES`) and ``fold`` (0..1); GPS_RAW_INT,
MISSION_CURRENT, NAV_CONTROLLER_OUTPUT and SERVO_OUTPUT_RAW (:mod:`fdm_awe.mavlink.messages`).
The winch is its own component (:mod:`fdm_awe.mavlink.winch`, id 169): its HEARTBEAT goes
with the autopilot's, WINCH_STATUS is the stream ``WINCH_STATUS``.

STATUSTEXT reports mode, arm, cycling, phase and winch changes and the flight's end
(:meth:`MavlinkEndpoint.flight_ended`; :mod:`fdm_awe.mavlink.statustext`). Signing
(``signing_key``): :mod:`fdm_awe.mavlink.signing`; messages refused by it are counted in
``stats["signing"]`` and SYS_STATUS ``errors_count3``.

SYS_STATUS: all simulated sensors/controllers are present, enabled and healthy,
including the geofence bit (the tether is the fence; without the health bit MAVProxy
announces a fence breach). ``drop_rate_comm`` is 10000 (100 %) while the ground-station
link is lost, ``errors_comm`` counts undecodable packets, ``errors_count1`` link losses and
``errors_count2`` messages whose handling failed.

Commands (COMMAND_LONG and COMMAND_INT; every command addressed to this vehicle gets a
COMMAND_ACK, unknown ones MAV_RESULT_UNSUPPORTED, bad parameters MAV_RESULT_DENIED,
a vehicle refusal MAV_RESULT_FAILED):

=================================  ==========================================================
MAV_CMD_COMPONENT_ARM_DISARM       param1 1 = arm, 0 = disarm; param2 21196 forces (a disarm in flight is refused otherwise)
MAV_CMD_DO_SET_MODE                param1 with MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, param2 mode
MAV_CMD_MISSION_START              start the pumping cycles (``vehicle.start_cycling``)
MAV_CMD_DO_PAUSE_CONTINUE          param1 0 = stop cycling, 1 = start cycling
MAV_CMD_NAV_RETURN_TO_LAUNCH       mode RECOVER
MAV_CMD_GET_HOME_POSITION          sends HOME_POSITION
MAV_CMD_REQUEST_MESSAGE            any streamed message, HOME_POSITION, AUTOPILOT_VERSION
MAV_CMD_SET_MESSAGE_INTERVAL       streamed messages (param2 us; -1 off, 0 default)
MAV_CMD_GET_MESSAGE_INTERVAL       answers MESSAGE_INTERVAL
MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES  sends AUTOPILOT_VERSION
=================================  ==========================================================

SET_MODE is answered with COMMAND_ACK(command = 11), as ArduPilot does.

Mission protocol (MAV_MISSION_TYPE_MISSION; fence and rally lists are empty): download
sends the vehicle's path as MISSION_ITEM_INT (MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
MAV_CMD_NAV_WAYPOINT, altitude relative to home = the winch); upload accepts
MISSION_ITEM_INT and MISSION_ITEM in the GLOBAL(_RELATIVE_ALT)(_INT) frames, re-requests
an item after ``mission_timeout_s`` up to ``mission_retries`` times, and rejects
with MAV_MISSION_NO_SPACE, UNSUPPORTED_FRAME, UNSUPPORTED (not a waypoint),
INVALID_PARAM5_X/6_Y/7 (bad latitude/longitude/altitude or too far from home),
OPERATION_CANCELLED (timeout) or INVALID (the vehicle's ``set_mission`` refused; the reason
goes out as STATUSTEXT). An upload of zero items and MISSION_CLEAR_ALL clear the mission.

Parameters: PARAM_REQUEST_LIST (sent ``param_burst`` per update), PARAM_REQUEST_READ,
PARAM_SET -> PARAM_VALUE (the old value and a STATUSTEXT when refused); a value is stored as
typed (:func:`fdm_awe.mavlink.params.from_wire`), not as the float32 that carried it. MAVFTP
(FILE_TRANSFER_PROTOCOL) is answered with a NAK (UnknownCommand) so ground stations fall
back to the parameter protocol at once.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass
from typing import Any, Callable

from fdm_awe.errors import InputError
from fdm_awe.mavlink.geo import GeoFrame, Home
from fdm_awe.mavlink.params import from_wire, param_text
from fdm_awe.mavlink.vehicle import (ARM_DISARM_FORCE, MODE_NAMES, MODE_NUMBERS, PHASE_CODES, RTL_MODE,
                                     Telemetry, VehicleInterface, Waypoint)

# Imported at module level on purpose: importing this module is the opt-in to MAVLink.
from pymavlink import mavutil  # noqa: E402
from pymavlink.dialects.v20 import common as mav  # noqa: E402

from fdm_awe.mavlink import signing as _signing  # noqa: E402
from fdm_awe.mavlink.messages import RATES as _EXTRA_RATES, SENDERS as _EXTRA_SENDERS, _f  # noqa: E402
from fdm_awe.mavlink.statustext import END_SEVERITY, ChangeReporter, chunks  # noqa: E402
from fdm_awe.mavlink.winch import WINCH_COMPID, WinchComponent  # noqa: E402

#: Default stream rates, Hz of simulation time.
DEFAULT_RATES: dict[str, float] = {
    "HEARTBEAT": 1.0,
    "ATTITUDE": 10.0,
    "GLOBAL_POSITION_INT": 10.0,
    "VFR_HUD": 4.0,
    "SYS_STATUS": 1.0,
    "BATTERY_STATUS": 1.0,
    "HOME_POSITION": 0.2,
    "NAMED_VALUE_FLOAT": 2.0,
    **_EXTRA_RATES,   # GPS_RAW_INT, MISSION_CURRENT, NAV_CONTROLLER_OUTPUT, SERVO_OUTPUT_RAW, WINCH_STATUS
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

_STREAM_IDS: dict[str, int] = {name: getattr(mav, f"MAVLINK_MSG_ID_{name}") for name in DEFAULT_RATES}
_STREAM_BY_ID: dict[int, str] = {v: k for k, v in _STREAM_IDS.items()}

_MAX_RATE_HZ = 200.0

_SENSORS = (mav.MAV_SYS_STATUS_SENSOR_3D_GYRO | mav.MAV_SYS_STATUS_SENSOR_3D_ACCEL
            | mav.MAV_SYS_STATUS_SENSOR_3D_MAG | mav.MAV_SYS_STATUS_SENSOR_ABSOLUTE_PRESSURE
            | mav.MAV_SYS_STATUS_SENSOR_DIFFERENTIAL_PRESSURE | mav.MAV_SYS_STATUS_SENSOR_GPS
            | mav.MAV_SYS_STATUS_SENSOR_ANGULAR_RATE_CONTROL
            | mav.MAV_SYS_STATUS_SENSOR_ATTITUDE_STABILIZATION
            | mav.MAV_SYS_STATUS_SENSOR_YAW_POSITION | mav.MAV_SYS_STATUS_SENSOR_Z_ALTITUDE_CONTROL
            | mav.MAV_SYS_STATUS_SENSOR_XY_POSITION_CONTROL
            | mav.MAV_SYS_STATUS_SENSOR_MOTOR_OUTPUTS | mav.MAV_SYS_STATUS_AHRS
            | mav.MAV_SYS_STATUS_GEOFENCE | mav.MAV_SYS_STATUS_SENSOR_BATTERY)

_CAPABILITIES = (mav.MAV_PROTOCOL_CAPABILITY_MISSION_FLOAT | mav.MAV_PROTOCOL_CAPABILITY_PARAM_FLOAT
                 | mav.MAV_PROTOCOL_CAPABILITY_MISSION_INT | mav.MAV_PROTOCOL_CAPABILITY_COMMAND_INT
                 | mav.MAV_PROTOCOL_CAPABILITY_MAVLINK2)

# MAVFTP opcodes/errors (mavlink.io/en/services/ftp.html)
_FTP_NAK = 129
_FTP_ERR_UNKNOWN_COMMAND = 7

_GLOBAL_FRAMES_REL = (mav.MAV_FRAME_GLOBAL_RELATIVE_ALT, mav.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT)
_GLOBAL_FRAMES_AMSL = (mav.MAV_FRAME_GLOBAL, mav.MAV_FRAME_GLOBAL_INT)


def _clamp_int(x: Any, lo: int, hi: int, default: int) -> int:
    """Round to int inside [lo, hi]; non-finite or non-numeric -> default."""
    try:
        xf = float(x)
    except (TypeError, ValueError):
        return default
    if not math.isfinite(xf):
        return default
    return int(min(hi, max(lo, round(xf))))


def _vec3(v: Any) -> tuple[float, float, float]:
    try:
        return _f(v[0]), _f(v[1]), _f(v[2])
    except (TypeError, IndexError, KeyError):
        return 0.0, 0.0, 0.0


#: pymavlink transports that deliver whole datagrams (UDP, UDP multicast)
DATAGRAM_TRANSPORTS = (mavutil.mavudp, mavutil.mavmcast)
#: resynchronisations tried within one datagram after a bad or cut frame (bounds a poll's cost)
MAX_RESYNC_PER_DATAGRAM = 32


def reset_parser(parser: mav.MAVLink) -> None:
    """Forget whatever a pymavlink parser holds of a partial frame."""
    parser.buf = bytearray()
    parser.buf_index = 0
    parser.expected_length = mav.HEADER_LEN_V1 + 2
    parser.have_prefix_error = False


def parse_datagram(parser: mav.MAVLink, data: bytes) -> tuple[list[Any], int]:
    """The MAVLink messages in one datagram, parsed on their own: ``(messages, bad)``.

    The parser starts empty and ends empty, so nothing of this datagram (a cut frame, a
    header announcing more bytes than came) can affect the next one. Within the datagram,
    after a frame that fails to decode (bad CRC, unknown flags) or is cut off, parsing
    resumes one byte after that frame's start byte, so a valid frame behind it is still found
    (at most :data:`MAX_RESYNC_PER_DATAGRAM` times). A frame of an unknown message id counts
    as failed (its CRC cannot be checked). ``bad`` counts the undecodable pieces (junk before
    a start byte, failed frames, a cut frame at the end)."""
    msgs: list[Any] = []
    bad = 0
    n = len(data)
    pos = 0
    resyncs = 0
    try:
        while pos < n:
            reset_parser(parser)
            m = parser.parse_char(data[pos:])
            nxt = n  # where to continue: the end, unless a bad or cut frame asks for a resync
            while m is not None:
                kind = m.get_type()
                if kind == "BAD_DATA" and m.reason == "Bad prefix":
                    bad += 1  # junk before a start byte: skipped
                elif kind == "BAD_DATA" and m.reason == "Invalid signature":
                    msgs.append(m)  # a whole frame refused by the signature check: counted there
                elif kind == "BAD_DATA" or kind.startswith("UNKNOWN"):
                    # a frame that failed (bad CRC or flags; an unknown id cannot be checked):
                    # look again from the byte after its start
                    bad += 1
                    if resyncs < MAX_RESYNC_PER_DATAGRAM:
                        nxt = n - parser.buf_len() - len(m.get_msgbuf()) + 1
                        break
                else:
                    msgs.append(m)
                m = parser.parse_char(b"")
            else:
                left = parser.buf_len()
                if left:  # a cut frame (or a header announcing more than the datagram holds)
                    bad += 1
                    if resyncs < MAX_RESYNC_PER_DATAGRAM:
                        nxt = n - left + 1
            if nxt < n:
                resyncs += 1
            pos = nxt
    except Exception:  # noqa: BLE001 - robust parsing should not raise; count it and move on
        bad += 1
    reset_parser(parser)
    return msgs, bad


@dataclass
class _Stream:
    name: str
    period: float      # s (simulation), inf = off
    next_t: float      # s (simulation)
    default_rate: float


class _Upload:
    """State of a mission upload from a ground station."""

    __slots__ = ("gcs", "count", "items", "expected", "last_req", "retries")

    def __init__(self, gcs: tuple[int, int], count: int, now: float) -> None:
        self.gcs = gcs
        self.count = count
        self.items: list[Waypoint] = []
        self.expected = 0
        self.last_req = now
        self.retries = 0


class MavlinkEndpoint:
    """A MAVLink 2 vehicle on a pymavlink connection (see module doc for the protocol).

    Args:
        url: pymavlink connection string: ``udpout:HOST:PORT`` (send to a ground station
            listening there), ``udpin:HOST:PORT`` (listen; reply to whoever sends),
            ``tcp:HOST:PORT``, ``tcpin:HOST:PORT``, a serial device, ...
        vehicle: the autopilot implementing VehicleInterface (None: telemetry only,
            commands answered MAV_RESULT_FAILED, empty mission and parameter list).
        rates: stream name -> Hz (simulation time), merged over DEFAULT_RATES; 0 = off.
        home: geodetic position of the winch (NED origin).
        sysid, compid: this vehicle's MAVLink system and component ids (1..255).
        log: a logging.Logger or a callable taking one string; default logger
            ``fdm_awe.mavlink``.
        rx_rate_hz: how often (simulation time) incoming data are drained.
        link_timeout_s: wall-clock time without any message from a ground station after
            which the link counts as lost.
        mission_timeout_s, mission_retries: mission-upload item timeout and re-requests.
        max_mission_items: largest mission accepted (MAV_MISSION_NO_SPACE above).
        max_range_m: largest horizontal distance of a waypoint from home.
        max_rx_per_poll: datagrams/reads handled per poll at most (bounds a poll's cost).
        param_burst: PARAM_VALUE messages sent per update while streaming the list.
        clock: wall clock for timeouts (monotonic seconds).
        signing_key: 32-byte MAVLink 2 signing key (:mod:`fdm_awe.mavlink.signing`), or
            None for no signing.
        signing_key_file: where a key set with SETUP_SIGNING is saved (None: kept in memory).
        signing_link_id: link id of the outgoing signatures, 0..255.

    Raises:
        InputError: bad URL, rate, id or option (one line naming it).
    """

    def __init__(self, url: str = "udpout:127.0.0.1:14550",
                 vehicle: VehicleInterface | None = None, *,
                 rates: dict[str, float] | None = None, home: Home | None = None,
                 sysid: int = 1, compid: int = mav.MAV_COMP_ID_AUTOPILOT1,
                 log: logging.Logger | Callable[[str], Any] | None = None,
                 rx_rate_hz: float = 100.0, link_timeout_s: float = 3.0,
                 mission_timeout_s: float = 1.5, mission_retries: int = 5,
                 max_mission_items: int = 2000, max_range_m: float = 20000.0,
                 max_rx_per_poll: int = 200, param_burst: int = 20,
                 clock: Callable[[], float] = time.monotonic,
                 signing_key: bytes | None = None, signing_key_file: Any = None,
                 signing_link_id: int = 0) -> None:
        for name, v in (("sysid", sysid), ("compid", compid)):
            if not isinstance(v, int) or not 1 <= v <= 255:
                raise InputError(f"MAVLink {name}: {v!r} outside [1, 255]")
        for name, v, lo in (("rx_rate_hz", rx_rate_hz, 1e-3), ("link_timeout_s", link_timeout_s, 1e-3),
                            ("mission_timeout_s", mission_timeout_s, 1e-3),
                            ("max_range_m", max_range_m, 1.0)):
            if not isinstance(v, (int, float)) or not math.isfinite(v) or v < lo:
                raise InputError(f"MAVLink {name}: {v!r} must be a finite number >= {lo:g}")
        for name, v in (("mission_retries", mission_retries), ("max_mission_items", max_mission_items),
                        ("max_rx_per_poll", max_rx_per_poll), ("param_burst", param_burst)):
            if not isinstance(v, int) or not 0 <= v <= 65535 or (v == 0 and name != "mission_retries"):
                raise InputError(f"MAVLink {name}: {v!r} outside [1, 65535]")
        self.url = url
        self.vehicle = vehicle
        self.sysid = sysid
        self.compid = compid
        self.geo = GeoFrame(home)
        self._log_target = log if log is not None else logging.getLogger("fdm_awe.mavlink")
        self.rx_period = 1.0 / rx_rate_hz
        self.link_timeout_s = float(link_timeout_s)
        self.mission_timeout_s = float(mission_timeout_s)
        self.mission_retries = mission_retries
        self.max_mission_items = max_mission_items
        self.max_range_m = float(max_range_m)
        self.max_rx_per_poll = max_rx_per_poll
        self.param_burst = param_burst
        self._clock = clock

        merged = dict(DEFAULT_RATES)
        for k, v in (rates or {}).items():
            if k not in DEFAULT_RATES:
                raise InputError(f"MAVLink rate {k!r}: unknown stream; allowed: {', '.join(DEFAULT_RATES)}")
            if not isinstance(v, (int, float)) or not math.isfinite(v) or not 0 <= v <= _MAX_RATE_HZ:
                raise InputError(f"MAVLink rate {k}: {v!r} Hz outside [0, {_MAX_RATE_HZ:g}]")
            merged[k] = float(v)
        self._streams = [_Stream(k, 1.0 / r if r > 0 else math.inf, 0.0, DEFAULT_RATES[k])
                         for k, r in merged.items()]
        self._stream_by_name = {s.name: s for s in self._streams}
        self._senders: dict[str, Callable[[Telemetry, float], None]] = {
            "HEARTBEAT": self._send_heartbeat, "ATTITUDE": self._send_attitude,
            "GLOBAL_POSITION_INT": self._send_global_position, "VFR_HUD": self._send_vfr_hud,
            "SYS_STATUS": self._send_sys_status, "BATTERY_STATUS": self._send_battery,
            "HOME_POSITION": self._send_home, "NAMED_VALUE_FLOAT": self._send_named_values,
        }
        for name, fn in _EXTRA_SENDERS.items():
            self._senders[name] = (lambda f: lambda tel, t: f(self, tel, t))(fn)

        try:
            self._conn = mavutil.mavlink_connection(url, source_system=sysid,
                                                    source_component=compid, autoreconnect=True)
        except Exception as e:  # noqa: BLE001 - pymavlink raises many types for bad URLs
            raise InputError(f"--mavlink {url!r}: cannot open ({type(e).__name__}: {e})") from None
        # Our own MAVLink 2 codec on pymavlink's transport: independent of mavutil's
        # process-wide dialect/protocol-version switch.
        self._mav = _signing.Codec(self._conn, srcSystem=sysid, srcComponent=compid)
        self._mav.robust_parsing = True
        #: the winch, its own component (MAV_COMP_ID_WINCH) on this connection
        self.winch = WinchComponent(self._conn, sysid)
        #: MAVLink 2 signing of both components (off without a key)
        self.signer = _signing.Signer([self._mav, self.winch.mav], signing_key, signing_link_id)
        self.signing_key_file = signing_key_file
        self._reporter = ChangeReporter()
        #: UDP (one message set per datagram, parsed on its own) or a byte stream (TCP, serial)
        self._datagrams = isinstance(self._conn, DATAGRAM_TRANSPORTS)

        # scheduling (simulation time)
        self._t_prev = -math.inf
        self._next_due = -math.inf
        self._next_rx = -math.inf
        self._t_now = 0.0
        self._tel_src: Telemetry | Callable[[], Telemetry] | None = None
        self._tel: Telemetry | None = None
        self._tel_t: float | None = None
        self._param_queue: list[int] = []
        self._param_target = (0, 0)
        # link (wall clock)
        self.link_up = False
        self._ever_linked = False
        self._last_rx_wall = -math.inf
        self.gcs: tuple[int, int] | None = None
        # mission transfers
        self._upload: _Upload | None = None
        self._download: list[tuple[int, int, float]] | None = None
        self._closed = False
        #: counters (messages sent per type, received, bad packets, failures, link losses)
        self.stats: dict[str, Any] = {"sent": {}, "received": 0, "bad_packets": 0,
                                      "handler_errors": 0, "send_errors": 0, "link_losses": 0,
                                      "polls": 0, "datagrams": 0, "bad_time": 0,
                                      "warnings_suppressed": 0,
                                      "signing": {"accepted": 0, "unsigned_rejected": 0,
                                                  "bad_signature_rejected": 0}}
        self._warned: dict[str, float] = {}
        self._handlers: dict[str, Callable[[Any], None]] = {
            "HEARTBEAT": lambda m: None,
            "COMMAND_LONG": self._on_command_long, "COMMAND_INT": self._on_command_int,
            "SET_MODE": self._on_set_mode,
            "PARAM_REQUEST_LIST": self._on_param_request_list,
            "PARAM_REQUEST_READ": self._on_param_request_read, "PARAM_SET": self._on_param_set,
            "MISSION_REQUEST_LIST": self._on_mission_request_list,
            "MISSION_REQUEST_INT": self._on_mission_request, "MISSION_REQUEST": self._on_mission_request,
            "MISSION_COUNT": self._on_mission_count, "MISSION_ITEM_INT": self._on_mission_item,
            "MISSION_ITEM": self._on_mission_item, "MISSION_ACK": self._on_mission_ack,
            "MISSION_CLEAR_ALL": self._on_mission_clear_all,
            "FILE_TRANSFER_PROTOCOL": self._on_ftp,
            "SETUP_SIGNING": lambda m: _signing.on_setup_signing(self, m),
        }
        self._info(f"MAVLink endpoint on {url} as system {sysid} component {compid} (winch component "
                   f"{WINCH_COMPID}); signing {'on' if self.signer.on else 'off'}")

    # ------------------------------------------------------------------ public API
    def update(self, t: float, telemetry: Telemetry | Callable[[], Telemetry]) -> None:
        """Advance the endpoint to simulation time ``t`` (s): send due streams, drain input.

        Call every simulation step. Never blocks, never raises. ``telemetry`` may be a
        zero-argument callable; it is called at most once per update, only when needed.
        """
        if self._t_prev <= t < self._next_due:   # the common case: nothing due
            self._t_prev = t
            return
        try:
            self._service(t, telemetry)
        except Exception as e:  # noqa: BLE001 - update() must never raise into the flight loop
            self.stats["handler_errors"] += 1
            self._warn(f"MAVLink update failed: {type(e).__name__}: {e}")
            self._next_due = t + min(self.rx_period, 1.0)

    def set_rate(self, stream: str, hz: float) -> None:
        """Set a stream's rate (Hz of simulation time, 0 = off); InputError if invalid."""
        if stream not in self._stream_by_name:
            raise InputError(f"MAVLink rate {stream!r}: unknown stream; allowed: {', '.join(DEFAULT_RATES)}")
        if not isinstance(hz, (int, float)) or not math.isfinite(hz) or not 0 <= hz <= _MAX_RATE_HZ:
            raise InputError(f"MAVLink rate {stream}: {hz!r} Hz outside [0, {_MAX_RATE_HZ:g}]")
        s = self._stream_by_name[stream]
        s.period = 1.0 / hz if hz > 0 else math.inf
        s.next_t = self._t_now if math.isfinite(self._t_now) else 0.0
        self._next_due = -math.inf

    def rates(self) -> dict[str, float]:
        """Current stream rates, Hz."""
        return {s.name: (0.0 if math.isinf(s.period) else 1.0 / s.period) for s in self._streams}

    def statustext(self, text: str, severity: int = mav.MAV_SEVERITY_INFO) -> None:
        """Send a STATUSTEXT to the ground station; a text over 50 characters goes out in
        chunks (:func:`fdm_awe.mavlink.statustext.chunks`)."""
        if self._closed:
            return
        for tid, seq, data in chunks(text):
            self._send("STATUSTEXT", self._mav.statustext_send, severity, data, tid, seq)

    def flight_ended(self, status: str, message: str) -> None:
        """Tell the ground station how the flight ended (STATUSTEXT ``flight STATUS: MESSAGE``;
        CRITICAL for a crash, a broken line or a limit, NOTICE for a completed flight or a
        landing, WARNING for an incomplete or interrupted one)."""
        self._reporter.vehicle(self, self.vehicle)
        self.statustext(f"flight {status}: {message}", END_SEVERITY.get(status, mav.MAV_SEVERITY_CRITICAL))

    def close(self) -> None:
        """Close the connection (idempotent)."""
        if not self._closed:
            self._closed = True
            try:
                self._conn.close()
            except Exception:  # noqa: BLE001
                pass

    def __enter__(self) -> "MavlinkEndpoint":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ------------------------------------------------------------------ scheduling
    def _service(self, t: float, telemetry: Telemetry | Callable[[], Telemetry]) -> None:
        if self._closed:
            self._next_due = math.inf
            return
        if not math.isfinite(t):
            self.stats["bad_time"] += 1
            return
        if t < self._t_prev:  # simulation restarted: restart the schedule
            for s in self._streams:
                s.next_t = t
            self._next_rx = t
        self._t_prev = t
        self._t_now = t
        self._tel_src = telemetry
        self._tel = None

        if t >= self._next_rx:
            self._next_rx = self._next_rx + self.rx_period if t - self._next_rx < self.rx_period else t + self.rx_period
            self._poll()
            self._reporter.vehicle(self, self.vehicle)

        for s in self._streams:
            if t >= s.next_t:
                s.next_t += s.period
                if s.next_t <= t:        # fell behind (or first call): no burst, restart phase
                    s.next_t = t + s.period
                tel = self._telemetry()
                try:
                    self._senders[s.name](tel, t)
                except Exception as e:  # noqa: BLE001 - bad telemetry must not stop the stream loop
                    self.stats["send_errors"] += 1
                    self._warn(f"MAVLink {s.name} not sent: {type(e).__name__}: {e}")

        if self._param_queue:
            self._send_param_burst()

        nd = self._next_rx
        for s in self._streams:
            if s.next_t < nd:
                nd = s.next_t
        if self._param_queue:
            nd = t  # keep streaming the parameter list on the next step
        self._next_due = nd
        self._tel_src = None

    def _telemetry(self) -> Telemetry:
        if self._tel is None:
            src = self._tel_src
            tel = src() if callable(src) else src
            self._tel = tel if isinstance(tel, Telemetry) else Telemetry(t=self._t_now)
            self._reporter.telemetry(self, self._tel)
        return self._tel

    # ------------------------------------------------------------------ receive
    def _poll(self) -> None:
        self.stats["polls"] += 1
        self.signer.tick()
        conn = self._conn
        parse = self._mav.parse_buffer
        datagrams = self._datagrams
        for _ in range(self.max_rx_per_poll):
            try:
                data = conn.recv(4096)
            except Exception:  # noqa: BLE001 - a transport error is not fatal; try next poll
                self.stats["bad_packets"] += 1
                break
            if not data:
                break
            self.stats["datagrams"] += 1
            if datagrams:  # one datagram, parsed on its own
                msgs, bad = parse_datagram(self._mav, data)
                self.stats["bad_packets"] += bad
            else:  # a byte stream: a message may span reads, the parser keeps its state
                try:
                    msgs = parse(data) or []
                except Exception:  # noqa: BLE001 - robust parsing should not raise; be safe anyway
                    self.stats["bad_packets"] += 1
                    reset_parser(self._mav)
                    continue
            for m in msgs:
                self._handle(m)
        now = self._clock()
        if self.link_up and now - self._last_rx_wall > self.link_timeout_s:
            self.link_up = False
            self.stats["link_losses"] += 1
            self._warn(f"MAVLink: ground-station link lost (no message for "
                       f"{now - self._last_rx_wall:.1f} s); flight continues", limit=False)
        if self._upload is not None:
            self._check_upload_timeout(now)

    def _handle(self, m: Any) -> None:
        mtype = m.get_type()
        if mtype == "BAD_DATA" or mtype.startswith("UNKNOWN"):
            refused = _signing.rejection(m)
            if refused is None:
                self.stats["bad_packets"] += 1
            else:
                self.stats["signing"][f"{refused}_rejected"] += 1
                self._warn(f"MAVLink: {refused.replace('_', ' ')} message ignored (signing on)")
            return
        if self.signer.on:
            self.stats["signing"]["accepted"] += 1
        src = (m.get_srcSystem(), m.get_srcComponent())
        if src == (self.sysid, self.compid):
            return  # our own packet echoed back (e.g. broadcast)
        self.stats["received"] += 1
        now = self._clock()
        self._last_rx_wall = now
        if not self.link_up:
            self.link_up = True
            self.gcs = src
            self._info(f"MAVLink: ground-station link {'regained' if self._ever_linked else 'up'} "
                       f"(system {src[0]} component {src[1]})")
            self._ever_linked = True
        h = self._handlers.get(mtype)
        if h is None:
            return
        try:
            h(m)
        except Exception as e:  # noqa: BLE001 - one bad message must not stop the loop
            self.stats["handler_errors"] += 1
            self._warn(f"MAVLink {mtype} from {src} not handled: {type(e).__name__}: {e}")

    def _for_me(self, m: Any) -> bool:
        ts = getattr(m, "target_system", 0)
        tc = getattr(m, "target_component", 0)
        return ts in (0, self.sysid) and tc in (0, self.compid)

    # ------------------------------------------------------------------ commands
    def _on_command_long(self, m: Any) -> None:
        p = (m.param1, m.param2, m.param3, m.param4, m.param5, m.param6, m.param7)
        if m.target_system == self.sysid and m.target_component == WINCH_COMPID:
            self.winch.on_command(self, m, p)
        elif self._for_me(m):
            self._run_command(m, p)

    def _on_command_int(self, m: Any) -> None:
        p = (m.param1, m.param2, m.param3, m.param4, float(m.x), float(m.y), m.z)
        if m.target_system == self.sysid and m.target_component == WINCH_COMPID:
            self.winch.on_command(self, m, p)
        elif self._for_me(m):
            self._run_command(m, p)

    def _run_command(self, m: Any, p: tuple[float, ...]) -> None:
        handler = self._commands.get(m.command)
        after: Callable[[], None] | None = None
        if handler is None:
            result = mav.MAV_RESULT_UNSUPPORTED
        else:
            try:
                result, after = handler(self, p)
            except Exception as e:  # noqa: BLE001 - a failing vehicle call is answered FAILED
                self.stats["handler_errors"] += 1
                self._warn(f"MAVLink command {m.command} failed: {type(e).__name__}: {e}")
                result, after = mav.MAV_RESULT_FAILED, None
        self._send("COMMAND_ACK", self._mav.command_ack_send, m.command, result, 0, 0,
                   m.get_srcSystem(), m.get_srcComponent())
        if after is not None and result == mav.MAV_RESULT_ACCEPTED:
            after()

    def _cmd_arm(self, p: tuple[float, ...]) -> tuple[int, Any]:
        if p[0] not in (0.0, 1.0):
            return mav.MAV_RESULT_DENIED, None
        if self.vehicle is None:
            return mav.MAV_RESULT_FAILED, None
        force = p[1] == ARM_DISARM_FORCE
        ok = bool(self.vehicle.arm(p[0] == 1.0, force=True) if force else self.vehicle.arm(p[0] == 1.0))
        self._info(f"MAVLink: {'arm' if p[0] == 1.0 else 'disarm'}{' (forced)' if force else ''} "
                   f"{'accepted' if ok else 'refused'}")
        return (mav.MAV_RESULT_ACCEPTED if ok else mav.MAV_RESULT_FAILED), None

    def _set_mode_number(self, number: Any) -> int:
        try:
            nf = float(number)
        except (TypeError, ValueError):
            return mav.MAV_RESULT_DENIED
        if not math.isfinite(nf) or nf != int(nf) or int(nf) not in MODE_NAMES:
            return mav.MAV_RESULT_DENIED
        name = MODE_NAMES[int(nf)]
        if self.vehicle is None:
            return mav.MAV_RESULT_FAILED
        if name not in self.vehicle.modes:
            return mav.MAV_RESULT_DENIED
        ok = bool(self.vehicle.set_mode(name))
        self._info(f"MAVLink: mode {name} {'accepted' if ok else 'refused'}")
        return mav.MAV_RESULT_ACCEPTED if ok else mav.MAV_RESULT_FAILED

    def _cmd_set_mode(self, p: tuple[float, ...]) -> tuple[int, Any]:
        base = _f(p[0], -1.0)
        if base < 0 or base != int(base) or not int(base) & mav.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED:
            return mav.MAV_RESULT_DENIED, None
        return self._set_mode_number(p[1]), None

    def _cmd_mission_start(self, p: tuple[float, ...]) -> tuple[int, Any]:
        if self.vehicle is None:
            return mav.MAV_RESULT_FAILED, None
        ok = bool(self.vehicle.start_cycling())
        self._info(f"MAVLink: start cycling {'accepted' if ok else 'refused'}")
        return (mav.MAV_RESULT_ACCEPTED if ok else mav.MAV_RESULT_FAILED), None

    def _cmd_pause_continue(self, p: tuple[float, ...]) -> tuple[int, Any]:
        if p[0] not in (0.0, 1.0):
            return mav.MAV_RESULT_DENIED, None
        if self.vehicle is None:
            return mav.MAV_RESULT_FAILED, None
        if p[0] == 1.0:
            return self._cmd_mission_start(p)
        ok = bool(self.vehicle.stop_cycling())
        self._info(f"MAVLink: stop cycling {'accepted' if ok else 'refused'}")
        return (mav.MAV_RESULT_ACCEPTED if ok else mav.MAV_RESULT_FAILED), None

    def _cmd_rtl(self, p: tuple[float, ...]) -> tuple[int, Any]:
        return self._set_mode_number(MODE_NUMBERS[RTL_MODE]), None

    def _cmd_get_home(self, p: tuple[float, ...]) -> tuple[int, Any]:
        return mav.MAV_RESULT_ACCEPTED, lambda: self._send_home(self._telemetry(), self._t_now)

    def _cmd_capabilities(self, p: tuple[float, ...]) -> tuple[int, Any]:
        return mav.MAV_RESULT_ACCEPTED, self._send_autopilot_version

    def _cmd_request_message(self, p: tuple[float, ...]) -> tuple[int, Any]:
        mid = _f(p[0], -1.0)
        if mid == mav.MAVLINK_MSG_ID_AUTOPILOT_VERSION:
            return mav.MAV_RESULT_ACCEPTED, self._send_autopilot_version
        name = _STREAM_BY_ID.get(int(mid)) if mid == int(mid) else None
        if name is None:
            return mav.MAV_RESULT_UNSUPPORTED, None
        return mav.MAV_RESULT_ACCEPTED, lambda: self._senders[name](self._telemetry(), self._t_now)

    def _cmd_set_interval(self, p: tuple[float, ...]) -> tuple[int, Any]:
        mid, us = _f(p[0], -1.0), _f(p[1], math.nan)
        name = _STREAM_BY_ID.get(int(mid)) if mid == int(mid) else None
        if name is None:
            return mav.MAV_RESULT_UNSUPPORTED, None
        if math.isnan(us) or us < -1:
            return mav.MAV_RESULT_DENIED, None
        s = self._stream_by_name[name]
        if us == -1:
            hz = 0.0
        elif us == 0:
            hz = s.default_rate
        else:
            hz = 1e6 / us
            if hz > _MAX_RATE_HZ:
                return mav.MAV_RESULT_DENIED, None
        self.set_rate(name, hz)
        self._info(f"MAVLink: {name} rate set to {hz:g} Hz")
        return mav.MAV_RESULT_ACCEPTED, None

    def _cmd_get_interval(self, p: tuple[float, ...]) -> tuple[int, Any]:
        mid = _f(p[0], -1.0)
        name = _STREAM_BY_ID.get(int(mid)) if mid == int(mid) else None
        if name is None:
            return mav.MAV_RESULT_UNSUPPORTED, None
        period = self._stream_by_name[name].period
        us = -1 if math.isinf(period) else int(round(period * 1e6))
        return mav.MAV_RESULT_ACCEPTED, lambda: self._send(
            "MESSAGE_INTERVAL", self._mav.message_interval_send, int(mid), us)

    _commands: dict[int, Callable[["MavlinkEndpoint", tuple[float, ...]], tuple[int, Any]]] = {
        mav.MAV_CMD_COMPONENT_ARM_DISARM: _cmd_arm,
        mav.MAV_CMD_DO_SET_MODE: _cmd_set_mode,
        mav.MAV_CMD_MISSION_START: _cmd_mission_start,
        mav.MAV_CMD_DO_PAUSE_CONTINUE: _cmd_pause_continue,
        mav.MAV_CMD_NAV_RETURN_TO_LAUNCH: _cmd_rtl,
        mav.MAV_CMD_GET_HOME_POSITION: _cmd_get_home,
        mav.MAV_CMD_REQUEST_MESSAGE: _cmd_request_message,
        mav.MAV_CMD_SET_MESSAGE_INTERVAL: _cmd_set_interval,
        mav.MAV_CMD_GET_MESSAGE_INTERVAL: _cmd_get_interval,
        mav.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES: _cmd_capabilities,
    }

    def _on_set_mode(self, m: Any) -> None:
        if m.target_system != self.sysid:
            return
        if m.base_mode & mav.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED:
            result = self._set_mode_number(m.custom_mode)
        else:
            result = mav.MAV_RESULT_DENIED
        self._send("COMMAND_ACK", self._mav.command_ack_send, mav.MAVLINK_MSG_ID_SET_MODE, result,
                   0, 0, m.get_srcSystem(), m.get_srcComponent())

    # ------------------------------------------------------------------ parameters
    def _params(self):
        return None if self.vehicle is None else self.vehicle.params

    def _on_param_request_list(self, m: Any) -> None:
        if not self._for_me(m):
            return
        ps = self._params()
        if ps is None:
            return
        self._param_queue = list(range(len(ps)))
        self._param_target = (m.get_srcSystem(), m.get_srcComponent())
        self._next_due = -math.inf

    def _send_param_burst(self) -> None:
        ps = self._params()
        q = self._param_queue
        n = min(self.param_burst, len(q))
        for i in q[:n]:
            self._send_param(ps, i)
        del q[:n]

    def _send_param(self, ps: Any, index: int) -> None:
        name = ps.name_at(index)
        if name is None:
            return
        self._send("PARAM_VALUE", self._mav.param_value_send, name.encode("ascii"), float(ps[name]),
                   mav.MAV_PARAM_TYPE_REAL32, len(ps), index)

    @staticmethod
    def _param_id(raw: Any) -> str:
        if isinstance(raw, (bytes, bytearray)):
            raw = raw.decode("ascii", "replace")
        return str(raw).split("\x00", 1)[0]

    def _on_param_request_read(self, m: Any) -> None:
        if not self._for_me(m):
            return
        ps = self._params()
        if ps is None:
            return
        if m.param_index >= 0:
            if ps.name_at(m.param_index) is not None:
                self._send_param(ps, m.param_index)
            return
        name = self._param_id(m.param_id)
        if name in ps:
            self._send_param(ps, ps.index(name))

    def _on_param_set(self, m: Any) -> None:
        if not self._for_me(m):
            return
        ps = self._params()
        name = self._param_id(m.param_id)
        if ps is None or name not in ps:
            self.statustext(f"unknown parameter {name[:24]}", mav.MAV_SEVERITY_WARNING)
            return
        ok, why = ps.try_set(name, from_wire(m.param_value))   # the value as typed, not float32's
        if ok:
            self._info(f"MAVLink: parameter {name} = {param_text(ps[name])}"
                       + ("" if why == "ok" else f" ({why})"))
            if why != "ok":
                self.statustext(why, mav.MAV_SEVERITY_WARNING)
        else:
            self._warn(f"MAVLink: PARAM_SET refused: {why}")
            self.statustext(why, mav.MAV_SEVERITY_WARNING)
        self._send_param(ps, ps.index(name))

    # ------------------------------------------------------------------ missions
    def _mission_ack(self, dest: tuple[int, int], result: int, mission_type: int) -> None:
        self._send("MISSION_ACK", self._mav.mission_ack_send, dest[0], dest[1], result, mission_type)

    def _on_mission_request_list(self, m: Any) -> None:
        if not self._for_me(m):
            return
        mt = getattr(m, "mission_type", 0)
        src = (m.get_srcSystem(), m.get_srcComponent())
        if mt == mav.MAV_MISSION_TYPE_MISSION:
            self._download = self._mission_snapshot()
            n = len(self._download)
        elif mt in (mav.MAV_MISSION_TYPE_FENCE, mav.MAV_MISSION_TYPE_RALLY):
            n = 0
        else:
            self._mission_ack(src, mav.MAV_MISSION_UNSUPPORTED, mt)
            return
        self._send("MISSION_COUNT", self._mav.mission_count_send, src[0], src[1], n, mt)

    def _mission_snapshot(self) -> list[tuple[int, int, float]]:
        if self.vehicle is None:
            return []
        out = []
        for wp in self.vehicle.mission():
            lat, lon, _alt = self.geo.to_geodetic(wp.north, wp.east, wp.down)
            out.append((int(round(lat * 1e7)), int(round(lon * 1e7)), float(-wp.down)))
        return out

    def _on_mission_request(self, m: Any) -> None:
        if not self._for_me(m):
            return
        mt = getattr(m, "mission_type", 0)
        src = (m.get_srcSystem(), m.get_srcComponent())
        if mt != mav.MAV_MISSION_TYPE_MISSION:
            self._mission_ack(src, mav.MAV_MISSION_INVALID_SEQUENCE, mt)
            return
        if self._download is None:
            self._download = self._mission_snapshot()
        items = self._download
        if not 0 <= m.seq < len(items):
            self._mission_ack(src, mav.MAV_MISSION_INVALID_SEQUENCE, mt)
            return
        x, y, z = items[m.seq]
        if m.get_type() == "MISSION_REQUEST_INT":
            self._send("MISSION_ITEM_INT", self._mav.mission_item_int_send, src[0], src[1], m.seq,
                       mav.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, mav.MAV_CMD_NAV_WAYPOINT, 0, 1,
                       0.0, 0.0, 0.0, 0.0, x, y, z, mt)
        else:
            self._send("MISSION_ITEM", self._mav.mission_item_send, src[0], src[1], m.seq,
                       mav.MAV_FRAME_GLOBAL_RELATIVE_ALT, mav.MAV_CMD_NAV_WAYPOINT, 0, 1,
                       0.0, 0.0, 0.0, 0.0, x * 1e-7, y * 1e-7, z, mt)

    def _on_mission_ack(self, m: Any) -> None:
        if not self._for_me(m):
            return
        if getattr(m, "mission_type", 0) != mav.MAV_MISSION_TYPE_MISSION:
            return
        self._download = None   # download finished (or cancelled by the ground station)
        up = self._upload
        if up is not None and up.gcs == (m.get_srcSystem(), m.get_srcComponent()):
            self._upload = None
            self._warn("MAVLink: mission upload cancelled by the ground station")

    def _on_mission_clear_all(self, m: Any) -> None:
        if not self._for_me(m):
            return
        mt = getattr(m, "mission_type", 0)
        src = (m.get_srcSystem(), m.get_srcComponent())
        if mt in (mav.MAV_MISSION_TYPE_MISSION, mav.MAV_MISSION_TYPE_ALL):
            if self.vehicle is None:
                self._mission_ack(src, mav.MAV_MISSION_ERROR, mt)
                return
            self.vehicle.clear_mission()
            self._download = None
            self._info("MAVLink: mission cleared")
        elif mt not in (mav.MAV_MISSION_TYPE_FENCE, mav.MAV_MISSION_TYPE_RALLY):
            self._mission_ack(src, mav.MAV_MISSION_UNSUPPORTED, mt)
            return
        self._mission_ack(src, mav.MAV_MISSION_ACCEPTED, mt)

    def _on_mission_count(self, m: Any) -> None:
        if not self._for_me(m):
            return
        mt = getattr(m, "mission_type", 0)
        src = (m.get_srcSystem(), m.get_srcComponent())
        if mt != mav.MAV_MISSION_TYPE_MISSION:
            ok = m.count == 0 and mt in (mav.MAV_MISSION_TYPE_FENCE, mav.MAV_MISSION_TYPE_RALLY)
            self._mission_ack(src, mav.MAV_MISSION_ACCEPTED if ok else mav.MAV_MISSION_UNSUPPORTED, mt)
            return
        if self.vehicle is None:
            self._mission_ack(src, mav.MAV_MISSION_ERROR, mt)
            return
        if m.count > self.max_mission_items:
            self._upload = None
            self._warn(f"MAVLink: mission of {m.count} items refused (max {self.max_mission_items})")
            self._mission_ack(src, mav.MAV_MISSION_NO_SPACE, mt)
            return
        if m.count == 0:
            self._upload = None
            self.vehicle.clear_mission()
            self._info("MAVLink: empty mission uploaded; mission cleared")
            self._mission_ack(src, mav.MAV_MISSION_ACCEPTED, mt)
            return
        self._upload = _Upload(src, m.count, self._clock())
        self._send("MISSION_REQUEST_INT", self._mav.mission_request_int_send, src[0], src[1], 0, mt)

    def _check_upload_timeout(self, now: float) -> None:
        up = self._upload
        if up is None or now - up.last_req < self.mission_timeout_s:
            return
        if up.retries >= self.mission_retries:
            self._upload = None
            self._warn(f"MAVLink: mission upload timed out waiting for item {up.expected}")
            self._mission_ack(up.gcs, mav.MAV_MISSION_OPERATION_CANCELLED, mav.MAV_MISSION_TYPE_MISSION)
            return
        up.retries += 1
        up.last_req = now
        self._send("MISSION_REQUEST_INT", self._mav.mission_request_int_send, up.gcs[0], up.gcs[1],
                   up.expected, mav.MAV_MISSION_TYPE_MISSION)

    def _item_to_waypoint(self, m: Any) -> tuple[int, Waypoint | None]:
        """Validate one uploaded item -> (MAV_MISSION_RESULT, waypoint or None)."""
        if m.command != mav.MAV_CMD_NAV_WAYPOINT:
            return mav.MAV_MISSION_UNSUPPORTED, None
        if m.frame in _GLOBAL_FRAMES_REL:
            relative = True
        elif m.frame in _GLOBAL_FRAMES_AMSL:
            relative = False
        else:
            return mav.MAV_MISSION_UNSUPPORTED_FRAME, None
        scale = 1e-7 if m.get_type() == "MISSION_ITEM_INT" else 1.0
        lat, lon, z = float(m.x) * scale, float(m.y) * scale, float(m.z)
        if not (math.isfinite(lat) and -90.0 <= lat <= 90.0):
            return mav.MAV_MISSION_INVALID_PARAM5_X, None
        if not (math.isfinite(lon) and -180.0 <= lon <= 180.0):
            return mav.MAV_MISSION_INVALID_PARAM6_Y, None
        if not (math.isfinite(z) and -1000.0 <= z <= 20000.0):
            return mav.MAV_MISSION_INVALID_PARAM7, None
        alt = self.geo.home.alt_m + z if relative else z
        n, e, d = self.geo.to_ned(lat, lon, alt)
        if abs(n) > self.max_range_m:
            return mav.MAV_MISSION_INVALID_PARAM5_X, None
        if abs(e) > self.max_range_m:
            return mav.MAV_MISSION_INVALID_PARAM6_Y, None
        return mav.MAV_MISSION_ACCEPTED, Waypoint(n, e, d)

    def _on_mission_item(self, m: Any) -> None:
        if not self._for_me(m):
            return
        up = self._upload
        src = (m.get_srcSystem(), m.get_srcComponent())
        if up is None or src != up.gcs or getattr(m, "mission_type", 0) != mav.MAV_MISSION_TYPE_MISSION:
            return  # not part of an upload we run: ignore
        if m.seq != up.expected:
            if m.seq > up.expected:  # we missed one: ask again for the one we need
                up.last_req = self._clock()
                self._send("MISSION_REQUEST_INT", self._mav.mission_request_int_send, src[0], src[1],
                           up.expected, mav.MAV_MISSION_TYPE_MISSION)
            return
        result, wp = self._item_to_waypoint(m)
        if wp is None:
            self._upload = None
            self._warn(f"MAVLink: mission item {m.seq} rejected (MAV_MISSION_RESULT {result})")
            self._mission_ack(src, result, mav.MAV_MISSION_TYPE_MISSION)
            return
        up.items.append(wp)
        up.expected += 1
        up.retries = 0
        up.last_req = self._clock()
        if up.expected < up.count:
            self._send("MISSION_REQUEST_INT", self._mav.mission_request_int_send, src[0], src[1],
                       up.expected, mav.MAV_MISSION_TYPE_MISSION)
            return
        self._upload = None
        ok, why = self.vehicle.set_mission(list(up.items))
        if ok:
            self._download = None
            self._info(f"MAVLink: mission of {len(up.items)} waypoints accepted")
            self._mission_ack(src, mav.MAV_MISSION_ACCEPTED, mav.MAV_MISSION_TYPE_MISSION)
        else:
            self._warn(f"MAVLink: mission refused by the vehicle: {why}")
            self.statustext(f"mission refused: {why}", mav.MAV_SEVERITY_WARNING)
            self._mission_ack(src, mav.MAV_MISSION_INVALID, mav.MAV_MISSION_TYPE_MISSION)

    # ------------------------------------------------------------------ MAVFTP
    def _on_ftp(self, m: Any) -> None:
        if not self._for_me(m):
            return
        req = bytes(bytearray(m.payload[:12]).ljust(12, b"\x00"))
        seq = req[0] | (req[1] << 8)
        session, opcode = req[2], req[3]
        payload = [0] * 251
        rseq = (seq + 1) & 0xFFFF
        payload[0], payload[1] = rseq & 0xFF, rseq >> 8
        payload[2] = session
        payload[3] = _FTP_NAK
        payload[4] = 1           # size of data
        payload[5] = opcode      # req_opcode
        payload[12] = _FTP_ERR_UNKNOWN_COMMAND
        self._send("FILE_TRANSFER_PROTOCOL", self._mav.file_transfer_protocol_send, 0,
                   m.get_srcSystem(), m.get_srcComponent(), payload)

    # ------------------------------------------------------------------ streams
    def _send(self, name: str, fn: Callable[..., None], *args: Any) -> None:
        try:
            fn(*args)
        except Exception as e:  # noqa: BLE001 - a send problem is counted, never raised
            self.stats["send_errors"] += 1
            self._warn(f"MAVLink {name} not sent: {type(e).__name__}: {e}")
            return
        sent = self.stats["sent"]
        sent[name] = sent.get(name, 0) + 1

    def _vehicle_state(self, tel: Telemetry) -> tuple[str, bool]:
        v = self.vehicle
        if v is not None:
            try:
                return str(v.mode), bool(v.armed)
            except Exception:  # noqa: BLE001
                pass
        return str(tel.mode), bool(tel.armed)

    def _send_heartbeat(self, tel: Telemetry, t: float) -> None:
        mode, armed = self._vehicle_state(tel)
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
        self._send("HEARTBEAT", self._mav.heartbeat_send, mav.MAV_TYPE_FIXED_WING,
                   mav.MAV_AUTOPILOT_GENERIC, base, custom, status)
        self.winch.send_heartbeat(self, tel)

    @staticmethod
    def _ms(t: float) -> int:
        return _clamp_int(t * 1000.0, 0, 0xFFFFFFFF, 0)

    def _send_attitude(self, tel: Telemetry, t: float) -> None:
        phi, theta, psi = _vec3(tel.euler)
        p, q, r = _vec3(tel.omega_body)
        self._send("ATTITUDE", self._mav.attitude_send, self._ms(t), phi, theta, psi, p, q, r)

    def _send_global_position(self, tel: Telemetry, t: float) -> None:
        n, e, d = _vec3(tel.pos_ned)
        vn, ve, vd = _vec3(tel.vel_ned)
        lat, lon, alt = self.geo.to_geodetic(n, e, d)
        hdg = math.degrees(_f(_vec3(tel.euler)[2])) % 360.0
        i32 = (-2**31, 2**31 - 1)
        self._send("GLOBAL_POSITION_INT", self._mav.global_position_int_send, self._ms(t),
                   _clamp_int(lat * 1e7, -900000000, 900000000, 0),
                   _clamp_int(lon * 1e7, -1800000000, 1800000000, 0),
                   _clamp_int(alt * 1000.0, *i32, 0), _clamp_int(-d * 1000.0, *i32, 0),
                   _clamp_int(vn * 100.0, -32768, 32767, 0), _clamp_int(ve * 100.0, -32768, 32767, 0),
                   _clamp_int(vd * 100.0, -32768, 32767, 0), _clamp_int(hdg * 100.0, 0, 35999, 65535))

    def _send_vfr_hud(self, tel: Telemetry, t: float) -> None:
        n, e, d = _vec3(tel.pos_ned)
        vn, ve, vd = _vec3(tel.vel_ned)
        hdg = _clamp_int(math.degrees(_vec3(tel.euler)[2]) % 360.0, 0, 359, 0)
        self._send("VFR_HUD", self._mav.vfr_hud_send, _f(tel.airspeed), math.hypot(vn, ve), hdg,
                   _clamp_int(_f(tel.throttle) * 100.0, 0, 100, 0), self.geo.home.alt_m - d, -vd)

    def _send_sys_status(self, tel: Telemetry, t: float) -> None:
        health = _SENSORS if tel.health_ok else _SENSORS & ~mav.MAV_SYS_STATUS_AHRS
        lost = self._ever_linked and not self.link_up
        st = self.stats
        self._send("SYS_STATUS", self._mav.sys_status_send, _SENSORS, _SENSORS, health, 0,
                   _clamp_int(_f(tel.battery_voltage_V, -1) * 1000.0, 0, 65534, 65535),
                   _clamp_int(_f(tel.battery_current_A, -0.01) * 100.0, -1, 32767, -1),
                   self._remaining_pct(tel), 10000 if lost else 0,
                   min(st["bad_packets"], 65535), min(st["link_losses"], 65535),
                   min(st["handler_errors"], 65535), min(self._signing_rejected(), 65535), 0)

    def _signing_rejected(self) -> int:
        sg = self.stats["signing"]
        return sg["unsigned_rejected"] + sg["bad_signature_rejected"]

    @staticmethod
    def _remaining_pct(tel: Telemetry) -> int:
        r = _f(tel.battery_remaining, -1.0)
        return -1 if r < 0 else _clamp_int(r * 100.0, 0, 100, -1)

    def _send_battery(self, tel: Telemetry, t: float) -> None:
        volts = [65535] * 10
        volts[0] = _clamp_int(_f(tel.battery_voltage_V, -1) * 1000.0, 0, 65534, 65535)
        self._send("BATTERY_STATUS", self._mav.battery_status_send, 0, mav.MAV_BATTERY_FUNCTION_ALL,
                   mav.MAV_BATTERY_TYPE_LIPO, 32767, volts,
                   _clamp_int(_f(tel.battery_current_A, -0.01) * 100.0, -1, 32767, -1), -1, -1,
                   self._remaining_pct(tel))

    def _send_home(self, tel: Telemetry, t: float) -> None:
        h = self.geo.home
        self._send("HOME_POSITION", self._mav.home_position_send, int(round(h.lat_deg * 1e7)),
                   int(round(h.lon_deg * 1e7)), int(round(h.alt_m * 1000.0)), 0.0, 0.0, 0.0,
                   [1.0, 0.0, 0.0, 0.0], 0.0, 0.0, 0.0, _clamp_int(t * 1e6, 0, 2**63 - 1, 0))

    def _send_named_values(self, tel: Telemetry, t: float) -> None:
        ms = self._ms(t)
        for name, value in ((b"tension", tel.tension_N), (b"reel_spd", tel.reel_speed_mps),
                            (b"winch_pwr", tel.winch_power_W), (b"net_energy", tel.net_energy_J),
                            (b"phase", PHASE_CODES.get(tel.phase, -1.0)), (b"fold", tel.fold)):
            self._send("NAMED_VALUE_FLOAT", self._mav.named_value_float_send, ms, name,
                       _f(value, math.nan))

    def _send_autopilot_version(self) -> None:
        from fdm_awe import __version__
        parts = [int(x) if x.isdigit() else 0 for x in __version__.split(".")[:3]] + [0, 0, 0]
        sw = (parts[0] << 24) | (parts[1] << 16) | (parts[2] << 8) | 255   # 255 = FIRMWARE_VERSION_TYPE_OFFICIAL
        self._send("AUTOPILOT_VERSION", self._mav.autopilot_version_send, _CAPABILITIES, sw, 0, 0, 0,
                   [0] * 8, [0] * 8, [0] * 8, 0, 0, 0)

    # ------------------------------------------------------------------ logging
    def _info(self, msg: str) -> None:
        lt = self._log_target
        if isinstance(lt, logging.Logger):
            lt.info(msg)
        else:
            lt(msg)

    def _warn(self, msg: str, limit: bool = True) -> None:
        # the same warning at most once per 5 s of wall time (garbage can repeat it fast)
        key = msg[:40]
        now = self._clock()
        last = self._warned.get(key)
        if limit and last is not None and now - last < 5.0:
            self.stats["warnings_suppressed"] += 1
            return
        if len(self._warned) > 256:
            self._warned.clear()
        self._warned[key] = now
        lt = self._log_target
        if isinstance(lt, logging.Logger):
            lt.warning(msg)
        else:
            lt(msg)
