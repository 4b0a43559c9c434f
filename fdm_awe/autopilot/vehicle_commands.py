"""What a ground station and a pilot command of the autopilot (its
:class:`~fdm_awe.autopilot.vehicle.VehicleInterface`, through MAVLink): the modes and their
change, the pilot's sticks, arming, the lost-link failsafe, cycling and the mission (the path
uploaded, checked and loaded as the reference, or kept when it is the reference's own).

:class:`VehicleCommands` is the part of :class:`~fdm_awe.autopilot.autopilot.Autopilot`
that answers these commands; it works on the autopilot's state (its mode, reference, path
parameter, guidance, recovery and log), which the autopilot sets up and flies.
"""

from __future__ import annotations

import math

import numpy as np

from ..mode_table import MODE_NUMBERS
from ..sixdof.state import Surfaces
from ..trajectory import PHASE_NAMES
from .tracking import TrackingReference
from .vehicle import Waypoint

MODES = ("MANUAL", "FBWA", "AUTO", "RECOVER", "LOITER")
#: how far [m] an uploaded point may lie from the reference's own to be its own path
#: (:meth:`VehicleCommands.own_path`)
OWN_PATH_TOL_M = 1.0


class VehicleCommands:
    """The ground station's and the pilot's commands of the autopilot (see the module doc);
    a base of :class:`~fdm_awe.autopilot.autopilot.Autopilot`, whose state they change."""

    @property
    def modes(self) -> list[str]:
        return [m for m in MODES if m in MODE_NUMBERS]

    def set_mode(self, name: str) -> bool:
        if name not in MODES:
            return False
        if name == "AUTO" and self.reference is None:
            return False
        if name != self.mode:
            self._note(f"mode {self.mode} -> {name}")
            self._trk_since = math.nan  # the lost-path failsafe times from the new mode's steps
            if name in ("RECOVER", "LOITER"):
                self.phase = "recovery"
                self.recovery.stage = None  # a new recovery from wherever the glider is
                self.recovery.hold_only = name == "LOITER"  # LOITER: the park, never the landing
                self.recover_cause = self._failsafe_note or "commanded"
                self._rec_ceiling = self._rec_throttle = 1.0  # the motor may be running: a soft stop
            else:
                self.recover_cause = None
            if name == "AUTO":
                self._rejoin_pending = True  # rejoin the path from the glider's own state
        self.mode = name
        return True

    def set_pilot(self, aileron: float, elevator: float, rudder: float, throttle: float) -> None:
        """The pilot's sticks (see :mod:`fdm_awe.autopilot.autopilot`): surfaces -1..1 with
        :class:`Surfaces`' signs (``elevator`` > 0 nose down, ``rudder`` > 0 nose left),
        ``throttle`` 0..1; values outside are clipped. MANUAL flies them as they are (the fold
        command kept), FBWA as bank, angle of attack and throttle."""
        def clip(x: float, lo: float) -> float:
            x = float(x)
            return min(max(x, lo), 1.0) if x == x else 0.0
        a, e, r, thr = clip(aileron, -1.0), clip(elevator, -1.0), clip(rudder, -1.0), clip(throttle, 0.0)
        self.manual = Surfaces(a, e, r, thr, self.manual.fold_cmd)
        self.pilot = (a, -e, thr)

    def arm(self, on: bool, force: bool = False) -> bool:
        """Arm or disarm the motor. A disarm in flight is refused unless ``force`` (as
        ArduPilot refuses it: MAV_CMD_COMPONENT_ARM_DISARM with param2 21196 forces it)."""
        if not on and self.armed and self.airborne and not force:
            self._note("disarm refused: in flight (force it with 21196)")
            return False
        self.armed = bool(on)
        self._note(("armed" if on else "disarmed") + (" (forced)" if force else ""))
        return True

    def gcs_link(self, up: bool, t: float) -> None:
        """The ground-station link's state at time ``t`` [s]. With FS_GCS_ENABL 1, a link that
        was up once and has been lost for FS_LONG_TIMEOUT switches an armed glider in flight
        to RECOVER (once per loss; the ground station may take another mode afterwards)."""
        now_up, ever, t_lost = self._gcs
        if up:
            self._gcs = (True, True, -math.inf)
            return
        if now_up:
            self._gcs = (False, ever, t)
            return
        p = self.params
        if (ever and p["FS_GCS_ENABL"] > 0.5 and t - t_lost >= p["FS_LONG_TIMEOUT"] and self.mode != "RECOVER"
                and self.armed and self.airborne):
            self._failsafe(f"failsafe: ground-station link lost for {t - t_lost:.1f} s")
            self._gcs = (False, ever, math.inf)  # acted on this loss

    def start_cycling(self) -> bool:
        if self.reference is None:
            return False
        if not self.cycling:
            # restart the cycle at the reference point nearest to where the glider is
            self.s_ref = self._cycle_start() + self._nearest_cycle_time()
            self.guidance.reset()
            self._rejoin_pending = True
            self._note("cycling started")
        self.cycling = True
        return True

    def stop_cycling(self) -> bool:
        if self.cycling:
            self._note("cycling stopped")
        self.cycling = False
        return True

    def mission(self) -> list[Waypoint]:
        if self.reference is None:
            return []
        return [Waypoint(n, e, d, t, PHASE_NAMES[p]) for n, e, d, t, p in self.reference.waypoints()]

    def set_mission(self, wps: list[Waypoint]) -> tuple[bool, str]:
        """Load the path ``wps`` as the reference (see :meth:`own_path` for the vehicle's own
        path uploaded back, which keeps the reference); ``(accepted, reason)``."""
        if len(wps) < 3:
            return False, f"need at least 3 waypoints, got {len(wps)}"
        if self.own_path(wps):
            # the reference's own path uploaded back (a download, MAVProxy's `wp save` and
            # `wp load`): a mission item carries only a position, not the cycle's phases,
            # timing, tension, reel speed, fold and motor, so rebuilding the reference from the
            # items would fly another cycle (no recovery phase); the cycle is kept as it is
            self._note(f"mission of {len(wps)} waypoints is the reference's own path: its cycle kept")
            return True, "own path"
        P = np.array([[w.north, w.east, w.down] for w in wps], float)
        if not np.all(np.isfinite(P)):
            return False, "waypoint not finite"
        if np.any(P[:, 2] > -5.0):
            return False, "every waypoint must be at least 5 m above the winch"
        if np.any(np.linalg.norm(P, axis=1) > 400.0):
            return False, "waypoint beyond 400 m from the winch"
        times = [w.time_s for w in wps]
        phases = [w.phase for w in wps]
        if all(t is not None for t in times) and np.all(np.diff(np.array(times, float)) > 0):
            tt = np.array(times, float)
            tt = tt - tt[0]
        else:
            tt = None
        ph = np.array([1 if p == "recovery" else 0 for p in phases]) if any(p == "recovery" for p in phases) else None
        speed = float(np.mean(self.reference.airspeed)) if self.reference is not None else 15.0
        self.reference = TrackingReference.from_waypoints(P, tt, ph, speed)
        self.guidance.reset()
        self._note(f"mission of {len(wps)} waypoints loaded")
        if self.cycling:
            self.s_ref = self._cycle_start() + self._nearest_cycle_time()
        return True, "accepted"

    def own_path(self, wps: list[Waypoint]) -> bool:
        """Whether ``wps`` is the loaded reference's own path, as :meth:`mission` gives it:
        as many points, each within :data:`OWN_PATH_TOL_M` of its own (the resolution of a
        mission item's position: 1e-7 deg in MISSION_ITEM_INT, float32 degrees in
        MISSION_ITEM, about 0.4 m of latitude)."""
        if self.reference is None:
            return False
        own = self.mission()
        if len(own) != len(wps):
            return False
        P = np.array([[w.north, w.east, w.down] for w in wps], float)
        Q = np.array([[w.north, w.east, w.down] for w in own], float)
        return bool(np.all(np.isfinite(P))) and float(np.max(np.linalg.norm(P - Q, axis=1))) <= OWN_PATH_TOL_M

    def clear_mission(self) -> None:
        self.reference = None
        self._note("mission cleared")
        if self.mode == "AUTO":
            self.set_mode("RECOVER")

    def _failsafe(self, text: str) -> None:
        """A failsafe takes the glider to RECOVER: ``text`` noted and kept as the
        :attr:`~fdm_awe.autopilot.autopilot.Autopilot.recover_cause`."""
        self._note(text)
        self._failsafe_note = text
        try:
            self.set_mode("RECOVER")
        finally:
            self._failsafe_note = None
