"""Real-time pacing of a simulation against the wall clock.

``RealtimePacer(factor)`` keeps simulation time ``t_sim`` at ``factor`` times wall time
(1.0 = real time, 2.0 = twice as fast). Each step the loop calls ``pacer.wait(t_sim)``
after computing the state at ``t_sim``; the pacer sleeps until the absolute wall-clock
deadline ``wall0 + (t_sim - t_sim0) / factor`` (monotonic clock). Deadlines are absolute,
so sleep errors do not accumulate (no drift), and a step that ran late is caught up by
not sleeping on the following steps. When the simulation falls more than ``max_lag_s``
behind (a slow stretch, a debugger stop) the pacer re-bases instead of racing to
catch up and counts a ``resync``.

Jitter of a step = wake-up time - deadline (>= 0 s; how late the step was released).
:meth:`RealtimePacer.stats` reports mean, 99th percentile and maximum in milliseconds.
"""

from __future__ import annotations

import math
import time
from array import array
from dataclasses import asdict, dataclass
from typing import Callable

from fdm_awe.errors import InputError


@dataclass(frozen=True)
class PacingStats:
    """Step-release statistics; times in ms except where stated."""

    steps: int
    factor: float
    mean_ms: float
    p99_ms: float
    max_ms: float
    late_steps: int          # steps released later than late_threshold_ms
    late_threshold_ms: float
    resyncs: int
    sim_s: float             # simulated time covered, s
    wall_s: float            # wall time covered, s
    achieved_factor: float   # sim_s / wall_s

    def as_dict(self) -> dict[str, float]:
        return asdict(self)


class RealtimePacer:
    """Sleeps the simulation loop against the wall clock (see module doc).

    Args:
        factor: simulation seconds per wall second (> 0, finite).
        max_lag_s: re-base when this far behind (wall seconds).
        late_threshold_ms: a step released later than this counts as late.
        clock, sleep: monotonic clock (s) and sleep function (s), replaceable in tests.
    """

    def __init__(self, factor: float = 1.0, *, max_lag_s: float = 0.5,
                 late_threshold_ms: float = 5.0,
                 clock: Callable[[], float] = time.monotonic,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        if not isinstance(factor, (int, float)) or not math.isfinite(factor) or factor <= 0:
            raise InputError(f"--realtime factor: {factor!r} must be a finite number > 0")
        if not isinstance(max_lag_s, (int, float)) or not max_lag_s > 0:
            raise InputError(f"pacer max_lag_s: {max_lag_s!r} must be > 0")
        self.factor = float(factor)
        self.max_lag_s = float(max_lag_s)
        self.late_threshold_ms = float(late_threshold_ms)
        self._clock = clock
        self._sleep = sleep
        self._wall0: float | None = None
        self._sim0 = 0.0
        self._first_wall = 0.0
        self._first_sim = 0.0
        self._last_sim = 0.0
        self._last_wall = 0.0
        self._jitter = array("d")
        self.resyncs = 0

    def start(self, t_sim: float = 0.0) -> None:
        """Anchor simulation time ``t_sim`` (s) to now. Called by the first wait() if not."""
        now = self._clock()
        self._wall0 = now
        self._sim0 = float(t_sim)
        self._first_wall = now
        self._first_sim = self._sim0
        self._last_sim = self._sim0
        self._last_wall = now

    def wait(self, t_sim: float) -> float:
        """Sleep until the wall-clock deadline of ``t_sim``; returns this step's jitter (s)."""
        if self._wall0 is None:
            self.start(t_sim)
            return 0.0
        deadline = self._wall0 + (t_sim - self._sim0) / self.factor
        now = self._clock()
        remaining = deadline - now
        if remaining > 0.0:
            self._sleep(remaining)
            now = self._clock()
        elif -remaining > self.max_lag_s:
            # far behind: re-base so that we do not race through the backlog
            self.resyncs += 1
            self._wall0 = now
            self._sim0 = float(t_sim)
            deadline = now
        jitter = now - deadline if now > deadline else 0.0
        self._jitter.append(jitter)
        self._last_sim = float(t_sim)
        self._last_wall = now
        return jitter

    def stats(self) -> PacingStats:
        """Statistics over all steps since start()."""
        j = sorted(self._jitter)
        n = len(j)
        if n:
            mean = sum(j) / n
            p99 = j[min(n - 1, int(math.ceil(0.99 * n)) - 1)]
            mx = j[-1]
        else:
            mean = p99 = mx = 0.0
        thr = self.late_threshold_ms * 1e-3
        late = sum(1 for x in j if x > thr)
        sim_s = self._last_sim - self._first_sim
        wall_s = self._last_wall - self._first_wall
        return PacingStats(
            steps=n, factor=self.factor, mean_ms=mean * 1e3, p99_ms=p99 * 1e3, max_ms=mx * 1e3,
            late_steps=late, late_threshold_ms=self.late_threshold_ms, resyncs=self.resyncs,
            sim_s=sim_s, wall_s=wall_s,
            achieved_factor=(sim_s / wall_s) if wall_s > 0 else math.nan)
