"""The co-simulation step compiled: ground station, tether hook, JSBSim step, state read, events.

:func:`cosim_steps` runs ``n`` steps of :class:`fdm_awe.cosim.CoSim`'s loop body without Python
in between: the ground station's compiled step (:func:`fdm_awe.groundstation.substeps.station_step`)
on the hook kinematics of the current state, the force written to the JSBSim tether hook, one
``FGFDMExec::Run()``, the state's properties read into the next log row, the next hook
kinematics, and the event checks in the order of the Python loop. JSBSim is called through its
library (:mod:`fdm_awe.sixdof.native`); the operations are those of the Python path
(``JSBSimGlider.advance``/``_read``, ``GroundStation.step``, ``CoSim.run``) in the same order, so
both give identical results (tested).

Arguments are packed to keep a one-step call cheap:

- ``h`` int64: Run, getDoubleValue, setDoubleValue, FGFDMExec*, the three tether-force nodes
  (x, y, z), then the nodes read per step (0: constant 0.0);
- ``p`` float64 parameters (``P_*`` offsets): step, sub-steps, frame and hook constants,
  limits, the winch command's terms, the airborne flag (updated), the current hook
  kinematics (updated) and the last line force (updated);
- ``log`` one row per step (row ``k0``: the current state), each row the JSBSim values (one
  per read node), then the ground-station outputs (:data:`GS_COLUMNS`), then the hook
  kinematics after the step and the line force applied during it (:data:`TAIL_COLUMNS`), so
  that one ``log[k].tolist()`` hands a step over to Python;
- ``s_gs``, ``c_gs`` the ground station's state and constants (updated in place).

Returns ``(steps done, event code)``; the event code (:data:`EVENT_CODES`) belongs to the last
step done (or, for a rejected hook or a non-finite force, to the step that was not done).
"""

from __future__ import annotations

import functools
import math
import warnings
from typing import Callable

# parameter offsets in ``p``
(P_DT, P_NSUB, P_LAT0, P_M0, P_N0COS, P_OX, P_OY, P_OZ, P_FT, P_LBF, P_VHI, P_VLO, P_THI, P_NMAX, P_GRACE,
 P_T0, P_CHECKV, P_GROUND, P_AIRBORNE, P_MOTOR, P_WREF, P_DUTY, P_D2, P_RL, P_KV, P_KFZ, P_KM,
 P_HX, P_HY, P_HZ, P_HVX, P_HVY, P_HVZ, P_FX, P_FY, P_FZ) = range(36)
N_PARAMS = 36
#: offset of the first read node in ``h``
H_GETTERS = 7
#: ground-station output columns per row (the first ten are CoSim's logged columns)
GS_COLUMNS = ("tension", "length", "reel_speed", "omega", "current", "duty", "p_electrical", "fx", "fy", "fz",
              "u_link", "event", "machine_mode", "p_mechanical", "distance", "slack", "broken")
#: the row's last columns: hook position and velocity after the step, line force during it
TAIL_COLUMNS = ("hook_x", "hook_y", "hook_z", "hook_vx", "hook_vy", "hook_vz", "fx", "fy", "fz")
#: event codes returned by :func:`cosim_steps`
EVENT_CODES = ("none", "hook_rejected", "nonfinite_force", "nonfinite_state", "ground_station", "ground_contact",
               "airspeed_high", "airspeed_low", "tension", "load_factor")
(E_NONE, E_HOOK, E_FORCE, E_STATE, E_GS, E_GROUND, E_VHI, E_VLO, E_TENSION, E_LOAD) = range(len(EVENT_CODES))


def _hook(r, p):
    """Hook position and velocity (NED) from a row of raw values: ``JSBSimGlider._read``."""
    ft = p[P_FT]
    x = (r[1] - p[P_LAT0]) * p[P_M0]
    y = r[2] * p[P_N0COS]
    z = -r[3] * ft
    vx, vy, vz = r[4] * ft, r[5] * ft, r[6] * ft
    ox, oy, oz = p[P_OX], p[P_OY], p[P_OZ]
    if ox == 0.0 and oy == 0.0 and oz == 0.0:
        p[P_HX], p[P_HY], p[P_HZ], p[P_HVX], p[P_HVY], p[P_HVZ] = x, y, z, vx, vy, vz
        return
    phi, th, psi = r[7], r[8], r[9]
    cf, sf = math.cos(phi), math.sin(phi)
    ct, st = math.cos(th), math.sin(th)
    cp, sp = math.cos(psi), math.sin(psi)
    pp, q, rr = r[10], r[11], r[12]
    wx, wy, wz = q * oz - rr * oy, rr * ox - pp * oz, pp * oy - q * ox
    m00, m01, m02 = ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp
    m10, m11, m12 = ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp
    m20, m21, m22 = -st, sf * ct, cf * ct
    p[P_HX] = x + m00 * ox + m01 * oy + m02 * oz
    p[P_HY] = y + m10 * ox + m11 * oy + m12 * oz
    p[P_HZ] = z + m20 * ox + m21 * oy + m22 * oz
    p[P_HVX] = vx + m00 * wx + m01 * wy + m02 * wz
    p[P_HVY] = vy + m10 * wx + m11 * wy + m12 * wz
    p[P_HVZ] = vz + m20 * wx + m21 * wy + m22 * wz


def _globals() -> tuple:
    """The compiled ground-station step and the native calls (None without numba)."""
    from .groundstation.substeps import compiled_station

    station = compiled_station()
    if station is None:
        return None, None, None, None
    from .sixdof.native import _intrinsics

    return (station,) + _intrinsics()


# module globals of the kernel: frozen into it when it is compiled
station, native_run, native_get, native_set = _globals()
hook = _hook


def cosim_steps(h, p, log, s_gs, c_gs, k0, n):  # noqa: C901
    f_run, f_get, f_set, fdm = h[0], h[1], h[2], h[3]
    nget = h.shape[0] - H_GETTERS
    dt = p[P_DT]
    nsub = int(p[P_NSUB])
    lbf = p[P_LBF]
    motor = p[P_MOTOR] != 0.0
    k = k0
    code = E_NONE
    while k < k0 + n:
        x, y, z = p[P_HX], p[P_HY], p[P_HZ]
        vx, vy, vz = p[P_HVX], p[P_HVY], p[P_HVZ]
        if not (math.isfinite(x + y + z) and math.isfinite(vx + vy + vz)):
            code = E_HOOK
            break
        (fx, fy, fz, tmean, length, w, i, duty, u_link, p_el, ev, mm, d, slack, broken) = station(
            s_gs, c_gs, nsub, dt, x, y, z, vx, vy, vz, motor, p[P_WREF], p[P_DUTY], p[P_D2], p[P_RL])
        p[P_FX], p[P_FY], p[P_FZ] = fx, fy, fz
        if not math.isfinite(fx + fy + fz):
            code = E_FORCE
            break
        native_set(f_set, h[4], fx / lbf)
        native_set(f_set, h[5], fy / lbf)
        native_set(f_set, h[6], fz / lbf)
        native_run(f_run, fdm)
        k += 1
        r = log[k]
        for j in range(nget):
            a = h[H_GETTERS + j]
            r[j] = native_get(f_get, a) if a != 0 else 0.0
        rr = c_gs[0] * w
        j = nget
        r[j], r[j + 1], r[j + 2], r[j + 3], r[j + 4], r[j + 5], r[j + 6] = tmean, length, rr, w, i, duty, p_el
        r[j + 7], r[j + 8], r[j + 9], r[j + 10], r[j + 11], r[j + 12] = fx, fy, fz, u_link, ev, mm
        r[j + 13], r[j + 14] = tmean * c_gs[0] * w, d
        r[j + 15], r[j + 16] = 1.0 if slack else 0.0, 1.0 if broken else 0.0
        hook(r, p)
        j += 17
        r[j], r[j + 1], r[j + 2], r[j + 3], r[j + 4], r[j + 5] = (p[P_HX], p[P_HY], p[P_HZ], p[P_HVX], p[P_HVY],
                                                              p[P_HVZ])
        r[j + 6], r[j + 7], r[j + 8] = fx, fy, fz
        # ---- events, in the order of CoSim.run
        sm = 0.0
        for j in range(1, 16):
            sm += r[j]
        if not math.isfinite(sm):
            code = E_STATE
            break
        if ev != 0:
            code = E_GS
            break
        if r[29] > 0.5:
            if p[P_AIRBORNE] != 0.0 and p[P_GROUND] != 0.0:
                code = E_GROUND
                break
        else:
            p[P_AIRBORNE] = 1.0
        if p[P_CHECKV] != 0.0 and r[0] - p[P_T0] >= p[P_GRACE]:
            v = r[13] * p[P_KV]
            if v > p[P_VHI]:
                code = E_VHI
                break
            if v < p[P_VLO]:
                code = E_VLO
                break
        if tmean > p[P_THI]:
            code = E_TENSION
            break
        if p[P_NMAX] == p[P_NMAX]:  # NaN: no load-factor limit
            nz = -r[21] * p[P_KFZ] / (r[22] * p[P_KM]) / 9.80665
            if nz > p[P_NMAX] or nz < -p[P_NMAX]:
                code = E_LOAD
                break
    return k - k0, code



@functools.lru_cache(maxsize=None)
def compiled_kernel() -> Callable | None:
    """:func:`cosim_steps` compiled by numba, or None (numba or the compiled ground station
    missing, ``FDM_AWE_JIT=0``)."""
    if station is None:
        return None
    try:
        import numba
        from numba.extending import register_jitable

        register_jitable(_hook)
        f8, i8 = numba.float64, numba.int64
        sig = numba.types.UniTuple(i8, 2)(i8[::1], f8[::1], f8[:, ::1], f8[::1], f8[::1], i8, i8)
        return numba.njit(sig, cache=True)(cosim_steps)
    except Exception as exc:  # a broken numba install must not stop a simulation
        warnings.warn(f"fdm_awe.cosim_kernel: numba failed ({exc}); the Python loop runs instead",
                      RuntimeWarning, stacklevel=2)
        return None


__all__ = ["EVENT_CODES", "GS_COLUMNS", "N_PARAMS", "TAIL_COLUMNS", "compiled_kernel"]
