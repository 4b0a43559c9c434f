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

from .. import slots
from ..sixdof.state import SixDofState, Surfaces
from .auto_step import (GROUND, GSO, MEM, OUT, PAR, PATH_REJOIN, PHASE_CHANGED, REF, REF_COLUMNS, REF_WHERE, REJOINED,
                        TRACK_LOST, UNDERSPEED, auto_guide)
from .fold import reference_fold_time
from .guidance import GIN, GK, POLAR, polar_arguments
from .guidance_loop import GuidanceCommand
from .motor import GATE
from ..trajectory.schema import GENERATION, PHASE_NAMES, RECOVERY
from .tracking import RefPoint, TrackingReference
from .winch import WL, limit_vector, winch_command

#: the AUTO step's phase codes of the autopilot's phases
PHASE_CODES = {"generation": float(GENERATION), "recovery": float(RECOVERY)}


class AutoStep:
    """The AUTO step's state and arrays (see the module doc); ``ap`` arguments are the
    :class:`~fdm_awe.autopilot.autopilot.Autopilot` it serves."""

    def __init__(self) -> None:
        self.mem = slots.new(MEM)  #: the step's state (:data:`~.auto_step.MEM`), updated in place
        self.mem[MEM.tlast] = self.mem[MEM.err] = math.nan
        self.mem[MEM.phase] = -1.0
        self.out = slots.new(OUT)  #: the last step's results (:data:`~.auto_step.OUT`)
        self.rrow = slots.new(REF)  #: the last step's reference row (:data:`~.auto_step.REF`)
        self._gso = [0.0] * slots.size(GSO)  # the station's last output (a list: the Python step's)
        # the guidance's input of the last step: a list for the Python step (faster items than an
        # array's, the same floats), an array for the compiled block
        self._gin, self._gin_block = [0.0] * slots.size(GIN), slots.new(GIN)
        #: the last step's position error exceeded FS_TRK_ERR (:data:`~.auto_step.TRACK_LOST`)
        self.track_lost = False
        #: the position error of the step before the last one [m] (NaN before it; the path rejoin's note)
        self.last_error = math.nan
        self._cache: tuple | None = None  # (reference, gate, arrays, the Python step's lists)

    def invalidate(self) -> None:
        """Build the constant arrays again at the next step (a parameter changed)."""
        self._cache = None

    @property
    def t_last(self) -> float:
        """Time of the last step [s] (NaN before the first)."""
        return float(self.mem[MEM.tlast])

    @property
    def path_rate(self) -> float:
        """The path parameter's rate at the last step (-)."""
        return float(self.out[OUT.rate])

    def begin_rejoin(self, t: float, dp: np.ndarray, dv: np.ndarray) -> None:
        """A rejoin segment from time ``t`` [s] with the glider ``dp`` [m], ``dv`` [m/s] off the path."""
        m = self.mem
        m[MEM.rj], m[MEM.rj_t0] = 1.0, t
        m[MEM.rj_dp:MEM.rj_dp + 3], m[MEM.rj_dv:MEM.rj_dv + 3] = dp, dv
        m[MEM.us] = 0.0  # AUTO begins unprotected

    def end_rejoin(self) -> None:
        """No rejoin segment."""
        self.mem[MEM.rj] = 0.0

    def arrays(self, ap: Any) -> tuple:
        """The constant arrays of :func:`~fdm_awe.autopilot.auto_step.auto_guide` for ``ap``: the
        reference's times, linear columns and per-segment motor plan and T2 duty, the guidance's
        gains and polars, the motor gate, the parameter vector (:data:`~.auto_step.PAR`), then the attitude law's
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
        par = slots.new(PAR)
        par[PAR.t1], par[PAR.period], par[PAR.foldable] = ref.T1, ref.period, 1.0 if ap.config == "foldable" else 0.0
        par[PAR.fold_time] = reference_fold_time(ref.meta, ap.glider.fold_time_s) if ap.config == "foldable" else 0.0
        par[PAR.fold_lead], par[PAR.unfold_lead], par[PAR.path_tau] = p["FOLD_LEAD"], p["UNFOLD_LEAD"], p["PATH_TAU"]
        par[PAR.mass], par[PAR.rho], par[PAR.g] = g.m, g.rho, g.g
        par[PAR.s_u], par[PAR.s_f], par[PAR.ratio] = S_u, g.aero_f.S, ratio
        par[PAR.ideal_winch], par[PAR.rl], par[PAR.line_ea] = 1.0 if ap.winch == "ideal" else 0.0, ap.R_L, ap.line_EA
        par[PAR.gen_rl_kp], par[PAR.rec_tension], par[PAR.winch_kl], par[PAR.winch_kt] = (
            p["GEN_RL_KP"], p["REC_TENSION"], p["WINCH_KL"], p["WINCH_KT"])
        par[PAR.thr_kp], par[PAR.thr_ki], par[PAR.thr_vzero], par[PAR.thrust_max_static] = (
            p["THR_KP"], p["THR_KI"], tl.v_zero, tl.thrust_max_static)
        par[PAR.thruster], par[PAR.g_att], par[PAR.rj_time] = (1.0 if ap.thruster is not None else 0.0, ap.att.g,
                                                        p["RJ_TIME"])
        par[PAR.fs_trk_err] = p["FS_TRK_ERR"]
        par[PAR.wlim:PAR.wlim + slots.size(WL)] = limit_vector(p, ap.reel_in_max)
        par[PAR.ref_pull], par[PAR.catch_time] = p["GUID_REFPULL"], p["GUID_CATCH_T"]
        par[PAR.rj_trk_err], par[PAR.rj_trk_max] = p["RJ_TRK_ERR"], p["RJ_TRK_MAX"]
        par[PAR.resc_gen], par[PAR.gp_ease], par[PAR.gp_line] = p["RESC_GEN_DEPTH"], p["GP_EASE"], p["GP_LINE"]
        w = ref.meta.get("wind_mps")
        par[PAR.cycle_wind] = float(w) if isinstance(w, (int, float)) and not isinstance(w, bool) else math.nan
        arrays = (np.ascontiguousarray(smp.t, float), np.ascontiguousarray(smp.table, float), segs,
                  np.asarray(g.k.vector(), float), cu, cf, gate.vector(), par, ap.att.law.gains.vector())
        # the compiled step reads them by offset, unchecked: their sizes are their layouts'
        for layout, a, what in ((GK, arrays[3], "gk"), (POLAR, cu, "cu"), (POLAR, cf, "cf"), (GATE, arrays[6], "gate")):
            slots.check(layout, a, f"the AUTO step's {what}")
        # the Python step reads the gains and the polars as lists of floats (faster items, the
        # same floats; as :meth:`.guidance_loop.Guidance.update` reads its gains)
        self._cache = (ref, gate, arrays, (arrays[3].tolist(), cu.tolist(), cf.tolist()))
        return arrays

    def step(self, ap: Any, s: SixDofState, gs: Any) -> tuple[Surfaces, Any, list[str]]:
        """One AUTO step of ``ap`` at glider state ``s`` with the ground station's last output
        ``gs`` (None before its first step): (surfaces, winch command, the notes of the step)."""
        ref_t, table, segs, _, _, _, gate, par, _ = self.arrays(ap)
        gk, cu, cf = self._cache[3]
        par[PAR.armed] = 1.0 if ap.armed else 0.0
        gso = self._gso
        if gs is not None:
            gso[GSO.valid], gso[GSO.tension], gso[GSO.length], gso[GSO.slack] = 1.0, gs.tension, gs.length, gs.slack
            gso[GSO.force:GSO.force + 3] = gs.force_on_glider_ned
        else:
            gso[GSO.valid] = 0.0
        mem, out = self.mem, self.out
        mem[MEM.phase] = PHASE_CODES.get(ap.phase, -1.0)
        self.last_error = float(mem[MEM.err])
        flags = auto_guide(s.raw, s.scale, s.offset, gso, (ref_t, table, segs), (gk, cu, cf, gate, par),
                           (mem, ap.guidance.integral, ap.thrust_loop.state, ap.motor.mem), (self._gin, self.rrow, out))
        notes = []
        self.track_lost = bool(flags & TRACK_LOST)
        if flags & PATH_REJOIN:
            notes.append(f"rejoin: the path lost ({self.last_error:.1f} m, RJ_TRK_ERR {ap.params['RJ_TRK_ERR']:g} m), "
                         f"rejoining at its nearest point (t_cycle {out[OUT.tc]:.2f} s)")
        if flags & UNDERSPEED:
            if mem[MEM.us] != 0.0:
                notes.append(f"underspeed: airspeed {s.airspeed:.1f} m/s, speed before path "
                             f"(stall speed {ap.stall_speed(s.fold):.1f} m/s)")
            else:
                notes.append(f"underspeed: airspeed {s.airspeed:.1f} m/s again, rejoining the path")
        if flags & GROUND:
            if mem[MEM.gp] != 0.0:
                notes.append(f"ground proximity: pull up at {-float(s.pos_ned[2]):.1f} m, sinking "
                             f"{float(s.vel_ned[2]):.1f} m/s (GP_ALT {ap.params['GP_ALT']:g} m)")
            else:
                notes.append(f"ground proximity: clear at {-float(s.pos_ned[2]):.1f} m, rejoining the path")
        if flags & REJOINED:
            notes.append("rejoin: on the path")
        if flags & PHASE_CHANGED:
            phase = PHASE_NAMES[int(out[OUT.phase])]
            notes.append(f"phase {ap.phase} -> {phase} (cycle {int(out[OUT.cycle])}, t_cycle {out[OUT.tc]:.2f} s)")
            ap.phase = phase
        if ap.thruster is not None:
            ap.thruster.command(float(out[OUT.ideal_thrust]))
        # the attitude loops (attitude.attitude_from_row, as the compiled block runs them)
        a, e, r = ap.att.update(s, out[OUT.alpha], out[OUT.roll], mem[MEM.dt])
        surf = Surfaces(a, e, r, float(out[OUT.throttle]), float(out[OUT.fold]))
        return surf, winch_command(out[OUT.w_motor], out[OUT.w_reel_speed], out[OUT.w_rl], out[OUT.w_d2]), notes

    def kernel_arrays(self, ap: Any) -> tuple | None:
        """The arrays of a compiled block for ``ap`` (the order of
        :func:`fdm_awe.sim.autopilot_kernel.autopilot_steps`), or None in a phase the AUTO step
        does not know (the Python step sets it first)."""
        if ap.phase not in PHASE_CODES:
            return None
        ref_t, table, segs, gk, cu, cf, gate, par, law_g = self.arrays(ap)
        par[PAR.armed] = 1.0 if ap.armed else 0.0
        self.mem[MEM.phase] = PHASE_CODES[ap.phase]
        law = ap.att.law
        return ((ref_t, table, segs), (gk, cu, cf, gate, par),
                (self.mem, ap.guidance.integral, ap.thrust_loop.state, ap.motor.mem), (self._gin_block, self.rrow, self.out),
                (law.coef, law_g, law.fold_at, law.integ))

    def command(self) -> GuidanceCommand:
        """The guidance's command of the last step."""
        o = self.out.tolist()
        return GuidanceCommand(o[OUT.alpha], o[OUT.mu], o[OUT.thrust], o[OUT.roll], o[OUT.pitch], o[OUT.yaw],
                               o[OUT.cl], o[OUT.err])

    def ref_point(self, reference: TrackingReference) -> RefPoint:
        """The reference point of the last step on ``reference``."""
        o, r = self.out.tolist(), self.rrow
        seg = int(o[OUT.seg])
        smp = reference.sampler()
        return RefPoint(t_cycle=o[OUT.tc], cycle=int(o[OUT.cycle]), phase=int(o[OUT.phase]),
                        pos=r[REF.pos:REF.pos + 3].copy(), vel=r[REF.vel:REF.vel + 3].copy(),
                        acc=r[REF.acc:REF.acc + 3].copy(), airspeed=float(r[REF.airspeed]),
                        alpha=float(r[REF.alpha]), phi=float(r[REF.phi]), thrust=float(r[REF.thrust]),
                        tension=float(r[REF.tension]), length=float(r[REF.length]),
                        reel_speed=float(r[REF.reel_speed]),
                        motor_on=float(smp.segments("motor_on")[seg]),
                        boost_duty=float(smp.segments("boost_duty")[seg]))
