"""Ground station: tether, winch, DC machine behind an asymmetric half-bridge, PI speed loop.

Paper section II-C (eqs. 14-19, Table 1) with docs/design.md's corrections (Coulomb friction once).
Modules, one job each:

- :mod:`.definitions` -- ``tether/ground_station.xml`` -> typed SI dataclasses
- :mod:`.tether` -- line geometry, elastic tension, drag and weight shares on the glider
- :mod:`.linemodels` -- the line models, one registry entry each (``--tether``), and their one parser
- :mod:`.lumped` -- the lumped-mass line (``tether="lumped:N"``): nodes, segments, its own ledger
- :mod:`.lumped_state` -- the lumped line's place in the state and constants arrays, its views
- :mod:`.winch` -- drum equation (eq. 14) with implicit set-valued Coulomb friction
- :mod:`.machine` -- armature equation (eqs. 15, 16, 18, 19) and the eq. 17 mode rule
- :mod:`.converter` -- averaged asymmetric half-bridge (generator: rectifier/boost; motor: PWM, current limit)
- :mod:`.controller` -- PI of the T1 duty with limits and anti-windup
- :mod:`.drivetrain` -- the coupled implicit sub-step integrator
- :mod:`.substeps` -- the step and its relations, written once (numba compiles it when available)
- :mod:`.ledger` -- energy ledger
- :mod:`.station` -- ``GroundStation.step`` co-simulation interface
- :mod:`.station_output` -- the output of one step, built by the Python step or filled from a compiled row
- :mod:`.steady` -- steady-state relations for NumPy and CasADi (OCP)
"""

from .definitions import GroundStationParams, load_ground_station
from .ledger import EnergyLedger
from .station import GroundStation, WinchCommand
from .station_output import GroundStationOutput
from .steady import generator_at_speed, generator_steady, motor_steady

__all__ = [
    "EnergyLedger",
    "GroundStation",
    "GroundStationOutput",
    "GroundStationParams",
    "WinchCommand",
    "generator_at_speed",
    "generator_steady",
    "load_ground_station",
    "motor_steady",
]
