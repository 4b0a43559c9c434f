"""The two phases of the cycle as state-space blocks: derivative, tension, reel speed, power terms.

Generation (phase 1): state ``(x, y, z, V, gamma, psi)`` [m, m, m, m/s, rad, rad]; the tether
is taut, so its length equals the distance ``d = |P|`` and the reel speed is ``ddot``.
Controls ``(alpha, phi, T, G)`` in the ``paper`` scenario (tension is a control),
``(alpha, phi, T)`` in ``physical`` (tension follows the passive-rectifier generator),
``(alpha, phi, T, D2)`` with the ``boost`` generator (the T2 duty sets the load the armature
sees, :mod:`fdm_awe.ocp.energy`), ``(alpha, phi, T, G)`` with the ``ideal`` generator bound
(tension free, power through a loss-free converter). The motor-off mode appends ``s``.

Recovery (phase 2): state ``(x, y, z, V, gamma, psi, l)`` with tether length ``l`` [m],
``ldot = v_reel``, ``d <= l``. Controls ``(alpha, phi, T, v_reel)``, and ``G`` where the recovery
tension is free (``CycleProblem.recovery_tension``, physical scenario): the tension [N] >= 0 the
winch's motor holds while it reels in (supply power :func:`fdm_awe.ocp.energy.motor_supply_power`
with that tension, the full-duty speed falling with it, the line taut wherever it pulls:
:mod:`fdm_awe.ocp.constraints`); otherwise the line is slack (``G = 0``).

Fold (foldable configuration): the wing folds through the 6-DOF glider's rate-limited actuator
in ``fold_time`` seconds (``fcs/wing-fold-time-s`` of ``aircraft/glider_foldable``), commanded
folded when recovery starts and open again ``fold_time`` before it ends, as the autopilot
commands it (``FOLD_LEAD`` 0, ``UNFOLD_LEAD`` = the fold time): the fold fraction
(:meth:`CycleModel.fold_fraction`) ramps 0 -> 1 over the first ``fold_time`` of recovery and
1 -> 0 over its last, and the aerodynamics blend with it as the 6-DOF model blends them
(:func:`fdm_awe.pointmass.aero.fold_blend`). ``fold_time`` 0 is an instantaneous switch at the phase
boundaries (generation unfolded, recovery folded).

Motor-off mode (propeller model ``engine``, whose running drive draws more than the idle
power at zero thrust): both phases carry the motor's on-fraction ``s`` in [0, 1] as a further
control (last). The glider pulses its motor: thrust ``s T_on`` (``T`` is the thrust while the
motor runs) and electrical power ``s P_on(T_on, V) + (1 - s) P_off``
(:func:`fdm_awe.ocp.energy.duty_cycled_power`), the convex hull of the running and the stopped
drive; ``s = 1`` is the model without the mode exactly.

Wind profile (:class:`fdm_awe.wind.WindProfile`): the wind ``(wx, wy)`` a block is given (the
NLP parameters) is the wind at the profile's reference height; the glider meets it scaled to its
own height ``h = -z`` (:meth:`CycleModel.wind_at`), and the line drag uses the wind at
:data:`fdm_awe.wind.LINE_HEIGHT_FRACTION` of that height (:meth:`CycleModel._tether_drag`). The
uniform profile passes the wind through unchanged, so its expressions are those of a model
without profiles.

The glider dynamics are :class:`fdm_awe.pointmass.model.PointMassModel`; this module only wires the
tether, winch and energy terms around it. Evaluates on floats/NumPy and CasADi symbols.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any, Sequence

from ..constants import G0, RHO0
from ..pointmass import mathops as mo
from ..groundstation.line import STRAIGHT_DRAG_SHARE
from ..pointmass.aero import fold_blend, tether_drag_coefficient
from ..pointmass.fold import fold_fraction  # the fold law, one source with the autopilot
from ..definitions.aircraft import AeroParams, Airframe, Glider
from ..pointmass.model import Environment, PointMassModel
from .energy import (WinchElectrics, duty_cycled_power, generator_load_power, generator_tension, ideal_generator_power,
                     mechanical_tether_power, motor_supply_power, thrust_power)
from ..definitions.engine import ElectricDrive, load_electric_drive
from .problem import CycleProblem, Scenario
from ..wind import WindProfile, line_height

GEN_STATES = ("x", "y", "z", "V", "gamma", "psi")
#: smoothing of the normal air speed of the line [m/s] (keeps its square root differentiable)
TETHER_VN_EPS = 0.1
REC_STATES = GEN_STATES + ("l",)
#: the motor's on-fraction control (motor-off mode)
ON_FRACTION = "s"
#: name of the generation phase's T2-duty control (generator "boost")
BOOST_DUTY = "D2"
#: propeller models with a motor-off mode: the running drive draws more than the stopped one at
#: zero thrust (the ``engine`` drive turns its propeller at the zero-thrust advance ratio, ~10 W
#: at 13 m/s). Momentum theory draws exactly ``P0`` at zero thrust and is convex in the thrust,
#: so stopping the motor never saves power there (and its on-fraction would be undetermined at
#: zero thrust); the paper's eq. 39 fit models no motor.
MOTOR_OFF_MODELS = ("engine",)
def definition_fold_time(aircraft: Any = None) -> float:
    """Fold time [s] of the morphing aircraft's definition (``fcs/wing-fold-time-s`` of the
    aircraft's ``P_foldable``: the actuator's full travel; ``aircraft`` as
    :func:`~fdm_awe.definitions.catalog.resolve_aircraft` takes it, None the package's glider),
    range-checked as the aircraft check does (DefinitionError naming file, property and range)."""
    from ..definitions.catalog import resolve_aircraft

    return resolve_aircraft(aircraft).fold_time()


@dataclass(frozen=True)
class CycleModel:
    """Phase models of one cycle for a scenario and configuration."""

    scenario: Scenario
    gen_airframe: Airframe
    rec_airframe: Airframe
    winch: WinchElectrics
    rho: float = RHO0
    g: float = G0
    tether_drag_scale: float = 1.0  #: factor on the line drag (CycleProblem.tether_drag_scale)
    drive: ElectricDrive | None = None  #: the 6-DOF glider's drive (propeller model "engine")
    line_weight: bool = False  #: the glider carries its share of the line's weight (CycleProblem.line_weight)
    #: full fold (and unfold) travel [s] at the start (end) of recovery; 0: instantaneous switch
    #: (always 0 when the recovery form is the generation form)
    fold_time: float = 0.0
    #: the motor's on-fraction is a control of both phases (module docstring)
    motor_off: bool = False
    #: wind speed over height (module docstring); the blocks' wind is the reference height's
    wind_profile: WindProfile = WindProfile()
    #: the glider's share of the drag of the whole line moving like it (line model, module
    #: docstring): the straight line's 1/4, or the calibrated model's
    line_drag_share: float = STRAIGHT_DRAG_SHARE
    #: the glider's share of the drag of the whole line standing still in the wind (0: the
    #: straight line, which leaves it out)
    line_wind_share: float = 0.0
    #: the line's weight the glider carries per metre of paid-out line [N/m] (None: the winch's
    #: ``line_weight_per_length``, the straight line's share)
    line_weight_per_length: float | None = None
    #: the line tension at the winch while reeling in [N] (calibrated model; 0: the slack
    #: straight line): the reel-in pays it
    line_recovery_tension: float = 0.0
    #: the line's tension in recovery is a control >= 0 the winch's motor holds (module docstring)
    recovery_tension: bool = False

    @classmethod
    def build(cls, problem: CycleProblem, glider: Glider, winch: WinchElectrics) -> "CycleModel":
        foldable = problem.config == "foldable"
        rec = glider.folded if foldable else glider.unfolded
        volts = getattr(problem, "supply_voltage", None)
        if volts is not None:
            winch = winch.with_supply_voltage(volts)
        spec = problem.scenario_spec
        aircraft = getattr(problem, "aircraft", None)  # the problem's (None: the package's glider)
        drive = load_electric_drive(aircraft) if spec.propeller == "engine" else None
        fold_time = 0.0
        if foldable:
            t = getattr(problem, "fold_time", None)
            fold_time = definition_fold_time(aircraft) if t is None else float(t)
        line: dict[str, Any] = {}
        if getattr(problem, "line_model", "straight") == "calibrated":
            a, b, c, g_rec = winch.calibrated_line(problem.config)
            line = {"line_drag_share": float(a), "line_wind_share": float(c),
                    "line_weight_per_length": float(b) * winch.line_weight_total_per_length,
                    "line_recovery_tension": float(g_rec)}
        return cls(spec, glider.unfolded, rec, winch, tether_drag_scale=problem.tether_drag_scale, drive=drive,
                   line_weight=problem.line_weight, fold_time=fold_time, motor_off=spec.propeller in MOTOR_OFF_MODELS,
                   wind_profile=getattr(problem, "wind_profile", None) or WindProfile(),
                   recovery_tension=getattr(problem, "recovery_tension", None) == "free" and spec.electrical, **line)

    @property
    def gen_controls(self) -> tuple[str, ...]:
        if self.scenario.tension_control:  # the paper's free tension, or the ideal generator's
            base: tuple[str, ...] = ("alpha", "phi", "T", "G")
        elif self.scenario.generator == "boost":
            base = ("alpha", "phi", "T", BOOST_DUTY)
        else:
            base = ("alpha", "phi", "T")
        return base + ((ON_FRACTION,) if self.motor_off else ())

    def boost_duty(self, u: Sequence[Any]) -> Any:
        """The T2 duty in generation controls ``u`` (None: not a control, the definition's
        default duty applies)."""
        return u[3] if self.scenario.generator == "boost" and not self.scenario.tension_control else None

    @property
    def rec_controls(self) -> tuple[str, ...]:
        return ("alpha", "phi", "T", "v_reel") + (("G",) if self.recovery_tension else ()) + \
            ((ON_FRACTION,) if self.motor_off else ())

    def full_controls(self, index: int, u: Sequence[Any]) -> Sequence[Any]:
        """Controls ``u`` of phase ``index`` with the recovery's tension ``G = 0`` inserted where
        it is a control and ``u`` is given without it (shorter than :meth:`controls`: the slack
        model's controls, with or without the on-fraction)."""
        if index == 1 and self.recovery_tension and 4 <= len(u) < len(self.rec_controls):
            return [*u[:4], 0.0, *u[4:]]
        return u

    def recovery_pull(self, u: Sequence[Any]) -> Any:
        """The line's tension [N] in recovery controls ``u``: the control ``G`` where the
        recovery tension is free (0 for controls given without it), else 0."""
        return self.full_controls(1, u)[4] if self.recovery_tension else 0.0

    def controls(self, index: int) -> tuple[str, ...]:
        """Control names of phase ``index`` (0 generation, 1 recovery)."""
        return self.gen_controls if index == 0 else self.rec_controls

    @property
    def folds(self) -> bool:
        """The wing takes time to fold: recovery starts and ends with a transition."""
        return self.fold_time > 0.0 and self.rec_airframe is not self.gen_airframe

    def fold_fraction(self, t: float, T2: float) -> float:
        """Fold state at time ``t`` [s] into a recovery of ``T2`` [s] (:func:`fold_fraction`;
        1 throughout for an instantaneous fold, 0 for the nominal glider)."""
        if self.rec_airframe is self.gen_airframe:
            return 0.0
        return fold_fraction(t, T2, self.fold_time)

    def on_fraction(self, index: int, u: Sequence[Any]) -> Any:
        """The motor's on-fraction in controls ``u`` of phase ``index``: None without the mode,
        and for controls given without it (the motor runs throughout)."""
        n = len(self.controls(index))
        u = self.full_controls(index, u)
        return u[n - 1] if self.motor_off and len(u) >= n else None

    def mean_thrust(self, index: int, u: Sequence[Any]) -> Any:
        """Thrust [N] the glider flies with controls ``u``: ``s T_on`` in the motor-off mode, else ``T``."""
        s = self.on_fraction(index, u)
        return u[2] if s is None else s * u[2]

    def wind_at(self, wind: Sequence[Any], z: Any) -> tuple[Any, ...]:
        """Horizontal wind (north, east) [m/s] at NED height ``z`` [m] (``h = -z``) from the
        reference height's ``wind`` (the same objects for the uniform profile)."""
        return self.wind_profile.wind_at((wind[0], wind[1]), -z)

    def distance_rate(self, x: Sequence[Any], wind: Sequence[Any]) -> Any:
        """The glider's distance rate ``ddot`` [m/s] at state ``x`` (its first six entries) in the
        reference height's ``wind`` (north, east) [m/s], met at the glider's height."""
        return self._pm(self.gen_airframe, self.wind_at(wind, x[2])).distance_rate(x)

    def _line_wind_offset(self, wind: Sequence[Any], z: Any) -> tuple[Any, Any] | None:
        """The glider's wind minus the line's (:func:`fdm_awe.wind.line_height`) [m/s], north and
        east, at NED height ``z`` [m]; None for the uniform profile (no difference)."""
        if self.wind_profile.uniform:
            return None
        h = -z
        f = self.wind_profile.factor(h) - self.wind_profile.factor(line_height(h))
        return (wind[0] * f, wind[1] * f)

    def _pm(self, af: Airframe, wind: Sequence[Any]) -> PointMassModel:
        env = Environment(self.rho, self.g, (wind[0], wind[1], 0.0))
        return PointMassModel(af.mass.mass, af.aero, env)

    def _tether_drag(self, aero: AeroParams, x: Sequence[Any], d: Any, length: Any, drag_factor: Any,
                     dw: tuple[Any, Any] | None = None) -> tuple[Any, Any]:
        """Tether line drag as (extra drag coefficient along the airspeed, extra tether-direction
        force [N], > 0 towards the winch).

        The glider carries a quarter of the line drag ``0.5 rho C_D_perp d_t l |v_n| v_n`` with
        ``v_n`` the glider's air velocity normal to the line (the straight-line model the ground
        station uses): ``-k |v_n| v_n = -k |v_n| V c1 + k |v_n| v_r e_r`` with
        ``k = q S C_D,t / V^2``, ``C_D,t = C_D_perp d_t l / (4 S)``
        (:func:`fdm_awe.pointmass.aero.tether_drag_coefficient`) and ``v_r`` the air velocity along
        ``e_r = P/|P|``. Motion along the line (reeling, flying straight at the winch) causes no
        line drag.

        Wind profile: the line sees the wind at :data:`fdm_awe.wind.LINE_HEIGHT_FRACTION` of the
        glider's height (where the share the glider carries is centred), not the glider's, so
        its air velocity at the glider end is ``V c1 + dw`` with ``dw`` the glider's wind minus
        the line's (:meth:`_line_wind_offset`; None for a uniform wind): ``|v_n|`` and ``v_r``
        are the line's. The force keeps its two directions ``c1`` (drag coefficient) and
        ``e_r``; the part ``-k |v_n| dw`` along the wind is left out (``dw`` is a few per cent
        of the airspeed: 0.4 m/s at 120 m in a log profile with z0 = 0.1 m and 8 m/s at 10 m).
        """
        if not self.scenario.tether_drag:
            return 0.0, 0.0
        w = self.winch
        cdt = drag_factor * self.tether_drag_scale * tether_drag_coefficient(length, w.tether_diameter, w.tether_cd_perp, aero.S)
        if self.line_drag_share != STRAIGHT_DRAG_SHARE:  # the calibrated line model's share
            cdt = cdt * (self.line_drag_share / STRAIGHT_DRAG_SHARE)
        V, gamma, psi = x[3], x[4], x[5]
        cg = mo.cos(gamma)
        va = (V * cg * mo.cos(psi), V * cg * mo.sin(psi), -V * mo.sin(gamma))
        v_r = (x[0] * va[0] + x[1] * va[1] + x[2] * va[2]) / d
        if dw is None:
            v_n = mo.sqrt(V * V - v_r * v_r + TETHER_VN_EPS**2)
        else:  # the line's air velocity at the glider end: V c1 + dw
            vl = (va[0] + dw[0], va[1] + dw[1], va[2])
            vl_r = (x[0] * vl[0] + x[1] * vl[1] + x[2] * vl[2]) / d
            v_n = mo.sqrt(vl[0] * vl[0] + vl[1] * vl[1] + vl[2] * vl[2] - vl_r * vl_r + TETHER_VN_EPS**2)
            v_r = vl_r
        k = 0.5 * self.rho * aero.S * cdt
        return cdt * v_n / V, -k * v_n * v_r

    def _line_weight(self, length: Any) -> Any:
        """Downward force [N] of the line's weight share on the glider at paid-out ``length`` [m]."""
        if not self.line_weight:
            return 0.0
        per_m = self.winch.line_weight_per_length if self.line_weight_per_length is None else self.line_weight_per_length
        return per_m * length

    def _line_wind_force(self, x: Sequence[Any], d: Any, length: Any, wind: Sequence[Any], drag_factor: Any) -> list[Any] | None:
        """The glider's share of the drag of the whole line standing still in the wind, NED [N]
        (the calibrated line model; None where the model has none):
        ``c 0.5 rho C_D_perp d_t l |w_n| w_n`` with ``c`` :attr:`line_wind_share`, ``l`` the
        paid-out ``length`` [m] and ``w_n`` the wind normal to the line (the wind at the line's
        height, :func:`fdm_awe.wind.line_height`, for a profile; ``wind`` the reference height's,
        north and east [m/s]); ``drag_factor`` and the line-drag factor scale it with the line's
        other drag. It pushes the glider downwind, normal to the line; the straight line's share,
        taken from the glider's air velocity, leaves it out."""
        if self.line_wind_share <= 0.0 or not self.scenario.tether_drag:
            return None
        w = self.winch
        wx, wy = self.wind_profile.wind_at((wind[0], wind[1]), line_height(-x[2]))
        w_r = (x[0] * wx + x[1] * wy) / d  # the wind along the line (away from the winch)
        w_n = (wx - w_r * x[0] / d, wy - w_r * x[1] / d, -w_r * x[2] / d)
        mag = mo.sqrt(w_n[0] * w_n[0] + w_n[1] * w_n[1] + w_n[2] * w_n[2] + TETHER_VN_EPS**2)
        k = drag_factor * self.tether_drag_scale * self.line_wind_share * 0.5 * self.rho * w.tether_cd_perp * w.tether_diameter
        return [k * length * mag * c for c in w_n]

    def _thrust_power(self, T: Any, V: Any, s: Any = None) -> Any:
        """Drive power [W] at thrust ``T`` (while the motor runs) and airspeed ``V``; ``s`` the
        on-fraction (None: the motor runs throughout)."""
        prop = self.gen_airframe.propulsion
        if s is None:
            return thrust_power(T, V, prop, self.rho, self.scenario.propeller, self.drive)
        return duty_cycled_power(T, s, V, prop, self.rho, self.scenario.propeller, self.drive)

    def generation(self, s: Sequence[Any], u: Sequence[Any], wind: Sequence[Any], drag_factor: Any = 1.0) -> dict[str, Any]:
        """Phase-1 block: ``f`` (6 derivatives), ``G`` [N], ``v_reel`` = ddot [m/s], ``d`` [m],
        powers ``P_gen``, ``P_thr``, ``P_rw`` [W]."""
        x = list(s[:6])
        dw = self._line_wind_offset(wind, x[2])
        pm = self._pm(self.gen_airframe, self.wind_at(wind, x[2]))
        d = mo.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2])
        ddot = self.distance_rate(x, wind)
        duty = self.boost_duty(u)
        if self.scenario.tension_control:
            G = u[3]
        else:
            G = generator_tension(ddot, self.winch, duty)
        cd_t, G_t = self._tether_drag(self.gen_airframe.aero, x, d, d, drag_factor, dw)
        on = self.on_fraction(0, u)
        f = pm.dynamics(x, (u[0], u[1], self.mean_thrust(0, u), G + G_t), cd_t, self._line_weight(d),
                        self._line_wind_force(x, d, d, wind, drag_factor))
        if self.scenario.electrical and self.scenario.generator == "ideal":
            P_gen = ideal_generator_power(G, ddot, self.winch)
        elif self.scenario.electrical:
            P_gen = generator_load_power(ddot, self.winch, duty)
        else:
            P_gen = mechanical_tether_power(G, ddot)
        return {"f": f, "G": G, "v_reel": ddot, "d": d, "l": d, "P_gen": P_gen,
                "P_thr": self._thrust_power(u[2], x[3], on), "P_rw": 0.0 * x[3]}

    def rec_aero(self, morph: Any = 1.0) -> AeroParams:
        """Recovery aerodynamics; ``morph`` in [0, 1] blends unfolded (0) into the recovery
        form (1) parameter by parameter. Intermediate values serve only as a homotopy path."""
        if isinstance(morph, (int, float)) and morph == 1.0 or self.rec_airframe is self.gen_airframe:
            return self.rec_airframe.aero
        a, b = self.gen_airframe.aero, self.rec_airframe.aero
        return AeroParams(**{f.name: (1 - morph) * getattr(a, f.name) + morph * getattr(b, f.name) for f in fields(AeroParams)})

    def fold_aero(self, fold: Any = None, morph: Any = 1.0) -> AeroParams:
        """Recovery aerodynamics at fold state ``fold`` (None or 1: the recovery form,
        :meth:`rec_aero`; below 1 the 6-DOF model's blend of the unfolded wing with it,
        :func:`fdm_awe.pointmass.aero.fold_blend`)."""
        rec = self.rec_aero(morph)
        if fold is None or (isinstance(fold, (int, float)) and fold == 1.0) or self.rec_airframe is self.gen_airframe:
            return rec
        return fold_blend(self.gen_airframe.aero, rec, fold)

    def recovery(self, s: Sequence[Any], u: Sequence[Any], wind: Sequence[Any], drag_factor: Any = 1.0,
                 morph: Any = 1.0, fold: Any = None) -> dict[str, Any]:
        """Phase-2 block: ``f`` (7 derivatives incl. ``ldot``), ``G`` = 0, ``v_reel``, ``d``,
        ``l`` [m], powers [W]. ``morph`` see :meth:`rec_aero`; ``fold`` the fold state
        (:meth:`fold_aero`; None: folded)."""
        af = self.rec_airframe
        aero = self.fold_aero(fold, morph)
        x = list(s[:6])
        dw = self._line_wind_offset(wind, x[2])
        w = self.wind_at(wind, x[2])
        env = Environment(self.rho, self.g, (w[0], w[1], 0.0))
        pm = PointMassModel(af.mass.mass, aero, env)
        l = s[6]
        d = mo.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2])
        v_reel = u[3]
        cd_t, G_t = self._tether_drag(aero, x, d, l, drag_factor, dw)
        G = self.recovery_pull(u)
        f = pm.dynamics(x, (u[0], u[1], self.mean_thrust(1, u), G + G_t), cd_t, self._line_weight(l),
                        self._line_wind_force(x, d, l, wind, drag_factor))
        if self.scenario.electrical:
            P_rw = motor_supply_power(v_reel, self.winch, G + self.line_recovery_tension)
        else:
            P_rw = self.scenario.P_rw + 0.0 * x[3]
        return {"f": [*f, v_reel], "G": G + 0.0 * x[3], "v_reel": v_reel, "d": d, "l": l, "P_gen": 0.0 * x[3],
                "P_thr": self._thrust_power(u[2], x[3], self.on_fraction(1, u)), "P_rw": P_rw}

    def phase(self, index: int):
        """The block of phase ``index`` (0 generation, 1 recovery)."""
        return self.generation if index == 0 else self.recovery

    def alpha_lower(self, index: int, alpha_max: float, cl_margin: float = 1.0, aero: AeroParams | None = None) -> float:
        """Lower bound on alpha [rad]: -alpha_max (Table 3), tightened by the negative stall
        C_L >= -C_Lmax if enabled (the aircraft definitions clip C_L there) and by
        C_L >= -cl_margin C_Lmax of the phase's own wing when ``cl_margin`` < 1 (a reference to
        be flown keeps the same margin from the negative stall as from the positive one).
        ``aero``: the wing of a fold transition instead of the phase's own."""
        a = aero if aero is not None else (self.gen_airframe if index == 0 else self.rec_airframe).aero
        lo = -alpha_max
        if self.scenario.stall_limit:
            lo = max(lo, (-a.CLmax - a.CL0) / a.CLalpha)
        if cl_margin < 1.0:
            lo = max(lo, (-cl_margin * a.CLmax - a.CL0) / a.CLalpha)
        return lo

    def alpha_upper(self, index: int, alpha_max: float, cl_margin: float = 1.0, aero: AeroParams | None = None) -> float:
        """Upper bound on alpha [rad]: Table 3's bound, tightened by C_L <= C_Lmax if enabled,
        and by C_L <= cl_margin C_Lmax of the phase's own wing when ``cl_margin`` < 1.
        ``aero``: the wing of a fold transition instead of the phase's own."""
        a = aero if aero is not None else (self.gen_airframe if index == 0 else self.rec_airframe).aero
        hi = min(alpha_max, a.alpha_max_lift) if self.scenario.stall_limit else alpha_max
        if cl_margin < 1.0:
            hi = min(hi, (cl_margin * a.CLmax - a.CL0) / a.CLalpha)
        return hi
