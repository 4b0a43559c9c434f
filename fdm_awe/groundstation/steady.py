"""Quasi-static (steady-state) relations of the ground station, for NumPy AND CasADi.

Written with plain arithmetic only (``+ - * /``; no branches, no ``max``, no numpy functions)
so every argument may be a float, a NumPy array or a CasADi ``SX``/``MX`` symbol. The formulas
hold inside their operating region, which is stated per function; checking it (e.g. as an
OCP constraint) is the caller's job.

Sign conventions: tension ``G >= 0`` N; reel-out speed > 0 in :func:`generator_steady`;
``reel_in_speed`` > 0 in :func:`motor_steady`. Parameters come from
:func:`fdm_awe.groundstation.load_ground_station` (floats).

Generator (passive rectifier, T2 off; or averaged boost with T2 duty ``d2``), steady drum::

    r_w G = M_c + B omega + K_t i,         K_e omega = (R + (1-d2)^2 R_L) i + 2 U_d
    omega = (r_w G - M_c + 2 U_d K_t / R_sum) / (B + K_t K_e / R_sum),  R_sum = R + (1-d2)^2 R_L

(docs/design.md section 6; valid while omega > 0 and i > 0, i.e. r_w G > M_c + B omega and
K_e omega > 2 U_d). Load power ``(1-d2)^2 R_L i^2``, mechanical power ``G r_w omega``.

Motor (reel-in at speed v, T1 duty averaged, line tension G opposing)::

    K_t i = r_w G + M_c + B omega_in,      d V_a = K_e omega_in + R i + 2 U_d,   omega_in = v / r_w

supply power ``d V_a i`` (valid while 0 <= d <= 1, i.e. the supply can deliver the voltage).
"""

from __future__ import annotations

from typing import Any, NamedTuple

from .definitions import GroundStationParams


class GeneratorSteady(NamedTuple):
    omega: Any  #: drum speed, rad/s
    reel_speed: Any  #: reel-out speed, m/s
    current: Any  #: armature current, A
    p_load: Any  #: power into R_L, W
    p_mech: Any  #: mechanical power of the line at the drum G r_w omega, W
    efficiency: Any  #: p_load / p_mech, -


class GeneratorAtSpeed(NamedTuple):
    tension: Any  #: line tension that holds the drum at that speed, N
    current: Any  #: armature current, A
    p_load: Any  #: power into R_L, W
    p_mech: Any  #: mechanical power of the line at the drum, W
    efficiency: Any  #: p_load / p_mech, -


class MotorSteady(NamedTuple):
    current: Any  #: armature current, A
    duty: Any  #: T1 duty (must lie in [0, 1]), -
    p_supply: Any  #: electrical power drawn from V_a, W
    p_mech: Any  #: mechanical power against the line G v, W
    p_loss: Any  #: copper + semiconductor + friction, W


def generator_steady(tension: Any, params: GroundStationParams, R_L: Any = None,
                     boost_duty: Any = 0.0) -> GeneratorSteady:
    """Steady generator operating point at line tension ``tension`` (N) and load ``R_L`` (ohm)."""
    w, m, c = params.winch, params.machine, params.converter
    RL = c.load_resistance if R_L is None else R_L
    s = 1.0 - boost_duty
    r_eff = s * s * RL
    r_sum = m.resistance + r_eff
    two_ud = 2.0 * c.device_drop
    omega = (w.radius * tension - w.coulomb_friction + two_ud * m.k / r_sum) / (
        w.viscous_friction + m.k * m.k / r_sum)
    i = (m.k * omega - two_ud) / r_sum
    p_load = r_eff * i * i
    p_mech = tension * w.radius * omega
    return GeneratorSteady(omega, w.radius * omega, i, p_load, p_mech, p_load / p_mech)


def generator_at_speed(reel_speed: Any, params: GroundStationParams, R_L: Any = None,
                       boost_duty: Any = 0.0) -> GeneratorAtSpeed:
    """Inverse of :func:`generator_steady`: the tension (N) that holds reel-out ``reel_speed`` (m/s).

    Handy when the OCP carries the reel speed and needs the tension it implies. Valid while
    ``K_e omega > 2 U_d`` (current flows).
    """
    w, m, c = params.winch, params.machine, params.converter
    RL = c.load_resistance if R_L is None else R_L
    s = 1.0 - boost_duty
    r_eff = s * s * RL
    omega = reel_speed / w.radius
    i = (m.k * omega - 2.0 * c.device_drop) / (m.resistance + r_eff)
    tension = (w.coulomb_friction + w.viscous_friction * omega + m.k * i) / w.radius
    p_load = r_eff * i * i
    p_mech = tension * reel_speed
    return GeneratorAtSpeed(tension, i, p_load, p_mech, p_load / p_mech)


def motor_steady(reel_in_speed: Any, tension: Any, params: GroundStationParams) -> MotorSteady:
    """Steady reel-in at ``reel_in_speed`` (m/s, > 0) against line tension ``tension`` (N)."""
    w, m, c = params.winch, params.machine, params.converter
    omega_in = reel_in_speed / w.radius
    i = (w.radius * tension + w.coulomb_friction + w.viscous_friction * omega_in) / m.k
    v_arm = m.k * omega_in + m.resistance * i + 2.0 * c.device_drop
    p_supply = v_arm * i
    p_mech = tension * reel_in_speed
    return MotorSteady(i, v_arm / c.supply_voltage, p_supply, p_mech, p_supply - p_mech)


def motor_max_reel_in_speed(tension: Any, params: GroundStationParams) -> Any:
    """The largest steady reel-in speed (m/s) at full T1 duty against line tension ``tension``
    (N): the supply voltage ``V_a`` across the armature (:func:`motor_steady` at duty 1,
    solved for the speed)::

        omega_in = (V_a - 2 U_d - R (r_w G + M_c) / K) / (K + R B / K),   v = r_w omega_in

    (11.1 m/s on a slack line with the 48 V supply of the definition file)."""
    w, m, c = params.winch, params.machine, params.converter
    drop = 2.0 * c.device_drop + m.resistance * (w.radius * tension + w.coulomb_friction) / m.k
    omega = (c.supply_voltage - drop) / (m.k + m.resistance * w.viscous_friction / m.k)
    return w.radius * omega


def motor_supply_needed(reel_in_speed: Any, tension: Any, params: GroundStationParams) -> Any:
    """The supply voltage (V) that reels in at ``reel_in_speed`` (m/s) against ``tension`` (N)
    at full duty: the armature voltage of :func:`motor_steady` (the inverse of
    :func:`motor_max_reel_in_speed`)."""
    w, m, c = params.winch, params.machine, params.converter
    omega_in = reel_in_speed / w.radius
    i = (w.radius * tension + w.coulomb_friction + w.viscous_friction * omega_in) / m.k
    return m.k * omega_in + m.resistance * i + 2.0 * c.device_drop
