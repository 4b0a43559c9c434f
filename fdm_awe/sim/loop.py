"""Fixed-step lock-step co-simulation: 6-DOF glider (JSBSim) + ground station + controller.

One step of length ``dt`` (120 Hz by default), in this order:

1. ``controller.update(t, glider_state, gs_output)`` -> ``(Surfaces, WinchCommand)`` -- the
   controller sees the glider state at ``t`` and the ground-station output of the previous step
   (None on the first step);
2. ``ground_station.step(dt, hook_pos, hook_vel, winch_cmd)`` with the tether attachment point at
   ``t``; it returns the line force to apply over ``[t, t + dt]`` (it may sub-step internally);
3. the force goes on the JSBSim tether hook, the surfaces on the FCS, JSBSim advances ``dt``;
4. the new state is logged and checked for events.

Events end the run cleanly: ``ground_contact`` (a contact touches the ground after the glider
was airborne), ``tether_break`` (reported by the ground station), ``nonfinite`` (state or line
force not finite), ``airspeed_limit``, ``load_limit`` (line tension or load factor), and
``interrupted`` (KeyboardInterrupt). Other ground-station events (e.g.
``tether_fully_reeled_in``) end the run with that name as the status. The result always holds
the data up to and including the step that raised the event.

Two loops run this step: the loop body compiled (:mod:`.kernel`: ground station, force,
JSBSim step, state read and event checks in one numba call that reaches JSBSim through the
bindings' library, :mod:`.sixdof.native`), chosen whenever the glider, the ground station and
the machine allow it, and the Python loop, its reference, which gives bit-identical results
(``CoSim(compiled=False)`` or ``FDM_AWE_JIT=0`` select it; after a run, :attr:`CoSim.loop` and
:attr:`CoSim.loop_reason` say which ran and why). The controller is called from Python every
step either way; one that declares ``constant_commands = True`` lets the compiled loop run in
blocks of one simulated second when no ``on_step`` is given.

This module wires blocks; it holds no physics. The run's result (statuses, events, the logged
columns, :class:`~fdm_awe.sim.result.FlightResult`) is :mod:`fdm_awe.sim.result`.
"""

from __future__ import annotations

import math
import time
from array import array
from dataclasses import dataclass
from typing import Any, Callable, Protocol, Sequence

import numpy as np

from .events import E_FORCE, E_HOOK, E_INTERRUPT, E_JSBSIM, E_NONE, event_message, limit_vector, step_event
from ..errors import InputError
from ..jitcache import jit_off
from ..sixdof.adapter import JSBSimGlider
from ..sixdof.row import FBZ, MASS, T, VT
from ..sixdof.state import SixDofState, Surfaces
from ..units import FT, LBF
from .result import COLUMNS, STATION_COLUMNS, Event, FlightResult, log_table

#: ground-station columns of a run's per-step record
_N_GS = len(STATION_COLUMNS)


class Controller(Protocol):
    """Anything with ``update(t, glider_state, gs_output) -> (Surfaces, WinchCommand)``.

    An optional attribute ``phase`` (str) is recorded every step. An optional attribute
    ``constant_commands = True`` promises the same commands (and phase) every step: the
    compiled loop may then call ``update`` once per block of steps."""

    def update(self, t: float, glider_state: SixDofState, gs_output: Any) -> tuple[Surfaces, Any]: ...


class GroundStationLike(Protocol):
    def step(self, dt: float, pos_ned: Sequence[float], vel_ned: Sequence[float], cmd: Any) -> Any: ...


@dataclass(frozen=True)
class Limits:
    """Event thresholds (None disables a check). Speeds m/s, tension N, load factor in g."""

    airspeed_min: float | None = None
    airspeed_max: float | None = 40.0
    max_tension: float | None = 150.0
    max_load_factor: float | None = 12.0
    ground_contact: bool = True
    grace_s: float = 0.0  #: s from the start during which the airspeed limits are not checked

    def __post_init__(self) -> None:
        for name in ("airspeed_min", "airspeed_max", "max_tension", "max_load_factor"):
            v = getattr(self, name)
            if v is not None and not (math.isfinite(v) and v >= 0.0):
                raise InputError(f"Limits.{name}: {v!r} out of range (allowed >= 0 or None)")
        if not (self.grace_s >= 0.0):
            raise InputError(f"Limits.grace_s: {self.grace_s!r} out of range (allowed >= 0)")


class _Commands:
    """The commands of a run's rows: the surfaces of each row (:attr:`controls`) and, for a
    controller with a ``phase`` (:attr:`has_phase`), its code per row (:attr:`phases`; codes
    index :attr:`labels`, in the order the phases first appeared)."""

    def __init__(self, ctrl: Any, controls: Surfaces) -> None:
        self.has_phase = hasattr(ctrl, "phase")
        self.controls: list[Surfaces] = [controls]
        self.labels: list[str] = []
        self._codes: dict[str, int] = {}
        self.phases: list[int] = [self.code(getattr(ctrl, "phase", None))]

    def code(self, phase: Any) -> int:
        """The code of ``phase`` (the next free one for a phase not seen yet); -1 for None."""
        if phase is None:
            return -1
        code = self._codes.get(phase)
        if code is None:
            code = self._codes[phase] = len(self.labels)
            self.labels.append(str(phase))
        return code

    def rows(self) -> int:
        """The rows every record has (an interrupt may fall between the appends of a step)."""
        return min(len(self.controls), len(self.phases)) if self.has_phase else len(self.controls)


def _advance_call(glider: Any) -> Callable[[float, float, float], SixDofState]:
    """``glider.advance(fx, fy, fz)``: the tether force [N] applied, one step, the new state in one
    call; on a glider without it, the three calls it stands for."""
    advance = getattr(glider, "advance", None)
    if advance is not None:
        return advance
    set_tf, step, state = glider.set_tether_force, glider.step, glider.state

    def three_calls(fx: float, fy: float, fz: float) -> SixDofState:
        set_tf((fx, fy, fz))
        step()
        return state()

    return three_calls


class CoSim:
    """Lock-step loop of ``glider`` (:class:`JSBSimGlider`), ``ground_station`` (anything with the
    ground-station ``step`` signature) and ``controller`` (:class:`Controller`).

    The glider must have been reset; ``dt`` must equal the glider's step.
    """

    def __init__(self, glider: JSBSimGlider, ground_station: GroundStationLike, controller: Controller,
                 dt: float | None = None, limits: Limits | None = None, compiled: bool | None = None) -> None:
        dt = glider.dt if dt is None else float(dt)
        if abs(dt - glider.dt) > 1e-12:
            raise InputError(f"dt: {dt!r} differs from the glider's JSBSim step {glider.dt!r}")
        self.glider = glider
        self.gs = ground_station
        self.controller = controller
        self.dt = dt
        self.limits = limits or Limits()
        self.last_gs_output: Any = None
        self.compiled = compiled
        #: which loop the last :meth:`run` used: "compiled" or "python", and why not compiled
        self.loop = ""
        self.loop_reason = ""
        #: runs blocks of steps with the controller compiled in (the compiled loop only; e.g.
        #: :class:`fdm_awe.sim.autopilot_kernel.AutopilotBlocks`): ``run(k, m, log, p, lim, s_gs,
        #: c_gs, h, gs_ready)`` -> None (the controller steps in Python now) or ``(steps done,
        #: event code, python_next)``, ``commands(k0, k1)`` (each row's five commands, lists) and
        #: ``after(k0, k1, state, gs_output)`` (the rows' bookkeeping; true ends the run)
        self.block_runner: Any = None
        #: steps of one such block at most
        self.block_steps = 1 << 12

    def _compiled_loop(self) -> tuple[Any, Any, Any] | str:
        """(kernel, handles, ground-station arrays) of the compiled loop, or why it can't run."""
        if self.compiled is False:
            return "compiled=False"
        why = jit_off()
        if why:
            return why
        if not isinstance(self.glider, JSBSimGlider):
            return "not a JSBSimGlider"
        if not hasattr(self.gs, "compiled_step_args"):
            return "ground station without a compiled step"
        gsa = self.gs.compiled_step_args(self.dt)
        if gsa is None:
            return "ground station steps in Python"
        h, why = self.glider.native_handles()
        if h is None:
            return why
        from .kernel import compiled_kernel  # imports numba (about 1 s): only when a compiled loop may run

        kern = compiled_kernel()
        if kern is None:
            return "numba not available"
        return kern, h, gsa

    def run(self, t_end: float, on_step: Callable[[int, SixDofState, Any], None] | None = None) -> FlightResult:
        """Run for ``t_end`` s of simulated time (or until an event); ``on_step(k, state, gs_out)``
        is called after every step when given, and a true return value ends the run there
        with status ``ok``."""
        if not (t_end > 0.0 and math.isfinite(t_end)):
            raise InputError(f"t_end: {t_end!r} out of range (allowed > 0 s)")
        loop = self._compiled_loop()
        if type(loop) is tuple:
            self.loop, self.loop_reason = "compiled", ""
            return self._run_compiled(t_end, on_step, *loop)
        if self.compiled:
            raise InputError(f"compiled: the compiled loop is not available here ({loop})")
        self.loop, self.loop_reason = "python", str(loop)
        return self._run_python(t_end, on_step)

    # Both loops write each step's work out in the loop body, with the methods it calls bound to
    # local names before the loop: a call per step costs measurable time there. Measured: a
    # method that records a step's commands and phase costs ~60 ns more per step than the same
    # lines in the loop (best of 9 runs of 10^6 steps); the compiled loop's body cut into its
    # parts (the block's records, the state rebuilt from the log row) would pay two or three such
    # calls with their arguments and results, 1-2 % of a compiled step with the controller
    # called every step (11 us).

    def _run_python(self, t_end: float, on_step: Callable[[int, SixDofState, Any], None] | None) -> FlightResult:
        """:meth:`run` in Python, the reference of the compiled loop (the step of the module doc)."""
        g, gs, ctrl, dt, lim = self.glider, self.gs, self.controller, self.dt, self.limits
        n = int(round(t_end / dt))
        # per-step records: raw JSBSim rows, ground-station tuples, commands (converted at the end)
        # (flat float arrays: turned into the result's columns without a per-row conversion)
        raws, gsrec = array("d"), array("d")
        cmds = _Commands(ctrl, g.controls)
        ctl, phases = cmds.controls, cmds.phases
        s = g.state()
        raw0 = g.raw()
        ncol = len(raw0)
        raws.extend(raw0)
        gsrec.extend((math.nan,) * _N_GS)  # no ground-station step yet
        r = s.raw  # the state's raw JSBSim row (positions of sixdof.row)
        # the event checks' thresholds, airborne flag and the state's SI factors (SixDofState)
        lim_v = limit_vector(lim, s.t, not s.on_ground, s.scale[VT], s.scale[FBZ], s.scale[MASS])
        gs_out = self.last_gs_output
        event: Event | None = None
        k = 0
        set_controls, advance = g.set_controls, _advance_call(g)
        update, gs_step = ctrl.update, gs.step
        gsrec_add = gsrec.fromlist
        raws_add = raws.fromlist if type(raw0) is list else raws.extend
        has_phase = cmds.has_phase
        last_phase, last_code = None, -1
        check, ndarray, isfinite = step_event, np.ndarray, math.isfinite
        wall0 = time.perf_counter()
        try:
            while k < n:
                surf, wcmd = update(r[T], s, gs_out)
                set_controls(surf)
                hp, hv = s.hook  # the state's tether attachment point (glider.hook_kinematics())
                try:
                    gs_out = gs_step(dt, hp, hv, wcmd)
                except InputError as exc:
                    event = self._event(E_HOOK, s, gs_out, error=str(exc))
                    break
                try:
                    fx, fy, fz = gs_out.force_xyz
                except AttributeError:  # a ground station whose output has no force_xyz
                    f = gs_out.force_on_glider_ned
                    if type(f) is ndarray:
                        f = f.tolist()
                    fx, fy, fz = f[0], f[1], f[2]
                if not isfinite(fx + fy + fz):
                    event = self._event(E_FORCE, s, gs_out, force=(fx, fy, fz))
                    break
                try:
                    s_new = advance(fx, fy, fz)
                except (RuntimeError, ValueError, ArithmeticError) as exc:  # JSBSim gave up on the state
                    event = self._event(E_JSBSIM, s, gs_out, error=str(exc))
                    break
                k += 1
                s = s_new
                r = s.raw
                raws_add(r)  # array.fromlist: the list fast path (extend iterates item by item)
                tension = gs_out.tension
                gsrec_add([tension, gs_out.length, gs_out.reel_speed, gs_out.omega, gs_out.current,
                           gs_out.duty, gs_out.p_electrical, fx, fy, fz])
                ctl.append(surf)
                if has_phase:
                    ph = ctrl.phase
                    if ph is not last_phase:
                        last_phase = ph
                        last_code = cmds.code(ph)
                    phases.append(last_code)
                if on_step is not None and on_step(k, s, gs_out):
                    break  # the caller's end condition (e.g. N cycles flown): status "ok"
                code = check(r, tension, gs_out.event is not None, lim_v)  # as the compiled step
                if code:
                    event = self._event(code, s, gs_out)
                    break
        except KeyboardInterrupt:
            event = self._event(E_INTERRUPT, s, gs_out)
        wall = time.perf_counter() - wall0
        self.last_gs_output = gs_out
        m = min(len(raws) // ncol, len(gsrec) // _N_GS, cmds.rows())
        return self._result(np.frombuffer(raws, dtype=float).reshape(-1, ncol)[:m],
                            np.frombuffer(gsrec, dtype=float).reshape(-1, _N_GS)[:m], cmds, event, wall)

    # over 80 lines: its loop body written out (see the note above _run_python)
    def _run_compiled(self, t_end: float, on_step: Callable[[int, SixDofState, Any], None] | None,
                      kern: Any, h: Any, gsa: tuple) -> FlightResult:
        """:meth:`run` with the loop body compiled (:mod:`.kernel`): the same steps, the
        same order, identical results. The controller is called every step from Python, unless
        it declares ``constant_commands = True`` (fixed commands, no ``phase`` changes) and no
        ``on_step`` is given: then blocks of up to one simulated second run in one call; or a
        :attr:`block_runner` flies blocks with the controller compiled in, whenever it can."""
        from . import kernel as ck  # loaded with the kernel (numba): only when the compiled loop runs

        g, gs, ctrl, dt = self.glider, self.gs, self.controller, self.dt
        n = int(round(t_end / dt))
        s = g.state()
        raw0 = g.raw()
        nr = len(raw0)
        ng = nr + len(ck.GS_COLUMNS)
        width = ng + len(ck.TAIL_COLUMNS)
        # the log (see cosim_kernel: raw | station | tail), grown by doubling as the run goes: a
        # long t_end that an event or on_step cuts short does not allocate its whole length
        log = np.full((min(n + 1, 1 << 14), width), math.nan)
        log[0, :nr] = raw0
        s_gs, c_gs, nsub = gsa
        p = self._kernel_params(s, nsub)
        lim_v = np.array(limit_vector(self.limits, s.t, not s.on_ground, s.scale[VT], s.scale[FBZ], s.scale[MASS]))
        cmds = _Commands(ctrl, g.controls)
        ctl, phases, has_phase = cmds.controls, cmds.phases, cmds.has_phase
        last_phase, last_code = None, -1
        block = (max(1, int(round(1.0 / dt))) if getattr(ctrl, "constant_commands", False) and on_step is None
                 else 1)
        gs_out = self.last_gs_output
        update, set_controls, command_terms = ctrl.update, g.set_controls, gs.command_terms
        output_from_row, make_state, sync = gs.output_from_row, g.make_state, g.sync_from_native
        # the compiled function without numba's argument-type dispatch (its one signature)
        call = getattr(next(iter(kern.overloads.values()), None), "entry_point", kern)
        i_motor = ck.P_MOTOR
        last_wcmd: Any = None
        mode = ""
        event: Event | None = None
        k = 0
        t = s.t
        wall0 = time.perf_counter()
        runner, python_next = self.block_runner, False
        try:
            while k < n:
                # the next steps: a block with the controller compiled in (the runner's), or the
                # controller called here and a block of the kernel (one step, or up to a second
                # of constant commands)
                res = None
                if runner is not None and not python_next:
                    m = self.block_steps if n - k > self.block_steps else n - k
                    if k + m >= len(log):
                        log = np.concatenate((log, np.full((min(n + 1, 2 * len(log) + m) - len(log), width), math.nan)))
                    res = runner.run(k, m, log, p, lim_v, s_gs, c_gs, h, gs_out is not None)
                if res is not None:
                    done, code, python_next = res
                    mode = "motor" if p[i_motor] != 0.0 else "generator"
                    last_wcmd = None
                else:
                    python_next = False
                    surf, wcmd = update(t, s, gs_out)
                    set_controls(surf)
                    if wcmd is not last_wcmd:
                        try:
                            mode, motor, omega_ref, duty, d2, rl = command_terms(wcmd)
                        except InputError as exc:  # as GroundStation.step in the Python loop
                            event = self._event(E_HOOK, s, gs_out, error=str(exc))
                            break
                        p[i_motor:i_motor + 5] = (1.0 if motor else 0.0, omega_ref, duty, d2, rl)
                        last_wcmd = wcmd
                    m = block if n - k > block else n - k
                    if k + m >= len(log):
                        log = np.concatenate((log, np.full((min(n + 1, 2 * len(log)) - len(log), width), math.nan)))
                    done, code = call(h, p, lim_v, log, s_gs, c_gs, k, m)
                if done:
                    k0, k = k, k + done
                    if res is not None:
                        ctl.extend(runner.commands(k0, k))
                    elif done == 1:
                        ctl.append(surf)
                    else:
                        ctl.extend([surf] * done)
                    if has_phase:
                        ph = ctrl.phase
                        if ph is not last_phase:
                            last_phase = ph
                            last_code = cmds.code(ph)
                        if done == 1:
                            phases.append(last_code)
                        else:
                            phases.extend([last_code] * done)
                    row = log[k].tolist()
                    r = row[:nr]
                    hx, hy, hz, hvx, hvy, hvz, fx, fy, fz = row[ng:]  # ck.TAIL_COLUMNS
                    hook, force = ((hx, hy, hz), (hvx, hvy, hvz)), (fx, fy, fz)
                    s = make_state(r, hook, force)
                    sync(r, hook, force, s)  # the glider's raw(), state(), hook_kinematics() follow
                    t = r[T]
                    gs_out = output_from_row(row[nr:ng], mode)
                    # the block's bookkeeping (the runner's) or the caller's step; true: the
                    # end condition, status "ok"
                    if runner.after(k0, k, s, gs_out) if res is not None else (on_step is not None
                                                                               and on_step(k, s, gs_out)):
                        code = E_NONE
                        break
                if code != E_NONE:
                    event = self._compiled_event(code, s, gs_out, p)
                    break
        except KeyboardInterrupt:
            event = self._event(E_INTERRUPT, s, gs_out)
        wall = time.perf_counter() - wall0
        self.last_gs_output = gs_out
        # an interrupt may fall between counting a step and appending its commands or phase:
        # keep the rows every record has
        m = min(k + 1, cmds.rows())
        return self._result(log[:m, :nr], log[:m, nr:nr + _N_GS], cmds, event, wall)

    def _kernel_params(self, s: SixDofState, nsub: int) -> np.ndarray:
        """The compiled step's parameter vector (:mod:`.kernel`'s ``P_*``) at glider state ``s``:
        step [s], the station's sub-steps, the glider's native constants, the unit factors, the
        tether hook's position [m] and velocity [m/s] and the force on it [N]."""
        from . import kernel as ck  # loaded with the kernel (numba): only when the compiled loop runs

        g = self.glider
        lat0, m0, n0cos, off = g.native_constants()
        p = np.zeros(ck.N_PARAMS)
        p[ck.P_DT], p[ck.P_NSUB], p[ck.P_LAT0], p[ck.P_M0], p[ck.P_N0COS] = self.dt, nsub, lat0, m0, n0cos
        p[ck.P_OX], p[ck.P_OY], p[ck.P_OZ] = off
        p[ck.P_FT], p[ck.P_LBF] = FT, LBF
        (p[ck.P_HX], p[ck.P_HY], p[ck.P_HZ]), (p[ck.P_HVX], p[ck.P_HVY], p[ck.P_HVZ]) = s.hook
        p[ck.P_FX], p[ck.P_FY], p[ck.P_FZ] = g.tether_force_ned
        return p

    def _result(self, raws: np.ndarray, gsrec: np.ndarray, cmds: "_Commands", event: Event | None,
                wall: float) -> FlightResult:
        """The :class:`FlightResult` of a run's rows (glider rows ``raws``, station rows
        ``gsrec``, commands ``cmds``), ended by ``event`` (None: the run's end) after ``wall`` s."""
        m = len(raws)
        data = log_table(self.glider.convert_raw, raws, gsrec, cmds.controls[:m],
                         cmds.phases if cmds.has_phase else None)
        if event is not None and event.kind == "interrupted" and m:
            event = Event("interrupted", float(data[-1, COLUMNS.index("t")]), event.message)
        status = "ok" if event is None else event.kind
        return FlightResult(status=status, event=event, data=data, phase_labels=cmds.labels, dt=self.dt, wall_s=wall,
                            steps=m - 1)

    def _compiled_event(self, code: int, s: SixDofState, gs_out: Any, p: np.ndarray) -> Event:
        """The :class:`Event` of a compiled loop's event code, as the Python loop gives it."""
        from . import kernel as ck  # loaded with the kernel (numba): only when the compiled loop runs

        if code == E_HOOK:  # the compiled step checked the hook as GroundStation.step does, with its words
            hp, hv = s.hook
            return self._event(code, s, gs_out, error="glider position/velocity must be finite, got "
                               f"pos={tuple(hp)!r} vel={tuple(hv)!r}")
        if code == E_FORCE:
            return self._event(code, s, gs_out, force=(float(p[ck.P_FX]), float(p[ck.P_FY]), float(p[ck.P_FZ])))
        return self._event(code, s, gs_out)

    def _event(self, code: int, s: SixDofState, gs_out: Any, force: tuple[float, float, float] | None = None,
               error: str = "") -> Event:
        """The :class:`Event` of event ``code`` (:data:`fdm_awe.sim.events.EVENTS`) at state ``s``."""
        kind, message = event_message(code, self.limits, s, gs_out, force, error)
        return Event(kind, s.t, message)


__all__ = ["CoSim", "Controller", "Limits"]
