"""The autopilot's mode numbers: the one table, plain constants below every layer.

The autopilot (:mod:`fdm_awe.autopilot.modes`, which also names and checks modes), the MAVLink
vehicle and the recording's mode lane all read it here, so the recording can show the modes
without importing the autopilot (tests/test_layers.py). Why these numbers:
:mod:`fdm_awe.autopilot.modes`.
"""

from __future__ import annotations

__all__ = ["MODE_NAMES", "MODE_NUMBERS"]

#: Mode name -> MAVLink ``custom_mode`` number (ArduPlane numbering where meanings match).
MODE_NUMBERS: dict[str, int] = {
    "MANUAL": 0,     # surfaces/throttle straight from the pilot (or held neutral)
    "FBWA": 5,       # stabilised attitude, no path following
    "AUTO": 10,      # fly the mission (reference path) and run the pumping cycle
    "RECOVER": 11,   # safe abort: reel in, circle down, land or park (shown as RTL)
    "LOITER": 12,    # hold: RECOVER's circle about the winch, parked, never landing
    "GUIDED": 15,    # not offered (refused with its reason)
}

#: ``custom_mode`` number -> mode name.
MODE_NAMES: dict[int, str] = {v: k for k, v in MODE_NUMBERS.items()}
