"""The physical winch's line limits on their own (:func:`fdm_awe.autopilot.winch.cycle_winch_values`
with the parameters of ``autopilot.xml``): in a lull (tension below WINCH_TLO) the motor reels
in behind the glider and hands back to the generator only above WINCH_TLO + WINCH_THYST; in a
gust (above WINCH_THI) the generator brakes less, so at that tension the drum pays out faster
(the ground station's steady generator); in recovery the reel-in never passes the glider's
approach by more than WINCH_VCATCH once the slack is gone, and a line pulling more than
WINCH_SLACK_T sags, it is not reeled in at the approach; the drive's largest reel-in speed
bounds every reel-in."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

from fdm_awe.autopilot.config import autopilot_params
from fdm_awe.trajectory.schema import GENERATION, RECOVERY
from fdm_awe.autopilot.winch import LIMIT_PARAMS, RL_MAX, cycle_winch_values, guard_load, limit_vector
from fdm_awe.groundstation import load_ground_station
from fdm_awe.groundstation.steady import generator_at_speed, generator_steady, motor_max_reel_in_speed

GS = load_ground_station()
P = autopilot_params()
V_IN_MAX = float(motor_max_reel_in_speed(0.0, GS))
LIM = limit_vector(P, V_IN_MAX)
R_L = GS.converter.load_resistance


def _winch(phase: int, tension: float, *, length: float = 200.0, dist: float = 200.0, dist_rate: float = 0.0,
           low: bool = False, ref_reel: float = 0.0, ref_length: float = 200.0,
           ref_tension: float = 30.0, rate: float = 1.0, lim: np.ndarray = LIM):
    """The command at line ``tension`` [N] and length ``length`` [m], the glider ``dist`` [m]
    from the winch moving out at ``dist_rate`` [m/s], the reference reeling at ``ref_reel``
    (limit vector ``lim``: the defaults')."""
    return cycle_winch_values(phase, False, rate, ref_reel, ref_length, ref_tension, 0.0, True, length, tension, R_L,
                              GS.tether.axial_stiffness, P["GEN_RL_KP"], P["REC_TENSION"], P["WINCH_KL"],
                              P["WINCH_KT"], dist, dist_rate, low, lim)


def test_the_limits_are_on_and_ordered():
    assert 0.0 < P["WINCH_TLO"] < P["WINCH_TLO"] + P["WINCH_THYST"] < P["WINCH_THI"]
    # the upper limit at the line's rating (Table 3's G_max), the drive's reel-in speed the
    # definition's (11.1 m/s on a slack line at 48 V)
    assert P["WINCH_THI"] == GS.tether.rated_tension
    assert V_IN_MAX == pytest.approx(11.103, abs=0.01)


def test_lull_reels_in_behind_the_approaching_glider():
    """Tension below WINCH_TLO with the glider coming back at 3 m/s on a slack line: motor mode,
    reeling in at least as fast as the glider approaches and at most WINCH_VCATCH faster."""
    for slack in (0.0, 2.0, 20.0):
        motor, v, _, _, low = _winch(GENERATION, 0.0, length=200.0 + slack, dist_rate=-3.0)
        assert motor == 1.0 and low
        assert -v >= 3.0 - 1e-12  # the slack does not grow
        assert -v <= 3.0 + P["WINCH_VCATCH"] + P["WINCH_TLO_KT"] * P["WINCH_TLO"] + 1e-12
    # more slack, faster take-up (until the catch bound)
    v_small = _winch(GENERATION, 0.0, length=200.1, dist_rate=-3.0)[1]
    v_big = _winch(GENERATION, 0.0, length=230.0, dist_rate=-3.0)[1]
    assert v_big < v_small - 0.2


def test_lull_hands_back_to_the_generator_with_hysteresis():
    """The motor holds between WINCH_TLO and WINCH_TLO + WINCH_THYST (no chatter), the
    generator takes the line back above; the generator does not hand over above WINCH_TLO."""
    t_lo, hyst = P["WINCH_TLO"], P["WINCH_THYST"]
    mid = t_lo + 0.5 * hyst
    assert _winch(GENERATION, mid, low=True, dist_rate=-1.0)[0] == 1.0  # held
    assert _winch(GENERATION, mid, low=False, dist_rate=-1.0)[0] == 0.0  # not taken over
    motor, _, rl, _, low = _winch(GENERATION, t_lo + hyst + 0.5, low=True)
    assert motor == 0.0 and not low and rl == pytest.approx(R_L)
    # on a line held at WINCH_TLO the tension term pays out above it and reels in below it
    v_hi = _winch(GENERATION, t_lo + 1.0, low=True, dist_rate=-1.0)[1]
    v_lo = _winch(GENERATION, t_lo - 1.0, low=True, dist_rate=-1.0)[1]
    assert v_hi > v_lo + 0.1


def test_a_glider_moving_out_on_a_low_tension_is_the_generators():
    """Below WINCH_TLO with the glider moving away on a taut line the line is paid out by the
    generator, not by the motor (a motor paying out brakes the drum through the armature)."""
    for low in (False, True):
        motor, _, rl, _, held = _winch(GENERATION, 0.5 * P["WINCH_TLO"], dist_rate=2.0, low=low)
        assert motor == 0.0 and not held and rl == pytest.approx(R_L)


def test_lull_reels_in_within_the_drive():
    motor, v, _, _, _ = _winch(GENERATION, 0.0, length=260.0, dist_rate=-9.0)
    assert motor == 1.0 and v >= -V_IN_MAX - 1e-12


def test_gust_pays_out_faster_above_the_upper_limit():
    """Above WINCH_THI the load resistance rises with the tension, continuously from the
    generator's law at WINCH_THI; at the same tension the ground station's steady generator
    then pays out faster, by at least 1 m/s 10 N above the limit."""
    t_hi = P["WINCH_THI"]
    rl_at = _winch(GENERATION, t_hi)[2]
    assert rl_at == pytest.approx(R_L)  # the generator's law up to the limit
    assert _winch(GENERATION, t_hi + 1e-6)[2] == pytest.approx(R_L, abs=1e-5)  # no jump
    prev = rl_at
    for tension in (t_hi + 2.0, t_hi + 10.0, t_hi + 30.0, t_hi + 60.0):
        motor, _, rl, _, low = _winch(GENERATION, tension)
        assert motor == 0.0 and not low
        assert prev < rl <= RL_MAX or rl == RL_MAX
        prev = rl
    tension = t_hi + 10.0
    rl = _winch(GENERATION, tension)[2]
    faster = generator_steady(tension, GS, R_L=rl).reel_speed
    before = generator_steady(tension, GS, R_L=R_L).reel_speed
    assert faster > before + 1.0, (faster, before)


def test_recovery_never_reels_in_faster_than_the_approach_plus_the_catch_margin():
    """Whatever the reference asks (here up to the drive's speed), on a line without slack the
    reel-in speed is at most the glider's approach plus WINCH_VCATCH (its own pull eases off
    on top); with slack the bound opens by WINCH_SLK_KL per metre; with more slack than the
    WINCH_SLACK, whatever the reference plans, it reels in at least at the approach."""
    rnd = random.Random(7)
    k, vc = P["WINCH_SLK_KL"], P["WINCH_VCATCH"]
    for _ in range(2000):
        approach = rnd.uniform(-6.0, 14.0)  # + towards the winch
        slack = rnd.choice((0.0, rnd.uniform(-0.5, 0.0), rnd.uniform(0.0, 40.0)))
        ref_reel = rnd.uniform(-V_IN_MAX, 0.0)
        dist = rnd.uniform(150.0, 260.0)
        motor, v, _, _, low = _winch(RECOVERY, rnd.uniform(0.0, 10.0), length=dist + slack, dist=dist,
                                     dist_rate=-approach, ref_reel=ref_reel, ref_length=dist + slack,
                                     rate=rnd.uniform(0.5, 1.5))
        assert motor == 1.0 and not low
        reel_in = -v
        # (a glider moving out faster pulls the line off the drum: the motor's set-point pays
        # out at most REC_PAY_MAX, the line draws the rest)
        assert reel_in <= max(approach + vc + k * max(slack, 0.0), -P["REC_PAY_MAX"]) + 1e-9, (approach, slack, v)
        assert reel_in <= V_IN_MAX + 1e-12
    # the glider approaches at 5 m/s with 30 m of slack: reel in at least at the approach even
    # where the reference reels in slowly, and even where the reference planned that slack
    # (the glider turns out for generation on the line as it hangs)
    for ref_length in (200.0, 230.0):
        v = _winch(RECOVERY, 0.0, length=230.0, dist=200.0, dist_rate=-5.0, ref_reel=-1.0, ref_length=ref_length)[1]
        assert -v >= 5.0 - 1e-12
    # ... and on a taut line that approaches at 1 m/s, no faster than 1 m/s + WINCH_VCATCH
    v = _winch(RECOVERY, 0.0, length=200.0, dist=200.0, dist_rate=-1.0, ref_reel=-V_IN_MAX)[1]
    assert -v == pytest.approx(1.0 + vc)


def test_recovery_leaves_a_sagging_line_to_the_reference_speed():
    """A line that pulls more than WINCH_SLACK_T at the winch sags, it is not slack: the glider
    diving at 9 m/s towards the winch with 10 m more line out than its distance (a lumped line
    at 1.5 N in the wind) is reeled in at the reference's 5.3 m/s, not at its approach (which
    snatched the sagging line taut again and again in the zero-lift dive); at or below
    WINCH_SLACK_T the line is slack and reeled in at least at the approach, as before; and
    WINCH_SLACK_T 0 is the earlier law (slack up to WINCH_TLO)."""
    t_slack = P["WINCH_SLACK_T"]
    assert 0.0 < t_slack < P["WINCH_TLO"]
    case = dict(length=210.0, dist=200.0, dist_rate=-9.0, ref_reel=-5.3, ref_length=210.0)
    sag = 0.5 * (t_slack + P["WINCH_TLO"])
    assert -_winch(RECOVERY, sag, **case)[1] == pytest.approx(5.3)
    assert -_winch(RECOVERY, t_slack, **case)[1] >= 9.0 - 1e-12
    lim = np.array(LIM)
    lim[LIMIT_PARAMS.index("WINCH_SLACK_T")] = 0.0
    v = cycle_winch_values(RECOVERY, False, 1.0, -5.3, 210.0, 0.0, 0.0, True, 210.0, sag, R_L,
                           GS.tether.axial_stiffness, P["GEN_RL_KP"], P["REC_TENSION"], P["WINCH_KL"],
                           P["WINCH_KT"], 200.0, -9.0, False, lim)[1]
    assert -v >= 9.0 - 1e-12


def test_recovery_does_not_reel_in_faster_for_a_glider_ahead_of_its_path():
    """In recovery the path runs ahead of flight time (path rate above 1) where the glider is
    ahead of it, and a line reeled in at that pace pulls the glider further ahead (a positive
    loop through the winch). WINCH_PACE_MAX 1 keeps the reference's speed there (flight time);
    a glider behind its path (rate below 1) slows it as before. Its default is 0, the law at
    the path's pace (capped by the catch speed): paced, a class A flight of the foldable 8 m/s
    cycle caught its line at 94 N and ran out of time."""
    assert P["WINCH_PACE_MAX"] == 0.0
    case = dict(length=200.0, dist=200.0, dist_rate=-5.0, ref_reel=-5.3, ref_length=200.0, ref_tension=0.0)
    paced = np.array(LIM)
    paced[LIMIT_PARAMS.index("WINCH_PACE_MAX")] = 1.0
    assert -_winch(RECOVERY, 1.0, rate=2.5, lim=paced, **case)[1] == pytest.approx(5.3)
    assert -_winch(RECOVERY, 1.0, rate=0.5, lim=paced, **case)[1] == pytest.approx(0.5 * 5.3)
    # the default: the reel-in at the path's pace
    assert -_winch(RECOVERY, 1.0, rate=2.5, **case)[1] == pytest.approx(min(2.5 * 5.3, 5.0 + P["WINCH_VCATCH"]))
    assert -_winch(RECOVERY, 1.0, rate=0.5, **case)[1] == pytest.approx(0.5 * 5.3)


def test_limits_off_give_the_generator_and_reference_reel_in():
    """WINCH_TLO, WINCH_THI, WINCH_VCATCH at 0: the law before the limits (the generator at any
    tension, the reference's reel-in)."""
    lim = np.array(LIM)
    lim[[0, 5, 6]] = 0.0
    lim[-1] = math.inf
    args = dict(rate=1.0)
    g = cycle_winch_values(GENERATION, False, args["rate"], 0.0, 200.0, 30.0, 0.0, True, 200.0, 0.0, R_L, 6760.0,
                           0.0, 15.0, 0.5, 0.1, 200.0, -3.0, False, lim)
    assert g[0] == 0.0 and g[2] == R_L
    r = cycle_winch_values(RECOVERY, False, 1.0, -5.0, 200.0, 0.0, 0.0, True, 200.0, 0.0, R_L, 6760.0, 0.0, 15.0,
                           0.5, 0.1, 200.0, -1.0, False, lim)
    assert r[1] == -5.0


def test_while_the_guard_pulls_up_the_generator_lets_the_line_go() -> None:
    """GP_EASE: while AUTO's ground-proximity guard pulls up in generation on the physical winch,
    the generator takes its largest load resistance; in every other case the cycle's law stands.
    And what that does, from the DC machine's steady state: at a reel-out speed of 2-6 m/s the
    largest load holds the drum with less than half the tension of the definition's load (the
    line lets the glider climb instead of holding it at the rating)."""
    rl = 1.5
    assert guard_load(rl, 0.0, GENERATION, False, True) == RL_MAX
    assert guard_load(rl, 0.0, GENERATION, False, False) == rl  # no pull-up (or GP_EASE 0)
    assert guard_load(rl, 0.0, RECOVERY, False, True) == rl  # recovery: the motor reels in
    assert guard_load(rl, 1.0, GENERATION, False, True) == rl  # motor mode (the lower limit's take-up)
    assert guard_load(rl, 0.0, GENERATION, True, True) == rl  # the kinematic winch has no load
    p = load_ground_station(line="sized")
    for v in (2.0, 4.0, 6.0):
        held, eased = generator_at_speed(v, p), generator_at_speed(v, p, R_L=RL_MAX)
        assert 0.0 < eased.tension < 0.5 * held.tension
