"""Telemetry streams: their rates and their schedule in simulation time.

Every stream of :data:`DEFAULT_RATES` (what each says: :mod:`fdm_awe.mavlink.messages`) has a
period in simulation seconds (``inf`` = off) and the simulation time it is next due. A stream
that falls behind (a long step, the first call) is not sent in a burst: its phase restarts at
the current time. A simulation that restarts (time going back) restarts every stream.

Rates are set with the endpoint's ``rates=``, :meth:`~fdm_awe.mavlink.endpoint.MavlinkEndpoint.set_rate`,
MAV_CMD_SET_MESSAGE_INTERVAL (:mod:`fdm_awe.mavlink.commands`) or REQUEST_DATA_STREAM: 0 Hz is
off, at most :data:`MAX_RATE_HZ`.

REQUEST_DATA_STREAM (MAVProxy's and QGroundControl's stream rates for an ArduPilot vehicle) sets
the rate of every stream of a group, as ArduPlane groups them (:data:`DATA_STREAMS`; its SRx_
parameters); ``start_stop`` 0 switches the group off; MAV_DATA_STREAM_ALL sets every group.
HEARTBEAT, HOME_POSITION, NAMED_VALUE_FLOAT and the winch's WINCH_STATUS are no group's (they
keep their rates). The rates hold until the next request.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

from pymavlink.dialects.v20 import ardupilotmega as apm
from pymavlink.dialects.v20 import common as mav

from fdm_awe.errors import InputError

from .link import Link
from .messages import RATES, SENDERS
from .vehicle import Telemetry


#: Default stream rates, Hz of simulation time, in the order the streams go out.
DEFAULT_RATES: dict[str, float] = dict(RATES)

#: highest stream rate accepted, Hz
MAX_RATE_HZ = 200.0

#: message ids of the streams (ArduPilot's own messages, e.g. WIND, from its dialect)
_STREAM_IDS: dict[str, int] = {name: getattr(mav, f"MAVLINK_MSG_ID_{name}", None)
                               or getattr(apm, f"MAVLINK_MSG_ID_{name}") for name in DEFAULT_RATES}
_STREAM_BY_ID: dict[int, str] = {v: k for k, v in _STREAM_IDS.items()}

#: ArduPlane's stream groups (MAV_DATA_STREAM) -> the streams of this vehicle in them
DATA_STREAMS: dict[int, tuple[str, ...]] = {
    mav.MAV_DATA_STREAM_EXTENDED_STATUS: ("SYS_STATUS", "GPS_RAW_INT", "MISSION_CURRENT", "NAV_CONTROLLER_OUTPUT"),
    mav.MAV_DATA_STREAM_RC_CHANNELS: ("SERVO_OUTPUT_RAW",),
    mav.MAV_DATA_STREAM_POSITION: ("GLOBAL_POSITION_INT",),
    mav.MAV_DATA_STREAM_EXTRA1: ("ATTITUDE", "ATTITUDE_QUATERNION"),
    mav.MAV_DATA_STREAM_EXTRA2: ("VFR_HUD",),
    mav.MAV_DATA_STREAM_EXTRA3: ("SYSTEM_TIME", "WIND", "BATTERY_STATUS", "EXTENDED_SYS_STATE"),
}


def data_stream_rates(stream_id: int, rate_hz: float, start: bool) -> dict[str, float]:
    """The stream rates (Hz) a REQUEST_DATA_STREAM sets: every stream of group ``stream_id``
    (all groups for MAV_DATA_STREAM_ALL) at ``rate_hz`` (at most :data:`MAX_RATE_HZ`), or 0 when
    ``start`` is false or the rate is 0; empty for a group this vehicle has no stream in."""
    hz = min(float(rate_hz), MAX_RATE_HZ) if start else 0.0
    if stream_id == mav.MAV_DATA_STREAM_ALL:
        names = [n for group in DATA_STREAMS.values() for n in group]
    else:
        names = list(DATA_STREAMS.get(stream_id, ()))
    return {n: hz for n in names if n in DEFAULT_RATES}


Sender = Callable[[Link, Telemetry, float], None]


def check_rate(stream: str, hz: object) -> float:
    """``hz`` as the float rate of ``stream``; InputError (one line) for an unknown stream or a
    rate that is not a number in [0, :data:`MAX_RATE_HZ`]."""
    if stream not in DEFAULT_RATES:
        raise InputError(f"MAVLink rate {stream!r}: unknown stream; allowed: {', '.join(DEFAULT_RATES)}")
    if not isinstance(hz, (int, float)) or not math.isfinite(hz) or not 0 <= hz <= MAX_RATE_HZ:
        raise InputError(f"MAVLink rate {stream}: {hz!r} Hz outside [0, {MAX_RATE_HZ:g}]")
    return float(hz)


def stream_of_message(msg_id: float) -> str | None:
    """The stream sending message id ``msg_id`` (a command parameter, float), or None."""
    return _STREAM_BY_ID.get(int(msg_id)) if msg_id == int(msg_id) else None


@dataclass
class _Stream:
    name: str
    period: float      # s (simulation), inf = off
    next_t: float      # s (simulation)
    default_rate: float  # Hz
    send: Sender


class StreamSchedule:
    """The streams, their periods and when each is next due (simulation time).

    Args:
        rates: stream name -> Hz, merged over :data:`DEFAULT_RATES`; 0 = off.

    Raises:
        InputError: unknown stream or bad rate (:func:`check_rate`).
    """

    def __init__(self, rates: dict[str, float] | None = None) -> None:
        merged = dict(DEFAULT_RATES)
        for k, v in (rates or {}).items():
            merged[k] = check_rate(k, v)
        self._streams = [_Stream(k, 1.0 / r if r > 0 else math.inf, 0.0, DEFAULT_RATES[k], SENDERS[k])
                         for k, r in merged.items()]
        self._by_name = {s.name: s for s in self._streams}

    def restart(self, t: float) -> None:
        """Make every stream due at simulation time ``t`` (s): the simulation restarted."""
        for s in self._streams:
            s.next_t = t

    def send_due(self, ep: Link, t: float, next_rx: float) -> float:
        """Send every stream due at simulation time ``t`` (s) through ``ep``; return the
        earliest time (s) anything is due next: a stream or ``next_rx``, the next input poll.

        A failing sender is counted (``stats["send_errors"]``) and warned about; the other
        streams still go out."""
        for s in self._streams:
            if t >= s.next_t:
                s.next_t += s.period
                if s.next_t <= t:        # fell behind (or first call): no burst, restart phase
                    s.next_t = t + s.period
                tel = ep.telemetry()
                try:
                    s.send(ep, tel, t)
                except Exception as e:  # noqa: BLE001 - bad telemetry must not stop the stream loop
                    ep.stats["send_errors"] += 1
                    ep.warn(f"MAVLink {s.name} not sent: {type(e).__name__}: {e}")
        nd = next_rx
        for s in self._streams:
            if s.next_t < nd:
                nd = s.next_t
        return nd

    def send_now(self, ep: Link, stream: str) -> None:
        """Send one message of ``stream`` now (a ground station's request), off the schedule."""
        self._by_name[stream].send(ep, ep.telemetry(), ep.t_now)

    def set_rate(self, stream: str, hz: float, t: float) -> None:
        """Set a stream's rate (Hz, 0 = off; :func:`check_rate`), due first at ``t`` (s)."""
        hz = check_rate(stream, hz)
        s = self._by_name[stream]
        s.period = 1.0 / hz if hz > 0 else math.inf
        s.next_t = t

    def default_rate(self, stream: str) -> float:
        """The rate ``stream`` had by default, Hz."""
        return self._by_name[stream].default_rate

    def interval_us(self, stream: str) -> int:
        """The period of ``stream`` in microseconds, -1 when it is off."""
        period = self._by_name[stream].period
        return -1 if math.isinf(period) else int(round(period * 1e6))

    def rates(self) -> dict[str, float]:
        """Current stream rates, Hz."""
        return {s.name: (0.0 if math.isinf(s.period) else 1.0 / s.period) for s in self._streams}
