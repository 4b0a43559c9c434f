"""The autopilot's winch commands: on the pumping cycle in AUTO (:func:`cycle_winch`) and
paying line out in generator mode (:func:`pay_out`, RECOVER's braking and free spool).

``winch``: ``"physical"`` (the ground station: generator with its load resistor, motor with
the PI speed loop) or ``"ideal"`` (the paper plant's kinematic winch, reeling at the commanded
speed in generation too)."""

from __future__ import annotations

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
    reeling in at the reference speed, trimmed on the length, easing off above REC_TENSION."""
    p = params
    if r.phase == GENERATION and winch == "ideal":
        # kinematic winch: reel at the reference speed (scaled by the path rate), on the
        # reference's unstretched length, and pay out faster when the line pulls harder
        # than the reference tension (the tension term damps the line's spring mode)
        v = rate * r.reel_speed
        if gs is not None:
            l_ref = r.length / (1.0 + r.tension / line_EA)
            v += p["WINCH_KL"] * (l_ref - gs.length) + p["WINCH_KT"] * (gs.tension - r.tension)
        return WinchCommand(mode="generator", reel_speed_ref=v)
    if r.phase == GENERATION:
        rl = load_resistance
        if p["GEN_RL_KP"] > 0 and gs is not None:
            # radial position is the winch's job: pay out faster (higher R_L, less
            # braking) when the line is shorter than the reference, slower when longer
            rl = min(max(load_resistance + p["GEN_RL_KP"] * (r.length - gs.length), 0.2), 20.0)
        # the generator's T2 duty as the optimiser chose it (0: the passive rectifier)
        return WinchCommand(mode="generator", load_resistance=rl, boost_duty=r.boost_duty)
    # reel in at the reference speed scaled by the path rate, trimmed towards the reference
    # length, and ease off when the line pulls the glider harder than REC_TENSION
    v = rate * r.reel_speed
    if gs is not None:
        v += 0.5 * (r.length - gs.length)
        if gs.tension > p["REC_TENSION"]:
            v += 0.2 * (gs.tension - p["REC_TENSION"])
    return WinchCommand(mode="motor", reel_speed_ref=min(v, 0.5))


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
