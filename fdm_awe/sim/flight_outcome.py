"""A flight's outcome, booked after it is flown: the propulsion's energy, the energy ledger
and its residual, and the status with its message (:mod:`fdm_awe.sim.flight`), among them
whether ground contact in RECOVER was a landing (:func:`landing_verdict`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..autopilot.autopilot import Autopilot
from .flight_log import FlightLog
from .flight_rig import Rig
from .glider_ledger import GliderLedger
from .propulsion import logged_propulsion
from .report import CycleMetrics
from .result import COLUMNS, FlightResult

#: largest touchdown sink rate [m/s] of a landing (ground contact in RECOVER)
LAND_SINK_MAX = 1.5
#: largest horizontal ground speed [m/s] at touchdown of a landing
LAND_SPEED_MAX = 15.0
#: largest horizontal distance [m] of a landing's touchdown from the winch
LAND_RADIUS_MAX = 150.0


def landing_verdict(pos_ned: np.ndarray, vel_ned: np.ndarray) -> str | None:
    """None when a touchdown at ``pos_ned`` [m, NED from the winch] with ground velocity
    ``vel_ned`` [m/s] is a landing (sink <= LAND_SINK_MAX, horizontal speed <= LAND_SPEED_MAX,
    within LAND_RADIUS_MAX of the winch), else the bound it broke, as a phrase."""
    sink = float(vel_ned[2])
    speed = math.hypot(float(vel_ned[0]), float(vel_ned[1]))
    dist = math.hypot(float(pos_ned[0]), float(pos_ned[1]))
    if sink > LAND_SINK_MAX:
        return f"sink {sink:.1f} m/s above {LAND_SINK_MAX:g} m/s"
    if speed > LAND_SPEED_MAX:
        return f"ground speed {speed:.1f} m/s above {LAND_SPEED_MAX:g} m/s"
    if dist > LAND_RADIUS_MAX:
        return f"{dist:.0f} m from the winch, beyond {LAND_RADIUS_MAX:g} m"
    return None


def thrust_energy(res: FlightResult, log: FlightLog, rig: Rig, paper: bool, dt: float) -> np.ndarray:
    """The cumulative energy [J] of the glider's propulsion per log row of ``res`` (whose
    propulsion columns it completes: the paper plant's ideal thruster, the motor's constant
    draw P0)."""
    k_end = res.steps
    it, ip = COLUMNS.index("thrust"), COLUMNS.index("p_prop")
    if paper:  # the logged propulsion columns show the ideal thruster (the real propeller is idle)
        res.data[1:, it], res.data[1:, ip] = logged_propulsion(res.data[1:, it], res.data[1:, ip], 0.0, rig.thruster,
                                                               np.asarray(log.t_ideal[1: k_end + 1], float))
        return log.e_ideal[: k_end + 1]
    res.data[:, it], res.data[:, ip] = logged_propulsion(res.data[:, it], res.data[:, ip],
                                                         rig.airframes.unfolded.propulsion.P0)
    p_prop = np.nan_to_num(res.p_prop)
    return np.r_[0.0, np.cumsum(0.5 * (p_prop[1:] + p_prop[:-1]) * dt)]


def flight_ledger(gl: GliderLedger, gs: Any, thrust_electrical: float, own: bool) -> tuple[dict[str, Any], float]:
    """The flight's energy ledger [J] (the glider's, the station's, with the line's own ledger
    when ``own``, the lumped line's) and the largest of their residuals relative to their largest term."""
    led = gs.ledger
    g_res, g_large = gl.residual()
    gs_res = led.residual()
    gs_large = led.largest_term()
    rel = max(abs(g_res) / max(g_large, 1e-9), abs(gs_res) / max(gs_large, 1e-9))
    ledger = {**{f"glider_{k}_J": v for k, v in gl.terms().items()}, "glider_residual_J": g_res,
              **{f"station_{k}_J": v for k, v in led.as_dict().items()},
              "station_residual_J": gs_res, "thrust_electrical_J": thrust_electrical}
    if own:  # the lumped line's own ledger (hook to drum); its residual is the integrator's error
        ll = gs.line_ledger
        ledger.update({f"line_{k}_J": v for k, v in ll.as_dict().items() if k != "relative_residual"})
        rel = max(rel, ll.relative_residual())
    return ledger, rel


def flight_status(res: FlightResult, ap: Autopilot, interrupted: bool, flown: bool, T_total: float, cycles: int,
            mets: list[CycleMetrics]) -> tuple[str, str]:
    """The flight's status and message (:mod:`fdm_awe.sim.flight`) from the co-simulation's ending, Ctrl-C,
    whether the requested cycles (or the requested length, ``flown``) were flown in the time
    cap ``T_total`` [s], and the autopilot's RECOVER state at the end."""
    status = res.status
    msg = res.event.message if res.event is not None else "completed"
    n_done = sum(1 for c in mets if c.complete)
    if interrupted:
        status, msg = "interrupted", (f"interrupted by the user at t = {res.sim_time_s:.2f} s, "
                                      f"{n_done} of {cycles} cycles complete")
    elif status == "ok" and ap.mode == "RECOVER" and ap.parked:
        # held in RECOVER at the end, also when a failsafe took the flight out of its cycles
        d = float(np.linalg.norm(res.pos[-1]))
        status, msg = "parked", (f"parked in the hold at t = {res.sim_time_s:.1f} s, {d:.0f} m from the winch, "
                                 f"line {float(res.data[-1, COLUMNS.index('length')]):.0f} m")
    elif status == "ok" and not flown:
        status, msg = "incomplete", (f"time cap of {T_total:.1f} s reached with {n_done} of {cycles} cycles "
                                     f"complete")
    if status == "ground_contact" and ap.mode == "RECOVER":
        # a landing, not a crash: at the winch, slow, gently (landing_verdict)
        v_down = float(res.vel[-1][2])
        why = landing_verdict(res.pos[-1], res.vel[-1])
        if why is None:
            status, msg = "landed", msg.replace("ground contact", "landed") + f", sink {v_down:.1f} m/s"
        else:
            msg += f", sink {v_down:.1f} m/s (a crash, not a landing: {why})"
    if status in ("landed", "parked") and ap.recover_cause != "commanded":
        # safe, but not what was asked: a failsafe ended the cycles (the exit code says so)
        msg += f"; RECOVER after the {ap.recover_cause}, {n_done} of {cycles} cycles complete"
    return status, msg
