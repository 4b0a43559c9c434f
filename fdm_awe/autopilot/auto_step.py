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

Arrays (float64; their layouts, declared with :func:`fdm_awe.slots.declare`, are the module's capitalised names):

- ``row``, ``scale``, ``offset``: the glider's raw JSBSim row (:mod:`fdm_awe.sixdof.row`) and its
  SI factors and offsets (SI value = raw * scale + offset, as :class:`~fdm_awe.sixdof.state.SixDofState`);
- ``gso``: the ground station's last output (:data:`GSO`: tension N, line length m, slack flag,
  line force on the glider N, NED; ``GSO.valid`` 0 before the station's first step);
- ``ref_t``, ``ref_table``: the cycle's sample times [s] and its linear columns
  (:data:`REF_COLUMNS` at the offsets of :data:`REF`), ``segs``: per segment the motor plan (1 run, 0
  stop; :meth:`.motor.MotorGate.plan`) and the generator's T2 duty (rows ``SEG.run``, ``SEG.d2``);
- ``gk``: the guidance gains (:meth:`.guidance_loop.GuidanceGains.vector`); ``cu``, ``cf``: the
  unfolded and folded polars (:func:`.guidance.polar_coefficients`); ``gate``: the motor gate
  (:meth:`.motor.MotorGate.vector`); ``par``: the rest (:data:`PAR`);
- ``mem``: the step's state between calls (:data:`MEM`), updated in place;
- ``gin``: the guidance's input of the step (:data:`.guidance.GIN`);
- ``out``: the step's results (:data:`OUT`).

:func:`auto_guide` takes them in four groups (tuples; numba passes them as one argument each):
the cycle ``(ref_t, ref_table, segs)``, the constants ``(gk, cu, cf, gate, par)``, the state
``(mem, integral, thr_state, motor_mem)`` and the results ``(gin, rrow, out)``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .. import slots
from ..definitions.aircraft import stall_speed
from ..pointmass.fold import fold_fraction
from ..sixdof.row import ROW, si_position, si_velocity
from ..trajectory.sampler import cycle_evaluate, cycle_time, segment_of
from .fold import fold_command
from .ground import ground_guard, line_against_pull_out, pull_out_height
from .guidance import CALLED as GUIDANCE_CALLED, GIN, GK, POLAR, US_PULL_UP, guidance_step, polar_at
from .motor import motor_ceiling, motor_spin_down, motor_update
from .rejoin import nearest_on_phase, rejoin_weights
from .thrust import THR, throttle_step
from .underspeed import FOLD_OPEN, underspeed_update
from .wind_estimate import LULL_SHARE
from .winch import WL, cycle_winch_values, guard_load, lower_limit_holds, take_up_speed, upper_limit_load

#: a float64 array (the compiled step's one array type)
Arr = np.ndarray

#: ``rrow``, the reference's row: its linear columns in the order of the table
#: (:data:`.tracking.TRACKING_RULES`; position m, velocity m/s, acceleration m/s^2, NED, airspeed
#: m/s, alpha rad, bank rad, thrust N, tension N, line length m, reel speed m/s)
REF = slots.declare("AutoReference", (("pos", 3), ("vel", 3), ("acc", 3), "airspeed", "alpha", "phi", "thrust",
                                      "tension", "length", "reel_speed"))
#: the columns' names and where the sampler of :data:`.tracking.TRACKING_RULES` must put them (checked)
REF_COLUMNS = REF._fields
REF_WHERE = tuple(slice(at, at + slots.width(REF, f)) if slots.width(REF, f) > 1 else at
                  for f, at in zip(REF._fields, REF))
#: rows of ``segs``: the motor plan (1 run, 0 stop), the generator's T2 duty
SEG = slots.declare("AutoSegments", ("run", "d2"))
#: ``gso``: 1.0 once the station has stepped, tension N, line length m, slack flag, the line force
#: on the glider N, NED
GSO = slots.declare("AutoStationOutput", ("valid", "tension", "length", "slack", ("force", 3)))
#: ``par``: the cycle, the aircraft, the winch and the thrust loop; then the winch's line limits
#: (:func:`.winch.limit_vector`, :data:`.winch.WL`); then the path rejoin (:mod:`.rejoin`): the
#: position error [m] above which AUTO rejoins its path at the point nearest the glider
#: (RJ_TRK_ERR, 0 off), at most this many times a cycle (RJ_TRK_MAX); then the depth below its
#: reference point [m] beyond which the motor's rescue (:func:`.motor.motor_update`) runs in
#: generation (RESC_GEN_DEPTH, 0: any error; :func:`rescue_allowed`); then the wind the cycle was
#: made for [m/s] (its metadata's ``wind_mps``; NaN: unknown); GP_EASE (1.0: the generator
#: brakes least while the ground-proximity guard pulls up in generation); GP_LINE (rad: in a dive
#: steeper than it the guard's pull-out prediction books what the line's pull takes from it; 0 off)
PAR = slots.declare("AutoParams", ("t1", "period", "foldable", "fold_time", "fold_lead", "unfold_lead", "path_tau",
                                   "mass", "rho", "g", "s_u", "s_f", "ratio", "ideal_winch", "rl", "line_ea",
                                   "gen_rl_kp", "rec_tension", "winch_kl", "winch_kt", "armed", "thr_kp", "thr_ki",
                                   "thr_vzero", "thrust_max_static", "thruster", "g_att", "rj_time", "fs_trk_err",
                                   "ref_pull", "catch_time", ("wlim", slots.size(WL)), "rj_trk_err", "rj_trk_max",
                                   "resc_gen", "cycle_wind", "gp_ease", "gp_line"))
#: the end of the line limits in ``par`` (``par[PAR.wlim:WLIM_END]``)
WLIM_END = PAR.wlim + slots.width(PAR, "wlim")
#: ``mem``: path parameter [s], time of the last step [s] (NaN before the first), position error
#: of the last step [m] (NaN before the first), phase of the last step (0 generation, 1
#: recovery, -1 another mode), the last step's length [s]; the guidance's integral, the thrust
#: loop's and the motor switch's states are their own arrays (``integral``, ``thr``, ``motor``);
#: then the rejoin segment under way (:mod:`.rejoin`): 1.0 while it lasts, its start time [s] and
#: the glider's offsets from the path at the start (position m, velocity m/s, NED); then 1.0
#: while the winch's lower tension limit holds (:func:`.winch.lower_limit_holds`); then the
#: underspeed protection (:mod:`.underspeed`): 1.0 while it acts, the last time [s] the airspeed
#: was below its entry speed; then the path rejoins: how many began in the cycle of index
#: ``rj_k``; then 1.0 while the ground-proximity guard pulls up (:mod:`.ground`), and 1.0 while
#: that pull-up began on the line's pull (GP_LINE: it holds until the sink is stopped)
MEM = slots.declare("AutoMemory", ("sref", "tlast", "err", "phase", "dt", "rj", "rj_t0", ("rj_dp", 3), ("rj_dv", 3),
                                   "wlow", "us", "us_t", "rj_n", "rj_k", "gp", "gp_line"))
#: a rejoin segment younger than this [s] is not begun again for the path error
RJ_SETTLE = 1.0
#: flags :func:`auto_guide` returns: the phase changed, the rejoin segment ended at this step, the
#: position error exceeds ``par[PAR.fs_trk_err]`` (> 0; the autopilot times it, FS_TRK_TIME), the
#: underspeed protection began or ended at this step, a rejoin of the lost path began at this step,
#: the ground-proximity guard began or ended its pull-up at this step
PHASE_CHANGED, REJOINED, TRACK_LOST, UNDERSPEED, PATH_REJOIN, GROUND = 1, 2, 4, 8, 16, 32
#: ``out``: the step's reference point (cycle, cycle time, phase, segment, position, path rate),
#: the guidance's command, the motor, fold, throttle and winch commands
OUT = slots.declare("AutoOutput", ("cycle", "tc", "phase", "seg", "rx", "ry", "rz", "rate", "alpha", "mu", "thrust",
                                   "roll", "pitch", "yaw", "cl", "err", "motor", "fold", "throttle", "ideal_thrust",
                                   "w_motor", "w_reel_speed", "w_rl", "w_d2"))


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
    rvx, rvy, rvz = rrow[REF.vel], rrow[REF.vel + 1], rrow[REF.vel + 2]
    vr = math.sqrt(rvx * rvx + rvy * rvy + rvz * rvz)
    if vr > 0.5:
        px0, py0, pz0 = rrow[REF.pos], rrow[REF.pos + 1], rrow[REF.pos + 2]
        e_at = ((px - px0) * rvx + (py - py0) * rvy + (pz - pz0) * rvz) / vr
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
    :data:`.wind_estimate.LULL_SHARE` of the cycle's (``par[PAR.cycle_wind]``; NaN: never)."""
    # only generation with RESC_GEN_DEPTH above 0 asks whether the line pulls
    pulling = (phase == 0 and par[PAR.resc_gen] > 0.0 and gso[GSO.valid] != 0.0 and gso[GSO.slack] == 0.0
               and gso[GSO.tension] >= par[PAR.wlim + WL.tlo] and not rejoining
               and math.sqrt(wx * wx + wy * wy) >= LULL_SHARE * par[PAR.cycle_wind])
    return rescue_allowed(phase, v_air, rrow[REF.airspeed], pull, protect, pz - rrow[REF.pos + 2], par[PAR.resc_gen],
                          pulling)


def paced(rrow: Arr, rate: float, phase: int, gin: Arr) -> None:
    """The reference row ``rrow`` into the guidance's input ``gin`` (:data:`.guidance.GIN`): its
    position [m] and tension [N], its velocity [m/s] and acceleration [m/s^2] at the pace the path
    parameter moves (``rate`` (-), :func:`path_rate`): in generation (``phase`` 0) a glider the
    wind slows (rate below 1) is asked for the path's velocity times the rate and its
    acceleration times the rate squared (the same path flown slower), not pushed to the planned
    speed by the propeller; elsewhere, and at rate 1, the row's own."""
    p = rate if rate < 1.0 and phase == 0 else 1.0
    r, v, a = REF.pos, REF.vel, REF.acc
    gin[GIN.ref_pos], gin[GIN.ref_pos + 1], gin[GIN.ref_pos + 2] = rrow[r], rrow[r + 1], rrow[r + 2]
    gin[GIN.ref_vel], gin[GIN.ref_vel + 1], gin[GIN.ref_vel + 2] = p * rrow[v], p * rrow[v + 1], p * rrow[v + 2]
    gin[GIN.ref_acc], gin[GIN.ref_acc + 1] = p * p * rrow[a], p * p * rrow[a + 1]
    gin[GIN.ref_acc + 2], gin[GIN.tension] = p * p * rrow[a + 2], rrow[REF.tension]


def glider_input(row: Any, scale: Any, offset: Any, par: Arr, gin: Arr) -> tuple[float, ...]:
    """The glider at its raw row ``row`` (SI factors ``scale``, ``offset``; SixDofState's
    relations: raw * scale + offset) into the guidance's input ``gin`` (:data:`.guidance.GIN`):
    its mass, the air density, gravity and its reference areas (from ``par``), its position [m],
    velocity [m/s] and the wind [m/s], NED; returns those nine."""
    gin[GIN.m], gin[GIN.rho], gin[GIN.g] = par[PAR.mass], par[PAR.rho], par[PAR.g]
    gin[GIN.s_u], gin[GIN.s_f] = par[PAR.s_u], par[PAR.s_f]
    px, py, pz = si_position(row, scale, offset)
    vx, vy, vz = si_velocity(row, scale)
    kw = scale[ROW.wind_north]
    # wind = vel - vel_air = vel - (vel - total wind), as the autopilot forms it
    wx = vx - (vx - row[ROW.wind_north] * kw)
    wy = vy - (vy - row[ROW.wind_east] * kw)
    wz = vz - (vz - row[ROW.wind_down] * kw)
    gin[GIN.pos], gin[GIN.pos + 1], gin[GIN.pos + 2] = px, py, pz
    gin[GIN.vel], gin[GIN.vel + 1], gin[GIN.vel + 2] = vx, vy, vz
    gin[GIN.wind], gin[GIN.wind + 1], gin[GIN.wind + 2] = wx, wy, wz
    return px, py, pz, vx, vy, vz, wx, wy, wz


def rejoin_begin(mem: Arr, rrow: Arr, t: float, px: float, py: float, pz: float, vx: float, vy: float,
                 vz: float) -> None:
    """A rejoin segment (:mod:`.rejoin`) from time ``t`` [s] into ``mem``: the glider at ``p*`` [m]
    and ``v*`` [m/s] (NED) off the point of the reference row ``rrow``."""
    mem[MEM.rj], mem[MEM.rj_t0] = 1.0, t
    dp, dv, r, v = MEM.rj_dp, MEM.rj_dv, REF.pos, REF.vel
    mem[dp], mem[dp + 1], mem[dp + 2] = px - rrow[r], py - rrow[r + 1], pz - rrow[r + 2]
    mem[dv], mem[dv + 1], mem[dv + 2] = vx - rrow[v], vy - rrow[v + 1], vz - rrow[v + 2]


def guard_update(mem: Arr, gso: Arr, par: Arr, gk: Arr, pz: float, vx: float, vy: float, vz: float, v_air: float,
                 v_stall: float) -> bool:
    """The ground-proximity guard after a step (:func:`.ground.ground_guard`): the glider at depth
    ``pz`` [m, NED], velocity ``v*`` [m/s], airspeed ``v_air`` and stall speed ``v_stall`` [m/s];
    in a dive steeper than GP_LINE (``par``) the pull-out it predicts books what the line's pull
    (``gso``'s force) takes from it (:func:`.ground.line_against_pull_out`), and a pull-up begun
    so holds until the sink is stopped. Updates ``mem``'s ``gp`` and ``gp_line``; returns whether
    it pulls up."""
    was_gp = mem[MEM.gp] != 0.0
    speed = math.sqrt(vx * vx + vy * vy + vz * vz)
    held = was_gp and mem[MEM.gp_line] != 0.0
    steep = par[PAR.gp_line] > 0.0 and vz > speed * math.sin(par[PAR.gp_line])
    line = gso[GSO.valid] != 0.0 and (held or steep)
    a_line = 0.0
    if line and not held:
        a_line = line_against_pull_out(gso[GSO.force], gso[GSO.force + 1], gso[GSO.force + 2], vx, vy, vz,
                                       par[PAR.mass])
    pull = ground_guard(was_gp, -pz, vz, speed, v_air, v_stall, par[PAR.g],
                        gk[GK.gp_alt], gk[GK.gp_acc], gk[GK.us_exit], gk[GK.us_enter], line, a_line)
    mem[MEM.gp_line] = 1.0 if pull and line else 0.0
    mem[MEM.gp] = 1.0 if pull else 0.0
    return pull


def auto_guide(row: Any, scale: Any, offset: Any, gso: Arr, cycle: tuple, consts: tuple, state: tuple,
               results: tuple) -> int:
    """One AUTO step up to the attitude loops, at the glider's raw row ``row`` (time ``row[T]``),
    on the cycle ``(ref_t, ref_table, segs)`` with the constants ``(gk, cu, cf, gate, par)``:
    advances the ``state`` ``(mem, integral, thr_state, motor_mem)``: ``mem``, the guidance's
    position-error ``integral`` (:mod:`.guidance`), the thrust loop's ``thr_state``
    (:mod:`.thrust`) and the motor switch's ``motor_mem`` (:mod:`.motor`); writes the
    ``results`` ``(gin, rrow, out)``: the guidance's input (:data:`.guidance.GIN`), the
    reference's row (:data:`REF`) and ``out``. Returns the step's flags (:data:`PHASE_CHANGED`,
    :data:`REJOINED`, :data:`TRACK_LOST`, :data:`UNDERSPEED`, :data:`PATH_REJOIN`,
    :data:`GROUND`; 0: none)."""
    ref_t, ref_table, segs = cycle
    gk, cu, cf, gate, par = consts
    mem, integral, thr_state, motor_mem = state
    gin, rrow, out = results
    t = row[0]
    t_last = mem[MEM.tlast]
    dt = 0.0 if t_last != t_last else max(0.0, t - t_last)
    mem[MEM.tlast] = t
    mem[MEM.dt] = dt
    px, py, pz, vx, vy, vz, wx, wy, wz = glider_input(row, scale, offset, par, gin)
    fold = row[ROW.fold]
    polar = polar_at(cu, cf, par[PAR.ratio], par[PAR.s_u], fold)
    # the reference point at the path parameter, and the parameter one step later
    s_par = mem[MEM.sref]
    k, tc, phase, seg, _ = cycle_evaluate(ref_t, ref_table, par[PAR.t1], par[PAR.period], s_par, rrow)
    # the underspeed protection: the airspeed against the stall speed of the fold state
    vax, vay, vaz = vx - wx, vy - wy, vz - wz
    v_air = math.sqrt(vax * vax + vay * vay + vaz * vaz)
    v_stall = stall_speed(par[PAR.mass], par[PAR.rho], par[PAR.g], polar[POLAR.clmax])
    was = mem[MEM.us] != 0.0
    protect, mem[MEM.us_t] = underspeed_update(was, mem[MEM.us_t], t, v_air, v_stall, rrow[REF.airspeed], fold,
                                               gk[GK.us_enter], gk[GK.us_exit], gk[GK.us_hold])
    mem[MEM.us] = 1.0 if protect else 0.0
    # the ground-proximity guard: pull up before the ground, before the path and the protection
    was_gp = mem[MEM.gp] != 0.0
    pull = guard_update(mem, gso, par, gk, pz, vx, vy, vz, v_air, v_stall)
    flags = 0
    rejoin = False
    if protect != was:
        flags = UNDERSPEED
        # protection over: back to the path over a rejoin segment from the glider's state
        rejoin = was and mem[MEM.rj] == 0.0
    if pull != was_gp:
        flags |= GROUND
        # pulled up: back to the path over a rejoin segment from the glider's state
        rejoin = rejoin or (was_gp and not protect and mem[MEM.rj] == 0.0)
    if mem[MEM.rj_k] != k:
        mem[MEM.rj_n], mem[MEM.rj_k] = 0.0, k
    if (not protect and not pull and (phase == 0 or fold < FOLD_OPEN) and par[PAR.rj_trk_err] > 0.0
            and mem[MEM.err] > par[PAR.rj_trk_err] and mem[MEM.rj_n] < par[PAR.rj_trk_max]
            and (mem[MEM.rj] == 0.0 or t - mem[MEM.rj_t0] >= RJ_SETTLE)):
        # the path is lost (the last step's error; a rejoin under way counts after RJ_SETTLE, the
        # error of its first step may be the one before it began): rejoin the path where it
        # passes nearest the glider, not at a point the path parameter froze or ran away with.
        # Not in a folded recovery: the folded wing cannot fly back onto its dive, a rejoin
        # there pushed it over into the ground (foldable, 8 m/s, moderate seed 9)
        flags |= PATH_REJOIN
        mem[MEM.rj_n] += 1.0
        s_par = k * par[PAR.period] + nearest_on_phase(ref_t, ref_table, par[PAR.t1], par[PAR.period], tc, px, py,
                                                       pz, vx, vy, vz)
        k, tc, phase, seg, _ = cycle_evaluate(ref_t, ref_table, par[PAR.t1], par[PAR.period], s_par, rrow)
        rejoin = True
    if rejoin:
        rejoin_begin(mem, rrow, t, px, py, pz, vx, vy, vz)
    if mem[MEM.rj] != 0.0:
        # the rejoin segment: the path's point plus a vanishing offset, the parameter at flight time
        done, w, w1, w2, e, e1, e2 = rejoin_weights(t, mem[MEM.rj_t0], par[PAR.rj_time])
        if done != 0.0:
            mem[MEM.rj] = 0.0
            flags |= REJOINED
        else:
            for j in range(3):
                dp, dv = mem[MEM.rj_dp + j], mem[MEM.rj_dv + j]
                rrow[REF.pos + j] = rrow[REF.pos + j] + (1.0 - w) * dp + e * dv
                rrow[REF.vel + j] = rrow[REF.vel + j] - w1 * dp + e1 * dv
                rrow[REF.acc + j] = rrow[REF.acc + j] - w2 * dp + e2 * dv
        # the parameter at flight time, in generation held back where the glider lags the
        # segment's point (a rejoin into a headwind would otherwise run away from the glider;
        # held in a folded recovery's dive, the reference pushed the wing over into the ground);
        # with the path rejoin off (RJ_TRK_ERR 0) at flight time throughout, as before it
        hold = phase == 0 and par[PAR.rj_trk_err] > 0.0
        rate = path_rate(px, py, pz, rrow, par[PAR.path_tau], 1.0) if hold else 1.0
    else:
        rate = path_rate(px, py, pz, rrow, par[PAR.path_tau], 3.0)
    mem[MEM.sref] = s_par + rate * dt
    paced(rrow, rate, phase, gin)
    valid = gso[GSO.valid] != 0.0
    # pulling up, the wing flies against the measured line force: no radial force of the reference's
    taut = valid and gso[GSO.slack] == 0.0 and phase == 0 and not pull
    ref_pull = reference_pull(par[PAR.ref_pull] != 0.0, phase, tc, par[PAR.catch_time]) and not pull
    f, ln = GSO.force, GIN.line
    if valid:
        gin[ln], gin[ln + 1], gin[ln + 2] = gso[f], gso[f + 1], gso[f + 2]
    else:
        gin[ln], gin[ln + 1], gin[ln + 2] = 0.0, 0.0, 0.0
    us = 0.0  # the protection: 0 off, 1 on, 2 on with the line slack; the guard's pull-up before it
    if pull:
        us = US_PULL_UP
    elif protect:
        us = 2.0 if valid and gso[GSO.slack] != 0.0 else 1.0
    # the motor: stopped where the reference stopped it (no thrust for the guidance to give)
    slow = rescue_gate(phase, v_air, pz, wx, wy, rrow, gso, par, mem[MEM.rj] != 0.0, pull, protect)
    motor = motor_update(segs[SEG.run], seg, t, mem[MEM.err], gate, motor_mem, slow) != 0.0
    if motor:
        t_max = gk[GK.thrust_max]
    elif par[PAR.thruster] != 0.0:
        t_max = 0.0
    else:  # a soft stop: the thrust the guidance may count on falls with the throttle
        t_max = motor_spin_down(t, gate, motor_mem, thr_state[THR.thrust])
    gin[GIN.fold], gin[GIN.dt], gin[GIN.t_max], gin[GIN.us] = fold, dt, t_max, us
    gin[GIN.taut], gin[GIN.ref_pull] = 1.0 if taut else 0.0, 1.0 if ref_pull else 0.0
    alpha, mu, thrust, roll, pitch, yaw, cl, err = guidance_step(gk, integral, polar, gin)
    mem[MEM.err] = err
    if par[PAR.fs_trk_err] > 0.0 and err > par[PAR.fs_trk_err]:
        flags |= TRACK_LOST
    if par[PAR.foldable] != 0.0:
        fold_cmd = fold_command(tc, par[PAR.t1], par[PAR.period], par[PAR.fold_time], par[PAR.fold_lead],
                                par[PAR.unfold_lead])
    else:
        fold_cmd = 0.0
    if phase != mem[MEM.phase]:
        flags |= PHASE_CHANGED
    mem[MEM.phase] = phase
    ideal_winch = par[PAR.ideal_winch] != 0.0
    dist = math.sqrt(px * px + py * py + pz * pz)
    dist_rate = (px * vx + py * vy + pz * vz) / max(dist, 1e-6)
    w_motor, w_speed, w_rl, w_d2, w_low = cycle_winch_values(
        phase, ideal_winch, rate, rrow[REF.reel_speed], rrow[REF.length], rrow[REF.tension], segs[SEG.d2, seg],
        valid, gso[GSO.length], gso[GSO.tension], par[PAR.rl], par[PAR.line_ea], par[PAR.gen_rl_kp],
        par[PAR.rec_tension], par[PAR.winch_kl], par[PAR.winch_kt], dist, dist_rate, mem[MEM.wlow] != 0.0,
        par[PAR.wlim:WLIM_END])
    mem[MEM.wlow] = 1.0 if w_low else 0.0
    w_rl = guard_load(w_rl, w_motor, phase, ideal_winch, pull and par[PAR.gp_ease] != 0.0)
    ideal = 0.0
    if par[PAR.thruster] != 0.0:
        thr = 0.0  # the paper plant's ideal thruster takes the thrust command, the propeller idles
        if motor and par[PAR.armed] != 0.0:
            ideal = thrust
    elif not motor:
        # stopped: the throttle falls to 0 (a soft stop), the thrust loop's integral is held
        thr = motor_spin_down(t, gate, motor_mem, thr_state[THR.last])
    else:
        # after a start the propeller spins up from rest under a rising throttle ceiling
        armed = par[PAR.armed] != 0.0
        ceiling = motor_ceiling(t, gate, motor_mem)
        thr = throttle_step(thrust, row[ROW.thrust] * scale[ROW.thrust], row[ROW.vt] * scale[ROW.vt], dt, armed,
                            ceiling, par[PAR.thr_kp], par[PAR.thr_ki], par[PAR.thr_vzero],
                            par[PAR.thrust_max_static], thr_state)
        thr_state[THR.last], thr_state[THR.thrust] = thr, thrust
    out[OUT.cycle], out[OUT.tc], out[OUT.phase], out[OUT.seg] = k, tc, phase, seg
    out[OUT.rx], out[OUT.ry], out[OUT.rz], out[OUT.rate] = rrow[REF.pos], rrow[REF.pos + 1], rrow[REF.pos + 2], rate
    out[OUT.alpha], out[OUT.mu], out[OUT.thrust] = alpha, mu, thrust
    out[OUT.roll], out[OUT.pitch], out[OUT.yaw], out[OUT.throttle], out[OUT.ideal_thrust] = roll, pitch, yaw, thr, ideal
    out[OUT.cl], out[OUT.err], out[OUT.motor], out[OUT.fold] = cl, err, 1.0 if motor else 0.0, fold_cmd
    out[OUT.w_motor], out[OUT.w_reel_speed], out[OUT.w_rl], out[OUT.w_d2] = w_motor, w_speed, w_rl, w_d2
    return flags


#: the plain functions the AUTO step calls, for a compiled caller to register
#: (``numba.extending.register_jitable``), then the step itself
CALLED = (si_position, si_velocity, cycle_time, segment_of, cycle_evaluate, rejoin_weights, paced, rescue_allowed,
          rescue_gate, motor_update, motor_ceiling, motor_spin_down, fold_fraction, fold_command, throttle_step,
          take_up_speed, lower_limit_holds, upper_limit_load, guard_load, cycle_winch_values, underspeed_update,
          line_against_pull_out, pull_out_height, ground_guard, guard_update,
          nearest_on_phase, path_rate, rejoin_begin, glider_input) + GUIDANCE_CALLED + (
              polar_at, guidance_step, reference_pull, auto_guide)
