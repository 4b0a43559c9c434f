"""A whole flight: the 6-DOF glider, the ground station and the autopilot flying the optimised
pumping cycle for N cycles, with per-cycle energies, tracking errors and an energy ledger.

Plants (``plant``): ``physical`` = the JSBSim propeller and the ground station of
:mod:`fdm_awe.groundstation`; ``paper`` = the ideal thruster and the kinematic winch of
:mod:`fdm_awe.paper_plant`, faithful to the ``paper`` scenario's simplifications.

Energy terms per cycle (J, all >= 0 except ``E_net_J``), counted as the plant's scenario
counts them. Physical plant, electrically: ``E_generated_J`` into the load resistor,
``E_thrust_J`` drawn by the glider's motor (its electrical input plus the constant P0 of
ESC and avionics that the optimiser's propulsion model also books), ``E_reel_in_J`` drawn
from the ground station's supply. Paper plant: ``E_generated_J`` = mechanical tension x reel speed in generation,
``E_thrust_J`` = the paper's P(T) fit of the commanded thrust, ``E_reel_in_J`` = the constant
reel-in power x recovery time. ``E_net_J = E_generated_J - E_thrust_J - E_reel_in_J``.

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

from .units import FT, LBF, SLUG

#: what each plant is (written into the flight's JSON)
PLANT_NOTES = {
    "physical": "JSBSim 9x5 propeller and motor; ground station with DC machine, converter and PI speed loop",
    "paper": "paper scenario's simplifications: ideal thruster (body-x force, power by the P(T) fit), "
             "kinematic winch on an elastic line (generation booked as tension x reel speed, reel-in at constant power)",
}

#: touchdown sink rate [m/s] below which ground contact in RECOVER counts as a landing
LAND_SINK_MAX = 3.0


@dataclass
class CycleMetrics:
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
        return {k: (round(v, 6) if isinstance(v, float) else v) for k, v in self.__dict__.items()}


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
    result: Any = field(repr=False, default=None)  #: fdm_awe.cosim.FlightResult
    track_error: np.ndarray | None = field(repr=False, default=None)
    reference_pos: np.ndarray | None = field(repr=False, default=None)
    autopilot_log: list[tuple[float, str]] = field(default_factory=list)
    plant: str = "physical"  #: "physical" or "paper" (see PLANT_NOTES)
    tether_drag_scale: float = 1.0  #: factor on the line drag the ground station applied (1 = the defined line)

    @property
    def realtime_factor(self) -> float:
        return self.sim_time_s / self.wall_s if self.wall_s > 0 else float("inf")

    def as_json(self) -> dict[str, Any]:
        """docs/design.md section 1 output contract of ``fdm-awe fly``."""
        return {
            "scenario": self.scenario, "plant": self.plant, "plant_note": PLANT_NOTES.get(self.plant, ""),
            "config": self.config, "wind_mps": self.wind_mps, "tether_drag_scale": self.tether_drag_scale,
            "status": self.status,
            "message": self.message, "sim_time_s": round(self.sim_time_s, 6), "wall_s": round(self.wall_s, 3),
            "realtime_factor": round(self.realtime_factor, 1), "ledger_residual_rel": float(f"{self.ledger_residual_rel:.3e}"),
            "ledger": {k: (round(v, 6) if isinstance(v, float) else v) for k, v in self.ledger.items()},
            "cycles": [c.as_dict() for c in self.cycles],
        }


def fly(
    reference: Any,
    config: str = "foldable",
    cycles: int = 3,
    dt: float = 1.0 / 120.0,
    turbulence: tuple[str, int] | None = None,
    on_step: Callable[[int, Any, Any], None] | None = None,
    params: Any = None,
    setup: Callable[[Any, Any], None] | None = None,
    t_end: float | None = None,
    plant: str = "physical",
    tether_drag_scale: float = 1.0,
) -> FlightReport:
    """Fly ``cycles`` pumping cycles of ``reference`` (a :class:`~.autopilot.tracking.TrackingReference`).

    ``setup(autopilot, cosim)`` is called before the run (e.g. to attach a MAVLink endpoint);
    ``on_step(k, state, gs_output)`` after every step. ``t_end`` overrides the flight length.
    ``plant``: ``"physical"`` (JSBSim propeller + ground station) or ``"paper"`` (ideal thruster +
    kinematic winch, :mod:`fdm_awe.paper_plant`). ``tether_drag_scale`` (-, 0 .. 10, default 1 =
    the defined line) scales the ground station's line drag on the glider, as
    ``CycleProblem.tether_drag_scale`` scales the optimiser's (the paper plant's ideal line has no drag).
    """
    from .autopilot.autopilot import Autopilot
    from .autopilot.guidance import norm3
    from .autopilot.config import autopilot_params
    from .cosim import COLUMNS, CoSim, Limits
    from .definitions.aircraft import load_glider
    from .groundstation import GroundStation, load_ground_station
    from .sixdof import JSBSimGlider

    from .paper_plant import PLANTS, IdealThruster, IdealWinch

    if plant not in PLANTS:
        raise ValueError(f"plant {plant!r} unknown (allowed: {', '.join(PLANTS)})")
    from .groundstation.tether import check_tether_drag_scale

    tether_drag_scale = check_tether_drag_scale(tether_drag_scale)  # also for the paper plant (no station)
    paper = plant == "paper"
    meta = reference.meta
    wind = tuple(float(v) for v in meta.get("wind_ned_mps", (0.0, 0.0, 0.0)))
    glider = JSBSimGlider("glider_foldable", dt=dt, wind_ned=wind, turbulence=turbulence)
    gsp = load_ground_station()
    airframes = load_glider()
    if paper:
        from .ocp.problem import Scenario

        gs = IdealWinch(gsp, P_rw=Scenario.named("paper").P_rw, wind_ned=wind)
    else:
        gs = GroundStation(gsp, wind_ned=wind, tether_drag_scale=tether_drag_scale)
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
    marks: list[tuple[int, int, int]] = []  # (step, cycle, phase) at every phase change
    last = [(-1, -1)]
    s_end = cycles * P

    def _on_step(k: int, s: Any, o: Any) -> bool:
        gl.step(dt)
        rp = ap.ref_point
        if rp is not None and ap.mode == "AUTO":
            refpos[k] = rp.pos
            err[k] = norm3(rp.pos - s.pos_ned)
            key = (ap.cycle, rp.phase)
            if key != last[0]:
                marks.append((k, *key))
                last[0] = key
        e_load[k] = led.load
        e_supply[k] = led.supply
        if thruster is not None:
            e_acc[0] += thruster.power() * dt  # the thrust commanded for the step just flown
            e_ideal[k] = e_acc[0]
            t_ideal[k] = thruster.thrust
        if on_step is not None:
            on_step(k, s, o)
        return t_end is None and ap.mode == "AUTO" and ap.s_ref >= s_end

    wall0 = time.perf_counter()
    res = sim.run(T_total, on_step=_on_step)
    wall = time.perf_counter() - wall0
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
    mets: list[CycleMetrics] = []
    # cycle c runs from its generation mark to the next cycle's generation mark (or the end)
    starts = {c: k for k, c, ph in marks if ph == 0}
    rec = {c: k for k, c, ph in marks if ph == 1}
    starts.setdefault(0, 0)
    for c in sorted(starts):
        i0 = starts[c] if c > 0 else 0
        nxt = starts.get(c + 1)
        complete = nxt is not None or (ap.s_ref >= (c + 1) * P - 1e-9)
        i1 = nxt if nxt is not None else k_end
        if i0 >= k_end:
            break
        ir = rec.get(c, i1)
        sl = slice(i0 + 1, i1 + 1)
        e = err[sl]
        e = e[np.isfinite(e)]
        E_gen = float(e_load[i1] - e_load[i0])
        E_thr = float(e_thrust[i1] - e_thrust[i0])
        E_rw = float(e_supply[i1] - e_supply[i0])
        mets.append(CycleMetrics(
            c, (ir - i0) * dt, (i1 - ir) * dt, E_gen, E_thr, E_rw, E_gen - E_thr - E_rw,
            float(np.sqrt(np.mean(e**2))) if len(e) else float("nan"), float(e.max()) if len(e) else float("nan"),
            complete=bool(complete),
        ))
    g_res, g_large = gl.residual()
    gs_res = led.residual()
    gs_large = led.largest_term()
    rel = max(abs(g_res) / max(g_large, 1e-9), abs(gs_res) / max(gs_large, 1e-9))
    ledger = {**{f"glider_{k}_J": v for k, v in gl.terms().items()}, "glider_residual_J": g_res,
              **{f"station_{k}_J": v for k, v in led.as_dict().items()},
              "station_residual_J": gs_res, "thrust_electrical_J": float(e_thrust[k_end])}
    status = res.status
    msg = res.event.message if res.event is not None else "completed"
    if status == "ground_contact" and ap.mode == "RECOVER":
        # a landing, not a crash: touchdown sink rate below LAND_SINK_MAX
        v_down = float(res.vel[-1][2])
        if v_down < LAND_SINK_MAX:
            status, msg = "landed", msg.replace("ground contact", "landed") + f", sink {v_down:.1f} m/s"
        else:
            msg += f", sink {v_down:.1f} m/s (a crash, not a landing)"
    return FlightReport(
        scenario=str(meta.get("scenario", "custom")), config=config, wind_mps=float(meta.get("wind_mps", math.hypot(wind[0], wind[1]))),
        status=status, message=msg, sim_time_s=float(res.t[-1] - res.t[0]), wall_s=wall, cycles=mets, ledger=ledger,
        ledger_residual_rel=rel, result=res, track_error=err[: k_end + 1], reference_pos=refpos[: k_end + 1],
        autopilot_log=list(ap.log), plant=plant, tether_drag_scale=float(tether_drag_scale),
    )
