"""What a reference-trajectory file holds and allows: its format name and version, the phases of
a cycle, the columns with their units and allowed ranges, the metadata's vocabularies (scenario,
configuration, propeller model, generator load; the optimiser's options use the same) and limits (the file
format is described in :mod:`fdm_awe.trajectory`)."""

from __future__ import annotations

import math

#: Phase names of a cycle, indexed by phase code (metadata ``phase_names``)
PHASE_NAMES = ("generation", "recovery")
#: Phase codes (column ``phase``)
GENERATION, RECOVERY = 0, 1

SCENARIOS = ("physical", "paper")
CONFIGS = ("nominal", "foldable")
#: propeller models of the physical scenario: the 6-DOF glider's own drive from the engine files
#: (fdm_awe.pointmass.propeller.power_engine, its default) or momentum theory + efficiencies
PROPELLERS = ("momentum", "engine")
#: generator loads of the physical scenario's generation phase (docs/design.md section 6):
#: ``passive``, the passive rectifier into the load resistor (T2 off, the paper's choice; the
#: tension follows the reel speed, about 8 N per m/s); ``boost``, the T2 duty of the asymmetric
#: half-bridge (eq. 18) as a bounded control, which scales the load the armature sees to
#: ``(1 - d2)^2 R_L`` and so chooses the tension at a given speed, paying its copper and device
#: losses; ``ideal``, a loss-free current-controlled converter that holds any tension within the
#: bounds (the machine's copper, device and friction losses kept): the physical counterpart of the
#: paper's free tension, an upper bound the half-bridge cannot reach, so it cannot be flown
GENERATORS = ("passive", "boost", "ideal")
#: generator loads a flight's ground station can realise
FLYABLE_GENERATORS = ("passive", "boost")

FORMAT = "fdm-awe-reference-trajectory"
VERSION = 1

COLUMN_UNITS = {
    "t": "s", "phase": "-", "x": "m", "y": "m", "z": "m", "V": "m/s", "gamma": "rad", "psi": "rad",
    "alpha": "rad", "phi": "rad", "T": "N", "tension": "N", "tether_length": "m", "reel_speed": "m/s",
    "fold": "-", "p_generated_W": "W", "p_thrust_W": "W", "p_reel_in_W": "W",
}
#: Columns a reference may carry beyond the required :data:`COLUMN_UNITS` (absent: the default)
OPTIONAL_COLUMN_UNITS = {"motor_on": "-", "boost_duty": "-"}

#: Largest reference file read [bytes] (a 60 s cycle on the default mesh is about 100 kB).
MAX_FILE_BYTES = 64 * 2**20
#: Allowed values of the columns: ``(lo, hi, lo_open)`` SI, or ``None`` for any finite number.
#: Bounds that the optimiser meets only up to its constraint tolerance get a relative slack of
#: :data:`SLACK` (of the column's largest magnitude); open lower bounds (airspeed, line length)
#: get none.
COLUMN_RANGES: dict[str, tuple[float, float, bool] | None] = {
    "t": None, "phase": (0.0, 1.0, False), "x": (-1e4, 1e4, False), "y": (-1e4, 1e4, False), "z": (-1e4, 0.0, False),
    "V": (0.0, 100.0, True), "gamma": (-math.pi / 2, math.pi / 2, False), "psi": None,
    "alpha": (-math.pi / 2, math.pi / 2, False), "phi": (-math.pi / 2, math.pi / 2, False), "T": (0.0, 1e3, False),
    "tension": (0.0, 1e4, False), "tether_length": (0.0, 1e4, True), "reel_speed": (-100.0, 100.0, False),
    "fold": (0.0, 1.0, False), "p_generated_W": None, "p_thrust_W": None, "p_reel_in_W": None,
    "motor_on": (0.0, 1.0, False), "boost_duty": (0.0, 1.0, False),
}
SLACK = 1e-6
#: Relative tolerance of the time relations (t ends at T1 + T2, the phase switch at T1, period_s).
TIME_RTOL = 1e-6
#: Periodicity of a reference: the largest difference allowed between a state column's last row
#: (the cycle's end, ``t = T1 + T2``) and its first (``t = 0``), SI units. What the optimiser
#: guarantees: it accepts a cycle only when every constraint row holds within 1e-6
#: (``fdm_awe.ocp.assemble.VIOLATION_TOL``), and its rows divide the position and the line length
#: by 100 m, the airspeed by 10 m/s and the angles by 1 rad (``fdm_awe.ocp.layout.STATE_SCALE``).
#: Each end coordinate is tied to the fixed start position by one row and the first row's by
#: another: 2 x 1e-6 x 100 m. The line length ends at ``d0`` by one row (1e-6 x 100 m) and
#: starts at the first point's distance from the winch, whose three coordinates are each within
#: 1e-6 x 100 m of the start position on the ``d0`` sphere (sqrt(3) x 1e-6 x 100 m). Airspeed,
#: flight-path angle and heading (after ``2 pi k_wrap``, metadata) are tied to the first row by
#: one row each: 1e-6 x 10 m/s and 1e-6 rad. The file stores the numbers exactly (JSON round
#: trip), so the guarantee is the tolerance; tests/test_trajectory_files.py ties these numbers to
#: the optimiser's.
PERIODIC_TOL = {"x": 2e-4, "y": 2e-4, "z": 2e-4, "tether_length": (1.0 + math.sqrt(3.0)) * 1e-4, "V": 1e-5,
                "gamma": 1e-6, "psi": 1e-6}
#: Continuity of the path: the position may move between consecutive rows at most
#: ``CONTINUITY_FACTOR x (largest airspeed of the V column + largest wind along the path) x dt``
#: plus :data:`CONTINUITY_ATOL` [m]. The ground speed is the airspeed plus the wind, so a
#: collocated path never moves faster; the factor leaves room for the airspeed between rows
#: exceeding the rows' largest (the stored references of tests/data move at most 0.98 of the
#: bound), the absolute term for the phase switch, where the time repeats and the position is
#: tied across it by the optimiser's continuity rows (1e-6 x 100 m per coordinate).
CONTINUITY_FACTOR = 1.25
CONTINUITY_ATOL = 2e-4
#: Wind speed range of a reference [m/s] (the optimiser's, :class:`fdm_awe.ocp.problem.CycleProblem`).
WIND_MAX = 25.0
#: Longest phase of a reference [s].
PHASE_MAX_S = 3600.0
#: Configuration -> airframe of its recovery phase (metadata ``recovery_airframe``).
RECOVERY_AIRFRAME = {"foldable": "folded", "nominal": "unfolded"}
