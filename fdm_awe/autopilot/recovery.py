"""RECOVER, the autopilot's safe mode: its path and its winch.

Unfold, glide to a circle of ``REC_RADIUS`` about the winch and descend on it at
``REC_AIRSPEED`` (stage ``return``), motor stopped, at the path's slope ``REC_SLOPE`` or as
steeply as the glider must (a glider on its line cannot hold 1:10: the path follows its own
glide); hold on it at its floor altitude (``hold``); with
``REC_LAND`` 1 turn off it on its downwind side onto the final approach, a straight line into
the wind over the winch (``final``), and, below ``REC_FLARE_ALT``, fly wings level and flare
(``flare``, no path). The motor runs only where the glide cannot do: level on the floor
(the hold, the wait for the turn onto the final), on the final approach (its 1:REC_SLOPE line
must reach the winch) and against a stall in the flare. With
``REC_LAND`` 0, or when
vertical gusts exceed ``REC_GUST_MAX`` near the hold, the glider parks in the hold at
``REC_HOLD_ALT``. The winch brakes a paying-out drum in generator mode first, then reels in the
slack beyond ``REC_SLACK`` (``REC_SLK_KL`` per metre, at most ``REC_REEL_SPD``), and spools free
on the final approach (``REC_SPOOL_RL``).

Every number of the recovery is an autopilot parameter (``REC_*``, ``autopilot.xml``, MAVLink
visible); what remains here are the geometry's own tolerances (a metre about the altitude
reference, the turn's 0.1 rad window, calm air below 1 m/s).
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from ..groundstation import WinchCommand
from ..sixdof.state import SixDofState
from .guidance import norm3
from .guidance_loop import Guidance
from .params import ParamStore
from ..trajectory.schema import RECOVERY
from .tracking import RefPoint
from .winch import pay_out


#: the steepest recovery path [m flown per m of descent] (REC_SLOPE's least value): the most
#: the altitude reference follows a glider sinking faster than the path
SLOPE_MIN = 3.0


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
        #: final approach: its track (unit vector, the line passes over the winch) and, while
        #: the glider turns onto it, the turn's centre [m] and radius [m] (None, 0 on the line)
        self._final: tuple[np.ndarray, np.ndarray | None, float] | None = None
        self.park = False  #: the recovery parks in the hold instead of landing
        #: the recovery is LOITER's: it parks in the hold whatever REC_LAND says
        self.hold_only = False
        self._gust2 = 0.0  # mean square of the vertical wind [m^2/s^2], ~10 s filter
        #: the last step's path descended to the floor (stages ``return`` and ``hold`` above it):
        #: the motor is stopped, the glider glides (docs/design.md section 8b)
        self.gliding = False

    def enter(self, s: SixDofState) -> None:
        """Start a recovery from glider state ``s``: circle in the sense the glider turns about
        the winch, from its altitude."""
        q = s.pos_ned[:2]
        v = s.vel_ned[:2]
        self._sense = 1.0 if float(q[0] * v[1] - q[1] * v[0]) >= 0.0 else -1.0
        self._h = -float(s.pos_ned[2])
        self.stage = "return"
        self._final = None
        self.gliding = False
        self.park = self.hold_only or self.params["REC_LAND"] < 0.5
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
            return pay_out(s, gs, p["REC_SPOOL_RL"], p["REC_SPOOL_SLK"], self.winch_kind, p["REC_TENSION"],
                           p["REC_SLK_KL"], p["REC_TENS_KT"])
        if gs is not None and (gs.reel_speed > p["REC_BRAKE_SPD"] or gs.tension > p["REC_TENSION"]):
            # the drum pays out fast or the line pulls: the generator brakes it through the
            # load (switching the machine to motor mode now would plug it: full supply voltage
            # on a back-EMF of the same sign, the armature current limited by its resistance only)
            return pay_out(s, gs, self.R_L, 0.0, self.winch_kind, p["REC_TENSION"], p["REC_SLK_KL"], p["REC_TENS_KT"])
        # keep REC_SLACK metres of slack: reel in the excess (the half-bridge drives the
        # motor one way only; line goes out through the generator when pulled)
        reel = -min(max(p["REC_SLK_KL"] * (slack - p["REC_SLACK"]), 0.0), p["REC_REEL_SPD"])
        return WinchCommand(mode="motor", reel_speed_ref=reel)

    def _circle_field(self, q: np.ndarray, centre: np.ndarray | None = None, radius: float = 0.0) -> np.ndarray:
        """Horizontal unit vector of a circle's guidance field at horizontal position ``q`` (m,
        north/east of the winch): tangent to the circle of ``radius`` [m] about ``centre`` [m]
        (default: REC_RADIUS about the winch) in the recovery's sense on it, turned towards it
        by ``atan((rho - R) / (w R))`` off it (REC_CAPT_W ``w``; straight at the centre far
        outside, straight out near the centre)."""
        if centre is None:
            R = self.params["REC_RADIUS"]
        else:
            R = radius
            q = q - centre
        rho = math.hypot(q[0], q[1])
        er = q / rho if rho > 1e-6 else np.array([1.0, 0.0])
        et = self._sense * np.array([-er[1], er[0]])
        beta = math.atan((rho - R) / (self.params["REC_CAPT_W"] * R))
        return math.cos(beta) * et - math.sin(beta) * er

    def _turn_onto_final(self, q: np.ndarray, wind: np.ndarray) -> tuple[np.ndarray, np.ndarray, float] | None:
        """The final approach if the glider, holding on the circle at horizontal position ``q``
        [m], turns onto it now, else None: its track (unit vector into the horizontal ``wind``
        [m/s]; in calm air, below 1 m/s, any direction: the turn begins now) and the centre [m]
        and radius [m] of the turn onto it.

        The final is the straight line over the winch: the touchdown lies the final's and the
        flare's ground run beyond the turn's end, which is ``sqrt(R^2 - 2 R r)`` downwind of the
        winch. (Left where the circle's track points upwind, abeam the winch, the touchdown would
        lie that run and REC_RADIUS ``R`` from the winch at right angles: beyond the landing
        bound when a weak headwind makes the run long.) The turn, in the circle's sense, is
        tangent to the circle and to the line: radius ``r`` for 45 deg bank at the fastest
        ground speed, ``(V + |wind|)^2 / g`` (REC_AIRSPEED ``V``), at most REC_TURN_RMAX R; its centre
        ``r`` off the line and ``R - r`` from the winch, so it begins at the circle's bearing
        ``atan(r / sqrt(R^2 - 2 R r))`` before the downwind point (or at most 0.1 rad after;
        a glider that reaches the final altitude later circles once more)."""
        R = self.params["REC_RADIUS"]
        V = self.params["REC_AIRSPEED"]
        wn = math.hypot(wind[0], wind[1])
        r = min((V + wn) ** 2 / self.guidance.g, self.params["REC_TURN_RMAX"] * R)
        xc = math.sqrt(R * R - 2.0 * R * r)  # the centre's distance down the line from the winch
        lead = math.atan2(r, xc)  # bearing of the circle's tangent point off its downwind point
        psi_q = math.atan2(q[1], q[0])
        if wn < 1.0:
            psi_e = psi_q + self._sense * lead
        else:
            psi_e = math.atan2(wind[1], wind[0])
            to_go = self._sense * ((psi_e - psi_q + math.pi) % (2.0 * math.pi) - math.pi)
            if not lead - 0.1 < to_go <= lead:  # at the tangent point (0.1 rad: ~0.5 s on the circle)
                return None
        e = np.array([math.cos(psi_e), math.sin(psi_e)])  # downwind
        side = self._sense * np.array([e[1], -e[0]])  # towards the glider's side of the line
        return -e, xc * e + r * side, r

    @staticmethod
    def _ground_speed(u: np.ndarray, wind: np.ndarray, V: float) -> float:
        """Ground speed [m/s] along horizontal unit vector ``u`` at airspeed ``V`` in the
        horizontal ``wind`` (at least half the airspeed: no hovering against a stronger wind)."""
        uw = float(u @ wind)
        return uw + math.sqrt(max(V * V - float(wind @ wind) + uw * uw, 0.25 * V * V))

    def _watch_gusts(self, wind: np.ndarray, h: float, dt: float) -> None:
        """Filter the vertical wind's mean square over REC_GUST_TAU (``wind`` [m/s] NED, step
        ``dt`` [s]); a landing recovery whose gusts exceed REC_GUST_MAX on the circle, below
        REC_HOLD_ALT + REC_GUST_BAND (``h`` [m]), parks in the hold instead."""
        p = self.params
        self._gust2 += (float(wind[2]) ** 2 - self._gust2) * min(dt / p["REC_GUST_TAU"], 1.0)
        if not self.park and p["REC_LAND"] > 0.5 and math.sqrt(self._gust2) > p["REC_GUST_MAX"] \
                and self.stage in ("return", "hold") and h < p["REC_HOLD_ALT"] + p["REC_GUST_BAND"]:
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
        q = np.array([s.pos_ned[0], s.pos_ned[1]])
        self._watch_gusts(wind, h, dt)
        land = p["REC_LAND"] > 0.5 and not self.park
        floor = p["REC_FINAL_ALT"] if land else p["REC_HOLD_ALT"]
        sink = V / p["REC_SLOPE"]
        if self.stage in ("return", "hold"):
            on_circle = abs(math.hypot(q[0], q[1]) - R) < p["REC_CIRC_BAND"] * R
            if self.stage == "return" and on_circle and h < floor + 3.0:
                self.stage = "hold"
                self._note(f"recovery: on the circle at {h:.1f} m")
            # the final begins at REC_FINAL_ALT: the altitude reference on the floor, the glider
            # within 1 m of it (it may lag the reference by a few metres)
            at_floor = self._h <= floor and h < floor + 1.0
            turn = self._turn_onto_final(q, w) if land and self.stage == "hold" and at_floor else None
            if turn is not None:
                self._final = turn
                self.stage = "final"
                track, _, radius = turn
                self._note(f"recovery: turn onto the final approach from {h:.1f} m, radius {radius:.0f} m, "
                           f"track {math.degrees(math.atan2(track[1], track[0])):.0f} deg over the winch")
        if self.stage == "final" and h < p["REC_FLARE_ALT"]:
            self.stage = "flare"
            self._note(f"recovery: flare at {h:.1f} m")
        if self.stage == "flare":
            return None
        centre: np.ndarray | None = None  # of the turn onto the final (None: the circle, or the line)
        r = 0.0
        if self.stage == "final":
            f, centre, r = self._final  # type: ignore[misc]
            if centre is not None and float((q - centre) @ f) >= 0.0:  # abeam the centre: the turn's end
                self._final, centre = (f, None, 0.0), None
        floor = 0.0 if self.stage == "final" else floor
        # to the circle and down on it to the floor the glider glides, motor stopped: the
        # altitude reference sinks at the path's rate or, where the glider cannot hold that glide
        # (the line's drag and weight on it), at the glider's own sink rate, at most that of the
        # steepest path the parameters allow (1:3, REC_SLOPE's least: a glider diving faster,
        # e.g. on entry from a dive, is pulled up). On the floor the path is level, and the final
        # approach must reach the winch at REC_SLOPE: there the motor holds what the glide cannot
        self.gliding = self.stage != "final" and self._h > floor
        if self.gliding:
            sink = max(sink, min(float(s.vel_ned[2]), V / SLOPE_MIN))
            self._h = min(max(self._h - sink * dt, floor), h + 1.0)
        else:
            self._h = min(max(self._h - sink * dt, floor), h + 10.0)
        descending = self._h > floor
        if self.stage == "final" and centre is None:
            # on the line over the winch
            pos_h = float(q @ f) * f
            vg = self._ground_speed(f, w, V)
            vel = np.array([vg * f[0], vg * f[1], sink if descending else 0.0])
            acc = np.zeros(3)
        else:
            # a circle's guidance field: REC_RADIUS about the winch or the turn onto the final
            u = self._circle_field(q, centre, r)
            vg = self._ground_speed(u, w, V)
            # the field's turn along the track: a = vg^2 du/ds (finite difference over 1 m)
            du = self._circle_field(q + u, centre, r) - u
            vel = np.array([vg * u[0], vg * u[1], sink if descending else 0.0])
            acc = np.array([vg * vg * du[0], vg * vg * du[1], 0.0])
            pos_h = q
        pos = np.array([pos_h[0], pos_h[1], -self._h])
        return RefPoint(t_cycle=0.0, cycle=0, phase=RECOVERY, pos=pos, vel=vel, acc=acc, airspeed=V, alpha=0.0,
                        phi=0.0, thrust=0.0, tension=0.0, length=0.0, reel_speed=0.0)

    def flare(self, s: SixDofState, trim_alpha: float) -> tuple[float, float]:
        """The flare's angle of attack [rad] and thrust [N] at glider state ``s``, wings level:
        ``trim_alpha`` [rad] (level flight at the airspeed) plus REC_FLR_KA per m/s of sink above
        the aimed sink rate (REC_FLR_SINK at REC_FLARE_ALT, falling linearly to REC_FLR_SINK_TD
        at touchdown), within 0 and the stall margin (REC_FLR_AMARG of the maximum-lift angle,
        at most LIM_ALPHA_MAX); the motor only guards against a stall: REC_FLR_KT per m/s below
        REC_FLR_VMIN times REC_AIRSPEED, at most REC_FLR_TMAX."""
        p = self.params
        h = -float(s.pos_ned[2])
        v_down = float(s.vel_ned[2])
        td = p["REC_FLR_SINK_TD"]
        sink_target = td + (p["REC_FLR_SINK"] - td) * min(h / max(p["REC_FLARE_ALT"], 0.1), 1.0)
        alpha = trim_alpha + p["REC_FLR_KA"] * (v_down - sink_target)
        a_max = min(p["LIM_ALPHA_MAX"], p["REC_FLR_AMARG"] * self.guidance.aero_u.alpha_max_lift)
        stall_guard = p["REC_FLR_KT"] * (p["REC_FLR_VMIN"] * p["REC_AIRSPEED"] - s.airspeed)
        thrust = min(max(stall_guard, 0.0), p["REC_FLR_TMAX"])
        return min(max(alpha, 0.0), a_max), thrust

    @property
    def holds(self) -> bool:
        """The recovery holds on the circle for good (REC_LAND 0, or vertical gusts above
        REC_GUST_MAX)."""
        return self.stage == "hold" and self.park

    def in_hold(self, s: SixDofState) -> bool:
        """Glider state ``s`` circles within REC_HOLD_TOL of REC_HOLD_ALT, within REC_CIRC_BAND
        times REC_RADIUS of the circle."""
        p = self.params
        rho = math.hypot(float(s.pos_ned[0]), float(s.pos_ned[1]))
        return (abs(-float(s.pos_ned[2]) - p["REC_HOLD_ALT"]) < p["REC_HOLD_TOL"]
                and abs(rho - p["REC_RADIUS"]) < p["REC_CIRC_BAND"] * p["REC_RADIUS"])
