"""Commands: COMMAND_LONG, COMMAND_INT and SET_MODE addressed to the vehicle.

Every command addressed to this vehicle gets a COMMAND_ACK: unknown ones
MAV_RESULT_UNSUPPORTED, bad parameters MAV_RESULT_DENIED, a vehicle refusal (or no vehicle)
MAV_RESULT_FAILED. Commands addressed to the winch component go to it
(:meth:`fdm_awe.mavlink.winch.WinchComponent.on_command`).

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

Mode numbers are those of :data:`fdm_awe.mavlink.vehicle.MODE_NUMBERS`; a mode the vehicle
does not offer, or a number not in the table, is DENIED. SET_MODE is answered with
COMMAND_ACK(command = 11), as ArduPilot does. A message the command asks for goes out after
the COMMAND_ACK.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Callable

from pymavlink.dialects.v20 import common as mav

from .messages import _f, send_autopilot_version
from .streams import MAX_RATE_HZ, stream_of_message
from .vehicle import ARM_DISARM_FORCE, MODE_NAMES, MODE_NUMBERS, RTL_MODE
from .winch import WINCH_COMPID

if TYPE_CHECKING:  # pragma: no cover
    from .endpoint import MavlinkEndpoint

#: what a command handler returns: MAV_RESULT and what to do after the ACK went out (or None)
Outcome = tuple[int, Callable[[], None] | None]


def _result(ok: bool) -> int:
    return mav.MAV_RESULT_ACCEPTED if ok else mav.MAV_RESULT_FAILED


class CommandHandler:
    """Runs the commands of the module doc's table on ``ep``'s vehicle and acknowledges them."""

    def __init__(self, ep: "MavlinkEndpoint") -> None:
        self._ep = ep

    # ------------------------------------------------------------------ messages
    def on_command_long(self, m: Any) -> None:
        """COMMAND_LONG: for the winch, for this vehicle, or ignored."""
        self._dispatch(m, (m.param1, m.param2, m.param3, m.param4, m.param5, m.param6, m.param7))

    def on_command_int(self, m: Any) -> None:
        """COMMAND_INT: as COMMAND_LONG, with x and y as params 5 and 6."""
        self._dispatch(m, (m.param1, m.param2, m.param3, m.param4, float(m.x), float(m.y), m.z))

    def on_set_mode(self, m: Any) -> None:
        """SET_MODE (custom mode): answered with COMMAND_ACK for message id 11."""
        ep = self._ep
        if m.target_system != ep.sysid:
            return
        if m.base_mode & mav.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED:
            result = self._set_mode_number(m.custom_mode)
        else:
            result = mav.MAV_RESULT_DENIED
        ep.send("COMMAND_ACK", ep.mav.command_ack_send, mav.MAVLINK_MSG_ID_SET_MODE, result,
                 0, 0, m.get_srcSystem(), m.get_srcComponent())

    def _dispatch(self, m: Any, p: tuple[float, ...]) -> None:
        ep = self._ep
        if m.target_system == ep.sysid and m.target_component == WINCH_COMPID:
            ep.winch.on_command(ep, m, p)
        elif ep.for_me(m):
            self._run(m, p)

    def _run(self, m: Any, p: tuple[float, ...]) -> None:
        ep = self._ep
        handler = self._table.get(m.command)
        after: Callable[[], None] | None = None
        if handler is None:
            result = mav.MAV_RESULT_UNSUPPORTED
        else:
            try:
                result, after = handler(self, p)
            except Exception as e:  # noqa: BLE001 - a failing vehicle call is answered FAILED
                ep.stats["handler_errors"] += 1
                ep.warn(f"MAVLink command {m.command} failed: {type(e).__name__}: {e}")
                result, after = mav.MAV_RESULT_FAILED, None
        ep.send("COMMAND_ACK", ep.mav.command_ack_send, m.command, result, 0, 0,
                 m.get_srcSystem(), m.get_srcComponent())
        if after is not None and result == mav.MAV_RESULT_ACCEPTED:
            after()

    # ------------------------------------------------------------------ vehicle commands
    def _arm(self, p: tuple[float, ...]) -> Outcome:
        if p[0] not in (0.0, 1.0):
            return mav.MAV_RESULT_DENIED, None
        vehicle = self._ep.vehicle
        if vehicle is None:
            return mav.MAV_RESULT_FAILED, None
        force = p[1] == ARM_DISARM_FORCE
        ok = bool(vehicle.arm(p[0] == 1.0, force=True) if force else vehicle.arm(p[0] == 1.0))
        self._ep.info(f"MAVLink: {'arm' if p[0] == 1.0 else 'disarm'}{' (forced)' if force else ''} "
                       f"{'accepted' if ok else 'refused'}")
        return _result(ok), None

    def _set_mode_number(self, number: Any) -> int:
        try:
            nf = float(number)
        except (TypeError, ValueError):
            return mav.MAV_RESULT_DENIED
        if not math.isfinite(nf) or nf != int(nf) or int(nf) not in MODE_NAMES:
            return mav.MAV_RESULT_DENIED
        name = MODE_NAMES[int(nf)]
        vehicle = self._ep.vehicle
        if vehicle is None:
            return mav.MAV_RESULT_FAILED
        if name not in vehicle.modes:
            return mav.MAV_RESULT_DENIED
        ok = bool(vehicle.set_mode(name))
        self._ep.info(f"MAVLink: mode {name} {'accepted' if ok else 'refused'}")
        return _result(ok)

    def _set_mode(self, p: tuple[float, ...]) -> Outcome:
        base = _f(p[0], -1.0)
        if base < 0 or base != int(base) or not int(base) & mav.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED:
            return mav.MAV_RESULT_DENIED, None
        return self._set_mode_number(p[1]), None

    def _mission_start(self, p: tuple[float, ...]) -> Outcome:
        vehicle = self._ep.vehicle
        if vehicle is None:
            return mav.MAV_RESULT_FAILED, None
        ok = bool(vehicle.start_cycling())
        self._ep.info(f"MAVLink: start cycling {'accepted' if ok else 'refused'}")
        return _result(ok), None

    def _pause_continue(self, p: tuple[float, ...]) -> Outcome:
        if p[0] not in (0.0, 1.0):
            return mav.MAV_RESULT_DENIED, None
        vehicle = self._ep.vehicle
        if vehicle is None:
            return mav.MAV_RESULT_FAILED, None
        if p[0] == 1.0:
            return self._mission_start(p)
        ok = bool(vehicle.stop_cycling())
        self._ep.info(f"MAVLink: stop cycling {'accepted' if ok else 'refused'}")
        return _result(ok), None

    def _rtl(self, p: tuple[float, ...]) -> Outcome:
        return self._set_mode_number(MODE_NUMBERS[RTL_MODE]), None

    # ------------------------------------------------------------------ messages on request
    def _get_home(self, p: tuple[float, ...]) -> Outcome:
        ep = self._ep
        return mav.MAV_RESULT_ACCEPTED, lambda: ep.streams.send_now(ep, "HOME_POSITION")

    def _capabilities(self, p: tuple[float, ...]) -> Outcome:
        ep = self._ep
        return mav.MAV_RESULT_ACCEPTED, lambda: send_autopilot_version(ep)

    def _request_message(self, p: tuple[float, ...]) -> Outcome:
        ep = self._ep
        mid = _f(p[0], -1.0)
        if mid == mav.MAVLINK_MSG_ID_AUTOPILOT_VERSION:
            return mav.MAV_RESULT_ACCEPTED, lambda: send_autopilot_version(ep)
        name = stream_of_message(mid)
        if name is None:
            return mav.MAV_RESULT_UNSUPPORTED, None
        return mav.MAV_RESULT_ACCEPTED, lambda: ep.streams.send_now(ep, name)

    def _set_interval(self, p: tuple[float, ...]) -> Outcome:
        ep = self._ep
        mid, us = _f(p[0], -1.0), _f(p[1], math.nan)
        name = stream_of_message(mid)
        if name is None:
            return mav.MAV_RESULT_UNSUPPORTED, None
        if math.isnan(us) or us < -1:
            return mav.MAV_RESULT_DENIED, None
        if us == -1:
            hz = 0.0
        elif us == 0:
            hz = ep.streams.default_rate(name)
        else:
            hz = 1e6 / us
            if hz > MAX_RATE_HZ:
                return mav.MAV_RESULT_DENIED, None
        ep.set_rate(name, hz)
        ep.info(f"MAVLink: {name} rate set to {hz:g} Hz")
        return mav.MAV_RESULT_ACCEPTED, None

    def _get_interval(self, p: tuple[float, ...]) -> Outcome:
        ep = self._ep
        mid = _f(p[0], -1.0)
        name = stream_of_message(mid)
        if name is None:
            return mav.MAV_RESULT_UNSUPPORTED, None
        us = ep.streams.interval_us(name)
        return mav.MAV_RESULT_ACCEPTED, lambda: ep.send(
            "MESSAGE_INTERVAL", ep.mav.message_interval_send, int(mid), us)

    _table: dict[int, Callable[["CommandHandler", tuple[float, ...]], Outcome]] = {
        mav.MAV_CMD_COMPONENT_ARM_DISARM: _arm,
        mav.MAV_CMD_DO_SET_MODE: _set_mode,
        mav.MAV_CMD_MISSION_START: _mission_start,
        mav.MAV_CMD_DO_PAUSE_CONTINUE: _pause_continue,
        mav.MAV_CMD_NAV_RETURN_TO_LAUNCH: _rtl,
        mav.MAV_CMD_GET_HOME_POSITION: _get_home,
        mav.MAV_CMD_REQUEST_MESSAGE: _request_message,
        mav.MAV_CMD_SET_MESSAGE_INTERVAL: _set_interval,
        mav.MAV_CMD_GET_MESSAGE_INTERVAL: _get_interval,
        mav.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES: _capabilities,
    }
