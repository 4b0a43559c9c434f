"""The underspeed protection (:mod:`fdm_awe.autopilot.underspeed`, after ArduPilot's TECS): its
hysteresis, its law in the guidance (below the threshold alpha stays below the stall and the
commanded flight path bends down; off or inactive it is today's guidance bit for bit, but for
the alpha margin), and a flight into a lull that stalls the unprotected glider."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from fdm_awe.autopilot.config import autopilot_params
from fdm_awe.autopilot.guidance_loop import Guidance, GuidanceGains
from fdm_awe.autopilot.tracking import RefPoint, TrackingReference
from fdm_awe.autopilot.underspeed import FOLD_OPEN, underspeed_update
from fdm_awe.definitions.aircraft import load_glider, stall_speed
from fdm_awe.sim.flight import fly

DATA = Path(__file__).parent / "data"
GAINS = GuidanceGains(kp=1.0, kd=2.0, ki=0.02, a_max=15.0, int_max=20.0, alpha_min=-0.25, alpha_max=0.35,
                      phi_max=1.1, thrust_max=8.0)
PROTECTED = replace(GAINS, us_enter=1.1, us_exit=1.3, us_hold=2.0, us_alpha_margin=0.04, us_speed_gain=1.0,
                    us_slack_acc=2.0, us_margin_speed=2.0)


def test_underspeed_is_entered_below_the_entry_speed_and_left_after_the_hold():
    """TECS's hysteresis on the stall speed (8 m/s): in below 1.1 x (8.8 m/s), held until the
    airspeed is back at 1.3 x (10.4 m/s) and 2 s have passed since it was last below 8.8 m/s;
    never where the reference itself flies slower or the wing is folded; off with enter 0."""
    vs, ref = 8.0, 12.0
    args = (vs, ref, 0.0, 1.1, 1.3, 2.0)
    assert underspeed_update(False, 0.0, 1.0, 9.0, *args) == (False, 0.0)
    assert underspeed_update(False, 0.0, 1.0, 8.7, *args) == (True, 1.0)
    assert underspeed_update(True, 1.0, 2.0, 10.0, *args) == (True, 1.0)  # below the exit speed
    assert underspeed_update(True, 1.0, 2.5, 11.0, *args) == (True, 1.0)  # above it, within the hold
    assert underspeed_update(True, 1.0, 3.0, 11.0, *args) == (False, 1.0)  # above it after the hold
    assert underspeed_update(True, 1.0, 3.0, 8.5, *args) == (True, 3.0)  # below again: the hold restarts
    # the exit speed is at most the reference's own airspeed
    assert underspeed_update(True, 1.0, 3.0, 9.9, vs, 9.5, 0.0, 1.1, 1.3, 2.0) == (False, 1.0)
    # a reference flying at or below the entry speed, a folded wing, the protection off: not entered
    assert underspeed_update(False, 0.0, 1.0, 7.0, vs, 8.7, 0.0, 1.1, 1.3, 2.0)[0] is False
    assert underspeed_update(False, 0.0, 1.0, 7.0, vs, ref, FOLD_OPEN, 1.1, 1.3, 2.0)[0] is False
    assert underspeed_update(True, 0.0, 1.0, 7.0, vs, ref, 0.0, 0.0, 1.3, 2.0) == (False, 0.0)


def _glider():
    g = load_glider()
    return g.unfolded.mass.mass, g.unfolded.aero, g.folded.aero


def _acceleration(cmd, gd: Guidance, vel: np.ndarray) -> tuple[float, float]:
    """The point mass's acceleration [m/s^2] under the command (lift and drag of the unfolded
    polar at the command's alpha and bank, its thrust on the body x-axis, gravity, no line):
    (along the air velocity, along the unbanked "up" across it)."""
    S_cl0, S_cla, _, S_cd0, S_cd1, S_cd2 = gd.polar(0.0)
    V = float(np.linalg.norm(vel))
    e1 = vel / V
    h = math.hypot(e1[0], e1[1])
    r0 = np.array([-e1[1] / h, e1[0] / h, 0.0])
    u0 = np.cross(r0, e1)
    eL = math.cos(cmd.mu) * u0 + math.sin(cmd.mu) * r0
    q, a = 0.5 * gd.rho * V * V, cmd.alpha
    xb = math.cos(a) * e1 + math.sin(a) * eL
    F = q * (S_cl0 + S_cla * a) * eL - q * (S_cd0 + S_cd1 * a + S_cd2 * a * a) * e1 + cmd.thrust * xb
    acc = F / gd.m + np.array([0.0, 0.0, gd.g])
    return float(acc @ e1), float(acc @ u0)


@pytest.mark.parametrize("t_max", [0.0, 8.0])
def test_below_the_threshold_alpha_stays_below_the_stall_and_the_path_bends_down(t_max):
    """Level at 8.7 m/s (1.08 x the 8.07 m/s stall speed, below the 1.1 x entry speed), the path
    5 m above and climbing: unprotected the guidance asks alpha at the stall and climbs; protected
    alpha stays 0.04 rad below the stall, the thrust is full where the motor runs (then no
    height is asked: the motor gives the speed), and without thrust the commanded flight path
    bends down (height traded for speed), with and without the slack line's pull away from the
    winch."""
    m, au, af = _glider()
    a_stall = au.alpha_max_lift
    pos, vel = np.array([100.0, 0.0, -80.0]), np.array([0.0, 8.7, 0.0])
    ref = RefPoint(0.0, 0, 0, pos + np.array([0.0, 2.0, -5.0]), np.array([0.0, 10.0, -1.0]), np.zeros(3), 10.0, 0.15,
                   0.0, 0.0, 0.0, 120.0, 0.0)
    off = Guidance(GAINS, m, au, af).update(ref, pos, vel, np.zeros(3), np.zeros(3), 0.0, 0.01, thrust_max=t_max)
    gd = Guidance(PROTECTED, m, au, af)
    assert a_stall - 0.01 < off.alpha < a_stall + 1e-12
    assert _acceleration(off, gd, vel)[1] > 0.5  # the path asks for height: the flight path bends up
    for us in (1.0, 2.0):
        on = Guidance(PROTECTED, m, au, af).update(ref, pos, vel, np.zeros(3), np.zeros(3), 0.0, 0.01,
                                                    thrust_max=t_max, underspeed=us)
        assert on.alpha <= a_stall - 0.04 + 1e-12
        assert on.pitch < off.pitch - 0.03  # nose down
        assert on.thrust == t_max  # all the thrust there is
        a_par, a_up = _acceleration(on, gd, vel)
        if t_max == 0.0:
            assert a_up < -0.5  # no thrust: the commanded flight path bends down, height traded for speed
        else:
            assert a_up < 0.5 and a_par > 3.0  # full thrust: no height asked, the speed comes from the motor
        assert a_par > _acceleration(off, gd, vel)[0]


def test_inactive_protection_is_todays_guidance_with_the_alpha_limit_below_the_stall():
    """Over random states: the protection off (enter 0) is the guidance without it, bit for bit
    (the gains' defaults); on but not acting, it is today's guidance with its alpha limit at the
    stall minus the 0.04 rad margin below twice the stall speed, bit for bit (the same cap in
    the lift trade and the inversion), alpha never above it there; faster it is today's."""
    m, au, af = _glider()
    rng = np.random.default_rng(5)
    capped = fast = 0
    for i in range(300):
        pos = rng.normal(0.0, 60.0, 3) + np.array([100.0, 0.0, -80.0])
        vel = rng.normal(0.0, 10.0, 3)
        ref = RefPoint(0.0, 0, 0, pos + rng.normal(0.0, 6.0, 3), vel + rng.normal(0.0, 3.0, 3), rng.normal(0.0, 12.0, 3),
                       12.0, 0.1, 0.0, 1.0, float(rng.uniform(0.0, 40.0)), 150.0, 0.0)
        wind, tf, fold = np.array([rng.uniform(0.0, 10.0), 0.0, 0.0]), rng.normal(0.0, 20.0, 3), float(i % 3) / 2.0
        p = Guidance(GAINS, m, au, af).polar(fold)
        a_cap = (p[2] - p[0]) / p[1] - 0.04
        gains = (GAINS, replace(PROTECTED, us_enter=0.0), PROTECTED, replace(GAINS, alpha_max=a_cap))
        cmds = [Guidance(k, m, au, af).update(ref, pos, vel, wind, tf, fold, 0.01, taut=bool(i % 2)) for k in gains]
        plain, off, on, limited = ([*c.__dict__.values()] for c in cmds)
        assert off == plain
        if np.linalg.norm(vel - wind) < 2.0 * stall_speed(m, 1.225, 9.81, p[2]):
            assert on == limited and cmds[2].alpha <= a_cap
            capped += cmds[0].alpha > a_cap
        else:
            assert on == plain
            fast += 1
    assert capped > 10 and fast > 10  # the margin acted, and not everywhere


def _lull_flight(enter: float):
    """The nominal 8 m/s cycle, 10 s in: the wind falls from 8 to 2.4 m/s over 2 s and stays
    there (a lull); flown to 18 s with the protection's entry speed ``enter`` (0: off). The
    winch's line limits are off (WINCH_TLO, WINCH_THI, WINCH_VCATCH 0): this is the guidance's
    test; with the lower limit on, the winch reels the slack line in through the lull and its
    pull adds to the lift the wing is asked for (the protected alpha then peaked at 0.227 rad,
    past the 0.213 rad stall, in this 2 s fall of the wind to 30 %)."""
    ref = TrackingReference.from_ocp_file(DATA / "ref_physical_nominal_8mps.json")
    params = autopilot_params()
    params.set("US_V_ENTER", enter)
    params.set("US_AMARG_V", 2.0)  # the alpha margin below twice the stall speed (0, off, by default)
    for name in ("WINCH_TLO", "WINCH_THI", "WINCH_VCATCH"):
        params.set(name, 0.0)
    held = {}

    def lull(k, s, o):
        if s.t >= 10.0:
            f = 1.0 - 0.7 * min((s.t - 10.0) / 2.0, 1.0)
            held["sim"].glider.set_wind((8.0 * f, 0.0, 0.0))

    rep = fly(ref, config="nominal", cycles=1, t_end=18.0, params=params, on_step=lull,
              setup=lambda ap, sim: held.update(sim=sim))
    r = rep.result
    after = r.t >= 10.0
    return rep, r.alpha[after], r.airspeed[after], r.dt


def test_a_lull_stalls_the_unprotected_glider_and_not_the_protected_one():
    """Unprotected, the glider in the lull keeps asking the path for lift: alpha past the
    stall (0.213 rad) for seconds (4.9 s; today's autopilot flies the same bits). Protected it
    enters at 8.9 m/s, alpha stays below the stall the whole time, and it says so."""
    a_stall = load_glider().unfolded.aero.alpha_max_lift
    rep0, alpha0, v0, dt = _lull_flight(0.0)
    assert (alpha0 > a_stall).sum() * dt > 2.0 and alpha0.max() > a_stall + 0.015
    assert not [n for _, n in rep0.autopilot_log if n.startswith("underspeed")]
    rep1, alpha1, v1, dt = _lull_flight(1.1)
    assert alpha1.max() < a_stall - 0.01
    notes = [n for _, n in rep1.autopilot_log if n.startswith("underspeed")]
    assert notes and "speed before path" in notes[0]
    assert min(v0.min(), v1.min()) < 8.07  # a real lull: below the 1 g stall speed


def test_compiled_blocks_fly_the_protection_as_python_does():
    """Light turbulence (seed 1) on the nominal cycle: the protection begins and ends within the
    first 30 s (each a note, flown by the Python step); the compiled blocks give the Python
    autopilot's flight bit for bit. The winch's line limits are off: with them the line stays
    taut in this flight's lulls and the protection is not needed in its first 30 s."""
    ref = TrackingReference.from_ocp_file(DATA / "ref_physical_nominal_8mps.json")
    params = autopilot_params()
    for name in ("WINCH_TLO", "WINCH_THI", "WINCH_VCATCH"):
        params.set(name, 0.0)
    runs = [fly(ref, config="nominal", cycles=1, t_end=30.0, turbulence=("light", 1), on_step=hook, params=params)
            for hook in (None, lambda k, s, o: None)]
    blocks, python = runs
    if blocks.loop["autopilot_compiled_steps"] == 0:
        pytest.skip(f"compiled blocks not available here ({blocks.loop['loop']}: {blocks.loop['reason']})")
    assert python.loop["autopilot_compiled_steps"] == 0
    notes = [n for _, n in blocks.autopilot_log if n.startswith("underspeed")]
    assert any("speed before path" in n for n in notes) and any("rejoining the path" in n for n in notes)
    assert np.array_equal(blocks.result.data, python.result.data, equal_nan=True)
    assert blocks.autopilot_log == python.autopilot_log
    assert np.array_equal(blocks.track_error, python.track_error, equal_nan=True)
