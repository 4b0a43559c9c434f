"""What the pumping-cycle optimal control problem is: scenario, configuration, bounds, mesh.

Plain dataclasses with input validation; nothing here imports CasADi. Every check raises
:class:`fdm_awe.errors.InputError` with a one-line message naming the field and the allowed range.

Units: SI throughout (m, s, m/s, N, W, rad) except ``elevation0_deg``, ``azimuth0_deg`` and
``wind_from_deg`` which are in degrees because users type them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace

from ..definitions.aircraft import FOLD_TIME_MAX_S
from ..definitions.catalog import Aircraft, resolve_aircraft
from ..errors import InputError
from ..groundstation.line import check_line, check_line_model
from ..groundstation.source import StationFile, resolve_ground_station
from ..groundstation.variants import SUPPLY_VOLTAGE_RANGE
from ..groundstation.tether import check_tether_drag_scale
from ..trajectory.schema import CONFIGS, GENERATORS, PROPELLERS, SCENARIOS
from ..wind import WindProfile

# the cycle's vocabularies (scenario, configuration, propeller model, generator load) are the
# reference file's metadata values, defined with its schema

#: What each scenario optimises when :class:`CycleProblem` is given no ``line``, ``propeller``
#: or ``line_weight``: the ``physical`` scenario models the plant the 6-DOF glider flies (the
#: line sized for its load, the glider's own drive, the line's weight on the glider); the
#: ``paper`` scenario keeps Table 1's line and its own massless line and eq. 39 propeller fit.
#: ``propeller`` None is the paper scenario's eq. 39 fit (it has no choice).
PLANT_DEFAULTS: dict[str, dict[str, object]] = {
    "physical": {"line": "sized", "propeller": "engine", "line_weight": True, "generator": "passive",
                 "recovery_tension": "free"},
    "paper": {"line": "paper", "propeller": None, "line_weight": False, "generator": None,
              "recovery_tension": "slack"},
}
#: the line's tension in recovery (:attr:`CycleProblem.recovery_tension`)
RECOVERY_TENSIONS = ("free", "slack")
#: The plant model of the physical numbers published before the defaults above (Table 1's line,
#: momentum-theory propeller, massless line, slack recovery): ``CycleProblem(**LEGACY_PHYSICAL_PLANT,
#: ...)`` reproduces them (``--line paper --propeller momentum --no-line-weight --recovery-tension slack``)
LEGACY_PHYSICAL_PLANT: dict[str, object] = {"line": "paper", "propeller": "momentum", "line_weight": False,
                                            "recovery_tension": "slack"}


@dataclass(frozen=True)
class Scenario:
    """Modelling choices of one scenario family (docs/design.md section 4).

    ``paper``: static quadratic P(T) (eq. 39), no tether drag, no stall limit (Table 3 only),
    mechanical accounting ``E_generated = int G ddot dt``, reel-in at a constant ``P_rw``.
    ``physical``: propeller power with airspeed (momentum theory here; a problem's
    :attr:`CycleProblem.scenario_spec` switches it to the glider's own drive, the default, see
    :data:`PLANT_DEFAULTS`), tether drag with the current tether length, ``C_L <= C_Lmax``,
    energies counted electrically through the quasi-static DC machine + converter (energy into
    the load in generation, from the supply in recovery).
    """

    name: str
    propeller: str  #: "paper", "physical" (momentum) or "engine" (fdm_awe.pointmass.propeller.power model)
    tether_drag: bool  #: add the tether's equivalent drag coefficient
    stall_limit: bool  #: enforce C_L <= C_Lmax
    electrical: bool  #: electrical (True) or mechanical (False) energy accounting
    tension_control: bool  #: tension G is a free control in generation (paper) or follows the generator (physical)
    P_rw: float = 6.0  #: constant reel-in power of the paper scenario [W]
    #: generator load of the physical scenario (:data:`GENERATORS`; "passive" unless a problem's
    #: :attr:`CycleProblem.scenario_spec` chooses another); the paper scenario's tension is free
    generator: str = "passive"

    @classmethod
    def named(cls, name: str) -> "Scenario":
        if name == "paper":
            return cls("paper", "paper", tether_drag=False, stall_limit=False, electrical=False, tension_control=True)
        if name == "physical":
            return cls("physical", "physical", tether_drag=True, stall_limit=True, electrical=True, tension_control=False)
        raise InputError(f"scenario {name!r} unknown (allowed: {', '.join(SCENARIOS)})")


#: largest tension margin (``Bounds.tension_margin``): the cycle's bound at least a fifth of the rating
TENSION_MARGIN_MAX = 4.0
#: largest stall margin (``1 - Bounds.cl_margin``): the cycle keeps at least 30 % of C_Lmax usable
STALL_MARGIN_MAX = 0.7


@dataclass(frozen=True)
class Bounds:
    """Path and time bounds (Table 3 plus the corrections of docs/design.md section 4).

    ``T_max`` None means the aircraft definition's ``propulsion/pm/T-max-N``; ``reel_in_speed_max``
    None means the DC machine's limit at full duty (supply voltage). ``h_min`` is the documented
    ground clearance: 10 m keeps the 1.1 m span glider well clear of the ground and of the
    winch area at the bottom of a loop.
    """

    V_min: float = 5.0  #: airspeed [m/s]
    V_max: float = 25.0
    alpha_max: float = 0.35  #: |alpha| <= alpha_max [rad]
    phi_max: float = 1.0  #: |phi| <= phi_max [rad]
    T_max: float | None = None  #: thrust upper bound [N]
    G_min: float = 0.0  #: tether tension [N]
    G_max: float = 50.0
    h_min: float = 10.0  #: minimum altitude (ground clearance) [m]
    t_max: float = 60.0  #: T1 + T2 <= t_max [s]
    T_phase_min: float = 2.0  #: each phase lasts at least this long [s]
    reel_in_speed_max: float | None = None  #: |reel-in speed| bound [m/s]
    #: |gamma| bound [rad]: keeps the heading equation's 1/cos(gamma) <= 1.85 (steeper dives make
    #: the point mass's heading dynamics stiff and unstable, so the collocated path could no longer
    #: be reproduced by integrating its controls)
    gamma_max: float = 1.0
    cl_margin: float = 1.0  #: usable share of C_Lmax (1 = up to stall); < 1 keeps a margin for a reference to be flown
    #: tension margin below the rating ``G_max`` [-]: the cycle's tension stays at most
    #: ``G_max / (1 + tension_margin)`` (:attr:`G_cycle_max`), leaving room for what the flown
    #: cycle adds to the optimum's tension (the catch of the line at the phase switch, gusts).
    #: 0: the optimiser may use the whole rating
    tension_margin: float = 0.0
    #: how fast the reference may change its bank [rad/s] and its angle of attack [rad/s]: each
    #: control's change between neighbouring intervals, across both phase switches too, at most
    #: the rate times the mean of the two intervals' lengths (None: unbounded, the optimiser's
    #: own answer). A smoothness bound for a reference to be flown: the 6-DOF glider follows a
    #: held-control step only with its surfaces' fast motion
    bank_rate_max: float | None = None
    alpha_rate_max: float | None = None
    #: how fast the slack line may go taut at the end of recovery [m/s]: the glider's distance
    #: rate minus the reel speed of the last interval (None: any speed; the point mass switches
    #: to the generator's tension at once, the elastic line of the 6-DOF plant snaps taut)
    catch_speed_max: float | None = None

    @property
    def G_cycle_max(self) -> float:
        """The cycle's tension bound [N]: the rating ``G_max`` over ``1 + tension_margin``."""
        return self.G_max / (1.0 + self.tension_margin)

    @property
    def stall_margin(self) -> float:
        """The stall margin [-]: the share of each wing's C_Lmax the cycle keeps unused,
        ``1 - cl_margin`` (to 12 digits: 0.85 gives 0.15, not 0.15000000000000002)."""
        return round(1.0 - self.cl_margin, 12)

    def validate(self) -> None:
        def pos(name: str, v: float) -> None:
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"{name} = {v!r} out of range (allowed > 0)")

        for n in ("V_min", "V_max", "alpha_max", "phi_max", "G_max", "t_max", "T_phase_min", "gamma_max"):
            pos(n, getattr(self, n))
        if self.V_min >= self.V_max:
            raise InputError(f"V_min = {self.V_min:g} m/s must be below V_max = {self.V_max:g} m/s")
        if self.alpha_max > 1.0:
            raise InputError(f"alpha_max = {self.alpha_max:g} rad out of range (allowed 0 < alpha_max <= 1)")
        if self.phi_max >= math.pi / 2:
            raise InputError(f"phi_max = {self.phi_max:g} rad out of range (allowed 0 < phi_max < pi/2)")
        if not (math.isfinite(self.cl_margin) and 0.3 <= self.cl_margin <= 1.0):
            raise InputError(f"cl_margin = {self.cl_margin!r} out of range (allowed {1 - STALL_MARGIN_MAX:g} .. 1: "
                             f"a stall margin of 0 .. {STALL_MARGIN_MAX:g})")
        if not (isinstance(self.tension_margin, (int, float)) and math.isfinite(self.tension_margin)
                and 0.0 <= self.tension_margin <= TENSION_MARGIN_MAX):
            raise InputError(f"tension_margin = {self.tension_margin!r} out of range (allowed 0 .. {TENSION_MARGIN_MAX:g}: "
                             f"the cycle's tension bound G_max / (1 + margin))")
        if self.gamma_max >= math.pi / 2:
            raise InputError(f"gamma_max = {self.gamma_max:g} rad out of range (allowed 0 < gamma_max < pi/2)")
        if self.T_max is not None and not (math.isfinite(self.T_max) and self.T_max >= 0):
            raise InputError(f"T_max = {self.T_max!r} N out of range (allowed >= 0)")
        if not (math.isfinite(self.G_min) and 0 <= self.G_min < self.G_max):
            raise InputError(f"tension bounds G_min = {self.G_min:g} N, G_max = {self.G_max:g} N invalid (allowed 0 <= G_min < G_max)")
        if not (math.isfinite(self.h_min) and self.h_min >= 0):
            raise InputError(f"h_min = {self.h_min!r} m out of range (allowed >= 0)")
        if 2 * self.T_phase_min > self.t_max:
            raise InputError(f"t_max = {self.t_max:g} s leaves no room for two phases of at least {self.T_phase_min:g} s")
        for n in ("reel_in_speed_max", "bank_rate_max", "alpha_rate_max"):
            if getattr(self, n) is not None:
                pos(n, getattr(self, n))
        if self.catch_speed_max is not None and not (math.isfinite(self.catch_speed_max) and self.catch_speed_max >= 0):
            raise InputError(f"catch_speed_max = {self.catch_speed_max!r} m/s out of range (allowed >= 0)")


@dataclass(frozen=True)
class Mesh:
    """Radau collocation mesh: intervals per phase and polynomial degree.

    The default is chosen by the re-integration check (:mod:`fdm_awe.ocp.verify`): in the
    ``physical`` scenario the generator ties tension to reel speed, which gives the radial motion
    a stiff mode (time constant ~0.1 s); with 60 generation intervals of degree 4 the re-integrated
    optimal controls reproduce the collocated path within ~0.1 % and the energies within ~0.5 %,
    with 30 intervals the defects grow to ~2 %.
    """

    n_gen: int = 60
    n_rec: int = 20
    degree: int = 4

    def validate(self) -> None:
        for name in ("n_gen", "n_rec"):
            v = getattr(self, name)
            if not (isinstance(v, int) and 4 <= v <= 1000):
                raise InputError(f"mesh {name} = {v!r} out of range (allowed integer 4..1000)")
        if not (isinstance(self.degree, int) and 1 <= self.degree <= 9):
            raise InputError(f"mesh degree = {self.degree!r} out of range (allowed integer 1..9)")


@dataclass(frozen=True)
class CycleProblem:
    """One pumping cycle: generation (unfolded, taut tether) then recovery (slack tether).

    The cycle starts and ends at distance ``d0`` [m] from the winch at ``elevation0_deg`` /
    ``azimuth0_deg`` (azimuth from north, towards east); generation ends at distance ``d_tf``.
    Wind ``wind_speed`` [m/s] blows FROM ``wind_from_deg`` (180 = from the south, the paper's case);
    ``wind_speed`` is the speed at the reference height of ``wind_profile``
    (:class:`fdm_awe.wind.WindProfile`; uniform by default, the same speed at every height).

    The plant model (``line``, ``propeller``, ``line_weight``): None takes the scenario's
    default (:data:`PLANT_DEFAULTS`), resolved when the problem is made, so every problem holds
    its concrete choices (``CycleProblem().line == "sized"``). ``dataclasses.replace`` keeps them:
    to move a problem to another scenario with that scenario's defaults, pass ``line=None,
    propeller=None, line_weight=None`` with it.
    """

    scenario: str = "physical"
    config: str = "foldable"
    wind_speed: float = 6.0
    wind_from_deg: float = 180.0
    d0: float = 200.0
    d_tf: float = 250.0
    elevation0_deg: float = 30.0
    azimuth0_deg: float = 0.0
    bounds: Bounds = field(default_factory=Bounds)
    #: factor on the tether's line drag (``physical`` scenario; 1 = the line of the ground-station
    #: definition). A sensitivity knob of the optimiser only (e.g. 0.5 ~ half the diameter or
    #: half the length): the 6-DOF flight always uses the defined line
    tether_drag_scale: float = 1.0
    mesh: Mesh = field(default_factory=Mesh)
    #: propeller model of the physical scenario (:data:`PROPELLERS`; None: the scenario's
    #: default, "engine" in ``physical``): "engine" is the 6-DOF glider's own drive, so that an
    #: optimised cycle books the thrust power the flown one draws; "momentum" is momentum theory
    #: with efficiencies. Always None in the ``paper`` scenario (its eq. 39 fit)
    propeller: str | None = None
    #: the glider carries its share of the line's weight (physical scenario; the ground station's
    #: ``weight_share`` x mass per length x g x paid-out length, downwards), as the 6-DOF plant's
    #: ground station applies it. None: the scenario's default (on in ``physical``, off in ``paper``)
    line_weight: bool | None = None
    #: tether line of the ground-station definition (:data:`fdm_awe.groundstation.line.LINES`):
    #: its diameter sets the line drag, its mass per length the line weight, and a flight of the
    #: reference flies it. None: the scenario's default ("sized" in ``physical``, Table 1's
    #: "paper" line in ``paper``)
    line: str | None = None
    #: full travel [s] of the wing's fold at the start of recovery and of its unfold at the end
    #: (foldable configuration; the aerodynamics blend with the fold state as in the 6-DOF model).
    #: None: the aircraft definition's (``fcs/wing-fold-time-s``); 0: an instantaneous switch
    fold_time: float | None = None
    #: generator load in generation (physical scenario, :data:`GENERATORS`): the passive
    #: rectifier, the T2 duty as a control (``boost``) or the ``ideal`` bound. None: the scenario's
    #: default ("passive" in ``physical``; always None in ``paper``, whose tension is free)
    generator: str | None = None
    #: the line's tension in recovery (:data:`RECOVERY_TENSIONS`): ``free``, a control >= 0 the
    #: winch's motor holds while it reels in (its supply power and its full-duty speed follow the
    #: drive's relations; the line is taut wherever it pulls), so the taut reel-in and the slack
    #: glide-back are both admissible cycles and the optimum decides; ``slack``, fixed at zero
    #: (the line never pulls in recovery). None: the scenario's default (``free`` in
    #: ``physical``; always ``slack`` in ``paper``, whose reel-in power is a constant)
    recovery_tension: str | None = None
    #: the winch's supply voltage V_a [V] (physical scenario; None: the one of the definition
    #: :attr:`ground_station`; the paper gives none). A design variable of the drive: it
    #: sets the full-duty reel-in speed (5.36 m/s at 24 V on a slack line). The optimiser's only;
    #: a flight flies the definition's drive
    supply_voltage: float | None = None
    #: wind speed over height (:class:`fdm_awe.wind.WindProfile`): uniform (the default, the
    #: paper's), ``log`` (roughness length) or ``power`` (exponent), each with the reference
    #: height at which ``wind_speed`` holds. The ``paper`` scenario's wind is uniform
    wind_profile: WindProfile = field(default_factory=WindProfile)
    #: the line force on the glider (physical scenario, :data:`fdm_awe.groundstation.line.LINE_MODELS`):
    #: ``straight`` (the straight line's 1/4 drag and 1/2 weight shares, the ground station's
    #: straight line) or ``calibrated`` (the shares fitted to flights on the lumped line, with the
    #: still line's drag in the wind: ``tether/calibrated`` of the ground-station definition)
    line_model: str = "straight"
    #: the aircraft optimised (:class:`~fdm_awe.definitions.catalog.Aircraft`, resolved when the
    #: problem is made from a table name or a definition folder: ``--aircraft``). None: the
    #: package's glider
    aircraft: Aircraft | None = None
    #: the ground station optimised with (:class:`~fdm_awe.groundstation.source.StationFile`,
    #: resolved when the problem is made from a definition file: ``--ground-station``): its
    #: drive, line and calibrated line model. None: the package's ``tether/ground_station.xml``
    ground_station: StationFile | None = None

    def __post_init__(self) -> None:
        # None = the scenario's default; an unknown scenario is left for validate() to name
        defaults = PLANT_DEFAULTS.get(self.scenario, {})
        for name, value in defaults.items():
            if getattr(self, name) is None:
                object.__setattr__(self, name, value)
        if not isinstance(self.aircraft, Aircraft):
            object.__setattr__(self, "aircraft", resolve_aircraft(self.aircraft, "aircraft"))
        if not isinstance(self.ground_station, StationFile):
            object.__setattr__(self, "ground_station", resolve_ground_station(self.ground_station, "ground_station"))

    def validate(self) -> "CycleProblem":
        Scenario.named(self.scenario)
        if self.config not in CONFIGS:
            raise InputError(f"configuration {self.config!r} unknown (allowed: {', '.join(CONFIGS)})")
        if not math.isfinite(self.wind_speed) or self.wind_speed < 0:
            raise InputError(f"wind speed {self.wind_speed!r} m/s out of range (a magnitude: allowed >= 0; set the direction with wind_from_deg)")
        if self.wind_speed > 25:
            raise InputError(f"wind speed {self.wind_speed:g} m/s out of range (allowed 0..25 m/s)")
        if not math.isfinite(self.wind_from_deg):
            raise InputError(f"wind direction {self.wind_from_deg!r} deg is not a number")
        if not (math.isfinite(self.d0) and self.d0 > 0):
            raise InputError(f"d0 = {self.d0!r} m out of range (allowed > 0)")
        if not (math.isfinite(self.d_tf) and self.d_tf > self.d0):
            raise InputError(f"d_tf = {self.d_tf!r} m must exceed d0 = {self.d0:g} m (generation reels out)")
        if not (0.0 < self.elevation0_deg < 90.0):
            raise InputError(f"elevation0 = {self.elevation0_deg!r} deg out of range (allowed 0 < elevation < 90)")
        if not math.isfinite(self.azimuth0_deg) or abs(self.azimuth0_deg) >= 90:
            raise InputError(f"azimuth0 = {self.azimuth0_deg!r} deg out of range (allowed |azimuth| < 90)")
        check_tether_drag_scale(self.tether_drag_scale)
        check_line(self.line, "line")
        check_line_model(self.line_model, "line_model")
        if self.line_model != "straight" and self.scenario != "physical":
            raise InputError(f"line_model {self.line_model!r}: only the physical scenario has a line model (the paper's "
                             f"line has no drag; allowed straight)")
        if not isinstance(self.line_weight, bool):
            raise InputError(f"line_weight {self.line_weight!r} invalid (allowed true or false)")
        if self.propeller is not None:
            if self.propeller not in PROPELLERS:
                raise InputError(f"propeller {self.propeller!r} unknown (allowed: {', '.join(PROPELLERS)})")
            if self.scenario != "physical":
                raise InputError(f"propeller {self.propeller!r}: only the physical scenario has a choice "
                                 f"(the paper scenario uses its eq. 39 fit)")
        if self.scenario == "physical" and self.generator not in GENERATORS:
            raise InputError(f"generator {self.generator!r} unknown (allowed: {', '.join(GENERATORS)})")
        if self.scenario != "physical" and self.generator is not None:
            raise InputError(f"generator {self.generator!r}: only the physical scenario has a generator model "
                             f"(the paper scenario's tension is a free control)")
        if self.recovery_tension not in RECOVERY_TENSIONS:
            raise InputError(f"recovery_tension {self.recovery_tension!r} unknown (allowed: {', '.join(RECOVERY_TENSIONS)})")
        if self.scenario != "physical" and self.recovery_tension != "slack":
            raise InputError(f"recovery_tension {self.recovery_tension!r}: only the physical scenario has the winch's motor "
                             f"relations (allowed: slack)")
        if self.supply_voltage is not None:
            v = self.supply_voltage
            if not (isinstance(v, (int, float)) and math.isfinite(v) and SUPPLY_VOLTAGE_RANGE[0] <= v <= SUPPLY_VOLTAGE_RANGE[1]):
                raise InputError(f"supply_voltage = {v!r} V out of range (allowed {SUPPLY_VOLTAGE_RANGE[0]:g}.."
                                 f"{SUPPLY_VOLTAGE_RANGE[1]:g} V)")
            if self.scenario != "physical":
                raise InputError("supply_voltage: only the physical scenario has the winch's drive (the paper scenario's "
                                 "reel-in power is a constant)")
        if self.line_weight and self.scenario != "physical":
            raise InputError("line_weight: only the physical scenario has a line model (the paper's line is massless)")
        if not isinstance(self.wind_profile, WindProfile):
            raise InputError(f"wind_profile {self.wind_profile!r} invalid (allowed a WindProfile: uniform, log or power)")
        self.wind_profile.validate()
        if self.scenario == "paper" and not self.wind_profile.uniform:
            raise InputError(f"wind_profile {self.wind_profile.label()!r}: the paper scenario's wind is uniform (allowed uniform; "
                             f"shear is a physical-scenario option)")
        self.bounds.validate()
        self.mesh.validate()
        if self.fold_time is not None:
            if not (isinstance(self.fold_time, (int, float)) and math.isfinite(self.fold_time)
                    and 0.0 <= self.fold_time <= FOLD_TIME_MAX_S):
                raise InputError(f"fold_time = {self.fold_time!r} s out of range (allowed 0 .. {FOLD_TIME_MAX_S:g} s)")
            if 2 * self.fold_time + self.bounds.T_phase_min > self.bounds.t_max:
                raise InputError(f"fold_time = {self.fold_time:g} s: a fold and an unfold leave no room in t_max = "
                                 f"{self.bounds.t_max:g} s (allowed <= (t_max - T_phase_min) / 2)")
        h0 = self.d0 * math.sin(math.radians(self.elevation0_deg))
        if h0 < self.bounds.h_min:
            raise InputError(f"start altitude {h0:.1f} m is below the ground clearance h_min = {self.bounds.h_min:g} m")
        return self

    @property
    def scenario_spec(self) -> Scenario:
        spec = Scenario.named(self.scenario)
        if self.propeller == "engine":
            spec = replace(spec, propeller="engine")
        if self.generator == "boost":
            spec = replace(spec, generator="boost")
        elif self.generator == "ideal":
            spec = replace(spec, generator="ideal", tension_control=True)
        return spec

    @property
    def start_position(self) -> tuple[float, float, float]:
        """NED start point [m] (winch at the origin)."""
        el, az = math.radians(self.elevation0_deg), math.radians(self.azimuth0_deg)
        return (self.d0 * math.cos(el) * math.cos(az), self.d0 * math.cos(el) * math.sin(az), -self.d0 * math.sin(el))

    def with_wind(self, speed: float, from_deg: float | None = None) -> "CycleProblem":
        return replace(self, wind_speed=speed, wind_from_deg=self.wind_from_deg if from_deg is None else from_deg)


def working_lengths() -> tuple[float, float]:
    """The optimiser's shortest and longest working line, m: the start distance ``d0`` and the
    end of generation ``d_tf`` of :class:`CycleProblem` (its defaults)."""
    defaults = {f.name: f.default for f in fields(CycleProblem)}
    return float(defaults["d0"]), float(defaults["d_tf"])
