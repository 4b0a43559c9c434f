"""The reference trajectory: one periodic pumping cycle of the optimiser, its file, its phases
and how it is sampled at any time.

Every user of an optimised cycle goes through this package: the optimiser writes the file
(:func:`write_reference`), ``fdm-awe fly`` hands the cycle it optimised to the flight in memory
(:func:`reference_from_result`, the content of the file it would write), the autopilot's
:class:`~fdm_awe.autopilot.tracking.TrackingReference` and the recordings sample it with
:class:`CycleSampler`.

Phases (:data:`PHASE_NAMES`, codes :data:`GENERATION` = 0 and :data:`RECOVERY` = 1): a cycle is
one generation phase from ``t = 0`` to ``T1``, then one recovery phase to ``T1 + T2``.

Reference-trajectory file format (``fdm-awe-reference-trajectory``, version 1), JSON::

    {
      "format": "fdm-awe-reference-trajectory", "version": 1,
      "metadata": {"scenario", "config", "wind_mps", "wind_from_deg", "wind_ned_mps" [3],
                   "d0_m", "d_tf_m", "elevation0_deg", "azimuth0_deg", "T1_s", "T2_s",
                   "period_s", "k_wrap", "mesh": {...}, "energies": {...}, "status",
                   "phase_names": ["generation", "recovery"], "recovery_airframe"},
      "units": {column: unit},
      "columns": {column: [values...]}
    }

Columns (one row per collocation point, rows in time order; the phase switch at ``t = T1``
appears twice, once per phase):

- ``t`` [s] cycle time, 0 .. T1 + T2; ``phase`` 0 = generation, 1 = recovery;
- ``x, y, z`` [m] NED glider position (winch at the origin); ``V`` [m/s] airspeed;
  ``gamma, psi`` [rad] air-path angles (``psi`` continuous, not wrapped);
- ``alpha, phi`` [rad], ``T`` [N] controls (piecewise constant per mesh interval: each row
  carries the value of the interval that starts at or contains it);
- ``tension`` [N] tether tension (in recovery the winch's pull, 0 on a slack line), ``tether_length`` [m], ``reel_speed`` [m/s]
  (> 0 paid out), ``fold`` (0 unfolded, 1 folded);
- ``p_generated_W, p_thrust_W, p_reel_in_W`` [W] the scenario's power terms;
- optional ``motor_on`` (0 .. 1): the motor's on-fraction of the interval (motor-off mode;
  ``T`` is then the mean thrust); absent = 1, the motor runs throughout;
- optional ``boost_duty`` (0 .. 1): the generator's T2 duty of the interval (generator
  ``boost``; 0 in recovery); absent = 0, the passive rectifier.

Metadata: ``scenario`` (physical | paper) and ``config`` (foldable | nominal) are required;
``T1_s``, ``T2_s`` [s] > 0 (at most 3600 each) are required; the wind is given as ``wind_mps``
(0..25 m/s) with ``wind_from_deg``, or as the horizontal vector ``wind_ned_mps``, or both
(then they must agree); ``tether_drag_scale`` (0..10, default 1), ``period_s`` (= T1 + T2),
``status`` (ok), ``recovery_airframe`` (folded for foldable, unfolded for nominal),
``propeller``, ``line_weight``, ``d0_m`` < ``d_tf_m`` are checked when present; ``line`` (the
tether line the cycle was optimised with, :data:`fdm_awe.groundstation.line.LINES`) is checked
when present; absent means ``paper`` (Table 1's line): every file written before lines were
named was optimised with it, and a flight flies it. ``fold_time_s`` [s] (0 .. 60; 0 for the
nominal config) is the fold (and unfold) time the cycle was optimised with; absent means 0, the
instantaneous fold every file written before fold transitions was optimised with.
``motor_off`` (boolean) says whether the optimiser could stop the motor (column ``motor_on``);
absent means false, and then ``motor_on`` (if present) must be 1 throughout. ``generator``
(physical scenario: :data:`fdm_awe.trajectory.schema.GENERATORS`) is the generator load of the
generation phase; absent means ``passive``, and then ``boost_duty`` (if present) must be 0
throughout. ``wind_profile`` (:meth:`fdm_awe.wind.WindProfile.as_dict`: ``kind`` uniform | log |
power, with ``ref_height_m`` and ``z0_m`` or ``exponent``) says how the wind varies with height;
``wind_mps`` / ``wind_ned_mps`` are then the wind at ``ref_height_m``; absent means uniform, the
wind of every file written before profiles existed. ``line_model`` (physical scenario:
:data:`fdm_awe.groundstation.line.LINE_MODELS`) is the optimiser's line model; absent means
``straight``. ``margins`` (an object, :func:`~fdm_awe.trajectory.files.margins_record`:
``tension_rating_N``, ``tension_margin``, ``tension_bound_N``, ``stall_margin``,
``cl_max_share`` and, with a reel-in margin, ``reel_in_speed_max_m_s``; each a number within
:data:`~fdm_awe.trajectory.checks.MARGIN_RANGES`) are the margins the cycle keeps below the
line's rating, the stall and the drive's fastest reel-in; absent in files written before they
were recorded (their ``bounds`` say the same). ``aircraft`` (an object:
:meth:`~fdm_awe.definitions.catalog.Aircraft.record`, ``name`` of the package's aircraft table
or ``directory`` of a definition folder, and ``sha256`` of its files) is the aircraft the
cycle was optimised for; absent in files written before it was recorded (the package's glider).
``fdm-awe fly`` warns when it flies another aircraft. ``ground_station`` (an object:
:meth:`~fdm_awe.groundstation.source.StationFile.record`, ``file`` "default" or the path of a
user's definition, and ``sha256`` of its bytes) is the ground station the cycle was optimised
with; absent in files written before it was recorded (the package's). ``fdm-awe fly`` warns
when it flies another station.

:func:`read_reference` checks a file field by field (:func:`check_reference_document`, then
:func:`check_reference`: every column a list of finite numbers within :data:`COLUMN_RANGES`,
all of one length, at least 2 rows; ``t`` from 0 strictly increasing to T1 + T2 except one
repeated time at the phase switch; ``phase`` 0 then 1 with the switch at T1; ``fold`` 0 for
the nominal config; the ``units`` block required, naming each column's unit as the package
writes it, :data:`COLUMN_UNITS`, no other unit accepted; one periodic cycle: every state's last
row equal to its first within :data:`~fdm_awe.trajectory.schema.PERIODIC_TOL`, the
optimiser's acceptance tolerance on its periodicity rows, the heading after ``2 pi k_wrap``;
a continuous path: no position step between consecutive rows beyond the fastest ground speed,
largest airspeed plus wind, times the time step, with the margin of
:data:`~fdm_awe.trajectory.schema.CONTINUITY_FACTOR`). A malformed file raises
:class:`~fdm_awe.errors.InputError` with one line naming the file, the field (with the row
where it applies) and the allowed range or form. It returns a
:class:`ReferenceTrajectory` with NumPy columns, the completed metadata (both wind forms,
``period_s``, ``tether_drag_scale``) and a ``sample(t)`` helper (:data:`REFERENCE_RULES`).
:func:`write_reference` runs the same checks before it writes, atomically.

Sampling (:class:`CycleSampler`, one implementation for every user): the cycle repeats with the
period ``T1 + T2`` (cycle ``k = floor(t / period)``, cycle time ``t - k * period``; generation
while the cycle time is below ``T1``). A cycle time falls into the segment between the last row
at or before it and the next row (before the first row: the first segment; at or after the last
row: the last one); at a time stored twice (the phase switch) the later row, the new phase,
opens the segment. Each column has a named rule:

- :data:`LINEAR`: linear in time across the segment, ``a_i (1 - w) + a_(i+1) w`` with
  ``w = (t - t_i) / (t_(i+1) - t_i)`` clipped to 0 .. 1. With the switch row stored once per
  phase (the file) this is linear within a phase; the autopilot's
  :class:`~fdm_awe.autopilot.tracking.TrackingReference` stores it once, so its first recovery
  segment runs from the generation's last row;
- :data:`HELD`: held per optimiser interval: the value of the row opening the segment (each row
  carries the value of its interval), the closing row's when the segment crosses a phase switch
  (a segment belongs to the phase of the row closing it).

The file's own meaning is :data:`REFERENCE_RULES` (states and derived quantities linear, the
optimiser's controls ``alpha, phi, T``, ``fold``, ``motor_on``, ``boost_duty`` held); the
autopilot's is :data:`fdm_awe.autopilot.tracking.TRACKING_RULES`.
"""

from .checks import check_reference, check_reference_document
from .files import as_reference, read_reference, reference_document, reference_from_result, write_reference
from .reference import REFERENCE_RULES, ReferenceTrajectory
from .sampler import HELD, LINEAR, RULES, CycleSample, CycleSampler
from .schema import (COLUMN_RANGES, COLUMN_UNITS, FORMAT, GENERATION, MAX_FILE_BYTES, OPTIONAL_COLUMN_UNITS, PHASE_MAX_S,
                     PHASE_NAMES, RECOVERY, RECOVERY_AIRFRAME, SLACK, TIME_RTOL, VERSION, WIND_MAX)

__all__ = [
    "COLUMN_RANGES", "COLUMN_UNITS", "FORMAT", "GENERATION", "HELD", "LINEAR", "MAX_FILE_BYTES", "OPTIONAL_COLUMN_UNITS",
    "PHASE_MAX_S", "PHASE_NAMES", "RECOVERY", "RECOVERY_AIRFRAME", "REFERENCE_RULES", "RULES", "SLACK", "TIME_RTOL",
    "VERSION", "WIND_MAX", "CycleSample", "CycleSampler", "ReferenceTrajectory", "as_reference", "check_reference",
    "check_reference_document", "read_reference", "reference_document", "reference_from_result", "write_reference",
]
