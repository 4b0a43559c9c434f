"""The parameter protocol: the vehicle's :class:`~fdm_awe.autopilot.params.ParamStore` on the link.

PARAM_REQUEST_LIST streams every parameter as PARAM_VALUE, ``param_burst`` per update of the
endpoint (so a long list does not stall a simulation step); PARAM_REQUEST_READ answers one
(by index or name); PARAM_SET sets one and answers with its PARAM_VALUE: the new value, or,
as ArduPilot answers a write it denies (GCS_Param.cpp), a STATUSTEXT saying why and the old
value (out of range, not a whole number, unknown name). A ground station that repeats the
refused write (MAVSDK retries at once when the value it reads back differs, up to its retry
count, and then reports TIMEOUT) gets the old value again but the reason only once per
:data:`REPEAT_S`. A value is stored as typed (:func:`fdm_awe.mavlink.params.from_wire`), not as
the float32 that carried it.

Types: a whole-number or on/off parameter (``kind`` ``int`` or ``bool``) goes out as
``MAV_PARAM_TYPE_INT32``, the others as ``REAL32``; the value field carries the number as a
float (ArduPilot's encoding, which MAVProxy, MAVSDK and QGroundControl read for an ArduPilot
vehicle), so MAVSDK's ``get_param_int`` reads them. Without a vehicle the parameter list is empty.
"""

from __future__ import annotations

from typing import Any

from pymavlink.dialects.v20 import common as mav

from .link import Link
from ..autopilot.params import ParamStore
from .params import from_wire, param_text

#: a refused PARAM_SET repeated (same id and value) within this wall-clock time gets no new STATUSTEXT, s
REPEAT_S = 5.0


def wire_type(kind: str) -> int:
    """MAV_PARAM_TYPE of a parameter of ``kind``: INT32 for ``int`` and ``bool``, else REAL32."""
    return mav.MAV_PARAM_TYPE_INT32 if kind in ("int", "bool") else mav.MAV_PARAM_TYPE_REAL32



def param_id(raw: Any) -> str:
    """A PARAM_* message's ``param_id`` (bytes or str, NUL-padded) as a name."""
    if isinstance(raw, (bytes, bytearray)):
        raw = raw.decode("ascii", "replace")
    return str(raw).split("\x00", 1)[0]


class ParamProtocol:
    """Answers the parameter messages for ``ep``'s vehicle (see module doc).

    Attributes:
        queue: indices of the parameters still to be sent of a requested list (empty: none).
    """

    def __init__(self, ep: Link) -> None:
        self._ep = ep
        self.queue: list[int] = []
        self._refused: tuple[str, float, float] | None = None  # the last refused write: id, value, wall time

    def _store(self) -> ParamStore | None:
        vehicle = self._ep.vehicle
        return None if vehicle is None else vehicle.params

    def on_request_list(self, m: Any) -> None:
        """PARAM_REQUEST_LIST: queue the whole list (:meth:`send_burst` sends it, a burst per update)."""
        ep = self._ep
        if not ep.for_me(m):
            return
        ps = self._store()
        if ps is None:
            return
        self.queue = list(range(len(ps)))   # PARAM_VALUE is broadcast: no target to keep
        ep.wake()

    def send_burst(self) -> None:
        """Send the next ``param_burst`` parameters of the queued list."""
        ps = self._store()
        q = self.queue
        n = min(self._ep.param_burst, len(q))
        for i in q[:n]:
            self._send(ps, i)
        del q[:n]

    def _send(self, ps: ParamStore, index: int) -> None:
        name = ps.name_at(index)
        if name is None:
            return
        self._ep.send("PARAM_VALUE", self._ep.mav.param_value_send, name.encode("ascii"),
                       float(ps[name]), wire_type(ps.info(name).kind), len(ps), index)

    def on_request_read(self, m: Any) -> None:
        """PARAM_REQUEST_READ: one parameter, by index (>= 0) or else by name."""
        if not self._ep.for_me(m):
            return
        ps = self._store()
        if ps is None:
            return
        if m.param_index >= 0:
            if ps.name_at(m.param_index) is not None:
                self._send(ps, m.param_index)
            return
        name = param_id(m.param_id)
        if name in ps:
            self._send(ps, ps.index(name))

    def on_set(self, m: Any) -> None:
        """PARAM_SET: set the value as typed, answer with the parameter's value now."""
        ep = self._ep
        if not ep.for_me(m):
            return
        ps = self._store()
        name = param_id(m.param_id)
        if ps is None or name not in ps:
            ep.statustext(f"unknown parameter {name[:24]}", mav.MAV_SEVERITY_WARNING)
            return
        ok, why = ps.try_set(name, from_wire(m.param_value))   # the value as typed, not float32's
        if ok:
            ep.info(f"MAVLink: parameter {name} = {param_text(ps[name])}"
                     + ("" if why == "ok" else f" ({why})"))
            if why != "ok":
                ep.statustext(why, mav.MAV_SEVERITY_WARNING)
        else:
            now, last = ep.clock(), self._refused
            if last is None or last[:2] != (name, float(m.param_value)) or now - last[2] > REPEAT_S:
                ep.warn(f"MAVLink: PARAM_SET refused: {why}")
                ep.statustext(why, mav.MAV_SEVERITY_WARNING)
                self._refused = (name, float(m.param_value), now)
        self._send(ps, ps.index(name))
