"""The thrust loop: the throttle that gives the guidance's thrust (feed-forward plus PI on the
measured thrust), or the paper plant's ideal thruster taking the thrust command itself."""

from __future__ import annotations

import math
from typing import Any

from ..sixdof.state import SixDofState
from .params import ParamStore


class ThrustLoop:
    """Throttle for a thrust command. ``params``: THR_KP, THR_KI and THR_VZERO (the airspeed
    [m/s] at which the propeller gives zero thrust at full throttle: its zero-thrust advance
    ratio times the tip speed scale; it sets the feed-forward); ``thrust_max_static``: the
    static thrust at full throttle [N]; ``thruster``: the paper plant's ideal thruster
    (:class:`fdm_awe.sim.paper_plant.IdealThruster`), which takes the thrust command instead of
    the propeller's throttle (held at zero), or None."""

    def __init__(self, params: ParamStore, thrust_max_static: float, thruster: Any = None) -> None:
        self.params = params
        self.thruster = thruster
        self._integral = 0.0
        self._thrust_max_static = thrust_max_static
        self._v_zero_thrust = params["THR_VZERO"]

    def throttle(self, thrust_cmd: float, thrust: float, airspeed: float, dt: float, armed: bool,
                 u_max: float = 1.0) -> float:
        """Feed-forward plus PI on the measured ``thrust`` [N] for ``thrust_cmd`` [N] at
        ``airspeed`` [m/s], step ``dt`` [s]. Thrust 0 is flown as zero thrust with the motor
        running (the propeller turning at its zero-thrust advance ratio); stopping the motor is
        the motor switch's decision. ``u_max``: the throttle's ceiling (the soft start after a
        motor start); disarmed: 0, the integral reset."""
        p = self.params
        if not armed:
            self._integral = 0.0
            return 0.0
        e = thrust_cmd - thrust
        v0 = min(max(airspeed / self._v_zero_thrust, 0.0), 1.0)
        ff = v0 + (1.0 - v0) * math.sqrt(min(max(thrust_cmd, 0.0) / self._thrust_max_static, 1.0))
        self._integral = min(max(self._integral + p["THR_KI"] * e * dt, -1.0), 1.0)
        u = ff + p["THR_KP"] * e + self._integral
        if u > u_max or u < 0.0:  # anti-windup: undo the last integration when saturated
            self._integral -= p["THR_KI"] * e * dt
        return min(max(u, 0.0), u_max)

    def propulsion(self, thrust_cmd: float, s: SixDofState, dt: float, armed: bool, u_max: float = 1.0) -> float:
        """Throttle for ``thrust_cmd`` [N] at glider state ``s`` (at most ``u_max``); with an ideal
        thruster it takes the command (0 disarmed) and the propeller's throttle stays at zero."""
        if self.thruster is not None:
            self.thruster.command(thrust_cmd if armed else 0.0)
            return 0.0
        return self.throttle(thrust_cmd, s.thrust_N, s.airspeed, dt, armed, u_max)

    def stop(self) -> float:
        """Throttle 0 with the motor stopped (the ESC brakes the propeller; the integral is held
        for the restart); an ideal thruster takes zero thrust."""
        if self.thruster is not None:
            self.thruster.command(0.0)
        return 0.0
