"""The pilot's sticks over MAVLink: RC_CHANNELS_OVERRIDE and MANUAL_CONTROL, as in ArduPilot SITL.

Both drive the vehicle's ``set_pilot(aileron, elevator, rudder, throttle)`` (the autopilot's
:meth:`~fdm_awe.autopilot.vehicle_commands.VehicleCommands.set_pilot`: MANUAL flies the sticks
as surfaces and throttle, FBWA as bank, angle of attack and throttle).

``RC_CHANNELS_OVERRIDE`` (MAVProxy's ``rc 1 1600``), ArduPlane's channel order and senses:
channel 1 roll (high PWM = roll right), 2 pitch (high = pulled back: nose up), 3 throttle
(1000..2000 us = 0..1), 4 yaw (high = nose right); 1500 us centred, +-500 us full. A channel of
0 or 65535 is released (centred; the throttle closed), as are all of them :data:`OVERRIDE_TIMEOUT_S`
(wall clock) after the last override, ArduPilot's ``RC_OVERRIDE_TIME`` default.

``MANUAL_CONTROL`` (MAVSDK's manual_control, a joystick): ``x`` pitch (+1000 = stick forward,
nose down), ``y`` roll (+ right), ``z`` throttle (0..1000), ``r`` yaw (+ right); released like
the override.
"""

from __future__ import annotations

import math
from typing import Any

from .link import Link


#: the sticks are released this long (wall clock, s) after the last override or manual control
OVERRIDE_TIMEOUT_S = 3.0

_RELEASED = (0, 65535)


def _stick(pwm: int) -> float:
    """A centred channel's PWM (us) as -1..1 (0 when released)."""
    return 0.0 if pwm in _RELEASED else min(max((pwm - 1500) / 500.0, -1.0), 1.0)


def _throttle(pwm: int) -> float:
    """The throttle channel's PWM (us) as 0..1 (closed when released)."""
    return 0.0 if pwm in _RELEASED else min(max((pwm - 1000) / 1000.0, 0.0), 1.0)


def _axis(v: float, scale: float = 1000.0) -> float:
    """A MANUAL_CONTROL axis as -1..1 (0 for a value that is not finite)."""
    v = float(v)
    return min(max(v / scale, -1.0), 1.0) if math.isfinite(v) else 0.0


class PilotInput:
    """Passes the ground station's sticks to ``ep``'s vehicle (see module doc).

    Attributes:
        last: wall-clock time of the last override or manual control (-inf: none held).
    """

    def __init__(self, ep: Link) -> None:
        self._ep = ep
        self.last = -math.inf

    def _set(self, aileron: float, elevator: float, rudder: float, throttle: float) -> None:
        v = self._ep.vehicle
        fn = getattr(v, "set_pilot", None)
        if fn is None:
            return
        fn(aileron, elevator, rudder, throttle)
        self.last = self._ep.clock()

    def on_rc_override(self, m: Any) -> None:
        """RC_CHANNELS_OVERRIDE addressed to this vehicle: channels 1-4 as the sticks."""
        if m.target_system not in (0, self._ep.sysid):
            return
        # elevator > 0 is nose down, rudder > 0 nose left (Surfaces' signs)
        self._set(_stick(m.chan1_raw), -_stick(m.chan2_raw), -_stick(m.chan4_raw), _throttle(m.chan3_raw))

    def on_manual_control(self, m: Any) -> None:
        """MANUAL_CONTROL addressed to this vehicle: x, y, z, r as the sticks."""
        if m.target not in (0, self._ep.sysid):
            return
        self._set(_axis(m.y), _axis(m.x), -_axis(m.r), max(_axis(m.z), 0.0))

    def check_timeout(self, now: float) -> None:
        """Release the sticks (centred, throttle closed) :data:`OVERRIDE_TIMEOUT_S` after the
        last input (``now``: wall clock, s)."""
        if now - self.last > OVERRIDE_TIMEOUT_S:
            self.last = -math.inf
            fn = getattr(self._ep.vehicle, "set_pilot", None)
            if fn is not None:
                fn(0.0, 0.0, 0.0, 0.0)
            self._ep.info("MAVLink: pilot sticks released (no override for "
                          f"{OVERRIDE_TIMEOUT_S:g} s)")
