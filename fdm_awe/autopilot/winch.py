"""The autopilot's winch commands: on the pumping cycle in AUTO (:func:`cycle_winch`) and
paying line out in generator mode (:func:`pay_out`, RECOVER's braking and free spool).

``winch``: ``"physical"`` (the ground station: generator with its load resistor, motor with
the PI speed loop) or ``"ideal"`` (the paper plant's kinematic winch, reeling at the commanded
speed in generation too).

The cycle's arithmetic is the pure :func:`cycle_winch_values`; :func:`cycle_winch` wraps it."""

from __future__ import annotations

import math
from typing import Any

from ..groundstation import WinchCommand
from ..sixdof.state import SixDofState
from .guidance import norm3
from .params import ParamStore
from .tracking import GENERATION, RefPoint


def cycle_winch(r: RefPoint, rate: float, gs: Any, params: ParamStore, winch: str, load_resistance: float,
                line_EA: float) -> WinchCommand:
    """The winch on reference point ``r`` flown at path rate ``rate`` (-), with the ground
    station's last output ``gs`` (None before its first step): in generation the generator
    (``load_resistance`` [ohm], trimmed on the line length with GEN_RL_KP; the reference's T2
    duty) or, on a kinematic winch, the reference's reel speed trimmed on the unstretched
    length (``line_EA`` [N]: the line's axial stiffness) and the tension; in recovery the motor
    reeling in at the reference speed, trimmed on the length, easing off above REC_TENSION
    (:func:`cycle_winch_values`)."""
    p = params
    on = gs is not None
    motor, v, rl, d2 = cycle_winch_values(
        r.phase, winch == "ideal", rate, r.reel_speed, r.length, r.tension, r.boost_duty, on,
        gs.length if on else math.nan, gs.tension if on else math.nan, load_resistance, line_EA,
        p["GEN_RL_KP"], p["REC_TENSION"], p["WINCH_KL"], p["WINCH_KT"])
    return winch_command(motor, v, rl, d2)


def winch_command(motor: float, reel_speed_ref: float, load_resistance: float, boost_duty: float) -> WinchCommand:
    """The :class:`WinchCommand` of :func:`cycle_winch_values`' values: ``motor`` 1.0 motor mode
    (else generator), ``reel_speed_ref`` [m/s], ``load_resistance`` [ohm] and ``boost_duty`` (-)
    with NaN for the ground station's definition default (None)."""
    return WinchCommand(mode="motor" if motor != 0.0 else "generator", reel_speed_ref=reel_speed_ref,
                        load_resistance=None if math.isnan(load_resistance) else load_resistance,
                        boost_duty=None if math.isnan(boost_duty) else boost_duty)


def cycle_winch_values(phase: int, ideal: bool, rate: float, reel_speed: float, length: float, tension: float,
                       boost_duty: float, gs_valid: bool, gs_length: float, gs_tension: float, load_resistance: float,
                       line_EA: float, gen_rl_kp: float, rec_tension: float, winch_kl: float,
                       winch_kt: float) -> tuple[float, float, float, float]:
    """The winch command on the pumping cycle as numbers: ``(motor_mode, reel_speed_ref,
    load_resistance, boost_duty)`` (:func:`cycle_winch`, a pure function numba compiles with the
    same bits as the Python call).

    Inputs: the reference point's ``phase`` (GENERATION / RECOVERY), ``reel_speed`` [m/s],
    ``length`` [m], ``tension`` [N] and T2 duty ``boost_duty`` (-); ``ideal`` the kinematic
    winch; the path rate ``rate`` (-); ``gs_valid`` the ground station has stepped (else
    ``gs_length`` [m] and ``gs_tension`` [N], its last output, are not read); the generator's
    ``load_resistance`` [ohm]; the line's axial stiffness ``line_EA`` [N]; the parameters
    GEN_RL_KP [ohm/m], REC_TENSION [N], WINCH_KL [1/s] and WINCH_KT [m/(N s)].

    Outputs: ``motor_mode`` 1.0 (motor) or 0.0 (generator), ``reel_speed_ref`` [m/s] (0.0, the
    command's default, where the generator ignores it), ``load_resistance`` [ohm] and
    ``boost_duty`` (-), NaN where the command leaves them at the station's definition default."""
    if phase == GENERATION and ideal:
        # kinematic winch: reel at the reference speed (scaled by the path rate), on the
        # reference's unstretched length, and pay out faster when the line pulls harder
        # than the reference tension (the tension term damps the line's spring mode)
        v = rate * reel_speed
        if gs_valid:
            l_ref = length / (1.0 + tension / line_EA)
            v += winch_kl * (l_ref - gs_length) + winch_kt * (gs_tension - tension)
        return 0.0, v, math.nan, math.nan
    if phase == GENERATION:
        rl = load_resistance
        if gen_rl_kp > 0 and gs_valid:
            # radial position is the winch's job: pay out faster (higher R_L, less
            # braking) when the line is shorter than the reference, slower when longer
            rl = min(max(load_resistance + gen_rl_kp * (length - gs_length), 0.2), 20.0)
        # the generator's T2 duty as the optimiser chose it (0: the passive rectifier)
        return 0.0, 0.0, rl, boost_duty
    # reel in at the reference speed scaled by the path rate, trimmed towards the reference
    # length, and ease off when the line pulls the glider harder than REC_TENSION
    v = rate * reel_speed
    if gs_valid:
        v += 0.5 * (length - gs_length)
        if gs_tension > rec_tension:
            v += 0.2 * (gs_tension - rec_tension)
    return 1.0, min(v, 0.5), math.nan, math.nan


def pay_out(s: SixDofState, gs: Any, load_resistance: float, slack: float, winch: str,
            max_tension: float) -> WinchCommand:
    """Let line out in generator mode: through the load resistor (``load_resistance`` [ohm]) on
    the real winch; on a kinematic winch, at the glider's opening speed plus a catch-up on
    ``slack`` [m] of line beyond the glider's distance and on a tension above ``max_tension``
    [N] (REC_TENSION)."""
    if winch != "ideal" or gs is None:
        return WinchCommand(mode="generator", load_resistance=load_resistance)
    d = norm3(s.hook_pos_ned)
    d_rate = float(s.hook_pos_ned @ s.hook_vel_ned) / max(d, 1e-6)
    v = max(d_rate, 0.0) + 0.5 * max(d + slack - gs.length, 0.0) + 0.2 * max(gs.tension - max_tension, 0.0)
    return WinchCommand(mode="generator", reel_speed_ref=v)
