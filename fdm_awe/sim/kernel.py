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

- ``h`` int64 (``H_*`` offsets): Run, getDoubleValue, setDoubleValue, FGFDMExec*, the three
  tether-force nodes (x, y, z), then the nodes read per step (0: constant 0.0), in the order
  of the raw row (:mod:`fdm_awe.sixdof.row`);
- ``p`` float64 parameters (``P_*`` offsets): step, sub-steps, frame and hook constants, the
  winch command's terms, the current hook kinematics (updated) and the last line force
  (updated);
- ``lim`` float64 thresholds of the event checks and the airborne flag (updated), as
  :func:`fdm_awe.sim.events.limit_vector` builds them;
- ``log`` one row per step (row ``k0``: the current state), each row the JSBSim values (one
  per read node), then the ground-station outputs (:data:`GS_COLUMNS`), then the hook
  kinematics after the step and the line force applied during it (:data:`TAIL_COLUMNS`), so
  that one ``log[k].tolist()`` hands a step over to Python;
- ``s_gs``, ``c_gs`` the ground station's state and constants (updated in place).

Returns ``(steps done, event code)``; the event code (:data:`fdm_awe.sim.events.EVENT_CODES`) belongs to the last
step done (or, for a rejected hook or a non-finite force, to the step that was not done).
"""

from __future__ import annotations

import functools
import math
import sys
from typing import Any, Callable

from .events import E_FORCE, E_HOOK, E_NONE, step_event
from ..groundstation.linemodels import kernel_called, kernel_sources, line_step
from ..jitcache import jit_off
from ..groundstation.substeps import STATION
from ..sixdof.row import hook_kinematics

# parameter offsets in ``p``
(P_DT, P_NSUB, P_LAT0, P_M0, P_N0COS, P_OX, P_OY, P_OZ, P_FT, P_LBF, P_MOTOR, P_WREF, P_DUTY, P_D2, P_RL,
 P_HX, P_HY, P_HZ, P_HVX, P_HVY, P_HVZ, P_FX, P_FY, P_FZ) = range(24)
N_PARAMS = 24
# offsets in ``h``: the calls, the object, the tether-force nodes, then the read nodes
(H_RUN, H_GET, H_SET, H_FDM, H_TX, H_TY, H_TZ, H_GETTERS) = range(8)
#: ground-station output columns per row, after the raw values (the first ten are CoSim's
#: logged columns)
GS_COLUMNS = ("tension", "length", "reel_speed", "omega", "current", "duty", "p_electrical", "fx", "fy", "fz",
              "u_link", "event", "machine_mode", "p_mechanical", "distance", "slack", "broken")
(G_TENSION, G_LENGTH, G_REEL_SPEED, G_OMEGA, G_CURRENT, G_DUTY, G_P_EL, G_FX, G_FY, G_FZ, G_U_LINK, G_EVENT,
 G_MACHINE_MODE, G_P_MECH, G_DISTANCE, G_SLACK, G_BROKEN) = range(17)
N_GS = 17
#: the row's last columns, after the ground-station ones: hook position and velocity after the
#: step, line force during it
TAIL_COLUMNS = ("hook_x", "hook_y", "hook_z", "hook_vx", "hook_vy", "hook_vz", "fx", "fy", "fz")
(K_HX, K_HY, K_HZ, K_HVX, K_HVY, K_HVZ, K_FX, K_FY, K_FZ) = range(len(TAIL_COLUMNS))


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
    x, y, z = p[P_HX], p[P_HY], p[P_HZ]
    vx, vy, vz = p[P_HVX], p[P_HVY], p[P_HVZ]
    if not (math.isfinite(x + y + z) and math.isfinite(vx + vy + vz)):
        return E_HOOK
    dt = p[P_DT]
    nsub = int(p[P_NSUB])
    motor = p[P_MOTOR] != 0.0
    (fx, fy, fz, tmean, length, w, i, duty, u_link, p_el, ev, mm, d, slack, broken) = line_step(
        int(c_gs[STATION.line]), s_gs, c_gs, nsub, dt, x, y, z, vx, vy, vz, motor, p[P_WREF], p[P_DUTY], p[P_D2], p[P_RL])
    p[P_FX], p[P_FY], p[P_FZ] = fx, fy, fz
    if not math.isfinite(fx + fy + fz):
        return E_FORCE
    lbf = p[P_LBF]
    f_set = h[H_SET]
    native_set(f_set, h[H_TX], fx / lbf)
    native_set(f_set, h[H_TY], fy / lbf)
    native_set(f_set, h[H_TZ], fz / lbf)
    native_run(h[H_RUN], h[H_FDM])
    r = log[k + 1]
    f_get = h[H_GET]
    nget = h.shape[0] - H_GETTERS
    for j in range(nget):
        a = h[H_GETTERS + j]
        r[j] = native_get(f_get, a) if a != 0 else 0.0
    g = nget  # first ground-station column
    e = nget + N_GS  # first tail column
    rr = c_gs[0] * w
    r[g + G_TENSION], r[g + G_LENGTH], r[g + G_REEL_SPEED], r[g + G_OMEGA] = tmean, length, rr, w
    r[g + G_CURRENT], r[g + G_DUTY], r[g + G_P_EL] = i, duty, p_el
    r[g + G_FX], r[g + G_FY], r[g + G_FZ], r[g + G_U_LINK], r[g + G_EVENT], r[g + G_MACHINE_MODE] = (
        fx, fy, fz, u_link, ev, mm)
    r[g + G_P_MECH], r[g + G_DISTANCE] = tmean * c_gs[0] * w, d
    r[g + G_SLACK], r[g + G_BROKEN] = 1.0 if slack else 0.0, 1.0 if broken else 0.0
    (hx, hy, hz), (hvx, hvy, hvz) = hook_kinematics(r, p[P_LAT0], p[P_M0], p[P_N0COS], p[P_FT], p[P_OX], p[P_OY],
                                                    p[P_OZ])
    p[P_HX], p[P_HY], p[P_HZ], p[P_HVX], p[P_HVY], p[P_HVZ] = hx, hy, hz, hvx, hvy, hvz
    r[e + K_HX], r[e + K_HY], r[e + K_HZ], r[e + K_HVX], r[e + K_HVY], r[e + K_HVZ] = hx, hy, hz, hvx, hvy, hvz
    r[e + K_FX], r[e + K_FY], r[e + K_FZ] = fx, fy, fz
    return step_event(r, tmean, ev != 0, lim)  # the events, as CoSim.run checks them


def cosim_steps(h, p, lim, log, s_gs, c_gs, k0, n):
    """``n`` steps of :func:`cosim_step` from row ``k0``: (steps done, event code)."""
    k = k0
    code = E_NONE
    while k < k0 + n:
        code = cosim_step(h, p, lim, log, s_gs, c_gs, k)
        if code == E_HOOK or code == E_FORCE:
            break
        k += 1
        if code != E_NONE:
            break
    return k - k0, code


@functools.lru_cache(maxsize=None)
def compiled_kernel() -> Callable | None:
    """:func:`cosim_steps` compiled by numba, or None (numba or the compiled ground station
    missing, ``FDM_AWE_JIT=0``)."""
    if native_run is None:
        return None
    from ..jitcache import compile_cached
    from ..sixdof import native

    def signature(nb: Any) -> Any:
        f8, i8 = nb.float64, nb.int64
        return nb.types.UniTuple(i8, 2)(i8[::1], f8[::1], f8[::1], f8[:, ::1], f8[::1], f8[::1], i8, i8)

    # tied to the source files of the functions compiled into it (numba's cache checks only
    # this file): an edit of the event check, the row's relations or a line model's step (the
    # registry's sources: the drivetrain, the lines, the wind profile) compiles the kernel anew
    return compile_cached(cosim_steps, signature, kernel_called() + (hook_kinematics, step_event, cosim_step),
                          (sys.modules[step_event.__module__], sys.modules[hook_kinematics.__module__], native)
                          + kernel_sources(), "fdm_awe.sim.kernel")


__all__ = ["GS_COLUMNS", "N_PARAMS", "TAIL_COLUMNS", "compiled_kernel"]
if len(GS_COLUMNS) != N_GS or len(TAIL_COLUMNS) != K_FZ + 1:  # pragma: no cover - a definition error here
    raise RuntimeError("fdm_awe.sim.kernel: column names and offsets disagree")
