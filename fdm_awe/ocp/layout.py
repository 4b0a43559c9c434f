"""The decision vector of the cycle NLP: scales, Radau mesh, fold transitions, where each variable lives.

Each phase ``p`` has ``N_p`` intervals of equal length ``h_p = T_p / N_p`` (free durations
``T_1``, ``T_2``), Radau collocation of degree ``d`` (:func:`radau_coefficients`; the last
collocation point is the next mesh node) and piecewise-constant controls (one value per
interval). Decision variables are scaled (``value = scale * variable``, :class:`Variables`)
with the scales of :data:`STATE_SCALE`, :data:`CONTROL_SCALE`, :data:`TIME_SCALE` and
:data:`SLACK_SCALE`.

Fold transitions: when the wing takes time to fold
(:attr:`fdm_awe.ocp.model.CycleModel.fold_time` > 0), the recovery's first and last
:func:`fold_intervals` intervals span exactly the fold and the unfold (each ``fold_time /
n_fold`` long) and the others share the rest, ``(T_2 - 2 fold_time) / (N_2 - 2 n_fold)``
(:func:`interval_lengths`). The fold state is linear in time inside a transition interval and
1 outside, so every collocation point has a fixed fold state (:func:`interval_fold`, the law of
:func:`fdm_awe.pointmass.fold.fold_fraction` at that point's time), the dynamics stay smooth within
each interval, and ``T_2 >= 2 fold_time``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

STATE_SCALE = {"x": 100.0, "y": 100.0, "z": 100.0, "V": 10.0, "gamma": 1.0, "psi": 1.0, "l": 100.0}
CONTROL_SCALE = {"alpha": 0.3, "phi": 1.0, "T": 5.0, "G": 30.0, "v_reel": 5.0, "s": 1.0, "D2": 0.5}
TIME_SCALE = 10.0
#: elastic slacks of the recovery dynamics: fictitious accelerations added to the airspeed
#: [m/s^2], flight-path-angle and heading [rad/s] equations, one value per interval, each split
#: into a positive and a negative part (scale of the variables)
SLACK_SCALE = {"V": 1.0, "gamma": 0.1, "psi": 0.1}

#: longest mesh interval of a fold transition [s]: the fold and the unfold each get
#: ``ceil(fold_time / FOLD_INTERVAL_S)`` intervals (at most a quarter of the recovery's each)
FOLD_INTERVAL_S = 1.0


def fold_intervals(n: int, fold_time: float) -> int:
    """Mesh intervals of each fold transition in a recovery of ``n`` intervals (0 without one)."""
    if fold_time <= 0.0:
        return 0
    return max(1, min(math.ceil(fold_time / FOLD_INTERVAL_S - 1e-9), n // 4))


def interval_lengths(T: Any, n: int, fold_time: float = 0.0, n_fold: int = 0) -> list[Any]:
    """Length [s] of each of the ``n`` intervals of a phase lasting ``T`` [s] (a number or a
    symbol): equal, or with ``n_fold`` intervals spanning each fold transition of ``fold_time``."""
    if n_fold == 0:
        return [T / n] * n
    hf = fold_time / n_fold
    hm = (T - 2.0 * fold_time) / (n - 2 * n_fold)
    return [hf] * n_fold + [hm] * (n - 2 * n_fold) + [hf] * n_fold


def interval_fold(k: int, tau: float, n: int, n_fold: int) -> float | None:
    """Fold state at local time ``tau`` in [0, 1] of interval ``k`` of the recovery's ``n``
    (:func:`interval_lengths`): rising over the first ``n_fold`` intervals, falling over the
    last ``n_fold``; None in between (folded, the recovery form itself)."""
    if k < n_fold:
        return (k + tau) / n_fold
    if k >= n - n_fold:
        return 1.0 - (k - (n - n_fold) + tau) / n_fold
    return None


def radau_coefficients(d: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Radau points ``tau`` (with 0 prepended), derivative matrix ``C``, continuity ``D`` and
    quadrature weights ``B`` of the Lagrange basis on [0, 1]."""
    tau = np.append(0.0, ca.collocation_points(d, "radau"))
    C = np.zeros((d + 1, d + 1))
    D = np.zeros(d + 1)
    B = np.zeros(d + 1)
    for j in range(d + 1):
        p = np.poly1d([1.0])
        for r in range(d + 1):
            if r != j:
                p *= np.poly1d([1.0, -tau[r]]) / (tau[j] - tau[r])
        D[j] = p(1.0)
        dp = np.polyder(p)
        for r in range(d + 1):
            C[j, r] = dp(tau[r])
        B[j] = np.polyint(p)(1.0)
    return tau, C, D, B


@dataclass
class PhaseLayout:
    """Where one phase's variables live in the decision vector."""

    states: tuple[str, ...]
    controls: tuple[str, ...]
    n: int
    X: list[list[Any]] = field(default_factory=list)  #: X[k][j] symbols (value units), j = 0..d
    U: list[Any] = field(default_factory=list)  #: U[k] symbols (value units)
    T: Any = None
    idx_X: np.ndarray | None = None  #: (n, d+1, nx) indices into w (j = d of k is node k+1)
    idx_U: np.ndarray | None = None  #: (n, nu)
    idx_T: int = -1
    n_fold: int = 0  #: intervals of each fold transition (recovery of a folding wing), else 0
    fold_time: float = 0.0  #: [s]

    def lengths(self, T: Any) -> list[Any]:
        """Interval lengths [s] for phase duration ``T`` (:func:`interval_lengths`)."""
        return interval_lengths(T, self.n, self.fold_time, self.n_fold)

    def node_times(self, T: float) -> np.ndarray:
        """Interval bounds [s] (``n + 1`` values from 0 to ``T``) for phase duration ``T``."""
        if self.n_fold == 0:
            return np.arange(self.n + 1) * (T / self.n)
        return np.concatenate(([0.0], np.cumsum(self.lengths(T))))

    def time(self, t_nodes: np.ndarray, k: int, tau: float) -> float:
        """Time [s] at local time ``tau`` in [0, 1] of interval ``k`` (bounds ``t_nodes``)."""
        if self.n_fold == 0:
            return (k + tau) * t_nodes[1]
        return t_nodes[k] + tau * (t_nodes[k + 1] - t_nodes[k])

    def fold(self, k: int, tau: float) -> float | None:
        """Fold state in interval ``k`` at local time ``tau`` (None: the phase's own wing)."""
        return interval_fold(k, tau, self.n, self.n_fold) if self.n_fold else None


@dataclass
class Variables:
    """The scaled decision vector while it is built: symbols, bounds (scaled), count."""

    parts: list[Any] = field(default_factory=list)  #: scaled symbols in vector order
    lbw: list[float] = field(default_factory=list)
    ubw: list[float] = field(default_factory=list)

    @property
    def n(self) -> int:
        """Variables so far."""
        return len(self.parts)

    def new(self, name: str, scale: float, lo: float, hi: float) -> tuple[Any, int]:
        """A new variable with bounds ``lo .. hi`` in value units: ``(scale * symbol, index)``."""
        v = ca.SX.sym(name)
        self.parts.append(v)
        self.lbw.append(lo / scale)
        self.ubw.append(hi / scale)
        return v * scale, len(self.parts) - 1

    def group(self, names: tuple[str, ...], tag: str, scales: dict[str, float],
              bounds: dict[str, tuple[float, float]]) -> tuple[list[Any], list[int]]:
        """One variable per name (called ``{name}_{tag}``) with its scale and bounds (value
        units): ``(values, indices)``."""
        vals, ids = [], []
        for s in names:
            lo, hi = bounds[s]
            v, i = self.new(f"{s}_{tag}", scales[s], lo, hi)
            vals.append(v)
            ids.append(i)
        return vals, ids
