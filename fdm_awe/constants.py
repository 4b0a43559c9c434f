"""Physical constants of the package, one value each (SI).

The 6-DOF model flies in JSBSim's atmosphere and gravity; the optimiser, the point-mass model,
the autopilot's guidance and the line's weight and drag use these values, so that both sides
agree where they must:

- ``G0``   standard gravity, 9.80665 m/s^2 (the ISA's and JSBSim's sea-level reference:
  ``FGInertial``'s GM / R^2 = 32.174 ft/s^2); also MAVLink's unit of the load factor.
- ``RHO0`` ISA sea-level air density, 1.225 kg/m^3 (JSBSim's 0.0023769 slug/ft^3).
"""

from __future__ import annotations

G0: float = 9.80665  #: m/s^2, standard gravity
RHO0: float = 1.225  #: kg/m^3, ISA sea-level air density

__all__ = ["G0", "RHO0"]
