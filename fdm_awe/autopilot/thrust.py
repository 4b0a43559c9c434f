"""The thrust loop: the throttle that gives the guidance's thrust (feed-forward plus PI on the
measured thrust), or the paper plant's ideal thruster taking the thrust command itself.

The arithmetic is one pure function, :func:`throttle_step` (floats and a float64 integrator
array: numba compiles it for the co-simulation kernel, Python runs the same source)."""

from __future__ import annotations

import math
from typing import Any

from .. import slots
from ..sixdof.state import SixDofState
from .params import ParamStore

#: layout of the thrust loop's state array: the PI integral (throttle fraction), the last
#: throttle and the last thrust command [N] of the running motor (where a soft stop starts
#: from, :func:`.motor.motor_spin_down`)
THR = slots.declare("ThrustState", ("integral", "last", "thrust"))


def throttle_step(thrust_cmd: float, thrust: float, airspeed: float, dt: float, armed: bool, u_max: float,
                  kp: float, ki: float, v_zero: float, thrust_max_static: float, integ: Any) -> float:
    """Throttle in [0, ``u_max``]: feed-forward plus PI on the measured ``thrust`` [N] for
    ``thrust_cmd`` [N] at ``airspeed`` [m/s], step ``dt`` [s]; ``kp`` [1/N], ``ki`` [1/(N s)]
    the PI gains, ``v_zero`` [m/s] the airspeed of zero thrust at full throttle,
    ``thrust_max_static`` [N] the static thrust at full throttle. ``integ``: the state
    (``THR.integral``; a float64 array, or run by Python any mutable sequence), updated in place:
    the integral limited to +-1, the last integration undone when the throttle saturates
    (anti-windup); disarmed: 0 and the integral reset."""
    # max/min spelled out as Python's max(a, b) / min(a, b) evaluate them (the same compiled)
    if not armed:
        integ[THR.integral] = 0.0
        return 0.0
    e = thrust_cmd - thrust
    v0 = airspeed / v_zero
    v0 = 0.0 if 0.0 > v0 else v0
    v0 = 1.0 if 1.0 < v0 else v0
    tc = 0.0 if 0.0 > thrust_cmd else thrust_cmd
    tc = tc / thrust_max_static
    tc = 1.0 if 1.0 < tc else tc
    ff = v0 + (1.0 - v0) * math.sqrt(tc)
    i = integ[THR.integral] + ki * e * dt
    i = -1.0 if -1.0 > i else i
    i = 1.0 if 1.0 < i else i
    u = ff + kp * e + i
    if u > u_max or u < 0.0:  # anti-windup: undo the last integration when saturated
        i -= ki * e * dt
    integ[THR.integral] = i
    u = 0.0 if 0.0 > u else u
    return u_max if u_max < u else u


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
        self.state = slots.new(THR)  #: the loop's state (:data:`THR`), updated in place
        self._thrust_max_static = thrust_max_static
        self._v_zero_thrust = params["THR_VZERO"]

    @property
    def v_zero(self) -> float:
        """THR_VZERO as the loop was built with [m/s]."""
        return self._v_zero_thrust

    @property
    def thrust_max_static(self) -> float:
        """Static thrust at full throttle [N]."""
        return self._thrust_max_static

    def throttle(self, thrust_cmd: float, thrust: float, airspeed: float, dt: float, armed: bool,
                 u_max: float = 1.0) -> float:
        """Feed-forward plus PI on the measured ``thrust`` [N] for ``thrust_cmd`` [N] at
        ``airspeed`` [m/s], step ``dt`` [s]. Thrust 0 is flown as zero thrust with the motor
        running (the propeller turning at its zero-thrust advance ratio); stopping the motor is
        the motor switch's decision. ``u_max``: the throttle's ceiling (the soft start after a
        motor start); disarmed: 0, the integral reset."""
        p = self.params
        return throttle_step(thrust_cmd, thrust, airspeed, dt, armed, u_max, p["THR_KP"], p["THR_KI"],
                             self._v_zero_thrust, self._thrust_max_static, self.state)

    def propulsion(self, thrust_cmd: float, s: SixDofState, dt: float, armed: bool, u_max: float = 1.0) -> float:
        """Throttle for ``thrust_cmd`` [N] at glider state ``s`` (at most ``u_max``); with an ideal
        thruster it takes the command (0 disarmed) and the propeller's throttle stays at zero."""
        if self.thruster is not None:
            self.thruster.command(thrust_cmd if armed else 0.0)
            return 0.0
        return self.throttle(thrust_cmd, s.thrust_N, s.airspeed, dt, armed, u_max)
