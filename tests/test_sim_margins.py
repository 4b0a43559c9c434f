"""Loop margins by loop breaking (fdm_awe.sim.margins, scripts/loop_margins.py).

The method against a stand-in loop whose margins are known in closed form, and the real glider's
loops at one operating point (high-tension generation, the point whose aileron and elevator
loops were short before the retune) against the aim of 6 dB and 45 deg.
"""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from fdm_awe.errors import InputError
from fdm_awe.sim.margins import Multisine, log_multisine, loop_gain, margins

REPO = Path(__file__).resolve().parent.parent
DT = 1.0 / 120.0


def _script():
    spec = importlib.util.spec_from_file_location("loop_margins", REPO / "scripts" / "loop_margins.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules.setdefault("loop_margins", mod)  # dataclasses look their module up there
    spec.loader.exec_module(mod)
    return mod


def _delayed_integrator(K: float, n: int, signal: Multisine, t_on: float, seconds: float):
    """Stand-in loop, sampled every DT: plant y[k+1] = y[k] + DT u_in[k] (an integrator),
    controller u_out[k] = -K y[k-n] (a gain behind n steps of delay), u_in = u_out + d.
    L(z) = K DT z^-n / (z - 1): |L| = K DT / (2 sin(w DT / 2)), angle = -90 deg - w (n + 1/2) DT."""
    steps = int(round(seconds / DT))
    t = np.arange(steps) * DT
    d = np.where(t >= t_on, signal(t - t_on), 0.0)
    y = np.zeros(steps + 1)
    u_in, u_out = np.zeros(steps), np.zeros(steps)
    for k in range(steps):
        u_out[k] = -K * (y[k - n] if k >= n else 0.0)
        u_in[k] = u_out[k] + d[k]
        y[k + 1] = y[k] + DT * u_in[k]
    return t, u_in, u_out


def _exact(K: float, n: int) -> tuple[float, float, float, float]:
    """Gain margin [dB] at w180 and phase margin [deg] at wc of the stand-in loop, closed form."""
    wc = 2.0 / DT * math.asin(K * DT / 2.0)
    pm = 90.0 - math.degrees(wc * (n + 0.5) * DT)
    w180 = math.pi / ((2 * n + 1) * DT)
    gm = 20.0 * math.log10(2.0 * math.sin(w180 * DT / 2.0) / (K * DT))
    return gm, w180, pm, wc


@pytest.mark.parametrize("K, n", [(4.0, 6), (10.0, 8), (6.0, 3)])
def test_the_method_recovers_the_margins_of_a_loop_known_in_closed_form(K, n):
    sig = _script().default_signal()
    t, u_in, u_out = _delayed_integrator(K, n, sig, 1.0, 1.0 + 3 * sig.period_s)
    w, L = loop_gain(t, u_in, u_out, sig, 1.0, settle_periods=1, periods=2)
    # the measured points are the closed form itself (a linear loop in its periodic steady state)
    z = np.exp(1j * w * DT)
    assert np.allclose(L, K * DT * z ** (-n) / (z - 1.0), rtol=1e-6, atol=1e-9)
    m = margins(w, L)
    gm, w180, pm, wc = _exact(K, n)
    # crossovers fall between measured frequencies (about 25 % apart): the interpolation in log
    # frequency costs up to 0.06 dB, 0.15 deg and 0.7 % of the frequency on these loops
    assert m.gain_margin_db == pytest.approx(gm, abs=0.25)
    assert m.phase_margin_deg == pytest.approx(pm, abs=0.5)
    assert m.w_gain == pytest.approx(wc, rel=0.015) and m.w_phase == pytest.approx(w180, rel=0.015)
    assert m.meets(6.0, 45.0) == (gm >= 6.0 and pm >= 45.0)


def test_margins_without_crossovers_are_infinite_and_bad_input_is_refused():
    w = np.geomspace(1.0, 100.0, 20)
    m = margins(w, 0.5 / (1.0 + 1j * w / 10.0))  # |L| < 1 everywhere, phase above -90 deg
    assert math.isinf(m.gain_margin_db) and math.isinf(m.phase_margin_deg) and m.w_gain is None
    assert m.as_dict()["gain_margin_db"] is None
    with pytest.raises(InputError):
        margins(w[::-1], np.ones(20))
    with pytest.raises(InputError):
        Multisine(10.0, (1, 1), 0.01)
    with pytest.raises(InputError):
        loop_gain(np.arange(0.0, 5.0, DT), np.zeros(600), np.zeros(600), log_multisine(10.0, 1.0, 10.0, 5, 0.01), 0.0)


def test_the_gliders_loops_meet_the_aim_in_high_tension_generation():
    lm = _script()
    from fdm_awe.autopilot.config import autopilot_params

    res = lm.analyse_point(lm.POINTS["gen_high"], list(lm.SURFACE_LOOPS), autopilot_params())
    for loop, (m, w, L) in res.items():
        assert m.meets(lm.AIM_GAIN_DB, lm.AIM_PHASE_DEG), (loop, m)
        assert np.all(np.isfinite(L)) and len(w) >= 15
