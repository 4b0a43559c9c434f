"""Commands: COMMAND_LONG, COMMAND_INT and SET_MODE addressed to the vehicle.

Every command addressed to this vehicle gets a COMMAND_ACK: unknown ones
MAV_RESULT_UNSUPPORTED, bad parameters MAV_RESULT_DENIED, a vehicle refusal (or no vehicle)
MAV_RESULT_FAILED. Every refusal also says why in a STATUSTEXT (WARNING) after the ACK, as
ArduPilot does (``disarm refused: in flight (force: param2 21196)``, ``mode 15 (GUIDED) not
offered``). Commands addressed to the winch component go to it
(:meth:`fdm_awe.mavlink.winch.WinchComponent.on_command`). After the flight's end
(:attr:`~fdm_awe.mavlink.endpoint.MavlinkEndpoint.flight_over`) the commands that would fly
(arm, modes, cycling, RTL, land) are refused (``flight over: the simulation has stopped``).

=================================  ==========================================================
MAV_CMD_COMPONENT_ARM_DISARM       param1 1 = arm, 0 = disarm; param2 21196 forces (a disarm in flight is refused otherwise)
MAV_CMD_DO_SET_MODE                param1 with MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, param2 mode
MAV_CMD_MISSION_START              start the pumping cycles (``vehicle.start_cycling``)
MAV_CMD_DO_PAUSE_CONTINUE          param1 0 = stop cycling, 1 = start cycling
MAV_CMD_NAV_RETURN_TO_LAUNCH       mode RECOVER
MAV_CMD_NAV_LAND                   mode RECOVER, which lands (refused with REC_LAND 0: RECOVER parks)
MAV_CMD_DO_CHANGE_SPEED            refused (DENIED): the cycle flies the reference's airspeed
MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN  param1 2 (shut down) after the flight's end: the program ends
MAV_CMD_GET_HOME_POSITION          sends HOME_POSITION
MAV_CMD_REQUEST_MESSAGE            any streamed message, HOME_POSITION, AUTOPILOT_VERSION
MAV_CMD_SET_MESSAGE_INTERVAL       streamed messages (param2 us; -1 off, 0 default)
MAV_CMD_GET_MESSAGE_INTERVAL       answers MESSAGE_INTERVAL
MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES  sends AUTOPILOT_VERSION
=================================  ==========================================================

Mode numbers are those of :data:`fdm_awe.mode_table.MODE_NUMBERS`; a mode the vehicle
does not offer, or a number not in the table, is DENIED (LOITER is the hold of MAVSDK's ``hold()``
and ``pause_mission()``: :mod:`fdm_awe.autopilot.modes`). SET_MODE is answered with
COMMAND_ACK(command = 11), as ArduPilot does. A message the command asks for goes out after
the COMMAND_ACK.
"""

from __future__ import annotations

import math
from typing import Any, Callable

from pymavlink.dialects.v20 import common as mav

from .link import Link
from .messages import as_finite, send_autopilot_version
from .streams import MAX_RATE_HZ, stream_of_message
from .vehicle import ARM_DISARM_FORCE, RTL_MODE
from ..mode_table import MODE_NAMES, MODE_NUMBERS
from .winch import WINCH_COMPID


#: what a command handler returns: MAV_RESULT and what to do after the ACK went out (or None)
Outcome = tuple[int, Callable[[], None] | None]


def _result(ok: bool) -> int:
    return mav.MAV_RESULT_ACCEPTED if ok else mav.MAV_RESULT_FAILED


#: the commands that fly the vehicle: refused once the flight is over
_FLYING = (mav.MAV_CMD_COMPONENT_ARM_DISARM, mav.MAV_CMD_DO_SET_MODE, mav.MAV_CMD_MISSION_START,
           mav.MAV_CMD_DO_PAUSE_CONTINUE, mav.MAV_CMD_NAV_RETURN_TO_LAUNCH, mav.MAV_CMD_NAV_LAND)

#: why a command is refused when its handler names no reason, by MAV_RESULT
_DEFAULT_WHY = {mav.MAV_RESULT_DENIED: "invalid parameters", mav.MAV_RESULT_FAILED: "refused by the autopilot",
                mav.MAV_RESULT_UNSUPPORTED: "unsupported"}

#: the reason of a refused command once the flight is over
FLIGHT_OVER = "flight over: the simulation has stopped"


def command_name(command: int) -> str:
    """MAV_CMD name of ``command`` without its prefix (``NAV_LAND``), or its number."""
    entry = mav.enums["MAV_CMD"].get(command)
    return entry.name.removeprefix("MAV_CMD_") if entry is not None else f"command {command}"


def _mode_list(vehicle: Any) -> str:
    """The modes the vehicle offers with their numbers (``MANUAL 0, FBWA 5, ...``)."""
    try:
        names = list(vehicle.modes) if vehicle is not None else []
    except Exception:  # noqa: BLE001 - a failing vehicle property lists no mode
        names = []
    return ", ".join(f"{n} {MODE_NUMBERS[n]}" for n in names if n in MODE_NUMBERS) or "none"


class CommandHandler:
    """Runs the commands of the module doc's table on ``ep``'s vehicle and acknowledges them."""

    def __init__(self, ep: Link) -> None:
        self._ep = ep
        self._why = ""  # the reason the command being handled was refused ("" = the result's default)

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
        self._why = ""
        if ep.flight_over:
            result, self._why = mav.MAV_RESULT_FAILED, f"SET_MODE: {FLIGHT_OVER}"
        elif m.base_mode & mav.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED:
            result = self._set_mode_number(m.custom_mode)
        else:
            result, self._why = mav.MAV_RESULT_DENIED, "SET_MODE without a custom mode"
        ep.send("COMMAND_ACK", ep.mav.command_ack_send, mav.MAVLINK_MSG_ID_SET_MODE, result,
                 0, 0, m.get_srcSystem(), m.get_srcComponent())
        self._refusal("SET_MODE", result)

    def _refusal(self, what: str, result: int) -> None:
        """The STATUSTEXT that says why ``what`` was refused (nothing when it was accepted)."""
        if result in (mav.MAV_RESULT_ACCEPTED, mav.MAV_RESULT_IN_PROGRESS):
            return
        why = self._why or f"{what}: {_DEFAULT_WHY.get(result, f'result {result}')}"
        self._ep.statustext(why[:150], mav.MAV_SEVERITY_WARNING)

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
        self._why = ""
        if handler is None:
            result = mav.MAV_RESULT_UNSUPPORTED
        elif ep.flight_over and m.command in _FLYING:
            result, self._why = mav.MAV_RESULT_FAILED, f"{command_name(m.command)}: {FLIGHT_OVER}"
        else:
            try:
                result, after = handler(self, p)
            except Exception as e:  # noqa: BLE001 - a failing vehicle call is answered FAILED
                ep.stats["handler_errors"] += 1
                ep.warn(f"MAVLink command {m.command} failed: {type(e).__name__}: {e}")
                result, after = mav.MAV_RESULT_FAILED, None
        ep.send("COMMAND_ACK", ep.mav.command_ack_send, m.command, result, 0, 0,
                 m.get_srcSystem(), m.get_srcComponent())
        self._refusal(command_name(m.command), result)
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
        if not ok:
            airborne = bool(getattr(vehicle, "airborne", False))
            self._why = ("disarm refused: in flight (force: param2 21196)" if p[0] == 0.0 and airborne
                         else f"{'arm' if p[0] == 1.0 else 'disarm'} refused by the autopilot")
        return _result(ok), None

    def _set_mode_number(self, number: Any) -> int:
        try:
            nf = float(number)
        except (TypeError, ValueError):
            return mav.MAV_RESULT_DENIED
        if not math.isfinite(nf) or nf != int(nf) or int(nf) not in MODE_NAMES:
            self._why = f"mode {number!r} unknown (modes: {_mode_list(self._ep.vehicle)})"
            return mav.MAV_RESULT_DENIED
        name = MODE_NAMES[int(nf)]
        vehicle = self._ep.vehicle
        if vehicle is None:
            self._why = "mode change refused: no autopilot"
            return mav.MAV_RESULT_FAILED
        if name not in vehicle.modes:
            self._why = f"mode {int(nf)} ({name}) not offered (modes: {_mode_list(vehicle)})"
            return mav.MAV_RESULT_DENIED
        ok = bool(vehicle.set_mode(name))
        self._ep.info(f"MAVLink: mode {name} {'accepted' if ok else 'refused'}")
        if not ok:
            self._why = (f"mode {name} refused: no mission (reference path) loaded"
                         if name == "AUTO" and not vehicle.mission() else f"mode {name} refused by the autopilot")
        return _result(ok)

    def _set_mode(self, p: tuple[float, ...]) -> Outcome:
        base = as_finite(p[0], -1.0)
        if base < 0 or base != int(base) or not int(base) & mav.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED:
            self._why = "DO_SET_MODE refused: custom modes only (param1 1)"
            return mav.MAV_RESULT_DENIED, None
        return self._set_mode_number(p[1]), None

    def _mission_start(self, p: tuple[float, ...]) -> Outcome:
        vehicle = self._ep.vehicle
        if vehicle is None:
            return mav.MAV_RESULT_FAILED, None
        ok = bool(vehicle.start_cycling())
        self._ep.info(f"MAVLink: start cycling {'accepted' if ok else 'refused'}")
        if not ok:
            self._why = ("mission start refused: no mission (reference path)" if not vehicle.mission()
                         else "mission start refused by the autopilot")
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

    def _land(self, p: tuple[float, ...]) -> Outcome:
        """NAV_LAND: RECOVER, which lands at the winch; refused while REC_LAND 0 makes it park."""
        vehicle = self._ep.vehicle
        if vehicle is not None and "REC_LAND" in vehicle.params and vehicle.params["REC_LAND"] < 0.5:
            self._why = "land refused: REC_LAND 0 (RECOVER parks in the hold); set REC_LAND 1 to land"
            return mav.MAV_RESULT_DENIED, None
        return self._set_mode_number(MODE_NUMBERS[RTL_MODE]), None

    def _change_speed(self, p: tuple[float, ...]) -> Outcome:
        """DO_CHANGE_SPEED: refused, the pumping cycle's airspeed is the reference's."""
        self._why = "speed change refused: the cycle flies the reference's airspeed (no speed setting)"
        return mav.MAV_RESULT_DENIED, None

    def _shutdown(self, p: tuple[float, ...]) -> Outcome:
        """PREFLIGHT_REBOOT_SHUTDOWN param1 2 (shut the autopilot down): after the flight's end the
        program ends (:attr:`~fdm_awe.mavlink.endpoint.MavlinkEndpoint.shutdown_requested`)."""
        ep = self._ep
        if p[0] != 2.0:
            self._why = "reboot refused: only param1 2 (shut down)"
            return mav.MAV_RESULT_UNSUPPORTED, None
        if not ep.flight_over:
            self._why = "shutdown refused: in flight (RTL, or Ctrl-C ends the program)"
            return mav.MAV_RESULT_DENIED, None
        ep.shutdown_requested = True
        return mav.MAV_RESULT_ACCEPTED, None

    # ------------------------------------------------------------------ messages on request
    def _get_home(self, p: tuple[float, ...]) -> Outcome:
        ep = self._ep
        return mav.MAV_RESULT_ACCEPTED, lambda: ep.streams.send_now(ep, "HOME_POSITION")

    def _capabilities(self, p: tuple[float, ...]) -> Outcome:
        ep = self._ep
        return mav.MAV_RESULT_ACCEPTED, lambda: send_autopilot_version(ep)

    def _request_message(self, p: tuple[float, ...]) -> Outcome:
        ep = self._ep
        mid = as_finite(p[0], -1.0)
        if mid == mav.MAVLINK_MSG_ID_AUTOPILOT_VERSION:
            return mav.MAV_RESULT_ACCEPTED, lambda: send_autopilot_version(ep)
        name = stream_of_message(mid)
        if name is None:
            self._why = f"REQUEST_MESSAGE: message {mid:g} not sent here"
            return mav.MAV_RESULT_UNSUPPORTED, None
        return mav.MAV_RESULT_ACCEPTED, lambda: ep.streams.send_now(ep, name)

    def _set_interval(self, p: tuple[float, ...]) -> Outcome:
        ep = self._ep
        mid, us = as_finite(p[0], -1.0), as_finite(p[1], math.nan)
        name = stream_of_message(mid)
        if name is None:
            self._why = f"SET_MESSAGE_INTERVAL: message {mid:g} not streamed"
            return mav.MAV_RESULT_UNSUPPORTED, None
        if math.isnan(us) or us < -1:
            self._why = f"SET_MESSAGE_INTERVAL: {us:g} us invalid (-1, 0, > 0)"
            return mav.MAV_RESULT_DENIED, None
        if us == -1:
            hz = 0.0
        elif us == 0:
            hz = ep.streams.default_rate(name)
        else:
            hz = 1e6 / us
            if hz > MAX_RATE_HZ:
                self._why = f"SET_MESSAGE_INTERVAL: {hz:g} Hz above {MAX_RATE_HZ:g} Hz"
                return mav.MAV_RESULT_DENIED, None
        ep.set_rate(name, hz)
        ep.info(f"MAVLink: {name} rate set to {hz:g} Hz")
        return mav.MAV_RESULT_ACCEPTED, None

    def _get_interval(self, p: tuple[float, ...]) -> Outcome:
        ep = self._ep
        mid = as_finite(p[0], -1.0)
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
        mav.MAV_CMD_NAV_LAND: _land,
        mav.MAV_CMD_DO_CHANGE_SPEED: _change_speed,
        mav.MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN: _shutdown,
        mav.MAV_CMD_GET_HOME_POSITION: _get_home,
        mav.MAV_CMD_REQUEST_MESSAGE: _request_message,
        mav.MAV_CMD_SET_MESSAGE_INTERVAL: _set_interval,
        mav.MAV_CMD_GET_MESSAGE_INTERVAL: _get_interval,
        mav.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES: _capabilities,
    }
