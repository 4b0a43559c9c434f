"""MAVLink link to ground stations (MAVProxy, QGroundControl).

- :mod:`fdm_awe.mavlink.vehicle`: Telemetry, Waypoint, VehicleInterface, mode table.
- :mod:`fdm_awe.mavlink.params`: ParamStore (named parameters, ranges, callbacks, file).
- :mod:`fdm_awe.mavlink.geo`: local NED <-> lat/lon/alt about a home.
- :mod:`fdm_awe.mavlink.endpoint`: MavlinkEndpoint (imports pymavlink; import it only
  when a link is wanted), with :mod:`~fdm_awe.mavlink.winch` (the winch component),
  :mod:`~fdm_awe.mavlink.messages` (standard streams), :mod:`~fdm_awe.mavlink.statustext`
  and :mod:`~fdm_awe.mavlink.signing` (MAVLink 2 signing, key files).
"""

from fdm_awe.mavlink.geo import GeoFrame, Home
from fdm_awe.mavlink.params import Param, ParamStore
from fdm_awe.mavlink.vehicle import (MODE_NAMES, MODE_NUMBERS, PHASE_CODES, Telemetry,
                                     VehicleInterface, Waypoint)

__all__ = ["GeoFrame", "Home", "Param", "ParamStore", "MODE_NAMES", "MODE_NUMBERS",
           "PHASE_CODES", "Telemetry", "VehicleInterface", "Waypoint"]
