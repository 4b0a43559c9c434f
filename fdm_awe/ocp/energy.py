"""Power terms of the pumping cycle [W] for both scenario families.

Every function evaluates on floats, NumPy arrays and CasADi symbols (via :mod:`fdm_awe.pointmass.mathops`),
so the optimiser's quadrature and the independent re-integration use the same definitions.

Quasi-static winch + DC machine + converter (paper eqs. 14-19 with ``di/dt = 0``,
``domega/dt = 0``, one Coulomb friction ``M_c``, docs/design.md sections 4.8, 5 and 6):

- generation, passive rectifier into ``R_L``: ``omega = v_reel / r_w``,
  ``i = max(0, K_e omega - 2 U_d) / (R + R_L)``, tension ``G = (M_c + B omega + K_t i) / r_w``,
  energy into the load ``P_load = R_L i^2``;
- generation with the T2 duty ``d2`` (eq. 18, averaged boost): the same with the load the
  armature sees, ``R_eff = (1 - d2)^2 R_load``: a larger duty brakes harder at a given speed and
  puts a larger share of the power into the armature resistance (``P_load = R_eff i^2``);
- generation through an ideal converter (a bound, not the half-bridge): any tension ``G``; the
  current follows from the drum's torque balance, ``i = (r_w G - M_c - B omega) / K_t``, and the
  converter delivers ``(K_e omega - 2 U_d) i - R i^2``;
- recovery, motor reels in at ``v_reel < 0`` against friction and the line's tension ``G``
  (0 on a slack tether; a control where the recovery tension is free):
  ``i = (r_w G + M_c + B |omega|) / K_t``, supply power ``P_supply = (K_e |omega| + R i + 2 U_d) i``;
  the speed is limited by full duty: ``K_e |omega| + R i + 2 U_d <= V_a``.

The diode threshold ``max(0, .)`` is smoothed as ``(a + sqrt(a^2 + eps^2)) / 2`` with
``eps = 0.02 V`` (current error below 5 mA) so the optimiser sees a smooth problem.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

from ..groundstation import load_ground_station
from ..groundstation.steady import motor_steady
from ..pointmass import mathops as mo
from ..definitions.aircraft import PropulsionParams
from ..pointmass.propeller import power as propeller_power

#: smoothing voltage of the rectifier's conduction threshold [V]
DIODE_EPS_V = 0.02


@dataclass(frozen=True)
class WinchElectrics:
    """Ground-station values the cycle's energy accounting needs (SI)."""

    r_w: float  #: drum radius [m]
    B: float  #: viscous friction [N m s]
    M_c: float  #: Coulomb friction torque [N m]
    K_e: float  #: back-emf constant [V s/rad]
    K_t: float  #: torque constant [N m/A]
    R: float  #: armature resistance [ohm]
    U_d: float  #: voltage drop of one diode/switch [V]
    V_a: float  #: supply voltage in motor mode [V]
    R_L: float  #: load resistance the armature sees with the definition's default T2 duty: (1 - d2)^2 R_load [ohm]
    tether_diameter: float  #: [m]
    tether_cd_perp: float  #: tether drag coefficient normal to the line [-]
    #: weight per metre of paid-out line the glider carries: weight share x mass per length x g [N/m]
    line_weight_per_length: float = 0.0
    gs_params: Any = None  #: the full ground-station parameters, when read from the definition
    R_load: float | None = None  #: the load resistor itself [ohm] (None: R_L, a definition without boost duty)
    boost_duty_max: float = 0.0  #: largest T2 duty of the generator mode [-] (the converter definition's)
    #: weight per metre of the whole paid-out line, mass per length x g [N/m]
    line_weight_total_per_length: float = 0.0
    #: the calibrated line model per glider configuration (the definition's ``tether/calibrated``:
    #: :attr:`fdm_awe.groundstation.definitions.TetherParams.calibrated`)
    calibrated: tuple = ()

    @classmethod
    def from_ground_station(cls, params: Any = None, line: str | None = None) -> "WinchElectrics":
        """Values from the ground-station parameters ``params`` (a
        :class:`~fdm_awe.groundstation.definitions.GroundStationParams`, whose tether is used as
        it is), or from the definition ``tether/ground_station.xml`` with the tether line ``line``
        (:data:`fdm_awe.groundstation.line.LINES`; None: the definition's default, ``sized``).
        A :class:`~fdm_awe.ocp.problem.CycleProblem` names its line (``problem.line``)."""
        if params is not None and line is not None:
            raise ValueError("from_ground_station: give params or line, not both (params carry their own line)")
        gs = load_ground_station(line=line) if params is None else params
        w, m, c, t = gs.winch, gs.machine, gs.converter, gs.tether
        return cls(r_w=w.radius, B=w.viscous_friction, M_c=w.coulomb_friction, K_e=m.k, K_t=m.k, R=m.resistance,
                   U_d=c.device_drop, V_a=c.supply_voltage, R_L=(1.0 - c.boost_duty) ** 2 * c.load_resistance, tether_diameter=t.diameter,
                   tether_cd_perp=t.cd_perpendicular, line_weight_per_length=t.weight_share * t.mass_per_length * t.gravity,
                   gs_params=gs, R_load=c.load_resistance, boost_duty_max=c.boost_duty_max,
                   line_weight_total_per_length=t.mass_per_length * t.gravity,
                   calibrated=tuple(getattr(t, "calibrated", ())))

    def with_supply_voltage(self, volts: float) -> "WinchElectrics":
        """The same winch on a supply of ``volts`` [V] (the ground-station parameters too, when
        at hand)."""
        gs = self.gs_params
        if gs is not None:
            gs = replace(gs, converter=replace(gs.converter, supply_voltage=float(volts)))
        return replace(self, V_a=float(volts), gs_params=gs)

    @property
    def R_sum(self) -> float:
        return self.R + self.R_L

    def calibrated_line(self, config: str) -> tuple[float, float, float, float]:
        """The calibrated line model of glider configuration ``config``: drag, weight and wind
        shares [-] and the recovery tension [N] (the straight line's where none is defined)."""
        for c, *values in self.calibrated:
            if c == config:
                return tuple(values)  # type: ignore[return-value]
        return (0.25, 0.5, 0.0, 0.0)

    def reel_in_speed_max(self) -> float:
        """Largest reel-in speed [m/s] the motor reaches at full duty with a slack tether."""
        omega = (self.V_a - 2 * self.U_d - self.R * self.M_c / self.K_t) / (self.K_e + self.R * self.B / self.K_t)
        return max(omega, 0.0) * self.r_w


def problem_winch(problem: Any) -> WinchElectrics:
    """The :class:`WinchElectrics` of a :class:`~fdm_awe.ocp.problem.CycleProblem`: its ground
    station (``problem.ground_station``; None: the package's) with its tether line."""
    from ..groundstation.source import station_params

    return WinchElectrics.from_ground_station(station_params(getattr(problem, "ground_station", None), problem.line))


def smooth_pos(a: Any, eps: float) -> Any:
    """Smooth ``max(0, a)``: ``(a + sqrt(a^2 + eps^2)) / 2``."""
    return 0.5 * (a + mo.sqrt(a * a + eps * eps))


def load_seen(w: WinchElectrics, boost_duty: Any = None) -> Any:
    """Load resistance [ohm] the armature sees: ``(1 - d2)^2 R_load`` with T2 duty ``boost_duty``
    (None: the definition's default duty, ``w.R_L``)."""
    if boost_duty is None:
        return w.R_L
    R_load = w.R_L if w.R_load is None else w.R_load
    return (1 - boost_duty) * (1 - boost_duty) * R_load


def generator_current(v_reel: Any, w: WinchElectrics, boost_duty: Any = None) -> Any:
    """Armature current [A] of the generator at reel-out speed ``v_reel`` [m/s]: passive
    rectifier, or boost with T2 duty ``boost_duty`` (None: the definition's default)."""
    omega = v_reel / w.r_w
    return smooth_pos(w.K_e * omega - 2 * w.U_d, DIODE_EPS_V) / (w.R + load_seen(w, boost_duty))


def generator_tension(v_reel: Any, w: WinchElectrics, boost_duty: Any = None) -> Any:
    """Tether tension [N] that holds the winch at reel-out speed ``v_reel`` [m/s] (quasi-static)
    with T2 duty ``boost_duty`` (None: the definition's default)."""
    omega = v_reel / w.r_w
    return (w.M_c + w.B * omega + w.K_t * generator_current(v_reel, w, boost_duty)) / w.r_w


def generator_load_power(v_reel: Any, w: WinchElectrics, boost_duty: Any = None) -> Any:
    """Electrical power into the load resistor [W] at reel-out speed ``v_reel`` [m/s] with T2
    duty ``boost_duty`` (None: the definition's default)."""
    i = generator_current(v_reel, w, boost_duty)
    return load_seen(w, boost_duty) * i * i


def ideal_generator_current(G: Any, v_reel: Any, w: WinchElectrics) -> Any:
    """Armature current [A] that holds tension ``G`` [N] at reel-out speed ``v_reel`` [m/s] (the
    drum's torque balance; an ideal converter sets it)."""
    omega = v_reel / w.r_w
    return (w.r_w * G - w.M_c - w.B * omega) / w.K_t


def ideal_generator_power(G: Any, v_reel: Any, w: WinchElectrics) -> Any:
    """Electrical power [W] a loss-free converter delivers holding tension ``G`` [N] at reel-out
    speed ``v_reel`` [m/s]: ``(K_e omega - 2 U_d) i - R i^2``, ``i`` from
    :func:`ideal_generator_current` (the machine's friction, copper and device losses kept)."""
    omega = v_reel / w.r_w
    i = ideal_generator_current(G, v_reel, w)
    return (w.K_e * omega - 2 * w.U_d) * i - w.R * i * i


def motor_supply_power(v_reel: Any, w: WinchElectrics, G: Any = 0.0) -> Any:
    """Power drawn from the supply [W] reeling in at ``v_reel <= 0`` [m/s] against line tension
    ``G`` [N] (0: a slack tether).

    Uses :func:`fdm_awe.groundstation.steady.motor_steady` when the ground-station definition
    is at hand (the same relation the co-simulation's ground station is built on).
    """
    if w.gs_params is not None:
        return motor_steady(-v_reel, G, w.gs_params).p_supply
    return motor_voltage(v_reel, w, G) * motor_current(v_reel, w, G)


def motor_current(v_reel: Any, w: WinchElectrics, G: Any = 0.0) -> Any:
    """Armature current [A] reeling in at ``v_reel <= 0`` [m/s] against friction and line
    tension ``G`` [N] (0: a slack tether)."""
    omega_abs = -v_reel / w.r_w
    return (w.r_w * G + w.M_c + w.B * omega_abs) / w.K_t


def motor_voltage(v_reel: Any, w: WinchElectrics, G: Any = 0.0) -> Any:
    """Mean armature-side voltage [V] the converter must apply reeling in at ``v_reel <= 0``
    against line tension ``G`` [N]."""
    omega_abs = -v_reel / w.r_w
    return w.K_e * omega_abs + w.R * motor_current(v_reel, w, G) + 2 * w.U_d


def reel_in_speed_loss(w: WinchElectrics) -> float:
    """How much the full-duty reel-in speed falls per newton of line tension [m/s per N]: the
    armature's resistive drop ``R r_w G / K_t`` taken from the speed (the slope of
    :func:`fdm_awe.groundstation.steady.motor_max_reel_in_speed` in the tension)."""
    return w.r_w * w.r_w * w.R / (w.K_t * w.K_e + w.R * w.B)


def thrust_power(T: Any, V: Any, prop: PropulsionParams, rho: float, scenario: str, drive: Any = None) -> Any:
    """Electrical power of the glider's propeller drive [W] (:func:`fdm_awe.pointmass.propeller.power`;
    model ``engine`` needs ``drive``, an :class:`fdm_awe.definitions.engine.ElectricDrive`)."""
    return propeller_power(T, V, prop, rho, scenario, drive)


def motor_off_power(prop: PropulsionParams) -> float:
    """Electrical power [W] of the glider with its motor stopped: the constant draw ``P0``
    (avionics, ESC). In the 6-DOF model (``engine/glider_motor.xml`` with ``prop_9x5.xml``)
    zero throttle makes the ESC brake the propeller to a stop within ~0.9 s; the stopped
    blades fold (the propeller tables are zero beyond J = 1.1), so the stopped drive gives no
    thrust, no drag and draws no motor power (the flight books ``P0`` on top, as here). The
    spin-down itself brakes the glider briefly (up to ~2 N at 20 m/s): a cost of each switch,
    not modelled."""
    return prop.P0


def duty_cycled_power(T_on: Any, s: Any, V: Any, prop: PropulsionParams, rho: float, scenario: str,
                      drive: Any = None) -> Any:
    """Mean electrical power [W] of a drive that runs a share ``s`` in [0, 1] of the time at
    thrust ``T_on`` [N] (airspeed ``V`` [m/s]) and is stopped otherwise (motor-off mode):
    ``s P_on(T_on, V) + (1 - s) P_off`` with :func:`thrust_power` and :func:`motor_off_power`.
    The convex hull of the running and the stopped drive; ``s = 1`` is :func:`thrust_power`
    exactly."""
    return s * thrust_power(T_on, V, prop, rho, scenario, drive) + (1 - s) * motor_off_power(prop)


def mechanical_tether_power(G: Any, ddot: Any) -> Any:
    """Mechanical power delivered to the winch ``G ddot`` [W] (docs/design.md 4.5)."""
    return G * ddot


def design_reference_generator(w: WinchElectrics, G: float) -> dict[str, float]:
    """Closed-form steady generator point at tension ``G`` [N] (docs/design.md section 6), unsmoothed."""
    omega = (w.r_w * G - w.M_c + 2 * w.U_d * w.K_t / w.R_sum) / (w.B + w.K_t * w.K_e / w.R_sum)
    i = (w.K_e * omega - 2 * w.U_d) / w.R_sum
    return {"omega": omega, "v_reel": omega * w.r_w, "i": i, "P_load": w.R_L * i * i, "P_mech": G * omega * w.r_w,
            "efficiency": w.R_L * i * i / (G * omega * w.r_w) if omega > 0 else math.nan}
