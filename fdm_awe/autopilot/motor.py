"""When the autopilot runs the glider's motor in AUTO: the gate's rules (:class:`MotorGate`),
its plan for a reference (:meth:`MotorGate.plan`) and the switch that follows the plan step by
step (:class:`MotorSwitch`: dwell time, the rescue for a lost path, the soft start).

The switch's arithmetic is the pure functions :func:`motor_update` and :func:`motor_ceiling`
(numba compiles them with the same bits as the Python call): the gate as a float64 vector
(:meth:`MotorGate.vector`, layout :data:`GATE`), its plan as floats per segment
(:meth:`MotorGate.plan_vector`), the switch's state in a caller-owned float64 array (layout
:data:`MOTOR_MEM`, :func:`motor_memory`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import slots
from .tracking import TrackingReference

#: layout of :meth:`MotorGate.vector`: off_below [-], min_off_s, min_on_s, min_dwell_s,
#: soft_start_s [s], rescue_error_m [m], soft_stop_s [s]
GATE = slots.declare("MotorGate", ("off_below", "min_off_s", "min_on_s", "min_dwell_s", "soft_start_s",
                                   "rescue_error_m", "soft_stop_s"))
#: layout of the switch's state (:func:`motor_memory`): running (1.0 / 0.0), time of the last
#: switch [s] (-inf before the first), switches so far, rescue (1.0 / 0.0)
MOTOR_MEM = slots.declare("MotorMemory", ("running", "switch_t", "switches", "rescue"))


@dataclass(frozen=True)
class MotorGate:
    """When AUTO stops the motor (the reference's motor-off mode, column ``motor_on``).

    The optimiser's on-fraction ``s`` of an interval is the share of it the motor runs
    (thrust ``s T_on`` on average, power ``s P_on + (1 - s) P0``). The motor stops where ``s``
    is below ``off_below``: throttle 0, the ESC brakes the propeller to a stop (no thrust, no
    windmill drag), the glider draws only P0, the thrust loop is off and its integral held.
    Elsewhere it runs and flies the guidance's thrust (the reference's mean thrust ``s T_on``
    plus corrections) continuously.

    Each start costs what the optimiser's model does not book: the 6-DOF drive spins its
    propeller up from rest (rotor and propeller 1e-4 kg m^2: 15-30 J at 5500-7900 rpm, lost
    again when the ESC brakes it) through the coil's resistance, 40-80 J more than running on
    after a throttle step at 12.5-20 m/s (about 90 J after the thrust loop's jump to ~0.9
    throttle on the nominal 8 m/s cycle), and its thrust comes 0.3-0.5 s late. So:

    - the motor starts soft: the throttle's ceiling rises from 0 to 1 over ``soft_start_s``
      after a start, which limits the inrush current as an ESC's soft start does (1 s halves
      the start's cost on that cycle, to about 50 J);
    - and it stops soft: the throttle falls from its last value to 0 over ``soft_stop_s``
      (:func:`motor_spin_down`). At throttle 0 the drive brakes the propeller through the coil
      (the current ``-rpm / (Kv R)``, about 35 A from 6000 rpm): its angular momentum (about
      0.06 N m s) leaves in 0.2 s as a roll torque of about 0.3 N m, which the folded wing's
      ailerons cannot hold (full aileron for over a second, the bank swinging by 1 rad). Over
      1 s the rotor follows the falling throttle (electrical time constant ``J R Kv^2`` 0.19 s)
      and the torque is a fifth of that;
    - it does not pulse within an interval (each pulse would cost a start, more than the duty
      cycle saves, 2-8 W);
    - it does not follow every switch of the reference (:meth:`plan`): a pause shorter than
      ``min_off_s`` is bridged with the motor running at the guidance's (near zero) thrust,
      which draws the turning propeller's idle power (5-30 W above P0), less than a restart;
      then a lone burst shorter than ``min_on_s`` is left out (the guidance trades its
      along-path force through the flight path);
    - a switch waits at least ``min_dwell_s`` after the previous one (no chattering);
    - the motor is the glider's reserve: when the position error exceeds ``rescue_error_m``
      it runs whatever the plan says, until the error is back below half of that (a glider
      that lost its path without thrust, e.g. in a slow low-tension climb, sinks away from it
      for good), but only for a glider no faster in the air than its reference point (or one
      pulling up from the ground or protecting its airspeed): off its path and faster, in a
      dive or a gust, it has energy to spare, and the 9x5 propeller spun up at 23 m/s needs
      about 0.8 throttle to make no thrust at all (the nominal 13 m/s cycle's rescue in its
      dive cost 70-110 J a cycle for no thrust, 106 J of thrust energy against the optimum's
      34 J; kept for slow gliders it books 35 J and nets 705-714 J against 703 J optimised).
    """

    off_below: float = 0.2  #: on-fraction below which the motor is stopped [-] (0 .. 1)
    min_off_s: float = 3.0  #: shortest reference pause the motor is stopped for [s]
    min_on_s: float = 1.0  #: shortest lone reference burst the stopped motor is started for [s]
    min_dwell_s: float = 0.5  #: least time between two motor switches [s]
    #: soft start: after a start the throttle may rise from 0 to 1 only over this time [s]
    soft_start_s: float = 1.0
    #: soft stop: after a stop the throttle falls from its last value to 0 over this time [s]
    soft_stop_s: float = 1.0
    #: position error above which the motor runs whatever the plan says [m]
    rescue_error_m: float = 10.0

    def __post_init__(self) -> None:
        if not (0.0 <= self.off_below <= 1.0):
            raise ValueError(f"MotorGate.off_below: {self.off_below!r} out of range (allowed 0 .. 1)")
        for name in ("min_off_s", "min_on_s", "min_dwell_s", "soft_start_s", "soft_stop_s"):
            v = getattr(self, name)
            if not (0.0 <= v <= 60.0):
                raise ValueError(f"MotorGate.{name}: {v!r} s out of range (allowed 0 .. 60 s)")
        if not (self.rescue_error_m > 0.0):
            raise ValueError(f"MotorGate.rescue_error_m: {self.rescue_error_m!r} m out of range (allowed > 0 m)")

    def plan(self, ref: TrackingReference) -> np.ndarray:
        """Whether the motor runs on each segment of ``ref``
        (:meth:`~.tracking.TrackingReference.motor_segments`; the cycle repeats): on where the
        on-fraction is at least ``off_below``, pauses shorter than ``min_off_s`` filled, then
        bursts shorter than ``min_on_s`` removed (both measured around the cycle's end too)."""
        run = ref.motor_segments() >= self.off_below
        dur = np.diff(ref.t)
        dur[-1] += max(ref.period - float(ref.t[-1]), 0.0)
        run = _flip_short(run, dur, False, self.min_off_s)
        return _flip_short(run, dur, True, self.min_on_s)

    def plan_vector(self, ref: TrackingReference) -> np.ndarray:
        """:meth:`plan` as float64 per segment (1.0 run, 0.0 stop): the ``plan`` of :func:`motor_update`."""
        return self.plan(ref).astype(float)

    def vector(self) -> np.ndarray:
        """The gate as the float64 vector of :func:`motor_update` (layout :data:`GATE`)."""
        v = slots.new(GATE)
        v[GATE.off_below] = self.off_below
        v[GATE.min_off_s] = self.min_off_s
        v[GATE.min_on_s] = self.min_on_s
        v[GATE.min_dwell_s] = self.min_dwell_s
        v[GATE.soft_start_s] = self.soft_start_s
        v[GATE.rescue_error_m] = self.rescue_error_m
        v[GATE.soft_stop_s] = self.soft_stop_s
        return v


def _flip_short(flags: np.ndarray, dur: np.ndarray, value: bool, limit: float) -> np.ndarray:
    """``flags`` with every cyclic run of ``value`` lasting less than ``limit`` [s] (segment
    durations ``dur``) flipped; unchanged when ``value`` fills the whole cycle or never occurs."""
    flags = np.asarray(flags, bool)
    n = len(flags)
    if limit <= 0.0 or n == 0 or flags.all() or not flags.any():
        return flags.copy()
    out = flags.copy()
    start = int(np.flatnonzero(flags != np.roll(flags, 1))[0])  # a run starts here
    order = np.roll(np.arange(n), -start)
    i = 0
    while i < n:
        j = i
        while j < n and flags[order[j]] == flags[order[i]]:
            j += 1
        run = order[i:j]
        if flags[run[0]] == value and float(dur[run].sum()) < limit:
            out[run] = not value
        i = j
    return out


def motor_memory() -> np.ndarray:
    """A switch's state before its first step (layout :data:`MOTOR_MEM`): running, no switch yet, no rescue."""
    mem = slots.new(MOTOR_MEM)
    mem[MOTOR_MEM.running] = 1.0
    mem[MOTOR_MEM.switch_t] = -math.inf
    return mem


def motor_update(plan: np.ndarray, seg: int, t: float, track_error: float, gate: np.ndarray,
                 mem: np.ndarray, slow: bool) -> float:
    """Whether the motor runs this step (1.0, else 0.0) on segment ``seg`` of a reference whose
    plan is ``plan`` (:meth:`MotorGate.plan_vector`), at time ``t`` [s]: as the plan says, or for
    a position error ``track_error`` [m] (the last step's; NaN: none yet) beyond the gate's
    ``rescue_error_m`` (until it is back below half of that) of a glider that is ``slow`` (flies
    no faster in the air than its reference point: off its path and faster, e.g. in a dive, it
    has energy to spare, and the fixed-pitch propeller spun up at that speed draws its power for
    next to no thrust); a switch at least ``min_dwell_s`` after the last. ``gate``:
    :meth:`MotorGate.vector`; ``mem``: the switch's state (layout :data:`MOTOR_MEM`, :func:`motor_memory`),
    updated in place."""
    want = plan[seg] != 0.0
    if not want:
        e = track_error
        if e > gate[GATE.rescue_error_m] and slow:
            mem[MOTOR_MEM.rescue] = 1.0
        elif not e > 0.5 * gate[GATE.rescue_error_m]:  # below half of it, or no error yet (NaN)
            mem[MOTOR_MEM.rescue] = 0.0
        want = mem[MOTOR_MEM.rescue] != 0.0
    if want != (mem[MOTOR_MEM.running] != 0.0) and t - mem[MOTOR_MEM.switch_t] >= gate[GATE.min_dwell_s]:
        mem[MOTOR_MEM.running] = 1.0 if want else 0.0
        mem[MOTOR_MEM.switch_t] = t
        mem[MOTOR_MEM.switches] += 1.0
    return mem[MOTOR_MEM.running]


def motor_ceiling(t: float, gate: np.ndarray, mem: np.ndarray) -> float:
    """The throttle's ceiling at time ``t`` [s] (0 .. 1) under ``gate`` (:meth:`MotorGate.vector`)
    for the switch's state ``mem`` (layout :data:`MOTOR_MEM`): rising from 0 to 1 over the gate's
    ``soft_start_s`` after a start (the propeller spins up from rest), else 1."""
    if mem[MOTOR_MEM.switches] != 0.0 and t - mem[MOTOR_MEM.switch_t] < gate[GATE.soft_start_s]:
        return (t - mem[MOTOR_MEM.switch_t]) / gate[GATE.soft_start_s]
    return 1.0


def motor_spin_down(t: float, gate: np.ndarray, mem: np.ndarray, u_last: float) -> float:
    """The throttle of a stopped motor at time ``t`` [s]: falling linearly from ``u_last`` (its
    last value while running) to 0 over the gate's ``soft_stop_s`` after the stop (0 at once
    when that is 0), for the switch's state ``mem`` (layout :data:`MOTOR_MEM`)."""
    ts = gate[GATE.soft_stop_s]
    dt = t - mem[MOTOR_MEM.switch_t]
    if mem[MOTOR_MEM.switches] != 0.0 and ts > 0.0 and dt < ts:
        return u_last * (1.0 - dt / ts)
    return 0.0


class MotorSwitch:
    """Whether AUTO runs the motor, step by step, under ``gate`` (:class:`MotorGate`): the state
    in :attr:`mem` (layout :data:`MOTOR_MEM`), the steps by :func:`motor_update` and :func:`motor_ceiling`."""

    def __init__(self, gate: MotorGate) -> None:
        self.gate = gate
        self.mem = motor_memory()  #: the switch's state (layout :data:`MOTOR_MEM`)
        # (reference, gate, gate.plan_vector(reference), gate.vector())
        self._plan: tuple[Any, MotorGate, np.ndarray, np.ndarray] | None = None

    @property
    def running(self) -> bool:
        """AUTO runs the motor (False: stopped where the reference's motor is off)."""
        return bool(self.mem[MOTOR_MEM.running])

    @property
    def switches(self) -> int:
        """Motor stops and starts in AUTO so far."""
        return int(self.mem[MOTOR_MEM.switches])

    @property
    def rescue(self) -> bool:
        """The motor runs for a position error beyond MotorGate.rescue_error_m."""
        return bool(self.mem[MOTOR_MEM.rescue])

    @property
    def switch_t(self) -> float:
        """Time of the last switch [s] (-inf before the first)."""
        return float(self.mem[MOTOR_MEM.switch_t])

    def update(self, ref: TrackingReference, t_cycle: float, t: float, track_error: float, slow: bool = True) -> bool:
        """Whether the motor runs this step at cycle time ``t_cycle`` [s] of ``ref``, time ``t``
        [s]: as :meth:`MotorGate.plan` says, or for a position error ``track_error`` [m] (the
        last step's) beyond the gate's ``rescue_error_m`` of a ``slow`` glider; a switch at least
        ``min_dwell_s`` after the last (:func:`motor_update`)."""
        gate = self.gate
        plan = self._plan
        if plan is None or plan[0] is not ref or plan[1] is not gate:
            plan = self._plan = (ref, gate, gate.plan_vector(ref), gate.vector())
        return bool(motor_update(plan[2], ref.segment_index(t_cycle), t, track_error, plan[3], self.mem, slow))

    def ceiling(self, t: float) -> float:
        """The throttle's ceiling at time ``t`` [s] (0 .. 1): rising from 0 to 1 over the gate's
        ``soft_start_s`` after a start (the propeller spins up from rest), else 1
        (:func:`motor_ceiling`)."""
        plan = self._plan
        gate = plan[3] if plan is not None and plan[1] is self.gate else self.gate.vector()
        return float(motor_ceiling(t, gate, self.mem))
