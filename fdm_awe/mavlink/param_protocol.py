"""The parameter protocol: the vehicle's :class:`~fdm_awe.mavlink.params.ParamStore` on the link.

PARAM_REQUEST_LIST streams every parameter as PARAM_VALUE, ``param_burst`` per update of the
endpoint (so a long list does not stall a simulation step); PARAM_REQUEST_READ answers one
(by index or name); PARAM_SET sets one and answers with its PARAM_VALUE: the new value, or
the old one and a STATUSTEXT when it is refused (out of range, unknown name). A value is
stored as typed (:func:`fdm_awe.mavlink.params.from_wire`), not as the float32 that carried
it. Without a vehicle the parameter list is empty.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from pymavlink.dialects.v20 import common as mav

from .params import ParamStore, from_wire, param_text

if TYPE_CHECKING:  # pragma: no cover
    from .endpoint import MavlinkEndpoint


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

    def __init__(self, ep: "MavlinkEndpoint") -> None:
        self._ep = ep
        self.queue: list[int] = []

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
                       float(ps[name]), mav.MAV_PARAM_TYPE_REAL32, len(ps), index)

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
            ep.warn(f"MAVLink: PARAM_SET refused: {why}")
            ep.statustext(why, mav.MAV_SEVERITY_WARNING)
        self._send(ps, ps.index(name))
