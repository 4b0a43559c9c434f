"""A whole flight: the 6-DOF glider, the ground station and the autopilot flying the optimised
pumping cycle for N cycles, with per-cycle energies, tracking errors and an energy ledger.

Plants (``plant``): ``physical`` = the JSBSim propeller and the ground station of
:mod:`fdm_awe.groundstation`; ``paper`` = the ideal thruster and the kinematic winch of
:mod:`fdm_awe.sim.paper_plant`, faithful to the ``paper`` scenario's simplifications.

Energy terms per cycle (J, all >= 0 except ``E_net_J``), counted as the plant's scenario
counts them. Physical plant, electrically: ``E_generated_J`` into the load resistor,
``E_thrust_J`` drawn by the glider's motor (its electrical input plus the constant P0 of
ESC and avionics that the optimiser's propulsion model also books), ``E_reel_in_J`` drawn
from the ground station's supply. Paper plant: ``E_generated_J`` = mechanical tension x reel speed in generation,
``E_thrust_J`` = the paper's P(T) fit of the commanded thrust, ``E_reel_in_J`` = the constant
reel-in power x recovery time. ``E_net_J = E_generated_J - E_thrust_J - E_reel_in_J``.

Status (``FlightReport.status``, :data:`~fdm_awe.sim.report.FLIGHT_STATUSES`):

- ``ok``: every requested cycle was flown to its end (with ``t_end`` given: the flight reached
  ``t_end`` without an event; its length, not a cycle count, was asked for);
- ``incomplete``: the time cap (``2 x cycles x period + 10 s``) ended the flight before all
  requested cycles were complete (e.g. a glider much slower than its reference);
- ``interrupted``: Ctrl-C (SIGINT / KeyboardInterrupt) during the flight; the report holds
  everything flown up to the last whole step;
- ``landed``: ground contact in RECOVER mode at the winch
  (:func:`~fdm_awe.sim.flight_outcome.landing_verdict`: sink rate at most
  :data:`~fdm_awe.sim.flight_outcome.LAND_SINK_MAX`, horizontal ground speed at most
  :data:`~fdm_awe.sim.flight_outcome.LAND_SPEED_MAX`, within
  :data:`~fdm_awe.sim.flight_outcome.LAND_RADIUS_MAX` of the winch); ground contact in RECOVER
  outside these bounds is a ``ground_contact`` (a crash), its message says which bound it broke;
- ``parked``: the flight reached ``t_end`` (or its time cap, e.g. after a failsafe) in RECOVER
  holding on a short line (the autopilot's
  :attr:`~fdm_awe.autopilot.recover_mode.RecoverMode.parked`: REC_LAND 0 or gusts, circling at
  REC_HOLD_ALT about the winch);
- an event of the co-simulation (:data:`fdm_awe.sim.result.STATUSES`: ``ground_contact``,
  ``tether_break``, ``nonfinite``, ``airspeed_limit``, ``load_limit``) or another
  ground-station event by name (e.g. ``tether_fully_reeled_in``).

Cycles (:func:`~fdm_awe.sim.cycles.segment_cycles`): every step is labelled with the cycle index
of the reference point the autopilot flew it on (none outside AUTO cycling) and with the autopilot's phase
(generation, recovery, or other). A cycle runs from its first step to the step before the next
cycle's first step, or to the end of the flight; its ``T1_s``/``T2_s`` are the times flown in
generation/recovery, its energies the changes of the cumulative energies over its steps (each
booked where and when it happened, so they keep their signs). A cycle is ``complete`` when the
autopilot went on to the next cycle; one cut off by the time cap, an event or Ctrl-C, in
either phase, is reported with ``complete`` false.

Energy ledger (whole flight): the glider's translational kinetic + potential energy change
equals the work of the aerodynamic, propeller, tether and ground forces on it (read from
JSBSim's force breakdown, work = force . velocity integrated by the trapezoidal rule; the
paper plant's ideal thrust is split off JSBSim's external forces as thrust work); the
ground station keeps its own ledger from the line end to the electrical terminals. The
residual of each, relative to the largest term, is reported (``ledger_residual_rel`` is the
larger of the two).

Modules: this one flies the plant and books every step; the plant is built by
:mod:`fdm_awe.sim.flight_rig`, the outcome (status, ledger) booked by :mod:`fdm_awe.sim.flight_outcome`;
the report's dataclasses are
:mod:`fdm_awe.sim.report`, the cycles' segmentation :mod:`fdm_awe.sim.cycles`, the glider's
ledger :mod:`fdm_awe.sim.glider_ledger`, the per-step bookkeeping :mod:`fdm_awe.sim.flight_log`.
"""


from __future__ import annotations

import math
import signal
import threading
import time
from dataclasses import dataclass
from typing import Any, Callable

from ..autopilot.autopilot import Autopilot
from ..autopilot.config import autopilot_params
from ..autopilot.schedule import ReferenceSet, ScheduledReference
from ..autopilot.shaping import flyable_reference
from ..definitions.catalog import resolve_aircraft
from ..groundstation.linemodels import TetherModel, parse_tether
from ..groundstation.tether import check_tether_drag_scale
from ..jitcache import jit_off
from ..sixdof.row import si_gust
from ..turbulence import Turbulence, TurbulenceSetting, measure
from ..wind import line_height
from .activity import control_activity
from .budget import check_length, check_step, time_cap
from .cycles import cycle_metrics, segment_cycles
from .events import machine_current
from .flight_log import FlightLog
from .flight_outcome import flight_ledger, flight_status, thrust_energy
from .flight_rig import FlightWind, Rig, build_rig, station_params, turbulence_setting
from .glider_ledger import GliderLedger
from .result import FlightResult
from .loop import CoSim
from .onboard_wind import CycleWind, note_text
from .resume import HoldWatch, failsafe_wind, lost_path
from .paper_plant import PLANTS
from .report import FlightReport




class _StopRequest:
    """Ctrl-C during a flight, taken at a step boundary.

    Within ``with``, in the main thread and where SIGINT would raise KeyboardInterrupt (the
    default handler), the first SIGINT only sets :attr:`requested`; the flight loop ends after
    the step in progress is booked. A second SIGINT raises KeyboardInterrupt at once (the
    co-simulation catches it and keeps the steps flown). The previous handler is restored on
    exit. Elsewhere (another thread, a handler of the caller's) nothing is installed and a
    KeyboardInterrupt is caught by the co-simulation loop as usual."""

    def __init__(self) -> None:
        self.requested = False
        self._previous: Any = None

    def _handler(self, signum: int, frame: Any) -> None:
        if self.requested:
            raise KeyboardInterrupt
        self.requested = True

    def __enter__(self) -> "_StopRequest":
        if threading.current_thread() is threading.main_thread() and \
                signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            self._previous = signal.signal(signal.SIGINT, self._handler)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)
            self._previous = None



def fly(
    reference: Any,
    config: str = "foldable",
    cycles: int = 3,
    dt: float = 1.0 / 120.0,
    turbulence: Turbulence | tuple[str, int] | None = None,
    on_step: Callable[[int, Any, Any], bool | None] | None = None,
    params: Any = None,
    setup: Callable[[Any, Any], None] | None = None,
    t_end: float | None = None,
    plant: str = "physical",
    tether_drag_scale: float = 1.0,
    tether: TetherModel | str = "straight",
    references: ReferenceSet | None = None,
    flight_wind: dict[str, Any] | None = None,
    aircraft: Any = None, ground_station: Any = None,
) -> FlightReport:
    """Fly ``cycles`` pumping cycles of ``reference`` (a :class:`~.autopilot.tracking.TrackingReference`).

    ``setup(autopilot, cosim)`` is called before the run (e.g. to attach a MAVLink endpoint);
    ``on_step(k, state, gs_output)`` after every step; a true return ends the flight there
    (status ``ok``, as the end of the reference would). ``t_end`` overrides the flight length.
    ``plant``: ``"physical"`` (JSBSim propeller + ground station) or ``"paper"`` (ideal thruster +
    kinematic winch, :mod:`fdm_awe.sim.paper_plant`). ``tether_drag_scale`` (-, 0 .. 10, default 1 =
    the defined line) scales the ground station's line drag on the glider, as
    ``CycleProblem.tether_drag_scale`` scales the optimiser's (the paper plant's ideal line has no drag).
    ``tether``: the ground station's line model, a :class:`~fdm_awe.groundstation.linemodels.TetherModel`
    (``--tether`` parsed once by :func:`~fdm_awe.groundstation.linemodels.parse_tether`) or its
    form: ``"straight"`` (default), ``"lumped:N"`` (:mod:`fdm_awe.groundstation.lumped`; its shape is
    sampled into the report's ``line_shape`` and its own ledger into ``ledger``) or another entry of
    :data:`~fdm_awe.groundstation.linemodels.LINE_MODELS`. ``turbulence``: None, a named level's ``(level, seed)``
    or a :class:`~fdm_awe.turbulence.Turbulence` form, realised in the reference's wind with
    the cycle's mean height as hub height; the report's ``turbulence`` holds its parameters,
    targets and the turbulence the glider met (:func:`fdm_awe.turbulence.measure`).
    The line is the one named by the reference metadata's ``line`` (:data:`fdm_awe.groundstation.line.LINES`);
    a reference without it flies Table 1's line (``paper``), that of every reference written before lines were named.

    The onboard wind estimate (:mod:`fdm_awe.sim.onboard_wind`) runs at every cycle boundary and
    is reported per cycle (``FlightReport.wind_estimates``). ``references``: a reference set
    (:class:`~fdm_awe.autopilot.schedule.ReferenceSet`, ``reference`` one of its members, flown
    first): at each cycle boundary the autopilot takes the set's reference nearest the estimated
    wind. ``flight_wind``: the wind the flight meets, as reference metadata gives it
    (``wind_ned_mps`` at the height of ``wind_profile``); None: the reference's own.

    A step the autopilot's attitude loops cannot fly with, or a flight whose time cap (or ``t_end``) holds
    more steps than a flight keeps in memory, is refused with an InputError before JSBSim loads (:mod:`.budget`).

    Ctrl-C (SIGINT, or a KeyboardInterrupt raised in ``on_step``) ends the flight and returns
    a normal report with status ``interrupted`` holding everything flown so far (see
    :class:`_StopRequest`); a KeyboardInterrupt in ``setup`` propagates (nothing was flown).

    ``aircraft``: the glider flown (:func:`~fdm_awe.definitions.catalog.resolve_aircraft`: a
    table name, a definition folder or an :class:`~fdm_awe.definitions.catalog.Aircraft`;
    None: the package's glider): its JSBSim root and morphing aircraft, its point-mass forms and
    its autopilot definition (``params`` None: that definition's defaults). ``ground_station``: the
    station flown (a definition file or :class:`~fdm_awe.groundstation.source.StationFile`; None: the package's).
    """
    if plant not in PLANTS:
        raise ValueError(f"plant {plant!r} unknown (allowed: {', '.join(PLANTS)})")
    tether_drag_scale = check_tether_drag_scale(tether_drag_scale)  # also for the paper plant (no station)
    paper = plant == "paper"
    model = parse_tether(tether).check_plant(paper)  # e.g. a lumped line only on the physical plant
    shape = model.has_shape  # a line with nodes: its shape sampled, its own ledger booked
    refs, current = _flyable_set(references, reference)
    reference = flyable_reference(reference) if refs is None else refs.entries[current].reference
    period = reference.period if refs is None else refs.longest_period
    aircraft = resolve_aircraft(aircraft, "aircraft")
    params = params if params is not None else autopilot_params(aircraft.autopilot_file)
    check_step(dt, params, "dt")  # the attitude loops fly with it (budget)
    check_length(cycles, period, dt, t_end, "cycles")  # the flight's steps fit in memory (budget)
    meta = reference.meta
    wind = FlightWind(meta if flight_wind is None else flight_wind)
    station, gsp = station_params(meta, paper, ground_station)
    turb = turbulence_setting(reference, turbulence, flight_wind)
    rig = build_rig(reference, wind, gsp, config, dt, turb, params, paper, tether_drag_scale, model, aircraft)
    if setup is not None:
        setup(rig.ap, rig.sim)
    gl = GliderLedger(rig.glider, ideal_thrust=paper)
    # cycles are counted by the autopilot's path parameter (the glider's own period); the
    # flight ends when the last cycle is flown, or at a generous time cap
    T_total = t_end if t_end is not None else time_cap(cycles, period)
    log = FlightLog(int(round(T_total / dt)), dt, rig, gl, shape)
    stop = _StopRequest()
    flown = [False]  # whether every requested cycle was flown
    # the path parameter at which the flight ends (a reference switch moves it to the new period)
    s_end = [math.inf if t_end is not None else cycles * reference.period]
    cw = CycleWind(rig.glider, dt, wind.profile if refs is None else refs.profile, refs, current)
    hook = _step_hook(rig, wind, log, stop, flown, on_step, s_end, cw, HoldWatch(rig.glider, dt, cw.profile, cw),
                      gust_on_line=turb is not None and not paper and shape)
    if on_step is None and not paper and wind.profile.uniform:
        # no per-step work in Python (a line's gust: the blocks hand it over): the autopilot may fly blocks compiled
        rig.sim.block_runner = _blocks(rig, gl, log, stop, flown, s_end, cw, wind if shape and turb is not None else None)
    rig.ap.on_cycle = _cycle_boundary(rig, cw, s_end, cycles)
    res, wall, interrupted = _run(rig.sim, T_total, hook, stop, log)
    setup_ = _Setup(meta, flight_wind, wind, config, plant, paper, dt, shape, cycles, t_end, T_total,
                    float(tether_drag_scale), model, turb, aircraft, station, gsp)
    return _report(rig, res, wall, interrupted, log, gl, cw, flown[0], setup_)


@dataclass(frozen=True)
class _Setup:
    """What :func:`fly` set up, for its report (:func:`_report`)."""

    meta: dict[str, Any]
    flight_wind: dict[str, Any] | None
    wind: FlightWind
    config: str
    plant: str
    paper: bool
    dt: float
    shape: bool
    cycles: int
    t_end: float | None
    T_total: float
    tether_drag_scale: float
    model: TetherModel
    turb: TurbulenceSetting | None
    aircraft: Any
    station: Any
    gsp: Any


def _report(rig: Rig, res: FlightResult, wall: float, interrupted: bool, log: FlightLog, gl: GliderLedger,
            cw: CycleWind, flown: bool, su: _Setup) -> FlightReport:
    """The flight's report from its result ``res`` (``wall`` s, ``interrupted`` by Ctrl-C), log,
    glider ledger, cycle winds, whether every requested cycle was ``flown``, and its setup."""
    meta, flight_wind, wind, paper, dt, shape = su.meta, su.flight_wind, su.wind, su.paper, su.dt, su.shape
    cycles, t_end, T_total, gsp = su.cycles, su.t_end, su.T_total, su.gsp
    k_end = res.steps
    e_thrust = thrust_energy(res, log, rig, paper, dt)
    ap = rig.ap
    reached = ap.cycle if ap.mode == "AUTO" and ap.cycling else None
    spans = segment_cycles(log.cycle[: k_end + 1], log.phase[: k_end + 1], reached)
    mets = cycle_metrics(spans, dt, log.e_load[: k_end + 1], e_thrust, log.e_supply[: k_end + 1], log.err[: k_end + 1])
    if mets:  # the last cycle's wind, from its rows so far
        cw.close(mets[-1].index, float(res.t[-1]), mets[-1].complete)
    ledger, rel = flight_ledger(gl, rig.gs, float(e_thrust[k_end]), shape)
    status, msg = flight_status(res, ap, interrupted, flown or t_end is not None, T_total, cycles, mets)
    if ap.mode == "RECOVER" and lost_path(ap.recover_cause):
        msg += failsafe_wind(res, ap, cw.profile, dt)
    m = gsp.machine  # the armature current against the machine's ratings (the paper plant's winch has none)
    i_pk, above, rated = (None, None, []) if paper else machine_current(res.t, res.current, m.rated_current,
                                                                          m.peak_current)
    notes = sorted(list(ap.log) + rated, key=lambda e: e[0])  # the autopilot's and the logged events
    line = meta.get("line")
    return FlightReport(
        scenario=str(meta.get("scenario", "custom")), config=su.config,
        wind_mps=float((meta if flight_wind is None else flight_wind).get("wind_mps",
                                                                          math.hypot(wind.ned[0], wind.ned[1]))),
        status=status, message=msg, sim_time_s=float(res.t[-1] - res.t[0]), wall_s=wall, cycles=mets, ledger=ledger,
        ledger_residual_rel=rel, result=res, track_error=log.err[: k_end + 1], reference_pos=log.refpos[: k_end + 1],
        autopilot_log=notes, plant=su.plant, tether_drag_scale=su.tether_drag_scale, tether=str(su.model),
        line="paper" if line is None else str(line), generator=None if paper else str(meta.get("generator") or "passive"),
        line_shape=log.line_shape(), peak_current_A=i_pk, time_above_rated_current_s=above,
        control_activity=control_activity(*res.controls[:, :3].T, dt), loop=_loop_facts(rig.sim, res.steps),
        turbulence=_turbulence_facts(su.turb, wind, res),
        wind_estimates=list(cw.records),
        recover_cause=ap.recover_cause if ap.mode == "RECOVER" else None,
        cycle_index=log.cycle[: k_end + 1].copy(),
        aircraft={**su.aircraft.record(), "mass_kg": float(rig.airframes.unfolded.mass.mass)},
        ground_station=su.station.record(),
    )


def _turbulence_facts(turb: TurbulenceSetting | None, wind: FlightWind, res: FlightResult) -> dict[str, Any] | None:
    """The report's ``turbulence`` (None in calm air): the form's parameters and targets
    (:meth:`~fdm_awe.turbulence.TurbulenceSetting.as_dict`) and ``measured``, the turbulence of
    the wind the glider met over the flight (:func:`~fdm_awe.turbulence.measure`)."""
    if turb is None:
        return None
    d = turb.as_dict()
    d["measured"] = measure(res.t, res.wind, wind.given(-res.pos[:, 2]), wind.ned[:2])
    return d


def _flyable_set(references: ReferenceSet | None, reference: Any) -> tuple[ReferenceSet | None, int]:
    """The reference set with its references made flyable (:func:`flyable_reference`) and the
    index of ``reference`` in it (a member, or the one of its wind); (None, 0) without a set."""
    if references is None:
        return None, 0
    refs = ReferenceSet([ScheduledReference(e.wind_mps, flyable_reference(e.reference), e.source)
                         for e in references.entries])
    mine = [i for i, e in enumerate(references.entries) if e.reference is reference]
    w = float(reference.meta.get("wind_mps", math.nan))
    return refs, mine[0] if mine else refs.nearest(w)


def _cycle_boundary(rig: Rig, cw: CycleWind, s_end: list[float], cycles: int) -> Callable[[int, float], Any]:
    """The autopilot's ``on_cycle`` of a flight: the wind of the cycle just flown estimated,
    noted and recorded (``cw``); with a reference set, the reference of the next cycle (the
    flight's end ``s_end[0]`` [s] then moves to ``cycles`` of its period)."""
    ap = rig.ap

    def on_cycle(cycle: int, t: float) -> Any:
        rec = cw.close(cycle - 1, t)
        if rec is None:
            return None
        ap.wind_estimate = cw.last
        ap.log.append((t, note_text(rec)))
        new = cw.next_reference(cw.last)
        if new is not None and s_end[0] < math.inf:
            s_end[0] = cycles * new.period
            runner = rig.sim.block_runner
            if runner is not None:
                runner.set_s_end(s_end[0])
        return new

    return on_cycle


def _loop_facts(sim: CoSim, steps: int) -> dict[str, Any]:
    """How a flight's steps ran (:attr:`FlightReport.loop`)."""
    runner = sim.block_runner
    compiled = 0 if runner is None else int(runner.steps)
    return {"loop": sim.loop, "reason": sim.loop_reason, "autopilot_compiled_steps": compiled,
            "autopilot_python_steps": int(steps) - compiled}


def _step_hook(rig: Rig, wind: FlightWind, log: FlightLog, stop: _StopRequest, flown: list[bool],
               on_step: Callable[[int, Any, Any], bool | None] | None, s_end: list[float], cw: CycleWind,
               watch: HoldWatch, gust_on_line: bool) -> Callable[[int, Any, Any], bool]:
    """The co-simulation's ``on_step`` of a flight: the next step's wind at the glider's (and
    the line's) height, the step's bookkeeping, the caller's ``on_step``, and the flight's end
    (the caller's, the path parameter at ``s_end[0]`` [s] in AUTO, which sets ``flown[0]``, or a
    stop request; inf: the flight runs its whole length). A step flown in AUTO cycling is kept
    for the cycle's wind estimate (``cw``); one held after a lost path, for the wind's return (``watch``)."""
    glider, gs, ap = rig.glider, rig.gs, rig.ap
    profile = wind.profile
    wind_at = wind.at

    def hook(k: int, s: Any, o: Any) -> bool:
        h = -float(s.pos_ned[2])
        if not profile.uniform:  # the next step's wind at the glider's (and the line's) height
            glider.set_wind(wind_at(h))
            gs.set_wind(wind_at(line_height(h)))
        if gust_on_line:  # the lumped line: the gust the glider meets now, uniform along the line
            gs.set_line_wind(profile, wind.ned[:2], si_gust(s.raw, s.scale, *wind_at(h)))
        log.book(k, s)
        if ap.mode == "AUTO" and ap.cycling:
            cw.add(k, s.raw)
        else:
            watch.step(k, s.t, s.raw, ap)
        if on_step is not None and on_step(k, s, o):
            return True  # the caller ends the flight here
        return _flight_ends(ap, s_end, flown, stop)

    return hook


def _flight_ends(ap: Autopilot, s_end: list[float], flown: list[bool], stop: _StopRequest) -> bool:
    """Whether the flight ends after the step just booked: the path parameter at ``s_end[0]`` [s]
    in AUTO (every cycle flown: sets ``flown[0]``), or a stop request."""
    if ap.mode == "AUTO" and ap.s_ref >= s_end[0]:
        flown[0] = True
        return True
    return stop.requested


def _blocks(rig: Rig, gl: GliderLedger, log: FlightLog, stop: _StopRequest, flown: list[bool],
            s_end: list[float], cw: CycleWind, gust_wind: FlightWind | None = None) -> Any:
    """The co-simulation's block runner of a flight (:class:`fdm_awe.sim.autopilot_kernel.AutopilotBlocks`:
    the autopilot's AUTO steps and their bookkeeping compiled), or None where it cannot run
    (no numba, no native JSBSim calls, ``FDM_AWE_JIT=0``, the Python loop chosen). A block's
    rows are booked (and kept for the cycle's wind estimate) as :func:`_step_hook` books a step,
    and the flight ends as it does there; with a line shape to sample, a block ends at each sample.
    ``gust_wind``: the flight's (uniform) wind when a lumped line meets turbulence: the blocks hand
    the line the gust the glider meets after every step, as :func:`_step_hook` does."""
    if jit_off() is not None:  # the Python path does not import numba
        return None
    from .autopilot_kernel import AutopilotBlocks

    ap = rig.ap

    def after(k0: int, k1: int, s: Any, o: Any) -> bool:
        log.book_block(k0, k1, runner.alog)
        cw.add_block(k0, runner.raw_rows(k0, k1))
        return _flight_ends(ap, s_end, flown, stop)

    runner = AutopilotBlocks.create(rig.sim, ap, gl, after, s_end[0])
    if runner is not None and gust_wind is not None:
        runner.set_line_gust(rig.gs.wind, gust_wind.at(0.0))
    if log.samples_shape:  # blocks end where the line's shape is sampled
        rig.sim.block_steps = log.shape_every
    return runner


def _run(sim: CoSim, T_total: float, hook: Callable[[int, Any, Any], bool], stop: _StopRequest,
         log: FlightLog) -> tuple[FlightResult, float, bool]:
    """Run ``sim`` for ``T_total`` [s] with ``hook`` after every step, Ctrl-C taken at a step
    boundary (``stop``); returns the result cut at the last step ``log`` booked whole, the wall
    time [s] and whether Ctrl-C ended the flight."""
    wall0 = time.perf_counter()
    with stop:
        res = sim.run(T_total, on_step=hook)
    wall = time.perf_counter() - wall0
    # Ctrl-C: taken at a step boundary (the loop ended "ok" on the request) or caught by the loop
    interrupted = res.status == "interrupted" or (stop.requested and res.status == "ok")
    if res.steps > log.booked:
        # Ctrl-C between a step and the end of its bookkeeping: the flight ends at the last
        # step that was booked whole
        res.truncate(log.booked)
    return res, wall, interrupted


__all__ = ["fly"]
