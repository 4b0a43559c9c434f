"""AUTO on the pumping cycle: the state of the AUTO step, its arrays, and one step run by Python.

:class:`AutoStep` holds what :func:`~fdm_awe.autopilot.auto_step.auto_guide` works on between
steps (``mem``: path parameter, time, position error, phase, the rejoin segment; the last step's
results ``out`` and reference row), builds its constant arrays from the autopilot's reference,
gains and parameters (again after a parameter change or for another reference or gate), runs one
step in Python (:meth:`AutoStep.step`: the AUTO step, then the attitude loops) and hands the same
arrays to a compiled block (:meth:`AutoStep.kernel_arrays`,
:func:`fdm_awe.sim.autopilot_kernel.autopilot_steps`), which updates them in place. Either way the
same functions run on the same arrays.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..sixdof.state import SixDofState, Surfaces
from .auto_step import (A_ARMED, A_CATCH_TIME, A_FOLD_LEAD, A_FOLD_TIME, A_FOLDABLE, A_FS_TRK_ERR, A_G, A_G_ATT,
                        A_GEN_RL_KP, A_IDEAL_WINCH, A_LINE_EA, A_MASS, A_PATH_TAU, A_PERIOD, A_RATIO, A_REC_TENSION,
                        A_CYCLE_WIND, A_REF_PULL, A_RESC_GEN, A_RHO, A_RJ_TIME, A_RJ_TRK_ERR, A_RJ_TRK_MAX, A_RL, A_S_F, A_S_U, A_T1,
                        A_THR_KI, A_THR_KP, A_THR_VZERO, A_THRUST_MAX_STATIC, A_THRUSTER, A_UNFOLD_LEAD, A_WINCH_KL, A_WINCH_KT, A_WLIM, GS_FX, GS_FZ,
                        GS_LENGTH, GS_SLACK, GS_TENSION, GS_VALID, M_DT, M_ERR, M_PHASE, M_RJ, M_RJ_DP, M_RJ_DV,
                        M_RJ_T0, M_TLAST, N_GSO, N_MEM, N_OUT, N_PAR, N_REF, O_ALPHA, O_CL, O_CYCLE, O_ERR, O_FOLD,
                        O_IDEAL_THRUST, O_MU, O_PHASE, O_PITCH, O_RATE, O_ROLL, O_SEG, O_TC, O_THROTTLE, O_THRUST,
                        O_W_D2, O_W_MOTOR, O_W_REEL_SPEED, O_W_RL, O_YAW, PHASE_CHANGED, R_AIRSPEED, R_ALPHA, R_AX,
                        R_AZ, R_LENGTH, R_PHI, R_PX, R_PZ, R_REEL_SPEED, R_TENSION, R_THRUST, R_VX, R_VZ, REF_COLUMNS,
                        REF_WHERE, REJOINED, TRACK_LOST, M_US, M_GP, GROUND, PATH_REJOIN, UNDERSPEED, auto_guide)
from .fold import reference_fold_time
from .guidance import polar_arguments
from .guidance_loop import GuidanceCommand
from ..trajectory.schema import GENERATION, PHASE_NAMES, RECOVERY
from .tracking import RefPoint, TrackingReference
from .winch import N_LIMITS, limit_vector, winch_command

#: the AUTO step's phase codes of the autopilot's phases
PHASE_CODES = {"generation": float(GENERATION), "recovery": float(RECOVERY)}


class AutoStep:
    """The AUTO step's state and arrays (see the module doc); ``ap`` arguments are the
    :class:`~fdm_awe.autopilot.autopilot.Autopilot` it serves."""

    def __init__(self) -> None:
        self.mem = np.zeros(N_MEM)  #: the step's state (``M_*``), updated in place
        self.mem[M_TLAST] = self.mem[M_ERR] = math.nan
        self.mem[M_PHASE] = -1.0
        self.out = np.zeros(N_OUT)  #: the last step's results (``O_*``)
        self.rrow = np.zeros(N_REF)  #: the last step's reference row (``R_*``)
        self._gso = np.zeros(N_GSO)
        #: the last step's position error exceeded FS_TRK_ERR (:data:`~.auto_step.TRACK_LOST`)
        self.track_lost = False
        #: the position error of the step before the last one [m] (NaN before it; the path rejoin's note)
        self.last_error = math.nan
        self._cache: tuple | None = None  # (reference, gate, arrays)

    def invalidate(self) -> None:
        """Build the constant arrays again at the next step (a parameter changed)."""
        self._cache = None

    @property
    def t_last(self) -> float:
        """Time of the last step [s] (NaN before the first)."""
        return float(self.mem[M_TLAST])

    @property
    def path_rate(self) -> float:
        """The path parameter's rate at the last step (-)."""
        return float(self.out[O_RATE])

    def begin_rejoin(self, t: float, dp: np.ndarray, dv: np.ndarray) -> None:
        """A rejoin segment from time ``t`` [s] with the glider ``dp`` [m], ``dv`` [m/s] off the path."""
        m = self.mem
        m[M_RJ], m[M_RJ_T0] = 1.0, t
        m[M_RJ_DP:M_RJ_DP + 3], m[M_RJ_DV:M_RJ_DV + 3] = dp, dv
        m[M_US] = 0.0  # AUTO begins unprotected

    def end_rejoin(self) -> None:
        """No rejoin segment."""
        self.mem[M_RJ] = 0.0

    def arrays(self, ap: Any) -> tuple:
        """The constant arrays of :func:`~fdm_awe.autopilot.auto_step.auto_guide` for ``ap``: the
        reference's times, linear columns and per-segment motor plan and T2 duty, the guidance's
        gains and polars, the motor gate, the parameter vector (``A_*``), then the attitude law's
        gains."""
        ref, gate = ap.reference, ap.motor.gate
        c = self._cache
        if c is not None and c[0] is ref and c[1] is gate:
            return c[2]
        smp = ref.sampler()
        if tuple(smp.where(n) for n in REF_COLUMNS) != REF_WHERE:  # pragma: no cover - a definition error
            raise RuntimeError("the reference's sampled columns are not in the AUTO step's order")
        segs = np.ascontiguousarray(np.vstack((gate.plan_vector(ref), smp.segments("boost_duty"))), float)
        g, p, tl = ap.guidance, ap.params, ap.thrust_loop
        cu, cf, ratio, S_u = polar_arguments(g.aero_u, g.aero_f)
        par = np.zeros(N_PAR)
        par[A_T1], par[A_PERIOD], par[A_FOLDABLE] = ref.T1, ref.period, 1.0 if ap.config == "foldable" else 0.0
        par[A_FOLD_TIME] = reference_fold_time(ref.meta, ap.glider.fold_time_s) if ap.config == "foldable" else 0.0
        par[A_FOLD_LEAD], par[A_UNFOLD_LEAD], par[A_PATH_TAU] = p["FOLD_LEAD"], p["UNFOLD_LEAD"], p["PATH_TAU"]
        par[A_MASS], par[A_RHO], par[A_G] = g.m, g.rho, g.g
        par[A_S_U], par[A_S_F], par[A_RATIO] = S_u, g.aero_f.S, ratio
        par[A_IDEAL_WINCH], par[A_RL], par[A_LINE_EA] = 1.0 if ap.winch == "ideal" else 0.0, ap.R_L, ap.line_EA
        par[A_GEN_RL_KP], par[A_REC_TENSION], par[A_WINCH_KL], par[A_WINCH_KT] = (
            p["GEN_RL_KP"], p["REC_TENSION"], p["WINCH_KL"], p["WINCH_KT"])
        par[A_THR_KP], par[A_THR_KI], par[A_THR_VZERO], par[A_THRUST_MAX_STATIC] = (
            p["THR_KP"], p["THR_KI"], tl.v_zero, tl.thrust_max_static)
        par[A_THRUSTER], par[A_G_ATT], par[A_RJ_TIME] = (1.0 if ap.thruster is not None else 0.0, ap.att.g,
                                                        p["RJ_TIME"])
        par[A_FS_TRK_ERR] = p["FS_TRK_ERR"]
        par[A_WLIM:A_WLIM + N_LIMITS] = limit_vector(p, ap.reel_in_max)
        par[A_REF_PULL], par[A_CATCH_TIME] = p["GUID_REFPULL"], p["GUID_CATCH_T"]
        par[A_RJ_TRK_ERR], par[A_RJ_TRK_MAX] = p["RJ_TRK_ERR"], p["RJ_TRK_MAX"]
        par[A_RESC_GEN] = p["RESC_GEN_DEPTH"]
        w = ref.meta.get("wind_mps")
        par[A_CYCLE_WIND] = float(w) if isinstance(w, (int, float)) and not isinstance(w, bool) else math.nan
        arrays = (np.ascontiguousarray(smp.t, float), np.ascontiguousarray(smp.table, float), segs,
                  np.asarray(g.k.vector(), float), cu, cf, gate.vector(), par, ap.att.law.gains.vector())
        self._cache = (ref, gate, arrays)
        return arrays

    def step(self, ap: Any, s: SixDofState, gs: Any) -> tuple[Surfaces, Any, list[str]]:
        """One AUTO step of ``ap`` at glider state ``s`` with the ground station's last output
        ``gs`` (None before its first step): (surfaces, winch command, the notes of the step)."""
        ref_t, table, segs, gk, cu, cf, gate, par, _ = self.arrays(ap)
        par[A_ARMED] = 1.0 if ap.armed else 0.0
        gso = self._gso
        if gs is not None:
            gso[GS_VALID], gso[GS_TENSION], gso[GS_LENGTH], gso[GS_SLACK] = 1.0, gs.tension, gs.length, gs.slack
            gso[GS_FX:GS_FZ + 1] = gs.force_on_glider_ned
        else:
            gso[GS_VALID] = 0.0
        mem, out = self.mem, self.out
        mem[M_PHASE] = PHASE_CODES.get(ap.phase, -1.0)
        self.last_error = float(mem[M_ERR])
        flags = auto_guide(s.raw, s.scale, s.offset, gso, ref_t, table, segs, gk, cu, cf, gate, par, mem,
                           ap.guidance.integral, ap.thrust_loop.state, ap.motor.mem, self.rrow, out)
        notes = []
        self.track_lost = bool(flags & TRACK_LOST)
        if flags & PATH_REJOIN:
            notes.append(f"rejoin: the path lost ({self.last_error:.1f} m, RJ_TRK_ERR {ap.params['RJ_TRK_ERR']:g} m), "
                         f"rejoining at its nearest point (t_cycle {out[O_TC]:.2f} s)")
        if flags & UNDERSPEED:
            if mem[M_US] != 0.0:
                notes.append(f"underspeed: airspeed {s.airspeed:.1f} m/s, speed before path "
                             f"(stall speed {ap.stall_speed(s.fold):.1f} m/s)")
            else:
                notes.append(f"underspeed: airspeed {s.airspeed:.1f} m/s again, rejoining the path")
        if flags & GROUND:
            if mem[M_GP] != 0.0:
                notes.append(f"ground proximity: pull up at {-float(s.pos_ned[2]):.1f} m, sinking "
                             f"{float(s.vel_ned[2]):.1f} m/s (GP_ALT {ap.params['GP_ALT']:g} m)")
            else:
                notes.append(f"ground proximity: clear at {-float(s.pos_ned[2]):.1f} m, rejoining the path")
        if flags & REJOINED:
            notes.append("rejoin: on the path")
        if flags & PHASE_CHANGED:
            phase = PHASE_NAMES[int(out[O_PHASE])]
            notes.append(f"phase {ap.phase} -> {phase} (cycle {int(out[O_CYCLE])}, t_cycle {out[O_TC]:.2f} s)")
            ap.phase = phase
        if ap.thruster is not None:
            ap.thruster.command(float(out[O_IDEAL_THRUST]))
        # the attitude loops (attitude.attitude_from_row, as the compiled block runs them)
        a, e, r = ap.att.update(s, out[O_ALPHA], out[O_ROLL], mem[M_DT])
        surf = Surfaces(a, e, r, float(out[O_THROTTLE]), float(out[O_FOLD]))
        return surf, winch_command(out[O_W_MOTOR], out[O_W_REEL_SPEED], out[O_W_RL], out[O_W_D2]), notes

    def kernel_arrays(self, ap: Any) -> tuple | None:
        """The arrays of a compiled block for ``ap`` (the order of
        :func:`fdm_awe.sim.autopilot_kernel.autopilot_steps`), or None in a phase the AUTO step
        does not know (the Python step sets it first)."""
        if ap.phase not in PHASE_CODES:
            return None
        ref_t, table, segs, gk, cu, cf, gate, par, law_g = self.arrays(ap)
        par[A_ARMED] = 1.0 if ap.armed else 0.0
        self.mem[M_PHASE] = PHASE_CODES[ap.phase]
        law = ap.att.law
        return (ref_t, table, segs, gk, cu, cf, gate, par, self.mem, ap.guidance.integral, ap.thrust_loop.state,
                ap.motor.mem, self.rrow, self.out, law.coef, law_g, law.fold_at, law.integ)

    def command(self) -> GuidanceCommand:
        """The guidance's command of the last step."""
        o = self.out.tolist()
        return GuidanceCommand(o[O_ALPHA], o[O_MU], o[O_THRUST], o[O_ROLL], o[O_PITCH], o[O_YAW], o[O_CL], o[O_ERR])

    def ref_point(self, reference: TrackingReference) -> RefPoint:
        """The reference point of the last step on ``reference``."""
        o, r = self.out.tolist(), self.rrow
        seg = int(o[O_SEG])
        smp = reference.sampler()
        return RefPoint(t_cycle=o[O_TC], cycle=int(o[O_CYCLE]), phase=int(o[O_PHASE]), pos=r[R_PX:R_PZ + 1].copy(),
                        vel=r[R_VX:R_VZ + 1].copy(), acc=r[R_AX:R_AZ + 1].copy(), airspeed=float(r[R_AIRSPEED]),
                        alpha=float(r[R_ALPHA]), phi=float(r[R_PHI]), thrust=float(r[R_THRUST]),
                        tension=float(r[R_TENSION]), length=float(r[R_LENGTH]), reel_speed=float(r[R_REEL_SPEED]),
                        motor_on=float(smp.segments("motor_on")[seg]),
                        boost_duty=float(smp.segments("boost_duty")[seg]))
