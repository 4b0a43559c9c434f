"""RECOVER's (and LOITER's) flying by the autopilot: the recovery's path
(:class:`~fdm_awe.autopilot.recovery.Recovery`) flown by the guidance with the motor stopped in
the glide, or the flare, the throttle's soft stop and start, and whether the glider is parked
in the hold.

:class:`RecoverMode` is the part of :class:`~fdm_awe.autopilot.autopilot.Autopilot` that
flies these modes; it works on the autopilot's state (glider, guidance, recovery, thrust loop,
motor gate), which the autopilot sets up.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..groundstation import WinchCommand
from ..sixdof.state import SixDofState, Surfaces


class RecoverMode:
    """RECOVER's and LOITER's commands (see the module doc); a base of
    :class:`~fdm_awe.autopilot.autopilot.Autopilot`."""

    @property
    def parked(self) -> bool:
        """RECOVER holds (REC_LAND 0, or vertical gusts above REC_GUST_MAX): circling within 5 m of
        REC_HOLD_ALT, within a quarter of REC_RADIUS of the circle (the line is reeled in to the
        distance plus REC_SLACK)."""
        rec = self.recovery
        return self.mode == "RECOVER" and rec.holds and rec.in_hold(self.glider.state())

    def _recover(self, s: SixDofState, gs: Any, dt: float) -> tuple[Surfaces, WinchCommand]:
        """RECOVER's (and LOITER's) commands: the recovery's path flown by the guidance, or the flare
        (wings level)."""
        self.phase = "recovery"
        rec = self.recovery
        if rec.stage is None:
            rec.enter(s)
        wind = s.vel_ned - s.vel_air_ned
        r = rec.reference(s, wind, dt)
        wcmd = rec.winch(s, gs)
        if r is None:
            # flare: wings level until the skids touch (:meth:`~.recovery.Recovery.flare`)
            self.ref_point = None
            alpha, thrust = rec.flare(s, self.glider.trim_alpha(max(s.airspeed, 5.0)))
            thr = self._recover_throttle(thrust, thrust <= 0.0, s, dt)
            return self._hold(s, alpha, 0.0, 0.0, dt, thr), wcmd
        self.ref_point = r
        f_t = np.asarray(gs.force_on_glider_ned) if gs is not None else np.zeros(3)
        # the motor is stopped while the path descends (the glide), it holds the level floor
        cmd = self.guidance.update(r, s.pos_ned, s.vel_ned, wind, f_t, s.fold, dt,
                                   thrust_max=0.0 if rec.gliding else None)
        self.last_guidance = cmd
        self.track_error = cmd.pos_error
        thr = self._recover_throttle(cmd.thrust, rec.gliding, s, dt)
        return self._hold(s, cmd.alpha, cmd.roll, 0.0, dt, thr), wcmd

    def _recover_throttle(self, thrust: float, stopped: bool, s: SixDofState, dt: float) -> float:
        """RECOVER's throttle for ``thrust`` [N] at glider state ``s``, step ``dt`` [s]: with the
        motor ``stopped`` (the glide) the throttle's ceiling falls from its last value to 0 over
        the motor gate's ``soft_stop_s`` (at 0 the ESC brakes the propeller: no thrust, no
        windmill drag, only the idle power P0), running it rises to 1 over ``soft_start_s``
        (:class:`~.motor.MotorGate`: the same soft stop and start as AUTO's motor)."""
        g = self.motor.gate
        if stopped:
            drop = dt / g.soft_stop_s if g.soft_stop_s > 0.0 else 1.0
            self._rec_ceiling = max(min(self._rec_ceiling, self._rec_throttle) - drop, 0.0)
        else:
            rise = dt / g.soft_start_s if g.soft_start_s > 0.0 else 1.0
            self._rec_ceiling = min(self._rec_ceiling + rise, 1.0)
        thr = self.thrust_loop.propulsion(thrust, s, dt, self.armed, u_max=self._rec_ceiling)
        self._rec_throttle = thr
        return thr
