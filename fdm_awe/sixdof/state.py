"""Plain data exchanged with the 6-DOF glider: control surfaces in, state out (SI, NED)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..constants import G0
from ..errors import InputError
from .row import FINITE_END, FINITE_FIRST, ROW, si_position, si_velocity, si_wind


@dataclass(frozen=True, slots=True)
class Surfaces:
    """Normalised commands for one step.

    ``aileron`` > 0 rolls right, ``elevator`` > 0 is trailing edge down (nose down), ``rudder``
    > 0 is trailing edge left (nose left), each in [-1, 1] (full deflection: aileron and
    elevator 20 deg, rudder 25 deg, set in the aircraft file). ``throttle`` in [0, 1] (motor
    voltage fraction). ``fold_cmd`` in [0, 1]: 0 unfolded, 1 folded (only the foldable
    aircraft has a fold actuator; the static forms ignore it).
    """

    aileron: float = 0.0
    elevator: float = 0.0
    rudder: float = 0.0
    throttle: float = 0.0
    fold_cmd: float = 0.0

    def __post_init__(self) -> None:
        # written out (no loop): this runs every step; comparisons also reject NaN
        if not (-1.0 <= self.aileron <= 1.0 and -1.0 <= self.elevator <= 1.0 and -1.0 <= self.rudder <= 1.0
                and 0.0 <= self.throttle <= 1.0 and 0.0 <= self.fold_cmd <= 1.0):
            for name, lo, hi in (("aileron", -1.0, 1.0), ("elevator", -1.0, 1.0), ("rudder", -1.0, 1.0),
                                 ("throttle", 0.0, 1.0), ("fold_cmd", 0.0, 1.0)):
                v = getattr(self, name)
                if not (lo <= v <= hi):
                    raise InputError(f"Surfaces.{name}: {v!r} out of range (allowed {lo:g} .. {hi:g})")

    @classmethod
    def fast(cls, aileron: float, elevator: float, rudder: float, throttle: float,
             fold_cmd: float) -> "Surfaces":
        """The same as ``Surfaces(...)`` (same range checks and errors), built without the
        frozen dataclass's per-field ``object.__setattr__`` calls (controllers' hot path)."""
        if not (-1.0 <= aileron <= 1.0 and -1.0 <= elevator <= 1.0 and -1.0 <= rudder <= 1.0
                and 0.0 <= throttle <= 1.0 and 0.0 <= fold_cmd <= 1.0):
            return cls(aileron, elevator, rudder, throttle, fold_cmd)  # raises the one-line error
        o = _new(cls)
        _set_a(o, aileron)
        _set_e(o, elevator)
        _set_r(o, rudder)
        _set_t(o, throttle)
        _set_f(o, fold_cmd)
        return o

    @classmethod
    def saturated(cls, aileron: float = 0.0, elevator: float = 0.0, rudder: float = 0.0,
                  throttle: float = 0.0, fold_cmd: float = 0.0) -> "Surfaces":
        """Commands saturated to their ranges (NaN becomes 0)."""
        def c(v: float, lo: float, hi: float) -> float:
            return lo if v < lo else hi if v > hi else (v if v == v else 0.0)
        return cls(c(aileron, -1, 1), c(elevator, -1, 1), c(rudder, -1, 1), c(throttle, 0, 1), c(fold_cmd, 0, 1))


_new = object.__new__
_set_a, _set_e, _set_r, _set_t, _set_f = (Surfaces.__dict__[n].__set__
                                         for n in ("aileron", "elevator", "rudder", "throttle", "fold_cmd"))


class SixDofState:
    """Glider state after a step. Ground frame NED with the origin at the winch; SI units.

    A light view on the values JSBSim reported for one step: each attribute is converted when
    read (so a controller pays only for what it uses). Attributes:

    ``t`` s; ``pos_ned`` CG position m; ``vel_ned`` ground velocity, ``vel_air_ned`` air-relative
    velocity (ground velocity minus the total wind including turbulence), m/s; ``quat`` = (w, x,
    y, z) rotating NED vectors into body axes; ``euler`` = (phi, theta, psi) rad (ZYX);
    ``omega_body`` = (p, q, r) rad/s; ``airspeed`` m/s, ``alpha``, ``beta`` rad; ``fold`` in
    [0, 1]; ``thrust_N``; ``prop_power_W`` electrical power into the motor, ``shaft_power_W``
    its mechanical output, ``current_A``; ``accel_body`` specific force (accelerometer) m/s^2,
    ``load_factor`` = -accel_body[2]/g0; ``mass`` kg; ``qbar`` Pa; ``rho`` kg/m^3;
    ``on_ground`` a contact touches the ground; ``hook_pos_ned``/``hook_vel_ned`` the tether
    attachment point; ``tether_force_ned`` the line force applied during the step just run (N).
    Scalars ``x, y, z, phi, theta, psi, p, q, r, altitude`` avoid building arrays.
    """

    __slots__ = ("_r", "_k", "_o", "_hook", "_force", "_volts")

    def __init__(self, raw: list, scale: list, offset: list, hook: tuple, force: tuple, volts: float) -> None:
        self._r, self._k, self._o = raw, scale, offset
        self._hook, self._force, self._volts = hook, force, volts

    def _v(self, i: int) -> float:
        return self._r[i] * self._k[i] + self._o[i]

    # the raw view (hot paths: the loop, the attitude laws, the AUTO step) ------------------
    @property
    def raw(self) -> list:
        """The raw JSBSim row of the step (positions of :mod:`fdm_awe.sixdof.row`, JSBSim's
        units); the state's own list, not a copy: read it, never write it."""
        return self._r

    @property
    def scale(self) -> list:
        """Per-column factors from the raw row to SI (``si = raw * scale + offset``)."""
        return self._k

    @property
    def offset(self) -> list:
        """Per-column offsets from the raw row to SI (used by the position, m: see
        :func:`~fdm_awe.sixdof.row.si_position`)."""
        return self._o

    @property
    def hook(self) -> tuple:
        """The tether attachment point as ``(position, velocity)``, NED tuples (m, m/s)."""
        return self._hook

    # scalars -------------------------------------------------------------------------------
    @property
    def t(self) -> float:
        return self._r[ROW.t]

    @property
    def x(self) -> float:
        return si_position(self._r, self._k, self._o)[0]

    @property
    def y(self) -> float:
        return si_position(self._r, self._k, self._o)[1]

    @property
    def z(self) -> float:
        return si_position(self._r, self._k, self._o)[2]

    @property
    def altitude(self) -> float:
        """Height of the CG above the winch, m."""
        return -si_position(self._r, self._k, self._o)[2]

    @property
    def phi(self) -> float:
        return self._r[ROW.phi]

    @property
    def theta(self) -> float:
        return self._r[ROW.theta]

    @property
    def psi(self) -> float:
        return self._r[ROW.psi]

    @property
    def p(self) -> float:
        return self._r[ROW.p_rate]

    @property
    def q(self) -> float:
        return self._r[ROW.q_rate]

    @property
    def r(self) -> float:
        return self._r[ROW.r_rate]

    @property
    def airspeed(self) -> float:
        return self._r[ROW.vt] * self._k[ROW.vt]

    @property
    def alpha(self) -> float:
        return self._r[ROW.alpha]

    @property
    def beta(self) -> float:
        return self._r[ROW.beta]

    @property
    def mass(self) -> float:
        return self._r[ROW.mass] * self._k[ROW.mass]

    @property
    def qbar(self) -> float:
        return self._r[ROW.qbar] * self._k[ROW.qbar]

    @property
    def rho(self) -> float:
        return self._r[ROW.rho] * self._k[ROW.rho]

    @property
    def thrust_N(self) -> float:
        return self._r[ROW.thrust] * self._k[ROW.thrust]

    @property
    def shaft_power_W(self) -> float:
        return self._r[ROW.shaft_hp] * self._k[ROW.shaft_hp]

    @property
    def current_A(self) -> float:
        return self._r[ROW.current]

    @property
    def prop_power_W(self) -> float:
        return self._r[ROW.throttle] * self._volts * self._r[ROW.current]

    @property
    def on_ground(self) -> bool:
        return self._r[ROW.wow] > 0.5

    @property
    def fold(self) -> float:
        return self._r[ROW.fold]

    @property
    def load_factor(self) -> float:
        return -self._r[ROW.fbz] * self._k[ROW.fbz] / (self._r[ROW.mass] * self._k[ROW.mass]) / G0

    # vectors -------------------------------------------------------------------------------
    @property
    def pos_ned(self) -> np.ndarray:
        return np.array(si_position(self._r, self._k, self._o))

    @property
    def vel_ned(self) -> np.ndarray:
        return np.array(si_velocity(self._r, self._k))

    @property
    def wind_ned(self) -> np.ndarray:
        """Total wind at the glider (steady + turbulence), m/s."""
        return np.array(si_wind(self._r, self._k))

    @property
    def vel_air_ned(self) -> np.ndarray:
        return self.vel_ned - self.wind_ned

    @property
    def euler(self) -> np.ndarray:
        return np.array(self._r[ROW.phi:ROW.psi + 1])

    @property
    def quat(self) -> np.ndarray:
        r = self._r
        return np.array(euler_to_quat(r[ROW.phi], r[ROW.theta], r[ROW.psi]))

    @property
    def omega_body(self) -> np.ndarray:
        return np.array(self._r[ROW.p_rate:ROW.r_rate + 1])

    @property
    def accel_body(self) -> np.ndarray:
        r, k = self._r, self._k
        m = r[ROW.mass] * k[ROW.mass]
        return np.array((r[ROW.fbx] * k[ROW.fbx] / m, r[ROW.fby] * k[ROW.fby] / m, r[ROW.fbz] * k[ROW.fbz] / m))

    @property
    def hook_pos_ned(self) -> np.ndarray:
        return np.array(self._hook[0])

    @property
    def hook_vel_ned(self) -> np.ndarray:
        return np.array(self._hook[1])

    @property
    def tether_force_ned(self) -> np.ndarray:
        return np.array(self._force)

    def is_finite(self) -> bool:
        return math.isfinite(math.fsum(self._r[FINITE_FIRST:FINITE_END]))

    def as_dict(self) -> dict[str, object]:
        """All attributes, converted (for printing and records)."""
        names = ("t", "pos_ned", "vel_ned", "vel_air_ned", "quat", "euler", "omega_body", "airspeed", "alpha",
                 "beta", "fold", "thrust_N", "prop_power_W", "shaft_power_W", "current_A", "accel_body",
                 "load_factor", "mass", "qbar", "rho", "on_ground", "hook_pos_ned", "hook_vel_ned",
                 "tether_force_ned")
        return {n: getattr(self, n) for n in names}

    def __repr__(self) -> str:
        return (f"SixDofState(t={self.t:.3f}, pos_ned={self.pos_ned.round(3).tolist()}, "
                f"airspeed={self.airspeed:.3f}, alpha={self.alpha:.4f}, fold={self.fold:.3f})")


def euler_to_quat(phi: float, theta: float, psi: float) -> tuple[float, float, float, float]:
    """ZYX Euler angles (rad) -> unit quaternion (w, x, y, z) of the NED -> body rotation."""
    cr, sr = math.cos(0.5 * phi), math.sin(0.5 * phi)
    cp, sp = math.cos(0.5 * theta), math.sin(0.5 * theta)
    cy, sy = math.cos(0.5 * psi), math.sin(0.5 * psi)
    return (cr * cp * cy + sr * sp * sy,
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy)


def dcm_body_to_ned(phi: float, theta: float, psi: float) -> np.ndarray:
    """Rotation matrix taking body-axis vectors to NED (ZYX Euler angles, rad)."""
    cf, sf = math.cos(phi), math.sin(phi)
    ct, st = math.cos(theta), math.sin(theta)
    cp, sp = math.cos(psi), math.sin(psi)
    return np.array([
        [ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp],
        [ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp],
        [-st, sf * ct, cf * ct],
    ])
