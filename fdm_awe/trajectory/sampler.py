"""Sampling one periodic cycle of rows at any time, with a named rule per column
(:data:`LINEAR`, :data:`HELD`; the rules are described in :mod:`fdm_awe.trajectory`): one
implementation for the reference file and the autopilot's tracking reference.

The sampling's arithmetic is the pure :func:`cycle_evaluate` (with :func:`cycle_time` and
:func:`segment_of`): arrays and floats in, numbers out, compiled by numba with the same bits as
the Python call; :meth:`CycleSampler.evaluate` wraps it."""

from __future__ import annotations

import math
from typing import Any, Mapping

import numpy as np

from .schema import GENERATION, RECOVERY

#: Sampling rule: linear in time across the segment (:mod:`fdm_awe.trajectory`)
LINEAR = "linear"
#: Sampling rule: held per optimiser interval (:mod:`fdm_awe.trajectory`)
HELD = "held"
RULES = (LINEAR, HELD)


class CycleSample:
    """One sample of a :class:`CycleSampler`: ``cycle`` (0-based), ``t_cycle`` [s], ``phase``
    (:data:`GENERATION` or :data:`RECOVERY`), ``segment`` (index of the row opening it) and
    ``weight`` (0 .. 1 across it); ``sample[name]`` is a column's value (a float, or a NumPy
    array for a column with several components, e.g. a position)."""

    __slots__ = ("cycle", "t_cycle", "phase", "segment", "weight", "_row", "_sampler")

    def __init__(self, sampler: "CycleSampler", cycle: int, t_cycle: float, phase: int, segment: int,
                 weight: float, row: np.ndarray) -> None:
        self._sampler = sampler
        self.cycle, self.t_cycle, self.phase, self.segment, self.weight = cycle, t_cycle, phase, segment, weight
        self._row = row

    def __getitem__(self, name: str) -> Any:
        j = self._sampler._where.get(name)
        if j is not None:
            return self._row[j]
        return float(self._sampler._held[name][self.segment])


class CycleSampler:
    """One periodic cycle of rows, evaluated at any time with a named rule per column.

    Args:
        t: row times [s], non-decreasing from the cycle start; a time may repeat only where the
            phase changes (the switch row stored once per phase).
        phase: phase code of each row.
        columns: name -> values per row (``(n,)``, or ``(n, k)`` for a vector such as a position).
        rules: name -> :data:`LINEAR` or :data:`HELD` for every name of ``columns`` (held columns
            one value per row).
        T1: cycle time of the phase switch [s]; the phase of a sample is generation below it.
        period: cycle period [s] (> 0).

    The rules are those of :mod:`fdm_awe.trajectory`; :meth:`sample` returns a :class:`CycleSample`.
    """

    def __init__(self, t: Any, phase: Any, columns: Mapping[str, Any], rules: Mapping[str, str], T1: float,
                 period: float) -> None:
        t = np.asarray(t, float)
        phase = np.asarray(phase)
        n = len(t)
        if n < 2 or t.shape != (n,) or phase.shape != (n,):
            raise ValueError("a cycle sampler needs at least 2 rows of times and phases")
        dt = np.diff(t)
        if not np.all(np.isfinite(t)) or np.any(dt < 0.0) or np.any((dt == 0.0) & (phase[:-1] == phase[1:])):
            raise ValueError("sampler times must be finite and increasing (a time repeated only at a phase switch)")
        if not (math.isfinite(period) and period > 0.0):
            raise ValueError(f"sampler period {period!r}: allowed > 0 s")
        self.t, self.phase, self.T1, self.period = t, phase, float(T1), period
        lin: list[np.ndarray] = []
        self._where: dict[str, int | slice] = {}
        self._held: dict[str, np.ndarray] = {}
        self.rules = dict(rules)
        col = 0
        for name, values in columns.items():
            rule = rules.get(name)
            a = np.asarray(values, float)
            if rule not in RULES:
                raise ValueError(f"sampler column {name}: rule {rule!r}, allowed {', '.join(RULES)}")
            if a.shape[:1] != (n,) or a.ndim > 2 or (rule == HELD and a.ndim != 1):
                raise ValueError(f"sampler column {name}: shape {a.shape}, expected ({n},)"
                                 + ("" if rule == HELD else f" or ({n}, k)"))
            if rule == HELD:
                # a segment belongs to the phase of the row closing it
                self._held[name] = np.where(phase[:-1] == phase[1:], a[:-1], a[1:])
            elif a.ndim == 1:
                self._where[name] = col
                lin.append(a[:, None])
                col += 1
            else:
                self._where[name] = slice(col, col + a.shape[1])
                lin.append(a)
                col += a.shape[1]
        self._table = np.column_stack(lin) if lin else np.zeros((n, 0))

    def cycle_time(self, t: float) -> tuple[int, float]:
        """(cycle index, cycle time [s]) of time ``t`` [s] (:func:`cycle_time`)."""
        return cycle_time(t, self.period)

    def segment_index(self, t_cycle: float) -> int:
        """Index of the segment ``[t_i, t_i+1)`` holding cycle time ``t_cycle`` [s] (the first one
        before the first row, the last one at or beyond the last row; :func:`segment_of`)."""
        return segment_of(self.t, t_cycle)

    def segments(self, name: str) -> np.ndarray:
        """The value of held column ``name`` on each of the ``n - 1`` segments."""
        return self._held[name]

    def where(self, name: str) -> int | slice:
        """Position of linear column ``name`` in the row :meth:`evaluate` returns."""
        return self._where[name]

    @property
    def table(self) -> np.ndarray:
        """The linear columns' values per row, ``(n, m)`` float64 (column offsets :meth:`where`):
        the table :func:`cycle_evaluate` interpolates."""
        return self._table

    def evaluate(self, t: float) -> tuple[int, float, int, int, float, np.ndarray]:
        """``(cycle, t_cycle, phase, segment, weight, row)`` at time ``t`` [s]: ``row`` (a new
        array) holds every linear column (at :meth:`where`), ``segments(name)[segment]`` a held
        one (:func:`cycle_evaluate`). The fast form of :meth:`sample`, for a caller sampling every
        step."""
        row = np.empty(self._table.shape[1])
        k, tc, phase, i, w = cycle_evaluate(self.t, self._table, self.T1, self.period, t, row)
        return k, tc, phase, i, w, row

    def sample(self, t: float) -> CycleSample:
        """Every column at time ``t`` [s] (the cycle repeated periodically)."""
        k, tc, phase, i, w, row = self.evaluate(t)
        return CycleSample(self, k, tc, phase, i, w, row)


def cycle_time(t: float, period: float) -> tuple[int, float]:
    """(cycle index, cycle time [s]) of time ``t`` [s] on a cycle of ``period`` [s]:
    ``k = floor(t / period)``, ``t - k period``."""
    k = int(t // period)
    return k, t - k * period


def segment_of(ts: np.ndarray, t_cycle: float) -> int:
    """Index ``i`` of the segment ``[ts[i], ts[i+1])`` of the row times ``ts`` [s]
    (non-decreasing, at least 2) holding cycle time ``t_cycle`` [s]: the last row at or before
    it (``np.searchsorted(ts, t_cycle, side="right") - 1``, by bisection here so that numba and
    Python run one source), clipped to the first segment before the first row and to the last
    one at or beyond the last row."""
    lo, hi = 0, len(ts)  # the first row after t_cycle lies in lo .. hi (NumPy's bisection)
    while lo < hi:
        mid = (lo + hi) // 2
        if t_cycle < ts[mid]:
            hi = mid
        else:
            lo = mid + 1
    return min(max(lo - 1, 0), len(ts) - 2)


def cycle_evaluate(ts: np.ndarray, table: np.ndarray, T1: float, period: float, t: float,
                   row: np.ndarray) -> tuple[int, float, int, int, float]:
    """One sample of a periodic cycle at time ``t`` [s]: ``(cycle, t_cycle, phase, segment,
    weight)`` with the linear columns written into ``row``.

    ``ts`` the row times [s] (``(n,)``, non-decreasing from the cycle start, a time repeated only
    at a phase switch); ``table`` the linear columns' values per row (``(n, m)`` float64,
    :attr:`CycleSampler.table`); ``T1`` the cycle time of the phase switch [s]; ``period`` the
    cycle period [s]; ``row`` the caller's ``(m,)`` float64 array, set to the interpolation
    across the segment. ``cycle`` = ``floor(t / period)``, ``t_cycle`` [s] the time into it,
    ``phase`` :data:`GENERATION` below ``T1`` else :data:`RECOVERY`, ``segment`` its index
    (:func:`segment_of`), ``weight`` 0 .. 1 across it. A pure function (numba compiles it with
    the same bits as the Python call)."""
    k, tc = cycle_time(t, period)
    i = segment_of(ts, tc)
    w = min(max((tc - ts[i]) / (ts[i + 1] - ts[i]), 0.0), 1.0)
    # one array expression (the Python call's cost; compiled, a temporary array of a few values)
    row[:] = table[i] * (1.0 - w) + table[i + 1] * w
    return k, tc, GENERATION if tc < T1 else RECOVERY, i, w
