"""The reference path the autopilot flies: one periodic pumping cycle, repeated.

Built from sampled point-mass states and controls (as the optimiser writes them), it gives,
at any flight time, the reference position, ground velocity and acceleration (NED, winch at
origin), the feed-forward controls (alpha, bank, thrust), the tension, the tether length and
the reel speed, the phase and the motor's on-fraction. The acceleration is evaluated from the point-mass dynamics at
the reference state and controls, not by differentiating noisy samples.

Sampling is :class:`fdm_awe.trajectory.CycleSampler` with :data:`TRACKING_RULES`; the phase
names and codes are the trajectory's (:data:`fdm_awe.trajectory.PHASE_NAMES`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

import numpy as np

from ..errors import InputError
from ..trajectory import HELD, LINEAR, CycleSampler

__all__ = ["TRACKING_RULES", "RefPoint", "TrackingReference"]

#: How the autopilot samples its reference: the path, the ground velocity and acceleration, the
#: airspeed, the feed-forward controls (alpha, bank, thrust: a smooth feed-forward, although the
#: optimiser holds them per interval), the tension, the tether length and the reel speed linear in
#: time; the motor's on-fraction and the generator's T2 duty held per optimiser interval (they
#: switch the motor and the converter). The switch row is stored once (times strictly increasing),
#: so the first recovery segment runs from the generation's last row.
TRACKING_RULES: dict[str, str] = {
    "pos": LINEAR, "vel": LINEAR, "acc": LINEAR, "airspeed": LINEAR, "alpha": LINEAR, "phi": LINEAR,
    "thrust": LINEAR, "tension": LINEAR, "length": LINEAR, "reel_speed": LINEAR,
    "motor_on": HELD, "boost_duty": HELD,
}


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
    #: the motor's on-fraction of the optimiser's interval here (0 stopped .. 1 running; the
    #: reference's motor-off mode, ``thrust`` is then the mean thrust); 1 without the mode
    motor_on: float = 1.0
    #: the generator's T2 duty of the optimiser's interval here (generator ``boost``; 0: the
    #: passive rectifier, and in recovery)
    boost_duty: float = 0.0


@dataclass
class TrackingReference:
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
    #: the motor's on-fraction per sample (0 .. 1, held per optimiser interval; None: 1
    #: throughout, the motor runs)
    motor_on: np.ndarray | None = None
    #: the generator's T2 duty per sample (0 .. 1, held per optimiser interval; None: 0
    #: throughout, the passive rectifier)
    boost_duty: np.ndarray | None = None

    def __post_init__(self) -> None:
        n = len(self.t)
        if n < 2 or np.any(np.diff(self.t) <= 0):
            raise ValueError("reference time must be strictly increasing with at least 2 samples")
        on = np.ones(n) if self.motor_on is None else np.asarray(self.motor_on, float)
        # the optimiser meets the bounds 0 and 1 to its tolerance (the file check allows that slack)
        if on.shape != (n,) or not np.all((on >= -1e-6) & (on <= 1.0 + 1e-6)):
            raise ValueError(f"reference motor_on must have {n} samples in 0 .. 1")
        self.motor_on = np.clip(on, 0.0, 1.0)
        d2 = np.zeros(n) if self.boost_duty is None else np.asarray(self.boost_duty, float)
        if d2.shape != (n,) or not np.all((d2 >= -1e-6) & (d2 <= 1.0 + 1e-6)):
            raise ValueError(f"reference boost_duty must have {n} samples in 0 .. 1")
        self.boost_duty = np.clip(d2, 0.0, 1.0)
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

    def sampler(self) -> CycleSampler:
        """The :class:`~fdm_awe.trajectory.CycleSampler` of the samples (:data:`TRACKING_RULES`),
        built at the first use."""
        smp = self.__dict__.get("_sampler")
        if smp is None:
            smp = CycleSampler(self.t, self.phase, {name: getattr(self, name) for name in TRACKING_RULES},
                               TRACKING_RULES, self.T1, self.period)
            self.__dict__["_sampler"] = smp
        return smp

    def motor_segments(self) -> np.ndarray:
        """The motor's on-fraction on each segment ``[t_i, t_i+1)`` between samples (``n - 1``
        values; the last runs to the period): the optimiser holds it per interval, so it is the
        value of the sample opening the segment, except for the segment after the last
        generation sample (``t = T1``), which is the recovery's."""
        return self.sampler().segments("motor_on")

    def segment_index(self, t_cycle: float) -> int:
        """Index of the segment ``[t_i, t_i+1)`` holding cycle time ``t_cycle`` [s] (the last
        one beyond the last sample)."""
        return self.sampler().segment_index(t_cycle)

    def cycle_time(self, t: float) -> tuple[int, float]:
        return self.sampler().cycle_time(t)

    def sample(self, t: float) -> RefPoint:
        """Reference at flight time ``t`` [s] (cycle repeated periodically), by :data:`TRACKING_RULES`."""
        smp = self.sampler()
        k, tc, phase, i, _, row = smp.evaluate(t)
        at = smp.where
        return RefPoint(
            t_cycle=tc, cycle=k, phase=phase, pos=row[at("pos")], vel=row[at("vel")], acc=row[at("acc")],
            airspeed=float(row[at("airspeed")]), alpha=float(row[at("alpha")]), phi=float(row[at("phi")]),
            thrust=float(row[at("thrust")]), tension=float(row[at("tension")]), length=float(row[at("length")]),
            reel_speed=float(row[at("reel_speed")]), motor_on=float(smp.segments("motor_on")[i]),
            boost_duty=float(smp.segments("boost_duty")[i]),
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
    ) -> "TrackingReference":
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

    @classmethod
    def from_ocp_file(cls, path: str | Path) -> "TrackingReference":
        """From a reference-trajectory file written by the optimiser (``fdm-awe optimize``).

        The file is checked field by field first (:func:`fdm_awe.trajectory.read_reference`): a
        malformed file raises :class:`~fdm_awe.errors.InputError` with one line naming the file,
        the field and its allowed range or form. ``meta`` carries the checked metadata
        (``scenario``, ``config``, ``T1_s``, ``T2_s``, ``wind_ned_mps``, ``tether_drag_scale``,
        ``fold_time_s``, ``motor_off``, ...).
        """
        from ..trajectory import read_reference

        return cls.from_ocp(read_reference(path))

    @classmethod
    def from_ocp(cls, ref: object) -> "TrackingReference":
        """From an optimiser :class:`~fdm_awe.trajectory.ReferenceTrajectory` (checked again by
        :func:`~fdm_awe.trajectory.check_reference`, so one built in memory gets the same checks)
        or an ``ok`` :class:`~fdm_awe.ocp.result.CycleResult` (through
        :func:`~fdm_awe.trajectory.reference_from_result`: the reference its file would hold).

        Ground velocity = air velocity (V, gamma, psi) + the wind in its metadata, at each
        row's height when the metadata's ``wind_profile`` has shear; ``motor_on``
        from the optional column of that name (absent: 1, the motor runs throughout); the
        acceleration is the time derivative of the velocity samples (second-order differences
        within each phase, so the jump of the controls at the phase switch is not smeared).
        """
        from ..trajectory import ReferenceTrajectory, check_reference, reference_from_result

        if callable(getattr(ref, "metadata", None)) and hasattr(ref, "summary"):  # a CycleResult
            if not getattr(ref, "ok", False):
                raise InputError(f"the optimiser's result is not a cycle ({getattr(ref, 'status', '?')}: "
                                 f"{getattr(ref, 'reason', '')}); only an ok result is a reference")
            ref = reference_from_result(ref, f"the optimised {ref.scenario} {ref.config} reference")
        if not isinstance(ref, ReferenceTrajectory):
            ref = ReferenceTrajectory(ref.metadata, ref.columns, getattr(ref, "units", {}),  # type: ignore[attr-defined]
                                      source=str(getattr(ref, "source", "reference trajectory")))
        ref = check_reference(ref)
        c = ref.columns  # type: ignore[attr-defined]
        meta = dict(ref.metadata)  # type: ignore[attr-defined]
        t, ph = np.asarray(c["t"], float), np.asarray(c["phase"], int)
        # the switch row appears twice (once per phase): keep strictly increasing times
        keep = np.r_[True, np.diff(t) > 1e-9]
        wind = np.asarray(meta["wind_ned_mps"], float)
        from ..wind import WindProfile

        profile = WindProfile.from_dict(meta.get("wind_profile"), "reference metadata.wind_profile")
        if not profile.uniform:  # the wind at each row's height
            wind = np.asarray(profile.factor(-np.asarray(c["z"], float)), float)[:, None] * wind
        V, gam, psi = c["V"], c["gamma"], c["psi"]
        vel = np.c_[V * np.cos(gam) * np.cos(psi), V * np.cos(gam) * np.sin(psi), -V * np.sin(gam)] + wind
        acc = np.zeros_like(vel)
        for p in (0, 1):
            sel = np.flatnonzero(ph == p)
            if len(sel) >= 3:
                acc[sel] = np.gradient(vel[sel], t[sel], axis=0, edge_order=2)
        pos = np.c_[c["x"], c["y"], c["z"]]
        return cls(
            t=t[keep], phase=ph[keep], pos=pos[keep], vel=vel[keep], acc=acc[keep], airspeed=np.asarray(V)[keep],
            alpha=c["alpha"][keep], phi=c["phi"][keep], thrust=c["T"][keep], tension=c["tension"][keep],
            length=c["tether_length"][keep], reel_speed=c["reel_speed"][keep],
            T1=float(meta["T1_s"]), T2=float(meta["T2_s"]), meta=meta,
            motor_on=c["motor_on"][keep] if "motor_on" in c else None,
            boost_duty=c["boost_duty"][keep] if "boost_duty" in c else None,
        )

    @classmethod
    def from_waypoints(
        cls, points: np.ndarray, times: np.ndarray | None, phases: np.ndarray | None, speed: float, T1: float | None = None
    ) -> "TrackingReference":
        """A closed path through NED ``points`` (N, 3) flown as one periodic cycle.

        With ``times`` (cycle times of the points, strictly increasing from 0) the path keeps
        that timing; otherwise the points are spaced by arc length at ground ``speed`` [m/s].
        ``phases`` (0/1 per point) default to generation throughout. Velocities and
        accelerations are periodic finite differences; the controls' feed-forward is left to
        the guidance inversion (zeros), the tether length follows the distance to the winch.
        """
        P = np.asarray(points, float)
        n = len(P)
        seg = np.linalg.norm(np.roll(P, -1, axis=0) - P, axis=1)
        if times is None:
            t = np.r_[0.0, np.cumsum(seg[:-1])] / speed
            period = float(np.sum(seg) / speed)
        else:
            t = np.asarray(times, float)
            period = float(t[-1] + (t[-1] - t[-2]))
        ph = np.zeros(n, int) if phases is None else np.asarray(phases, int)
        # periodic central differences
        tn, tp = np.roll(t, -1), np.roll(t, 1)
        tn[-1] += period
        tp[0] -= period
        Pn, Pp = np.roll(P, -1, axis=0), np.roll(P, 1, axis=0)
        vel = (Pn - Pp) / (tn - tp)[:, None]
        acc = (np.roll(vel, -1, axis=0) - np.roll(vel, 1, axis=0)) / (tn - tp)[:, None]
        d = np.linalg.norm(P, axis=1)
        dd = np.einsum("ij,ij->i", P, vel) / np.maximum(d, 1e-9)
        T1v = float(T1) if T1 is not None else (float(t[np.argmax(ph == 1)]) if np.any(ph == 1) else period - 1e-6)
        zeros = np.zeros(n)
        return cls(
            t=t, phase=ph, pos=P, vel=vel, acc=acc, airspeed=np.linalg.norm(vel, axis=1), alpha=zeros, phi=zeros.copy(),
            thrust=zeros.copy(), tension=zeros.copy(), length=d, reel_speed=dd, T1=T1v, T2=period - T1v,
            meta={"source": "uploaded mission"},
        )

