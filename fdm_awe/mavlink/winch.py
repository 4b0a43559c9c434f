"""The winch as its own MAVLink component (``MAV_COMP_ID_WINCH`` = 169).

The ground station's winch is a separate device on the vehicle's MAVLink network, as on a
real installation: it has its own component id, its own HEARTBEAT (``MAV_TYPE_WINCH``,
``MAV_AUTOPILOT_INVALID``: a component without an autopilot) and sends ``WINCH_STATUS``:

=============  =====================================================================
line_length    unstretched line paid out, m
speed          reel speed, m/s (+ = paid out, - = reeled in)
tension        line tension at the drum, kg (MAVLink's unit: newtons / 9.80665)
voltage        DC-link voltage of the winch converter, V
current        machine (armature) current, A
temperature    INT16_MAX (not simulated)
status         ``MAV_WINCH_STATUS_FLAG`` bits: HEALTHY (line intact), FULLY_RETRACTED,
               MOVING (|speed| > :data:`MOVING_MPS`), RETRACTING (reeling in faster than
               that), CLUTCH_ENGAGED (the machine drives or brakes the drum: generator or
               motor, not idle)
=============  =====================================================================

Unknown values go out as NaN, as the message definition asks. The component shares the
vehicle's connection and system id; it is a second pymavlink encoder whose source component
is 169 (signed with the vehicle's key when signing is on). Commands addressed to it are
answered by it: ``MAV_CMD_REQUEST_MESSAGE`` for WINCH_STATUS or HEARTBEAT is accepted,
every other command is ``MAV_RESULT_UNSUPPORTED`` (the winch follows the autopilot's phase
logic, not direct commands).
"""

from __future__ import annotations

import math
from typing import Any

from pymavlink.dialects.v20 import common as mav

from ..constants import G0
from .link import Link
from .vehicle import Telemetry


#: MAVLink component id of the winch
WINCH_COMPID = mav.MAV_COMP_ID_WINCH
#: standard gravity: WINCH_STATUS gives the tension in kg
#: reel speed above which the winch counts as moving, m/s
MOVING_MPS = 0.05

_INT16_MAX = 32767
# flags of MAV_WINCH_STATUS_FLAG (common.xml); not every pymavlink release names all of them
_HEALTHY = mav.MAV_WINCH_STATUS_HEALTHY
_FULLY_RETRACTED = mav.MAV_WINCH_STATUS_FULLY_RETRACTED
_MOVING = mav.MAV_WINCH_STATUS_MOVING
_CLUTCH_ENGAGED = mav.MAV_WINCH_STATUS_CLUTCH_ENGAGED
_RETRACTING = getattr(mav, "MAV_WINCH_STATUS_RETRACTING", 256)


def _num(x: Any) -> float:
    try:
        v = float(x)
    except (TypeError, ValueError):
        return math.nan
    return v if math.isfinite(v) else math.nan


def winch_flags(tel: Telemetry) -> int:
    """``MAV_WINCH_STATUS_FLAG`` bits of a telemetry snapshot (see module doc)."""
    flags = 0
    if tel.winch_ok:
        flags |= _HEALTHY
    if tel.line_fully_in:
        flags |= _FULLY_RETRACTED
    v = _num(tel.reel_speed_mps)
    if abs(v) > MOVING_MPS:
        flags |= _MOVING
        if v < 0:
            flags |= _RETRACTING
    if tel.winch_mode in ("generator", "motor"):
        flags |= _CLUTCH_ENGAGED
    return flags


class WinchComponent:
    """The winch's MAVLink identity on the vehicle's connection (see module doc).

    Args:
        conn: the pymavlink transport the vehicle endpoint opened.
        sysid: the vehicle's system id.
    """

    def __init__(self, conn: Any, sysid: int) -> None:
        self.sysid = sysid
        self.compid = WINCH_COMPID
        self.mav = mav.MAVLink(conn, srcSystem=sysid, srcComponent=WINCH_COMPID)

    def send_heartbeat(self, ep: Link, tel: Telemetry) -> None:
        status = mav.MAV_STATE_ACTIVE if tel.winch_ok else mav.MAV_STATE_CRITICAL
        ep.send("HEARTBEAT_WINCH", self.mav.heartbeat_send, mav.MAV_TYPE_WINCH,
                 mav.MAV_AUTOPILOT_INVALID, 0, 0, status)

    def send_status(self, ep: Link, tel: Telemetry, t: float) -> None:
        us = int(min(max(_num(t), 0.0) * 1e6, 2.0**63)) if math.isfinite(_num(t)) else 0
        tension = _num(tel.tension_N)
        ep.send("WINCH_STATUS", self.mav.winch_status_send, us, _num(tel.line_length_m),
                 _num(tel.reel_speed_mps), tension / G0 if math.isfinite(tension) else math.nan,
                 _num(tel.winch_voltage_V), _num(tel.winch_current_A), _INT16_MAX, winch_flags(tel))

    def on_command(self, ep: Link, m: Any, p: tuple[float, ...]) -> None:
        """Answer a COMMAND_LONG/COMMAND_INT addressed to the winch (see module doc)."""
        after = None
        result = mav.MAV_RESULT_UNSUPPORTED
        if m.command == mav.MAV_CMD_REQUEST_MESSAGE:
            mid = _num(p[0])
            if mid == mav.MAVLINK_MSG_ID_WINCH_STATUS:
                result = mav.MAV_RESULT_ACCEPTED
                after = lambda: self.send_status(ep, ep.telemetry(), ep.t_now)  # noqa: E731
            elif mid == mav.MAVLINK_MSG_ID_HEARTBEAT:
                result = mav.MAV_RESULT_ACCEPTED
                after = lambda: self.send_heartbeat(ep, ep.telemetry())  # noqa: E731
        ep.send("COMMAND_ACK", self.mav.command_ack_send, m.command, result, 0, 0,
                 m.get_srcSystem(), m.get_srcComponent())
        if after is not None:
            after()
