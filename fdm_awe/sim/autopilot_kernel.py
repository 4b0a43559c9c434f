"""The co-simulation step with the autopilot's AUTO step compiled in: whole blocks of an
autopilot flight without Python in between.

:func:`autopilot_steps` runs, per step, what :meth:`fdm_awe.sim.loop.CoSim.run` does with the
autopilot as its controller and a flight's bookkeeping as its ``on_step``:

1. the autopilot's AUTO step on the current row (:func:`fdm_awe.autopilot.auto_step.auto_guide`:
   reference point, path rate, motor, guidance, fold, winch, thrust), then its attitude loops
   (:func:`fdm_awe.autopilot.attitude.attitude_from_row` on the attitude law's coefficients, re-read
   from JSBSim when the fold state moves as :class:`~fdm_awe.sixdof.attitude_law.AttitudeLaw`
   re-reads them);
2. the commands into JSBSim's flight controls and the ground station's command terms
   (:func:`fdm_awe.groundstation.station.command_values`);
3. the co-simulation step (:func:`fdm_awe.sim.kernel.cosim_step`);
4. the flight's bookkeeping of the step (:func:`fdm_awe.sim.glider_ledger.ledger_step`, the
   reference point flown, the tracking error, the station's energies) into ``alog``;
5. with a lumped line in turbulence (uniform wind), the gust the glider meets handed to the line
   for the next step (:func:`hand_gust`), as a flight's step hook hands it over.

Everything the autopilot must do in Python ends a block *before* the step, with the autopilot's
state as it was (``mem`` restored): a phase change (the autopilot notes it), a winch command the
ground station would refuse; the caller then runs that step through the Python autopilot, which
calls the same functions. A block also ends after the step whose path parameter reaches
``s_end`` (the flight's last cycle flown), and at an event. The same functions in the same order
give the Python loop's results bit for bit (tested).
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from .block_log import ALOG, N_COMMANDS
from .events import CODE
from .flight_log import track_error
from .glider_ledger import VALS, ledger_step
from . import kernel as ck  # its native JSBSim calls are read at compile time (ck.native_get)
from .kernel import COSIM, GS, HANDLES, cosim_step
from .. import slots
from ..autopilot.auto_step import GSO, MEM, OUT, PAR, auto_guide
from ..autopilot.attitude import attitude_from_row
from ..groundstation.lumped_forces import set_gust
from ..groundstation.station import command_values
from ..sixdof.attitude_law import N_LAW_PROPERTIES, law_refresh, law_stale
from ..sixdof.row import ROW, si_gust, si_position, si_velocity, si_wind
from ..jitcache import compiled_once, is_cached

#: the glider ledger's values per step
_N_VALS = slots.size(VALS)
#: ``ha`` (int64): the flight controls' setters (aileron, elevator, rudder, throttle, fold; 0: the
#: aircraft has none), the attitude law's getters (:data:`fdm_awe.sixdof.attitude_law.LAW_PROPERTIES`),
#: the ledger's (:data:`fdm_awe.sim.glider_ledger.LEDGER_PROPERTIES`), the ideal thrust's (0: none)
HA = slots.declare("AutoHandles", ("aileron", "elevator", "rudder", "throttle", "fold", ("law", N_LAW_PROPERTIES),
                                   ("ledger", _N_VALS), "ideal"))
#: ``q`` (float64): the flight's constants (raw row length, drum radius [m], the station's default
#: T2 duty and line resistance [ohm], the path parameter that ends the flight [s], the offsets of
#: the station's ledger energies in its state, the units' factors), the block's outcome (the
#: station has stepped, why the block ended) and a lumped line's gust (1.0: handed to the line
#: after every step, :meth:`AutopilotBlocks.set_line_gust`; the station's wind and the steady
#: wind the glider meets, m/s NED)
Q = slots.declare("AutoBlockConstants", ("nraw", "r_drum", "d2_default", "rl_default", "s_end", "ledger_load",
                                         "ledger_supply", "slug_ft2", "ft", "lbf", "gs_valid", "why", "gust_line",
                                         ("station_wind", 3), ("steady", 3)))
#: the length of ``gso`` (a constant numba compiles in)
GSO_SIZE = slots.size(GSO)
#: why a block ended (``q[Q.why]``): its steps done (or an event), the next step is the Python
#: autopilot's, the path parameter reached ``s_end``
WHY_DONE, WHY_PYTHON, WHY_END = 0, 1, 2


def keep_state(state: tuple, saved: np.ndarray, back: bool) -> None:
    """The AUTO step's ``state`` (its arrays, :func:`fdm_awe.autopilot.auto_step.auto_guide`) into
    ``saved`` one after the other, or (``back``) from ``saved`` back into them."""
    at = 0
    for a in state:
        k = a.shape[0]
        if back:
            a[:] = saved[at:at + k]
        else:
            saved[at:at + k] = a
        at += k


def hand_gust(q, c_gs, r, scale):
    """With ``q[Q.gust_line]`` set: the gust the glider meets in row ``r`` (:func:`fdm_awe.sixdof.row.si_gust`
    less the steady wind ``q[Q.steady]``) into the lumped line's constants ``c_gs``
    (:func:`fdm_awe.groundstation.lumped_forces.set_gust` with the station's wind ``q[Q.station_wind]``),
    as a flight's step hook hands it over (a gust that is not finite leaves them)."""
    if q[Q.gust_line] != 0.0:
        gn, ge, gd = si_gust(r, scale, q[Q.steady], q[Q.steady + 1], q[Q.steady + 2])
        if math.isfinite(gn + ge + gd):
            set_gust(c_gs, q[Q.station_wind], q[Q.station_wind + 1], q[Q.station_wind + 2], gn, ge, gd)


def book_reference(al, out, r, scale, offset):
    """The reference point flown, its cycle and the tracking error of row ``r`` into the
    bookkeeping row ``al`` (the AUTO step's results ``out``)."""
    rx, ry, rz = out[OUT.rx], out[OUT.ry], out[OUT.rz]
    x, y, z = si_position(r, scale, offset)
    al[ALOG.ref_x], al[ALOG.ref_y], al[ALOG.ref_z], al[ALOG.cycle] = rx, ry, rz, out[OUT.cycle]
    al[ALOG.track_error] = track_error(rx, ry, rz, x, y, z)


# one flight step written out in the order of the Python loop (module doc), with the block's
# exits between its parts
def autopilot_steps(cosim, k0, n, ha, q, scale, offset, cycle, consts, state, results, law, ledger, alog):
    """Up to ``n`` steps from row ``k0`` (``cosim``: the arrays of
    :func:`fdm_awe.sim.kernel.cosim_steps` before its ``k0``; the handles ``ha``, the constants
    ``q``, the raw row's SI ``scale`` and ``offset``; the AUTO step's ``cycle``, ``consts``,
    ``state``, ``results`` and the attitude law's arrays ``law`` of
    :meth:`fdm_awe.autopilot.autopilot.Autopilot.kernel_arrays`; the glider's ledger ``(work,
    v_prev)``, the bookkeeping rows ``alog``): (steps done, event code); ``q[Q.why]`` says why."""
    h, p, lim, log, s_gs, c_gs = cosim
    law_c, law_g, law_fold_at, law_integ = law
    work, v_prev = ledger
    mem, par, out = state[0], consts[4], results[2]
    nraw = int(q[Q.nraw])
    g0 = h.shape[0] - HANDLES.getters  # first ground-station column of a log row
    f_get, f_set = h[HANDLES.get], h[HANDLES.set]
    gso = np.empty(GSO_SIZE)
    saved = np.empty(mem.shape[0] + state[1].shape[0] + state[2].shape[0] + state[3].shape[0])
    lvals = np.empty(_N_VALS)
    cvals = np.empty(N_LAW_PROPERTIES)
    k = k0
    code = CODE.none
    q[Q.why] = WHY_DONE
    while k < k0 + n:
        lr = log[k]
        row = lr[:nraw]
        gso[GSO.valid] = q[Q.gs_valid]
        gso[GSO.tension], gso[GSO.length], gso[GSO.slack] = lr[g0 + GS.tension], lr[g0 + GS.length], lr[g0 + GS.slack]
        gso[GSO.force], gso[GSO.force + 1], gso[GSO.force + 2] = lr[g0 + GS.fx], lr[g0 + GS.fy], lr[g0 + GS.fz]
        # the step's state, to be restored when the Python autopilot must fly it
        keep_state(state, saved, False)
        flags = auto_guide(row, scale, offset, gso, cycle, consts, state, results)
        ok, motor, omega_ref, duty, d2, rl = command_values(out[OUT.w_motor], out[OUT.w_reel_speed], out[OUT.w_rl],
                                                            out[OUT.w_d2], math.nan, q[Q.r_drum], q[Q.d2_default],
                                                            q[Q.rl_default])
        if flags != 0 or not ok:
            # a phase change or a rejoin's end (the autopilot notes them), a command the ground
            # station refuses (the Python path raises its error): the Python autopilot flies it
            keep_state(state, saved, True)
            q[Q.why] = WHY_PYTHON
            break
        fold = row[ROW.fold]
        if law_stale(fold, law_fold_at[0]):  # the law's derivatives at the new fold state
            for j in range(N_LAW_PROPERTIES):
                cvals[j] = ck.native_get(f_get, ha[HA.law + j])
            law_refresh(cvals, law_c, q[Q.slug_ft2], True)
            law_fold_at[0] = fold
        a, e, r = attitude_from_row(row, scale, out[OUT.alpha], out[OUT.roll], mem[MEM.dt], law_c, law_g,
                                    par[PAR.g_att], law_integ)
        thr, fc = out[OUT.throttle], out[OUT.fold]
        ck.native_set(f_set, ha[HA.aileron], a)
        ck.native_set(f_set, ha[HA.elevator], e)
        ck.native_set(f_set, ha[HA.rudder], r)
        ck.native_set(f_set, ha[HA.throttle], thr)
        if ha[HA.fold] != 0:
            ck.native_set(f_set, ha[HA.fold], fc)
        p[COSIM.motor], p[COSIM.wref], p[COSIM.duty] = 1.0 if motor else 0.0, omega_ref, duty
        p[COSIM.d2], p[COSIM.rl] = d2, rl
        code = cosim_step(h, p, lim, log, s_gs, c_gs, k)
        if code == CODE.hook_rejected or code == CODE.nonfinite_force:
            break  # the step was not done
        k += 1
        q[Q.gs_valid] = 1.0
        nr = log[k]
        for j in range(_N_VALS):
            lvals[j] = ck.native_get(f_get, ha[HA.ledger + j])
        ideal = ck.native_get(f_get, ha[HA.ideal]) if ha[HA.ideal] != 0 else 0.0
        ledger_step(lvals, ideal, work, v_prev, p[COSIM.dt], q[Q.ft], q[Q.lbf])
        hand_gust(q, c_gs, nr, scale)  # a lumped line's gust of the next step
        al = alog[k]
        al[ALOG.aileron], al[ALOG.elevator], al[ALOG.rudder], al[ALOG.throttle], al[ALOG.fold_cmd] = a, e, r, thr, fc
        book_reference(al, out, nr, scale, offset)
        al[ALOG.e_load], al[ALOG.e_supply] = s_gs[int(q[Q.ledger_load])], s_gs[int(q[Q.ledger_supply])]
        al[ALOG.mass_slug] = lvals[VALS.mass]
        if code != CODE.none:
            break
        if mem[MEM.sref] >= q[Q.s_end]:
            q[Q.why] = WHY_END
            break
    return k - k0, code


def _kernel_parts() -> tuple[tuple, tuple]:
    """(the functions compiled into :func:`autopilot_steps`, the source files of everything
    compiled into it: numba's cache checks only this file)."""
    from ..autopilot import attitude, auto_step, fold, guidance, motor, rejoin, thrust, underspeed, winch
    from ..definitions import aircraft
    from ..groundstation import linemodels, station
    from ..pointmass import aero
    from ..pointmass import fold as pm_fold
    from ..sixdof import attitude_law, native, row
    from ..trajectory import sampler
    from . import block_log, events, flight_log, glider_ledger, kernel

    helpers = linemodels.kernel_called() + auto_step.CALLED + attitude.CALLED + (
        attitude_from_row, row.hook_kinematics, events.step_event, kernel.cosim_step, ledger_step, law_refresh,
        law_stale, command_values, track_error, keep_state, si_velocity, si_wind, si_gust, set_gust, hand_gust,
        book_reference)
    modules = (block_log, events, flight_log, glider_ledger, kernel, attitude, auto_step, fold, guidance, motor, rejoin,
               thrust, underspeed, aircraft, winch, station, aero, pm_fold, attitude_law, native, row,
               sampler) + linemodels.kernel_sources()
    return helpers, modules


def kernel_cached() -> bool | None:
    """Whether :func:`compiled_autopilot_kernel` would load the kernel from numba's on-disk
    cache (:func:`fdm_awe.jitcache.is_cached`): nothing compiles."""
    return is_cached(autopilot_steps, _kernel_parts()[1])


@compiled_once
def compiled_autopilot_kernel() -> Callable | None:
    """:func:`autopilot_steps` compiled by numba, or None (numba or the compiled co-simulation
    step missing, ``FDM_AWE_JIT=0``)."""
    if ck.compiled_kernel() is None:  # also fetches the native calls the kernel reads
        return None
    from ..jitcache import compile_cached

    def signature(nb: Any) -> Any:
        f8, i8, t = nb.float64, nb.int64, nb.types
        a1, a2, i1 = f8[::1], f8[:, ::1], i8[::1]
        cosim = t.Tuple((i1, a1, a1, a2, a1, a1))
        return t.UniTuple(i8, 2)(cosim, i8, i8, i1, a1, a1, a1, t.Tuple((a1, a2, a2)), t.UniTuple(a1, 5),
                                 t.UniTuple(a1, 4), t.UniTuple(a1, 3), t.UniTuple(a1, 4), t.UniTuple(a1, 2), a2)

    helpers, modules = _kernel_parts()
    return compile_cached(autopilot_steps, signature, helpers, modules, "fdm_awe.sim.autopilot_kernel")

#: the flight controls the autopilot sets (the fold's only on the foldable aircraft)
FCS_SETTERS = ("fcs/aileron-cmd-norm", "fcs/elevator-cmd-norm", "fcs/rudder-cmd-norm", "fcs/throttle-cmd-norm[0]",
               "fcs/wing-fold-cmd-norm")


class AutopilotBlocks:
    """The block runner of :class:`fdm_awe.sim.loop.CoSim` (its ``block_runner``) for a flight
    with the autopilot: blocks of :func:`autopilot_steps` whenever the autopilot can fly
    compiled (:meth:`fdm_awe.autopilot.autopilot.Autopilot.kernel_arrays`), the glider's ledger
    ``ledger`` advanced in place, ``after(k0, k1, state, gs_output)`` the flight's bookkeeping of
    the block's rows (:attr:`alog`; true ends the flight). Build it with :meth:`create`."""

    def __init__(self, call: Callable, ap: Any, ha: np.ndarray, q: np.ndarray, ledger: Any,
                 after: Callable[[int, int, Any, Any], bool]) -> None:
        self._call, self.ap, self.ha, self.q, self.ledger, self._after = call, ap, ha, q, ledger, after
        scale, offset = ap.glider.si_factors()
        self.scale, self.offset = np.array(scale, float), np.array(offset, float)
        #: the bookkeeping rows of the flight (:data:`fdm_awe.sim.block_log.ALOG`), grown with the log
        self.alog = np.full((1, slots.size(ALOG)), math.nan)
        self.steps = 0  #: steps flown in compiled blocks so far
        self._log: np.ndarray | None = None  # the loop's log of the last block

    @classmethod
    def create(cls, sim: Any, ap: Any, ledger: Any, after: Callable[[int, int, Any, Any], bool],
               s_end: float) -> "AutopilotBlocks | None":
        """The runner of ``sim`` flown by ``ap`` up to path parameter ``s_end`` [s] (inf: no
        end), or None where it cannot run (the Python loop chosen, numba or the native JSBSim
        calls missing, a ground station without the compiled step)."""
        if sim.compiled is False:
            return None
        glider, gs = sim.glider, sim.gs
        if not (hasattr(gs, "command_defaults") and hasattr(glider, "native_handles")):
            return None
        if glider.native_handles()[0] is None:
            return None
        kern = compiled_autopilot_kernel()
        if kern is None:
            return None
        from ..groundstation.ledger import FIELDS
        from ..sixdof.attitude_law import LAW_PROPERTIES
        from ..sixdof.native import native_jsbsim
        from ..units import FT, LBF, SLUG_FT2
        from .glider_ledger import IDEAL_THRUST_PROPERTY, LEDGER_PROPERTIES

        setters = list(FCS_SETTERS if glider.foldable else FCS_SETTERS[:4])
        getters = list(LAW_PROPERTIES) + list(LEDGER_PROPERTIES) + [IDEAL_THRUST_PROPERTY if ledger.ideal_thrust else None]
        hn, _ = native_jsbsim(glider.fdm, getters, setters)
        if hn is None:
            return None
        ha = slots.new(HA, 0, np.int64)
        ha[:len(setters)] = hn.setters
        ha[HA.law:] = hn.getters
        r_drum, d2, rl = gs.command_defaults()
        base = gs.ledger_offset()
        q = slots.new(Q)
        q[Q.nraw], q[Q.r_drum], q[Q.d2_default], q[Q.rl_default], q[Q.s_end] = len(glider.raw()), r_drum, d2, rl, s_end
        q[Q.ledger_load], q[Q.ledger_supply] = base + FIELDS.index("load"), base + FIELDS.index("supply")
        q[Q.slug_ft2], q[Q.ft], q[Q.lbf] = SLUG_FT2, FT, LBF
        # the compiled function without numba's argument-type dispatch (its one signature)
        call = getattr(next(iter(kern.overloads.values()), None), "entry_point", kern)
        return cls(call, ap, ha, q, ledger, after)

    def run(self, k: int, m: int, log: np.ndarray, p: np.ndarray, lim: np.ndarray, s_gs: np.ndarray,
            c_gs: np.ndarray, h: np.ndarray, gs_ready: bool) -> tuple[int, int, bool] | None:
        """Up to ``m`` steps from row ``k`` of ``log`` (the compiled loop's arrays); None when the
        autopilot steps in Python now (before the ground station's first step too)."""
        arrays = self.ap.kernel_arrays() if gs_ready else None
        if arrays is None:
            return None
        if len(self.alog) < len(log):
            self.alog = np.concatenate((self.alog, np.full((len(log) - len(self.alog), slots.size(ALOG)), math.nan)))
        self.q[Q.gs_valid] = 1.0
        self._log = log
        done, code = self._call((h, p, lim, log, s_gs, c_gs), k, m, self.ha, self.q, self.scale, self.offset, *arrays,
                                (self.ledger.work_array, self.ledger.v_prev), self.alog)
        if done:
            self.steps += done
            self.ap.after_block(log[k + done, :int(self.q[Q.nraw])])
        return done, code, self.q[Q.why] == WHY_PYTHON

    def set_line_gust(self, station_wind: Any, steady: Any) -> None:
        """Hand a lumped line the gust the glider meets after every step, as a flight's step hook
        does (:meth:`fdm_awe.groundstation.station.GroundStation.set_line_wind` with a uniform
        profile): the station's wind ``station_wind`` and the steady wind ``steady`` the glider
        meets (m/s NED)."""
        self.q[Q.gust_line] = 1.0
        self.q[Q.station_wind:Q.station_wind + 3] = station_wind
        self.q[Q.steady:Q.steady + 3] = steady

    def set_s_end(self, s_end: float) -> None:
        """The path parameter [s] after whose step a block ends (the flight's last cycle flown)."""
        self.q[Q.s_end] = s_end

    def raw_rows(self, k0: int, k1: int) -> np.ndarray:
        """The glider's raw rows ``k0 + 1 .. k1`` of the last block (:mod:`fdm_awe.sixdof.row`)."""
        return self._log[k0 + 1: k1 + 1, :int(self.q[Q.nraw])]

    def commands(self, k0: int, k1: int) -> list:
        """The five commands of rows ``k0 + 1 .. k1`` (lists)."""
        return self.alog[k0 + 1: k1 + 1, :N_COMMANDS].tolist()

    def after(self, k0: int, k1: int, s: Any, gs_out: Any) -> bool:
        """The flight's bookkeeping of rows ``k0 + 1 .. k1``; true ends the flight."""
        return self._after(k0, k1, s, gs_out)
