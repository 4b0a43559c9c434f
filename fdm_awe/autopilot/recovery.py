"""RECOVER, the autopilot's safe mode: its path and its winch.

Unfold, no thrust, glide to a circle of ``REC_RADIUS`` about the winch and descend on it at
``REC_AIRSPEED`` (stage ``return``); hold on it at its floor altitude (``hold``); with
``REC_LAND`` 1 turn into the wind for the final approach (``final``) and, below
``REC_FLARE_ALT``, fly wings level and flare (``flare``, no path). With ``REC_LAND`` 0, or when
vertical gusts exceed ``REC_GUST_MAX`` near the hold, the glider parks in the hold at
``REC_HOLD_ALT``. The winch brakes a paying-out drum in generator mode first, then reels in the
slack beyond ``REC_SLACK`` (at most ``REC_REEL_SPD``), and spools free on the final approach.
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from ..groundstation import WinchCommand
from ..sixdof.state import SixDofState
from .guidance import Guidance, norm3
from .params import ParamStore
from .tracking import RECOVERY, RefPoint
from .winch import pay_out


class Recovery:
    """The state of a recovery and the reference point and winch command of each of its steps.

    ``params``: the autopilot's parameters (``REC_*``); ``winch``: ``"physical"`` or ``"ideal"``
    (the paper plant's kinematic winch); ``load_resistance``: the generator's R_L [ohm];
    ``guidance``: reset when a recovery starts; ``note``: the autopilot's log."""

    def __init__(self, params: ParamStore, winch: str, load_resistance: float, guidance: Guidance,
                 note: Callable[[str], None]) -> None:
        self.params = params
        self.winch_kind = winch
        self.R_L = load_resistance
        self.guidance = guidance
        self._note = note
        #: the stage: None (not entered), "return" (to the circle, descending), "hold" (on the
        #: circle at its floor altitude), "final" (straight into the wind), "flare"
        self.stage: str | None = None
        self._sense = 1.0  # +1 clockwise, -1 counter-clockwise seen from above
        self._h = 0.0  # altitude reference [m]
        self._final: tuple[np.ndarray, np.ndarray] | None = None  # final approach: start, track
        self.park = False  #: the recovery parks in the hold instead of landing
        self._gust2 = 0.0  # mean square of the vertical wind [m^2/s^2], ~10 s filter

    def enter(self, s: SixDofState) -> None:
        """Start a recovery from glider state ``s``: circle in the sense the glider turns about
        the winch, from its altitude."""
        q = s.pos_ned[:2]
        v = s.vel_ned[:2]
        self._sense = 1.0 if float(q[0] * v[1] - q[1] * v[0]) >= 0.0 else -1.0
        self._h = -float(s.pos_ned[2])
        self.stage = "return"
        self._final = None
        self.park = self.params["REC_LAND"] < 0.5
        self._gust2 = 0.0
        self.guidance.reset()
        self._note(f"recovery: return to the {self.params['REC_RADIUS']:.0f} m circle "
                   f"({'counter-clockwise' if self._sense < 0 else 'clockwise'} seen from above)")

    def winch(self, s: SixDofState, gs: Any) -> WinchCommand:
        """The winch in RECOVER: brake a paying-out drum in generator mode first, then reel in
        the slack beyond REC_SLACK in motor mode; free spool on the final approach."""
        p = self.params
        d = norm3(s.hook_pos_ned)
        slack = (gs.length - d) if gs is not None else 0.0
        if self.stage in ("final", "flare"):
            # final approach and touchdown: free spool (open-circuit generator: only the drum's
            # friction and inertia resist), the line pays out if the glider reaches its end
            return pay_out(s, gs, 1.0e4, 2.0, self.winch_kind, p["REC_TENSION"])
        if gs is not None and (gs.reel_speed > p["REC_BRAKE_SPD"] or gs.tension > p["REC_TENSION"]):
            # the drum pays out fast or the line pulls: the generator brakes it through the
            # load (switching the machine to motor mode now would plug it: full supply voltage
            # on a back-EMF of the same sign, the armature current limited by its resistance only)
            return pay_out(s, gs, self.R_L, 0.0, self.winch_kind, p["REC_TENSION"])
        # keep REC_SLACK metres of slack: reel in the excess (the half-bridge drives the
        # motor one way only; line goes out through the generator when pulled)
        reel = -min(max(0.5 * (slack - p["REC_SLACK"]), 0.0), p["REC_REEL_SPD"])
        return WinchCommand(mode="motor", reel_speed_ref=reel)

    def _circle_field(self, q: np.ndarray) -> np.ndarray:
        """Horizontal unit vector of the recovery circle's guidance field at horizontal
        position ``q`` (m, north/east of the winch): tangent to the circle of REC_RADIUS in the
        recovery's sense on it, turned towards it by ``atan((rho - R) / (R / 2))`` off it
        (straight at the winch far outside, straight out near the centre)."""
        R = self.params["REC_RADIUS"]
        rho = math.hypot(q[0], q[1])
        er = q / rho if rho > 1e-6 else np.array([1.0, 0.0])
        et = self._sense * np.array([-er[1], er[0]])
        beta = math.atan((rho - R) / (0.5 * R))
        return math.cos(beta) * et - math.sin(beta) * er

    @staticmethod
    def _ground_speed(u: np.ndarray, wind: np.ndarray, V: float) -> float:
        """Ground speed [m/s] along horizontal unit vector ``u`` at airspeed ``V`` in the
        horizontal ``wind`` (at least half the airspeed: no hovering against a stronger wind)."""
        uw = float(u @ wind)
        return uw + math.sqrt(max(V * V - float(wind @ wind) + uw * uw, 0.25 * V * V))

    def _watch_gusts(self, wind: np.ndarray, h: float, dt: float) -> None:
        """Filter the vertical wind's mean square over ~10 s (``wind`` [m/s] NED, step ``dt``
        [s]); a landing recovery whose gusts exceed REC_GUST_MAX on the circle, below
        REC_HOLD_ALT + 10 m (``h`` [m]), parks in the hold instead."""
        p = self.params
        self._gust2 += (float(wind[2]) ** 2 - self._gust2) * min(dt / 10.0, 1.0)
        if not self.park and p["REC_LAND"] > 0.5 and math.sqrt(self._gust2) > p["REC_GUST_MAX"] \
                and self.stage in ("return", "hold") and h < p["REC_HOLD_ALT"] + 10.0:
            self.park = True
            self._note(f"recovery: vertical gusts {math.sqrt(self._gust2):.1f} m/s RMS above REC_GUST_MAX: "
                       f"no landing, parking in the hold at {p['REC_HOLD_ALT']:.0f} m")

    def reference(self, s: SixDofState, wind: np.ndarray, dt: float) -> RefPoint | None:
        """Reference point of the RECOVER guidance this step (stages ``return``, ``hold`` and
        ``final``; see the module doc) at glider state ``s`` in ``wind`` [m/s] NED, step ``dt``
        [s]; None in the flare."""
        p = self.params
        V = p["REC_AIRSPEED"]
        R = p["REC_RADIUS"]
        h = -float(s.pos_ned[2])
        w = np.array([wind[0], wind[1]])
        wn = math.hypot(w[0], w[1])
        q = np.array([s.pos_ned[0], s.pos_ned[1]])
        self._watch_gusts(wind, h, dt)
        land = p["REC_LAND"] > 0.5 and not self.park
        floor = p["REC_FINAL_ALT"] if land else p["REC_HOLD_ALT"]
        sink = V / p["REC_SLOPE"]
        if self.stage in ("return", "hold"):
            u = self._circle_field(q)
            on_circle = abs(math.hypot(q[0], q[1]) - R) < 0.25 * R
            if self.stage == "return" and on_circle and h < floor + 3.0:
                self.stage = "hold"
                self._note(f"recovery: on the circle at {h:.1f} m")
            upwind = wn < 1.0 or float(u @ w) < -0.87 * wn  # the track within 30 deg of the wind's eye
            if land and self.stage == "hold" and upwind:
                f = -w / wn if wn >= 1.0 else u
                self._final = (q.copy(), f)
                self.stage = "final"
                self._note(f"recovery: final approach from {h:.1f} m, track {math.degrees(math.atan2(f[1], f[0])):.0f} deg")
        if self.stage == "final":
            q0, f = self._final  # type: ignore[misc]
            if h < p["REC_FLARE_ALT"]:
                self.stage = "flare"
                self._note(f"recovery: flare at {h:.1f} m")
                return None
            along = float((q - q0) @ f)
            pos_h = q0 + along * f
            vg = self._ground_speed(f, w, V)
            self._h = min(max(self._h - sink * dt, 0.0), h + 10.0)
            vel = np.array([vg * f[0], vg * f[1], sink if self._h > 0.0 else 0.0])
            acc = np.zeros(3)
        elif self.stage == "flare":
            return None
        else:
            vg = self._ground_speed(u, w, V)
            # the field's turn along the track: a = vg^2 du/ds (finite difference over 1 m)
            du = self._circle_field(q + u) - u
            self._h = min(max(self._h - sink * dt, floor), h + 10.0)
            descending = self._h > floor
            vel = np.array([vg * u[0], vg * u[1], sink if descending else 0.0])
            acc = np.array([vg * vg * du[0], vg * vg * du[1], 0.0])
            pos_h = q
        pos = np.array([pos_h[0], pos_h[1], -self._h])
        return RefPoint(t_cycle=0.0, cycle=0, phase=RECOVERY, pos=pos, vel=vel, acc=acc, airspeed=V, alpha=0.0,
                        phi=0.0, thrust=0.0, tension=0.0, length=0.0, reel_speed=0.0)

    @property
    def holds(self) -> bool:
        """The recovery holds on the circle for good (REC_LAND 0, or vertical gusts above
        REC_GUST_MAX)."""
        return self.stage == "hold" and self.park

    def in_hold(self, s: SixDofState) -> bool:
        """Glider state ``s`` circles within 5 m of REC_HOLD_ALT, within a quarter of REC_RADIUS
        of the circle."""
        rho = math.hypot(float(s.pos_ned[0]), float(s.pos_ned[1]))
        return (abs(-float(s.pos_ned[2]) - self.params["REC_HOLD_ALT"]) < 5.0
                and abs(rho - self.params["REC_RADIUS"]) < 0.25 * self.params["REC_RADIUS"])
