"""The autopilot of the tethered glider, structured like a real one.

guidance (:mod:`.guidance`, path tracking by point-mass force inversion)
  -> attitude loops (angle of attack, bank, yaw damper: :class:`fdm_awe.sixdof.Stabilizer`)
  -> thrust loop (throttle)                         -> surfaces, throttle, fold command
phase logic (generation / recovery)                 -> winch command (machine mode, reel speed)

Modes (MAVLink ``custom_mode`` numbers in :data:`fdm_awe.mode_table.MODE_NUMBERS`):

- ``MANUAL``: surfaces and throttle held at :attr:`Autopilot.manual` (neutral by default); the winch in generator mode.
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
- ``RECOVER``: the safe mode. Unfold, glide (motor stopped) to a circle of ``REC_RADIUS`` about
  the winch and descend on it at ``REC_AIRSPEED`` (as steeply as the glider must); the motor runs
  only to hold the level floor circle and against a stall in the flare; the winch reels in
  whatever line hangs slack (at most ``REC_REEL_SPD``); below ``REC_FLARE_ALT`` fly wings level
  and flare. Losing the reference in AUTO (mission cleared) switches to RECOVER.
- ``LOITER``: hold (MAVLink's hold and pause, ArduPlane's LOITER number): RECOVER's path that never
  lands: glide to the ``REC_RADIUS`` circle about the winch and circle there at ``REC_HOLD_ALT``
  with the line reeled in to the distance (RECOVER with ``REC_LAND`` 0, the park). AUTO afterwards
  rejoins the cycle where the glider is.

Pilot sticks (:meth:`~fdm_awe.autopilot.vehicle_commands.VehicleCommands.set_pilot`, from
MAVLink's RC_CHANNELS_OVERRIDE or MANUAL_CONTROL): MANUAL flies them as surfaces and throttle; FBWA takes the roll stick as a bank of up to
``LIM_BANK``, the pitch stick as an angle of attack from the trim's towards ``LIM_ALPHA_MAX``
(pulled) or ``LIM_ALPHA_MIN`` (pushed), and the throttle stick as the throttle. Centred sticks and
a closed throttle are the modes as they were without a pilot.

Gains and limits come from the definition file ``aircraft/glider_foldable/autopilot.xml`` via a
:class:`~fdm_awe.autopilot.params.ParamStore`; changes (e.g. MAVLink ``PARAM_SET``) take effect
at the next step.

This module is the core: the autopilot's state, the path parameter and each step's commands.
Its parts have modules of their own: the ground station's and the pilot's commands (modes,
arming, cycling, the mission: :mod:`.vehicle_commands`), RECOVER's flying (:mod:`.recover_mode`),
the loops' gains (:mod:`.loop_gains`), the thrust loop (:mod:`.thrust`), the motor's gate and
switch (:mod:`.motor`), the fold (:mod:`.fold`), the winch commands (:mod:`.winch`), the rejoin
segment (:mod:`.rejoin`) and RECOVER's path and winch (:mod:`.recovery`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..constants import G0, RHO0
from ..definitions.aircraft import Glider, stall_speed
from ..groundstation import WinchCommand
from ..groundstation.definitions import GroundStationParams, load_ground_station
from ..sixdof.adapter import JSBSimGlider
from ..sixdof.row import ROW
from ..sixdof.state import SixDofState, Surfaces
from .attitude import AttitudeLoops
from .auto_mode import AutoStep
from .auto_step import MEM
from .fold import fold_command, reference_fold_time
from .guidance import POLAR, norm3
from .guidance_loop import Guidance, GuidanceCommand
from .loop_gains import STAB_PARAMS, guidance_gains, stabilizer_gains
from .motor import MotorGate, MotorSwitch
from .params import ParamStore
from .recover_mode import RecoverMode
from .recovery import Recovery
from .thrust import ThrustLoop
from .tracking import RefPoint, TrackingReference
from .vehicle_commands import VehicleCommands

CONFIGS = ("foldable", "nominal")


class Autopilot(VehicleCommands, RecoverMode):
    """Controller for :class:`fdm_awe.sim.loop.CoSim` and :class:`VehicleInterface` for MAVLink.

    ``config``: ``"foldable"`` folds for recovery, ``"nominal"`` never folds.
    ``station``: the ground station's definition, from which the generator's R_L [ohm] (its
    converter's load resistance) and the line's axial stiffness EA [N] (the kinematic winch's
    length) come (None: the default definition, ``tether/ground_station.xml``).
    ``thruster``/``winch``: the paper plant's ideal thruster, ``"ideal"`` for its kinematic winch.
    ``motor``: when AUTO stops the motor (:class:`MotorGate`; default gate if None).
    ``reel_in_max``: the drive's largest reel-in speed [m/s] (ground-station definition,
    :func:`fdm_awe.groundstation.steady.motor_max_reel_in_speed`; inf: no bound of its own).

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
        station: GroundStationParams | None = None,
        rho: float = RHO0,
        g: float = G0,
        thruster: Any = None,
        winch: str = "physical",
        motor: MotorGate | None = None,
        reel_in_max: float = math.inf,
    ) -> None:
        if config not in CONFIGS:
            raise ValueError(f"config {config!r} unknown (allowed: {', '.join(CONFIGS)})")
        if winch not in ("physical", "ideal"):
            raise ValueError(f"winch {winch!r} unknown (allowed: physical, ideal)")
        if reference is not None and config == "foldable":
            reference_fold_time(reference.meta, glider.fold_time_s)
        gsp = station if station is not None else load_ground_station()
        self.R_L = float(gsp.converter.load_resistance)  #: the generator's load resistance [ohm]
        #: the line's axial stiffness EA [N] (the kinematic winch's length)
        self.line_EA = float(gsp.tether.axial_stiffness)
        self._init_state(glider, airframes, params, reference, config, thruster, winch, g)
        af = airframes.unfolded
        self.guidance = Guidance(guidance_gains(params), af.mass.mass, af.aero, airframes.folded.aero, rho, g)
        self.att = AttitudeLoops(glider, stabilizer_gains(params))
        self._t_now = 0.0
        self.thrust_loop = ThrustLoop(params, af.propulsion.T_max, thruster)  #: throttle for the thrust command
        self.reel_in_max = float(reel_in_max)  #: the drive's largest reel-in speed [m/s]
        #: whether AUTO runs the motor (:class:`MotorSwitch` under the gate ``motor``)
        self.motor = MotorSwitch(motor if motor is not None else MotorGate())
        #: RECOVER's path and winch (:class:`~fdm_awe.autopilot.recovery.Recovery`)
        self.recovery = Recovery(params, winch, self.R_L, self.guidance, self._note)
        #: called as ``on_cycle(cycle, t)`` at the AUTO step that starts a new cycle's generation
        #: (``cycle`` its index, ``t`` [s]); a reference it returns is flown from the next step
        #: (:meth:`switch_reference`), None keeps the one flown
        self.on_cycle: Any = None
        #: the latest onboard wind estimate (:class:`~.wind_estimate.WindEstimate`), None before one
        self.wind_estimate: Any = None
        self._rejoin_before = math.inf  # a rejoin searches the reference's points before this cycle time [s]
        self._cycle_begun = 0  # the last cycle whose start went to on_cycle
        for name in params.names():
            params.on_change(name, self._on_param)

    def _init_state(self, glider: JSBSimGlider, airframes: Glider, params: ParamStore,
                    reference: TrackingReference | None, config: str, thruster: Any, winch: str, g: float) -> None:
        """The autopilot's plain state at construction (modes, logs, the last AUTO step's views)."""
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
        self.g = g
        self.reference = reference
        self.mode = "AUTO" if reference is not None else "FBWA"
        self.armed = True
        self.cycling = reference is not None
        #: AUTO's step: its state (path parameter, time, position error, phase, rejoin) and arrays
        self.auto = AutoStep()
        self.path_rate = 1.0
        self._rejoin_pending = False
        self.airborne = True  #: no contact touched the ground at the last step
        #: ground-station link: (up now, was up once, time it was lost [s])
        self._gcs = (False, False, -math.inf)
        #: when the AUTO steps' position error rose above FS_TRK_ERR [s] (NaN: it is below)
        self._trk_since = math.nan
        #: why the glider is in RECOVER: None (not in RECOVER), "commanded" (the start mode, the
        #: ground station's mode change or RTL, its clearing of the mission) or the failsafe's
        #: note ("failsafe: ...": the lost path, the lost link); the flight's exit code reads it
        self.recover_cause: str | None = None
        self._failsafe_note: str | None = None
        #: RECOVER's throttle ceiling and last throttle (:meth:`_recover_throttle`)
        self._rec_ceiling = self._rec_throttle = 1.0
        self.phase = "generation" if reference is not None else "ground"
        self.manual = Surfaces()
        #: FBWA's pilot sticks: roll -1..1 (+ right), pitch -1..1 (+ nose up), throttle 0..1 (:meth:`set_pilot`)
        self.pilot = (0.0, 0.0, 0.0)
        self.log: list[tuple[float, str]] = []
        self._ref_point: RefPoint | None = None
        self._last_guidance: GuidanceCommand | None = None
        # ref_point and last_guidance are the last AUTO step's, built from its arrays when read
        self._auto_point = self._auto_guidance = False

    # ------------------------------------------------------------------ parameters
    def stall_speed(self, fold: float) -> float:
        """The 1 g stall speed [m/s] of the wing at fold state ``fold`` (0 unfolded .. 1 folded),
        as the underspeed protection counts it (:func:`~fdm_awe.definitions.aircraft.stall_speed`
        of the guidance's blended polar)."""
        g = self.guidance
        return stall_speed(g.m, g.rho, g.g, g.polar(fold)[POLAR.clmax])

    def _on_param(self, name: str, value: float) -> None:
        self.auto.invalidate()
        if name in STAB_PARAMS:
            setattr(self.att.gains, STAB_PARAMS[name], float(value))
        else:
            self.guidance.k = guidance_gains(self.params)

    def _note(self, text: str) -> None:
        self.log.append((self._t_now, text))

    @property
    def s_ref(self) -> float:
        """Path parameter: reference time flown so far [s] (cycle k spans k P .. (k+1) P). It
        advances with flight time, faster when the glider is ahead of its reference point and
        slower when behind, so the loops act on the distance to the path rather than on a
        schedule (path following; the cycle's period is the glider's own)."""
        return float(self.auto.mem[MEM.sref])

    @s_ref.setter
    def s_ref(self, value: float) -> None:
        self.auto.mem[MEM.sref] = value

    @property
    def track_error(self) -> float:
        """Position error of the last guided step [m] (NaN before the first)."""
        return float(self.auto.mem[MEM.err])

    @track_error.setter
    def track_error(self, value: float) -> None:
        self.auto.mem[MEM.err] = value

    @property
    def ref_point(self) -> RefPoint | None:
        """The reference point the last step flew (None: none, e.g. RECOVER's flare)."""
        if self._auto_point:
            self._ref_point = self.auto.ref_point(self.reference)  # type: ignore[arg-type]
            self._auto_point = False
        return self._ref_point

    @ref_point.setter
    def ref_point(self, r: RefPoint | None) -> None:
        self._auto_point = False
        self._ref_point = r

    @property
    def last_guidance(self) -> GuidanceCommand | None:
        """The guidance's command of the last guided step."""
        if self._auto_guidance:
            self._last_guidance = self.auto.command()
            self._auto_guidance = False
        return self._last_guidance

    @last_guidance.setter
    def last_guidance(self, cmd: GuidanceCommand | None) -> None:
        self._auto_guidance = False
        self._last_guidance = cmd

    @property
    def rec_stage(self) -> str | None:
        """RECOVER's stage (:attr:`Recovery.stage`): None (not entered), "return", "hold", "final", "flare"."""
        return self.recovery.stage

    @property
    def motor_gate(self) -> MotorGate:
        """When AUTO stops the motor (:class:`MotorGate`)."""
        return self.motor.gate

    @motor_gate.setter
    def motor_gate(self, gate: MotorGate) -> None:
        self.motor.gate = gate

    @property
    def motor_running(self) -> bool:
        """AUTO runs the motor (False: stopped where the reference's motor is off)."""
        return self.motor.running

    @property
    def motor_switches(self) -> int:
        """Motor stops and starts in AUTO so far."""
        return self.motor.switches

    @property
    def motor_rescue(self) -> bool:
        """The motor runs for a position error beyond :attr:`MotorGate.rescue_error_m`."""
        return self.motor.rescue

    # ------------------------------------------------------------------ FBWA
    def _fbwa(self, s: SixDofState, dt: float) -> Surfaces:
        """FBWA's commands: the pilot's bank, angle of attack and throttle (:attr:`pilot`); wings
        level at the trim angle of attack and no thrust with centred sticks and a closed throttle."""
        p = self.params
        roll_stick, pitch_stick, thr = self.pilot
        alpha = self.glider.trim_alpha(max(s.airspeed, 8.0))
        if pitch_stick > 0.0:
            alpha += pitch_stick * max(p["LIM_ALPHA_MAX"] - alpha, 0.0)
        elif pitch_stick < 0.0:
            alpha += pitch_stick * max(alpha - p["LIM_ALPHA_MIN"], 0.0)
        if thr > 0.0 and self.armed:
            if self.thruster is not None:
                self.thruster.command(thr * self.thruster.T_max)
                thr = 0.0
        else:
            self.thrust_loop.propulsion(0.0, s, dt, self.armed)
            thr = 0.0
        return self._hold(s, min(alpha, p["LIM_ALPHA_MAX"]), roll_stick * p["LIM_BANK"], 0.0, dt, thr)

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

    def fold_command(self, t_cycle: float, T1: float, period: float) -> float:
        """Fold command (0 open .. 1 folded) at cycle time ``t_cycle`` [s] of a cycle of
        ``period`` [s] whose recovery starts at ``T1`` [s]: :func:`~fdm_awe.autopilot.fold.fold_command`
        with the reference's fold time (metadata ``fold_time_s``, absent = 0) and FOLD_LEAD,
        UNFOLD_LEAD; 0 for the nominal configuration."""
        if self.config != "foldable":
            return 0.0
        ft = reference_fold_time(self.reference.meta, self.glider.fold_time_s) if self.reference is not None else 0.0
        return fold_command(t_cycle, T1, period, ft, self.params["FOLD_LEAD"], self.params["UNFOLD_LEAD"])

    def _hold(self, s: SixDofState, alpha: float, roll: float, fold: float, dt: float, throttle: float = 0.0) -> Surfaces:
        a, e, r = self.att.update(s, alpha, roll, dt)
        return Surfaces(a, e, r, throttle, fold)

    # ------------------------------------------------------------------ controller
    def update(self, t: float, s: SixDofState, gs: Any) -> tuple[Surfaces, WinchCommand]:
        mem = self.auto.mem
        tl = mem[MEM.tlast]
        dt = 0.0 if tl != tl else max(0.0, t - float(tl))
        self._t_now = t
        self.airborne = not s.on_ground
        if self.mode == "AUTO" and self.cycling and self.reference is not None:
            return self._auto(t, s, gs)  # the AUTO step keeps its own time (auto_guide)
        mem[MEM.tlast] = t
        if self.mode == "MANUAL":
            self.phase = "ground" if s.on_ground else self.phase
            if self.thruster is not None:
                self.thruster.command(self.manual.throttle * self.thruster.T_max)
            return self.manual, WinchCommand(mode="generator", load_resistance=self.R_L)
        if self.mode in ("RECOVER", "LOITER"):
            return self._recover(s, gs, dt)
        # FBWA (or AUTO without a path): the pilot's sticks; centred: wings level, trim alpha, no thrust
        return self._fbwa(s, dt), WinchCommand(mode="generator", load_resistance=self.R_L)

    def _rejoin_start(self, ref: TrackingReference, s: SixDofState, t: float) -> None:
        """Begin a rejoin segment: the path parameter moves to the reference point nearest the
        glider's position and velocity (velocity error weighted by 2 s), and the offset
        between them decays over RJ_TIME (:func:`~fdm_awe.autopilot.rejoin.rejoin_weights`)."""
        self._rejoin_pending = False
        T = self.params["RJ_TIME"]
        cost = (np.sum((ref.pos - s.pos_ned) ** 2, axis=1) + 4.0 * np.sum((ref.vel - s.vel_ned) ** 2, axis=1))
        if self._rejoin_before < math.inf:  # a switch at a cycle boundary: on the new cycle's generation
            cost = np.where(np.asarray(ref.t) < self._rejoin_before, cost, math.inf)
            self._rejoin_before = math.inf
        i = int(np.argmin(cost))
        self.s_ref = self._cycle_start() + float(ref.t[i])
        self.guidance.reset()
        self.auto.end_rejoin()
        if T <= 0.0:
            return
        r0 = ref.sample(self.s_ref)
        dp, dv = np.asarray(s.pos_ned - r0.pos, float), np.asarray(s.vel_ned - r0.vel, float)
        self.auto.begin_rejoin(t, dp, dv)
        self._note(f"rejoin: {norm3(dp):.1f} m, {norm3(dv):.1f} m/s from the path "
                   f"at t_cycle {r0.t_cycle:.2f} s, over {T:g} s")

    def _auto(self, t: float, s: SixDofState, gs: Any) -> tuple[Surfaces, WinchCommand]:
        """One AUTO step (:meth:`~fdm_awe.autopilot.auto_mode.AutoStep.step`)."""
        if self._rejoin_pending:
            self._rejoin_start(self.reference, s, t)  # type: ignore[arg-type]
        self._auto_point = self._auto_guidance = True
        before = self.phase
        surf, wcmd, notes = self.auto.step(self, s, gs)
        for text in notes:
            self._note(text)
        self.path_rate = self.auto.path_rate
        self._track_failsafe(t)
        if (before == "recovery" and self.phase == "generation" and self.on_cycle is not None and self.mode == "AUTO"
                and self.cycle > self._cycle_begun):
            self._cycle_begun = self.cycle  # once per cycle (not again after a RECOVER rejoins the same cycle)
            new = self.on_cycle(self.cycle, t)
            if new is not None:
                self.switch_reference(new)
        return surf, wcmd

    def switch_reference(self, reference: TrackingReference) -> None:
        """Fly ``reference`` from the next step on, in the cycle under way: the path parameter
        keeps the cycle's index on the new period, and a rejoin segment (:meth:`_rejoin_start`)
        takes the glider from where it is to the nearest point (position and velocity) of the
        new reference's generation phase, so the switch at a cycle boundary is as smooth as a
        rejoin."""
        if self.config == "foldable":
            reference_fold_time(reference.meta, self.glider.fold_time_s)
        k = self.cycle
        self._note(f"reference switched at cycle {k}: {self.reference.meta.get('wind_mps', float('nan')):g} -> "
                   f"{reference.meta.get('wind_mps', float('nan')):g} m/s")
        self.reference = reference
        self.s_ref = k * reference.period
        self._rejoin_before = reference.T1
        self._rejoin_pending = True

    def _track_failsafe(self, t: float) -> None:
        """The lost-path failsafe after an AUTO step at time ``t`` [s]: a position error above
        FS_TRK_ERR (> 0) for FS_TRK_TIME switches an armed glider in flight to RECOVER. The
        compiled blocks hand every step with the error above the bound to this Python step
        (:data:`~fdm_awe.autopilot.auto_step.TRACK_LOST`), so both time it alike."""
        if not self.auto.track_lost:
            self._trk_since = math.nan
            return
        if self._trk_since != self._trk_since:
            self._trk_since = t
        p = self.params
        if t - self._trk_since >= p["FS_TRK_TIME"] and self.armed and self.airborne:
            self._failsafe(f"failsafe: {self.track_error:.1f} m from the path for {t - self._trk_since:.1f} s "
                           f"(FS_TRK_ERR {p['FS_TRK_ERR']:g} m)")

    def kernel_arrays(self) -> tuple | None:
        """The arrays of a compiled block (:func:`fdm_awe.sim.autopilot_kernel.autopilot_steps`)
        when the next steps are plain AUTO steps (cycling on a reference, no rejoin to begin, the
        physical plant), else None (the Python autopilot flies the next step)."""
        if not (self.mode == "AUTO" and self.cycling and self.reference is not None) or self._rejoin_pending:
            return None
        if self.thruster is not None:
            return None
        return self.auto.kernel_arrays(self)

    def after_block(self, raw: Any) -> None:
        """After a compiled block of AUTO steps ending in the raw row ``raw``: the step's time,
        the ground contact, the last step's reference point and command (built when read)."""
        self._t_now = self.auto.t_last
        self.airborne = not raw[ROW.wow] > 0.5
        self._auto_point = self._auto_guidance = True
        self.path_rate = self.auto.path_rate
