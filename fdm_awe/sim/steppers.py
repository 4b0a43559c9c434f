"""The co-simulation's steppers: the steps of :class:`fdm_awe.sim.loop.CoSim`'s one driver loop.

A stepper advances the run from step ``k``: :attr:`Stepper.step` ``(k, s, gs_out)`` ->
``(done, code, s, gs_out, surf)``: the steps it did (0 when an event stopped it before a step),
its event code (:data:`fdm_awe.sim.events.EVENTS`; 0: none) or the :class:`~.result.Event`
itself, the state and the ground-station output after them, and the surfaces the steps flew
(None: a block of the ``block_runner`` with the controller compiled in, whose rows
:attr:`Stepper.commands` gives and whose bookkeeping :attr:`Stepper.after` does). It writes the
glider's and the station's rows itself; the driver records the commands and phases, calls
``on_step``, turns the code into an event and assembles the result from :attr:`Stepper.rows`.

- :func:`python_stepper`: one step in Python (controller, ground station, JSBSim, records), the
  reference of the compiled one;
- :func:`compiled_stepper`: a block of the compiled loop body (:mod:`.kernel`): the
  ``block_runner``'s block with the controller compiled in, or the controller called from
  Python and the kernel's block (one step, or up to a second of constant commands).

A step's work is written out in the step functions, with the methods they call bound to local
names beforehand: a call per step costs measurable time there (~60 ns a method call, best of 9
runs of 10^6 steps).
"""

from __future__ import annotations

import math
from array import array
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from .. import slots
from .events import CODE, limit_vector, step_event
from ..errors import InputError
from ..sixdof.row import ROW
from ..sixdof.state import SixDofState
from ..units import FT, LBF
from .result import STATION_COLUMNS, Event

#: ground-station columns of a run's per-step record
_N_GS = len(STATION_COLUMNS)


@dataclass
class Stepper:
    """One stepper of the driver loop (see the module doc)."""

    #: ``(k, s, gs_out)`` -> ``(done, code or Event, s, gs_out, surfaces or None)``
    step: Callable[[int, SixDofState, Any], tuple]
    #: ``(code, s, gs_out)`` -> the :class:`Event` of a step's event code
    event: Callable[[int, SixDofState, Any], Event]
    #: ``(k)`` -> the glider's raw rows and the station's rows of steps 0..k (each an array)
    rows: Callable[[int], tuple[np.ndarray, np.ndarray]]
    #: ``(k0, k1)`` -> the commands of a runner's block's rows
    commands: Callable[[int, int], list] | None = None
    #: ``(k0, k1, s, gs_out)`` -> the runner's bookkeeping of its block; true ends the run
    after: Callable[[int, int, SixDofState, Any], bool] | None = None


def advance_call(glider: Any) -> Callable[[float, float, float], SixDofState]:
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


def python_stepper(sim: Any, s: SixDofState, event: Callable[..., Event]) -> Stepper:
    """The Python step of co-simulation ``sim`` (:class:`~.loop.CoSim`) from glider state ``s``
    (the step of :mod:`.loop`'s module doc); ``event(code, s, gs_out, force, error)`` gives the
    :class:`Event` of an event code."""
    g, gs, ctrl, dt = sim.glider, sim.gs, sim.controller, sim.dt
    # per-step records: raw JSBSim rows, ground-station tuples (flat float arrays: turned into the
    # result's columns without a per-row conversion)
    raws, gsrec = array("d"), array("d")
    raw0 = g.raw()
    ncol = len(raw0)
    raws.extend(raw0)
    gsrec.extend((math.nan,) * _N_GS)  # no ground-station step yet
    # the event checks' thresholds, airborne flag and the state's SI factors (SixDofState)
    lim_v = limit_vector(sim.limits, s.t, not s.on_ground, s.scale[ROW.vt], s.scale[ROW.fbz], s.scale[ROW.mass])
    set_controls, advance = g.set_controls, advance_call(g)
    update, gs_step = ctrl.update, gs.step
    gsrec_add = gsrec.fromlist
    raws_add = raws.fromlist if type(raw0) is list else raws.extend
    check, ndarray, isfinite = step_event, np.ndarray, math.isfinite

    def step(k: int, s: SixDofState, gs_out: Any) -> tuple:
        surf, wcmd = update(s.raw[ROW.t], s, gs_out)
        set_controls(surf)
        hp, hv = s.hook  # the state's tether attachment point (glider.hook_kinematics())
        try:
            gs_out = gs_step(dt, hp, hv, wcmd)
        except InputError as exc:
            return 0, event(CODE.hook_rejected, s, gs_out, error=str(exc)), s, gs_out, surf
        try:
            fx, fy, fz = gs_out.force_xyz
        except AttributeError:  # a ground station whose output has no force_xyz
            f = gs_out.force_on_glider_ned
            if type(f) is ndarray:
                f = f.tolist()
            fx, fy, fz = f[0], f[1], f[2]
        if not isfinite(fx + fy + fz):
            return 0, event(CODE.nonfinite_force, s, gs_out, force=(fx, fy, fz)), s, gs_out, surf
        try:
            s = advance(fx, fy, fz)
        except (RuntimeError, ValueError, ArithmeticError) as exc:  # JSBSim gave up on the state
            return 0, event(CODE.jsbsim_failed, s, gs_out, error=str(exc)), s, gs_out, surf
        r = s.raw
        raws_add(r)  # array.fromlist: the list fast path (extend iterates item by item)
        tension = gs_out.tension
        gsrec_add([tension, gs_out.length, gs_out.reel_speed, gs_out.omega, gs_out.current,
                   gs_out.duty, gs_out.p_electrical, fx, fy, fz])
        return 1, check(r, tension, gs_out.event is not None, lim_v), s, gs_out, surf  # as the compiled step

    def rows(k: int) -> tuple[np.ndarray, np.ndarray]:
        # an interrupt may fall between the appends of a step: the rows both records have
        m = min(len(raws) // ncol, len(gsrec) // _N_GS)
        return (np.frombuffer(raws, dtype=float).reshape(-1, ncol)[:m],
                np.frombuffer(gsrec, dtype=float).reshape(-1, _N_GS)[:m])

    return Stepper(step, event, rows)


def compiled_stepper(sim: Any, s: SixDofState, n: int, block: int, kern: Any, h: Any, gsa: tuple,
                     event: Callable[..., Event]) -> Stepper:
    """The compiled loop body (:mod:`.kernel`) of co-simulation ``sim`` (:class:`~.loop.CoSim`)
    from glider state ``s`` for a run of ``n`` steps: the ``block_runner``'s blocks whenever it
    flies one, else the controller called here and ``block`` steps of the kernel (fewer at the end)
    with its commands, JSBSim reached through the handles ``h``, the station's arrays ``gsa``;
    ``event`` as for :func:`python_stepper`."""
    from . import kernel as ck  # loaded with the kernel (numba): only when the compiled loop runs

    g, gs, ctrl, dt = sim.glider, sim.gs, sim.controller, sim.dt
    raw0 = g.raw()
    nr = len(raw0)
    ng = nr + slots.size(ck.GS)
    width = ng + slots.size(ck.TAIL)
    # the log (see cosim_kernel: raw | station | tail), grown by doubling as the run goes: a
    # long t_end that an event or on_step cuts short does not allocate its whole length
    log = np.full((min(n + 1, 1 << 14), width), math.nan)
    log[0, :nr] = raw0
    s_gs, c_gs, nsub = gsa
    p = kernel_params(g, dt, s, nsub)
    lim_v = np.array(limit_vector(sim.limits, s.t, not s.on_ground, s.scale[ROW.vt], s.scale[ROW.fbz],
                                  s.scale[ROW.mass]))
    update, set_controls, command_terms = ctrl.update, g.set_controls, gs.command_terms
    output_from_row, make_state, sync = gs.output_from_row, g.make_state, g.sync_from_native
    # the compiled function without numba's argument-type dispatch (its one signature)
    call = getattr(next(iter(kern.overloads.values()), None), "entry_point", kern)
    i_motor = ck.COSIM.motor
    runner, block_steps = sim.block_runner, sim.block_steps
    last_wcmd: Any = None
    mode = ""
    python_next = False
    t = s.t

    def step(k: int, s: SixDofState, gs_out: Any) -> tuple:
        nonlocal log, last_wcmd, mode, python_next, t
        # the next steps: a block with the controller compiled in (the runner's), or the
        # controller called here and a block of the kernel
        res = None
        if runner is not None and not python_next:
            m = block_steps - k % block_steps  # to the next multiple of block_steps
            m = m if n - k > m else n - k
            if k + m >= len(log):
                log = np.concatenate((log, np.full((min(n + 1, 2 * len(log) + m) - len(log), width), math.nan)))
            res = runner.run(k, m, log, p, lim_v, s_gs, c_gs, h, gs_out is not None)
        if res is not None:
            done, code, python_next = res
            mode = "motor" if p[i_motor] != 0.0 else "generator"
            last_wcmd = surf = None
        else:
            python_next = False
            surf, wcmd = update(t, s, gs_out)
            set_controls(surf)
            if wcmd is not last_wcmd:
                try:
                    mode, motor, omega_ref, duty, d2, rl = command_terms(wcmd)
                except InputError as exc:  # as GroundStation.step in the Python loop
                    return 0, event(CODE.hook_rejected, s, gs_out, error=str(exc)), s, gs_out, surf
                p[i_motor:i_motor + 5] = (1.0 if motor else 0.0, omega_ref, duty, d2, rl)
                last_wcmd = wcmd
            m = block if n - k > block else n - k
            if k + m >= len(log):
                log = np.concatenate((log, np.full((min(n + 1, 2 * len(log)) - len(log), width), math.nan)))
            done, code = call(h, p, lim_v, log, s_gs, c_gs, k, m)
        if done:
            row = log[k + done].tolist()
            r = row[:nr]
            hx, hy, hz, hvx, hvy, hvz, fx, fy, fz = row[ng:]  # ck.TAIL
            hook, force = ((hx, hy, hz), (hvx, hvy, hvz)), (fx, fy, fz)
            s = make_state(r, hook, force)
            sync(r, hook, force, s)  # the glider's raw(), state(), hook_kinematics() follow
            t = r[ROW.t]
            gs_out = output_from_row(row[nr:ng], mode)
        return done, code, s, gs_out, surf

    def rows(k: int) -> tuple[np.ndarray, np.ndarray]:
        return log[:k + 1, :nr], log[:k + 1, nr:nr + _N_GS]

    return Stepper(step, _compiled_event(event, p), rows,
                   runner.commands if runner is not None else None, runner.after if runner is not None else None)


def kernel_params(g: Any, dt: float, s: SixDofState, nsub: int) -> np.ndarray:
    """The compiled step's parameter vector (layout :data:`.kernel.COSIM`) of glider ``g`` at its state
    ``s``: step ``dt`` [s], the station's sub-steps ``nsub``, the glider's native constants, the unit
    factors, the tether hook's position [m] and velocity [m/s] and the force on it [N]."""
    from . import kernel as ck  # loaded with the kernel (numba): only when the compiled loop runs

    lat0, m0, n0cos, off = g.native_constants()
    P = ck.COSIM
    p = slots.new(P)
    p[P.dt], p[P.nsub], p[P.lat0], p[P.m0], p[P.n0cos] = dt, nsub, lat0, m0, n0cos
    p[P.ox], p[P.oy], p[P.oz] = off
    p[P.ft], p[P.lbf] = FT, LBF
    (p[P.hx], p[P.hy], p[P.hz]), (p[P.hvx], p[P.hvy], p[P.hvz]) = s.hook
    p[P.fx], p[P.fy], p[P.fz] = g.tether_force_ned
    return p


def _compiled_event(event: Callable[..., Event], p: np.ndarray) -> Callable[[int, SixDofState, Any], Event]:
    """The compiled step's :class:`Event` of its event code, as the Python step gives it (by
    ``event``: :meth:`~.loop.CoSim._event`), with the kernel's parameter vector ``p``."""
    from . import kernel as ck  # loaded with the kernel (numba): only when the compiled loop runs

    def compiled_event(code: int, s: SixDofState, gs_out: Any) -> Event:
        if code == CODE.hook_rejected:  # the compiled step checked the hook as GroundStation.step does, with its words
            hp, hv = s.hook
            return event(code, s, gs_out, error="glider position/velocity must be finite, got "
                         f"pos={tuple(hp)!r} vel={tuple(hv)!r}")
        if code == CODE.nonfinite_force:
            return event(code, s, gs_out, force=(float(p[ck.COSIM.fx]), float(p[ck.COSIM.fy]), float(p[ck.COSIM.fz])))
        return event(code, s, gs_out)

    return compiled_event
