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
time), at most ``max_rx_per_poll`` datagrams or stream reads per poll, each peer within its
share (:mod:`~fdm_awe.mavlink.transport`); link and mission-transfer timeouts use the wall
clock, because ground stations run on it. The link counts as lost
after ``link_timeout_s`` without a message from a ground station (``link_up``; SYS_STATUS
reports it): another system than this vehicle's, and with signing on a message with a valid
signature (:meth:`MavlinkEndpoint.from_ground_station`).

This module is the link: the transport, the update loop, the receive loop that hands each
message to its handler, sending (every send is counted in ``stats["sent"]``, a failing one
in ``stats["send_errors"]``, never raised) and logging. Each protocol is its own module:

- :mod:`~fdm_awe.mavlink.streams`: stream rates and their schedule (:data:`DEFAULT_RATES`);
  :mod:`~fdm_awe.mavlink.messages`: what each streamed message says;
- :mod:`~fdm_awe.mavlink.commands`: COMMAND_LONG, COMMAND_INT, SET_MODE (table of commands);
- :mod:`~fdm_awe.mavlink.mission`: mission download and upload;
- :mod:`~fdm_awe.mavlink.param_protocol`: PARAM_REQUEST_LIST/READ, PARAM_SET;
- :mod:`~fdm_awe.mavlink.pilot`: RC_CHANNELS_OVERRIDE and MANUAL_CONTROL, the pilot's sticks;
- REQUEST_DATA_STREAM: ArduPlane's stream groups at the asked rates
  (:func:`~fdm_awe.mavlink.streams.data_stream_rates`);
- :mod:`~fdm_awe.mavlink.boot`: the heartbeat sent while the flight loads, before this endpoint
  runs;
- :mod:`~fdm_awe.mavlink.ftp`: MAVFTP, answered with a NAK so ground stations fall back to
  the parameter protocol at once;
- :mod:`~fdm_awe.mavlink.transport`: the connection (``tcpin:`` serves several ground
  stations), read fairly: a flooding peer cannot starve the others;
- :mod:`~fdm_awe.mavlink.framing`: UDP datagrams parsed one by one, byte streams as streams,
  both resynchronising on the next frame after a bad one;
- :mod:`~fdm_awe.mavlink.winch`: the winch, its own component (id 169) on this connection;
- :mod:`~fdm_awe.mavlink.statustext`: STATUSTEXT of mode, arm, cycling, phase and winch
  changes and of the flight's end (:meth:`MavlinkEndpoint.flight_ended`; afterwards
  ``flight_over``: the vehicle still answers, the commands that would fly are refused with their
  reason, and a ground station's shutdown sets ``shutdown_requested``);
- :mod:`~fdm_awe.mavlink.signing`: MAVLink 2 signing (``signing_key``); messages refused by
  it are counted in ``stats["signing"]`` and SYS_STATUS ``errors_count3``.

Composition, not mixins: the endpoint holds one object per protocol (``StreamSchedule``,
``CommandHandler``, ``MissionProtocol``, ``ParamProtocol``), each owning its own state (the
schedule, the mission transfers, the parameter queue) and reaching the link only through
the endpoint it was given, as a :class:`~fdm_awe.mavlink.link.Link` (send, log, vehicle,
configuration: the members the protocol modules use, typed). Mixins would put all of that
state back on one object with one namespace of ~60 methods, the same class only spread over
files. The per-step fast path stays on the endpoint itself: ``update`` compares the time
with two of its own attributes and returns, so splitting costs nothing when nothing is due.
"""

from __future__ import annotations

import logging
import math
import time
from typing import Any, Callable

from fdm_awe.errors import InputError
from fdm_awe.mavlink.geo import GeoFrame, Home
from fdm_awe.mavlink.vehicle import Telemetry
from fdm_awe.autopilot.vehicle import VehicleInterface

# Imported at module level on purpose: importing this module is the opt-in to MAVLink.
from pymavlink.dialects.v20 import common as mav  # noqa: E402

from fdm_awe.mavlink import signing as _signing  # noqa: E402
from fdm_awe.mavlink.commands import CommandHandler  # noqa: E402
from fdm_awe.mavlink.ftp import on_ftp  # noqa: E402
from fdm_awe.mavlink.mission import MissionProtocol  # noqa: E402
from fdm_awe.mavlink.param_protocol import ParamProtocol  # noqa: E402
from fdm_awe.mavlink.pilot import PilotInput  # noqa: E402
from fdm_awe.mavlink.statustext import END_SEVERITY, ChangeReporter, chunks  # noqa: E402
from fdm_awe.mavlink.streams import StreamSchedule, data_stream_rates  # noqa: E402
from fdm_awe.mavlink.transport import Receiver, open_link  # noqa: E402
from fdm_awe.mavlink.winch import WINCH_COMPID, WinchComponent  # noqa: E402

__all__ = ["MavlinkEndpoint"]


def _check_options(sysid: int, compid: int, rx_rate_hz: float, link_timeout_s: float,
                   mission_timeout_s: float, max_range_m: float, mission_retries: int,
                   max_mission_items: int, max_rx_per_poll: int, param_burst: int) -> None:
    """InputError (one line naming the option) for an id, time, distance or count out of range."""
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


def _new_stats() -> dict[str, Any]:
    """The endpoint's counters, all zero."""
    return {"sent": {}, "received": 0, "bad_packets": 0, "handler_errors": 0, "send_errors": 0,
            "link_losses": 0, "polls": 0, "datagrams": 0, "rx_dropped": 0, "bad_time": 0, "warnings_suppressed": 0,
            "signing": {"accepted": 0, "unsigned_accepted": 0, "unsigned_rejected": 0,
                        "bad_signature_rejected": 0}}


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
        link_timeout_s: wall-clock time without any message from a ground station
            (:meth:`from_ground_station`) after which the link counts as lost.
        mission_timeout_s, mission_retries: mission-upload item timeout and re-requests.
        max_mission_items: largest mission accepted (MAV_MISSION_NO_SPACE above).
        max_range_m: largest horizontal distance of a waypoint from home.
        max_rx_per_poll: datagrams/reads handled per poll at most (bounds a poll's cost); one
            peer gets a quarter of them, what it sends beyond that in a poll is not parsed.
        param_burst: PARAM_VALUE messages sent per update while streaming the list.
        clock: wall clock for timeouts (monotonic seconds).
        signing_key: 32-byte MAVLink 2 signing key (:mod:`fdm_awe.mavlink.signing`), or
            None for no signing.
        signing_key_file: where a key set with SETUP_SIGNING is saved (None: kept in memory).
        signing_link_id: link id of the outgoing signatures, 0..255.
        connection: the transport of ``url`` already opened by
            :func:`fdm_awe.mavlink.transport.open_link` (None: opened here); closed by
            :meth:`close`.

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
                 signing_link_id: int = 0, connection: Any = None) -> None:
        _check_options(sysid, compid, rx_rate_hz, link_timeout_s, mission_timeout_s, max_range_m,
                       mission_retries, max_mission_items, max_rx_per_poll, param_burst)
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
        self.clock = clock  #: the wall clock of the timeouts (monotonic seconds)
        self.streams = StreamSchedule(rates)  #: the telemetry streams' rates and schedule
        self._open(url, signing_key, signing_link_id, connection)
        self.signing_key_file = signing_key_file
        self._reporter = ChangeReporter()

        # scheduling (simulation time)
        self._t_prev = -math.inf
        self._next_due = -math.inf
        self._next_rx = -math.inf
        self.t_now = 0.0  #: simulation time of the last update [s]
        self._tel_src: Telemetry | Callable[[], Telemetry] | None = None
        self._tel: Telemetry | None = None
        # link (wall clock)
        self.link_up = False
        self._ever_linked = False
        self._last_rx_wall = -math.inf
        self.gcs: tuple[int, int] | None = None
        self._closed = False
        #: counters (messages sent per type, received, bad packets, failures, link losses)
        self.stats: dict[str, Any] = _new_stats()
        self._warned: dict[str, float] = {}
        self._commands = CommandHandler(self)
        self._params = ParamProtocol(self)
        self._mission = MissionProtocol(self)
        self._pilot = PilotInput(self)
        #: the flight is over (:meth:`flight_ended`): the vehicle still answers, the commands that
        #: would fly are refused with their reason
        self.flight_over = False
        #: a ground station asked for the shutdown (MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN 2) after the flight
        self.shutdown_requested = False
        self._handlers = self._handler_table()
        self.info(f"MAVLink endpoint on {url} as system {sysid} component {self.compid} (winch component "
                   f"{WINCH_COMPID}); signing {'on' if self.signer.on else 'off'}")

    def _open(self, url: str, signing_key: bytes | None, signing_link_id: int, connection: Any = None) -> None:
        """Open the connection (or take ``connection``, opened by :func:`.transport.open_link`),
        this vehicle's codec, the winch component and the signer."""
        self._conn = connection if connection is not None else open_link(url, self.sysid, self.compid, log=self.info)
        # Our own MAVLink 2 codec on pymavlink's transport: independent of mavutil's
        # process-wide dialect/protocol-version switch.
        #: the vehicle's MAVLink encoder (signed once a key is set); the protocol modules send through
        #: :meth:`send` with its ``*_send`` methods
        self.mav = _signing.Codec(self._conn, srcSystem=self.sysid, srcComponent=self.compid)
        self.mav.robust_parsing = True
        #: the winch, its own component (MAV_COMP_ID_WINCH) on this connection
        self.winch = WinchComponent(self._conn, self.sysid)
        #: MAVLink 2 signing of both components (off without a key)
        self.signer = _signing.Signer([self.mav, self.winch.mav], signing_key, signing_link_id)
        #: reads the connection poll by poll, each peer within its share
        self._rx = Receiver(self._conn, self.mav, self.max_rx_per_poll)

    def _handler_table(self) -> dict[str, Callable[[Any], None]]:
        """Incoming message type -> handler (other types only keep the link up)."""
        cmd, par, mis = self._commands, self._params, self._mission
        return {
            "HEARTBEAT": lambda m: None,
            "COMMAND_LONG": cmd.on_command_long, "COMMAND_INT": cmd.on_command_int,
            "SET_MODE": cmd.on_set_mode,
            "PARAM_REQUEST_LIST": par.on_request_list,
            "PARAM_REQUEST_READ": par.on_request_read, "PARAM_SET": par.on_set,
            "MISSION_REQUEST_LIST": mis.on_request_list,
            "MISSION_REQUEST_INT": mis.on_request, "MISSION_REQUEST": mis.on_request,
            "MISSION_COUNT": mis.on_count, "MISSION_ITEM_INT": mis.on_item,
            "MISSION_ITEM": mis.on_item, "MISSION_ACK": mis.on_ack,
            "MISSION_CLEAR_ALL": mis.on_clear_all,
            "FILE_TRANSFER_PROTOCOL": lambda m: on_ftp(self, m),
            "RC_CHANNELS_OVERRIDE": self._pilot.on_rc_override,
            "MANUAL_CONTROL": self._pilot.on_manual_control,
            "REQUEST_DATA_STREAM": self._on_request_data_stream,
            "SETUP_SIGNING": lambda m: _signing.on_setup_signing(self, m),
        }

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
            self.warn(f"MAVLink update failed: {type(e).__name__}: {e}")
            self._next_due = t + min(self.rx_period, 1.0)

    def set_rate(self, stream: str, hz: float) -> None:
        """Set a stream's rate (Hz of simulation time, 0 = off); InputError if invalid."""
        self.streams.set_rate(stream, hz, self.t_now if math.isfinite(self.t_now) else 0.0)
        self.wake()

    def rates(self) -> dict[str, float]:
        """Current stream rates, Hz."""
        return self.streams.rates()

    def _on_request_data_stream(self, m: Any) -> None:
        """REQUEST_DATA_STREAM: the group's streams at the requested rate, or off
        (:func:`~fdm_awe.mavlink.streams.data_stream_rates`)."""
        if not self.for_me(m):
            return
        rates = data_stream_rates(m.req_stream_id, m.req_message_rate, bool(m.start_stop) and m.req_message_rate > 0)
        for name, hz in rates.items():
            self.set_rate(name, hz)
        if rates:
            self.info(f"MAVLink: data stream {m.req_stream_id} at {m.req_message_rate if m.start_stop else 0} Hz "
                      f"({', '.join(rates)})")

    def statustext(self, text: str, severity: int = mav.MAV_SEVERITY_INFO) -> None:
        """Send a STATUSTEXT to the ground station; a text over 50 characters goes out in
        chunks (:func:`fdm_awe.mavlink.statustext.chunks`)."""
        if self._closed:
            return
        for tid, seq, data in chunks(text):
            self.send("STATUSTEXT", self.mav.statustext_send, severity, data, tid, seq)

    def flight_ended(self, status: str, message: str) -> None:
        """Tell the ground station how the flight ended (STATUSTEXT ``flight STATUS: MESSAGE``;
        CRITICAL for a crash, a broken line or a limit, NOTICE for a completed flight or a
        landing, WARNING for an incomplete or interrupted one)."""
        self._reporter.vehicle(self, self.vehicle)
        self.statustext(f"flight {status}: {message}", END_SEVERITY.get(status, mav.MAV_SEVERITY_CRITICAL))
        self.flight_over = True

    @property
    def ever_linked(self) -> bool:
        """A ground station has been heard on the link (:meth:`from_ground_station`) at least once."""
        return self._ever_linked

    @property
    def link_lost(self) -> bool:
        """A ground station was linked and is not any more."""
        return self._ever_linked and not self.link_up

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
    def wake(self) -> None:
        """Have the next ``update`` do its work, whatever its time (a rate changed, a list
        to stream)."""
        self._next_due = -math.inf

    def _service(self, t: float, telemetry: Telemetry | Callable[[], Telemetry]) -> None:
        if self._closed:
            self._next_due = math.inf
            return
        if not math.isfinite(t):
            self.stats["bad_time"] += 1
            return
        if t < self._t_prev:  # simulation restarted: restart the schedule
            self.streams.restart(t)
            self._next_rx = t
        self._t_prev = t
        self.t_now = t
        self._tel_src = telemetry
        self._tel = None

        if t >= self._next_rx:
            self._next_rx = self._next_rx + self.rx_period if t - self._next_rx < self.rx_period else t + self.rx_period
            self._poll()
            self._reporter.vehicle(self, self.vehicle)

        nd = self.streams.send_due(self, t, self._next_rx)
        params = self._params
        if params.queue:
            params.send_burst()
            if params.queue:
                nd = t  # keep streaming the parameter list on the next step
        self._next_due = nd
        self._tel_src = None

    def telemetry(self) -> Telemetry:
        """The telemetry of this update (a callable source is called once, when first needed)."""
        if self._tel is None:
            src = self._tel_src
            tel = src() if callable(src) else src
            self._tel = tel if isinstance(tel, Telemetry) else Telemetry(t=self.t_now)
            self._reporter.telemetry(self, self._tel)
        return self._tel

    # ------------------------------------------------------------------ receive
    def _poll(self) -> None:
        self.stats["polls"] += 1
        self.signer.tick()
        rx = self._rx.stats
        reads, dropped, errors = rx["reads"], rx["dropped"], rx["read_errors"]
        for msgs, bad in self._rx.poll():
            self.stats["bad_packets"] += bad
            for m in msgs:
                self._handle(m)
        self.stats["datagrams"] += rx["reads"] - reads
        self.stats["rx_dropped"] += rx["dropped"] - dropped
        self.stats["bad_packets"] += rx["read_errors"] - errors
        now = self.clock()
        if self.link_up and now - self._last_rx_wall > self.link_timeout_s:
            self.link_up = False
            self.stats["link_losses"] += 1
            self.warn(f"MAVLink: ground-station link lost (no message for "
                       f"{now - self._last_rx_wall:.1f} s); flight continues", limit=False)
        if self._mission.upload is not None:
            self._mission.check_timeout(now)
        if self._pilot.last > -math.inf:
            self._pilot.check_timeout(now)

    def _handle(self, m: Any) -> None:
        mtype = m.get_type()
        if mtype == "BAD_DATA" or mtype.startswith("UNKNOWN"):
            refused = _signing.rejection(m)
            if refused is None:
                self.stats["bad_packets"] += 1
            else:
                self.stats["signing"][f"{refused}_rejected"] += 1
                self.warn(f"MAVLink: {refused.replace('_', ' ')} message ignored (signing on)")
            return
        if self.signer.on:
            self.stats["signing"]["accepted" if m.get_signed() else "unsigned_accepted"] += 1
        src = (m.get_srcSystem(), m.get_srcComponent())
        if src == (self.sysid, self.compid):
            return  # our own packet echoed back (e.g. broadcast)
        self.stats["received"] += 1
        if self.from_ground_station(m):
            self._last_rx_wall = self.clock()
            if not self.link_up:
                self.link_up = True
                self.gcs = src
                self.info(f"MAVLink: ground-station link {'regained' if self._ever_linked else 'up'} "
                           f"(system {src[0]} component {src[1]})")
                self._ever_linked = True
        h = self._handlers.get(mtype)
        if h is None:
            return
        try:
            h(m)
        except Exception as e:  # noqa: BLE001 - one bad message must not stop the loop
            self.stats["handler_errors"] += 1
            self.warn(f"MAVLink {mtype} from {src} not handled: {type(e).__name__}: {e}")

    def from_ground_station(self, m: Any) -> bool:
        """Does ``m`` come from a ground station, so it keeps the link up (``link_up``, the
        FS_GCS_ENABL failsafe)? Not when it comes from this vehicle's own system (its winch, any
        other of its components, an echo of what it sent); with signing on, only when it carried
        a valid signature (RADIO_STATUS and RADIO pass unsigned, but a radio is no ground
        station)."""
        if m.get_srcSystem() == self.sysid:
            return False
        return m.get_signed() or not self.signer.on

    def for_me(self, m: Any) -> bool:
        """Is ``m`` addressed to this vehicle (or broadcast)?"""
        ts = getattr(m, "target_system", 0)
        tc = getattr(m, "target_component", 0)
        return ts in (0, self.sysid) and tc in (0, self.compid)

    # ------------------------------------------------------------------ send and log
    def send(self, name: str, fn: Callable[..., None], *args: Any) -> None:
        """Call the encoder ``fn(*args)``, count it under ``name``; a failure is counted and
        warned about, never raised."""
        try:
            fn(*args)
        except Exception as e:  # noqa: BLE001 - a send problem is counted, never raised
            self.stats["send_errors"] += 1
            self.warn(f"MAVLink {name} not sent: {type(e).__name__}: {e}")
            return
        sent = self.stats["sent"]
        sent[name] = sent.get(name, 0) + 1

    def info(self, msg: str) -> None:
        """Log ``msg`` (the endpoint's log target: a logger's info, or the callable given)."""
        lt = self._log_target
        if isinstance(lt, logging.Logger):
            lt.info(msg)
        else:
            lt(msg)

    def warn(self, msg: str, limit: bool = True) -> None:
        """Log ``msg`` as a warning; with ``limit`` the same warning at most once per 5 s of wall
        time (garbage can repeat it fast)."""
        key = msg[:40]
        now = self.clock()
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
