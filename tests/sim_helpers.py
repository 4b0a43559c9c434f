"""Stand-in ground stations for co-simulation tests (same ``step`` signature as
:class:`fdm_awe.groundstation.GroundStation`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass
class LineOutput:
    force_on_glider_ned: np.ndarray
    tension: float
    length: float
    reel_speed: float = 0.0
    omega: float = 0.0
    current: float = 0.0
    duty: float = 0.0
    p_electrical: float = 0.0
    event: str | None = None
    broken: bool = False


class FixedLengthLine:
    """Massless, dragless elastic line of fixed unstretched length ``length`` (m) from the winch
    at the origin: tension = k (d - length) + c d_dot when taut (k = EA/length), zero when slack.
    ``break_at`` N: the line breaks (event "tether_break") when the tension exceeds it."""

    def __init__(self, length: float, ea: float = 22.6e3, damping_ratio: float = 0.5, mass: float = 0.738,
                 break_at: float | None = None) -> None:
        self.length = length
        self.k = ea / length
        self.c = 2.0 * damping_ratio * math.sqrt(self.k * mass)
        self.break_at = break_at
        self.broken = False

    def step(self, dt, pos_ned, vel_ned, cmd):
        x, y, z = pos_ned
        d = math.sqrt(x * x + y * y + z * z)
        if self.broken or d <= self.length:
            return LineOutput(np.zeros(3), 0.0, self.length, broken=self.broken)
        ddot = (x * vel_ned[0] + y * vel_ned[1] + z * vel_ned[2]) / d
        tension = max(0.0, self.k * (d - self.length) + self.c * ddot)
        if self.break_at is not None and tension > self.break_at:
            self.broken = True
            return LineOutput(np.zeros(3), tension, self.length, event="tether_break", broken=True)
        f = np.array((x, y, z)) * (-tension / d)
        return LineOutput(f, tension, self.length)
