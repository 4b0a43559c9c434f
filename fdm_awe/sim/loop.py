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

One driver loop runs this step (:meth:`CoSim._drive`: the commands and phases recorded,
``on_step``, the events, the interrupt, the result) with one of two steppers (:mod:`.steppers`):
the loop body compiled (:mod:`.kernel`: ground station, force,
JSBSim step, state read and event checks in one numba call that reaches JSBSim through the
bindings' library, :mod:`.sixdof.native`), chosen whenever the glider, the ground station and
the machine allow it, and the Python step, its reference, which gives bit-identical results
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
from dataclasses import dataclass
from typing import Any, Callable, Protocol, Sequence

import numpy as np

from .events import CODE, event_message
from ..errors import InputError
from ..jitcache import jit_off
from ..sixdof.adapter import JSBSimGlider
from ..sixdof.state import SixDofState, Surfaces
from .result import COLUMNS, Event, FlightResult, log_table
from .steppers import Stepper, compiled_stepper, python_stepper

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
        #: steps of one such block at most; a block ends at a multiple of it (a flight that samples
        #: every so many steps, e.g. the lumped line's shape, sets it to that number)
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

    def _run_python(self, t_end: float, on_step: Callable[[int, SixDofState, Any], None] | None) -> FlightResult:
        """:meth:`run` in Python, the reference of the compiled loop (the step of the module doc)."""
        s = self.glider.state()
        return self._drive(python_stepper(self, s, self._event), s, int(round(t_end / self.dt)), on_step)

    def _run_compiled(self, t_end: float, on_step: Callable[[int, SixDofState, Any], None] | None,
                      kern: Any, h: Any, gsa: tuple) -> FlightResult:
        """:meth:`run` with the loop body compiled (:mod:`.kernel`): the same steps, the
        same order, identical results. The controller is called every step from Python, unless
        it declares ``constant_commands = True`` (fixed commands, no ``phase`` changes) and no
        ``on_step`` is given: then blocks of up to one simulated second run in one call; or a
        :attr:`block_runner` flies blocks with the controller compiled in, whenever it can."""
        s, n = self.glider.state(), int(round(t_end / self.dt))
        block = (max(1, int(round(1.0 / self.dt))) if getattr(self.controller, "constant_commands", False)
                 and on_step is None else 1)
        return self._drive(compiled_stepper(self, s, n, block, kern, h, gsa, self._event), s, n, on_step)

    def _drive(self, stepper: Stepper, s: SixDofState, n: int,
               on_step: Callable[[int, SixDofState, Any], None] | None) -> FlightResult:
        """The run's loop: ``stepper`` (:mod:`.steppers`) advances from glider state ``s`` until
        ``n`` steps are done, an event, or the end condition (``on_step`` or the block runner's);
        here the bookkeeping of both loops: the commands and phases of the steps' rows, the end
        conditions, the events, the interrupt and the result."""
        ctrl = self.controller
        cmds = _Commands(ctrl, self.glider.controls)
        ctl, phases, has_phase = cmds.controls, cmds.phases, cmds.has_phase
        last_phase, last_code = None, -1
        step, commands, after, to_event = stepper.step, stepper.commands, stepper.after, stepper.event
        gs_out = self.last_gs_output
        event: Event | None = None
        k = 0
        wall0 = time.perf_counter()
        try:
            while k < n:
                done, code, s, gs_out, surf = step(k, s, gs_out)
                if done:
                    k0, k = k, k + done
                    if surf is None:  # a block of the runner's, the controller compiled in
                        ctl.extend(commands(k0, k))
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
                    # the block's bookkeeping (the runner's) or the caller's step; true: the
                    # end condition, status "ok"
                    if after(k0, k, s, gs_out) if surf is None else (on_step is not None and on_step(k, s, gs_out)):
                        break
                if code:
                    event = code if type(code) is Event else to_event(code, s, gs_out)
                    break
        except KeyboardInterrupt:
            event = self._event(CODE.interrupted, s, gs_out)
        wall = time.perf_counter() - wall0
        self.last_gs_output = gs_out
        raws, gsrec = stepper.rows(k)
        # an interrupt may fall between counting a step and appending its commands or phase:
        # keep the rows every record has
        m = min(len(raws), cmds.rows())
        return self._result(raws[:m], gsrec[:m], cmds, event, wall)

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

    def _event(self, code: int, s: SixDofState, gs_out: Any, force: tuple[float, float, float] | None = None,
               error: str = "") -> Event:
        """The :class:`Event` of event ``code`` (:data:`fdm_awe.sim.events.EVENTS`) at state ``s``."""
        kind, message = event_message(code, self.limits, s, gs_out, force, error)
        return Event(kind, s.t, message)


__all__ = ["CoSim", "Controller", "Limits"]
