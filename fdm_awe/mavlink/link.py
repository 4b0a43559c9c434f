"""The link as the protocol modules see it: :class:`Link`, what they use of the endpoint.

The protocol modules (:mod:`~fdm_awe.mavlink.commands`, :mod:`~fdm_awe.mavlink.mission`,
:mod:`~fdm_awe.mavlink.param_protocol`, :mod:`~fdm_awe.mavlink.messages`,
:mod:`~fdm_awe.mavlink.streams`, :mod:`~fdm_awe.mavlink.statustext`,
:mod:`~fdm_awe.mavlink.winch`, :mod:`~fdm_awe.mavlink.pilot`, :mod:`~fdm_awe.mavlink.ftp`,
:mod:`~fdm_awe.mavlink.signing`) are handed the endpoint and use it only through these members;
:class:`~fdm_awe.mavlink.endpoint.MavlinkEndpoint` is the one implementation (tests/test_structure.py
checks both sides).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable, Protocol, runtime_checkable

if TYPE_CHECKING:  # pragma: no cover
    from .geo import GeoFrame
    from .signing import Signer
    from .streams import StreamSchedule
    from .vehicle import Telemetry
    from ..autopilot.vehicle import VehicleInterface
    from .winch import WinchComponent


@runtime_checkable
class Link(Protocol):
    """The vehicle's end of a MAVLink link, as its protocol modules use it."""

    # identity, frame, vehicle
    sysid: int  #: this vehicle's MAVLink system id
    geo: GeoFrame  #: local NED <-> lat/lon/alt about the home
    vehicle: VehicleInterface | None  #: the autopilot (None: telemetry only)
    # the connection's parts
    mav: Any  #: the MAVLink codec: its ``*_send`` encoders write to the connection
    winch: WinchComponent  #: the winch component (its own component id)
    streams: StreamSchedule  #: the telemetry streams' rates and schedule
    signer: Signer  #: MAVLink 2 signing of the link
    signing_key_file: Any  #: where a key set with SETUP_SIGNING is saved (None: kept in memory)
    stats: dict[str, Any]  #: the link's counters (sent, errors, signing, ...)
    # time
    clock: Callable[[], float]  #: wall clock of the timeouts (monotonic seconds)
    t_now: float  #: simulation time of the last update [s]
    # the flight's end
    flight_over: bool  #: the simulation has stopped: the commands that would fly are refused
    shutdown_requested: bool  #: a ground station asked the program to end (after the flight)
    # protocol limits
    max_mission_items: int  #: largest mission accepted
    max_range_m: float  #: largest horizontal distance of a waypoint from home [m]
    mission_retries: int  #: re-requests of a mission item
    mission_timeout_s: float  #: mission-upload item timeout (wall clock) [s]
    param_burst: int  #: PARAM_VALUE messages sent per update while streaming the list

    @property
    def link_lost(self) -> bool:
        """A ground station was linked and is not any more."""

    def telemetry(self) -> Telemetry:
        """The telemetry of this update."""

    def for_me(self, m: Any) -> bool:
        """Is ``m`` addressed to this vehicle (or broadcast)?"""

    def send(self, name: str, fn: Callable[..., None], *args: Any) -> None:
        """Call the encoder ``fn(*args)``, counted under ``name``; a failure is counted, never raised."""

    def set_rate(self, stream: str, hz: float) -> None:
        """Set a stream's rate (Hz of simulation time, 0 = off); InputError if invalid."""

    def statustext(self, text: str, severity: int = ...) -> None:
        """Send ``text`` to the ground stations (STATUSTEXT, in chunks)."""

    def wake(self) -> None:
        """Have the next update do its work, whatever its time (a rate changed, a list to stream)."""

    def info(self, msg: str) -> None:
        """Log ``msg``."""

    def warn(self, msg: str, limit: bool = True) -> None:
        """Log ``msg`` as a warning (with ``limit`` at most once per 5 s of wall time)."""
