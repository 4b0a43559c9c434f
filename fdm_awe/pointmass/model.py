"""Point-mass glider with wind and tether force (paper eqs. 7, 13; corrected per docs/design.md 4).

State ``x = (x, y, z, V, gamma, psi)``: NED position of the glider [m] (origin at the winch),
airspeed [m/s], air-path flight-path angle and heading [rad]. Control
``u = (alpha, phi, T, G)``: angle of attack [rad], bank [rad], thrust [N] and tether tension [N]
(``G >= 0`` pulls the glider towards the winch along ``-P/|P|``).

Kinematics add the (constant, horizontal) wind: ``xdot = V cg cpsi + vwx`` etc. Dynamics are
eq. 13 with the corrected frame (``C_CN`` entry (1,3) = ``-sin gamma``) and ``-g sin gamma`` in
``Vdot``. Written once with :mod:`fdm_awe.pointmass.mathops`, so it evaluates on floats, NumPy arrays
and CasADi symbols alike.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Sequence


from ..constants import G0, RHO0
from . import mathops as mo
from .aero import lift_drag
from ..definitions.aircraft import AeroParams
from ..errors import InputError
from .frames import n_to_c, tether_direction_ned

STATE_NAMES = ("x", "y", "z", "V", "gamma", "psi")
CONTROL_NAMES = ("alpha", "phi", "T", "G")


def wind_vector(speed: float, from_deg: float = 180.0) -> tuple[float, float, float]:
    """Horizontal wind in NED [m/s] blowing FROM compass direction ``from_deg``.

    Wind from the south (180 deg) blows north: ``(+speed, 0, 0)``.
    """
    if not math.isfinite(speed) or speed < 0:
        raise InputError(f"wind speed {speed!r} m/s out of range (allowed >= 0)")
    a = math.radians(from_deg)
    vx, vy = -speed * math.cos(a), -speed * math.sin(a)
    return (vx + 0.0 if abs(vx) > 1e-15 else 0.0, vy + 0.0 if abs(vy) > 1e-15 else 0.0, 0.0)


@dataclass(frozen=True)
class Environment:
    """Atmosphere and steady wind: density [kg/m^3], gravity [m/s^2], wind NED [m/s]."""

    rho: float = RHO0
    g: float = G0
    wind_ned: tuple[float, float, float] = field(default=(0.0, 0.0, 0.0))

    def __post_init__(self) -> None:
        if not (self.rho > 0 and math.isfinite(self.rho)):
            raise InputError(f"air density {self.rho!r} kg/m^3 out of range (allowed > 0)")
        if not (self.g > 0 and math.isfinite(self.g)):
            raise InputError(f"gravity {self.g!r} m/s^2 out of range (allowed > 0)")
        if abs(self.wind_ned[2]) > 0:
            raise InputError("wind must be horizontal (wind_ned[2] == 0)")


@dataclass(frozen=True)
class PointMassModel:
    """One configuration of the glider as a point mass: mass [kg] and aerodynamics."""

    mass: float
    aero: AeroParams
    env: Environment = Environment()

    def forces(self, x: Sequence[Any], u: Sequence[Any], cd_extra: Any = 0.0,
               f_line: Sequence[Any] | None = None) -> dict[str, Any]:
        """Lift, drag [N] and the tether force in N and C components [N]; ``f_line`` a further
        line force on the glider, NED [N] (None: none), added to the tension's."""
        px, py, pz, V, gamma, psi = x
        alpha, phi, T, G = u
        L, D = lift_drag(V, alpha, self.aero, self.env.rho, cd_extra)
        e = tether_direction_ned(px, py, pz)
        G_n = [G * e[0], G * e[1], G * e[2]]
        if f_line is not None:
            G_n = [G_n[i] + f_line[i] for i in range(3)]
        G_c = n_to_c(G_n, gamma, psi, phi)
        return {"L": L, "D": D, "G_n": G_n, "G_c": G_c}

    def dynamics(self, x: Sequence[Any], u: Sequence[Any], cd_extra: Any = 0.0, f_down: Any = 0.0,
                 f_line: Sequence[Any] | None = None) -> list[Any]:
        """State derivative (eq. 13 corrected) as a list of 6 expressions. ``f_down`` [N] an
        extra downward force on the glider that adds no mass (e.g. the share of the line's
        weight it carries): it enters like gravity, ``g + f_down / m``. ``f_line`` a further
        line force, NED [N] (e.g. the share of the still line's drag in the wind; None: none)."""
        px, py, pz, V, gamma, psi = x
        alpha, phi, T, G = u
        m, g = self.mass, self.env.g
        if not (isinstance(f_down, (int, float)) and f_down == 0.0):
            g = g + f_down / m
        f = self.forces(x, u, cd_extra, f_line)
        L, D = f["L"], f["D"]
        Gxc, Gyc, Gzc = f["G_c"]
        cg, sg = mo.cos(gamma), mo.sin(gamma)
        cf, sf = mo.cos(phi), mo.sin(phi)
        return [
            *self.ground_velocity(x),
            (T - D + Gxc) / m - g * sg,
            (L * cf - Gyc * sf - Gzc * cf) / (m * V) - g * cg / V,
            (L * sf + Gyc * cf - Gzc * sf) / (m * V * cg),
        ]

    def f(self, x: Sequence[Any], u: Sequence[Any], cd_extra: Any = 0.0) -> Any:
        """:meth:`dynamics` stacked: NumPy array for numbers, ``casadi`` column for symbols."""
        return mo.stack(self.dynamics(x, u, cd_extra))

    def ground_velocity(self, x: Sequence[Any]) -> list[Any]:
        """Velocity over ground, NED [m/s]: air velocity ``V c1`` plus wind."""
        _, _, _, V, gamma, psi = x
        vw = self.env.wind_ned
        return [V * mo.cos(gamma) * mo.cos(psi) + vw[0], V * mo.cos(gamma) * mo.sin(psi) + vw[1], -V * mo.sin(gamma)]

    def distance_rate(self, x: Sequence[Any]) -> Any:
        """``ddot = P . Pdot / |P|`` from the ground velocity [m/s] (docs/design.md 4.5)."""
        px, py, pz = x[0], x[1], x[2]
        v = self.ground_velocity(x)
        return (px * v[0] + py * v[1] + pz * v[2]) / mo.sqrt(px * px + py * py + pz * pz)

    def total_energy(self, x: Sequence[Any]) -> Any:
        """Kinetic (ground-relative) plus potential energy [J]."""
        v = self.ground_velocity(x)
        return 0.5 * self.mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) - self.mass * self.env.g * x[2]

    def power_balance(self, x: Sequence[Any], u: Sequence[Any], cd_extra: Any = 0.0) -> dict[str, Any]:
        """Power of each external force on the ground-relative motion [W].

        With constant wind, ``dE/dt = P_thrust + P_aero + P_tether`` holds exactly, where the
        aerodynamic power includes the wind's work ``(L + D) . v_w``.
        """
        px, py, pz, V, gamma, psi = x
        alpha, phi, T, G = u
        f = self.forces(x, u, cd_extra)
        v = self.ground_velocity(x)
        c1 = [mo.cos(gamma) * mo.cos(psi), mo.cos(gamma) * mo.sin(psi), -mo.sin(gamma)]
        # lift along -c3 in N: -(third row of C_CN)
        cf, sf = mo.cos(phi), mo.sin(phi)
        cg, sg = mo.cos(gamma), mo.sin(gamma)
        cpsi, spsi = mo.cos(psi), mo.sin(psi)
        c3 = [sf * spsi + cf * sg * cpsi, -sf * cpsi + cf * sg * spsi, cf * cg]
        dot = lambda a, b: a[0] * b[0] + a[1] * b[1] + a[2] * b[2]  # noqa: E731
        aero_n = [-f["D"] * c1[i] - f["L"] * c3[i] for i in range(3)]
        return {
            "thrust": T * dot(c1, v),
            "aero": dot(aero_n, v),
            "tether": dot(f["G_n"], v),
            "drag_air": -f["D"] * V,
        }

