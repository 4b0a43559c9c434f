"""The autopilot's AUTO step on arrays: one source, run compiled by numba or as plain Python.

:meth:`fdm_awe.autopilot.autopilot.Autopilot.update` in AUTO, cycling on its reference, is
:func:`auto_guide` followed by the attitude loops (:func:`.attitude.attitude_from_row`): the
reference point at the path parameter and the path rate (path following) or the rejoin segment,
the motor switch, the guidance's force inversion, the fold command, the winch command and the
thrust loop, in the order the autopilot has always run them. Every relation is the pure
function of its own module (the sampler of :mod:`fdm_awe.trajectory.sampler`,
:func:`.rejoin.rejoin_weights`, :func:`.guidance.guidance_step`, :func:`.motor.motor_update`,
:func:`.fold.fold_command`, :func:`.winch.cycle_winch_values`, :func:`.thrust.throttle_step`);
this module only wires them on the arrays below, so that the same function runs in the Python
autopilot (:mod:`.auto_mode`) and compiled (:mod:`fdm_awe.sim.autopilot_kernel`), bit for bit
the same.

Arrays (float64; offsets are the module's ``*_`` constants):

- ``row``, ``scale``, ``offset``: the glider's raw JSBSim row (:mod:`fdm_awe.sixdof.row`) and its
  SI factors and offsets (SI value = raw * scale + offset, as :class:`~fdm_awe.sixdof.state.SixDofState`);
- ``gso``: the ground station's last output (``GS_*``: tension N, line length m, slack flag,
  line force on the glider N, NED; ``GS_VALID`` 0 before the station's first step);
- ``ref_t``, ``ref_table``: the cycle's sample times [s] and its linear columns
  (:data:`REF_COLUMNS` at the ``R_*`` offsets), ``segs``: per segment the motor plan (1 run, 0
  stop; :meth:`.motor.MotorGate.plan`) and the generator's T2 duty (rows ``SEG_RUN``, ``SEG_D2``);
- ``gk``: the guidance gains (:meth:`.guidance_loop.GuidanceGains.vector`); ``cu``, ``cf``: the
  unfolded and folded polars (:func:`.guidance.polar_coefficients`); ``gate``: the motor gate
  (:meth:`.motor.MotorGate.vector`); ``par``: the rest (``A_*``);
- ``mem``: the step's state between calls (``M_*``), updated in place;
- ``out``: the step's results (``O_*``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..definitions.aircraft import stall_speed
from ..pointmass.fold import fold_fraction
from ..sixdof.row import ROW, si_position, si_velocity
from ..trajectory.sampler import cycle_evaluate, cycle_time, segment_of
from .fold import fold_command
from .ground import ground_guard, pull_out_height
from .guidance import (CALLED as GUIDANCE_CALLED, GK_GP_ACC, GK_GP_ALT, GK_THRUST_MAX, GK_US_ENTER, GK_US_EXIT,
                       GK_US_HOLD, P_CLMAX, US_PULL_UP, guidance_step, polar_at)
from .motor import motor_ceiling, motor_spin_down, motor_update
from .rejoin import nearest_on_phase, rejoin_weights
from .thrust import T_LAST, T_THRUST, throttle_step
from .underspeed import FOLD_OPEN, underspeed_update
from .wind_estimate import LULL_SHARE
from .winch import N_LIMITS, WL_TLO, cycle_winch_values, lower_limit_holds, take_up_speed, upper_limit_load

#: a float64 array (the compiled step's one array type)
Arr = np.ndarray

#: the reference's linear columns in the order of the table (:data:`.tracking.TRACKING_RULES`)
REF_COLUMNS = ("pos", "vel", "acc", "airspeed", "alpha", "phi", "thrust", "tension", "length", "reel_speed")
(R_PX, R_PY, R_PZ, R_VX, R_VY, R_VZ, R_AX, R_AY, R_AZ, R_AIRSPEED, R_ALPHA, R_PHI, R_THRUST, R_TENSION, R_LENGTH,
 R_REEL_SPEED) = range(16)
N_REF = 16
#: where the sampler of :data:`.tracking.TRACKING_RULES` puts :data:`REF_COLUMNS` (checked)
REF_WHERE = (slice(0, 3), slice(3, 6), slice(6, 9), 9, 10, 11, 12, 13, 14, 15)
#: rows of ``segs``
SEG_RUN, SEG_D2 = 0, 1
#: ``gso``
GS_VALID, GS_TENSION, GS_LENGTH, GS_SLACK, GS_FX, GS_FY, GS_FZ = range(7)
N_GSO = 7
#: ``par``: the cycle, the aircraft, the winch and the thrust loop
(A_T1, A_PERIOD, A_FOLDABLE, A_FOLD_TIME, A_FOLD_LEAD, A_UNFOLD_LEAD, A_PATH_TAU, A_MASS, A_RHO, A_G, A_S_U, A_S_F,
 A_RATIO, A_IDEAL_WINCH, A_RL, A_LINE_EA, A_GEN_RL_KP, A_REC_TENSION, A_WINCH_KL, A_WINCH_KT, A_ARMED, A_THR_KP,
 A_THR_KI, A_THR_VZERO, A_THRUST_MAX_STATIC, A_THRUSTER, A_G_ATT, A_RJ_TIME, A_FS_TRK_ERR, A_REF_PULL,
 A_CATCH_TIME) = range(31)
#: then the winch's line limits (:func:`.winch.limit_vector`, :data:`.winch.N_LIMITS` values)
A_WLIM = 31
#: then the path rejoin (:mod:`.rejoin`): the position error [m] above which AUTO rejoins its
#: path at the point nearest the glider (RJ_TRK_ERR, 0 off), at most this many times a cycle
#: (RJ_TRK_MAX)
A_RJ_TRK_ERR = A_WLIM + N_LIMITS
A_RJ_TRK_MAX = A_RJ_TRK_ERR + 1
#: then the depth below its reference point [m] beyond which the motor's rescue
#: (:func:`.motor.motor_update`) runs in generation (RESC_GEN_DEPTH, 0: any error;
#: :func:`rescue_allowed`)
A_RESC_GEN = A_RJ_TRK_MAX + 1
#: then the wind the cycle was made for [m/s] (its metadata's ``wind_mps``; NaN: unknown)
A_CYCLE_WIND = A_RESC_GEN + 1
N_PAR = A_CYCLE_WIND + 1
#: ``mem``: path parameter [s], time of the last step [s] (NaN before the first), position error
#: of the last step [m] (NaN before the first), phase of the last step (0 generation, 1
#: recovery, -1 another mode), the last step's length [s]; the guidance's integral, the thrust
#: loop's and the motor switch's states are their own arrays (``integral``, ``thr``, ``motor``)
M_SREF, M_TLAST, M_ERR, M_PHASE, M_DT = range(5)
#: then the rejoin segment under way (:mod:`.rejoin`): 1.0 while it lasts, its start time [s] and
#: the glider's offsets from the path at the start (position m, velocity m/s, NED)
M_RJ, M_RJ_T0, M_RJ_DP, M_RJ_DV = 5, 6, 7, 10
#: then 1.0 while the winch's lower tension limit holds (:func:`.winch.lower_limit_holds`)
M_WLOW = 13
#: then the underspeed protection (:mod:`.underspeed`): 1.0 while it acts, the last time [s] the
#: airspeed was below its entry speed
M_US, M_US_T = 14, 15
#: then the path rejoins: how many began in the cycle of index M_RJ_K
M_RJ_N, M_RJ_K = 16, 17
#: then 1.0 while the ground-proximity guard pulls up (:mod:`.ground`)
M_GP = 18
N_MEM = 19
#: a rejoin segment younger than this [s] is not begun again for the path error
RJ_SETTLE = 1.0
#: flags :func:`auto_guide` returns: the phase changed, the rejoin segment ended at this step, the
#: position error exceeds ``par[A_FS_TRK_ERR]`` (> 0; the autopilot times it, FS_TRK_TIME), the
#: underspeed protection began or ended at this step, a rejoin of the lost path began at this step,
#: the ground-proximity guard began or ended its pull-up at this step
PHASE_CHANGED, REJOINED, TRACK_LOST, UNDERSPEED, PATH_REJOIN, GROUND = 1, 2, 4, 8, 16, 32
#: ``out``: the step's reference point (cycle, cycle time, phase, position, motor-on fraction,
#: path rate), the guidance's command, the motor, fold, throttle and winch commands
(O_CYCLE, O_TC, O_PHASE, O_SEG, O_RX, O_RY, O_RZ, O_RATE, O_ALPHA, O_MU, O_THRUST, O_ROLL, O_PITCH, O_YAW, O_CL,
 O_ERR, O_MOTOR, O_FOLD, O_THROTTLE, O_IDEAL_THRUST, O_W_MOTOR, O_W_REEL_SPEED, O_W_RL, O_W_D2) = range(24)
N_OUT = 24


def reference_pull(on: bool, phase: int, tc: float, catch_time: float) -> bool:
    """Whether the guidance counts a line that is not taut with the reference's pull, not the
    measured one (GUID_REFPULL ``on``; :func:`.guidance._air_force`): in recovery (``phase`` 1)
    and while generation's first ``catch_time`` [s] (GUID_CATCH_T) of cycle time ``tc`` [s]
    catch the slack line."""
    return on and (phase != 0 or tc < catch_time)


def path_rate(px: float, py: float, pz: float, rrow: Arr, tau: float, hi: float) -> float:
    """The path parameter's rate [-] for the glider at ``p*`` [m] and the reference row ``rrow``
    (position, velocity): ``1 + e_at / (v_ref tau)``, ``e_at`` [m] how far the glider is ahead
    of the reference point along its velocity ``v_ref`` [m/s], ``tau`` [s] (PATH_TAU) the time
    constant of the catch-up; between 0 and ``hi``; 1 where the reference stands (below 0.5 m/s)."""
    rvx, rvy, rvz = rrow[R_VX], rrow[R_VY], rrow[R_VZ]
    vr = math.sqrt(rvx * rvx + rvy * rvy + rvz * rvz)
    if vr > 0.5:
        e_at = ((px - rrow[R_PX]) * rvx + (py - rrow[R_PY]) * rvy + (pz - rrow[R_PZ]) * rvz) / vr
        return min(max(1.0 + e_at / (vr * tau), 0.0), hi)
    return 1.0


def rescue_allowed(phase: int, v_air: float, v_ref: float, pull: bool, protect: bool, depth: float,
                   gen_depth: float, pulling: bool) -> bool:
    """Whether the motor's rescue (:func:`.motor.motor_update`: the stopped motor started for a
    large position error) may run: for a glider pulling up from the ground (``pull``) or
    protecting its airspeed (``protect``); else for one no faster in the air (``v_air`` [m/s])
    than its reference point (``v_ref`` [m/s]); in generation (``phase`` 0) with ``gen_depth``
    > 0 [m] (RESC_GEN_DEPTH; 0, the default: for any error, as in the other phases) and
    ``pulling`` (on its path, no rejoin under way, on a line that pulls, at least WINCH_TLO,
    in at least :data:`.wind_estimate.LULL_SHARE` of the cycle's wind) only where it is more
    than ``gen_depth`` below that point (``depth`` [m], + below). A generating glider that
    lags its path in a lull, or flies above it, hangs on a line the wind still pulls: its
    propeller pushes against the generator (battery energy into the drum at both machines'
    losses: 300-820 J a cycle in 6 of the 30 cycles of the nominal 10 m/s cycle in light
    turbulence, against 51 J in calm air). One that sinks below its path, hangs on a slack
    line or meets still air gets the motor: without the rescue in generation two flights of
    the real-wind grid hit the ground, and without the wind's share the nominal 10 m/s cycle
    in still air."""
    if pull or protect:
        return True
    if v_air > v_ref:
        return False
    return phase != 0 or not gen_depth > 0.0 or not pulling or depth > gen_depth


def rescue_gate(phase: int, v_air: float, pz: float, wx: float, wy: float, rrow: Arr, gso: Arr, par: Arr,
                rejoining: bool, pull: bool, protect: bool) -> bool:
    """:func:`rescue_allowed` for the glider at height ``pz`` [m, NED down] in the horizontal wind
    ``wx``, ``wy`` [m/s] on the reference row ``rrow``, with the ground station's last output
    ``gso`` and the step's ``par``: the line pulls where the station has stepped, the line is
    taut at WINCH_TLO or more, no rejoin is under way (``rejoining``) and the wind is at least
    :data:`.wind_estimate.LULL_SHARE` of the cycle's (``par[A_CYCLE_WIND]``; NaN: never)."""
    # only generation with RESC_GEN_DEPTH above 0 asks whether the line pulls
    pulling = (phase == 0 and par[A_RESC_GEN] > 0.0 and gso[GS_VALID] != 0.0 and gso[GS_SLACK] == 0.0
               and gso[GS_TENSION] >= par[A_WLIM + WL_TLO] and not rejoining
               and math.sqrt(wx * wx + wy * wy) >= LULL_SHARE * par[A_CYCLE_WIND])
    return rescue_allowed(phase, v_air, rrow[R_AIRSPEED], pull, protect, pz - rrow[R_PZ], par[A_RESC_GEN], pulling)


def paced(rrow: Arr, rate: float, phase: int) -> tuple[float, float, float, float, float, float]:
    """The reference row ``rrow``'s velocity [m/s] and acceleration [m/s^2] at the pace the path
    parameter moves (``rate`` (-), :func:`path_rate`): in generation (``phase`` 0) a glider the
    wind slows (rate below 1) is asked for the path's velocity times the rate and its
    acceleration times the rate squared (the same path flown slower), not pushed to the planned
    speed by the propeller; elsewhere, and at rate 1, the row's own."""
    p = rate if rate < 1.0 and phase == 0 else 1.0
    return p * rrow[R_VX], p * rrow[R_VY], p * rrow[R_VZ], p * p * rrow[R_AX], p * p * rrow[R_AY], p * p * rrow[R_AZ]


def auto_guide(row: Any, scale: Any, offset: Any, gso: Arr, ref_t: Arr, ref_table: Arr, segs: Arr, gk: Arr, cu: Arr,
               cf: Arr, gate: Arr, par: Arr, mem: Arr, integral: Arr, thr_state: Arr, motor_mem: Arr, rrow: Arr,
               out: Arr) -> int:
    """One AUTO step up to the attitude loops, at the glider's raw row ``row`` (time ``row[T]``):
    writes ``out`` and advances ``mem``, the guidance's position-error ``integral``
    (:mod:`.guidance`), the thrust loop's ``thr_state`` (:mod:`.thrust`) and the motor switch's
    ``motor_mem`` (:mod:`.motor`); ``rrow`` receives the reference's row (:data:`N_REF` values).
    Returns the step's flags (:data:`PHASE_CHANGED`, :data:`REJOINED`, :data:`TRACK_LOST`,
    :data:`UNDERSPEED`, :data:`PATH_REJOIN`, :data:`GROUND`; 0: none)."""
    t = row[0]
    t_last = mem[M_TLAST]
    dt = 0.0 if t_last != t_last else max(0.0, t - t_last)
    mem[M_TLAST] = t
    mem[M_DT] = dt
    # the glider's state, SI (SixDofState's relations: raw * scale + offset)
    px, py, pz = si_position(row, scale, offset)
    vx, vy, vz = si_velocity(row, scale)
    kw = scale[ROW.wind_north]
    # wind = vel - vel_air = vel - (vel - total wind), as the autopilot forms it
    wx = vx - (vx - row[ROW.wind_north] * kw)
    wy = vy - (vy - row[ROW.wind_east] * kw)
    wz = vz - (vz - row[ROW.wind_down] * kw)
    fold = row[ROW.fold]
    polar = polar_at(cu, cf, par[A_RATIO], par[A_S_U], fold)
    # the reference point at the path parameter, and the parameter one step later
    s_par = mem[M_SREF]
    k, tc, phase, seg, _ = cycle_evaluate(ref_t, ref_table, par[A_T1], par[A_PERIOD], s_par, rrow)
    # the underspeed protection: the airspeed against the stall speed of the fold state
    vax, vay, vaz = vx - wx, vy - wy, vz - wz
    v_air = math.sqrt(vax * vax + vay * vay + vaz * vaz)
    v_stall = stall_speed(par[A_MASS], par[A_RHO], par[A_G], polar[P_CLMAX])
    was = mem[M_US] != 0.0
    protect, mem[M_US_T] = underspeed_update(was, mem[M_US_T], t, v_air, v_stall, rrow[R_AIRSPEED], fold,
                                             gk[GK_US_ENTER], gk[GK_US_EXIT], gk[GK_US_HOLD])
    mem[M_US] = 1.0 if protect else 0.0
    # the ground-proximity guard: pull up before the ground, before the path and the protection
    was_gp = mem[M_GP] != 0.0
    pull = ground_guard(was_gp, -pz, vz, math.sqrt(vx * vx + vy * vy + vz * vz), v_air, v_stall, par[A_G],
                        gk[GK_GP_ALT], gk[GK_GP_ACC], gk[GK_US_EXIT], gk[GK_US_ENTER])
    mem[M_GP] = 1.0 if pull else 0.0
    flags = 0
    rejoin = False
    if protect != was:
        flags = UNDERSPEED
        # protection over: back to the path over a rejoin segment from the glider's state
        rejoin = was and mem[M_RJ] == 0.0
    if pull != was_gp:
        flags |= GROUND
        # pulled up: back to the path over a rejoin segment from the glider's state
        rejoin = rejoin or (was_gp and not protect and mem[M_RJ] == 0.0)
    if mem[M_RJ_K] != k:
        mem[M_RJ_N], mem[M_RJ_K] = 0.0, k
    if (not protect and not pull and (phase == 0 or fold < FOLD_OPEN) and par[A_RJ_TRK_ERR] > 0.0
            and mem[M_ERR] > par[A_RJ_TRK_ERR] and mem[M_RJ_N] < par[A_RJ_TRK_MAX]
            and (mem[M_RJ] == 0.0 or t - mem[M_RJ_T0] >= RJ_SETTLE)):
        # the path is lost (the last step's error; a rejoin under way counts after RJ_SETTLE, the
        # error of its first step may be the one before it began): rejoin the path where it
        # passes nearest the glider, not at a point the path parameter froze or ran away with.
        # Not in a folded recovery: the folded wing cannot fly back onto its dive, a rejoin
        # there pushed it over into the ground (foldable, 8 m/s, moderate seed 9)
        flags |= PATH_REJOIN
        mem[M_RJ_N] += 1.0
        s_par = k * par[A_PERIOD] + nearest_on_phase(ref_t, ref_table, par[A_T1], par[A_PERIOD], tc, px, py, pz,
                                                     vx, vy, vz)
        k, tc, phase, seg, _ = cycle_evaluate(ref_t, ref_table, par[A_T1], par[A_PERIOD], s_par, rrow)
        rejoin = True
    if rejoin:
        mem[M_RJ], mem[M_RJ_T0] = 1.0, t
        mem[M_RJ_DP], mem[M_RJ_DP + 1], mem[M_RJ_DP + 2] = px - rrow[R_PX], py - rrow[R_PY], pz - rrow[R_PZ]
        mem[M_RJ_DV], mem[M_RJ_DV + 1], mem[M_RJ_DV + 2] = vx - rrow[R_VX], vy - rrow[R_VY], vz - rrow[R_VZ]
    if mem[M_RJ] != 0.0:
        # the rejoin segment: the path's point plus a vanishing offset, the parameter at flight time
        done, w, w1, w2, e, e1, e2 = rejoin_weights(t, mem[M_RJ_T0], par[A_RJ_TIME])
        if done != 0.0:
            mem[M_RJ] = 0.0
            flags |= REJOINED
        else:
            for j in range(3):
                dp, dv = mem[M_RJ_DP + j], mem[M_RJ_DV + j]
                rrow[R_PX + j] = rrow[R_PX + j] + (1.0 - w) * dp + e * dv
                rrow[R_VX + j] = rrow[R_VX + j] - w1 * dp + e1 * dv
                rrow[R_AX + j] = rrow[R_AX + j] - w2 * dp + e2 * dv
        # the parameter at flight time, in generation held back where the glider lags the
        # segment's point (a rejoin into a headwind would otherwise run away from the glider;
        # held in a folded recovery's dive, the reference pushed the wing over into the ground);
        # with the path rejoin off (RJ_TRK_ERR 0) at flight time throughout, as before it
        hold = phase == 0 and par[A_RJ_TRK_ERR] > 0.0
        rate = path_rate(px, py, pz, rrow, par[A_PATH_TAU], 1.0) if hold else 1.0
    else:
        rate = path_rate(px, py, pz, rrow, par[A_PATH_TAU], 3.0)
    mem[M_SREF] = s_par + rate * dt
    rvx, rvy, rvz, ax, ay, az = paced(rrow, rate, phase)
    valid = gso[GS_VALID] != 0.0
    # pulling up, the wing flies against the measured line force: no radial force of the reference's
    taut = valid and gso[GS_SLACK] == 0.0 and phase == 0 and not pull
    ref_pull = reference_pull(par[A_REF_PULL] != 0.0, phase, tc, par[A_CATCH_TIME]) and not pull
    if valid:
        tx, ty, tz = gso[GS_FX], gso[GS_FY], gso[GS_FZ]
    else:
        tx, ty, tz = 0.0, 0.0, 0.0
    us = 0.0  # the protection: 0 off, 1 on, 2 on with the line slack; the guard's pull-up before it
    if pull:
        us = US_PULL_UP
    elif protect:
        us = 2.0 if valid and gso[GS_SLACK] != 0.0 else 1.0
    # the motor: stopped where the reference stopped it (no thrust for the guidance to give)
    slow = rescue_gate(phase, v_air, pz, wx, wy, rrow, gso, par, mem[M_RJ] != 0.0, pull, protect)
    motor = motor_update(segs[SEG_RUN], seg, t, mem[M_ERR], gate, motor_mem, slow) != 0.0
    if motor:
        t_max = gk[GK_THRUST_MAX]
    elif par[A_THRUSTER] != 0.0:
        t_max = 0.0
    else:  # a soft stop: the thrust the guidance may count on falls with the throttle
        t_max = motor_spin_down(t, gate, motor_mem, thr_state[T_THRUST])
    alpha, mu, thrust, roll, pitch, yaw, cl, err = guidance_step(
        gk, integral, polar, par[A_MASS], par[A_RHO], par[A_G], par[A_S_U], par[A_S_F],
        rrow[R_PX], rrow[R_PY], rrow[R_PZ], rvx, rvy, rvz, ax, ay, az, rrow[R_TENSION],
        px, py, pz, vx, vy, vz, wx, wy, wz, tx, ty, tz, fold, dt, taut, t_max, ref_pull, us)
    mem[M_ERR] = err
    if par[A_FS_TRK_ERR] > 0.0 and err > par[A_FS_TRK_ERR]:
        flags |= TRACK_LOST
    if par[A_FOLDABLE] != 0.0:
        fold_cmd = fold_command(tc, par[A_T1], par[A_PERIOD], par[A_FOLD_TIME], par[A_FOLD_LEAD], par[A_UNFOLD_LEAD])
    else:
        fold_cmd = 0.0
    if phase != mem[M_PHASE]:
        flags |= PHASE_CHANGED
    mem[M_PHASE] = phase
    ideal_winch = par[A_IDEAL_WINCH] != 0.0
    # the glider's distance from the winch and its rate
    dist = math.sqrt(px * px + py * py + pz * pz)
    dist_rate = (px * vx + py * vy + pz * vz) / max(dist, 1e-6)
    w_motor, w_speed, w_rl, w_d2, w_low = cycle_winch_values(
        phase, ideal_winch, rate, rrow[R_REEL_SPEED], rrow[R_LENGTH], rrow[R_TENSION], segs[SEG_D2, seg],
        valid, gso[GS_LENGTH], gso[GS_TENSION], par[A_RL], par[A_LINE_EA], par[A_GEN_RL_KP], par[A_REC_TENSION],
        par[A_WINCH_KL], par[A_WINCH_KT], dist, dist_rate, mem[M_WLOW] != 0.0,
        par[A_WLIM:A_WLIM + N_LIMITS])
    mem[M_WLOW] = 1.0 if w_low else 0.0
    ideal = 0.0
    if par[A_THRUSTER] != 0.0:
        thr = 0.0  # the paper plant's ideal thruster takes the thrust command, the propeller idles
        if motor and par[A_ARMED] != 0.0:
            ideal = thrust
    elif not motor:
        # stopped: the throttle falls to 0 (a soft stop), the thrust loop's integral is held
        thr = motor_spin_down(t, gate, motor_mem, thr_state[T_LAST])
    else:
        # after a start the propeller spins up from rest under a rising throttle ceiling
        armed = par[A_ARMED] != 0.0
        ceiling = motor_ceiling(t, gate, motor_mem)
        thr = throttle_step(thrust, row[ROW.thrust] * scale[ROW.thrust], row[ROW.vt] * scale[ROW.vt], dt, armed,
                            ceiling, par[A_THR_KP], par[A_THR_KI],
                            par[A_THR_VZERO], par[A_THRUST_MAX_STATIC], thr_state)
        thr_state[T_LAST], thr_state[T_THRUST] = thr, thrust
    out[O_CYCLE], out[O_TC], out[O_PHASE], out[O_SEG] = k, tc, phase, seg
    out[O_RX], out[O_RY], out[O_RZ], out[O_RATE] = rrow[R_PX], rrow[R_PY], rrow[R_PZ], rate
    out[O_ALPHA], out[O_MU], out[O_THRUST], out[O_ROLL], out[O_PITCH], out[O_YAW] = alpha, mu, thrust, roll, pitch, yaw
    out[O_CL], out[O_ERR], out[O_MOTOR], out[O_FOLD] = cl, err, 1.0 if motor else 0.0, fold_cmd
    out[O_THROTTLE], out[O_IDEAL_THRUST] = thr, ideal
    out[O_W_MOTOR], out[O_W_REEL_SPEED], out[O_W_RL], out[O_W_D2] = w_motor, w_speed, w_rl, w_d2
    return flags


#: the plain functions the AUTO step calls, for a compiled caller to register
#: (``numba.extending.register_jitable``), then the step itself
CALLED = (si_position, si_velocity, cycle_time, segment_of, cycle_evaluate, rejoin_weights, paced, rescue_allowed,
          rescue_gate, motor_update, motor_ceiling, motor_spin_down, fold_fraction, fold_command, throttle_step,
          take_up_speed, lower_limit_holds, upper_limit_load, cycle_winch_values, underspeed_update,
          pull_out_height, ground_guard,
          nearest_on_phase, path_rate) + GUIDANCE_CALLED + (
              polar_at, guidance_step, reference_pull, auto_guide)
