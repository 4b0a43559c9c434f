"""The autopilot's winch commands: on the pumping cycle in AUTO (:func:`cycle_winch`) and
paying line out in generator mode (:func:`pay_out`, RECOVER's braking and free spool).

``winch``: ``"physical"`` (the ground station: generator with its load resistor, motor with
the PI speed loop) or ``"ideal"`` (the paper plant's kinematic winch, reeling at the commanded
speed in generation too).

On the physical winch the line is held between two tensions (:data:`LIMIT_PARAMS`, autopilot
parameters): below the lower one the motor reels in behind the glider, above the upper one the
generator brakes less, and in recovery the reel-in keeps to the glider's approach.

The cycle's arithmetic is the pure :func:`cycle_winch_values`; :func:`cycle_winch` wraps it."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .. import slots
from ..groundstation import WinchCommand
from ..sixdof.state import SixDofState
from .guidance import norm3
from .params import ParamStore
from ..trajectory.schema import GENERATION
from .tracking import RefPoint


#: the winch's line limits and the recovery phase's reel gains, autopilot parameters in the
#: order of the ``lim`` vector of :func:`cycle_winch_values` (:func:`limit_vector`); then the
#: drive's largest reel-in speed
LIMIT_PARAMS = ("WINCH_TLO", "WINCH_THYST", "WINCH_TLO_KT", "WINCH_SLK_KL", "WINCH_SLACK", "WINCH_VCATCH",
                "WINCH_THI", "WINCH_THI_KRL", "WINCH_SLACK_T", "WINCH_PACE_MAX", "REC_LEN_KL",
                "REC_TENS_KT", "REC_PAY_MAX")
WL = slots.declare("WinchLimits", ("tlo", "thyst", "tlo_kt", "slk_kl", "slack", "vcatch", "thi", "thi_krl", "slack_t",
                                   "pace_max", "len_kl", "tens_kt", "pay_max", "vin_max"))
#: the load resistance's range in generation [ohm] (the length trim's and the upper limit's)
RL_MIN, RL_MAX = 0.2, 20.0


def limit_vector(params: ParamStore, reel_in_max: float) -> np.ndarray:
    """The ``lim`` vector of :func:`cycle_winch_values`: :data:`LIMIT_PARAMS` from ``params``, then
    the drive's largest reel-in speed ``reel_in_max`` [m/s] (ground-station definition,
    :func:`fdm_awe.groundstation.steady.motor_max_reel_in_speed`)."""
    return np.array([params[n] for n in LIMIT_PARAMS] + [reel_in_max], dtype=float)


def cycle_winch(r: RefPoint, rate: float, gs: Any, params: ParamStore, winch: str, load_resistance: float,
                line_EA: float, dist: float = math.nan, dist_rate: float = 0.0, low: bool = False,
                reel_in_max: float = math.inf) -> tuple[WinchCommand, bool]:
    """The winch on reference point ``r`` flown at path rate ``rate`` (-), with the ground
    station's last output ``gs`` (None before its first step) and the glider's distance from the
    winch ``dist`` [m] and its rate ``dist_rate`` [m/s] (NaN distance: unknown, the line limits
    act on the tension only): in generation the generator (``load_resistance`` [ohm], trimmed
    on the line length with GEN_RL_KP; the reference's T2 duty) between the line's lower and
    upper tension limits, or, on a kinematic winch, the reference's reel speed trimmed on the
    unstretched length (``line_EA`` [N]: the line's axial stiffness) and the tension; in
    recovery the motor reeling in at the reference speed, trimmed on the length, bounded by the
    glider's approach, easing off above REC_TENSION, paced at most at WINCH_PACE_MAX
    (:func:`cycle_winch_values`). ``low``: the
    lower tension limit held at the last step; ``reel_in_max`` [m/s]: the drive's largest
    reel-in speed. Returns the command and whether the lower limit holds now."""
    p = params
    on = gs is not None
    motor, v, rl, d2, lo = cycle_winch_values(
        r.phase, winch == "ideal", rate, r.reel_speed, r.length, r.tension, r.boost_duty, on,
        gs.length if on else math.nan, gs.tension if on else math.nan, load_resistance, line_EA,
        p["GEN_RL_KP"], p["REC_TENSION"], p["WINCH_KL"], p["WINCH_KT"], dist, dist_rate, low,
        limit_vector(p, reel_in_max))
    return winch_command(motor, v, rl, d2), lo


def winch_command(motor: float, reel_speed_ref: float, load_resistance: float, boost_duty: float) -> WinchCommand:
    """The :class:`WinchCommand` of :func:`cycle_winch_values`' values: ``motor`` 1.0 motor mode
    (else generator), ``reel_speed_ref`` [m/s], ``load_resistance`` [ohm] and ``boost_duty`` (-)
    with NaN for the ground station's definition default (None)."""
    return WinchCommand(mode="motor" if motor != 0.0 else "generator", reel_speed_ref=reel_speed_ref,
                        load_resistance=None if math.isnan(load_resistance) else load_resistance,
                        boost_duty=None if math.isnan(boost_duty) else boost_duty)


def take_up_speed(dist: float, dist_rate: float, gs_length: float, slack_kept: float, k_slack: float,
                  v_catch: float) -> float:
    """The reel speed [m/s, + out] that follows the glider (distance ``dist`` [m] from the winch,
    its rate ``dist_rate`` [m/s]) and takes up the line's slack beyond ``slack_kept`` [m] (line
    length ``gs_length`` [m] minus the distance) at ``k_slack`` [1/s], reeling in at most
    ``v_catch`` [m/s] faster than the glider approaches: the line is caught without a snatch.
    An unknown distance (NaN) follows nothing: 0."""
    if dist != dist:
        return 0.0
    return dist_rate - min(k_slack * max(gs_length - dist - slack_kept, 0.0), v_catch)


def lower_limit_holds(low: bool, tension: float, t_lo: float, hysteresis: float) -> bool:
    """Whether the line's lower tension limit holds the winch (motor mode) after a step at
    ``tension`` [N]: it takes over below ``t_lo`` [N] and hands back to the generator above
    ``t_lo + hysteresis`` (no chatter between the two); ``low``: it held at the last step; a
    ``t_lo`` of 0 turns it off."""
    if t_lo <= 0.0:
        return False
    if low:
        return tension <= t_lo + hysteresis
    return tension < t_lo


def upper_limit_load(load_resistance: float, boost_duty: float, tension: float, t_hi: float,
                     k_rl: float) -> tuple[float, float]:
    """The generator's load resistance [ohm] and T2 duty (-) above the line's upper tension
    limit ``t_hi`` [N] (0: off): ``R_L`` raised by ``k_rl`` [ohm/N] per newton above it (less
    braking: the drum pays out faster), up to :data:`RL_MAX`, and the duty scaled down by the
    same ratio (the load the armature sees rises with both); continuous at ``t_hi``, so the
    generator's law and the limit blend without a switch."""
    if t_hi <= 0.0 or tension <= t_hi:
        return load_resistance, boost_duty
    rl = min(load_resistance + k_rl * (tension - t_hi), RL_MAX)
    return max(rl, load_resistance), boost_duty * (load_resistance / max(rl, load_resistance))


def guard_load(load_resistance: float, motor_mode: float, phase: int, ideal: bool, pulling_up: bool) -> float:
    """The generator's load resistance [ohm] while AUTO's ground-proximity guard pulls up
    (``pulling_up``: the guard on, with GP_EASE): in generation on the physical winch (generator
    mode, ``motor_mode`` 0.0) its largest, :data:`RL_MAX`, so that the generator brakes the drum
    least and the line lets the glider climb; otherwise ``load_resistance`` as the cycle's law
    gave it (:func:`cycle_winch_values`)."""
    if pulling_up and phase == GENERATION and motor_mode == 0.0 and not ideal:
        return RL_MAX
    return load_resistance


def cycle_winch_values(phase: int, ideal: bool, rate: float, reel_speed: float, length: float, tension: float,
                       boost_duty: float, gs_valid: bool, gs_length: float, gs_tension: float, load_resistance: float,
                       line_EA: float, gen_rl_kp: float, rec_tension: float, winch_kl: float,
                       winch_kt: float, dist: float, dist_rate: float, low: bool,
                       lim: np.ndarray) -> tuple[float, float, float, float, bool]:
    """The winch command on the pumping cycle as numbers: ``(motor_mode, reel_speed_ref,
    load_resistance, boost_duty, low)`` (:func:`cycle_winch`, a pure function numba compiles
    with the same bits as the Python call).

    Inputs: the reference point's ``phase`` (GENERATION / RECOVERY), ``reel_speed`` [m/s],
    ``length`` [m], ``tension`` [N] and T2 duty ``boost_duty`` (-); ``ideal`` the kinematic
    winch; the path rate ``rate`` (-); ``gs_valid`` the ground station has stepped (else
    ``gs_length`` [m] and ``gs_tension`` [N], its last output, are not read); the generator's
    ``load_resistance`` [ohm]; the line's axial stiffness ``line_EA`` [N]; the parameters
    GEN_RL_KP [ohm/m], REC_TENSION [N], WINCH_KL [1/s] and WINCH_KT [m/(N s)]; the glider's
    distance from the winch ``dist`` [m] (NaN: unknown) and its rate ``dist_rate`` [m/s];
    ``low`` the lower tension limit held at the last step; ``lim`` the line limits
    (:data:`LIMIT_PARAMS` at the offsets of :data:`WL`, then the drive's largest reel-in speed
    [m/s]).

    Physical winch in generation: the generator's law (R_L trimmed on the length, the
    reference's T2 duty) between two tension limits. Below WINCH_TLO the motor takes over
    (speed loop): it follows the glider back and takes up the slack (:func:`take_up_speed`),
    the tension held at WINCH_TLO by WINCH_TLO_KT, until the tension passes WINCH_TLO +
    WINCH_THYST (:func:`lower_limit_holds`) or the line would be paid out (the generator's
    job: a motor paying out brakes the drum through the armature). Above WINCH_THI the generator brakes less
    (:func:`upper_limit_load`). In recovery the motor reels in at the reference speed,
    trimmed on the length, but never more than WINCH_VCATCH faster than the glider approaches,
    plus WINCH_SLK_KL per metre of slack line (the slack closes no faster than that: the line is
    caught at WINCH_VCATCH), and at least as fast as the glider approaches where more than
    WINCH_SLACK of line hangs and the tension is at most WINCH_SLACK_T (0: WINCH_TLO; slack, not
    sagging), whatever slack the reference planned (a glider turning out on a slack line runs out
    against a standing drum: its inertia against the line's stiffness makes the catch's peak;
    0 WINCH_VCATCH: the reference's speed alone), paced at most at WINCH_PACE_MAX, trimmed by
    REC_LEN_KL, REC_TENS_KT above REC_TENSION, paying out at most REC_PAY_MAX; every reel-in
    within the drive's largest speed.

    Outputs: ``motor_mode`` 1.0 (motor) or 0.0 (generator), ``reel_speed_ref`` [m/s] (0.0, the
    command's default, where the generator ignores it), ``load_resistance`` [ohm] and
    ``boost_duty`` (-), NaN where the command leaves them at the station's definition default;
    ``low`` whether the lower tension limit holds after this step."""
    if phase == GENERATION and ideal:
        # kinematic winch: reel at the reference speed (scaled by the path rate), on the
        # reference's unstretched length, and pay out faster when the line pulls harder
        # than the reference tension (the tension term damps the line's spring mode)
        v = rate * reel_speed
        if gs_valid:
            l_ref = length / (1.0 + tension / line_EA)
            v += winch_kl * (l_ref - gs_length) + winch_kt * (gs_tension - tension)
        return 0.0, v, math.nan, math.nan, False
    v_in_max = lim[WL.vin_max]
    if phase == GENERATION:
        if gs_valid and lower_limit_holds(low, gs_tension, lim[WL.tlo], lim[WL.thyst]):
            # the line would go slack: reel in behind the glider, the tension held at WINCH_TLO
            v = take_up_speed(dist, dist_rate, gs_length, 0.0, lim[WL.slk_kl], lim[WL.vcatch])
            v += lim[WL.tlo_kt] * (gs_tension - lim[WL.tlo])
            if dist == dist:
                v = max(v, dist_rate - lim[WL.vcatch])
            if v < 0.0:
                return 1.0, max(v, -v_in_max), math.nan, math.nan, True
            # where it would pay out the generator does (the motor mode would brake a drum
            # paying out through the armature: plugging)
        rl = load_resistance
        if gen_rl_kp > 0 and gs_valid:
            # radial position is the winch's job: pay out faster (higher R_L, less
            # braking) when the line is shorter than the reference, slower when longer
            rl = min(max(load_resistance + gen_rl_kp * (length - gs_length), RL_MIN), RL_MAX)
        d2 = boost_duty
        if gs_valid:
            rl, d2 = upper_limit_load(rl, d2, gs_tension, lim[WL.thi], lim[WL.thi_krl])
        # the generator's T2 duty as the optimiser chose it (0: the passive rectifier)
        return 0.0, 0.0, rl, d2, False
    # reel in at the reference speed scaled by the path rate (at most WINCH_PACE_MAX, 0: any: a
    # glider pulled ahead runs the path ahead, and that pace pulls it further), trimmed towards
    # the reference length, easing off when the line pulls the glider harder than REC_TENSION
    v = (min(rate, lim[WL.pace_max]) if lim[WL.pace_max] > 0.0 else rate) * reel_speed
    if gs_valid:
        v += lim[WL.len_kl] * (length - gs_length)
        v_catch = lim[WL.vcatch]
        if v_catch > 0.0 and not ideal and dist == dist:
            # at least the approach where more than WINCH_SLACK hangs on a line pulling at most
            # WINCH_SLACK_T (0: WINCH_TLO; a lumped line sagging in the wind pulls a newton or
            # two, reeled in at a diving glider's approach it snatches taut again and again),
            # never much faster than the approach (the paper plant's winch: the paper's cycle)
            kept, slack = lim[WL.slack], gs_length - dist
            if slack > kept and gs_tension <= (lim[WL.slack_t] if lim[WL.slack_t] > 0.0 else lim[WL.tlo]):
                v = min(v, take_up_speed(dist, dist_rate, gs_length, kept, lim[WL.slk_kl], v_catch))
            # the slack closes at most at WINCH_SLK_KL per metre plus WINCH_VCATCH (the catch's speed)
            v = max(v, dist_rate - v_catch - lim[WL.slk_kl] * max(slack, 0.0))
        if gs_tension > rec_tension:
            v += lim[WL.tens_kt] * (gs_tension - rec_tension)
    return 1.0, max(min(v, lim[WL.pay_max]), -v_in_max), math.nan, math.nan, False


def pay_out(s: SixDofState, gs: Any, load_resistance: float, slack: float, winch: str,
            max_tension: float, k_slack: float, k_tension: float) -> WinchCommand:
    """Let line out in generator mode: through the load resistor (``load_resistance`` [ohm]) on
    the real winch; on a kinematic winch, at the glider's opening speed plus a catch-up of
    ``k_slack`` [1/s] (REC_SLK_KL) per metre of line short of the glider's distance plus
    ``slack`` [m], and of ``k_tension`` [m/(N s)] (REC_TENS_KT) per newton above
    ``max_tension`` [N] (REC_TENSION)."""
    if winch != "ideal" or gs is None:
        return WinchCommand(mode="generator", load_resistance=load_resistance)
    d = norm3(s.hook_pos_ned)
    d_rate = float(s.hook_pos_ned @ s.hook_vel_ned) / max(d, 1e-6)
    v = max(d_rate, 0.0) + k_slack * max(d + slack - gs.length, 0.0) + k_tension * max(gs.tension - max_tension, 0.0)
    return WinchCommand(mode="generator", reel_speed_ref=v)
