"""Initial guesses for the cycle NLP: crosswind loops on the tether sphere.

Both phases are guessed as one loop each in the plane tangent to the sphere at the start point,
passing through the start point and leaving it upwards (elevation increasing): generation reels
out from ``d0`` to ``d_tf`` along the loop, recovery comes back in along a second loop. The
loops turn the same way (the heading winds twice) or opposite ways (a figure of eight, the
heading unwinds). Airspeed, flight-path angle and heading are derived from the ground velocity
minus the wind, so the guess is kinematically consistent; the heading wrap count ``k`` of the
periodicity condition follows from the guess. Controls: alpha for about 1 g of lift, bank from
the turn rate, a little thrust, mid-range tension, uniform reel-in.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from .energy import generator_tension
from .model import CycleModel
from .problem import CycleProblem


@dataclass(frozen=True)
class LoopStart:
    """Shape of one initial guess: phase durations [s], loop radii [m], turn directions (+1/-1)."""

    T1: float = 15.0
    T2: float = 12.0
    r1: float = 30.0
    r2: float = 30.0
    dir1: int = 1
    dir2: int = 1
    n1: int = 1  #: loops (or figures of eight) flown during generation
    G: float = 20.0  #: tension guess [N] (paper scenario)
    shape: str = "loop"  #: "loop" or "eight" (a figure of eight lying across the wind, r = half-width)

    def label(self) -> str:
        return (f"{self.shape}s T1={self.T1:.3g}s T2={self.T2:.3g}s n={self.n1} r1={self.r1:.3g}m r2={self.r2:.3g}m "
                f"turns={self.dir1:+d}/{self.dir2:+d}")


def default_starts(problem: CycleProblem) -> list[LoopStart]:
    """A few distinct starts, tried in order.

    Generation: reel-out at about a third of the wind speed (Loyd's optimum, clipped to
    1.5..4 m/s), crosswind airspeed about 2.5 times the wind (clipped to 12 m/s .. 0.8 V_max),
    as many loops of about 40 m radius as fit. Recovery: one loop, wider for the folded glider
    (its stall speed is about 21 m/s). The wind is the one at the start's height (the problem's
    wind profile; the given speed for a uniform wind).
    """
    b = problem.bounds
    folded = problem.config == "foldable"
    span = problem.d_tf - problem.d0
    vw = problem.wind_speed
    profile = getattr(problem, "wind_profile", None)
    if profile is not None and not profile.uniform:
        vw = vw * float(profile.factor(-problem.start_position[2]))
    v_r = min(max(vw / 3.0, 1.5), 4.0)
    T1 = span / v_r
    V = min(max(2.5 * vw, 12.0), 0.8 * b.V_max)
    n1 = max(1, int(round(V * T1 / (2 * math.pi * 40.0))))
    r1 = V * T1 / (2 * math.pi * n1)
    r2 = 60.0 if folded else 30.0
    T2 = 12.0
    # figure of eight: half-width so that one eight (length ~ 6.1 x half-width) fits T1
    a1 = min(max(V * T1 / 6.1, 30.0), 90.0)
    return [
        LoopStart(T1, T2, r1, r2, 1, 1, n1),
        LoopStart(T1, T2, r1, r2, 1, -1, n1),
        LoopStart(T1, T2, a1, r2 * 1.5, 1, 1, 1, shape="eight"),
    ]


def _basis(problem: CycleProblem) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    el, az = math.radians(problem.elevation0_deg), math.radians(problem.azimuth0_deg)
    e_r = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), -math.sin(el)])
    e_az = np.array([-math.sin(az), math.cos(az), 0.0])
    e_el = np.array([-math.sin(el) * math.cos(az), -math.sin(el) * math.sin(az), -math.cos(el)])
    return e_r, e_az, e_el


def _loop_position(problem: CycleProblem, r: float, direction: int, d_of_s: Callable[[np.ndarray], np.ndarray],
                   s: np.ndarray, n_loops: int = 1, shape: str = "loop") -> np.ndarray:
    """NED positions [m] along ``n_loops`` loops of tangent radius ``r`` for path fractions ``s`` in [0, 1]."""
    e_r, e_az, e_el = _basis(problem)
    th = 2 * math.pi * n_loops * s
    if shape == "eight":
        oa = direction * r * np.sin(th)
        oe = 0.25 * r * np.sin(2 * th)
    else:
        oa = direction * r * (1 - np.cos(th))
        oe = r * np.sin(th)
    dirs = e_r[None, :] + (oa[:, None] * e_az[None, :] + oe[:, None] * e_el[None, :]) / problem.d0
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    return d_of_s(s)[:, None] * dirs


def loop_guess(problem: CycleProblem, model: CycleModel, start: LoopStart, wind_ned: tuple[float, float], n: int = 2001) -> tuple[list[dict[str, Any]], int]:
    """Per-phase guess dictionaries for :meth:`CycleNLP.pack` and the heading wrap ``k``."""
    b = problem.bounds
    wind = np.array([wind_ned[0], wind_ned[1], 0.0])
    s = np.linspace(0.0, 1.0, n)
    d0, d1 = problem.d0, problem.d_tf
    P_gen = _loop_position(problem, start.r1, start.dir1, lambda s: d0 + (d1 - d0) * s, s, start.n1, start.shape)
    P_rec = _loop_position(problem, start.r2, start.dir2, lambda s: d1 + (d0 - d1) * s - 3.0 * np.sin(math.pi * s), s, 1, start.shape)
    l_rec = d1 + (d0 - d1) * s
    phases = []
    psi_last = None
    for ip, (P, T, af) in enumerate(((P_gen, start.T1, model.gen_airframe), (P_rec, start.T2, model.rec_airframe))):
        t = s * T
        vg = np.gradient(P, t, axis=0)
        if model.wind_profile.uniform:
            va = vg - wind
        else:  # the wind at each point's height (the profile's)
            f = np.asarray(model.wind_profile.factor(-P[:, 2]), float)
            va = vg - f[:, None] * wind
        V = np.linalg.norm(va, axis=1)
        gamma = np.arcsin(np.clip(-va[:, 2] / V, -1, 1))
        psi = np.unwrap(np.arctan2(va[:, 1], va[:, 0]))
        if psi_last is not None:
            psi += 2 * math.pi * round((psi_last - psi[0]) / (2 * math.pi))
        psi_last = psi[-1]
        if ip == 0:
            psi_first = psi[0]
        Vc = np.clip(V, b.V_min + 0.5, b.V_max - 0.5)
        gamma = np.clip(gamma, -0.9 * b.gamma_max, 0.9 * b.gamma_max)
        psidot = np.gradient(psi, t)
        phi = np.clip(np.arctan(Vc * psidot / model.g), -0.8 * b.phi_max, 0.8 * b.phi_max)
        a = af.aero
        if ip == 0:
            G = np.full(n, start.G) if model.scenario.tension_control else generator_tension(np.gradient(np.linalg.norm(P, axis=1), t), model.winch)
        else:
            G = np.zeros(n)
        CL = 2 * (af.mass.mass * model.g + G) / (model.rho * a.S * Vc**2 * np.cos(phi))
        alpha = np.clip((CL - a.CL0) / a.CLalpha, max(-0.1, model.alpha_lower(ip, b.alpha_max, b.cl_margin)),
                        0.8 * model.alpha_upper(ip, b.alpha_max, b.cl_margin))
        X = np.column_stack([P, Vc, gamma, psi] + ([l_rec] if ip == 1 else []))
        if ip == 0:
            # the tension where it is a control, a passive start (zero T2 duty) where the duty is
            extra = {"G": [G], "D2": [np.zeros(n)]}
            U = np.column_stack([alpha, phi, np.full(n, 1.0)] + [c for name in model.gen_controls[3:] for c in extra.get(name, [])])
        else:
            U = np.column_stack([alpha, phi, np.full(n, 1.0), np.full(n, -(d1 - d0) / T)]
                                + ([np.zeros(n)] if "G" in model.rec_controls else []))  # a slack start
        phases.append({"T": T, "state": _interp(t, X), "control": _interp(t, U)})
    k = int(round((psi_last - psi_first) / (2 * math.pi)))
    return phases, k


def _interp(t: np.ndarray, Y: np.ndarray) -> Callable[[float], np.ndarray]:
    def f(tq: float) -> np.ndarray:
        return np.array([np.interp(tq, t, Y[:, i]) for i in range(Y.shape[1])])

    return f


def guess_from_result(result: Any, model: CycleModel) -> tuple[list[dict[str, Any]], int]:
    """Per-phase guesses interpolated from a solved cycle (any mesh, any scenario).

    States are interpolated linearly between the collocation points; controls are held per
    interval. Controls the source lacks come from its columns: the tension of a free-tension
    generation phase from its tension column, a T2 duty as 0 (the passive rectifier), the motor's
    on-fraction as 1 (added when the guess is packed).
    """
    phases = []
    for ip, ph in enumerate(result.phases):
        t, X, U = np.asarray(ph["t"]), np.asarray(ph["X"]), np.asarray(ph["U"])
        T = float(ph["T"])
        names = list(ph["controls"])
        want = model.gen_controls if ip == 0 else model.rec_controls
        n = len(U)
        sel = result.columns["phase"] == ip
        t_col = result.columns["t"][sel] - (0.0 if ip == 0 else result.phases[0]["T"])
        G_col = result.columns["tension"][sel]

        def control(tq: float, U=U, n=n, T=T, names=names, want=want, t_col=t_col, G_col=G_col) -> np.ndarray:
            k = int(min(max(tq / T * n, 0), n - 1))
            out = []
            for c in want:
                if c in names:
                    out.append(U[k, names.index(c)])
                elif c == "D2":  # a source without the T2 duty control ran the passive rectifier
                    out.append(0.0)
                elif c == "G":
                    out.append(float(np.interp(tq, t_col, G_col)))
            return np.array(out)

        phases.append({"T": T, "state": _interp(t, X), "control": control})
    return phases, int(result.k_wrap)
