"""The reference path the autopilot flies: one periodic pumping cycle, repeated.

Built from sampled point-mass states and controls (as the optimiser writes them), it gives,
at any flight time, the reference position, ground velocity and acceleration (NED, winch at
origin), the feed-forward controls (alpha, bank, thrust), the tension, the tether length and
the reel speed, and the phase. The acceleration is evaluated from the point-mass dynamics at
the reference state and controls, not by differentiating noisy samples.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

GENERATION, RECOVERY = 0, 1
PHASE_NAMES = ("generation", "recovery")


@dataclass(frozen=True)
class RefPoint:
    """Reference at one instant (SI, NED)."""

    t_cycle: float  #: time within the cycle [s]
    cycle: int  #: cycle index (0-based)
    phase: int  #: GENERATION or RECOVERY
    pos: np.ndarray  #: [m]
    vel: np.ndarray  #: ground velocity [m/s]
    acc: np.ndarray  #: ground acceleration [m/s^2]
    airspeed: float  #: [m/s]
    alpha: float  #: [rad]
    phi: float  #: bank [rad]
    thrust: float  #: [N]
    tension: float  #: [N]
    length: float  #: tether length [m]
    reel_speed: float  #: [m/s], + = reel-out


@dataclass
class ReferenceTrajectory:
    """Samples of one cycle; ``t`` strictly increasing from 0, ``period`` = T1 + T2."""

    t: np.ndarray
    phase: np.ndarray
    pos: np.ndarray  # (N, 3)
    vel: np.ndarray  # (N, 3)
    acc: np.ndarray  # (N, 3)
    airspeed: np.ndarray
    alpha: np.ndarray
    phi: np.ndarray
    thrust: np.ndarray
    tension: np.ndarray
    length: np.ndarray
    reel_speed: np.ndarray
    T1: float
    T2: float
    meta: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        n = len(self.t)
        if n < 2 or np.any(np.diff(self.t) <= 0):
            raise ValueError("reference time must be strictly increasing with at least 2 samples")
        for name in ("pos", "vel", "acc"):
            if getattr(self, name).shape != (n, 3):
                raise ValueError(f"reference {name} must have shape ({n}, 3)")
        for name in ("phase", "airspeed", "alpha", "phi", "thrust", "tension", "length", "reel_speed"):
            if len(getattr(self, name)) != n:
                raise ValueError(f"reference {name} must have {n} samples")
        if not np.all(np.isfinite(self.pos)):
            raise ValueError("reference positions must be finite")

    @property
    def period(self) -> float:
        return self.T1 + self.T2

    def _interp(self, arr: np.ndarray, tc: float) -> np.ndarray | float:
        i = int(np.searchsorted(self.t, tc, side="right") - 1)
        i = min(max(i, 0), len(self.t) - 2)
        w = (tc - self.t[i]) / (self.t[i + 1] - self.t[i])
        w = min(max(w, 0.0), 1.0)
        return arr[i] * (1 - w) + arr[i + 1] * w

    def cycle_time(self, t: float) -> tuple[int, float]:
        k = int(t // self.period)
        return k, t - k * self.period

    def sample(self, t: float) -> RefPoint:
        """Reference at flight time ``t`` [s] (cycle repeated periodically)."""
        k, tc = self.cycle_time(t)
        phase = GENERATION if tc < self.T1 else RECOVERY
        f = self._interp
        return RefPoint(
            t_cycle=tc,
            cycle=k,
            phase=phase,
            pos=np.asarray(f(self.pos, tc)),
            vel=np.asarray(f(self.vel, tc)),
            acc=np.asarray(f(self.acc, tc)),
            airspeed=float(f(self.airspeed, tc)),
            alpha=float(f(self.alpha, tc)),
            phi=float(f(self.phi, tc)),
            thrust=float(f(self.thrust, tc)),
            tension=float(f(self.tension, tc)),
            length=float(f(self.length, tc)),
            reel_speed=float(f(self.reel_speed, tc)),
        )

    def waypoints(self, n: int = 60) -> list[tuple[float, float, float, float, int]]:
        """``n`` samples (north, east, down, t_cycle, phase) spread evenly in time."""
        ts = np.linspace(0.0, self.period, n, endpoint=False)
        return [(*map(float, self.sample(t).pos), float(t), int(self.sample(t).phase)) for t in ts]

    @classmethod
    def from_point_mass(
        cls,
        t: Sequence[float],
        states: np.ndarray,
        controls: np.ndarray,
        phase: Sequence[int],
        length: Sequence[float],
        reel_speed: Sequence[float],
        models: dict[int, object],
        T1: float,
        T2: float,
        cd_extra: Sequence[float] | None = None,
        meta: dict | None = None,
    ) -> "ReferenceTrajectory":
        """From point-mass samples: ``states`` (N, 6) = (x, y, z, V, gamma, psi), ``controls``
        (N, 4) = (alpha, phi, T, G); ``models[phase]`` is the PointMassModel of each phase."""
        t = np.asarray(t, float)
        X = np.asarray(states, float)
        U = np.asarray(controls, float)
        ph = np.asarray(phase, int)
        cdx = np.zeros(len(t)) if cd_extra is None else np.asarray(cd_extra, float)
        vel = np.zeros((len(t), 3))
        acc = np.zeros((len(t), 3))
        for i in range(len(t)):
            m = models[int(ph[i])]
            xdot = m.dynamics(X[i], U[i], cdx[i])  # type: ignore[attr-defined]
            vel[i] = xdot[:3]
            V, g, p = X[i, 3], X[i, 4], X[i, 5]
            Vd, gd, pd = xdot[3], xdot[4], xdot[5]
            cg, sg, cp, sp = np.cos(g), np.sin(g), np.cos(p), np.sin(p)
            acc[i] = [
                Vd * cg * cp - V * sg * gd * cp - V * cg * sp * pd,
                Vd * cg * sp - V * sg * gd * sp + V * cg * cp * pd,
                -Vd * sg - V * cg * gd,
            ]
        return cls(
            t=t, phase=ph, pos=X[:, :3].copy(), vel=vel, acc=acc, airspeed=X[:, 3].copy(),
            alpha=U[:, 0].copy(), phi=U[:, 1].copy(), thrust=U[:, 2].copy(), tension=U[:, 3].copy(),
            length=np.asarray(length, float), reel_speed=np.asarray(reel_speed, float), T1=float(T1), T2=float(T2),
            meta=dict(meta or {}),
        )
