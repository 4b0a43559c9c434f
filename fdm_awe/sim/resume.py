"""After a lull: what the lost-path failsafe met, and AUTO again when the wind is back.

In a lull the glider cannot hold its cycle's path; the lost-path failsafe (FS_TRK_ERR) takes it
to RECOVER, and in gusty air RECOVER parks in the hold circle about the winch instead of landing.
A pumping kite system on the ground waits out the lull and relaunches; here the glider is still
flying, so it waits in the hold and goes back to its cycle when the onboard wind estimate says
the wind is back:

- :func:`failsafe_wind`: the failsafe's wind for the flight's message (a lull named by its wind
  and length, :func:`fdm_awe.autopilot.wind_estimate.wind_before`);
- :class:`HoldWatch`: while the glider holds after a lost-path failsafe that met a lull (the
  onboard estimate of the cycle's last :data:`~fdm_awe.autopilot.wind_estimate.LULL_WINDOW`
  seconds below :data:`~fdm_awe.autopilot.wind_estimate.LULL_SHARE` of the cycle's wind in one of
  its slices; a path lost in a good wind is another fault: the glider stays parked), the wind
  estimate over
  the last FS_RESUME seconds of the hold (sensed quantities only: pitot airspeed, AHRS attitude,
  GPS ground velocity; :func:`fdm_awe.autopilot.wind_estimate.estimate_wind`, the circle turns
  the heading through every direction, so the two wind components are well determined); at
  FS_RESUME_SHR of the wind the cycle was made for (at the profile's reference height, as the
  references record it) or more, AUTO again: the autopilot rejoins its cycle where the glider is
  (the rejoin of LOITER -> AUTO). FS_RESUME 0: the glider stays parked (the old behaviour).

The estimate runs every :data:`CHECK_S` seconds of the hold, on samples at
:data:`~fdm_awe.sim.onboard_wind.SENSE_HZ`.
"""

from __future__ import annotations

import math
from collections import deque
from typing import Any

import numpy as np

from ..autopilot.wind_estimate import estimate_wind, wind_before, wind_before_text
from ..wind import WindProfile
from .onboard_wind import SENSE_HZ

#: how often the hold's wind is estimated [s]
CHECK_S = 1.0


def lost_path(cause: str | None) -> bool:
    """Whether ``cause`` (:attr:`~fdm_awe.autopilot.autopilot.Autopilot.recover_cause`) is the
    lost-path failsafe's."""
    return cause is not None and cause.startswith("failsafe") and "FS_TRK_ERR" in cause


def failsafe_wind(res: Any, ap: Any, profile: WindProfile, dt: float) -> str:
    """What the lost-path failsafe met, for the flight's message: the onboard wind estimate over
    the window before it (:func:`fdm_awe.autopilot.wind_estimate.wind_before`, samples at
    :data:`SENSE_HZ` of the flight result ``res`` with steps ``dt`` [s]), a lull named by its wind
    and length; "" when it cannot tell."""
    t_fs = [t for t, text in ap.log if text.startswith("failsafe")]
    w_cycle = float(ap.reference.meta.get("wind_mps", math.nan)) if ap.reference is not None else math.nan
    if not t_fs or not w_cycle > 0.0:
        return ""
    k = slice(None, None, max(1, int(round(1.0 / (SENSE_HZ * dt)))))
    w = wind_before(res.t[k], res.vel[k], res.airspeed[k], res.euler[k], -res.pos[k][:, 2],
                    None if profile.uniform else profile.factor, t_fs[-1], w_cycle)
    return "" if w is None else f"; {wind_before_text(w, w_cycle)}"


class HoldWatch:
    """The wind in the hold after a lost-path failsafe, and the return to AUTO (module doc), for
    a flight of ``glider`` (its ``convert_raw``) with steps of ``dt`` [s] in the onboard wind
    profile ``profile``; ``cycle_wind`` is the flight's :class:`~fdm_awe.sim.onboard_wind.CycleWind`
    (with a reference set, the resumed cycle is the set's member for the wind found)."""

    def __init__(self, glider: Any, dt: float, profile: WindProfile, cycle_wind: Any = None) -> None:
        self.glider = glider
        self.dt = dt
        self.stride = max(1, int(round(1.0 / (SENSE_HZ * dt))))  #: steps between samples
        self.profile = profile
        self.cycle_wind = cycle_wind
        self._rows: deque[tuple[float, tuple]] = deque()
        self._next = -math.inf  # the time of the next estimate [s]
        self._lull: bool | None = None  # whether the failsafe met a lull (None: not yet asked)
        self.resumed = 0  #: how many times the flight went back to AUTO

    def step(self, k: int, t: float, raw: Any, ap: Any) -> bool:
        """After step ``k`` at time ``t`` [s] with the raw JSBSim row ``raw``: keep the hold's
        samples and, with the wind back, put the autopilot ``ap`` in AUTO; whether it did."""
        window = float(ap.params["FS_RESUME"])
        if window <= 0.0 or ap.mode != "RECOVER" or not lost_path(ap.recover_cause):
            self._lull = None
        if self._lull is None and window > 0.0 and ap.mode == "RECOVER" and lost_path(ap.recover_cause):
            self._lull = self._met_lull(t, ap)  # the first step after the failsafe
        if not self._lull or not ap.parked:
            self._rows.clear()
            self._next = -math.inf
            return False
        if k % self.stride == 0:
            self._rows.append((t, tuple(raw)))
        while self._rows and self._rows[0][0] <= t - window:
            self._rows.popleft()
        if self._next == -math.inf:
            self._next = t + window  # a whole window of the hold first
        if t < self._next or not self._rows:
            return False
        self._next = t + CHECK_S
        si = self.glider.convert_raw(np.array([r for _, r in self._rows], float))
        est = estimate_wind(si["vel_ned"], si["airspeed"], si["euler"], -si["pos_ned"][:, 2],
                            None if self.profile.uniform else self.profile.factor)
        if est is None:
            return False
        new = None
        cw = self.cycle_wind
        if cw is not None and cw.refs is not None:
            i = cw.refs.nearest(est.speed, cw.current)
            w_cycle = cw.refs.entries[i].wind_mps
        else:
            w_cycle = float(ap.reference.meta.get("wind_mps", math.nan))
        share = float(ap.params["FS_RESUME_SHR"])
        if not est.speed >= share * w_cycle:
            return False
        if cw is not None and cw.refs is not None:
            new = cw.next_reference(est)
        ap.wind_estimate = est
        ap.log.append((t, f"wind back: {est.speed:.1f} m/s over the last {window:g} s of the hold "
                          f"(FS_RESUME_SHR {share:g} x the cycle's {w_cycle:g} m/s), AUTO again"))
        if new is not None:
            ap.switch_reference(new)
        ap.set_mode("AUTO")
        self._rows.clear()
        self._next = -math.inf
        self._lull = None
        self.resumed += 1
        return True

    def _met_lull(self, t: float, ap: Any) -> bool:
        """Whether the lost-path failsafe just before ``t`` [s] met a lull: the onboard estimate
        over the cycle's rows so far (:meth:`~fdm_awe.sim.onboard_wind.CycleWind.peek`,
        :func:`~fdm_awe.autopilot.wind_estimate.wind_before`); False when it cannot tell."""
        cw = self.cycle_wind
        rows = None if cw is None else cw.peek()
        w_cycle = float(ap.reference.meta.get("wind_mps", math.nan)) if ap.reference is not None else math.nan
        if rows is None or not w_cycle > 0.0:
            return False
        si = self.glider.convert_raw(rows)
        w = wind_before(si["t"], si["vel_ned"], si["airspeed"], si["euler"], -si["pos_ned"][:, 2],
                        None if self.profile.uniform else self.profile.factor, t, w_cycle)
        return w is not None and w["lull_s"] > 0.0
