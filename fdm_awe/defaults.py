"""The one table of defaults of every command and of the Python API (docs/design.md section 1).

Every command's options and every keyword of :mod:`fdm_awe.api` that says "default" take its
value from here; ``tests/test_defaults.py`` checks that each command's ``--help`` shows these
numbers. Why these values:

- ``scenario`` physical: the plant that is flown (JSBSim propeller, ground station, sized line);
  the ``paper`` scenario reproduces the published numbers and is chosen explicitly.
- ``config`` nominal: in the physical scenario the foldable glider's folded recovery needs
  thrust against the line drag, so its cycle loses more than the nominal one on the sized line,
  and on Table 1's line it has no periodic cycle (:data:`NOMINAL_WHY`).
- ``wind`` 8 m/s from the south: the lowest wind at which the nominal cycle of the physical
  scenario gains energy (README, the physical scenario's table), and the wind of the stored
  example references. The paper's Table 3 setting (3 m/s) is a documented option
  (``fdm-awe compare --scenario paper --wind 3``), not a default.
- Bounds: Table 3's (airspeed 5..25 m/s, ground clearance 10 m, cycle at most 60 s) on the
  reel-out range 200..250 m. A reference that is flown (``fdm-awe fly`` optimising its own,
  ``fdm-awe optimize --flyable``, ``fdm_awe.optimize(flyable=True)``) keeps the flyable margins
  on top: C_L at most :data:`FLYABLE_CL_MARGIN` of C_Lmax, the tension at most the rating /
  (1 + :data:`FLYABLE_TENSION_MARGIN`) and the bank at most :data:`FLYABLE_PHI_MAX` rad, leaving
  the autopilot room to correct and the winch room for the catch and gusts.

Plain constants only: importing this module imports nothing else.
"""

from __future__ import annotations

#: model family: ``physical`` or ``paper`` (docs/design.md section 4)
SCENARIO = "physical"
#: glider configuration: ``nominal`` (never folds) or ``foldable`` (folds for recovery)
CONFIG = "nominal"
#: wind speed at the reference height [m/s]
WIND_MPS = 8.0
#: direction the wind blows FROM [deg, compass] (180 = from the south, the paper's)
WIND_FROM_DEG = 180.0
#: tether length at the cycle start [m]
D0_M = 200.0
#: tether length at the end of generation [m]
D_TF_M = 250.0
#: airspeed bounds [m/s] (Table 3)
V_MIN_MPS = 5.0
V_MAX_MPS = 25.0
#: ground clearance [m]
H_MIN_M = 10.0
#: longest cycle T1 + T2 [s] (Table 3)
T_MAX_S = 60.0
#: factor on the line drag (1 = the defined line)
TETHER_DRAG_SCALE = 1.0
#: flyable margins of a reference that is flown: share of C_Lmax kept unused [-], tension margin
#: below the 50 N rating (the cycle's tension at most rating / (1 + margin)) [-], usable share
#: of C_Lmax [-] and bank bound [rad] (why these: FLY_TENSION_MARGIN of fdm_awe/commands/_fly_optimise.py)
FLYABLE_STALL_MARGIN = 0.15
FLYABLE_TENSION_MARGIN = 0.25
FLYABLE_CL_MARGIN = 1.0 - FLYABLE_STALL_MARGIN
FLYABLE_PHI_MAX = 0.8
#: pumping cycles of a flight
CYCLES = 3
#: co-simulation step [s]
DT_S = 1.0 / 120.0
#: the line model of the ground station in a flight
TETHER = "straight"
#: wind speeds of a sweep [m/s] (START:STOP:STEP)
SWEEP_WINDS = "3:12:1"
#: configurations of a sweep and of ``compare``
SWEEP_CONFIGS = "nominal,foldable"

#: Why the default configuration is ``nominal`` (help texts of ``optimize`` and ``fly``).
NOMINAL_WHY = ("default nominal: in the physical scenario the foldable glider's folded recovery needs thrust "
               "against the line drag, so its cycle loses more than the nominal one on the sized line, and on "
               "Table 1's line it has no periodic cycle")

#: The table by option name (``--wind`` -> value) for the options every command shares, as the
#: commands' help texts show them; the help test reads it.
TABLE: dict[str, object] = {
    "--scenario": SCENARIO,
    "--config": CONFIG,
    "--wind": WIND_MPS,
    "--wind-from": WIND_FROM_DEG,
    "--d0": D0_M,
    "--d-tf": D_TF_M,
    "--v-min": V_MIN_MPS,
    "--v-max": V_MAX_MPS,
    "--h-min": H_MIN_M,
    "--t-max": T_MAX_S,
    "--tether-drag-scale": TETHER_DRAG_SCALE,
    "--cycles": CYCLES,
}

__all__ = ["CONFIG", "CYCLES", "D0_M", "DT_S", "D_TF_M", "FLYABLE_CL_MARGIN", "FLYABLE_PHI_MAX",
           "FLYABLE_STALL_MARGIN", "FLYABLE_TENSION_MARGIN", "H_MIN_M",
           "NOMINAL_WHY", "SCENARIO", "SWEEP_CONFIGS", "SWEEP_WINDS", "TABLE", "TETHER", "TETHER_DRAG_SCALE",
           "T_MAX_S", "V_MAX_MPS", "V_MIN_MPS", "WIND_FROM_DEG", "WIND_MPS"]
