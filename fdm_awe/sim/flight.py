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

Status (``FlightReport.status``, :data:`FLIGHT_STATUSES`):

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
- ``parked``: the flight reached ``t_end`` in RECOVER holding on a short line (the
  autopilot's :attr:`~fdm_awe.autopilot.autopilot.Autopilot.parked`: REC_LAND 0, circling at
  REC_HOLD_ALT about the winch);
- an event of the co-simulation (:data:`fdm_awe.sim.loop.STATUSES`: ``ground_contact``,
  ``tether_break``, ``nonfinite``, ``airspeed_limit``, ``load_limit``) or another
  ground-station event by name (e.g. ``tether_fully_reeled_in``).

Cycles (:func:`segment_cycles`): every step is labelled with the cycle index of the reference
point the autopilot flew it on (none outside AUTO cycling) and with the autopilot's phase
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
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from ..units import FT, LBF, SLUG

#: samples per second of the lumped line's shape in a flight report
LINE_SHAPE_HZ = 10.0
#: what each plant is (written into the flight's JSON)
PLANT_NOTES = {
    "physical": "JSBSim 9x5 propeller and motor; ground station with DC machine, converter and PI speed loop",
    "paper": "paper scenario's simplifications: ideal thruster (body-x force, power by the P(T) fit), "
             "kinematic winch on an elastic line (generation booked as tension x reel speed, reel-in at constant power)",
}

#: largest touchdown sink rate [m/s] of a landing (ground contact in RECOVER)
LAND_SINK_MAX = 1.5
#: largest horizontal ground speed [m/s] at touchdown of a landing
LAND_SPEED_MAX = 15.0
#: largest horizontal distance [m] of a landing's touchdown from the winch
LAND_RADIUS_MAX = 150.0

#: statuses of a flight (see the module doc); other ground-station events appear by name
FLIGHT_STATUSES = ("ok", "incomplete", "interrupted", "landed", "parked", "ground_contact", "tether_break",
                   "nonfinite", "airspeed_limit", "load_limit")


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

#: phase codes of the per-step labels (:func:`segment_cycles`): autopilot phase name -> code
PHASE_CODES = {"generation": 0, "recovery": 1}
OTHER_PHASE = -1  #: any other phase (e.g. on the ground)
NO_CYCLE = -1  #: cycle label of a step flown outside AUTO cycling


@dataclass
class CycleMetrics:
    """One cycle of a flight: ``index`` (0-based), times flown in generation ``T1_s`` and in
    recovery ``T2_s`` (s, >= 0), energies (J; see the module doc; all >= 0 except ``E_net_J``),
    position tracking error RMS and maximum (m; NaN when no step of the cycle had a reference
    point), and whether the cycle was flown to its end (``complete``)."""

    index: int
    T1_s: float
    T2_s: float
    E_generated_J: float
    E_thrust_J: float
    E_reel_in_J: float
    E_net_J: float
    track_rms_m: float
    track_max_m: float
    complete: bool

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: floats rounded to 6 decimals, NaN as None."""
        return {k: (_json_float(v) if isinstance(v, float) else v) for k, v in self.__dict__.items()}


def _json_float(v: float, digits: int = 6) -> float | None:
    """``v`` rounded for JSON, None when not finite (JSON never carries NaN)."""
    v = float(v)
    return round(v, digits) if math.isfinite(v) else None


@dataclass(frozen=True)
class CycleSpan:
    """Where a cycle lies in a flight's log (rows: 0 the initial state, k the state after
    step k). Its steps are ``i0 + 1 .. i1``, so a cumulative quantity ``c`` changes by
    ``c[i1] - c[i0]`` over the cycle; ``n_generation``/``n_recovery`` count its steps in each
    phase (steps in another phase count in neither)."""

    index: int
    i0: int
    i1: int
    n_generation: int
    n_recovery: int
    complete: bool


def segment_cycles(cycle: np.ndarray, phase: np.ndarray, reached: int | None = None) -> list[CycleSpan]:
    """The cycles in a flight's log of steps ``1 .. K`` (row 0, the initial state, is ignored).

    ``cycle[k]``: index of the reference cycle that step k was flown on, :data:`NO_CYCLE`
    outside AUTO cycling; ``phase[k]``: 0 generation, 1 recovery, :data:`OTHER_PHASE` else
    (:data:`PHASE_CODES`). ``reached``: the cycle index the autopilot's path parameter had
    reached after the last step (None: unknown).

    A cycle starts at a step whose label differs from the running cycle's; steps without a
    label belong to the running cycle (steps before the first label to none); the last cycle
    runs to step K. A cycle is complete when the next one has a higher index, the last one
    when ``reached`` is past it."""
    cyc = np.asarray(cycle, dtype=np.int64)
    ph = np.asarray(phase, dtype=np.int64)
    if cyc.shape != ph.shape or cyc.ndim != 1:
        raise ValueError(f"cycle and phase labels must be 1-D of one length, got {cyc.shape} and {ph.shape}")
    K = len(cyc) - 1
    if K < 1:
        return []
    lab = cyc[1:]
    steps = np.flatnonzero(lab != NO_CYCLE) + 1  # labelled steps
    if len(steps) == 0:
        return []
    lv = cyc[steps]
    first = steps[np.r_[True, lv[1:] != lv[:-1]]]  # first step of each cycle
    spans: list[CycleSpan] = []
    gen = np.r_[0, np.cumsum(ph[1:] == PHASE_CODES["generation"])]
    rec = np.r_[0, np.cumsum(ph[1:] == PHASE_CODES["recovery"])]
    for j, k0 in enumerate(first):
        c = int(cyc[k0])
        i0 = int(k0) - 1
        i1 = int(first[j + 1]) - 1 if j + 1 < len(first) else K
        if j + 1 < len(first):
            complete = int(cyc[first[j + 1]]) > c
        else:
            complete = reached is not None and reached > c
        spans.append(CycleSpan(c, i0, i1, int(gen[i1] - gen[i0]), int(rec[i1] - rec[i0]), bool(complete)))
    return spans


def cycle_metrics(spans: list[CycleSpan], dt: float, e_generated: np.ndarray, e_thrust: np.ndarray,
                  e_reel_in: np.ndarray, track_error: np.ndarray) -> list[CycleMetrics]:
    """Per-cycle numbers of ``spans`` (:func:`segment_cycles`) from cumulative energies (J since
    the start, one value per log row: into the load, drawn by the glider's motor, drawn from the
    supply; a cycle gets each one's change over its steps) and the per-row tracking error (m,
    NaN where there was no reference point). ``dt``: step length, s."""
    out: list[CycleMetrics] = []
    for sp in spans:
        e = np.asarray(track_error[sp.i0 + 1: sp.i1 + 1], dtype=float)
        e = e[np.isfinite(e)]
        E_gen = float(e_generated[sp.i1] - e_generated[sp.i0])
        E_thr = float(e_thrust[sp.i1] - e_thrust[sp.i0])
        E_rw = float(e_reel_in[sp.i1] - e_reel_in[sp.i0])
        out.append(CycleMetrics(
            sp.index, sp.n_generation * dt, sp.n_recovery * dt, E_gen, E_thr, E_rw, E_gen - E_thr - E_rw,
            float(np.sqrt(np.mean(e**2))) if len(e) else float("nan"), float(e.max()) if len(e) else float("nan"),
            complete=sp.complete,
        ))
    return out


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
        import signal
        import threading

        if threading.current_thread() is threading.main_thread() and \
                signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            self._previous = signal.signal(signal.SIGINT, self._handler)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._previous is not None:
            import signal

            signal.signal(signal.SIGINT, self._previous)
            self._previous = None


class GliderLedger:
    """Work-energy bookkeeping of the glider's CG motion from JSBSim's force breakdown."""

    _FORCES = ("aero", "prop", "external", "gear", "weight")

    def __init__(self, glider: Any, ideal_thrust: bool = False) -> None:
        """``ideal_thrust``: the paper plant's body-x force is among JSBSim's external forces;
        its work is booked as thrust work, not tether work."""
        pm = glider.fdm.get_property_manager()
        node = lambda n: pm.get_node(n, False).get_double_value  # noqa: E731
        self._f = {k: [node(f"forces/fb{a}-{k}-lbs") for a in "xyz"] for k in self._FORCES}
        self._v = [node(f"velocities/{a}-fps") for a in "uvw"]
        self._mass = node("inertia/mass-slugs")
        self.work = {k: 0.0 for k in self._FORCES}
        self.work["ideal_thrust"] = 0.0
        self._ti = node("external_reactions/ideal-thrust/magnitude") if ideal_thrust else None
        self._v_prev = self._vel()
        self.ke0 = self._ke()
        self.ke = self.ke0

    def _vel(self) -> tuple[float, float, float]:
        return (self._v[0]() * FT, self._v[1]() * FT, self._v[2]() * FT)

    def _ke(self) -> float:
        v = self._vel()
        return 0.5 * self._mass() * SLUG * (v[0] ** 2 + v[1] ** 2 + v[2] ** 2)

    def step(self, dt: float) -> None:
        v = self._vel()
        vm = [(a + b) * 0.5 for a, b in zip(v, self._v_prev)]
        for k, fs in self._f.items():
            self.work[k] += (fs[0]() * vm[0] + fs[1]() * vm[1] + fs[2]() * vm[2]) * LBF * dt
        if self._ti is not None:
            self.work["ideal_thrust"] += self._ti() * vm[0] * LBF * dt
        self._v_prev = v
        self.ke = self._ke()

    def terms(self) -> dict[str, float]:
        """J: kinetic change, potential change (= -weight work), works of the other forces."""
        w = self.work
        return {"delta_kinetic": self.ke - self.ke0, "delta_potential": -w["weight"],
                "aero_work": w["aero"], "thrust_work": w["prop"] + w["ideal_thrust"],
                "tether_work": w["external"] - w["ideal_thrust"], "ground_work": w["gear"]}

    def residual(self) -> tuple[float, float]:
        t = self.terms()
        res = t["delta_kinetic"] + t["delta_potential"] - t["aero_work"] - t["thrust_work"] - t["tether_work"] - t["ground_work"]
        largest = max(abs(v) for v in t.values())
        return res, largest


@dataclass
class FlightReport:
    scenario: str
    config: str
    wind_mps: float
    status: str
    message: str
    sim_time_s: float
    wall_s: float
    cycles: list[CycleMetrics]
    ledger: dict[str, Any]
    ledger_residual_rel: float
    result: Any = field(repr=False, default=None)  #: fdm_awe.sim.loop.FlightResult
    track_error: np.ndarray | None = field(repr=False, default=None)
    reference_pos: np.ndarray | None = field(repr=False, default=None)
    autopilot_log: list[tuple[float, str]] = field(default_factory=list)
    plant: str = "physical"  #: "physical" or "paper" (see PLANT_NOTES)
    tether_drag_scale: float = 1.0  #: factor on the line drag the ground station applied (1 = the defined line)
    line: str | None = None  #: the tether line flown (:data:`fdm_awe.groundstation.line.LINES`)
    #: the generator load the winch flew in generation (reference metadata ``generator``;
    #: None on the paper plant, whose kinematic winch has none)
    generator: str | None = None
    tether: str = "straight"  #: the line model: "straight" or "lumped:N"
    #: the lumped line's shape sampled at :data:`LINE_SHAPE_HZ`: ``t`` (m,) s, ``nodes`` (m, N+1, 3)
    #: m NED winch first, ``tension`` (m, N) N per segment; None for the straight line
    line_shape: dict[str, np.ndarray] | None = field(repr=False, default=None)
    #: surface motion above 0.5 Hz (:class:`fdm_awe.sim.activity.ControlActivity`), None before a run
    control_activity: Any = None

    @property
    def realtime_factor(self) -> float:
        return self.sim_time_s / self.wall_s if self.wall_s > 0 else float("inf")

    def as_json(self) -> dict[str, Any]:
        """docs/design.md section 1 output contract of ``fdm-awe fly``.

        ``status``: one of :data:`FLIGHT_STATUSES` or a ground-station event name (module doc:
        ``ok`` only when every requested cycle was completed; ``incomplete`` when the time cap
        ended the flight first; ``interrupted`` after Ctrl-C; ``landed``; event names). Each
        cycle carries ``complete``. Numbers that cannot be computed (e.g. the tracking error
        of a cycle without a reference point) are ``null``: the JSON never carries NaN."""
        return {
            "scenario": self.scenario, "plant": self.plant, "plant_note": PLANT_NOTES.get(self.plant, ""),
            "config": self.config, "wind_mps": _json_float(self.wind_mps), "tether_drag_scale": self.tether_drag_scale,
            "line": self.line, "generator": self.generator, "tether": self.tether,
            "status": self.status,
            "message": self.message, "sim_time_s": _json_float(self.sim_time_s), "wall_s": _json_float(self.wall_s, 3),
            "realtime_factor": _json_float(self.realtime_factor, 1),
            "ledger_residual_rel": _json_float(float(f"{self.ledger_residual_rel:.3e}"), 12),
            "ledger": {k: (_json_float(v) if isinstance(v, float) else v) for k, v in self.ledger.items()},
            "cycles": [c.as_dict() for c in self.cycles],
            "control_activity": None if self.control_activity is None else
            {k: _json_float(v) for k, v in self.control_activity.as_dict().items()},
        }


def fly(
    reference: Any,
    config: str = "foldable",
    cycles: int = 3,
    dt: float = 1.0 / 120.0,
    turbulence: tuple[str, int] | None = None,
    on_step: Callable[[int, Any, Any], bool | None] | None = None,
    params: Any = None,
    setup: Callable[[Any, Any], None] | None = None,
    t_end: float | None = None,
    plant: str = "physical",
    tether_drag_scale: float = 1.0,
    tether: str = "straight",
) -> FlightReport:
    """Fly ``cycles`` pumping cycles of ``reference`` (a :class:`~.autopilot.tracking.TrackingReference`).

    ``setup(autopilot, cosim)`` is called before the run (e.g. to attach a MAVLink endpoint);
    ``on_step(k, state, gs_output)`` after every step; a true return ends the flight there
    (status ``ok``, as the end of the reference would). ``t_end`` overrides the flight length.
    ``plant``: ``"physical"`` (JSBSim propeller + ground station) or ``"paper"`` (ideal thruster +
    kinematic winch, :mod:`fdm_awe.sim.paper_plant`). ``tether_drag_scale`` (-, 0 .. 10, default 1 =
    the defined line) scales the ground station's line drag on the glider, as
    ``CycleProblem.tether_drag_scale`` scales the optimiser's (the paper plant's ideal line has no drag).
    ``tether``: the ground station's line model, ``"straight"`` (default) or ``"lumped:N"``
    (:mod:`fdm_awe.groundstation.lumped`; its shape is sampled into the report's ``line_shape``
    and its own ledger into ``ledger``).
    The line is the one named by the reference metadata's ``line``
    (:data:`fdm_awe.groundstation.line.LINES`); a reference without it flies Table 1's line
    (``paper``), the line every reference written before lines were named was optimised with.

    Ctrl-C (SIGINT, or a KeyboardInterrupt raised in ``on_step``) ends the flight and returns
    a normal report with status ``interrupted`` holding everything flown so far (see
    :class:`_StopRequest`); a KeyboardInterrupt in ``setup`` propagates (nothing was flown).
    """
    from ..autopilot.autopilot import Autopilot
    from ..autopilot.guidance import norm3
    from ..autopilot.shaping import flyable_reference
    from .activity import control_activity
    from ..autopilot.config import autopilot_params
    from .loop import COLUMNS, CoSim, Limits
    from ..definitions.aircraft import load_glider
    from ..groundstation import GroundStation, load_ground_station
    from ..groundstation.line import check_line
    from ..sixdof import JSBSimGlider

    from .paper_plant import PLANTS, IdealThruster, IdealWinch

    if plant not in PLANTS:
        raise ValueError(f"plant {plant!r} unknown (allowed: {', '.join(PLANTS)})")
    from ..groundstation.tether import check_tether_drag_scale

    tether_drag_scale = check_tether_drag_scale(tether_drag_scale)  # also for the paper plant (no station)
    from ..groundstation.lumped import parse_tether

    nseg = parse_tether(tether)
    paper = plant == "paper"
    reference = flyable_reference(reference)  # the optimiser's held-control steps smoothed out
    meta = reference.meta
    wind = tuple(float(v) for v in meta.get("wind_ned_mps", (0.0, 0.0, 0.0)))
    # the wind profile the reference was optimised in (absent: uniform): JSBSim's steady wind
    # follows the glider's altitude step by step, the ground station's line drag the wind at
    # the line's height (fdm_awe.wind.LINE_HEIGHT_FRACTION of the glider's), turbulence on top
    from ..wind import WindProfile, line_height

    profile = WindProfile.from_dict(meta.get("wind_profile"), "reference metadata.wind_profile")
    wind_ref = wind

    def wind_at(h: float) -> tuple[float, float, float]:
        f = float(profile.factor(h))
        return (wind_ref[0] * f, wind_ref[1] * f, 0.0)

    if not profile.uniform:
        wind = wind_at(-float(reference.sample(0.0).pos[2]))
    # the line the reference was optimised with; a reference written before lines were named
    # was optimised with Table 1's line ("paper"). Read (and an unknown name refused) before JSBSim loads
    line = meta.get("line")
    gen = meta.get("generator")
    if not paper and gen == "ideal":
        from ..errors import InputError

        raise InputError("reference metadata.generator: 'ideal' is the optimiser's upper bound (a loss-free converter "
                         "holding any tension), which no ground station realises; allowed passive, boost")
    gsp = load_ground_station(line="paper" if line is None else check_line(line, "reference metadata.line"))
    if paper and nseg:
        from ..errors import InputError

        raise InputError("--tether lumped:N needs the physical plant (the paper plant's winch is kinematic)")
    glider = JSBSimGlider("glider_foldable", dt=dt, wind_ned=wind, turbulence=turbulence)
    airframes = load_glider()
    if paper:
        from ..ocp.problem import Scenario

        gs = IdealWinch(gsp, P_rw=Scenario.named("paper").P_rw, wind_ned=wind)
    else:
        gs = GroundStation(gsp, wind_ned=wind if profile.uniform else wind_at(line_height(-float(reference.sample(0.0).pos[2]))),
                           tether_drag_scale=tether_drag_scale, tether=tether)
        gs.set_line_wind(profile, wind_ref[:2])  # the lumped line's nodes: the profile at their own heights
    r0 = reference.sample(0.0)
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
    ps = params if params is not None else autopilot_params()
    thruster = IdealThruster.for_glider(glider, airframes.unfolded.propulsion) if paper else None
    ap = Autopilot(glider, airframes, ps, reference, config=config, load_resistance=gsp.converter.load_resistance,
                   thruster=thruster, winch="ideal" if paper else "physical", line_EA=gsp.tether.axial_stiffness)
    # the line's own breaking load ends a run as "tether_break" (ground-station event); the
    # co-simulation's tension limit sits just above it so it never pre-empts that event
    sim = CoSim(glider, gs, ap, dt=dt, limits=Limits(max_tension=1.01 * gsp.tether.breaking_load, grace_s=1.0))
    if setup is not None:
        setup(ap, sim)
    gl = GliderLedger(glider, ideal_thrust=paper)
    P = reference.period
    # cycles are counted by the autopilot's path parameter (the glider's own period); the
    # flight ends when the last cycle is flown, or at a generous time cap
    T_total = t_end if t_end is not None else cycles * P * 2.0 + 10.0
    n = int(round(T_total / dt))
    err = np.full(n + 1, np.nan)
    refpos = np.full((n + 1, 3), np.nan)
    e_load = np.zeros(n + 1)
    e_supply = np.zeros(n + 1)
    e_ideal = np.zeros(n + 1)  # paper plant: P(T) of the ideal thrust, J
    t_ideal = np.zeros(n + 1)  # paper plant: ideal thrust, N
    e_acc = [0.0]
    led = gs.ledger
    cyc = np.full(n + 1, NO_CYCLE, dtype=np.int64)  # per step: cycle of the reference point flown
    phs = np.full(n + 1, OTHER_PHASE, dtype=np.int64)  # per step: the autopilot's phase
    s_end = cycles * P
    done = [0, False]  # the last step whose bookkeeping is complete; whether the cycles are flown
    every = max(1, int(round(1.0 / (LINE_SHAPE_HZ * dt))))  # lumped line: shape samples
    shape_t: list[float] = []
    shape_nodes: list[np.ndarray] = []
    shape_tension: list[np.ndarray] = []
    stop = _StopRequest()
    gust_on_line = turbulence is not None and not paper and bool(gs.tether_segments)

    def _on_step(k: int, s: Any, o: Any) -> bool:
        h = -float(s.pos_ned[2])
        if not profile.uniform:  # the next step's wind at the glider's (and the line's) height
            glider.set_wind(wind_at(h))
            gs.set_wind(wind_at(line_height(h)))
        if gust_on_line:  # the lumped line: the gust the glider meets now, uniform along the line
            gs.set_line_wind(profile, wind_ref[:2], np.subtract(np.subtract(s.vel_ned, s.vel_air_ned), wind_at(h)))
        gl.step(dt)
        rp = ap.ref_point
        if rp is not None and ap.mode == "AUTO" and ap.cycling:
            refpos[k] = rp.pos
            err[k] = norm3(rp.pos - s.pos_ned)
            cyc[k] = rp.cycle
        phs[k] = PHASE_CODES.get(ap.phase, OTHER_PHASE)
        e_load[k] = led.load
        e_supply[k] = led.supply
        if thruster is not None:
            e_acc[0] += thruster.power() * dt  # the thrust commanded for the step just flown
            e_ideal[k] = e_acc[0]
            t_ideal[k] = thruster.thrust
        done[0] = k
        if nseg and k % every == 0:
            shape_t.append(k * dt)
            shape_nodes.append(gs.line_nodes())
            shape_tension.append(gs.line_tensions())
        if on_step is not None and on_step(k, s, o):
            return True  # the caller ends the flight here
        if t_end is None and ap.mode == "AUTO" and ap.s_ref >= s_end:
            done[1] = True
            return True
        return stop.requested

    wall0 = time.perf_counter()
    with stop:
        res = sim.run(T_total, on_step=_on_step)
    wall = time.perf_counter() - wall0
    # Ctrl-C: taken at a step boundary (the loop ended "ok" on the request) or caught by the loop
    interrupted = res.status == "interrupted" or (stop.requested and res.status == "ok")
    if res.steps > done[0]:
        # Ctrl-C between a step and the end of its bookkeeping: the flight ends at the last
        # step that was booked whole
        res.truncate(done[0])
    k_end = res.steps
    if paper:
        e_thrust = e_ideal[: k_end + 1]
        # the logged propulsion columns show the ideal thruster (the real propeller is idle)
        res.data[1:, COLUMNS.index("thrust")] = t_ideal[1: k_end + 1]
        res.data[1:, COLUMNS.index("p_prop")] = [thruster.power(t) for t in t_ideal[1: k_end + 1]]
    else:
        # the logged propulsion power: the motor's electrical input (JSBSim: throttle x battery
        # voltage x current) plus the constant draw the optimiser's propulsion model books
        # (P0: ESC and avionics), so that flight and optimiser count the same consumers
        res.data[:, COLUMNS.index("p_prop")] += airframes.unfolded.propulsion.P0
        p_prop = np.nan_to_num(res.p_prop)
        e_thrust = np.r_[0.0, np.cumsum(0.5 * (p_prop[1:] + p_prop[:-1]) * dt)]
    reached = ap.cycle if ap.mode == "AUTO" and ap.cycling else None
    spans = segment_cycles(cyc[: k_end + 1], phs[: k_end + 1], reached)
    mets = cycle_metrics(spans, dt, e_load[: k_end + 1], e_thrust, e_supply[: k_end + 1], err[: k_end + 1])
    g_res, g_large = gl.residual()
    gs_res = led.residual()
    gs_large = led.largest_term()
    rel = max(abs(g_res) / max(g_large, 1e-9), abs(gs_res) / max(gs_large, 1e-9))
    ledger = {**{f"glider_{k}_J": v for k, v in gl.terms().items()}, "glider_residual_J": g_res,
              **{f"station_{k}_J": v for k, v in led.as_dict().items()},
              "station_residual_J": gs_res, "thrust_electrical_J": float(e_thrust[k_end])}
    line_shape = None
    if nseg:  # the lumped line's own ledger (hook to drum); its residual is the integrator's error
        ll = gs.line_ledger
        ledger.update({f"line_{k}_J": v for k, v in ll.as_dict().items() if k != "relative_residual"})
        rel = max(rel, ll.relative_residual())
        line_shape = {"t": np.array(shape_t), "nodes": np.array(shape_nodes), "tension": np.array(shape_tension)}
    status = res.status
    msg = res.event.message if res.event is not None else "completed"
    n_done = sum(1 for c in mets if c.complete)
    if interrupted:
        status, msg = "interrupted", (f"interrupted by the user at t = {res.sim_time_s:.2f} s, "
                                      f"{n_done} of {cycles} cycles complete")
    elif status == "ok" and t_end is None and not done[1]:
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
    elif status == "ok" and ap.mode == "RECOVER" and ap.parked:
        d = float(np.linalg.norm(res.pos[-1]))
        status, msg = "parked", (f"parked in the hold at t = {res.sim_time_s:.1f} s, {d:.0f} m from the winch, "
                                 f"line {float(res.data[-1, COLUMNS.index('length')]):.0f} m")
    return FlightReport(
        scenario=str(meta.get("scenario", "custom")), config=config, wind_mps=float(meta.get("wind_mps", math.hypot(wind_ref[0], wind_ref[1]))),
        status=status, message=msg, sim_time_s=float(res.t[-1] - res.t[0]), wall_s=wall, cycles=mets, ledger=ledger,
        ledger_residual_rel=rel, result=res, track_error=err[: k_end + 1], reference_pos=refpos[: k_end + 1],
        autopilot_log=list(ap.log), plant=plant, tether_drag_scale=float(tether_drag_scale), tether=tether,
        line="paper" if line is None else str(line), generator=None if paper else str(gen or "passive"),
        line_shape=line_shape, control_activity=control_activity(*res.controls[:, :3].T, dt),
    )
