"""The constraint groups of the cycle NLP (docs/design.md section 4, Table 3).

- variable bounds (:func:`state_bounds`, :func:`control_bounds`, :func:`fold_alpha_bounds`):
  airspeed, |gamma|, ground clearance (``z <= -h_min``), controls (alpha with the stall limit,
  bank, thrust, tension, reel-in speed); a fold transition interval's angle of attack is bounded
  by the stall limits of every wing it passes through;
- path constraints at the phase start and every collocation point (:func:`point_path`,
  :func:`add_path`): ``ddot >= 0`` and, where tension follows the generator, ``G`` at most
  the cycle's tension bound ``G_max / (1 + tension_margin)`` (:attr:`Bounds.G_cycle_max`: the
  rating less the margin for the catch and gusts) in generation (the ``ideal`` generator: a
  current of one direction); ``d <= l`` in recovery, and where its tension is free (a control
  ``G >= 0``) the line pulls only where it is taut (``G (l - d) <= TAUT_NM``) and the reel-in
  speed falls with the pull as the drive's full duty allows (``|v_reel| + c G <= v_in``,
  :func:`fdm_awe.ocp.energy.reel_in_speed_loss`);
  in the ``physical`` scenario the thrust at most what the propeller gives at the airspeed
  (``T <= T_avail(V)`` from the aircraft definition);
- boundaries (:func:`add_boundaries`): start position fixed, ``d(T_1) = d_tf``, continuity
  between the phases (position, airspeed, angles; tether length ``l = d_tf``), periodicity
  back to the start (airspeed, flight-path angle, heading + ``2 pi k``; ``l = d0``),
  ``T_1 + T_2 <= t_max``;
- a reference's smoothness, where its bounds ask for it (:func:`add_smoothness`): the bank's
  and the angle of attack's change between neighbouring intervals, around the whole cycle,
  within a rate; the slack line's catch at the end of recovery (:func:`add_catch`) within a
  closing speed.

Every row is scaled (divided by a typical size) and named (``CycleNLP.g_names``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import casadi as ca

from .energy import ideal_generator_current, reel_in_speed_loss
from .layout import CONTROL_SCALE, STATE_SCALE, TIME_SCALE, PhaseLayout
from .model import GEN_STATES, CycleModel
from .problem import Bounds, CycleProblem


#: how much the line may pull while it is slack in recovery (free recovery tension): tension x
#: slack length <= this [N m] (the relaxed complementarity of a pull and a slack line: 0.01 N on
#: 1 m of slack, 10 N on 1 mm)
TAUT_NM = 0.01
#: scale [m/s] of the recovery's reel-in rows (``reel_in_*``, the full-duty speed against the pull)
REEL_IN_ROW_SCALE = 5.0


@dataclass
class Constraints:
    """The NLP's constraint rows ``lo <= g <= hi`` while they are built, each with a name."""

    g: list[Any] = field(default_factory=list)
    lbg: list[float] = field(default_factory=list)
    ubg: list[float] = field(default_factory=list)
    names: list[str] = field(default_factory=list)

    def add(self, expr: Any, lo: float, hi: float, name: str) -> None:
        """One row ``lo <= expr <= hi`` (scaled)."""
        self.g.append(expr)
        self.lbg.append(lo)
        self.ubg.append(hi)
        self.names.append(name)


def state_bounds(problem: CycleProblem) -> dict[str, tuple[float, float]]:
    """Bounds of each state in value units [m, m/s, rad]: positions within ten times the end of
    generation's distance, above ``h_min``, the airspeed and flight-path-angle limits."""
    bnd, d_tf = problem.bounds, problem.d_tf
    return {
        "x": (-10 * d_tf, 10 * d_tf), "y": (-10 * d_tf, 10 * d_tf), "z": (-10 * d_tf, -bnd.h_min),
        "V": (bnd.V_min, bnd.V_max), "gamma": (-bnd.gamma_max, bnd.gamma_max), "psi": (-60.0, 60.0),
        "l": (0.0, 10 * d_tf),
    }


def reel_in_limit(model: CycleModel, bnd: Bounds) -> float:
    """The cycle's fastest reel-in [m/s]: ``bnd.reel_in_speed_max`` where set, else what the
    model's winch reaches at full duty on a slack line (its supply voltage)."""
    return bnd.reel_in_speed_max if bnd.reel_in_speed_max is not None else model.winch.reel_in_speed_max()


def control_bounds(model: CycleModel, bnd: Bounds, ip: int, T_max: float, v_in: float) -> dict[str, tuple[float, float]]:
    """Bounds of each control of phase ``ip`` in value units [rad, N, m/s, -]: angle of attack
    within the phase's stall limits, thrust up to ``T_max`` [N], reel-in speed up to ``v_in``
    [m/s], tension within ``G_min .. G_cycle_max`` in generation and ``0 .. G_cycle_max`` in recovery [N]."""
    a_hi = model.alpha_upper(ip, bnd.alpha_max, bnd.cl_margin)
    a_lo = model.alpha_lower(ip, bnd.alpha_max, bnd.cl_margin)
    return {"alpha": (a_lo, a_hi), "phi": (-bnd.phi_max, bnd.phi_max), "T": (0.0, T_max),
            "G": (bnd.G_min if ip == 0 else 0.0, bnd.G_cycle_max), "v_reel": (-v_in, 0.0), "s": (0.0, 1.0),
            "D2": (0.0, model.winch.boost_duty_max)}


def fold_alpha_bounds(model: CycleModel, bnd: Bounds, ip: int, folds: list[float]) -> tuple[float, float]:
    """Angle-of-attack bounds [rad] of an interval of a fold transition: the stall limits of
    the wing at every fold state ``folds`` the interval passes through."""
    wings = [model.fold_aero(f) for f in folds]
    return (max(model.alpha_lower(ip, bnd.alpha_max, bnd.cl_margin, a) for a in wings),
            min(model.alpha_upper(ip, bnd.alpha_max, bnd.cl_margin, a) for a in wings))


def point_path(model: CycleModel, ip: int, out: dict[str, Any], s: Any, u: Any, p: Any) -> list[Any]:
    """Path-constraint expressions of phase ``ip`` at one point (state ``s``, controls ``u``,
    NLP parameters ``p``; ``out`` the phase block's outputs), in the order :func:`add_path`
    bounds them: generation ``ddot``, ``G`` (and the ideal generator's current); recovery
    ``l - d``; the thrust margin ``T_avail(V) - T`` where the propeller limits it."""
    if ip == 0:
        path = [out["v_reel"], out["G"]]
        if model.scenario.generator == "ideal":  # the half-bridge carries one current direction
            path.append(ideal_generator_current(out["G"], out["v_reel"], model.winch))
    else:
        path = [out["l"] - out["d"]]
        if model.recovery_tension:  # the line pulls only where it is taut; the drive's speed falls with the pull
            path += [out["G"] * (out["l"] - out["d"]), -out["v_reel"] + reel_in_speed_loss(model.winch) * out["G"]]
    if model.scenario.propeller in ("physical", "engine"):
        # thrust within what the propeller gives at this airspeed (full throttle); p[6] < 1
        # blends the bound towards the static T_max (a homotopy path only)
        prop = model.gen_airframe.propulsion
        path.append(p[6] * (prop.thrust_available(s[3]) - prop.T_max) + prop.T_max - u[2])
    return path


def add_path(cs: Constraints, model: CycleModel, bnd: Bounds, ip: int, path: Any, tag: str) -> None:
    """The rows of the path expressions ``path`` (:func:`point_path`) of phase ``ip`` at the
    point named ``tag``."""
    if ip == 0:
        cs.add(path[0] / 5.0, 0.0, ca.inf, f"ddot_{tag}")
        if not model.scenario.tension_control:
            cs.add(path[1] / 30.0, bnd.G_min / 30.0, bnd.G_cycle_max / 30.0, f"G_{tag}")
        if model.scenario.generator == "ideal":
            cs.add(path[2] / 10.0, 0.0, ca.inf, f"current_{tag}")
    else:
        cs.add(path[0] / 100.0, 0.0, ca.inf, f"slack_{tag}")
        if model.recovery_tension:
            cs.add(path[1] / TAUT_NM, -ca.inf, 1.0, f"taut_{tag}")
            cs.add(path[2] / REEL_IN_ROW_SCALE, -ca.inf, reel_in_limit(model, bnd) / REEL_IN_ROW_SCALE, f"reel_in_{tag}")
    if model.scenario.propeller in ("physical", "engine"):
        cs.add(path[-1] / 5.0, 0.0, ca.inf, f"thrust_avail_{tag}")


def add_boundaries(cs: Constraints, problem: CycleProblem, gen: PhaseLayout, rec: PhaseLayout, d: int,
                   kwrap: Any) -> None:
    """The rows of the cycle's boundaries (module docstring): start, end of generation,
    continuity between the phases, periodicity (heading up to ``2 pi kwrap``), total duration."""
    P0 = problem.start_position
    x0 = gen.X[0][0]
    xe1 = gen.X[-1][d]
    x20 = rec.X[0][0]
    xe2 = rec.X[-1][d]
    for i in range(3):
        cs.add((x0[i] - P0[i]) / 100.0, 0.0, 0.0, f"start_{GEN_STATES[i]}")
    d_end = ca.sqrt(xe1[0] ** 2 + xe1[1] ** 2 + xe1[2] ** 2)
    cs.add((d_end - problem.d_tf) / 100.0, 0.0, 0.0, "d_tf")
    for i, s in enumerate(GEN_STATES):
        cs.add((x20[i] - xe1[i]) / STATE_SCALE[s], 0.0, 0.0, f"continuity_{s}")
    cs.add((x20[6] - problem.d_tf) / 100.0, 0.0, 0.0, "continuity_l")
    for i in range(3):
        cs.add((xe2[i] - P0[i]) / 100.0, 0.0, 0.0, f"periodic_{GEN_STATES[i]}")
    cs.add((xe2[3] - x0[3]) / 10.0, 0.0, 0.0, "periodic_V")
    cs.add(xe2[4] - x0[4], 0.0, 0.0, "periodic_gamma")
    cs.add(xe2[5] - x0[5] - 2 * math.pi * kwrap, 0.0, 0.0, "periodic_psi")
    cs.add((xe2[6] - problem.d0) / 100.0, 0.0, 0.0, "periodic_l")
    cs.add((gen.T + rec.T) / TIME_SCALE, 0.0, problem.bounds.t_max / TIME_SCALE, "t_max")


def add_smoothness(cs: Constraints, bnd: Bounds, gen: PhaseLayout, rec: PhaseLayout) -> None:
    """The rows of the reference's rate bounds (:attr:`Bounds.bank_rate_max`,
    :attr:`Bounds.alpha_rate_max`): between neighbouring intervals ``a`` and ``b`` of the cycle
    (generation, recovery, and from the recovery's last back to the generation's first, as the
    cycles follow each other) ``|u_b - u_a| <= rate (h_a + h_b) / 2`` with ``h`` the intervals'
    lengths [s]."""
    for name, rate in (("phi", bnd.bank_rate_max), ("alpha", bnd.alpha_rate_max)):
        if rate is None:
            continue
        seq = []
        for ip, ph in enumerate((gen, rec)):
            i = ph.controls.index(name)
            hs = ph.lengths(ph.T)
            seq += [(ph.U[k][i], hs[k], f"p{ip}_{k}") for k in range(ph.n)]
        sc = CONTROL_SCALE[name]
        for a in range(len(seq)):
            (ua, ha, tag), (ub, hb, _) = seq[a], seq[(a + 1) % len(seq)]
            step, reach = (ub - ua) / sc, rate * 0.5 * (ha + hb) / sc
            cs.add(step - reach, -ca.inf, 0.0, f"rate_{name}_up_{tag}")
            cs.add(step + reach, 0.0, ca.inf, f"rate_{name}_down_{tag}")


def add_catch(cs: Constraints, model: CycleModel, bnd: Bounds, rec: PhaseLayout, d: int, wind: Any) -> None:
    """The row of the line's catch (:attr:`Bounds.catch_speed_max`): at the end of recovery
    the glider's distance rate minus the reel speed of the last interval [m/s] (the speed at
    which the slack closes as the line goes taut) at most the bound; ``wind`` the NLP's wind
    parameters (north, east) [m/s]."""
    if bnd.catch_speed_max is None:
        return
    xe = rec.X[-1][d]
    closing = model.distance_rate(xe[:6], wind) - rec.U[-1][rec.controls.index("v_reel")]
    cs.add(closing / 5.0, -ca.inf, bnd.catch_speed_max / 5.0, "catch")
