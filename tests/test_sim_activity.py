"""The control-activity measure against signals whose band power is known in closed form."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fdm_awe.errors import InputError
from fdm_awe.sim.activity import band_rms, control_activity

DT = 1.0 / 120.0


def _t(seconds: float) -> np.ndarray:
    return np.arange(0.0, seconds, DT)


def test_a_sine_above_the_cut_off_gives_its_rms():
    t = _t(60.0)
    for f, a in ((1.1, 0.4), (3.0, 0.05), (10.0, 0.2)):
        # Welch's estimate of a pure tone's power is exact up to the window's spread at the band
        # edge, which is far from these tones: 2 % covers the estimate's ripple
        assert band_rms(a * np.sin(2 * math.pi * f * t + 0.3), DT) == pytest.approx(a / math.sqrt(2), rel=0.02)


def test_a_slow_manoeuvre_does_not_leak_into_the_band():
    t = _t(60.0)
    slow = 0.8 * np.sin(2 * math.pi * 0.05 * t) + 0.3 * np.sin(2 * math.pi * 0.2 * t + 1.0) + 0.1 * t / 60.0
    assert band_rms(slow, DT) < 0.01 * 0.8  # under 1 % of the slow amplitude
    fast = 0.1 * np.sin(2 * math.pi * 1.5 * t)
    assert band_rms(slow + fast, DT) == pytest.approx(0.1 / math.sqrt(2), rel=0.03)


def test_white_noise_band_power_is_its_share_of_the_spectrum():
    rng = np.random.default_rng(3)
    sigma = 0.2
    x = rng.normal(0.0, sigma, len(_t(120.0)))
    nyquist = 0.5 / DT
    expected = sigma * math.sqrt((nyquist - 0.5) / nyquist)  # flat spectrum: variance share of the band
    assert band_rms(x, DT) == pytest.approx(expected, rel=0.05)


def test_surfaces_and_total():
    t = _t(40.0)
    ca = control_activity(0.3 * np.sin(2 * math.pi * 1.1 * t), np.zeros_like(t), 0.4 * np.sin(2 * math.pi * 2 * t), DT)
    assert ca.elevator == pytest.approx(0.0, abs=1e-12)
    assert ca.total == pytest.approx(math.hypot(0.3, 0.4) / math.sqrt(2), rel=0.02)
    d = ca.as_dict()
    assert set(d) == {"f_cut_hz", "aileron_rms", "elevator_rms", "rudder_rms", "total_rms"}


def test_a_flight_that_ended_early_is_measured_up_to_its_end_and_bad_input_is_refused():
    t = _t(30.0)
    x = 0.2 * np.sin(2 * math.pi * 2.0 * t)
    x[len(x) // 2:] = np.nan
    assert band_rms(x, DT) == pytest.approx(0.2 / math.sqrt(2), rel=0.03)
    assert math.isnan(band_rms(x[:5], DT))
    with pytest.raises(InputError, match="f_cut"):
        band_rms(x, DT, f_cut=70.0)
    with pytest.raises(InputError, match="dt"):
        band_rms(x, 0.0)
