"""The autopilot's modes and their numbers.

Each mode has a number, the ``custom_mode`` a ground station sees in HEARTBEAT and sends in
``DO_SET_MODE`` / ``SET_MODE`` (:mod:`fdm_awe.mavlink` carries it). Where the meaning matches,
the number is ArduPlane's, because MAVProxy and other ArduPilot-aware tools name a fixed-wing
vehicle's ``custom_mode`` with ArduPlane's table: MANUAL shows as ``MANUAL``, AUTO as ``AUTO``
and RECOVER (the safe abort: brake the drum, reel in the slack, circle down and land at the winch
or park in a hold) as ``RTL``.
"""

from __future__ import annotations

from fdm_awe.errors import InputError

__all__ = ["MODE_NAMES", "MODE_NUMBERS", "mode_number"]

#: Mode name -> MAVLink ``custom_mode`` number (ArduPlane numbering where meanings match).
MODE_NUMBERS: dict[str, int] = {
    "MANUAL": 0,     # surfaces/throttle straight from the pilot (or held neutral)
    "FBWA": 5,       # stabilised attitude, no path following
    "AUTO": 10,      # fly the mission (reference path) and run the pumping cycle
    "RECOVER": 11,   # safe abort: reel in, circle down, land or park (shown as RTL)
    "LOITER": 12,    # circle on the tether at constant length
    "GUIDED": 15,    # hold the current point of the path
}

#: ``custom_mode`` number -> mode name.
MODE_NAMES: dict[int, str] = {v: k for k, v in MODE_NUMBERS.items()}


def mode_number(name: str) -> int:
    """``custom_mode`` number of a mode name; InputError for a name not in MODE_NUMBERS."""
    try:
        return MODE_NUMBERS[name]
    except KeyError:
        raise InputError(
            f"mode {name!r}: unknown; allowed: {', '.join(MODE_NUMBERS)}") from None
