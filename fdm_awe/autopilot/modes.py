"""The autopilot's modes and their numbers.

Each mode has a number, the ``custom_mode`` a ground station sees in HEARTBEAT and sends in
``DO_SET_MODE`` / ``SET_MODE`` (:mod:`fdm_awe.mavlink` carries it). Where the meaning matches,
the number is ArduPlane's, because MAVProxy and other ArduPilot-aware tools name a fixed-wing
vehicle's ``custom_mode`` with ArduPlane's table: MANUAL shows as ``MANUAL``, AUTO as ``AUTO``
RECOVER (the safe abort: brake the drum, reel in the slack, circle down and land at the winch
or park in a hold) as ``RTL`` and LOITER (RECOVER's hold circle about the winch, never landing) as
``LOITER``. The MAVLink link declares the ArduPilot autopilot, so MAVSDK and QGroundControl read the
same table: MAVSDK's flight modes MANUAL, MISSION (AUTO), RETURN_TO_LAUNCH (RTL) and HOLD
(LOITER); its ``hold()`` and ``pause_mission()`` ask for LOITER, ``start_mission()`` for AUTO,
``return_to_launch()`` for RTL.
"""

from __future__ import annotations

from fdm_awe.errors import InputError
from fdm_awe.mode_table import MODE_NUMBERS  # the one table, below every layer that shows modes

__all__ = ["mode_number"]

def mode_number(name: str) -> int:
    """``custom_mode`` number of a mode name; InputError for a name not in MODE_NUMBERS."""
    try:
        return MODE_NUMBERS[name]
    except KeyError:
        raise InputError(
            f"mode {name!r}: unknown; allowed: {', '.join(MODE_NUMBERS)}") from None
