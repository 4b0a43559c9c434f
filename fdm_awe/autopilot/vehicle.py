"""What the autopilot offers a ground station: its vehicle interface, its path points and phases.

``Waypoint``
    One point of the reference path: ``north, east, down`` in metres relative to the
    winch, optionally the reference time within the cycle ``time_s`` and the cycle
    ``phase``. A path uploaded from a ground station arrives with ``time_s = phase = None``
    (a MAVLink mission item carries neither) and the autopilot decides how to time it (or
    rejects it through ``set_mission``); its own path uploaded back keeps its reference.

``VehicleInterface``
    The protocol the autopilot implements so a ground station can command it::

        modes: list[str]                 # names from MODE_NUMBERS, incl. MANUAL, AUTO, RECOVER
        mode: str                        # current mode name
        set_mode(name) -> bool           # False = refused (stays in the old mode)
        armed: bool
        arm(on: bool, force=False) -> bool  # False = refused (a disarm in flight unless forced)
        cycling: bool                    # pumping cycles running
        start_cycling() -> bool
        stop_cycling() -> bool
        mission() -> list[Waypoint]      # the loaded reference path
        set_mission(wps) -> (ok, reason) # validate + load; reason says why not ("own path":
                                         # the vehicle's own path back, its cycle kept)
        clear_mission() -> None
        params: ParamStore               # gains etc.; a change calls their callbacks
        set_pilot(aileron, elevator, rudder, throttle)  # optional: the pilot's sticks (MANUAL, FBWA)

    The MAVLink endpoint (:mod:`fdm_awe.mavlink`) adapts to it: every method is called from
    inside ``MavlinkEndpoint.update`` (the simulation thread), so no locking is needed; a method
    that raises is answered to the ground station as a failure and logged, it never stops the
    simulation.

Modes and their numbers: :mod:`fdm_awe.autopilot.modes`; parameters:
:mod:`fdm_awe.autopilot.params`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

from fdm_awe.autopilot.params import ParamStore
from fdm_awe.errors import InputError

__all__ = ["PHASES", "VehicleInterface", "Waypoint"]

#: The vehicle's phases (telemetry ``phase``, a waypoint's ``phase``).
PHASES: tuple[str, ...] = ("ground", "generation", "transition", "recovery")


@dataclass(frozen=True)
class Waypoint:
    """A point of the reference path, m relative to the winch (NED).

    ``time_s`` is the reference time within the cycle (s) and ``phase`` the cycle phase
    (one of PHASES); both are optional and are not carried by MAVLink missions.
    """

    north: float
    east: float
    down: float
    time_s: float | None = None
    phase: str | None = None

    def __post_init__(self) -> None:
        for name in ("north", "east", "down"):
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or not math.isfinite(v):
                raise InputError(f"waypoint {name}: {v!r} is not a finite number (m)")
        if self.time_s is not None and not math.isfinite(self.time_s):
            raise InputError(f"waypoint time_s: {self.time_s!r} is not finite (s)")
        if self.phase is not None and self.phase not in PHASES:
            raise InputError(
                f"waypoint phase: {self.phase!r}; allowed: {', '.join(PHASES)}")


@runtime_checkable
class VehicleInterface(Protocol):
    """What a ground station may command; implemented by the autopilot (see module doc)."""

    @property
    def modes(self) -> list[str]: ...

    @property
    def mode(self) -> str: ...

    def set_mode(self, name: str) -> bool: ...

    @property
    def armed(self) -> bool: ...

    def arm(self, on: bool, force: bool = False) -> bool: ...

    @property
    def cycling(self) -> bool: ...

    def start_cycling(self) -> bool: ...

    def stop_cycling(self) -> bool: ...

    def mission(self) -> list[Waypoint]: ...

    def set_mission(self, waypoints: list[Waypoint]) -> tuple[bool, str]: ...

    def clear_mission(self) -> None: ...

    @property
    def params(self) -> ParamStore: ...
