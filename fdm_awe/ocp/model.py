"""The two phases of the cycle as state-space blocks: derivative, tension, reel speed, power terms.

Generation (phase 1): state ``(x, y, z, V, gamma, psi)`` [m, m, m, m/s, rad, rad]; the tether
is taut, so its length equals the distance ``d = |P|`` and the reel speed is ``ddot``.
Controls ``(alpha, phi, T, G)`` in the ``paper`` scenario (tension is a control),
``(alpha, phi, T)`` in ``physical`` (tension follows the passive-rectifier generator).

Recovery (phase 2): state ``(x, y, z, V, gamma, psi, l)`` with tether length ``l`` [m],
``ldot = v_reel``; tether slack (``G = 0``, ``d <= l``). Controls ``(alpha, phi, T, v_reel)``.

The glider dynamics are :class:`fdm_awe.pointmass.PointMassModel`; this module only wires the
tether, winch and energy terms around it. Evaluates on floats/NumPy and CasADi symbols.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any, Sequence

from .. import mathops as mo
from ..aero import tether_drag_coefficient
from ..definitions.aircraft import AeroParams, Airframe, Glider
from ..pointmass import Environment, PointMassModel
from .energy import (WinchElectrics, generator_load_power, generator_tension, mechanical_tether_power,
                     motor_supply_power, thrust_power)
from ..definitions.engine import ElectricDrive, load_electric_drive
from .problem import CycleProblem, Scenario

GEN_STATES = ("x", "y", "z", "V", "gamma", "psi")
#: smoothing of the normal air speed of the line [m/s] (keeps its square root differentiable)
TETHER_VN_EPS = 0.1
REC_STATES = GEN_STATES + ("l",)


@dataclass(frozen=True)
class CycleModel:
    """Phase models of one cycle for a scenario and configuration."""

    scenario: Scenario
    gen_airframe: Airframe
    rec_airframe: Airframe
    winch: WinchElectrics
    rho: float = 1.225
    g: float = 9.81
    tether_drag_scale: float = 1.0  #: factor on the line drag (CycleProblem.tether_drag_scale)
    drive: ElectricDrive | None = None  #: the 6-DOF glider's drive (propeller model "engine")
    line_weight: bool = False  #: the glider carries its share of the line's weight (CycleProblem.line_weight)

    @classmethod
    def build(cls, problem: CycleProblem, glider: Glider, winch: WinchElectrics) -> "CycleModel":
        rec = glider.folded if problem.config == "foldable" else glider.unfolded
        spec = problem.scenario_spec
        drive = load_electric_drive() if spec.propeller == "engine" else None
        return cls(spec, glider.unfolded, rec, winch, tether_drag_scale=problem.tether_drag_scale, drive=drive,
                   line_weight=problem.line_weight)

    @property
    def gen_controls(self) -> tuple[str, ...]:
        return ("alpha", "phi", "T", "G") if self.scenario.tension_control else ("alpha", "phi", "T")

    rec_controls = ("alpha", "phi", "T", "v_reel")

    def _pm(self, af: Airframe, wind: Sequence[Any]) -> PointMassModel:
        env = Environment(self.rho, self.g, (wind[0], wind[1], 0.0))
        return PointMassModel(af.mass.mass, af.aero, env)

    def _tether_drag(self, aero: AeroParams, x: Sequence[Any], d: Any, length: Any, drag_factor: Any) -> tuple[Any, Any]:
        """Tether line drag as (extra drag coefficient along the airspeed, extra tether-direction
        force [N], > 0 towards the winch).

        The glider carries a quarter of the line drag ``0.5 rho C_D_perp d_t l |v_n| v_n`` with
        ``v_n`` the glider's air velocity normal to the line (the straight-line model the ground
        station uses): ``-k |v_n| v_n = -k |v_n| V c1 + k |v_n| v_r e_r`` with
        ``k = q S C_D,t / V^2``, ``C_D,t = C_D_perp d_t l / (4 S)``
        (:func:`fdm_awe.aero.tether_drag_coefficient`) and ``v_r`` the air velocity along
        ``e_r = P/|P|``. Motion along the line (reeling, flying straight at the winch) causes no
        line drag.
        """
        if not self.scenario.tether_drag:
            return 0.0, 0.0
        w = self.winch
        cdt = drag_factor * self.tether_drag_scale * tether_drag_coefficient(length, w.tether_diameter, w.tether_cd_perp, aero.S)
        V, gamma, psi = x[3], x[4], x[5]
        cg = mo.cos(gamma)
        va = (V * cg * mo.cos(psi), V * cg * mo.sin(psi), -V * mo.sin(gamma))
        v_r = (x[0] * va[0] + x[1] * va[1] + x[2] * va[2]) / d
        v_n = mo.sqrt(V * V - v_r * v_r + TETHER_VN_EPS**2)
        k = 0.5 * self.rho * aero.S * cdt
        return cdt * v_n / V, -k * v_n * v_r

    def _line_weight(self, length: Any) -> Any:
        """Downward force [N] of the line's weight share on the glider at paid-out ``length`` [m]."""
        return self.winch.line_weight_per_length * length if self.line_weight else 0.0

    def _thrust_power(self, T: Any, V: Any) -> Any:
        return thrust_power(T, V, self.gen_airframe.propulsion, self.rho, self.scenario.propeller, self.drive)

    def generation(self, s: Sequence[Any], u: Sequence[Any], wind: Sequence[Any], drag_factor: Any = 1.0) -> dict[str, Any]:
        """Phase-1 block: ``f`` (6 derivatives), ``G`` [N], ``v_reel`` = ddot [m/s], ``d`` [m],
        powers ``P_gen``, ``P_thr``, ``P_rw`` [W]."""
        pm = self._pm(self.gen_airframe, wind)
        x = list(s[:6])
        d = mo.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2])
        ddot = pm.distance_rate(x)
        if self.scenario.tension_control:
            G = u[3]
        else:
            G = generator_tension(ddot, self.winch)
        cd_t, G_t = self._tether_drag(self.gen_airframe.aero, x, d, d, drag_factor)
        f = pm.dynamics(x, (u[0], u[1], u[2], G + G_t), cd_t, self._line_weight(d))
        if self.scenario.electrical:
            P_gen = generator_load_power(ddot, self.winch)
        else:
            P_gen = mechanical_tether_power(G, ddot)
        return {"f": f, "G": G, "v_reel": ddot, "d": d, "l": d, "P_gen": P_gen,
                "P_thr": self._thrust_power(u[2], x[3]), "P_rw": 0.0 * x[3]}

    def rec_aero(self, morph: Any = 1.0) -> AeroParams:
        """Recovery aerodynamics; ``morph`` in [0, 1] blends unfolded (0) into the recovery
        form (1) parameter by parameter. Intermediate values serve only as a homotopy path."""
        if isinstance(morph, (int, float)) and morph == 1.0 or self.rec_airframe is self.gen_airframe:
            return self.rec_airframe.aero
        a, b = self.gen_airframe.aero, self.rec_airframe.aero
        return AeroParams(**{f.name: (1 - morph) * getattr(a, f.name) + morph * getattr(b, f.name) for f in fields(AeroParams)})

    def recovery(self, s: Sequence[Any], u: Sequence[Any], wind: Sequence[Any], drag_factor: Any = 1.0,
                 morph: Any = 1.0) -> dict[str, Any]:
        """Phase-2 block: ``f`` (7 derivatives incl. ``ldot``), ``G`` = 0, ``v_reel``, ``d``,
        ``l`` [m], powers [W]. ``morph`` see :meth:`rec_aero`."""
        af = self.rec_airframe
        aero = self.rec_aero(morph)
        env = Environment(self.rho, self.g, (wind[0], wind[1], 0.0))
        pm = PointMassModel(af.mass.mass, aero, env)
        x = list(s[:6])
        l = s[6]
        d = mo.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2])
        v_reel = u[3]
        cd_t, G_t = self._tether_drag(aero, x, d, l, drag_factor)
        f = pm.dynamics(x, (u[0], u[1], u[2], G_t), cd_t, self._line_weight(l))
        if self.scenario.electrical:
            P_rw = motor_supply_power(v_reel, self.winch)
        else:
            P_rw = self.scenario.P_rw + 0.0 * x[3]
        return {"f": [*f, v_reel], "G": 0.0 * x[3], "v_reel": v_reel, "d": d, "l": l, "P_gen": 0.0 * x[3],
                "P_thr": self._thrust_power(u[2], x[3]), "P_rw": P_rw}

    def phase(self, index: int):
        """The block of phase ``index`` (0 generation, 1 recovery)."""
        return self.generation if index == 0 else self.recovery

    def alpha_lower(self, index: int, alpha_max: float, cl_margin: float = 1.0) -> float:
        """Lower bound on alpha [rad]: -alpha_max (Table 3), tightened by the negative stall
        C_L >= -C_Lmax if enabled (the aircraft definitions clip C_L there) and by
        C_L >= -cl_margin C_Lmax of the phase's own wing when ``cl_margin`` < 1 (a reference to
        be flown keeps the same margin from the negative stall as from the positive one)."""
        a = (self.gen_airframe if index == 0 else self.rec_airframe).aero
        lo = -alpha_max
        if self.scenario.stall_limit:
            lo = max(lo, (-a.CLmax - a.CL0) / a.CLalpha)
        if cl_margin < 1.0:
            lo = max(lo, (-cl_margin * a.CLmax - a.CL0) / a.CLalpha)
        return lo

    def alpha_upper(self, index: int, alpha_max: float, cl_margin: float = 1.0) -> float:
        """Upper bound on alpha [rad]: Table 3's bound, tightened by C_L <= C_Lmax if enabled,
        and by C_L <= cl_margin C_Lmax of the phase's own wing when ``cl_margin`` < 1."""
        a = (self.gen_airframe if index == 0 else self.rec_airframe).aero
        hi = min(alpha_max, a.alpha_max_lift) if self.scenario.stall_limit else alpha_max
        if cl_margin < 1.0:
            hi = min(hi, (cl_margin * a.CLmax - a.CL0) / a.CLalpha)
        return hi
