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
- ``landed``: ground contact in RECOVER mode at the winch (:func:`landing_verdict`: sink rate
  at most :data:`LAND_SINK_MAX`, horizontal ground speed at most :data:`LAND_SPEED_MAX`, within
  :data:`LAND_RADIUS_MAX` of the winch); ground contact in RECOVER outside these bounds is a
  ``ground_contact`` (a crash), its message says which bound it broke;
- ``parked``: the flight reached ``t_end`` (or its time cap, e.g. after a failsafe) in RECOVER
  holding on a short line (the autopilot's :attr:`~fdm_awe.autopilot.autopilot.Autopilot.parked`:
  REC_LAND 0 or gusts, circling at REC_HOLD_ALT about the winch);
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

Modules: this one builds the plant, flies it and books every step; the report's dataclasses are
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

import numpy as np

from ..autopilot.autopilot import Autopilot
from ..autopilot.config import autopilot_params
from ..autopilot.schedule import ReferenceSet, ScheduledReference
from ..autopilot.shaping import flyable_reference
from ..definitions.aircraft import Glider, load_glider
from ..definitions.catalog import Aircraft, resolve_aircraft
from ..errors import InputError
from ..groundstation import GroundStation, GroundStationParams
from ..groundstation.line import check_line
from ..groundstation.source import StationFile, resolve_ground_station
from ..groundstation.linemodels import TetherModel, parse_tether
from ..groundstation.steady import motor_max_reel_in_speed
from ..groundstation.tether import check_tether_drag_scale
from ..ocp.problem import Scenario
from ..sixdof import JSBSimGlider
from ..turbulence import Turbulence, TurbulenceSetting, mean_height, measure
from ..wind import WindProfile, line_height
from .activity import control_activity
from .budget import check_length, check_step, time_cap
from .cycles import cycle_metrics, segment_cycles
from .events import machine_current
from .flight_log import FlightLog
from .glider_ledger import GliderLedger
from .result import COLUMNS, FlightResult
from .loop import CoSim, Limits
from .onboard_wind import CycleWind, note_text
from .resume import HoldWatch, failsafe_wind, lost_path
from .propulsion import logged_propulsion
from .paper_plant import PLANTS, IdealThruster, IdealWinch
from .report import CycleMetrics, FlightReport


#: largest touchdown sink rate [m/s] of a landing (ground contact in RECOVER)
LAND_SINK_MAX = 1.5
#: largest horizontal ground speed [m/s] at touchdown of a landing
LAND_SPEED_MAX = 15.0
#: largest horizontal distance [m] of a landing's touchdown from the winch
LAND_RADIUS_MAX = 150.0


def landing_verdict(pos_ned: np.ndarray, vel_ned: np.ndarray) -> str | None:
    """None when a touchdown at ``pos_ned`` [m, NED from the winch] with ground velocity
    ``vel_ned`` [m/s] is a landing (sink <= LAND_SINK_MAX, horizontal speed <= LAND_SPEED_MAX,
    within LAND_RADIUS_MAX of the winch), else the bound it broke, as a phrase."""
    sink = float(vel_ned[2])
    speed = math.hypot(float(vel_ned[0]), float(vel_ned[1]))
    dist = math.hypot(float(pos_ned[0]), float(pos_ned[1]))
    if sink > LAND_SINK_MAX:
        return f"sink {sink:.1f} m/s above {LAND_SINK_MAX:g} m/s"
    if speed > LAND_SPEED_MAX:
        return f"ground speed {speed:.1f} m/s above {LAND_SPEED_MAX:g} m/s"
    if dist > LAND_RADIUS_MAX:
        return f"{dist:.0f} m from the winch, beyond {LAND_RADIUS_MAX:g} m"
    return None


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


class _FlightWind:
    """The wind a reference was optimised in (metadata ``wind_ned_mps`` at the height of its
    ``wind_profile``; absent: uniform, no wind): JSBSim's steady wind follows the glider's
    altitude step by step, the ground station's line drag the wind at the line's height
    (:data:`fdm_awe.wind.LINE_HEIGHT_FRACTION` of the glider's), turbulence on top."""

    def __init__(self, meta: dict[str, Any]) -> None:
        #: the wind at the profile's reference height, NED [m/s]
        self.ned = tuple(float(v) for v in meta.get("wind_ned_mps", (0.0, 0.0, 0.0)))
        self.profile = WindProfile.from_dict(meta.get("wind_profile"), "reference metadata.wind_profile")

    def at(self, h: float) -> tuple[float, float, float]:
        """The steady wind at height ``h`` [m], NED [m/s]."""
        f = float(self.profile.factor(h))
        return (self.ned[0] * f, self.ned[1] * f, 0.0)

    def glider_start(self, h: float) -> tuple[float, float, float]:
        """The glider's wind at the start height ``h`` [m] (the reference wind when uniform)."""
        return self.ned if self.profile.uniform else self.at(h)

    def given(self, height: np.ndarray) -> np.ndarray:
        """The steady wind JSBSim was given for each logged row, NED [m/s] (n, 3), from the
        glider's logged heights ``height`` [m]: the start wind for the first row, then the wind
        at the height of the row before (:func:`_step_hook` sets the next step's wind)."""
        n = len(height)
        if self.profile.uniform:
            return np.tile(np.asarray(self.ned, float), (n, 1))
        out = np.empty((n, 3))
        if n:
            out[0] = self.glider_start(float(height[0]))
            for k in range(1, n):
                out[k] = self.at(float(height[k - 1]))
        return out


def turbulence_setting(reference: Any, turbulence: Turbulence | tuple[str, int] | None,
                       flight_wind: dict[str, Any] | None = None) -> TurbulenceSetting | None:
    """The turbulence of a flight of ``reference`` (a :class:`~fdm_awe.autopilot.tracking.TrackingReference`)
    realised in its wind (metadata ``wind_ned_mps`` and ``wind_profile``; :mod:`fdm_awe.turbulence`),
    the hub height the time-mean height of its cycle; None without turbulence. A form that
    cannot be realised there raises a one-line :class:`InputError` naming ``--turbulence``.
    ``flight_wind`` (reference-metadata form) is the wind the flight meets where it is not the
    reference's own (a reference set flown in another wind)."""
    form = Turbulence.of(turbulence)
    if form is None:
        return None
    wind = _FlightWind(reference.meta if flight_wind is None else flight_wind)
    hub = mean_height(reference.t, -reference.pos[:, 2])
    return form.setting(math.hypot(wind.ned[0], wind.ned[1]), wind.profile, hub)


def _station_params(meta: dict[str, Any], paper: bool, station: Any) -> tuple[StationFile, GroundStationParams]:
    """The ground station ``station`` (:func:`~fdm_awe.groundstation.source.resolve_ground_station`) and its
    definition with the line a reference (metadata ``meta``) was optimised with (none named: Table 1's,
    ``paper``, that of references written before lines were named). Read and checked before JSBSim loads."""
    line = meta.get("line")
    if not paper and meta.get("generator") == "ideal":
        raise InputError("reference metadata.generator: 'ideal' is the optimiser's upper bound (a loss-free converter "
                         "holding any tension), which no ground station realises; allowed passive, boost")
    st = resolve_ground_station(station, "ground_station")
    return st, st.load("paper" if line is None else check_line(line, "reference metadata.line"))


@dataclass
class _Rig:
    """The blocks of a flight, wired: glider, ground station (or the paper plant's winch),
    airframes, the paper plant's thruster (None on the physical plant), autopilot, co-simulation."""

    glider: JSBSimGlider
    gs: Any
    airframes: Glider
    thruster: IdealThruster | None
    ap: Autopilot
    sim: CoSim


def _rig(reference: Any, wind: _FlightWind, gsp: GroundStationParams, config: str, dt: float,
         turbulence: TurbulenceSetting | None, params: Any, paper: bool, tether_drag_scale: float,
         tether: TetherModel, aircraft: Aircraft) -> _Rig:
    """Build the plant (see :func:`fly`) of ``aircraft``, start it on the reference's first
    point and wire the autopilot and the co-simulation."""
    h0 = -float(reference.sample(0.0).pos[2])
    w0 = wind.glider_start(h0)
    glider = JSBSimGlider.of(aircraft, dt=dt, wind_ned=w0, turbulence=turbulence)
    airframes = load_glider(aircraft)
    if paper:
        gs = IdealWinch(gsp, P_rw=Scenario.named("paper").P_rw, wind_ned=w0)
    else:
        gs = GroundStation(gsp, wind_ned=w0 if wind.profile.uniform else wind.at(line_height(h0)),
                           tether_drag_scale=tether_drag_scale, tether=tether)
        gs.set_line_wind(wind.profile, wind.ned[:2])  # a line's nodes: the profile at their own heights
    _start_on_reference(glider, gs, reference.sample(0.0), w0, paper)
    ps = params if params is not None else autopilot_params(aircraft.autopilot_file)
    thruster = IdealThruster.for_glider(glider, airframes.unfolded.propulsion) if paper else None
    ap = Autopilot(glider, airframes, ps, reference, config=config, load_resistance=gsp.converter.load_resistance,
                   thruster=thruster, winch="ideal" if paper else "physical", line_EA=gsp.tether.axial_stiffness,
                   reel_in_max=math.inf if paper else motor_max_reel_in_speed(0.0, gsp))
    # the line's own breaking load ends a run as "tether_break" (ground-station event); the
    # co-simulation's tension limit sits just above it so it never pre-empts that event
    sim = CoSim(glider, gs, ap, dt=dt, limits=Limits(max_tension=1.01 * gsp.tether.breaking_load, grace_s=1.0))
    return _Rig(glider, gs, airframes, thruster, ap, sim)


def _start_on_reference(glider: JSBSimGlider, gs: Any, r0: Any, wind: tuple[float, float, float],
                        paper: bool) -> None:
    """Put the glider on the reference point ``r0`` (position, air velocity in ``wind`` [m/s],
    bank, angle of attack, wing open) and the line at its tension there."""
    va = r0.vel - np.asarray(wind)
    V = float(np.linalg.norm(va))
    gamma = -math.asin(max(-1.0, min(1.0, va[2] / V)))
    psi = math.atan2(va[1], va[0])
    glider.reset(r0.pos, V, gamma=gamma, psi=psi, phi=r0.phi, alpha=r0.alpha, fold=0.0)
    s0 = glider.state()
    # start on the reference: the line carries the reference tension at the start point
    d_start = float(np.linalg.norm(s0.hook_pos_ned))
    l_start = gs.unstretched_length(d_start, r0.tension)
    if paper:
        gs.reset(tether_length=l_start, reel_speed=max(r0.reel_speed, 0.0), mode="generator", distance=d_start)
    else:
        gs.reset(tether_length=l_start, reel_speed=max(r0.reel_speed, 0.0), mode="generator")


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
    wind = _FlightWind(meta if flight_wind is None else flight_wind)
    station, gsp = _station_params(meta, paper, ground_station)
    turb = turbulence_setting(reference, turbulence, flight_wind)
    rig = _rig(reference, wind, gsp, config, dt, turb, params, paper, tether_drag_scale, model, aircraft)
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
    if on_step is None and not paper and not shape and wind.profile.uniform:
        # no per-step work in Python: the autopilot may fly whole blocks compiled
        rig.sim.block_runner = _blocks(rig, gl, log, stop, flown, s_end, cw)
    rig.ap.on_cycle = _cycle_boundary(rig, cw, s_end, cycles)
    res, wall, interrupted = _run(rig.sim, T_total, hook, stop, log)
    k_end = res.steps
    e_thrust = _thrust_energy(res, log, rig, paper, dt)
    ap = rig.ap
    reached = ap.cycle if ap.mode == "AUTO" and ap.cycling else None
    spans = segment_cycles(log.cycle[: k_end + 1], log.phase[: k_end + 1], reached)
    mets = cycle_metrics(spans, dt, log.e_load[: k_end + 1], e_thrust, log.e_supply[: k_end + 1], log.err[: k_end + 1])
    if mets:  # the last cycle's wind, from its rows so far
        cw.close(mets[-1].index, float(res.t[-1]), mets[-1].complete)
    ledger, rel = _ledger(gl, rig.gs, float(e_thrust[k_end]), shape)
    status, msg = _status(res, ap, interrupted, flown[0] or t_end is not None, T_total, cycles, mets)
    if ap.mode == "RECOVER" and lost_path(ap.recover_cause):
        msg += failsafe_wind(res, ap, cw.profile, dt)
    m = gsp.machine  # the armature current against the machine's ratings (the paper plant's winch has none)
    i_pk, above, rated = (None, None, []) if paper else machine_current(res.t, res.current, m.rated_current,
                                                                          m.peak_current)
    notes = sorted(list(ap.log) + rated, key=lambda e: e[0])  # the autopilot's and the logged events
    line = meta.get("line")
    return FlightReport(
        scenario=str(meta.get("scenario", "custom")), config=config,
        wind_mps=float((meta if flight_wind is None else flight_wind).get("wind_mps",
                                                                          math.hypot(wind.ned[0], wind.ned[1]))),
        status=status, message=msg, sim_time_s=float(res.t[-1] - res.t[0]), wall_s=wall, cycles=mets, ledger=ledger,
        ledger_residual_rel=rel, result=res, track_error=log.err[: k_end + 1], reference_pos=log.refpos[: k_end + 1],
        autopilot_log=notes, plant=plant, tether_drag_scale=float(tether_drag_scale), tether=str(model),
        line="paper" if line is None else str(line), generator=None if paper else str(meta.get("generator") or "passive"),
        line_shape=log.line_shape(), peak_current_A=i_pk, time_above_rated_current_s=above,
        control_activity=control_activity(*res.controls[:, :3].T, dt), loop=_loop_facts(rig.sim, res.steps),
        turbulence=_turbulence_facts(turb, wind, res),
        wind_estimates=list(cw.records),
        recover_cause=ap.recover_cause if ap.mode == "RECOVER" else None,
        cycle_index=log.cycle[: k_end + 1].copy(),
        aircraft={**aircraft.record(), "mass_kg": float(rig.airframes.unfolded.mass.mass)}, ground_station=station.record(),
    )


def _turbulence_facts(turb: TurbulenceSetting | None, wind: _FlightWind, res: FlightResult) -> dict[str, Any] | None:
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


def _cycle_boundary(rig: _Rig, cw: CycleWind, s_end: list[float], cycles: int) -> Callable[[int, float], Any]:
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


def _step_hook(rig: _Rig, wind: _FlightWind, log: FlightLog, stop: _StopRequest, flown: list[bool],
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
            gs.set_line_wind(profile, wind.ned[:2], np.subtract(np.subtract(s.vel_ned, s.vel_air_ned), wind_at(h)))
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


def _blocks(rig: _Rig, gl: GliderLedger, log: FlightLog, stop: _StopRequest, flown: list[bool],
            s_end: list[float], cw: CycleWind) -> Any:
    """The co-simulation's block runner of a flight (:class:`fdm_awe.sim.autopilot_kernel.AutopilotBlocks`:
    the autopilot's AUTO steps and their bookkeeping compiled), or None where it cannot run
    (no numba, no native JSBSim calls, ``FDM_AWE_JIT=0``, the Python loop chosen). A block's
    rows are booked (and kept for the cycle's wind estimate) as :func:`_step_hook` books a step,
    and the flight ends as it does there."""
    from .autopilot_kernel import AutopilotBlocks

    ap = rig.ap

    def after(k0: int, k1: int, s: Any, o: Any) -> bool:
        log.book_block(k0, k1, runner.alog)
        cw.add_block(k0, runner.raw_rows(k0, k1))
        return _flight_ends(ap, s_end, flown, stop)

    runner = AutopilotBlocks.create(rig.sim, ap, gl, after, s_end[0])
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


def _thrust_energy(res: FlightResult, log: FlightLog, rig: _Rig, paper: bool, dt: float) -> np.ndarray:
    """The cumulative energy [J] of the glider's propulsion per log row of ``res`` (whose
    propulsion columns it completes: the paper plant's ideal thruster, the motor's constant
    draw P0)."""
    k_end = res.steps
    it, ip = COLUMNS.index("thrust"), COLUMNS.index("p_prop")
    if paper:  # the logged propulsion columns show the ideal thruster (the real propeller is idle)
        res.data[1:, it], res.data[1:, ip] = logged_propulsion(res.data[1:, it], res.data[1:, ip], 0.0, rig.thruster,
                                                               np.asarray(log.t_ideal[1: k_end + 1], float))
        return log.e_ideal[: k_end + 1]
    res.data[:, it], res.data[:, ip] = logged_propulsion(res.data[:, it], res.data[:, ip],
                                                         rig.airframes.unfolded.propulsion.P0)
    p_prop = np.nan_to_num(res.p_prop)
    return np.r_[0.0, np.cumsum(0.5 * (p_prop[1:] + p_prop[:-1]) * dt)]


def _ledger(gl: GliderLedger, gs: Any, thrust_electrical: float, own: bool) -> tuple[dict[str, Any], float]:
    """The flight's energy ledger [J] (the glider's, the station's, with the line's own ledger
    when ``own``, the lumped line's) and the largest of their residuals relative to their largest term."""
    led = gs.ledger
    g_res, g_large = gl.residual()
    gs_res = led.residual()
    gs_large = led.largest_term()
    rel = max(abs(g_res) / max(g_large, 1e-9), abs(gs_res) / max(gs_large, 1e-9))
    ledger = {**{f"glider_{k}_J": v for k, v in gl.terms().items()}, "glider_residual_J": g_res,
              **{f"station_{k}_J": v for k, v in led.as_dict().items()},
              "station_residual_J": gs_res, "thrust_electrical_J": thrust_electrical}
    if own:  # the lumped line's own ledger (hook to drum); its residual is the integrator's error
        ll = gs.line_ledger
        ledger.update({f"line_{k}_J": v for k, v in ll.as_dict().items() if k != "relative_residual"})
        rel = max(rel, ll.relative_residual())
    return ledger, rel


def _status(res: FlightResult, ap: Autopilot, interrupted: bool, flown: bool, T_total: float, cycles: int,
            mets: list[CycleMetrics]) -> tuple[str, str]:
    """The flight's status and message (module doc) from the co-simulation's ending, Ctrl-C,
    whether the requested cycles (or the requested length, ``flown``) were flown in the time
    cap ``T_total`` [s], and the autopilot's RECOVER state at the end."""
    status = res.status
    msg = res.event.message if res.event is not None else "completed"
    n_done = sum(1 for c in mets if c.complete)
    if interrupted:
        status, msg = "interrupted", (f"interrupted by the user at t = {res.sim_time_s:.2f} s, "
                                      f"{n_done} of {cycles} cycles complete")
    elif status == "ok" and ap.mode == "RECOVER" and ap.parked:
        # held in RECOVER at the end, also when a failsafe took the flight out of its cycles
        d = float(np.linalg.norm(res.pos[-1]))
        status, msg = "parked", (f"parked in the hold at t = {res.sim_time_s:.1f} s, {d:.0f} m from the winch, "
                                 f"line {float(res.data[-1, COLUMNS.index('length')]):.0f} m")
    elif status == "ok" and not flown:
        status, msg = "incomplete", (f"time cap of {T_total:.1f} s reached with {n_done} of {cycles} cycles "
                                     f"complete")
    if status == "ground_contact" and ap.mode == "RECOVER":
        # a landing, not a crash: at the winch, slow, gently (landing_verdict)
        v_down = float(res.vel[-1][2])
        why = landing_verdict(res.pos[-1], res.vel[-1])
        if why is None:
            status, msg = "landed", msg.replace("ground contact", "landed") + f", sink {v_down:.1f} m/s"
        else:
            msg += f", sink {v_down:.1f} m/s (a crash, not a landing: {why})"
    if status in ("landed", "parked") and ap.recover_cause != "commanded":
        # safe, but not what was asked: a failsafe ended the cycles (the exit code says so)
        msg += f"; RECOVER after the {ap.recover_cause}, {n_done} of {cycles} cycles complete"
    return status, msg


__all__ = ["LAND_RADIUS_MAX", "LAND_SINK_MAX", "LAND_SPEED_MAX", "fly", "landing_verdict", "turbulence_setting"]
