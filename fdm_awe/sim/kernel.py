"""The co-simulation step compiled: ground station, tether hook, JSBSim step, state read, events.

:func:`cosim_steps` runs ``n`` steps of :class:`fdm_awe.sim.loop.CoSim`'s loop body without Python
in between: the ground station's step (its line model's:
:func:`fdm_awe.groundstation.linemodels.line_step` dispatches on the model's code in the
station's constants) on the hook kinematics of the current state, the force written to the
JSBSim tether hook, one ``FGFDMExec::Run()``, the state's properties read into the next log row, the next hook
kinematics (:func:`fdm_awe.sixdof.row.hook_kinematics`), and the event checks
(:func:`fdm_awe.sim.events.step_event`): the same functions the Python loop runs. JSBSim is called through its
library (:mod:`fdm_awe.sixdof.native`); the operations are those of the Python path
(``JSBSimGlider.advance``/``_read``, ``GroundStation.step``, ``CoSim.run``) in the same order, so
both give identical results (tested).

Arguments are packed to keep a one-step call cheap:

- ``h`` int64 (layout :data:`HANDLES`): Run, getDoubleValue, setDoubleValue, FGFDMExec*, the
  three tether-force nodes (x, y, z), then the nodes read per step (0: constant 0.0), in the
  order of the raw row (:mod:`fdm_awe.sixdof.row`);
- ``p`` float64 parameters (layout :data:`COSIM`): step, sub-steps, frame and hook constants, the
  winch command's terms, the current hook kinematics (updated) and the last line force
  (updated);
- ``lim`` float64 thresholds of the event checks and the airborne flag (updated), as
  :func:`fdm_awe.sim.events.limit_vector` builds them;
- ``log`` one row per step (row ``k0``: the current state), each row the JSBSim values (one
  per read node), then the ground-station outputs (:data:`GS`), then the hook
  kinematics after the step and the line force applied during it (:data:`TAIL`), so
  that one ``log[k].tolist()`` hands a step over to Python;
- ``s_gs``, ``c_gs`` the ground station's state and constants (updated in place).

Returns ``(steps done, event code)``; the event code (:data:`fdm_awe.sim.events.CODE`) belongs to the last
step done (or, for a rejected hook or a non-finite force, to the step that was not done).
"""

from __future__ import annotations

import math
import sys
from typing import Any, Callable

from .. import slots
from .events import CODE, step_event
from ..groundstation.linemodels import kernel_called, kernel_sources, line_step
from ..jitcache import compiled_once, is_cached, jit_off
from ..groundstation.substeps import CONST, STATION
from ..sixdof.row import hook_kinematics

#: the parameters ``p``: step s, sub-steps, the frame's and the hook's constants (home latitude
#: rad, meridian radius m, N0 cos(lat0) m, the hook's offset from the CG m body axes, m per ft, N
#: per lbf), the winch command's terms (motor flag, speed reference rad/s, T1 duty, T2 duty, load
#: ohm), the current hook position m and velocity m/s NED (updated) and the last line force N
#: (updated)
COSIM = slots.declare("CosimParams", ("dt", "nsub", "lat0", "m0", "n0cos", "ox", "oy", "oz", "ft", "lbf", "motor",
                                    "wref", "duty", "d2", "rl", "hx", "hy", "hz", "hvx", "hvy", "hvz", "fx", "fy",
                                    "fz"))
#: the int64 handles ``h``: the calls, the object, the tether-force nodes, then from ``getters``
#: the read nodes
HANDLES = slots.declare("CosimHandles", ("run", "get", "set", "fdm", "tx", "ty", "tz", "getters"))
#: ground-station output columns per row, after the raw values (the first ten are CoSim's
#: logged columns)
GS = slots.declare("StationColumns", ("tension", "length", "reel_speed", "omega", "current", "duty", "p_electrical",
                                      "fx", "fy", "fz", "u_link", "event", "machine_mode", "p_mechanical", "distance",
                                      "slack", "broken"))
#: the row's last columns, after the ground-station ones: hook position and velocity after the
#: step, line force during it
TAIL = slots.declare("TailColumns", ("hook_x", "hook_y", "hook_z", "hook_vx", "hook_vy", "hook_vz", "fx", "fy", "fz"))
_N_GS = slots.size(GS)


def _globals() -> tuple:
    """The native calls (None where compiled code does not run: :func:`fdm_awe.jitcache.jit_off`;
    numba failing on the kernel later falls back to the Python loop as well)."""
    if jit_off() is not None:
        return None, None, None
    from ..sixdof.native import native_calls

    return native_calls()


# module globals of the kernel: frozen into it when it is compiled
native_run, native_get, native_set = _globals()


def cosim_step(h, p, lim, log, s_gs, c_gs, k):
    """One step from row ``k`` to row ``k + 1`` of ``log`` (the arguments as :func:`cosim_steps`
    takes them): the event code of the step, or of the step that was not done (a rejected hook,
    a non-finite force: ``log[k + 1]`` is then not written)."""
    x, y, z = p[COSIM.hx], p[COSIM.hy], p[COSIM.hz]
    vx, vy, vz = p[COSIM.hvx], p[COSIM.hvy], p[COSIM.hvz]
    if not (math.isfinite(x + y + z) and math.isfinite(vx + vy + vz)):
        return CODE.hook_rejected
    dt = p[COSIM.dt]
    nsub = int(p[COSIM.nsub])
    motor = p[COSIM.motor] != 0.0
    (fx, fy, fz, tmean, length, w, i, duty, u_link, p_el, ev, mm, d, slack, broken) = line_step(
        int(c_gs[STATION.line]), s_gs, c_gs, nsub, dt, x, y, z, vx, vy, vz, motor, p[COSIM.wref], p[COSIM.duty],
        p[COSIM.d2], p[COSIM.rl])
    p[COSIM.fx], p[COSIM.fy], p[COSIM.fz] = fx, fy, fz
    if not math.isfinite(fx + fy + fz):
        return CODE.nonfinite_force
    lbf = p[COSIM.lbf]
    f_set = h[HANDLES.set]
    native_set(f_set, h[HANDLES.tx], fx / lbf)
    native_set(f_set, h[HANDLES.ty], fy / lbf)
    native_set(f_set, h[HANDLES.tz], fz / lbf)
    native_run(h[HANDLES.run], h[HANDLES.fdm])
    r = log[k + 1]
    f_get = h[HANDLES.get]
    nget = h.shape[0] - HANDLES.getters
    for j in range(nget):
        a = h[HANDLES.getters + j]
        r[j] = native_get(f_get, a) if a != 0 else 0.0
    g = nget  # first ground-station column
    e = nget + _N_GS  # first tail column
    rr = c_gs[CONST.r] * w
    r[g + GS.tension], r[g + GS.length], r[g + GS.reel_speed], r[g + GS.omega] = tmean, length, rr, w
    r[g + GS.current], r[g + GS.duty], r[g + GS.p_electrical] = i, duty, p_el
    r[g + GS.fx], r[g + GS.fy], r[g + GS.fz], r[g + GS.u_link], r[g + GS.event], r[g + GS.machine_mode] = (
        fx, fy, fz, u_link, ev, mm)
    r[g + GS.p_mechanical], r[g + GS.distance] = tmean * c_gs[CONST.r] * w, d
    r[g + GS.slack], r[g + GS.broken] = 1.0 if slack else 0.0, 1.0 if broken else 0.0
    (hx, hy, hz), (hvx, hvy, hvz) = hook_kinematics(r, p[COSIM.lat0], p[COSIM.m0], p[COSIM.n0cos], p[COSIM.ft], p[COSIM.ox],
                                                    p[COSIM.oy], p[COSIM.oz])
    p[COSIM.hx], p[COSIM.hy], p[COSIM.hz], p[COSIM.hvx], p[COSIM.hvy], p[COSIM.hvz] = hx, hy, hz, hvx, hvy, hvz
    r[e + TAIL.hook_x], r[e + TAIL.hook_y], r[e + TAIL.hook_z] = hx, hy, hz
    r[e + TAIL.hook_vx], r[e + TAIL.hook_vy], r[e + TAIL.hook_vz] = hvx, hvy, hvz
    r[e + TAIL.fx], r[e + TAIL.fy], r[e + TAIL.fz] = fx, fy, fz
    return step_event(r, tmean, ev != 0, lim)  # the events, as CoSim.run checks them


def cosim_steps(h, p, lim, log, s_gs, c_gs, k0, n):
    """``n`` steps of :func:`cosim_step` from row ``k0``: (steps done, event code)."""
    k = k0
    code = CODE.none
    while k < k0 + n:
        code = cosim_step(h, p, lim, log, s_gs, c_gs, k)
        if code == CODE.hook_rejected or code == CODE.nonfinite_force:
            break
        k += 1
        if code != CODE.none:
            break
    return k - k0, code


def _kernel_sources() -> tuple:
    """The source files of everything compiled into the kernel (numba's cache checks only this
    file): an edit of the event check, the row's relations or a line model's step (the
    registry's sources: the drivetrain, the lines, the wind profile) compiles the kernel anew."""
    from ..sixdof import native

    return (sys.modules[step_event.__module__], sys.modules[hook_kinematics.__module__], native) + kernel_sources()


def kernel_cached() -> bool | None:
    """Whether :func:`compiled_kernel` would load the kernel from numba's on-disk cache
    (:func:`fdm_awe.jitcache.is_cached`): nothing compiles."""
    return is_cached(cosim_steps, _kernel_sources())


@compiled_once
def compiled_kernel() -> Callable | None:
    """:func:`cosim_steps` compiled by numba, or None (numba or the compiled ground station
    missing, ``FDM_AWE_JIT=0``)."""
    global native_run, native_get, native_set
    if native_run is None:  # this module was imported on the Python path: the calls now
        native_run, native_get, native_set = _globals()
        if native_run is None:
            return None
    from ..jitcache import compile_cached

    def signature(nb: Any) -> Any:
        f8, i8 = nb.float64, nb.int64
        return nb.types.UniTuple(i8, 2)(i8[::1], f8[::1], f8[::1], f8[:, ::1], f8[::1], f8[::1], i8, i8)

    return compile_cached(cosim_steps, signature, kernel_called() + (hook_kinematics, step_event, cosim_step),
                          _kernel_sources(), "fdm_awe.sim.kernel")


__all__ = ["GS", "HANDLES", "COSIM", "TAIL", "compiled_kernel", "kernel_cached"]
