"""The flyable reference (fdm_awe.autopilot.shaping): the optimiser's held-control steps smoothed
out by centred running means over the periodic cycle."""

from __future__ import annotations

import numpy as np
import pytest

from fdm_awe.autopilot.shaping import WINDOWS, flyable_reference, hold_interval, periodic_mean
from fdm_awe.autopilot.tracking import TrackingReference
from flight_helpers import DATA


def test_a_running_mean_of_one_hold_interval_turns_a_staircase_into_ramps():
    h, n = 0.8, 25
    P = h * n
    rng = np.random.default_rng(3)
    levels = rng.normal(size=n)
    # the staircase as the reference stores it: each interval's value at 4 rows inside it
    t = (np.arange(n)[:, None] * h + np.array([0.0, 0.25, 0.5, 0.999]) * h).ravel()
    y = np.repeat(levels, 4)
    m = periodic_mean(t, y, h, P)
    # a mean over one interval, centred at an interval's middle, is that interval's value;
    # between two middles it is the straight line between their values (the steps' harmonics vanish)
    mid = np.arange(n) * h + 0.5 * h
    expect = np.interp(t, np.r_[mid[-1] - P, mid, mid[0] + P], np.r_[levels[-1], levels, levels[0]])
    assert np.allclose(m, expect, atol=5e-3)  # the stored steps are ramps over 0.1 % of an interval
    # the mean over the cycle is kept, a constant is left alone, vectors go column by column
    assert np.trapezoid(m, t) == pytest.approx(np.trapezoid(y, t), abs=0.05)
    assert np.allclose(periodic_mean(t, np.full(len(t), 2.5), 1.3 * h, P), 2.5)
    assert np.allclose(periodic_mean(t, np.c_[y, 2 * y], h, P)[:, 1], 2 * m)
    with pytest.raises(ValueError):
        periodic_mean(t, y, P, P)


def test_the_flyable_reference_stays_near_the_optimisers_path_and_consistent():
    ref = TrackingReference.from_ocp_file(DATA / "ref_physical_nominal_8mps_sized.json")
    h = hold_interval(ref)
    # the longer of the phases' intervals: here the recovery's, 20 over T2 (0.761 s; the
    # generation's 60 over T1 are 0.746 s)
    mesh = ref.meta["mesh"]
    assert h == pytest.approx(ref.T2 / mesh["n_rec"]) and h > ref.T1 / mesh["n_gen"]
    fly = flyable_reference(ref)
    assert fly.meta["shaping_windows_s"] == [pytest.approx(w * h, rel=1e-5) for w in WINDOWS]
    dev = np.linalg.norm(fly.pos - ref.pos, axis=1)
    assert np.sqrt(np.mean(dev ** 2)) < 0.4 and dev.max() < 2.0  # m: 0.29 RMS, 1.46 at most
    # one filter for all columns: the smoothed velocity is the smoothed position's rate
    tt = np.linspace(0.0, ref.period, 3001)[:-1]
    pos = np.array([fly.sample(t).pos for t in tt])
    vel = np.array([fly.sample(t).vel for t in tt])
    rate = np.gradient(pos, tt, axis=0)
    assert np.sqrt(np.mean((rate - vel)[5:-5] ** 2)) < 0.1 * np.sqrt(np.mean(vel ** 2))
    # the winch's targets are the optimiser's
    assert np.array_equal(fly.length, ref.length) and np.array_equal(fly.reel_speed, ref.reel_speed)


def test_a_reference_without_held_controls_is_flown_as_it_is():
    pts = np.array([[100.0, 0.0, -50.0], [0.0, 100.0, -60.0], [-100.0, 0.0, -50.0], [0.0, -100.0, -60.0]])
    ref = TrackingReference.from_waypoints(pts, None, None, 12.0)
    assert hold_interval(ref) == 0.0 and flyable_reference(ref) is ref
