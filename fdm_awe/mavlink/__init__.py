"""MAVLink link to ground stations (MAVProxy, MAVSDK, QGroundControl): an ArduPlane-like vehicle.

- :mod:`fdm_awe.mavlink.vehicle`: Telemetry, the wire's phase codes, RTL and the forced disarm; the
  vehicle interface (Waypoint, VehicleInterface) is the autopilot's (:mod:`fdm_awe.autopilot.vehicle`),
  the mode table :mod:`fdm_awe.mode_table`.
- :mod:`fdm_awe.mavlink.params`: the wire's float32 values of the autopilot's ParamStore
  (:mod:`fdm_awe.autopilot.params`: named parameters, ranges, callbacks, file).
- :mod:`fdm_awe.mavlink.geo`: local NED <-> lat/lon/alt about a home.
- :mod:`fdm_awe.mavlink.endpoint`: MavlinkEndpoint, the link and its update loop (imports
  pymavlink; import it only when a link is wanted), with one module per protocol:
  :mod:`~fdm_awe.mavlink.streams` (stream rates and schedule), :mod:`~fdm_awe.mavlink.messages`
  (what each stream says), :mod:`~fdm_awe.mavlink.commands` (COMMAND_LONG/INT, SET_MODE),
  :mod:`~fdm_awe.mavlink.mission` (mission download/upload),
  :mod:`~fdm_awe.mavlink.param_protocol` (parameters on the link), :mod:`~fdm_awe.mavlink.ftp`
  (MAVFTP NAK), :mod:`~fdm_awe.mavlink.link` (the endpoint as the protocol modules use it, a typed
  Protocol), :mod:`~fdm_awe.mavlink.transport` (the connection, read fairly; a TCP
  server for several ground stations; a tcp client tried once, bounded in time),
  :mod:`~fdm_awe.mavlink.framing` (datagram and stream parsing),
  :mod:`~fdm_awe.mavlink.winch` (the winch component), :mod:`~fdm_awe.mavlink.statustext`,
  :mod:`~fdm_awe.mavlink.pilot` (RC_CHANNELS_OVERRIDE, MANUAL_CONTROL: the pilot's sticks)
  and :mod:`~fdm_awe.mavlink.signing` (MAVLink 2 signing, key files).
- :mod:`fdm_awe.mavlink.boot`: the heartbeat sent while the flight loads.
"""

from fdm_awe.autopilot.params import Param, ParamStore
from fdm_awe.autopilot.vehicle import VehicleInterface, Waypoint
from fdm_awe.mavlink.geo import GeoFrame, Home
from fdm_awe.mavlink.vehicle import PHASE_CODES, Telemetry
from fdm_awe.mode_table import MODE_NAMES, MODE_NUMBERS

__all__ = ["GeoFrame", "Home", "Param", "ParamStore", "MODE_NAMES", "MODE_NUMBERS",
           "PHASE_CODES", "Telemetry", "VehicleInterface", "Waypoint"]
