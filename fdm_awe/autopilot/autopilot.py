"""The autopilot of the tethered glider, structured like a real one.

guidance (:mod:`.guidance`, path tracking by point-mass force inversion)
  -> attitude loops (angle of attack, bank, yaw damper: :class:`fdm_awe.sixdof.Stabilizer`)
  -> thrust loop (throttle)                         -> surfaces, throttle, fold command
phase logic (generation / recovery)                 -> winch command (machine mode, reel speed)

Modes (MAVLink ``custom_mode`` numbers in :data:`fdm_awe.autopilot.modes.MODE_NUMBERS`):

- ``MANUAL``: surfaces and throttle held at :attr:`Autopilot.manual` (neutral by default);
  the winch holds in generator mode.
- ``FBWA``: wings level at the trim angle of attack for the current airspeed, no thrust.
- ``AUTO``: with cycling started and a reference loaded, fly the pumping cycle: follow the
  reference path; generation = unfolded wing, generator (passive rectifier into R_L, optionally
  trimmed on the reel-speed error); recovery = folded wing (foldable configuration), motor
  mode with the PI speed loop at the reference reel speed. The machine switches at the
  reference's phase boundaries. The fold follows the reference's fold time (metadata
  ``fold_time_s``, :meth:`Autopilot.fold_command`): the optimiser's fold law (fold from the
  start of recovery, unfold over its last fold time) is the command; a reference optimised with
  an instantaneous fold (``fold_time_s`` 0 or absent, every file written before fold
  transitions) is flown as before, folded from ``FOLD_LEAD`` before recovery to
  ``UNFOLD_LEAD`` before its end. The motor follows the reference's motor-off mode (column
  ``motor_on``, :class:`MotorGate`): where the optimiser stopped it the throttle is cut (the
  ESC brakes the propeller to a stop: no thrust, no drag, only the idle power P0).
  Without cycling or without a reference, AUTO holds FBWA.
- ``RECOVER``: the safe mode. Unfold, no thrust, glide to a circle of ``REC_RADIUS`` about
  the winch and descend on it at ``REC_AIRSPEED``; the winch reels in whatever line hangs
  slack (at most ``REC_REEL_SPD``); below ``REC_FLARE_ALT`` fly wings level and flare. Losing
  the reference in AUTO (mission cleared) switches to RECOVER.

Gains and limits come from the definition file ``aircraft/glider_foldable/autopilot.xml`` via a
:class:`~fdm_awe.autopilot.params.ParamStore`; changes (e.g. MAVLink ``PARAM_SET``) take effect
at the next step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..definitions.aircraft import Glider
from ..errors import InputError
from ..groundstation import WinchCommand
from ..sixdof.adapter import JSBSimGlider
from ..sixdof.stabilizer import StabilizerGains
from ..sixdof.state import SixDofState, Surfaces
from .attitude import AttitudeLoops
from .guidance import Guidance, GuidanceGains, norm3
from .modes import MODE_NUMBERS
from .params import ParamStore
from .tracking import GENERATION, PHASE_NAMES, RECOVERY, RefPoint, TrackingReference
from .vehicle import Waypoint

MODES = ("MANUAL", "FBWA", "AUTO", "RECOVER")
CONFIGS = ("foldable", "nominal")

_STAB_PARAMS = {"W_ALPHA": "w_alpha", "Z_ALPHA": "z_alpha", "KI_ALPHA": "ki_alpha", "W_PHI": "w_phi",
                "Z_PHI": "z_phi", "W_R": "w_r", "K_BETA": "k_beta"}


def _wrap(a: float) -> float:
    return math.atan2(math.sin(a), math.cos(a))


#: slack on the fold-time comparison [s] (the reference's and the aircraft's are one number)
FOLD_TIME_TOL_S = 1e-6


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
      for good).
    """

    off_below: float = 0.2  #: on-fraction below which the motor is stopped [-] (0 .. 1)
    min_off_s: float = 3.0  #: shortest reference pause the motor is stopped for [s]
    min_on_s: float = 1.0  #: shortest lone reference burst the stopped motor is started for [s]
    min_dwell_s: float = 0.5  #: least time between two motor switches [s]
    #: soft start: after a start the throttle may rise from 0 to 1 only over this time [s]
    soft_start_s: float = 1.0
    #: position error above which the motor runs whatever the plan says [m]
    rescue_error_m: float = 10.0

    def __post_init__(self) -> None:
        if not (0.0 <= self.off_below <= 1.0):
            raise ValueError(f"MotorGate.off_below: {self.off_below!r} out of range (allowed 0 .. 1)")
        for name in ("min_off_s", "min_on_s", "min_dwell_s", "soft_start_s"):
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


def reference_fold_time(meta: dict, aircraft_fold_time_s: float) -> float:
    """Fold time [s] a reference (metadata ``meta``) is flown with on an aircraft whose fold
    actuator takes ``aircraft_fold_time_s`` for its full travel: the reference's
    ``fold_time_s`` (absent = 0: optimised with an instantaneous fold, flown with the
    FOLD_LEAD/UNFOLD_LEAD parameters). A fold time the aircraft can fly (0, or at least its
    actuator's) is returned; a faster one raises a one-line :class:`InputError`."""
    ft = meta.get("fold_time_s")
    ft = 0.0 if ft is None else float(ft)
    if not math.isfinite(ft) or ft < 0.0:
        raise InputError(f"reference metadata.fold_time_s: {ft:g} s out of range (allowed 0 or >= {aircraft_fold_time_s:g} s)")
    if 0.0 < ft < aircraft_fold_time_s - FOLD_TIME_TOL_S:
        raise InputError(f"reference metadata.fold_time_s: {ft:g} s, faster than the aircraft's fold actuator "
                         f"(fcs/wing-fold-time-s {aircraft_fold_time_s:g} s); allowed 0 (an instantaneous fold) or "
                         f">= {aircraft_fold_time_s:g} s: optimise the reference with the aircraft's fold time")
    return ft


class Autopilot:
    """Controller for :class:`fdm_awe.sim.loop.CoSim` and :class:`VehicleInterface` for MAVLink.

    ``config``: ``"foldable"`` folds for recovery, ``"nominal"`` never folds.
    ``load_resistance``: the generator's R_L [ohm] (definition default of the ground station).
    ``thruster``/``winch``/``line_EA``: the paper plant's ideal thruster, ``"ideal"`` for its
    kinematic winch, and the line's axial stiffness EA [N] (ground-station definition).
    ``motor``: when AUTO stops the motor (:class:`MotorGate`; default gate if None).

    A foldable reference whose fold time the aircraft cannot fly (faster than its fold
    actuator, :func:`reference_fold_time`) raises :class:`~fdm_awe.errors.InputError`.
    """

    def __init__(
        self,
        glider: JSBSimGlider,
        airframes: Glider,
        params: ParamStore,
        reference: TrackingReference | None = None,
        config: str = "foldable",
        load_resistance: float = 1.5,
        rho: float = 1.225,
        g: float = 9.81,
        thruster: Any = None,
        winch: str = "physical",
        line_EA: float = 22600.0,
        motor: MotorGate | None = None,
    ) -> None:
        if config not in CONFIGS:
            raise ValueError(f"config {config!r} unknown (allowed: {', '.join(CONFIGS)})")
        if winch not in ("physical", "ideal"):
            raise ValueError(f"winch {winch!r} unknown (allowed: physical, ideal)")
        if reference is not None and config == "foldable":
            reference_fold_time(reference.meta, glider.fold_time_s)
        #: paper plant: an ideal thruster (:class:`fdm_awe.sim.paper_plant.IdealThruster`) takes the
        #: thrust command instead of the propeller's throttle (held at zero)
        self.thruster = thruster
        #: "ideal": a kinematic winch (paper plant) reels at the commanded speed in generation
        #: too; "physical": the passive generator sets the reel-out speed
        self.winch = winch
        self.glider = glider
        self.airframes = airframes
        self.params = params
        self.config = config
        self.R_L = float(load_resistance)
        self.g = g
        self.reference = reference
        self.mode = "AUTO" if reference is not None else "FBWA"
        self.armed = True
        self.cycling = reference is not None
        #: path parameter: reference time flown so far [s] (cycle k spans k P .. (k+1) P). It
        #: advances with flight time, faster when the glider is ahead of its reference point
        #: and slower when behind, so the loops act on the distance to the path rather than on
        #: a schedule (path following; the cycle's period is the glider's own).
        self.s_ref = 0.0
        self.path_rate = 1.0
        #: RECOVER's stage: None (not entered), "return" (to the circle, descending), "hold"
        #: (on the circle at its floor altitude), "final" (straight into the wind), "flare"
        self.rec_stage: str | None = None
        self._rec_sense = 1.0  # +1 clockwise, -1 counter-clockwise seen from above
        self._rec_h = 0.0  # altitude reference [m]
        self._rec_final: tuple[np.ndarray, np.ndarray] | None = None  # final approach: start, track
        self._rec_park = False  # RECOVER parks in the hold instead of landing
        self._rec_gust2 = 0.0  # mean square of the vertical wind [m^2/s^2], ~10 s filter
        #: AUTO rejoin segment: (start time [s], position offset [m], velocity offset [m/s]) or None
        self._rejoin: tuple[float, np.ndarray, np.ndarray] | None = None
        self._rejoin_pending = False
        self.airborne = True  #: no contact touched the ground at the last step
        #: ground-station link: (up now, was up once, time it was lost [s])
        self._gcs = (False, False, -math.inf)
        self.phase = "generation" if reference is not None else "ground"
        self.manual = Surfaces()
        self.log: list[tuple[float, str]] = []
        self.ref_point = None
        self.last_guidance = None
        self.track_error = float("nan")
        af = airframes.unfolded
        self.guidance = Guidance(self._guidance_gains(), af.mass.mass, af.aero, airframes.folded.aero, rho, g)
        self.att = AttitudeLoops(glider, StabilizerGains(**{v: params[k] for k, v in _STAB_PARAMS.items()}))
        self._thr_int = 0.0
        self._t_last: float | None = None
        self._t_now = 0.0
        self._thrust_max_static = af.propulsion.T_max
        #: airspeed [m/s] at which the propeller gives zero thrust at full throttle (its
        #: zero-thrust advance ratio times the tip speed scale); sets the throttle feed-forward
        self._v_zero_thrust = params["THR_VZERO"]
        self._line_EA = line_EA
        self.motor_gate = motor if motor is not None else MotorGate()
        #: AUTO runs the motor (False: stopped where the reference's motor is off)
        self.motor_running = True
        self.motor_switches = 0  #: motor stops and starts in AUTO so far
        self.motor_rescue = False  #: the motor runs for a position error beyond MotorGate.rescue_error_m
        self._motor_switch_t = -math.inf  # time of the last switch [s]
        self._motor_plan: tuple[Any, MotorGate, np.ndarray] | None = None  # (reference, gate, gate.plan(reference))
        for name in params.names():
            params.on_change(name, self._on_param)

    # ------------------------------------------------------------------ parameters
    def _guidance_gains(self) -> GuidanceGains:
        p = self.params
        return GuidanceGains(
            kp=p["GUID_KP"], kd=p["GUID_KD"], ki=p["GUID_KI"], a_max=p["GUID_AMAX"], int_max=p["GUID_IMAX"],
            alpha_min=p["LIM_ALPHA_MIN"], alpha_max=p["LIM_ALPHA_MAX"], phi_max=p["LIM_BANK"], thrust_max=p["LIM_THRUST"],
            energy_trade=p["GUID_ETRADE"], negative_lift=p["GUID_NEGLIFT"] > 0.5, phi_max_vertical=p["LIM_BANK_VERT"],
            curv_scale_max=p["GUID_CURVMAX"],
            overspeed_tension=p["GUID_VTENS"], overspeed_margin=p["GUID_VMARGIN"],
        )

    def _on_param(self, name: str, value: float) -> None:
        if name in _STAB_PARAMS:
            setattr(self.att.gains, _STAB_PARAMS[name], float(value))
        else:
            self.guidance.k = self._guidance_gains()

    def _note(self, text: str) -> None:
        self.log.append((self._t_now, text))

    # ------------------------------------------------------------------ VehicleInterface
    @property
    def modes(self) -> list[str]:
        return [m for m in MODES if m in MODE_NUMBERS]

    def set_mode(self, name: str) -> bool:
        if name not in MODES:
            return False
        if name == "AUTO" and self.reference is None:
            return False
        if name != self.mode:
            self._note(f"mode {self.mode} -> {name}")
            if name == "RECOVER":
                self.phase = "recovery"
                self.rec_stage = None  # a new recovery from wherever the glider is
            if name == "AUTO":
                self._rejoin_pending = True  # rejoin the path from the glider's own state
        self.mode = name
        return True

    def arm(self, on: bool, force: bool = False) -> bool:
        """Arm or disarm the motor. A disarm in flight is refused unless ``force`` (as
        ArduPilot refuses it: MAV_CMD_COMPONENT_ARM_DISARM with param2 21196 forces it)."""
        if not on and self.armed and self.airborne and not force:
            self._note("disarm refused: in flight (force it with 21196)")
            return False
        self.armed = bool(on)
        self._note(("armed" if on else "disarmed") + (" (forced)" if force else ""))
        return True

    def gcs_link(self, up: bool, t: float) -> None:
        """The ground-station link's state at time ``t`` [s]. With FS_GCS_ENABL 1, a link that
        was up once and has been lost for FS_LONG_TIMEOUT switches an armed glider in flight
        to RECOVER (once per loss; the ground station may take another mode afterwards)."""
        now_up, ever, t_lost = self._gcs
        if up:
            self._gcs = (True, True, -math.inf)
            return
        if now_up:
            self._gcs = (False, ever, t)
            return
        p = self.params
        if (ever and p["FS_GCS_ENABL"] > 0.5 and t - t_lost >= p["FS_LONG_TIMEOUT"] and self.mode != "RECOVER"
                and self.armed and self.airborne):
            self._note(f"failsafe: ground-station link lost for {t - t_lost:.1f} s")
            self.set_mode("RECOVER")
            self._gcs = (False, ever, math.inf)  # acted on this loss

    def start_cycling(self) -> bool:
        if self.reference is None:
            return False
        if not self.cycling:
            # restart the cycle at the reference point nearest to where the glider is
            self.s_ref = self._cycle_start() + self._nearest_cycle_time()
            self.guidance.reset()
            self._rejoin_pending = True
            self._note("cycling started")
        self.cycling = True
        return True

    def stop_cycling(self) -> bool:
        if self.cycling:
            self._note("cycling stopped")
        self.cycling = False
        return True

    def mission(self) -> list[Waypoint]:
        if self.reference is None:
            return []
        return [Waypoint(n, e, d, t, PHASE_NAMES[p]) for n, e, d, t, p in self.reference.waypoints()]

    def set_mission(self, wps: list[Waypoint]) -> tuple[bool, str]:
        if len(wps) < 3:
            return False, f"need at least 3 waypoints, got {len(wps)}"
        P = np.array([[w.north, w.east, w.down] for w in wps], float)
        if not np.all(np.isfinite(P)):
            return False, "waypoint not finite"
        if np.any(P[:, 2] > -5.0):
            return False, "every waypoint must be at least 5 m above the winch"
        if np.any(np.linalg.norm(P, axis=1) > 400.0):
            return False, "waypoint beyond 400 m from the winch"
        times = [w.time_s for w in wps]
        phases = [w.phase for w in wps]
        if all(t is not None for t in times) and np.all(np.diff(np.array(times, float)) > 0):
            tt = np.array(times, float)
            tt = tt - tt[0]
        else:
            tt = None
        ph = np.array([1 if p == "recovery" else 0 for p in phases]) if any(p == "recovery" for p in phases) else None
        speed = float(np.mean(self.reference.airspeed)) if self.reference is not None else 15.0
        self.reference = TrackingReference.from_waypoints(P, tt, ph, speed)
        self.guidance.reset()
        self._note(f"mission of {len(wps)} waypoints loaded")
        if self.cycling:
            self.s_ref = self._cycle_start() + self._nearest_cycle_time()
        return True, "accepted"

    def clear_mission(self) -> None:
        self.reference = None
        self._note("mission cleared")
        if self.mode == "AUTO":
            self.set_mode("RECOVER")

    # ------------------------------------------------------------------ helpers
    def _cycle_start(self) -> float:
        """Path parameter at the start of the current cycle [s]."""
        if self.reference is None:
            return self.s_ref
        P = self.reference.period
        return math.floor(self.s_ref / P + 1e-9) * P

    @property
    def cycle(self) -> int:
        """Index of the cycle being flown (0-based)."""
        return int(self.s_ref // self.reference.period) if self.reference is not None else 0

    def _nearest_cycle_time(self) -> float:
        ref = self.reference
        assert ref is not None
        s = self.glider.state()
        i = int(np.argmin(np.linalg.norm(ref.pos - s.pos_ned, axis=1)))
        return float(ref.t[i])

    def _throttle(self, thrust_cmd: float, thrust: float, airspeed: float, dt: float, u_max: float = 1.0) -> float:
        """Thrust loop: feed-forward plus PI on the measured thrust. Thrust 0 is flown as
        zero thrust with the motor running (the propeller turning at its zero-thrust advance
        ratio); stopping the motor is :meth:`_motor_update`'s decision. ``u_max``: the
        throttle's ceiling (the soft start after a motor start, :class:`MotorGate`)."""
        p = self.params
        if not self.armed:
            self._thr_int = 0.0
            return 0.0
        e = thrust_cmd - thrust
        v0 = min(max(airspeed / self._v_zero_thrust, 0.0), 1.0)
        ff = v0 + (1.0 - v0) * math.sqrt(min(max(thrust_cmd, 0.0) / self._thrust_max_static, 1.0))
        self._thr_int = min(max(self._thr_int + p["THR_KI"] * e * dt, -1.0), 1.0)
        u = ff + p["THR_KP"] * e + self._thr_int
        if u > u_max or u < 0.0:  # anti-windup: undo the last integration when saturated
            self._thr_int -= p["THR_KI"] * e * dt
        return min(max(u, 0.0), u_max)

    def _propulsion(self, thrust_cmd: float, s: SixDofState, dt: float, u_max: float = 1.0) -> float:
        """Throttle for the thrust command (at most ``u_max``); with an ideal thruster it takes
        the command and the propeller's throttle stays at zero."""
        if self.thruster is not None:
            self.thruster.command(thrust_cmd if self.armed else 0.0)
            return 0.0
        return self._throttle(thrust_cmd, s.thrust_N, s.airspeed, dt, u_max)

    def _motor_update(self, ref: TrackingReference, t_cycle: float, t: float) -> bool:
        """Whether the motor runs this step in AUTO at cycle time ``t_cycle`` [s] of ``ref``:
        as :meth:`MotorGate.plan` says, or for a position error (the last step's) beyond the
        gate's ``rescue_error_m``; a switch at least ``min_dwell_s`` after the last."""
        gate = self.motor_gate
        plan = self._motor_plan
        if plan is None or plan[0] is not ref or plan[1] is not gate:
            plan = self._motor_plan = (ref, gate, gate.plan(ref))
        want = bool(plan[2][ref.segment_index(t_cycle)])
        if not want:
            e = self.track_error
            if e > gate.rescue_error_m:
                self.motor_rescue = True
            elif not e > 0.5 * gate.rescue_error_m:  # below half of it, or no error yet (NaN)
                self.motor_rescue = False
            want = self.motor_rescue
        if want != self.motor_running and t - self._motor_switch_t >= self.motor_gate.min_dwell_s:
            self.motor_running = want
            self._motor_switch_t = t
            self.motor_switches += 1
        return self.motor_running

    def _motor_stop(self) -> float:
        """Throttle 0 with the motor stopped (the ESC brakes the propeller; the thrust loop's
        integral is held for the restart); an ideal thruster takes zero thrust."""
        if self.thruster is not None:
            self.thruster.command(0.0)
        return 0.0

    def fold_command(self, t_cycle: float, T1: float, period: float) -> float:
        """Fold command (0 open .. 1 folded) at cycle time ``t_cycle`` [s] of a cycle of
        ``period`` [s] whose recovery starts at ``T1`` [s]; 0 for the nominal configuration.

        With the reference's fold time ``f`` (metadata ``fold_time_s`` > 0) the command is the
        optimiser's fold law (:func:`fdm_awe.ocp.model.fold_fraction`: folding from the start
        of recovery, unfolding over its last ``f``), a ramp the rate-limited actuator follows
        (at its own full rate when ``f`` is the aircraft's fold time). A reference optimised
        with an instantaneous fold (``fold_time_s`` 0 or absent) is flown as such references
        always were: folded from ``FOLD_LEAD`` before the recovery to ``UNFOLD_LEAD`` before
        its end."""
        if self.config != "foldable":
            return 0.0
        ft = float(self.reference.meta.get("fold_time_s") or 0.0) if self.reference is not None else 0.0
        if ft > 0.0:
            if t_cycle < T1:
                return 0.0
            from ..ocp.model import fold_fraction

            return fold_fraction(t_cycle - T1, period - T1, ft)
        p = self.params
        return 1.0 if (T1 - p["FOLD_LEAD"]) <= t_cycle < (period - p["UNFOLD_LEAD"]) else 0.0

    def _pay_out(self, s: SixDofState, gs: Any, load_resistance: float, slack: float) -> WinchCommand:
        """Let line out in generator mode: through the load resistor on the real winch; on a
        kinematic winch, at the glider's opening speed plus a catch-up on ``slack`` (m) of
        line beyond the glider's distance and on a tension above REC_TENSION."""
        if self.winch != "ideal" or gs is None:
            return WinchCommand(mode="generator", load_resistance=load_resistance)
        d = norm3(s.hook_pos_ned)
        d_rate = float(s.hook_pos_ned @ s.hook_vel_ned) / max(d, 1e-6)
        v = max(d_rate, 0.0) + 0.5 * max(d + slack - gs.length, 0.0) + 0.2 * max(gs.tension - self.params["REC_TENSION"], 0.0)
        return WinchCommand(mode="generator", reel_speed_ref=v)

    def _hold(self, s: SixDofState, alpha: float, roll: float, fold: float, dt: float, throttle: float = 0.0) -> Surfaces:
        a, e, r = self.att.update(s, alpha, roll, dt)
        return Surfaces(a, e, r, throttle, fold)

    # ------------------------------------------------------------------ controller
    def update(self, t: float, s: SixDofState, gs: Any) -> tuple[Surfaces, WinchCommand]:
        dt = 0.0 if self._t_last is None else max(0.0, t - self._t_last)
        self._t_last = t
        self._t_now = t
        self.airborne = not s.on_ground
        if self.mode == "MANUAL":
            self.phase = "ground" if s.on_ground else self.phase
            if self.thruster is not None:
                self.thruster.command(self.manual.throttle * self.thruster.T_max)
            return self.manual, WinchCommand(mode="generator", load_resistance=self.R_L)
        if self.mode == "RECOVER":
            return self._recover(s, gs, dt)
        if self.mode == "AUTO" and self.cycling and self.reference is not None:
            return self._auto(t, s, gs, dt)
        # FBWA (or AUTO without a path): wings level, trim alpha, no thrust
        alpha = self.glider.trim_alpha(max(s.airspeed, 8.0))
        self._propulsion(0.0, s, dt)
        return self._hold(s, min(alpha, self.params["LIM_ALPHA_MAX"]), 0.0, 0.0, dt), WinchCommand(mode="generator", load_resistance=self.R_L)

    def _advance(self, ref: TrackingReference, s_par: float, s: SixDofState, dt: float):
        """Reference point at path parameter ``s_par`` and the parameter one step later: it moves
        with the along-path error over the reference speed, relaxed in PATH_TAU seconds and
        bounded to 0 .. 3x real time. Returns (point, rate, new parameter)."""
        r = ref.sample(s_par)
        vr = norm3(r.vel)
        if vr > 0.5:
            e_at = float((s.pos_ned - r.pos) @ r.vel) / vr
            rate = min(max(1.0 + e_at / (vr * self.params["PATH_TAU"]), 0.0), 3.0)
        else:
            rate = 1.0
        return r, rate, s_par + rate * dt

    def _rejoin_start(self, ref: TrackingReference, s: SixDofState, t: float) -> None:
        """Begin a rejoin segment: the path parameter moves to the reference point nearest the
        glider's position and velocity (velocity error weighted by 2 s), and the offset
        between them decays over RJ_TIME (:meth:`_rejoin_point`)."""
        self._rejoin_pending = False
        T = self.params["RJ_TIME"]
        cost = (np.sum((ref.pos - s.pos_ned) ** 2, axis=1) + 4.0 * np.sum((ref.vel - s.vel_ned) ** 2, axis=1))
        i = int(np.argmin(cost))
        self.s_ref = self._cycle_start() + float(ref.t[i])
        self.guidance.reset()
        if T <= 0.0:
            self._rejoin = None
            return
        r0 = ref.sample(self.s_ref)
        self._rejoin = (t, np.asarray(s.pos_ned - r0.pos, float), np.asarray(s.vel_ned - r0.vel, float))
        self._note(f"rejoin: {norm3(self._rejoin[1]):.1f} m, {norm3(self._rejoin[2]):.1f} m/s from the path "
                   f"at t_cycle {r0.t_cycle:.2f} s, over {T:g} s")

    def _rejoin_point(self, ref: TrackingReference, t: float):
        """The reference point on the rejoin segment: the path's point plus an offset that
        starts at the glider's position and velocity offsets (dp, dv) and vanishes with its
        first two derivatives after RJ_TIME: (1 - w(tau)) dp + e(t) dv, w the quintic
        smoothstep, e = (t - t0) (1 - tau)^3. Returns (point, path rate 1)."""
        t0, dp, dv = self._rejoin
        T = self.params["RJ_TIME"]
        r = ref.sample(self.s_ref)
        tau = (t - t0) / T if T > 0.0 else 1.0
        if tau >= 1.0:
            self._rejoin = None
            self._note("rejoin: on the path")
            return r, 1.0
        w = tau ** 3 * (10.0 - 15.0 * tau + 6.0 * tau * tau)
        w1 = 30.0 * tau * tau * (1.0 - tau) ** 2 / T
        w2 = 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau) / (T * T)
        e = (t - t0) * (1.0 - tau) ** 3
        e1 = (1.0 - tau) ** 2 * (1.0 - 4.0 * tau)
        e2 = (1.0 - tau) * (12.0 * tau - 6.0) / T
        return replace(r, pos=r.pos + (1.0 - w) * dp + e * dv, vel=r.vel - w1 * dp + e1 * dv,
                       acc=r.acc - w2 * dp + e2 * dv), 1.0

    def _auto(self, t: float, s: SixDofState, gs: Any, dt: float) -> tuple[Surfaces, WinchCommand]:
        ref_traj = self.reference
        assert ref_traj is not None
        p = self.params
        if self._rejoin_pending:
            self._rejoin_start(ref_traj, s, t)
        if self._rejoin is not None:
            r, rate = self._rejoin_point(ref_traj, t)
            self.s_ref += dt
        else:
            r, rate, self.s_ref = self._advance(ref_traj, self.s_ref, s, dt)
        self.ref_point = r
        self.path_rate = rate
        wind = s.vel_ned - s.vel_air_ned
        f_t = np.asarray(gs.force_on_glider_ned) if gs is not None else np.zeros(3)
        taut = gs is not None and not gs.slack and r.phase == GENERATION
        # the motor: stopped where the reference stopped it (no thrust for the guidance to give)
        motor = self._motor_update(ref_traj, r.t_cycle, t)
        cmd = self.guidance.update(r, s.pos_ned, s.vel_ned, wind, f_t, s.fold, dt, taut=taut,
                                   thrust_max=None if motor else 0.0)
        self.track_error = cmd.pos_error
        self.last_guidance = cmd
        tc, T1, T = r.t_cycle, ref_traj.T1, ref_traj.period
        fold_cmd = self.fold_command(tc, T1, T)
        phase = "generation" if r.phase == GENERATION else "recovery"
        if phase != self.phase:
            self._note(f"phase {self.phase} -> {phase} (cycle {r.cycle}, t_cycle {tc:.2f} s)")
            self.phase = phase
        # winch
        if r.phase == GENERATION and self.winch == "ideal":
            # kinematic winch: reel at the reference speed (scaled by the path rate), on the
            # reference's unstretched length, and pay out faster when the line pulls harder
            # than the reference tension (the tension term damps the line's spring mode)
            v = rate * r.reel_speed
            if gs is not None:
                l_ref = r.length / (1.0 + r.tension / self._line_EA)
                v += p["WINCH_KL"] * (l_ref - gs.length) + p["WINCH_KT"] * (gs.tension - r.tension)
            wcmd = WinchCommand(mode="generator", reel_speed_ref=v)
        elif r.phase == GENERATION:
            rl = self.R_L
            if p["GEN_RL_KP"] > 0 and gs is not None:
                # radial position is the winch's job: pay out faster (higher R_L, less
                # braking) when the line is shorter than the reference, slower when longer
                rl = min(max(self.R_L + p["GEN_RL_KP"] * (r.length - gs.length), 0.2), 20.0)
            # the generator's T2 duty as the optimiser chose it (0: the passive rectifier)
            wcmd = WinchCommand(mode="generator", load_resistance=rl, boost_duty=r.boost_duty)
        else:
            # reel in at the reference speed scaled by the path rate, trimmed towards the reference
            # length, and ease off when the line pulls the glider harder than REC_TENSION
            v = rate * r.reel_speed
            if gs is not None:
                v += 0.5 * (r.length - gs.length)
                if gs.tension > p["REC_TENSION"]:
                    v += 0.2 * (gs.tension - p["REC_TENSION"])
            wcmd = WinchCommand(mode="motor", reel_speed_ref=min(v, 0.5))
        if not motor:
            thr = self._motor_stop()
        elif self.motor_switches and t - self._motor_switch_t < self.motor_gate.soft_start_s:
            # soft start: the propeller spins up from rest under a rising throttle ceiling
            thr = self._propulsion(cmd.thrust, s, dt, (t - self._motor_switch_t) / self.motor_gate.soft_start_s)
        else:
            thr = self._propulsion(cmd.thrust, s, dt)
        return self._hold(s, cmd.alpha, cmd.roll, fold_cmd, dt, thr), wcmd

    # ------------------------------------------------------------------ RECOVER
    def _recover_winch(self, s: SixDofState, gs: Any) -> WinchCommand:
        """The winch in RECOVER: brake a paying-out drum in generator mode first, then reel in
        the slack beyond REC_SLACK in motor mode; free spool on the final approach."""
        p = self.params
        d = norm3(s.hook_pos_ned)
        slack = (gs.length - d) if gs is not None else 0.0
        if self.rec_stage in ("final", "flare"):
            # final approach and touchdown: free spool (open-circuit generator: only the drum's
            # friction and inertia resist), the line pays out if the glider reaches its end
            return self._pay_out(s, gs, 1.0e4, 2.0)
        if gs is not None and (gs.reel_speed > p["REC_BRAKE_SPD"] or gs.tension > p["REC_TENSION"]):
            # the drum pays out fast or the line pulls: the generator brakes it through the
            # load (switching the machine to motor mode now would plug it: full supply voltage
            # on a back-EMF of the same sign, the armature current limited by its resistance only)
            return self._pay_out(s, gs, self.R_L, 0.0)
        # keep REC_SLACK metres of slack: reel in the excess (the half-bridge drives the
        # motor one way only; line goes out through the generator when pulled)
        reel = -min(max(0.5 * (slack - p["REC_SLACK"]), 0.0), p["REC_REEL_SPD"])
        return WinchCommand(mode="motor", reel_speed_ref=reel)

    def _circle_field(self, q: np.ndarray) -> np.ndarray:
        """Horizontal unit vector of the recovery circle's guidance field at horizontal
        position ``q`` (m, north/east of the winch): tangent to the circle of REC_RADIUS in the
        sense :attr:`_rec_sense` on it, turned towards it by ``atan((rho - R) / (R / 2))``
        off it (straight at the winch far outside, straight out near the centre)."""
        R = self.params["REC_RADIUS"]
        rho = math.hypot(q[0], q[1])
        er = q / rho if rho > 1e-6 else np.array([1.0, 0.0])
        et = self._rec_sense * np.array([-er[1], er[0]])
        beta = math.atan((rho - R) / (0.5 * R))
        return math.cos(beta) * et - math.sin(beta) * er

    def _ground_speed(self, u: np.ndarray, wind: np.ndarray, V: float) -> float:
        """Ground speed [m/s] along horizontal unit vector ``u`` at airspeed ``V`` in the
        horizontal ``wind`` (at least half the airspeed: no hovering against a stronger wind)."""
        uw = float(u @ wind)
        return uw + math.sqrt(max(V * V - float(wind @ wind) + uw * uw, 0.25 * V * V))

    def _rec_enter(self, s: SixDofState) -> None:
        q = s.pos_ned[:2]
        v = s.vel_ned[:2]
        self._rec_sense = 1.0 if float(q[0] * v[1] - q[1] * v[0]) >= 0.0 else -1.0
        self._rec_h = -float(s.pos_ned[2])
        self.rec_stage = "return"
        self._rec_final = None
        self._rec_park = self.params["REC_LAND"] < 0.5
        self._rec_gust2 = 0.0
        self.guidance.reset()
        self._note(f"recovery: return to the {self.params['REC_RADIUS']:.0f} m circle "
                   f"({'counter-clockwise' if self._rec_sense < 0 else 'clockwise'} seen from above)")

    def _rec_reference(self, s: SixDofState, wind: np.ndarray, dt: float):
        """Reference point of the RECOVER guidance this step (stages ``return``, ``hold`` and
        ``final``; see the module doc), or None in the flare."""
        p = self.params
        V = p["REC_AIRSPEED"]
        R = p["REC_RADIUS"]
        h = -float(s.pos_ned[2])
        w = np.array([wind[0], wind[1]])
        wn = math.hypot(w[0], w[1])
        q = np.array([s.pos_ned[0], s.pos_ned[1]])
        # vertical gust intensity: the measured vertical wind's mean square over ~10 s
        self._rec_gust2 += (float(wind[2]) ** 2 - self._rec_gust2) * min(dt / 10.0, 1.0)
        if not self._rec_park and p["REC_LAND"] > 0.5 and math.sqrt(self._rec_gust2) > p["REC_GUST_MAX"] \
                and self.rec_stage in ("return", "hold") and h < p["REC_HOLD_ALT"] + 10.0:
            self._rec_park = True
            self._note(f"recovery: vertical gusts {math.sqrt(self._rec_gust2):.1f} m/s RMS above REC_GUST_MAX: "
                       f"no landing, parking in the hold at {p['REC_HOLD_ALT']:.0f} m")
        land = p["REC_LAND"] > 0.5 and not self._rec_park
        floor = p["REC_FINAL_ALT"] if land else p["REC_HOLD_ALT"]
        sink = V / p["REC_SLOPE"]
        if self.rec_stage in ("return", "hold"):
            u = self._circle_field(q)
            on_circle = abs(math.hypot(q[0], q[1]) - R) < 0.25 * R
            if self.rec_stage == "return" and on_circle and h < floor + 3.0:
                self.rec_stage = "hold"
                self._note(f"recovery: on the circle at {h:.1f} m")
            upwind = wn < 1.0 or float(u @ w) < -0.87 * wn  # the track within 30 deg of the wind's eye
            if land and self.rec_stage == "hold" and upwind:
                f = -w / wn if wn >= 1.0 else u
                self._rec_final = (q.copy(), f)
                self.rec_stage = "final"
                self._note(f"recovery: final approach from {h:.1f} m, track {math.degrees(math.atan2(f[1], f[0])):.0f} deg")
        if self.rec_stage == "final":
            q0, f = self._rec_final
            if h < p["REC_FLARE_ALT"]:
                self.rec_stage = "flare"
                self._note(f"recovery: flare at {h:.1f} m")
                return None
            along = float((q - q0) @ f)
            pos_h = q0 + along * f
            vg = self._ground_speed(f, w, V)
            self._rec_h = min(max(self._rec_h - sink * dt, 0.0), h + 10.0)
            vel = np.array([vg * f[0], vg * f[1], sink if self._rec_h > 0.0 else 0.0])
            acc = np.zeros(3)
        elif self.rec_stage == "flare":
            return None
        else:
            vg = self._ground_speed(u, w, V)
            # the field's turn along the track: a = vg^2 du/ds (finite difference over 1 m)
            du = self._circle_field(q + u) - u
            self._rec_h = min(max(self._rec_h - sink * dt, floor), h + 10.0)
            descending = self._rec_h > floor
            vel = np.array([vg * u[0], vg * u[1], sink if descending else 0.0])
            acc = np.array([vg * vg * du[0], vg * vg * du[1], 0.0])
            pos_h = q
        pos = np.array([pos_h[0], pos_h[1], -self._rec_h])
        return RefPoint(t_cycle=0.0, cycle=0, phase=RECOVERY, pos=pos, vel=vel, acc=acc, airspeed=V, alpha=0.0,
                        phi=0.0, thrust=0.0, tension=0.0, length=0.0, reel_speed=0.0)

    @property
    def parked(self) -> bool:
        """RECOVER holds (REC_LAND 0, or vertical gusts above REC_GUST_MAX): circling within 5 m of
        REC_HOLD_ALT, within a quarter of REC_RADIUS of the circle (the line is reeled in to the
        distance plus REC_SLACK)."""
        if self.mode != "RECOVER" or self.rec_stage != "hold" or not self._rec_park:
            return False
        s = self.glider.state()
        rho = math.hypot(float(s.pos_ned[0]), float(s.pos_ned[1]))
        return (abs(-float(s.pos_ned[2]) - self.params["REC_HOLD_ALT"]) < 5.0
                and abs(rho - self.params["REC_RADIUS"]) < 0.25 * self.params["REC_RADIUS"])

    def _recover(self, s: SixDofState, gs: Any, dt: float) -> tuple[Surfaces, WinchCommand]:
        p = self.params
        self.phase = "recovery"
        if self.rec_stage is None:
            self._rec_enter(s)
        h = -float(s.pos_ned[2])
        wind = s.vel_ned - s.vel_air_ned
        r = self._rec_reference(s, wind, dt)
        wcmd = self._recover_winch(s, gs)
        if r is None:
            # flare: wings level, angle of attack for level flight plus a sink-rate term
            # (hold ~0.5 m/s down) until the skids touch
            self.ref_point = None
            v_down = float(s.vel_ned[2])
            sink_target = 0.3 + 0.7 * min(h / max(p["REC_FLARE_ALT"], 0.1), 1.0)  # 1.0 m/s at the top, 0.3 at touchdown
            alpha = self.glider.trim_alpha(max(s.airspeed, 5.0)) + 0.05 * (v_down - sink_target)
            a_max = min(p["LIM_ALPHA_MAX"], 0.9 * self.guidance.aero_u.alpha_max_lift)  # stall margin
            # the motor only guards against stalling (below 80 % of the recovery airspeed)
            thrust = min(max(4.0 * (0.8 * p["REC_AIRSPEED"] - s.airspeed), 0.0), 8.0)
            thr = self._propulsion(thrust, s, dt)
            return self._hold(s, min(max(alpha, 0.0), a_max), 0.0, 0.0, dt, thr), wcmd
        self.ref_point = r
        f_t = np.asarray(gs.force_on_glider_ned) if gs is not None else np.zeros(3)
        cmd = self.guidance.update(r, s.pos_ned, s.vel_ned, wind, f_t, s.fold, dt)
        self.last_guidance = cmd
        self.track_error = cmd.pos_error
        thr = self._propulsion(cmd.thrust, s, dt)
        return self._hold(s, cmd.alpha, cmd.roll, 0.0, dt, thr), wcmd
