"""STATUSTEXT: long texts in chunks, and the vehicle's changes and events as texts.

:func:`chunks` splits a text into MAVLink 2 STATUSTEXT chunks: up to 50 characters each; a
text longer than one chunk gets a non-zero ``id`` shared by its chunks and ``chunk_seq``
0, 1, ...; its last chunk is shorter than 50 characters (an empty one follows a text whose
length is a multiple of 50), which tells the receiver the text is complete.

:class:`ChangeReporter` watches the vehicle and its telemetry and reports as STATUSTEXT:

=================================  =================  =============================================
change                             severity           text
=================================  =================  =============================================
failsafe (the autopilot's note)    WARNING            ``failsafe: 68.5 m from the path for 5.0 s ...``
mode                               NOTICE             ``mode AUTO -> RECOVER``
armed / disarmed                   NOTICE             ``armed`` / ``disarmed``
cycling started / stopped          INFO               ``cycling started`` / ``cycling stopped``
cycle phase                        INFO               ``phase generation -> recovery``
winch line broken                  CRITICAL           ``winch: line broken``
line fully reeled in               NOTICE             ``winch: line fully reeled in``
simulation fault (health)          CRITICAL           ``simulation fault: state not finite``
=================================  =================  =============================================

The first observation only records the state (nothing to compare with). The end of a flight
(completed, landed, crashed, line broken, limits, interrupted) is reported by
:meth:`fdm_awe.mavlink.endpoint.MavlinkEndpoint.flight_ended` with the flight's own message.
"""

from __future__ import annotations

import itertools
from typing import Any

from pymavlink.dialects.v20 import common as mav

from .link import Link
from .vehicle import Telemetry


#: characters of one STATUSTEXT
CHUNK = 50
#: chunks of one text at most (longer texts are cut, ending in "...")
MAX_CHUNKS = 4

#: flight status -> STATUSTEXT severity of the flight's end
END_SEVERITY: dict[str, int] = {
    "ok": mav.MAV_SEVERITY_NOTICE,
    "landed": mav.MAV_SEVERITY_NOTICE,
    "incomplete": mav.MAV_SEVERITY_WARNING,
    "interrupted": mav.MAV_SEVERITY_WARNING,
}

_ids = itertools.count(1)


def chunks(text: str) -> list[tuple[int, int, bytes]]:
    """``(id, chunk_seq, bytes)`` of each STATUSTEXT chunk of ``text`` (ASCII; see module doc)."""
    data = text.encode("ascii", "replace")
    limit = CHUNK * MAX_CHUNKS - 1
    if len(data) > limit:
        data = data[: limit - 3] + b"..."
    if len(data) <= CHUNK:
        return [(0, 0, data)]
    tid = next(_ids) % 65535 + 1
    parts = [data[i:i + CHUNK] for i in range(0, len(data), CHUNK)]
    if len(parts[-1]) == CHUNK:
        parts.append(b"")
    return [(tid, k, part) for k, part in enumerate(parts)]


class ChangeReporter:
    """Reports the vehicle's changes as STATUSTEXT (table in the module doc)."""

    def __init__(self) -> None:
        self._vehicle: tuple[str, bool, bool] | None = None
        self._tel: tuple[str, bool, bool, bool] | None = None
        self._notes_seen = 0  # entries of the vehicle's log already looked at

    def vehicle(self, ep: Link, vehicle: Any) -> None:
        """Compare the vehicle's mode, armed and cycling flags with the last look; before a mode
        change, the failsafe notes of the vehicle's log (``log``: ``(t, text)`` entries, if it
        keeps one) since the last look, which say why."""
        if vehicle is None:
            return
        log = getattr(vehicle, "log", None)
        if isinstance(log, list):
            for _, text in log[self._notes_seen:]:
                if str(text).startswith("failsafe"):
                    ep.statustext(str(text), mav.MAV_SEVERITY_WARNING)
            self._notes_seen = len(log)
        try:
            now = (str(vehicle.mode), bool(vehicle.armed), bool(vehicle.cycling))
        except Exception:  # noqa: BLE001 - a failing vehicle property is not a change
            return
        last, self._vehicle = self._vehicle, now
        if last is None or last == now:
            return
        if now[0] != last[0]:
            ep.statustext(f"mode {last[0]} -> {now[0]}", mav.MAV_SEVERITY_NOTICE)
        if now[1] != last[1]:
            ep.statustext("armed" if now[1] else "disarmed", mav.MAV_SEVERITY_NOTICE)
        if now[2] != last[2]:
            ep.statustext("cycling started" if now[2] else "cycling stopped", mav.MAV_SEVERITY_INFO)

    def telemetry(self, ep: Link, tel: Telemetry) -> None:
        """Compare the telemetry's phase, winch and health flags with the last snapshot."""
        now = (str(tel.phase), bool(tel.winch_ok), bool(tel.line_fully_in), bool(tel.health_ok))
        last, self._tel = self._tel, now
        if last is None or last == now:
            return
        if now[0] != last[0]:
            ep.statustext(f"phase {last[0]} -> {now[0]}", mav.MAV_SEVERITY_INFO)
        if last[1] and not now[1]:
            ep.statustext("winch: line broken", mav.MAV_SEVERITY_CRITICAL)
        if now[2] and not last[2]:
            ep.statustext("winch: line fully reeled in", mav.MAV_SEVERITY_NOTICE)
        if last[3] and not now[3]:
            ep.statustext("simulation fault: state not finite", mav.MAV_SEVERITY_CRITICAL)
